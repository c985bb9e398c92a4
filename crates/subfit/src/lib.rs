//! subfit: fit compact subdivision surfaces to dense 3D scans.
//!
//! The front door is [`fit_scan`]: the whole pipeline — read or take the scan, analyse it,
//! build an initial control mesh with its topology, fit it in stages while measuring the error
//! both ways, keep the best cage — returning a [`Fitted`] cage in the input's coordinates with
//! a typed [`Report`] (`report.json` is its serialization) that can write every output
//! ([`Fitted::write_into`], [`OUTPUTS`]). The command-line tool, its demo and benchmarks call
//! it; none re-implements a step. Its steps (DESIGN.md §2, STYLE.md rules 11–12):
//! [`prepare`] reads, repairs and analyses the input once ([`Prepared`]); [`starts`] lists the
//! candidate initial cages ([`StartKind`]: the one place where a new kind is added);
//! `fit_start` fits each from the shared [`Prepared`]; [`choose`] keeps the best by its typed
//! [`Measurement`]. [`initialize`] builds the first start alone (`subfit init`).
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
//! - [`measure`]: the one measurer: two-sided distances, data samples, the limit tessellation;
//! - [`report`]: error colours, plots, the preview image, report.html.

pub mod choose;
pub mod chordal;
mod closing;
mod error;
mod fit_start;
mod fitted;
mod html_report;
mod initialize;
mod limit_stencils;
mod markers;
mod measure_fit;
mod options;
mod outputs;
pub mod pipeline_report;
pub mod prepare;
mod progress;
mod repair;
mod report_build;
mod scan;
mod sequence;
mod sequence_output;
mod sequence_tracking;
mod start;
pub mod start_cad;
mod start_curvature_lines;
mod start_given;
mod start_qem;
pub mod starts;
pub mod tolerance;

pub use choose::Measurement;
pub use closing::{ClosingSummary, ErrorFigure};
pub use error::Error;
pub use fitted::Fitted;
pub use html_report::{ViewMesh, VIEW_POINTS, VIEW_TRIANGLES};
pub use initialize::{initialize, Initialized};
pub use markers::{parse_markers, read_markers};
pub use options::{method_named, FitScanOptions, InitialCage, Input, QuadLayout, EXACT_ERROR};
pub use outputs::{log_csv, usd_scheme, OutputOptions, OUTPUTS};
pub use pipeline_report::Report;
pub use prepare::Prepared;
pub use progress::{Progress, Step};
pub use repair::{repair_mesh, repair_or_points};
pub use scan::{fit_scan, read_cage};
pub use sequence::{
    fit_sequence, frame_file_name, DriftDiagnostics, FrameReport, FrameTimings, MarkerObservation,
    Sequence, SequenceFrame, SequenceOptions, SequenceOptionsSummary, SequenceReport,
    SilhouetteOptions, TrackingOptions, TrackingReport, DEFAULT_SILHOUETTE_WEIGHT,
};
pub use starts::{Start, StartKind, BOTH_INITS_POINTS, BUDGET_STARTS};

pub use subfit_fit as fit;
pub use subfit_init as init;
pub use subfit_io as io;
pub use subfit_measure as measure;
pub use subfit_mesh as mesh;
pub use subfit_report as report;
pub use subfit_subdiv as subdiv;
pub use subfit_target as target;
