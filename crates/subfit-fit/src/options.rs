//! Options of the fitting loop and of its error term (Cheng et al. 2007, §II-B, §II-D, §II-E,
//! §III-C; DESIGN.md §3.4).

use std::sync::Arc;

use subfit_mesh::{Cancel, Tags};
use subfit_subdiv::{BoundaryRule, Options, Scheme};

use crate::surface_term::WeightedSurfaceTerm;

pub use crate::ordering::FillOrdering;

/// The error term (distance measure) used to build the quadratic model (Cheng 2007 §II-D).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Method {
    /// Point distance (eq. 3), `Q = I`: the classic alternating method, linear convergence.
    Pdm,
    /// Tangent distance (eq. 4), `Q = N Nᵀ`: a Gauss-Newton step; unstable without damping.
    Tdm,
    /// Squared distance (eq. 6), `Q = N Nᵀ + [α1]₊ T1 T1ᵀ + [α2]₊ T2 T2ᵀ`: a (modified) Newton
    /// step. The default.
    #[default]
    Sdm,
    /// The IMLS distance of Xie et al. 2023 (eq. 2–4): not a foot-point term — the fitter
    /// takes [`crate::ImlsTerm`] for it (through [`crate::AnyTerm`]). A [`crate::FootPointTerm`] given
    /// it measures foot-point distances (how the pipeline compares fits of every method) and
    /// models them as TD, the foot-point analogue of IMLS's `∇f ∇fᵀ`.
    Imls,
}

/// The source of foot points.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FootPointSource {
    /// The exact closest point on the target's triangles when it has them, else the quadrics.
    #[default]
    Auto,
    /// Always the local quadrics of the data points.
    Quadric,
}

/// How the damped normal equations are solved each iteration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum LinearSolver {
    /// Sparse Cholesky below [`FitOptions::pcg_min_points`] control points, preconditioned
    /// conjugate gradients at and above it. The default.
    #[default]
    Auto,
    /// Always the sparse Cholesky factorization (exact up to rounding).
    Cholesky,
    /// Always preconditioned conjugate gradients (inexact: stops at
    /// [`FitOptions::pcg_tolerance`]).
    Pcg,
}

/// Step control on the true (re-projected) objective (Cheng 2007 §III-C).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum StepControl {
    /// Take the minimizer of the quadratic model as it is (PDM, TDM, SDM).
    None,
    /// Levenberg–Marquardt damping `H + μI` with the gain ratio
    /// `ρ = actual / predicted decrease` and the update of Madsen, Nielsen & Tingleff (2004):
    /// accept when `ρ > 0`, then `μ ← μ·max(1/3, 1 − (2ρ − 1)³)`, `ν ← 2`; otherwise
    /// `μ ← μν`, `ν ← 2ν`. The objective never increases. The default.
    #[default]
    LevenbergMarquardt,
    /// Armijo backtracking on the step length `t ∈ {1, β, β², …}`:
    /// accept the first `t` with `F(P + tδ) ≤ F(P) + c₁ t ∇Fᵀδ`.
    Armijo,
}

/// The optimizer of [`crate::Fitter::run`]. Gauss-Newton solves the sparse normal equations
/// of the quadratic models (Cheng et al. 2007); the first-order optimizers only need the
/// objective and its gradient `∇_P F = Cᵀ ∂F/∂S` ([`crate::Fitter::objective_and_gradient`]),
/// the path of a differentiable pipeline (Xie et al. 2023 §3.1 fit with Adam). With a
/// first-order optimizer one iteration is [`FIRST_ORDER_STEPS`] gradient steps, so that the
/// iteration budgets of the stages stay comparable.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Optimizer {
    /// Gauss-Newton with the step control of [`FitOptions::step`]. The default.
    #[default]
    GaussNewton,
    /// Adam (Kingma & Ba 2015), β₁ = 0.9, β₂ = 0.999, ε = 1e-12, with this step size
    /// (normalized units: the largest move of a control point per step).
    Adam {
        /// Step size α (normalized units).
        learning_rate: f64,
    },
    /// L-BFGS (argmin's, with a More–Thuente line search) keeping this many correction pairs.
    Lbfgs {
        /// Correction pairs kept (argmin's `m`).
        memory: usize,
    },
}

