//! What the stage driver ([`crate::fit_stages`]; Cheng et al. 2007 §II-B step 8, Table IV;
//! DESIGN.md §3.5) reports: one [`StageReport`] per stage, the whole log, the result and the
//! progress events. The driver and its last step, the polish ([`crate::polish`]), both write
//! them.

use std::time::Duration;

use subfit_measure::data_samples::SampleKind;
use subfit_measure::TwoSided;
use subfit_mesh::{PolyMesh, Tags};

use crate::remesh::RefineStats;
use crate::report::{ErrorStats, FitReport, IterationRow};

/// One stage: a fit at one `λ` and one control mesh, then the mesh changes made after it.
#[derive(Clone, Debug, PartialEq)]
pub struct StageReport {
    /// 0-based stage number.
    pub stage: usize,
    /// `λ` of this stage.
    pub lambda: f64,
    /// Control points during this stage's fit.
    pub num_control_points: usize,
    /// Control faces during this stage's fit.
    pub num_faces: usize,
    /// The iterations of this stage.
    pub fit: FitReport,
    /// Both-way distances of the cage at the end of this stage's fit (before its changes).
    pub two_sided: TwoSided,
    /// Edge flips evaluated after the fit.
    pub flips_tried: usize,
    /// Edge flips kept (they lowered the error on their faces).
    pub flips_kept: usize,
    /// Local refinement after the fit, if any.
    pub refine: Option<RefineStats>,
    /// Control points added by local enrichment after the fit, one per local error field
    /// merged ([`crate::enrich`]).
    pub local_points: usize,
    /// Control points optimized in this stage when it was local ([`crate::StageOptions::local`]);
    /// `None`: all of them.
    pub active_points: Option<usize>,
    /// `Some(kept)` for the last step, the polish of the best cage ([`crate::polish`]): whether
    /// the polished cage replaced it. `None` for the stages before.
    pub polish: Option<bool>,
    /// Wall time of the stage (fit, flips and refinement).
    pub time: Duration,
}

/// Why the stage driver stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StageStop {
    /// Every tolerance set is met (both ways unless [`crate::StageOptions::two_sided`] is off).
    Tolerance,
    /// The control-point budget is spent, `λ` is at its end value and the last stage did not
    /// gain more than [`crate::STALL_GAIN`].
    Budget,
    /// Nothing left to change (`λ` at its end, no refinement possible or useful), or
    /// [`crate::STALL_STAGES`] stages in a row did not improve on the best cage by more than
    /// [`crate::STALL_GAIN`].
    Stalled,
    /// Refinement stopped paying: [`crate::UNPAID_REFINEMENTS`] refinements in a row each lowered the
    /// judged RMS by less than [`crate::StageOptions::refine_payoff`] asks while it still missed its
    /// tolerance (the floor of a noisy target).
    Diminishing,
    /// `max_stages` or `max_iterations` reached.
    Limit,
    /// With [`crate::StageOptions::must_reach`], the tolerances cannot be met within the budget even
    /// at the best rate of approximation.
    Hopeless,
}

/// The log of [`crate::fit_stages`].
#[derive(Clone, Debug, PartialEq)]
pub struct StagesReport {
    /// Errors of the initial control mesh (at the first stage's `λ`; surface → data).
    pub initial: ErrorStats,
    /// Both-way distances of the initial control mesh.
    pub initial_two_sided: TwoSided,
    /// Errors of the returned control mesh (surface → data, at the `λ` of its stage).
    pub last: ErrorStats,
    /// Both-way distances of the returned control mesh.
    pub two_sided: TwoSided,
    /// The stage whose fitted cage is returned: the best measured ([`crate::StageOptions`] decide
    /// what "best" means: see [`crate::fit_stages`]).
    pub best_stage: usize,
    /// Where the data → surface distances were measured from.
    pub data_samples: SampleKind,
    /// One entry per stage.
    pub stages: Vec<StageReport>,
    /// Why it stopped.
    pub stop: StageStop,
    /// Total wall time.
    pub time: Duration,
}

impl StagesReport {
    /// Iterations over all stages.
    pub fn iterations(&self) -> usize {
        self.stages.iter().map(|s| s.fit.iterations.len()).sum()
    }
}

/// Result of [`crate::fit_stages`].
#[derive(Clone, Debug)]
pub struct StagesResult {
    /// The fitted cage in the target's normalized units (new control points appended after
    /// the initial ones; the initial ids persist).
    pub mesh: PolyMesh,
    /// Its crease and corner tags (those given, carried through refinement).
    pub tags: Tags,
    /// The log.
    pub report: StagesReport,
}

/// A progress event of [`crate::fit_stages`].
#[derive(Clone, Copy, Debug)]
pub enum StageEvent<'a> {
    /// An iteration of stage `stage` ended.
    Iteration {
        /// 0-based stage.
        stage: usize,
        /// The iteration's row.
        row: &'a IterationRow,
    },
    /// A stage ended (after its measurement and mesh changes).
    Stage(&'a StageReport),
}
