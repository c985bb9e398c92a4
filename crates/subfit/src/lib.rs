//! subfit: fit compact subdivision surfaces to dense 3D scans.
//!
//! The front door is [`fit_scan`]: the whole pipeline — read or take the scan, analyse it,
//! build an initial control mesh with its topology, fit it in stages while measuring the error
//! both ways, keep the best cage — returning a [`Fitted`] cage in the input's coordinates with
//! a typed [`Report`] (`report.json` is its serialization) that can write every output
//! ([`Fitted::write_into`], [`OUTPUTS`]). The command-line tool, its demo and benchmarks call
//! it; none re-implements a step.
//!
//! ```no_run
//! use subfit::{fit_scan, FitScanOptions, Input};
//!
//! let mut fitted = fit_scan(Input::File("scan.ply".into()), &FitScanOptions::default(), None)?;
//! println!("{}", fitted.summary());
//! std::fs::create_dir_all("out")?;
//! fitted.write_into(std::path::Path::new("out"))?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! The workspace crates are re-exported:
//! - [`mesh`]: polygon topology, half-edge view, diagnostics, generated shapes;
//! - [`io`]: PLY, OBJ, OFF, STL and XYZ readers and writers, USDA cages;
//! - [`subdiv`]: subdivision schemes, stencils and limit evaluation;
//! - [`target`]: the shape being fitted (normals, curvature, foot points);
//! - [`fit`]: the fitting engine (PDM/TDM/SDM, smoothing, LM and Armijo step control, stages);
//! - [`init`]: initial control meshes with the target's topology (QEM simplification, contouring);
//! - [`report`]: two-sided distances, error colours, the limit tessellation, plots.

mod budget_starts;
pub mod cad_start;
mod error;
mod html_report;
pub mod initial_cage;
mod markers;
mod outputs;
pub mod pipeline_report;
mod repair;
mod scan;
mod sequence;
mod sequence_tracking;
pub mod tolerance;

pub use budget_starts::BUDGET_STARTS;
pub use error::Error;
pub use html_report::{ViewMesh, VIEW_POINTS, VIEW_TRIANGLES};
pub use markers::{parse_markers, read_markers};
pub use outputs::{log_csv, usd_scheme, OUTPUTS};
pub use pipeline_report::Report;
pub use repair::repair_mesh;
pub use scan::{
    fit_scan, read_cage, FitScanOptions, Fitted, InitialCage, Input, Progress, Step, EXACT_ERROR,
};
pub use sequence::{
    fit_sequence, frame_file_name, DriftDiagnostics, FrameReport, FrameTimings, MarkerObservation,
    Sequence, SequenceFrame, SequenceOptions, SequenceOptionsSummary, SequenceReport,
    SilhouetteOptions, TrackingOptions, TrackingReport, DEFAULT_SILHOUETTE_WEIGHT,
};

pub use subfit_fit as fit;
pub use subfit_init as init;
pub use subfit_io as io;
pub use subfit_mesh as mesh;
pub use subfit_report as report;
pub use subfit_subdiv as subdiv;
pub use subfit_target as target;
