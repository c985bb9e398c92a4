//! What a sequence fit gives back ([`crate::sequence`]): per-frame reports, the sequence's
//! report (`report.json`) and the fitted cages, with their output files.

use serde::Serialize;
use subfit_mesh::{PolyMesh, Polygons, Tags};
use subfit_subdiv::{sampling_operator, BoundaryRule, Scheme};

use crate::error::Error;
use crate::pipeline_report::{Reorientation, TwoSidedErrors};
use crate::sequence_tracking::TrackingReport;

/// One frame's figures (`report.json` → `frames[i]`).
#[derive(Clone, Debug, Serialize)]
pub struct FrameReport {
    /// 0-based frame index.
    pub index: usize,
    /// The frame's name (its file).
    pub name: String,
    /// Points of the frame after duplicates and outliers.
    pub points: usize,
    /// Whether the frame had faces (a mesh) or was a point cloud.
    pub mesh: bool,
    /// Faces re-oriented on reading, if any.
    pub reoriented: Option<Reorientation>,
    /// The frame's bounding-box diagonal (its own units).
    pub bbox_diagonal: f64,
    /// Both-way errors of the frame's cage against the frame.
    pub two_sided: TwoSidedErrors,
    /// Whether both directions' RMS are within the tolerance.
    pub tolerance_reached: bool,
    /// LM iterations (solves) spent on the frame (the template fit's for an automatic template).
    pub iterations: usize,
    /// The silhouette loss at the end (mean squared pixel difference), when the term is on.
    pub silhouette_loss: Option<f64>,
    /// Drift diagnostics of the tracked limit points (see the module docs).
    pub drift: DriftDiagnostics,
    /// The tracking step before the fit, when it ran.
    pub tracking: Option<TrackingReport>,
    /// Seconds per phase.
    pub timings_s: FrameTimings,
}

/// How the tracked limit points moved and the cage deformed (fractions of the frame's
/// bounding-box diagonal; zero for the first frame).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct DriftDiagnostics {
    /// RMS motion of the control vertices' limit points since the previous frame.
    pub motion_rms: f64,
    /// Its part along the limit normal (RMS).
    pub normal_motion_rms: f64,
    /// Its tangential part (RMS): sliding over the surface.
    pub tangential_motion_rms: f64,
    /// RMS relative change of the cage's edge lengths against the template.
    pub edge_strain_rms: f64,
}

/// Seconds per phase of one frame.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct FrameTimings {
    /// Reading the file.
    pub read: f64,
    /// Target analysis.
    pub analyse: f64,
    /// Target images of the silhouette term.
    pub silhouette: f64,
    /// The tracking step.
    pub track: f64,
    /// Fitting (with the measurement at its end).
    pub fit: f64,
    /// The whole frame.
    pub total: f64,
}

/// The sequence's report (`report.json`).
#[derive(Clone, Debug, Serialize)]
pub struct SequenceReport {
    /// Frames fitted.
    pub frames_fitted: usize,
    /// Control points of the cage (every frame).
    pub control_points: usize,
    /// Control faces.
    pub control_faces: usize,
    /// The subdivision scheme.
    pub scheme: String,
    /// Where the template came from: `"fit"` (the first frame fitted with `fit_scan`) or the
    /// file given.
    pub template: String,
    /// The template fit's own report when it was fitted here.
    pub template_report: Option<Box<crate::Report>>,
    /// Per-frame options in effect.
    pub options: SequenceOptionsSummary,
    /// Worst frame's two-sided RMS (fraction of its diagonal).
    pub worst_rms_fraction_of_diagonal: f64,
    /// Worst frame's two-sided maximum (fraction of its diagonal).
    pub worst_max_fraction_of_diagonal: f64,
    /// Mean seconds per frame (after the first).
    pub mean_seconds_per_frame: f64,
    /// Per frame.
    pub frames: Vec<FrameReport>,
    /// Warnings, in order.
    pub warnings: Vec<String>,
}

/// The options a sequence ran with (`report.json` → `options`).
#[derive(Clone, Debug, Serialize)]
pub struct SequenceOptionsSummary {
    /// Data term.
    pub method: String,
    /// `λ`.
    pub lambda: f64,
    /// ARAP `α` towards the template.
    pub arap: f64,
    /// LM iterations per frame at most.
    pub iterations: usize,
    /// Per-frame tolerance (normalized units).
    pub tolerance_rms: f64,
    /// Silhouette views (0: off).
    pub silhouette_views: usize,
    /// Silhouette image resolution.
    pub silhouette_resolution: usize,
    /// Silhouette weight.
    pub silhouette_weight: f64,
    /// Sample level.
    pub sample_level: usize,
}

