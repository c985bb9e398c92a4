//! Per-iteration reports (Cheng 2007 §II-B step 7: `E_m` and `E_rms` with fresh samples).

use std::time::Duration;

use crate::options::{Method, StepControl};

/// Wall-clock time spent per phase (summed over Armijo trials within one iteration).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhaseTimings {
    /// `S = C·P` at trial control points.
    pub sample: Duration,
    /// Projections of the trial samples by the data term (foot-point queries).
    pub project: Duration,
    /// `Q_k`, the in-place fill of `H` and the gradient.
    pub assemble: Duration,
    /// Numeric Cholesky and triangular solves.
    pub solve: Duration,
    /// Objective and error statistics from the fresh projections.
    pub evaluate: Duration,
}

impl PhaseTimings {
    /// Sum of all phases.
    pub fn total(&self) -> Duration {
        self.sample + self.project + self.assemble + self.solve + self.evaluate
    }

    /// Adds `other` phase by phase.
    pub fn accumulate(&mut self, other: &PhaseTimings) {
        self.sample += other.sample;
        self.project += other.project;
        self.assemble += other.assemble;
        self.solve += other.solve;
        self.evaluate += other.evaluate;
    }
}

/// Fitting errors of one set of control points, measured with fresh samples and projections.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ErrorStats {
    /// `E_max = max_k ‖S_k − V_k‖` (normalized units).
    pub e_max: f64,
    /// `E_rms = (1/m Σ_k ‖S_k − V_k‖²)^½` (normalized units).
    pub e_rms: f64,
    /// `E_max` as a fraction of the target's bounding-box diagonal.
    pub e_max_diag: f64,
    /// `E_rms` as a fraction of the target's bounding-box diagonal.
    pub e_rms_diag: f64,
    /// The objective `F = E_rms² + λ/n Σ|W(P_i)|² (+ α/n E_arap with [`crate::FitOptions::arap`])`
    /// (squared normalized units).
    pub objective: f64,
}

/// One row of the iteration log.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IterationRow {
    /// Iteration number, 1-based (one linear solve each).
    pub iteration: usize,
    /// Whether the step was taken (always true without step control).
    pub accepted: bool,
    /// Errors of the current control points after this iteration (the trial's if accepted,
    /// the previous ones if rejected).
    pub errors: ErrorStats,
    /// Objective at the (last) trial control points.
    pub trial_objective: f64,
    /// LM damping `μ` used for this solve (0 without LM; absolute, units of `H`).
    pub damping: f64,
    /// Step length `t` (1 except after Armijo backtracking).
    pub step_length: f64,
    /// LM gain ratio `ρ = actual / predicted decrease` (NaN without LM).
    pub gain_ratio: f64,
    /// Time per phase.
    pub timings: PhaseTimings,
}

/// Why the loop stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// Every tolerance set holds: `E_rms ≤ tolerance_rms` and `E_max ≤ tolerance_max`.
    Tolerance,
    /// `max_iterations` reached.
    MaxIterations,
    /// An accepted step decreased the objective by less than `min_relative_decrease`.
    Stalled,
    /// LM damping grew past any useful value, or Armijo found no acceptable step length.
    NoDescent,
}

/// The log of one [`crate::Fitter::run`].
#[derive(Clone, Debug, PartialEq)]
pub struct FitReport {
    /// The options' error term ([`crate::FitOptions::method`]: what a [`crate::FootPointTerm`]
    /// built by [`crate::Fitter::new`] uses; another data term may ignore it).
    pub method: Method,
    /// Step control used.
    pub step: StepControl,
    /// Number of control points `n`.
    pub num_control_points: usize,
    /// Number of samples `m`.
    pub num_samples: usize,
    /// Errors of the initial control points.
    pub initial: ErrorStats,
    /// One row per iteration.
    pub iterations: Vec<IterationRow>,
    /// Why the loop stopped.
    pub stop: StopReason,
    /// Setup time spent in [`crate::Fitter::new`]: sampling operator, pattern and the symbolic
    /// Cholesky analysis.
    pub setup: std::time::Duration,
}

impl FitReport {
    /// Errors of the final control points.
    pub fn last(&self) -> ErrorStats {
        self.iterations.last().map_or(self.initial, |r| r.errors)
    }

    /// The first iteration (1-based) after which `E_rms ≤ tol`, if any.
    pub fn iterations_to_rms(&self, tol: f64) -> Option<usize> {
        self.iterations
            .iter()
            .find(|r| r.errors.e_rms <= tol)
            .map(|r| r.iteration)
    }
}
