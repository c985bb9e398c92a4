//! The closing summary of a fit: what a person or a script wants to know once the outputs are
//! written — the cage's size, the two-sided error in the input's units and as a fraction of
//! its bounding-box diagonal (DESIGN.md: every error is judged both ways), the time and the
//! files. `subfit fit` prints it as text, or as JSON with `--json`.

use std::fmt;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::fitted::Fitted;
use crate::outputs::OUTPUTS;
use crate::pipeline_report::LargestErrorAt;

/// One error figure in the three units a fit reports.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ErrorFigure {
    /// In the input's units.
    pub units: f64,
    /// As a fraction of the input's bounding-box diagonal.
    pub fraction_of_diagonal: f64,
    /// In the normalized units the fit works in (the input scaled so its longest side is 1).
    pub unit_cube: f64,
}

/// The closing summary of a fit ([`Fitted::closing_summary`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClosingSummary {
    /// Control points of the cage written.
    pub control_points: usize,
    /// Faces of the cage written.
    pub control_faces: usize,
    /// Its subdivision scheme, as report.json `options.scheme` names it (`Loop`,
    /// `CatmullClark`, `QuadTriangle`).
    pub scheme: String,
    /// Whether the tolerances hold (both ways unless a one-sided fit was asked).
    pub tolerance_reached: bool,
    /// Why the stages stopped (see [`crate::Report::stop`]).
    pub stop: String,
    /// The input's bounding-box diagonal, in its units.
    pub diagonal: f64,
    /// Two-sided RMS distance between the limit surface and the data (the worse direction).
    pub two_sided_rms: ErrorFigure,
    /// Two-sided largest distance (Hausdorff).
    pub two_sided_max: ErrorFigure,
    /// Where each direction's largest distance lies, in the input's coordinates.
    pub largest_at: LargestErrorAt,
    /// Seconds the whole run took (reading to writing).
    pub seconds: f64,
    /// The files written, in the order they were moved into place.
    pub files: Vec<PathBuf>,
}

impl Fitted {
    /// The closing summary of this fit, whose outputs were written into `dir`.
    pub fn closing_summary(&self, dir: &Path) -> ClosingSummary {
        let r = &self.report;
        let two = &r.r#final.two_sided;
        let figure = |units, fraction_of_diagonal, unit_cube| ErrorFigure {
            units,
            fraction_of_diagonal,
            unit_cube,
        };
        ClosingSummary {
            control_points: r.control_points,
            control_faces: r.control_faces,
            scheme: r.options.scheme.clone(),
            tolerance_reached: r.tolerance_reached,
            stop: r.stop.clone(),
            diagonal: r.bbox_diagonal_unit_cube * r.normalized_unit_in_original_units,
            two_sided_rms: figure(
                two.e_rms_original_units,
                two.e_rms_fraction_of_diagonal,
                two.e_rms,
            ),
            two_sided_max: figure(
                two.e_max_original_units,
                two.e_max_fraction_of_diagonal,
                two.e_max,
            ),
            largest_at: r.r#final.largest_at,
            seconds: r.timings_s.total,
            files: OUTPUTS.iter().map(|f| dir.join(f)).collect(),
        }
    }
}

impl fmt::Display for ClosingSummary {
    /// A few lines for a person: the cage, the error both ways in the input's units and in %
    /// of the diagonal, the time, the files.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "cage: {} control points, {} faces ({}); tolerances {} (stopped: {})",
            self.control_points,
            self.control_faces,
            self.scheme,
            if self.tolerance_reached {
                "reached"
            } else {
                "NOT reached"
            },
            self.stop
        )?;
        writeln!(
            f,
            "error both ways: RMS {:.4e} ({:.4}% of the diagonal), largest {:.4e} ({:.4}%), in the input's units (diagonal {:.4e})",
            self.two_sided_rms.units,
            100.0 * self.two_sided_rms.fraction_of_diagonal,
            self.two_sided_max.units,
            100.0 * self.two_sided_max.fraction_of_diagonal,
            self.diagonal
        )?;
        let at = |p: [f64; 3]| format!("({:.5e}, {:.5e}, {:.5e})", p[0], p[1], p[2]);
        writeln!(
            f,
            "largest distances at: data → surface {}, surface → data {} (input coordinates)",
            at(self.largest_at.data_to_surface),
            at(self.largest_at.surface_to_data)
        )?;
        writeln!(f, "time: {:.2} s", self.seconds)?;
        let dir = self
            .files
            .first()
            .and_then(|p| p.parent())
            .map(|d| d.display().to_string())
            .unwrap_or_default();
        let names: Vec<String> = self
            .files
            .iter()
            .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
            .collect();
        write!(f, "wrote {dir}: {}", names.join(", "))
    }
}
