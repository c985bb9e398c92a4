//! Typed errors of the fitter (STYLE.md rule 5).

use subfit_subdiv::SubdivError;

/// The phase of an iteration, for diagnostics and timings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FitPhase {
    /// Building the sampling operator, the pattern and the symbolic factorization.
    Setup,
    /// Evaluating the sample points `S = C·P`.
    Sample,
    /// Foot-point queries on the target.
    Project,
    /// Filling the normal equations.
    Assemble,
    /// Numeric factorization and triangular solves.
    Solve,
    /// Evaluating the true objective at trial control points.
    Evaluate,
}

/// Why a fit failed.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// The control mesh is unusable (bad topology, wrong face type for the scheme, …).
    #[error("invalid control mesh: {0}")]
    ControlMesh(#[from] SubdivError),
    /// The control mesh has no vertices or faces, or positions are not finite.
    #[error("invalid control mesh: {0}")]
    BadInput(String),
    /// An option is out of range.
    #[error("invalid option `{name}` = {value}")]
    BadOption {
        /// Field name in [`crate::FitOptions`].
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// The normal matrix could not be factored (not positive definite) and no damping could
    /// repair it.
    #[error("iteration {iteration}: {phase:?}: normal matrix not positive definite (pivot {pivot}, damping {damping:e}, mean diagonal {mean_diagonal:e})")]
    NotPositiveDefinite {
        /// Iteration (1-based) in which it happened.
        iteration: usize,
        /// FitPhase ([`FitPhase::Solve`]).
        phase: FitPhase,
        /// Index of the failing pivot in the factorization's order.
        pivot: usize,
        /// Damping `μ` in effect.
        damping: f64,
        /// Mean diagonal entry of `H`.
        mean_diagonal: f64,
    },
    /// A non-finite value appeared (control points, objective, or the solution).
    #[error("iteration {iteration}: {phase:?}: non-finite {what}")]
    NonFinite {
        /// Iteration (1-based; 0 = the initial evaluation).
        iteration: usize,
        /// FitPhase in which it was detected.
        phase: FitPhase,
        /// What was not finite.
        what: &'static str,
    },
    /// Another failure of the sparse solver (memory, …).
    #[error("sparse solver: {0}")]
    Solver(String),
    /// [`crate::FitOptions::cancel`] was cancelled.
    #[error("interrupted")]
    Interrupted,
}

impl From<subfit_mesh::Cancelled> for FitError {
    fn from(_: subfit_mesh::Cancelled) -> Self {
        FitError::Interrupted
    }
}