/// Gradient steps per iteration of a first-order [`Optimizer`].
pub const FIRST_ORDER_STEPS: usize = 25;

/// The eight variants named in Cheng 2007 (§II-D, §IV-C).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Variant {
    /// Point distance minimization, no step control.
    Pdm,
    /// Tangent distance minimization, no step control.
    Tdm,
    /// Squared distance minimization, no step control.
    Sdm,
    /// TDM with Levenberg–Marquardt damping.
    TdmLm,
    /// SDM with Levenberg–Marquardt damping.
    SdmLm,
    /// PDM with Armijo step control.
    PdmSc,
    /// TDM with Armijo step control.
    TdmSc,
    /// SDM with Armijo step control.
    SdmSc,
}

impl Variant {
    /// All eight variants, in the order above.
    pub const ALL: [Variant; 8] = [
        Variant::Pdm,
        Variant::Tdm,
        Variant::Sdm,
        Variant::TdmLm,
        Variant::SdmLm,
        Variant::PdmSc,
        Variant::TdmSc,
        Variant::SdmSc,
    ];

    /// The error term and step control of the variant.
    pub fn parts(self) -> (Method, StepControl) {
        use StepControl as S;
        match self {
            Variant::Pdm => (Method::Pdm, S::None),
            Variant::Tdm => (Method::Tdm, S::None),
            Variant::Sdm => (Method::Sdm, S::None),
            Variant::TdmLm => (Method::Tdm, S::LevenbergMarquardt),
            Variant::SdmLm => (Method::Sdm, S::LevenbergMarquardt),
            Variant::PdmSc => (Method::Pdm, S::Armijo),
            Variant::TdmSc => (Method::Tdm, S::Armijo),
            Variant::SdmSc => (Method::Sdm, S::Armijo),
        }
    }

    /// The paper's name (`"PDM"`, `"SDMLM"`, `"TDMSC"`, …).
    pub fn name(self) -> &'static str {
        match self {
            Variant::Pdm => "PDM",
            Variant::Tdm => "TDM",
            Variant::Sdm => "SDM",
            Variant::TdmLm => "TDMLM",
            Variant::SdmLm => "SDMLM",
            Variant::PdmSc => "PDMSC",
            Variant::TdmSc => "TDMSC",
            Variant::SdmSc => "SDMSC",
        }
    }
}

