//! The result of [`crate::fit_scan`]: the cage written, in the input's coordinates, its typed
//! report, and what writing the outputs needs ([`crate::outputs`], [`crate::html_report`]).

use std::sync::Arc;

use subfit_fit::{FitOptions, StagesResult};
use subfit_mesh::{Cancel, PolyMesh, Tags};
use subfit_subdiv::Scheme;
use subfit_target::Target;

use crate::choose::Measurement;
use crate::pipeline_report::Report;

/// The result of [`crate::fit_scan`]: the cage in the input's coordinates, what is needed to write
/// the outputs, and the report.
pub struct Fitted {
    /// The cage: positions in the input's coordinates, faces.
    pub cage: PolyMesh,
    /// Its crease and corner tags.
    pub tags: Tags,
    /// Its subdivision scheme.
    pub scheme: Scheme,
    /// The report (`report.json`).
    pub report: Report,
    /// What the choice between starts compared ([`crate::choose`]).
    pub measurement: Measurement,
    pub(crate) target: Arc<Target>,
    pub(crate) normalized: PolyMesh,
    pub(crate) stages: StagesResult,
    pub(crate) fit: FitOptions,
    /// The limit tessellation (normalized units) and the distance of each of its vertices to
    /// the target.
    pub(crate) limit: PolyMesh,
    pub(crate) local_error: Vec<f64>,
    /// The distance of each data sample to that tessellation (data → surface).
    pub(crate) data_error: Vec<f64>,
    pub(crate) cancel: Cancel,
}

impl Fitted {
    /// Whether the cage meets the tolerances (both ways unless one-sided was asked).
    pub fn reached(&self) -> bool {
        self.report.tolerance_reached
    }

    /// The cage in the target's normalized units.
    pub fn normalized_cage(&self) -> &PolyMesh {
        &self.normalized
    }

    /// The analysed target.
    pub fn target(&self) -> &Target {
        &self.target
    }

    /// The subdivision rules the cage was fitted with (scheme, boundary and triangle rules):
    /// with [`Self::cage`] and [`Self::tags`], what any evaluator needs for its limit surface.
    pub fn subdivision(&self) -> subfit_subdiv::Options {
        self.fit.subdivision()
    }
}
