//! The fitting engine of subfit (DESIGN.md §2 `subfit-fit`, §3.3–3.4): a subdivision surface's
//! control points are fitted to a [`subfit_target::Target`] by the separable iteration of
//! Cheng et al. 2007 (§II-B, §III): sample the limit surface linearly (`S = C·P`), project the
//! samples onto the target, minimize a quadratic model of the squared distance — PD, TD or SD
//! (§II-D; Cheng et al. 2004 §3, §4.4) plus the umbrella smoothing term (§II-E) — with a sparse
//! Cholesky solve, and control the step by Levenberg–Marquardt or Armijo (§III-C).
//!
//! * [`DataTerm`]: what is fitted — per sample, the true squared error and its quadratic model
//!   (`Q_k`, `Q_k (S_k − V_k)`); [`FootPointTerm`] is Cheng's PD/TD/SD on a target,
//!   [`ImlsTerm`] Xie et al. 2023's IMLS distance (§4.1, eq. 2–4; [`Method::Imls`]), and
//!   [`AnyTerm`] whichever [`FitOptions::method`] names;
//! * [`Arap`]: the as-rigid-as-possible regularizer on the control mesh (Sorkine & Alexa
//!   2007; Xie et al. 2023 eq. 5), [`FitOptions::arap`], folded into the same sparse system;
//! * [`Fitter`] / [`fit`]: the loop with step control (sampling operator, the pattern of the
//!   normal matrix and its symbolic Cholesky analysis kept between iterations and calls; PCG
//!   for large systems, [`LinearSolver`]); [`FitReport`] logs every iteration;
//! * [`fit_stages`]: multi-stage fitting — `λ` schedule, edge flips and red-green local
//!   refinement until a tolerance or a control-point budget.
//!
//! Everything is in the target's normalized units (unit cube). The library prints nothing;
//! progress goes to an optional callback.
//!
//! Variants ([`Variant`]) as named in the paper: PDM, TDM, SDM (no step control), TDMLM, SDMLM
//! (Levenberg–Marquardt), PDMSC, TDMSC, SDMSC (Armijo). On the paper's ellipsoid from a
//! 14-vertex Loop cage (`tests/convergence.rs`, λ = 0, sample level 3) iterations to
//! `E_rms < 0.002`: SDM 4, SDMLM 4, SDMSC 4, TDMLM 3, TDMSC 9, TDM oscillates, PDM and PDMSC
//! not within 10 (E_rms 0.011) — the behaviour of Cheng 2007 §IV.
//!
//! ```
//! use subfit_fit::{fit, FitOptions, Variant};
//! use subfit_mesh::shapes::{octahedron_mesh, Shape};
//! use subfit_target::{Target, TargetOptions};
//!
//! let cloud = Shape::PAPER_ELLIPSOID.sample(3_000, 0.0, 1);
//! let target =
//!     Target::from_points(&cloud.positions, cloud.normals.as_deref(), &TargetOptions::default())
//!         .unwrap();
//! // The control mesh lives in the target's normalized coordinates.
//! let mut cage = octahedron_mesh(0.25, 0.5, 1.0);
//! for p in &mut cage.positions {
//!     *p = target.to_normalized(*p);
//! }
//! let options = FitOptions::variant(Variant::SdmLm).with_max_iterations(5);
//! let result = fit(&target, &cage, &options).unwrap();
//! assert!(result.report.last().e_rms < result.report.initial.e_rms);
//! let original: Vec<[f64; 3]> =
//!     result.control_points.iter().map(|&p| target.to_original(p)).collect();
//! assert_eq!(original.len(), 6);
//! ```

mod active;
mod any_term;
mod arap;
mod assemble;
mod coverage;
mod enrich;
mod error;
mod error_field;
mod fitter;
mod foot_point_term;
mod grouped_fill;
mod imls_term;
mod options;
mod ordering;
mod pcg;
pub mod polish;
mod refine_polygons;
mod remesh;
mod report;
pub mod silhouette;
mod smooth;
mod solve;
mod stage_flips;
mod stage_measure;
mod stage_options;
mod stage_refine;
mod stage_report;
mod stages;
mod surface_term;
mod term;
pub mod track;

pub use any_term::{AnySample, AnyTerm};
pub use arap::Arap;
pub use coverage::{CoverSum, Coverage, FEATURE_WEIGHT};
pub use error::{FitError, FitPhase};
pub use fitter::{fit, FitResult, Fitter};
pub use foot_point_term::{FootPointTerm, FootSample, POWER_WEIGHT_MAX, POWER_WEIGHT_MIN};
pub use imls_term::{ImlsSample, ImlsTerm};
pub use options::{
    FillOrdering, FitOptions, FootPointSource, LinearSolver, Method, Optimizer, StepControl,
    Variant, FIRST_ORDER_STEPS,
};
pub use pcg::PcgStats;
pub use refine_polygons::{refine_polygons, PolyRefinement, TriangleSplit};
pub use remesh::RefineStats;
pub use report::{ErrorStats, FitReport, IterationRow, PhaseTimings, StopReason};
pub use stage_measure::judged_with_boundary;
pub use stage_options::{StageOptions, LOCAL_FIELD_PEAK, LOCAL_FIELD_SHARE, REFINE_PAYOFF};
pub use stage_report::{StageEvent, StageReport, StageStop, StagesReport, StagesResult};
pub use stages::{fit_stages, STALL_GAIN, STALL_STAGES, UNPAID_REFINEMENTS};
pub use surface_term::{fan_triangles, SurfaceTerm, WeightedSurfaceTerm};
pub use term::{DataTerm, Mat3};

/// The fitter's building blocks, reachable only for this crate's integration tests (`tests/`)
/// and the assembly benchmark (`crates/subfit/examples/assemble_igea.rs`), which check them
/// against dense references and time them one by one. Not part of the API: undocumented, no
/// stability promise; use [`Fitter`].
#[doc(hidden)]
pub mod internals {
    pub use crate::assemble::{weighted_residuals, FillScratch, Pattern};
    pub use crate::foot_point_term::error_matrix;
    pub use crate::ordering::{block_amd, nested_dissection, BlockGraph};
    pub use crate::pcg::PcgSolver;
    pub use crate::remesh::{face_owners, refine_red_green};
    pub use crate::smooth::Laplacian;
    pub use crate::solve::{CholeskySolver, SolveFailure};
    pub use crate::term::{mul, quadratic};
}