/// Options of [`crate::fit`] and [`crate::Fitter`]. All lengths are in the target's normalized
/// units (the unit cube, Cheng 2007 §II-B step 1).
#[derive(Clone, Debug, PartialEq)]
pub struct FitOptions {
    /// Subdivision scheme of the control mesh. Default [`Scheme::Loop`].
    pub scheme: Scheme,
    /// Boundary interpolation rule of the subdivision. Default [`BoundaryRule::EdgeOnly`]
    /// (OpenSubdiv's `VTX_BOUNDARY_EDGE_ONLY`).
    pub boundary: BoundaryRule,
    /// Crease and corner tags of the control mesh (OpenSubdiv semantics; vertex ids of the
    /// cage). Default none. [`crate::fit_stages`] carries them through refinement.
    pub tags: Tags,
    /// Refinement level `l` at which the limit surface is sampled (one sample per level-`l`
    /// vertex, about `4^l ·` #faces samples for triangles). Default 3.
    pub sample_level: usize,
    /// Error term. Default [`Method::Sdm`].
    pub method: Method,
    /// Step control. Default [`StepControl::LevenbergMarquardt`].
    pub step: StepControl,
    /// Optimizer. Default [`Optimizer::GaussNewton`].
    pub optimizer: Optimizer,
    /// Smoothing weight `λ` of `F_s = λ/n Σ|W(P_i)|²` (§II-E; dimensionless, as the error term
    /// is a mean over samples). Default `1e-3` (the papers' starting value); 0 disables it.
    pub lambda: f64,
    /// Maximum number of iterations (solves; rejected LM / Armijo trials count). Default 20.
    pub max_iterations: usize,
    /// Stop when `E_rms` (normalized units) falls to or below this. Default 0 (off).
    pub tolerance_rms: f64,
    /// Stop when `E_max` (normalized units) falls to or below this. Default 0 (off).
    pub tolerance_max: f64,
    /// Stop when an accepted iteration lowers the objective by less than this fraction of it.
    /// Default `1e-9`.
    pub min_relative_decrease: f64,
    /// Tikhonov shift added to the diagonal of `H`, relative to the mean diagonal entry; keeps
    /// TD systems (rank-deficient tangentially without smoothing) factorizable. Dimensionless.
    /// Default `1e-9`.
    pub ridge: f64,
    /// LM: initial damping `μ₀ = τ · max diag(H)` (Madsen–Nielsen–Tingleff `τ`). Default `1e-3`.
    pub lm_tau: f64,
    /// Armijo: sufficient-decrease constant `c₁`. Default `1e-4`.
    pub armijo_c1: f64,
    /// Armijo: backtracking factor `β ∈ (0, 1)`. Default 0.5.
    pub armijo_beta: f64,
    /// Armijo: maximum number of halvings per iteration. Default 12.
    pub armijo_max_backtracks: usize,
    /// Linear solver for the normal equations. Default [`LinearSolver::Auto`].
    pub linear_solver: LinearSolver,
    /// Fill-reducing ordering of the sparse Cholesky. Default [`FillOrdering::BlockAmd`].
    pub fill_ordering: FillOrdering,
    /// [`LinearSolver::Auto`] switches to PCG at this many control points (SD/TD only; PD keeps
    /// its three scalar Cholesky solves). Default 2000: on Igea (level 3) PCG's solve was
    /// 2–4× faster than Cholesky's from 2k control points on, with the same errors per iteration
    /// (10k: factor of 22.4M values, 1.8–2.9 s, against 0.13–0.26 s).
    pub pcg_min_points: usize,
    /// PCG stops when `‖r‖ ≤ pcg_tolerance · ‖g‖` (relative residual, dimensionless).
    /// Default `1e-2`: on Igea at 10k control points the per-iteration errors match those
    /// with `1e-3` to three digits at half the PCG iterations (the LM gain ratio stays exact
    /// for any tolerance: the predicted decrease is computed from the step solved).
    pub pcg_tolerance: f64,
    /// PCG iteration cap per solve. Default 500.
    pub pcg_max_iterations: usize,
    /// Where foot points come from: the target's triangles when it has them (default), or
    /// always the local quadrics.
    pub foot_points: FootPointSource,
    /// Weight `w` of the data → surface part of the objective ([`crate::Coverage`]: data points
    /// at the data's or the surface's boundary pull their nearest sample, so open rims reach
    /// the data's edge),
    /// relative to the surface → data mean: `F = mean_k e_k² + w · mean_j e_j² + …`.
    /// Dimensionless, ≥ 0. Default 0 (off: the papers' one-sided objective, as in the
    /// convergence studies); `subfit::fit_scan` turns it on (1).
    pub coverage: f64,
    /// Whether a mesh target's foot points face the sample's side inside thin parts
    /// ([`subfit_target::Target::mesh_foot_points_facing`]): a sample whose surface has sunk
    /// past the middle of a limb is pulled by the wall on its own side, not the nearer
    /// opposite one. Default false here (the papers' closest point); `subfit::FitScanOptions`
    /// turns it on (`subfit fit` and Python's `fit` with it; `--no-facing`, `facing=False`
    /// turn it off).
    pub facing: bool,
    /// The data's sharp feature curves as segments (normalized units), e.g. the sharp edges
    /// [`subfit_target::detect_features`] finds on a mesh target: with [`Self::coverage`] > 0
    /// they pull the creases of the limit surface onto them ([`crate::Coverage::with_features`]).
    /// Default `None`; `subfit::fit_scan` sets the features its initial cage was built along.
    pub feature_segments: Option<Arc<Vec<[[f64; 3]; 2]>>>,
    /// The exponent `p` of the surface → data error the foot-point terms minimize:
    /// `F = mean_k e_k^p / r^(p−2) + …`, `r` the RMS error at the fit's first projection (so
    /// `F` stays in squared units). 2 (the default) is least squares, the papers' objective;
    /// a larger `p` trades a little RMS for a lower maximum (iteratively reweighted least
    /// squares: each sample's model is weighted by `(e_k / r)^(p−2)`, clamped to
    /// [[`crate::POWER_WEIGHT_MIN`], [`crate::POWER_WEIGHT_MAX`]]). [`crate::fit_stages`]
    /// ends with such a polish ([`crate::StageOptions::polish_power`]). Valid: `2 ≤ p ≤ 8`.
    pub error_power: f64,
    /// [`Method::Imls`]: the kernel support radius `h` (normalized units, the unit cube the
    /// target is scaled into — the units of Xie et al. 2023 §5.1's `h₀`). Default `None`:
    /// chosen from the target ([`crate::ImlsTerm::auto_radius`]: half the point spacing, at
    /// least 4 × the noise level). Valid: finite, `> 0`.
    pub imls_radius: Option<f64>,
    /// [`Method::Imls`]: weight `β ≥ 0` of the tangential term added to the Gauss-Newton
    /// matrix, `Q = ∇f ∇fᵀ + β (‖∇f‖² I − ∇f ∇fᵀ)` (a constant stand-in for SD's curvature
    /// terms; the residual, hence the gradient, is unchanged). Dimensionless. Default 0 (see
    /// [`crate::ImlsTerm`] for the measurements).
    pub imls_tangential: f64,
    /// Weight `α` of the as-rigid-as-possible regularizer on the control mesh (Sorkine & Alexa
    /// 2007; Xie et al. 2023 eq. 5; [`crate::Arap`]), added to the objective as
    /// `α/n · E_arap` beside the data term's mean and the umbrella smoothing `λ/n ‖L P‖²`
    /// (both are kept: set `λ = 0` for ARAP alone). Its rest shape is the cage a
    /// [`crate::Fitter`] first runs from — in [`crate::fit_stages`] the initial cage until a
    /// refinement or flip changes the topology, then the changed cage. Dimensionless. Default 0
    /// (off); the paper uses 0.01 on clean scans, 0.1 on noisy ones (its data term is a sum
    /// over about as many samples as control points, so the same `α` means the same balance).
    pub arap: f64,
    /// The ARAP rest shape (normalized units, one position per control point). Default `None`:
    /// the cage the fitter first runs from. A sequence sets the template here, so every frame
    /// keeps the template's local shape whatever cage it starts from.
    pub arap_rest: Option<Arc<Vec<[f64; 3]>>>,

