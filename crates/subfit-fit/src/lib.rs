//! The fitting engine of subfit (DESIGN.md §2 `subfit-fit`, §3.3–3.4): a subdivision surface's
//! control points are fitted to a [`subfit_target::Target`] by the separable iteration of
//! Cheng et al. 2007 (§II-B, §III): sample the limit surface linearly (`S = C·P`), project the
//! samples onto the target, minimize a quadratic model of the squared distance — PD, TD or SD
//! (§II-D; Cheng et al. 2004 §3, §4.4) plus the umbrella smoothing term (§II-E) — with a sparse
//! Cholesky solve, and control the step by Levenberg–Marquardt or Armijo (§III-C).
//!
//! * [`terms`]: the per-sample 3×3 error matrices `Q_k`;
//! * [`smooth`]: the umbrella Laplacian;
//! * [`assemble`]: the pattern of `H`, built once per topology, filled in place in parallel;
//! * [`solve`]: `faer` supernodal Cholesky with the symbolic analysis reused;
//! * [`Fitter`] / [`fit`]: the loop with step control; [`FitReport`] logs every iteration.
//!
//! Everything is in the target's normalized units (unit cube). The library prints nothing;
//! progress goes to an optional callback.

pub mod assemble;
mod error;
mod fitter;
mod options;
mod report;
pub mod smooth;
pub mod solve;
pub mod terms;

pub use error::{FitError, Phase};
pub use fitter::{fit, FitResult, Fitter};
pub use options::{FitOptions, Method, StepControl, Variant};
pub use report::{ErrorStats, FitReport, IterationRow, PhaseTimings, StopReason};
