//! The one measurer of a fit (DESIGN.md §2 "One measurer", decision 11): how far a limit
//! surface is from the data, both ways. The fit's stopping test (the stages of `subfit-fit`), the
//! pipeline's final figures and report, and the Python package all call it; `subfit-report`
//! only formats and draws what it measured. (The scoreboard's judge in `subfit-bench` is a
//! separate code path on purpose.)
//!
//! * [`distance`]: distance statistics one way ([`DistanceStats`]) and both ways
//!   ([`TwoSided`]): surface → data and data → surface, in normalized (unit-cube) units; a fit
//!   has reached a tolerance only when both directions are within it.
//! * [`limit_distance`]: exact distances from points to a limit surface (closest points on the
//!   limit surface, [`subfit_subdiv::ClosestPointFinder`]), with the control face they land on.
//! * [`mesh_distance`]: distances from points to a tessellation of it (point–triangle, BVH),
//!   within the tessellation's chordal error of the exact ones and ~50× faster.
//! * [`data_samples`]: the points the data → surface direction is measured from: a point
//!   cloud's points, or a mesh's surface sampled uniformly by area.
//! * [`tessellate`]: the limit tessellation a fit is measured on and written with, at the
//!   coarsest level whose chordal error is a tenth of the fitting error.
//!
//! Nothing here prints or touches files.

pub mod data_samples;
pub mod distance;
pub mod limit_distance;
pub mod mesh_distance;
pub mod tessellate;

pub use data_samples::{
    data_samples, data_samples_with_vertices, mesh_vertices, DataSamples, SampleKind,
};
pub use distance::{DistanceStats, TwoSided};
pub use limit_distance::{LimitDistance, LimitDistanceError, PointToLimit};
pub use mesh_distance::MeshDistance;
pub use tessellate::{limit_tessellation, Chordal, LimitTessellation};