    /// A term on the whole sampled surface with its weight ([`crate::SurfaceTerm`], e.g. the
    /// soft silhouette loss of [`crate::silhouette`]), added to the objective and, as a
    /// first-order term, to the gradient. Default `None`. Evaluated on all samples even with an
    /// active set.
    pub surface_term: Option<WeightedSurfaceTerm>,
    /// Cancellation token, polled at the start of every iteration and of every LM / Armijo
    /// trial; once cancelled, [`crate::Fitter::run`] (and [`crate::fit`], [`crate::fit_stages`])
    /// return [`crate::FitError::Interrupted`]. Default: a fresh token, never cancelled.
    pub cancel: Cancel,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            scheme: Scheme::Loop,
            boundary: BoundaryRule::EdgeOnly,
            tags: Tags::new(),
            sample_level: 3,
            method: Method::Sdm,
            step: StepControl::LevenbergMarquardt,
            optimizer: Optimizer::GaussNewton,
            lambda: 1e-3,
            max_iterations: 20,
            tolerance_rms: 0.0,
            tolerance_max: 0.0,
            min_relative_decrease: 1e-9,
            ridge: 1e-9,
            lm_tau: 1e-3,
            armijo_c1: 1e-4,
            armijo_beta: 0.5,
            armijo_max_backtracks: 12,
            linear_solver: LinearSolver::Auto,
            fill_ordering: FillOrdering::BlockAmd,
            pcg_min_points: 2000,
            pcg_tolerance: 1e-2,
            pcg_max_iterations: 500,
            foot_points: FootPointSource::Auto,
            coverage: 0.0,
            facing: false,
            error_power: 2.0,
            feature_segments: None,
            imls_radius: None,
            imls_tangential: 0.0,
            arap: 0.0,
            arap_rest: None,