/// One fitted frame, as given to the callback of [`crate::fit_sequence`].
pub struct SequenceFrame<'a> {
    /// The cage in the frame's (the input's) coordinates; same faces every frame.
    pub cage: &'a PolyMesh,
    /// Its tags (the template's).
    pub tags: &'a Tags,
    /// The scheme.
    pub scheme: Scheme,
    /// The frame's report.
    pub report: &'a FrameReport,
}

/// What [`crate::fit_sequence`] returns: the cage's connectivity, every frame's positions (input
/// coordinates) and the report.
pub struct Sequence {
    /// Faces of the cage (every frame).
    pub faces: Polygons,
    /// Tags of the cage.
    pub tags: Tags,
    /// The scheme.
    pub scheme: Scheme,
    /// The boundary rule (the per-frame fit's, [`subfit_fit::FitOptions::boundary`]).
    pub boundary: BoundaryRule,
    /// Positions per frame.
    pub positions: Vec<Vec<[f64; 3]>>,
    /// The report.
    pub report: SequenceReport,
}

impl Sequence {
    /// The limit points of the cage refined `level` times (`level = 0`: the control vertices'
    /// limit points), every frame, input coordinates: the same surface point has the same
    /// index in every frame — what a user tracks (e.g. to measure drift).
    ///
    /// Errors: a topology the subdivision refuses (not after a successful fit).
    pub fn limit_points(&self, level: usize) -> Result<Vec<Vec<[f64; 3]>>, Error> {
        let n = self.positions.first().map_or(0, Vec::len);
        let opts = subfit_subdiv::Options::default()
            .with_scheme(self.scheme)
            .with_boundary(self.boundary);
        let op = sampling_operator(&self.faces, n, &self.tags, &opts, level)
            .map_err(|e| Error::Output(e.to_string()))?;
        Ok(self
            .positions
            .iter()
            .map(|p| op.position.apply(p))
            .collect())
    }

    /// The names of the files [`Self::write_into`] writes, in order.
    pub fn output_names(&self) -> Vec<String> {
        let mut v: Vec<String> = (0..self.positions.len()).map(frame_file_name).collect();
        v.push("sequence.usda".into());
        v.push("report.json".into());
        v
    }

    /// Writes every frame's cage (`frame_0000.obj` …, ASCII OBJ in the input's coordinates),
    /// `sequence.usda` (at `fps` frames per second) and `report.json` into `dir`, which must
    /// exist.
    pub fn write_into(&self, dir: &std::path::Path, fps: f64) -> Result<(), Error> {
        let ascii = subfit_io::WriteOptions {
            format: None,
            encoding: subfit_io::Encoding::Ascii,
            single_precision: false,
        };
        for (i, p) in self.positions.iter().enumerate() {
            let cage = PolyMesh::new(p.clone(), self.faces.clone());
            subfit_io::write_file(&dir.join(frame_file_name(i)), &cage, &ascii)?;
        }
        let write = |name: &str, bytes: &[u8]| {
            std::fs::write(dir.join(name), bytes)
                .map_err(|e| Error::Output(format!("{}: {e}", dir.join(name).display())))
        };
        subfit_io::write_usda_animated_file(
            &dir.join("sequence.usda"),
            &self.faces,
            &self.positions,
            &self.tags,
            crate::outputs::usd_scheme(self.scheme, &self.faces),
            crate::outputs::usd_boundary(self.boundary),
            fps,
        )?;
        let json = serde_json::to_vec_pretty(&self.report)
            .map_err(|e| Error::Output(format!("report.json: {e}")))?;
        write("report.json", &json)
    }

    /// `sequence.usda`: one mesh with the cage's topology, scheme and tags and time-sampled
    /// points (time codes 0 … frames − 1 at `fps` frames per second, `fps` > 0).
    pub fn usda(&self, fps: f64) -> Vec<u8> {
        let mut out = Vec::new();
        subfit_io::usda::write_animated(
            &self.faces,
            &self.positions,
            &self.tags,
            crate::outputs::usd_scheme(self.scheme, &self.faces),
            crate::outputs::usd_boundary(self.boundary),
            fps,
            &mut out,
        );
        out
    }
}

/// `frame_0000.obj` for frame 0.
pub fn frame_file_name(index: usize) -> String {
    format!("frame_{index:04}.obj")
}
