//! The data term: what the fitter minimizes besides smoothing (DESIGN.md §2 "Error terms",
//! §3.3; Cheng et al. 2007 §II-B steps 5–6).
//!
//! The fitter samples the limit surface linearly, `S = C·P` (`m` samples, `C` the sampling
//! operator), and minimizes `(1/m) Σ_k e_k(S_k)² + λ·(smoothing)`. A [`DataTerm`] supplies,
//! per sample, the true squared error `e_k²` (judged by the step control: LM gain ratio,
//! Armijo) and a quadratic model of it around the current sample position,
//!
//! ```text
//! e_k(S_k + Δ)² ≈ (S_k + Δ − V_k)ᵀ Q_k (S_k + Δ − V_k),    Q_k 3×3 symmetric PSD,
//! ```
//!
//! given as `Q_k` and the weighted residual `r_k = Q_k (S_k − V_k)`. Summed over the samples it
//! makes the normal matrix `H = (1/m) Σ_k (c_k c_kᵀ) ⊗ Q_k + …` and the gradient
//! `g = (1/m) Cᵀ r + …` (half the gradient of the objective): the Gauss-Newton (or modified
//! Newton) step of the fitter. An isotropic term (`Q_k = I`, the PD term of Cheng 2007 eq. 3)
//! separates the system into one `n × n` matrix with three right-hand sides.
//!
//! Per sample a term keeps whatever its model needs — a foot point and its frame for
//! Cheng's PD/TD/SD ([`crate::FootPointTerm`]), an implicit function's value and gradient
//! for IMLS (Xie et al. 2023 eq. 2–3) — as its [`DataTerm::Sample`]. The fitter and the
//! stage driver see only this trait.

/// A symmetric 3×3 matrix, row-major. Units: dimensionless weights.
pub type Mat3 = [[f64; 3]; 3];

/// The 3×3 identity: `Q` of an isotropic term.
pub const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// A data term of the fit: per sample of the limit surface, the true squared error and its
/// quadratic model (see the module docs). All positions in the target's normalized units.
///
/// The fitter calls [`Self::project`] once per evaluation of a set of control points (the
/// current one and every trial), [`Self::squared_error`] for every sample of it, and
/// [`Self::model`] for every sample of an accepted one; [`Self::project_fresh`] measures
/// points that are not the fitter's samples. Everything may run on several threads at once
/// (`Send + Sync`); warm-start state behind `&self` needs interior mutability.
pub trait DataTerm: Send + Sync {
    /// What the term keeps per sample after a projection (e.g. a foot point).
    type Sample: Send + Sync;

    /// Whether every `Q_k` is the identity. The fitter then solves the separable system (block
    /// size 1, three right-hand sides) and reads only the residual of [`Self::model`]. Must not
    /// change during the term's life (it fixes the pattern of the normal matrix).
    fn isotropic(&self) -> bool;

    /// The per-sample state at the sample positions `xs`. `rows` names the samples of the
    /// fitter's sampling operator that `xs` are (`xs[i]` is row `rows[i]`); `None` means all
    /// of them, in order (`xs.len() = m`). A term may keep a warm start per row (the samples
    /// move little between calls); results must not depend on it beyond ties. Cost: the
    /// term's, typically one query per sample, in parallel.
    fn project(&self, rows: Option<&[u32]>, xs: &[[f64; 3]]) -> Vec<Self::Sample>;

    /// [`Self::project`] for points that are not (or not known to be) the fitter's samples:
    /// no warm-start state is read or written.
    fn project_fresh(&self, xs: &[[f64; 3]]) -> Vec<Self::Sample>;

    /// The true squared error `e²` of the point `x` with the state `s` projected for it
    /// (normalized units²).
    fn squared_error(&self, s: &Self::Sample, x: [f64; 3]) -> f64;

    /// The share of the sample in the objective at `x` with the state `s`: the squared error
    /// plus whatever else the term adds to it (e.g. the data → surface part of
    /// [`crate::FootPointTerm`] with coverage). The model of [`Self::model`] is this one's.
    /// Default: [`Self::squared_error`].
    fn objective_error(&self, s: &Self::Sample, x: [f64; 3]) -> f64 {
        self.squared_error(s, x)
    }

    /// Called once by the fitter with its sampling operator, before any projection (e.g. to
    /// learn the sample tessellation). Default: nothing.
    fn prepare(&mut self, op: &subfit_subdiv::SamplingOperator) {
        let _ = op;
    }

    /// The quadratic model of [`Self::objective_error`] around `x` with the state `s`: `Q` (3×3
    /// symmetric PSD) and the weighted residual `r = Q (x − V)`, so that the model's gradient
    /// in `x` is `2r`. An isotropic term returns the identity and `x − V`.
    fn model(&self, s: &Self::Sample, x: [f64; 3]) -> (Mat3, [f64; 3]);

    /// The diagonal of the data's bounding box (normalized units): the scale of the relative
    /// errors in [`crate::ErrorStats`].
    fn bbox_diagonal(&self) -> f64;

    /// Turns the squared surface → data errors `err2` of the points `xs` (from
    /// [`Self::squared_errors`] or a state: distances to the term's own model of the data) into
    /// what a user measures: for a point cloud, the distance to the data's local surface,
    /// bounded where the data ends ([`Target::to_local_surface`]). The measurements call it;
    /// the objective does not. Default: nothing.
    ///
    /// [`Target::to_local_surface`]: subfit_target::Target::to_local_surface
    fn measured_errors(&self, xs: &[[f64; 3]], err2: &mut [f64]) {
        let _ = (xs, err2);
    }

    /// Squared errors of `xs` ([`Self::squared_error`] after [`Self::project_fresh`]), in
    /// parallel, in order.
    fn squared_errors(&self, xs: &[[f64; 3]]) -> Vec<f64> {
        use rayon::prelude::*;
        let s = self.project_fresh(xs);
        xs.par_iter()
            .zip(s.par_iter())
            .map(|(&x, s)| self.squared_error(s, x))
            .collect()
    }
}

/// The quadratic form `eᵀ Q e`. Cost: O(1).
#[inline]
pub fn quadratic(q: &Mat3, e: [f64; 3]) -> f64 {
    let qe = mul(q, e);
    e[0] * qe[0] + e[1] * qe[1] + e[2] * qe[2]
}

/// `a + b`. Cost: O(1).
#[inline]
pub fn add_mat(a: &Mat3, b: &Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][j] + b[i][j]))
}

/// `Q e`. Cost: O(1).
#[inline]
pub fn mul(q: &Mat3, e: [f64; 3]) -> [f64; 3] {
    [
        q[0][0] * e[0] + q[0][1] * e[1] + q[0][2] * e[2],
        q[1][0] * e[0] + q[1][1] * e[1] + q[1][2] * e[2],
        q[2][0] * e[0] + q[2][1] * e[1] + q[2][2] * e[2],
    ]
}