            surface_term: None,
            cancel: Cancel::default(),
        }
    }
}

impl FitOptions {
    /// Default options with the method and step control of a paper variant.
    pub fn variant(v: Variant) -> Self {
        let (method, step) = v.parts();
        Self {
            method,
            step,
            ..Self::default()
        }
    }

    /// Sets the smoothing weight `λ`.
    pub fn with_lambda(mut self, lambda: f64) -> Self {
        self.lambda = lambda;
        self
    }

    /// Sets the maximum iteration count.
    pub fn with_max_iterations(mut self, k: usize) -> Self {
        self.max_iterations = k;
        self
    }

    /// Sets the `E_rms` stopping tolerance (normalized units).
    pub fn with_tolerance_rms(mut self, t: f64) -> Self {
        self.tolerance_rms = t;
        self
    }

    /// Sets the sample level.
    pub fn with_sample_level(mut self, l: usize) -> Self {
        self.sample_level = l;
        self
    }

    /// The subdivision options: scheme and boundary rule.
    pub fn subdivision(&self) -> Options {
        Options::new(self.scheme).with_boundary(self.boundary)
    }

    /// Sets the subdivision scheme.
    pub fn with_scheme(mut self, s: Scheme) -> Self {
        self.scheme = s;
        self
    }

    /// Checks value ranges; returns the offending field's name and value.
    pub(crate) fn validate(&self) -> Result<(), (&'static str, f64)> {
        let h = self.imls_radius.unwrap_or(1.0);
        let w = self.surface_term.as_ref().map_or(0.0, |t| t.weight);
        let checks: [(&'static str, f64, bool); 15] = [
            ("surface_term.weight", w, w >= 0.0),
            (
                "error_power",
                self.error_power,
                (2.0..=8.0).contains(&self.error_power),
            ),
            ("coverage", self.coverage, self.coverage >= 0.0),
            ("lambda", self.lambda, self.lambda >= 0.0),
            ("imls_radius", h, h > 0.0),
            (
                "imls_tangential",
                self.imls_tangential,
                self.imls_tangential >= 0.0,
            ),
            ("arap", self.arap, self.arap >= 0.0),
            (
                "tolerance_rms",
                self.tolerance_rms,
                self.tolerance_rms >= 0.0,
            ),
            (
                "tolerance_max",
                self.tolerance_max,
                self.tolerance_max >= 0.0,
            ),
            ("ridge", self.ridge, self.ridge >= 0.0),
            ("lm_tau", self.lm_tau, self.lm_tau > 0.0),
            (
                "armijo_c1",
                self.armijo_c1,
                self.armijo_c1 > 0.0 && self.armijo_c1 < 1.0,
            ),
            (
                "armijo_beta",
                self.armijo_beta,
                self.armijo_beta > 0.0 && self.armijo_beta < 1.0,
            ),
            (
                "pcg_tolerance",
                self.pcg_tolerance,
                self.pcg_tolerance > 0.0 && self.pcg_tolerance < 1.0,
            ),
            (
                "pcg_max_iterations",
                self.pcg_max_iterations as f64,
                self.pcg_max_iterations > 0,
            ),
        ];
        for (name, v, ok) in checks {
            if !ok || !v.is_finite() {
                return Err((name, v));
            }
        }
        match self.optimizer {
            Optimizer::Adam { learning_rate: a } if !(a.is_finite() && a > 0.0) => {
                Err(("optimizer learning_rate", a))
            }
            Optimizer::Lbfgs { memory: 0 } => Err(("optimizer memory", 0.0)),
            _ => Ok(()),
        }
    }
}
