//! Cheng's foot-point error terms PD, TD and SD (Cheng et al. 2007, §II-D; [`crate::terms`])
//! as a [`DataTerm`]: each sample `S_k` is projected onto the fixed target from the source the
//! options name ([`crate::feet`]), which gives the foot point `V_k` and its frame; the true
//! squared error is `‖S_k − V_k‖²`, the model `Q_k` of the method and `Q_k (S_k − V_k)`.
//!
//! Since `S_k − V_k` is along `N` at a foot point, every model has the true error's value and
//! gradient there (PD exactly, TD and SD through `Q (S − V) = S − V`).

use std::sync::{Mutex, PoisonError};

use subfit_target::{FootPoint, Target};

use crate::feet::FootPointSource;
use crate::options::FitOptions;
use crate::term::{DataTerm, IDENTITY};
use crate::terms::{error_matrix, mul, Mat3, Method};

/// Cheng's foot-point terms on a [`Target`]: the samples are projected onto the target from
/// `source`, and `method` makes the quadratic model. The nearest data point of every sample is
/// kept as the warm start of the next projection of the same sample row
/// ([`Target::foot_points_hinted`]; the triangle path needs none), so a term serves one
/// sampling operator (one [`crate::Fitter`]).
#[derive(Debug)]
pub struct FootPointTerm<'t> {
    target: &'t Target,
    method: Method,
    source: FootPointSource,
    /// Nearest data point of every sample row at its last projection (`u32::MAX`: none).
    hints: Mutex<Vec<u32>>,
}

impl<'t> FootPointTerm<'t> {
    /// The term `method` with foot points on `target` from `source`.
    pub fn new(target: &'t Target, method: Method, source: FootPointSource) -> Self {
        Self {
            target,
            method,
            source,
            hints: Mutex::new(Vec::new()),
        }
    }

    /// The term `options` name ([`FitOptions::method`], [`FitOptions::foot_points`]).
    pub fn from_options(target: &'t Target, options: &FitOptions) -> Self {
        Self::new(target, options.method, options.foot_points)
    }

    /// The target.
    pub fn target(&self) -> &'t Target {
        self.target
    }

    /// The error term.
    pub fn method(&self) -> Method {
        self.method
    }

    /// Fresh foot points of `xs` (normalized coordinates) from the term's source, in parallel;
    /// the warm start is left alone. Same as [`DataTerm::project_fresh`].
    pub fn foot_points(&self, xs: &[[f64; 3]]) -> Vec<FootPoint> {
        crate::feet::foot_points(self.target, self.source, xs)
    }

    /// [`Self::foot_points`] warm-started from (and updating) `hints`
    /// ([`crate::feet::foot_points_hinted`]).
    fn foot_points_hinted(&self, xs: &[[f64; 3]], hints: &mut Vec<u32>) -> Vec<FootPoint> {
        crate::feet::foot_points_hinted(self.target, self.source, xs, hints)
    }
}

impl DataTerm for FootPointTerm<'_> {
    type Sample = FootPoint;

    /// PD: `Q = I`.
    fn isotropic(&self) -> bool {
        self.method == Method::Pdm
    }

    fn project(&self, rows: Option<&[u32]>, xs: &[[f64; 3]]) -> Vec<FootPoint> {
        // A poisoned lock only loses the hints.
        let mut hints = self.hints.lock().unwrap_or_else(PoisonError::into_inner);
        let Some(rows) = rows else {
            return self.foot_points_hinted(xs, &mut hints);
        };
        let need = rows.iter().max().map_or(0, |&k| k as usize + 1);
        if hints.len() < need {
            hints.resize(need, u32::MAX);
        }
        let mut sub: Vec<u32> = rows.iter().map(|&k| hints[k as usize]).collect();
        let feet = self.foot_points_hinted(xs, &mut sub);
        for (&k, &h) in rows.iter().zip(&sub) {
            hints[k as usize] = h;
        }
        feet
    }

    fn project_fresh(&self, xs: &[[f64; 3]]) -> Vec<FootPoint> {
        self.foot_points(xs)
    }

    /// `‖x − V‖²`.
    #[inline]
    fn squared_error(&self, f: &FootPoint, x: [f64; 3]) -> f64 {
        (0..3).map(|a| (x[a] - f.point[a]).powi(2)).sum::<f64>()
    }

    /// [`error_matrix`] and `Q (x − V)` (PD: `x − V`).
    #[inline]
    fn model(&self, f: &FootPoint, x: [f64; 3]) -> (Mat3, [f64; 3]) {
        let e = std::array::from_fn(|a| x[a] - f.point[a]);
        if self.method == Method::Pdm {
            return (IDENTITY, e);
        }
        let q = error_matrix(self.method, f);
        let r = mul(&q, e);
        (q, r)
    }

    fn bbox_diagonal(&self) -> f64 {
        bbox_diagonal(self.target.points())
    }
}

/// The diagonal of the bounding box of `p` (1 when empty or degenerate).
fn bbox_diagonal(p: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for x in p {
        for a in 0..3 {
            lo[a] = lo[a].min(x[a]);
            hi[a] = hi[a].max(x[a]);
        }
    }
    let d = (0..3).map(|a| (hi[a] - lo[a]).powi(2)).sum::<f64>().sqrt();
    if d.is_finite() && d > 0.0 {
        d
    } else {
        1.0
    }
}
