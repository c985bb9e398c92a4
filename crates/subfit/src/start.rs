//! A start of the fit as a value (DESIGN.md §2 "Starts → fit → choose"): which kind of
//! initial cage ([`StartKind`]) and the cage it built ([`Start`]). [`crate::starts`] lists and
//! builds them; [`crate::fit_start`] fits one.

use std::sync::Arc;

use subfit_mesh::{PolyMesh, Tags};

use crate::pipeline_report::InitSummary;

/// The kinds of initial cage the pipeline can start from. A new kind (a CAD cage, a
/// thin-part-aware octree, cross-field quads) is a variant here, built in
/// [`crate::starts::build_start`] and listed by [`crate::starts::starts`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StartKind {
    /// The cage given by the caller ([`crate::InitialCage::Given`]).
    Given,
    /// QEM simplification of a mesh target or the trimmed IMLS contour of a point cloud
    /// ([`subfit_init::initial_control_mesh`]); `budget_fraction`: a quad-scheme start capped
    /// by the budget begins at this fraction of it ([`crate::starts::BUDGET_STARTS`]).
    Qem {
        /// The fraction of the budget the start was capped to, if it was.
        budget_fraction: Option<f64>,
        /// The cage laid along a cross field ([`subfit_init::cross_field`]) instead of the
        /// simplification paired into quads (the simplification when the field's cage cannot
        /// be taken).
        cross_field: bool,
    },
    /// The curvature-line cage of Lavoué et al. 2007 §4 ([`subfit_init::curvature_lines`]).
    CurvatureLines,
    /// The cage of a CAD tessellation from its own creases and corners
    /// ([`crate::start_cad`], [`subfit_init::cad_cage`]).
    Cad,
    /// The CAD tessellation's cage with every edge that turns an infinitely sharp crease: its
    /// limit is the facets themselves (emptied planes aside), the fallback when the smooth
    /// one misses the tolerances ([`crate::start_cad`]).
    CadFaceted,
}

impl StartKind {
    /// The kind's name in report.json's `init.source` for the starts whose name does not come
    /// from [`subfit_init`] (a QEM start says `Mesh` or `Contour`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Given => "File",
            Self::Qem { .. } => "Qem",
            Self::CurvatureLines => "CurvatureLines",
            Self::Cad => "CadTessellation",
            Self::CadFaceted => "CadFaceted",
        }
    }
}

/// An initial cage built from the prepared input, ready to be fitted (`fit_start.rs`).
#[derive(Clone, Debug)]
pub struct Start {
    /// Which kind of start built it.
    pub kind: StartKind,
    /// The cage in the target's normalized units (unit cube).
    pub cage: PolyMesh,
    /// Its crease and corner tags.
    pub tags: Tags,
    /// What report.json says of it (`init`).
    pub summary: InitSummary,
    /// The target's feature curves the cage follows (for the fit's coverage term), if any.
    pub feature_segments: Option<Arc<Vec<[[f64; 3]; 2]>>>,
    /// What building it told the user (kept in the report of its fit).
    pub warnings: Vec<String>,
    /// Seconds spent building it.
    pub seconds: f64,
    /// What [`subfit_init::initial_control_mesh`] did, for a QEM start.
    pub init_report: Option<subfit_init::InitReport>,
    /// What [`subfit_init::curvature_lines::curvature_line_cage`] did, for a curvature-line
    /// start.
    pub curvature_report: Option<subfit_init::curvature_lines::CurvatureLineReport>,
}
