//! The data term a [`FitOptions`] names, as one concrete type (DESIGN.md §2 "Error terms": the
//! fitter and the stage driver never name a term): Cheng et al. 2007's foot-point terms
//! (§II-D; [`FootPointTerm`]) for PD/TD/SD, or Xie et al. 2023's IMLS distance (§4.1, eq. 2–4;
//! [`ImlsTerm`]) for [`Method::Imls`]. A `match` per call; the samples carry which term made
//! them.

use subfit_target::Target;

use crate::foot_point_term::FootPointTerm;
use crate::imls_term::{ImlsSample, ImlsTerm};
use crate::options::{FitOptions, Method};
use crate::term::{DataTerm, Mat3};

/// Either data term, chosen by [`FitOptions::method`] ([`Self::from_options`]).
// One per fitter, never moved in a loop: the size of the larger variant does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Debug)]
pub enum AnyTerm<'t> {
    /// PD, TD or SD on foot points.
    FootPoint(FootPointTerm<'t>),
    /// The IMLS distance.
    Imls(ImlsTerm<'t>),
}

/// A sample of an [`AnyTerm`]: the state of the term that projected it.
#[derive(Debug)]
pub enum AnySample<'t> {
    /// A foot-point term's sample.
    FootPoint(<FootPointTerm<'t> as DataTerm>::Sample),
    /// An IMLS value and gradient.
    Imls(ImlsSample),
}

impl<'t> AnyTerm<'t> {
    /// [`ImlsTerm::from_options`] for [`Method::Imls`], else [`FootPointTerm::from_options`].
    pub fn from_options(target: &'t Target, options: &FitOptions) -> Self {
        match options.method {
            Method::Imls => Self::Imls(ImlsTerm::from_options(target, options)),
            _ => Self::FootPoint(FootPointTerm::from_options(target, options)),
        }
    }
}

/// A sample projected by the other term: a broken invariant (samples never leave their term).
#[cold]
#[track_caller]
fn foreign() -> ! {
    panic!("AnyTerm: a sample projected by another term")
}

impl<'t> DataTerm for AnyTerm<'t> {
    type Sample = AnySample<'t>;

    fn isotropic(&self) -> bool {
        match self {
            Self::FootPoint(t) => t.isotropic(),
            Self::Imls(t) => t.isotropic(),
        }
    }

    fn project(&self, rows: Option<&[u32]>, xs: &[[f64; 3]]) -> Vec<AnySample<'t>> {
        match self {
            Self::FootPoint(t) => wrap(t.project(rows, xs), AnySample::FootPoint),
            Self::Imls(t) => wrap(t.project(rows, xs), AnySample::Imls),
        }
    }

    fn project_fresh(&self, xs: &[[f64; 3]]) -> Vec<AnySample<'t>> {
        match self {
            Self::FootPoint(t) => wrap(t.project_fresh(xs), AnySample::FootPoint),
            Self::Imls(t) => wrap(t.project_fresh(xs), AnySample::Imls),
        }
    }

    #[inline]
    fn squared_error(&self, s: &AnySample<'t>, x: [f64; 3]) -> f64 {
        match (self, s) {
            (Self::FootPoint(t), AnySample::FootPoint(s)) => t.squared_error(s, x),
            (Self::Imls(t), AnySample::Imls(s)) => t.squared_error(s, x),
            _ => foreign(),
        }
    }

    #[inline]
    fn objective_error(&self, s: &AnySample<'t>, x: [f64; 3]) -> f64 {
        match (self, s) {
            (Self::FootPoint(t), AnySample::FootPoint(s)) => t.objective_error(s, x),
            (Self::Imls(t), AnySample::Imls(s)) => t.objective_error(s, x),
            _ => foreign(),
        }
    }

    fn prepare(&mut self, op: &subfit_subdiv::SamplingOperator) {
        match self {
            Self::FootPoint(t) => t.prepare(op),
            Self::Imls(t) => t.prepare(op),
        }
    }

    #[inline]
    fn model(&self, s: &AnySample<'t>, x: [f64; 3]) -> (Mat3, [f64; 3]) {
        match (self, s) {
            (Self::FootPoint(t), AnySample::FootPoint(s)) => t.model(s, x),
            (Self::Imls(t), AnySample::Imls(s)) => t.model(s, x),
            _ => foreign(),
        }
    }

    fn bbox_diagonal(&self) -> f64 {
        match self {
            Self::FootPoint(t) => t.bbox_diagonal(),
            Self::Imls(t) => t.bbox_diagonal(),
        }
    }

    fn measured_errors(&self, xs: &[[f64; 3]], err2: &mut [f64]) {
        match self {
            Self::FootPoint(t) => t.measured_errors(xs, err2),
            Self::Imls(t) => t.measured_errors(xs, err2),
        }
    }

    fn squared_errors(&self, xs: &[[f64; 3]]) -> Vec<f64> {
        match self {
            Self::FootPoint(t) => t.squared_errors(xs),
            Self::Imls(t) => t.squared_errors(xs),
        }
    }
}

/// `v` with every element wrapped by `f` (in parallel: samples are many).
fn wrap<S: Send, A: Send>(v: Vec<S>, f: fn(S) -> A) -> Vec<A> {
    use rayon::prelude::*;
    v.into_par_iter().map(f).collect()
}
