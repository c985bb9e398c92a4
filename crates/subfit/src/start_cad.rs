//! The start of a CAD tessellation (DESIGN.md §2, "tessellation-aware CAD cages"): when the
//! target is a mesh whose facets say it is a CAD export ([`subfit_target::tessellation`]) and
//! has creases, its cage is built from its own features ([`subfit_init::cad_cage`]) instead of
//! by QEM to a point count, and it is judged by the tessellation's tolerances.
//!
//! What the facets allow is decided here, from the tolerance the fit is judged by: an edge of a
//! curved face may be smoothed when the smooth limit's predicted deviation from the facets
//! (two thirds of its sag at most, 0.3 of it in RMS) stays within [`SAG_SHARE`] of the maximum
//! tolerance and, summed over the surface, within [`RMS_SHARE`] of the RMS one; every other edge
//! that turns is an infinitely sharp crease, which reproduces its facets exactly. So the
//! default fit of a coarse export is the export itself, emptied of the vertices its planes do
//! not need; a fine export's cylinders and fillets come out smooth.
//!
//! The hook: [`crate::starts::starts`] lists this start ([`StartKind::Cad`]) first when
//! [`cad_applies`] (the start is automatic, no control-point count asked, features on, not as
//! points, and the target recognised as a tessellation, [`subfit_target::Target::facets`]);
//! [`cad_start`] builds it, or fails with a budget error (no creases, or a cage over the budget)
//! that leaves the QEM start listed after it to fit the input as any mesh. The fit of a CAD
//! start is judged by [`ToleranceKind::CadPart`] within at most the tessellation's vertices
//! (`fit_start.rs`); the QEM start after it must then be more compact to win.

use std::sync::Arc;

use subfit_init::{cad_cage, CadOptions};
use subfit_target::tessellation::{
    classify_edges, classify_edges_chordal, EdgeClass, Facets, SmoothBudget,
};

use crate::error::Error;
use crate::options::{FitScanOptions, InitialCage};
use crate::pipeline_report::{face_counts, BoundaryLoops, CadSummary, InitSummary, InitTimings};
use crate::prepare::{topology, Prepared};
use crate::start::{Start, StartKind};
#[cfg(doc)]
use crate::tolerance::ToleranceKind;
use crate::tolerance::{CAD_MAX, CAD_RMS};

/// A smooth edge may sag by at most this share of the maximum tolerance: the smooth limit
/// fitted to its facets lies within two thirds of the sag of them, so half the tolerance is
/// left to the fit.
pub const SAG_SHARE: f64 = 0.75;

/// The smooth edges' predicted RMS deviation from the facets, over the whole surface, stays
/// within this share of the RMS tolerance.
pub const RMS_SHARE: f64 = 0.5;

/// A smooth face's cage may lie this many sags (the largest of a smooth edge) off its facets
/// after simplification: the fitted limit of a coarser polygon lies much closer than the
/// polygon.
pub const SMOOTH_CAGE_SAGS: f64 = 4.0;

/// A tessellation is a CAD part when at least one of its edges turns by this much (degrees),
/// the default feature angle of scans (`subfit_target::FeatureOptions`): a designed edge (box
/// edges, chamfers and hole rims turn by 45–90°). A smoothly curved surface tessellated for
/// export (a half-cylinder of 24 strips turns by 7.5° per edge, a gridded geological horizon
/// by less) is fitted as any mesh.
pub const CAD_EDGE_DEG: f64 = 40.0;

/// Whether the CAD start applies to `prepared` under `options` (see the module docs): the
/// target is a recognised tessellation with an edge that turns by [`CAD_EDGE_DEG`] or more,
/// and neither a feature angle nor semi-sharp creases were asked for (the feature detection
/// of the QEM start gives those).
/// Cost: O(E).
pub fn cad_applies(prepared: &Prepared, options: &FitScanOptions) -> bool {
    let asked = matches!(options.init, InitialCage::Auto)
        && options.control_points.is_none()
        && !options.as_points
        && options.init_options.features.is_some()
        // A feature angle or semi-sharp creases asked for are the feature detection's.
        && options.cad_feature_angle.is_some()
        && !options.init_options.semi_sharp
        && prepared.mesh_faces() > 0;
    let min_angle = CAD_EDGE_DEG.to_radians();
    prepared
        .target
        .facets()
        .filter(|_| asked)
        .is_some_and(|f| f.edges.iter().any(|e| !e.flat && e.angle >= min_angle))
}

/// The control points a fit of the tessellation `prepared` may reach, given the run's
/// `budget`: never more than its (distinct) vertices; and, when the user set no limit (the
/// target's tolerances) and no kept fit capped the budget, exactly that many — the faceted
/// cage of a curved export keeps nearly every vertex, and the generic default budget is no
/// reason to leave its tolerances unmet.
pub(crate) fn tessellation_budget(
    prepared: &Prepared,
    options: &FitScanOptions,
    budget: usize,
) -> usize {
    let vertices = prepared.target.len();
    if options.target_tolerances && budget == options.stages.max_control_points {
        vertices
    } else {
        budget.min(vertices)
    }
}

/// The smooth budget of the tolerances (see the module docs): a smooth edge may sag by
/// [`SAG_SHARE`] of the maximum tolerance, the smooth faces' predicted RMS stay within
/// [`RMS_SHARE`] of the RMS one; the CAD tolerances unless others were given.
fn smooth_budget(prepared: &Prepared, options: &FitScanOptions) -> SmoothBudget {
    let diagonal = prepared.diagonal;
    let (rms, max) = if options.target_tolerances {
        (CAD_RMS * diagonal, CAD_MAX * diagonal)
    } else {
        (options.stages.tolerance_rms, options.stages.tolerance_max)
    };
    // Without a maximum, the sag is bounded through the RMS (a strip deviates by 0.3 of it).
    let max_sag = if max > 0.0 {
        SAG_SHARE * max
    } else {
        RMS_SHARE * rms / 0.3
    };
    SmoothBudget {
        max_sag,
        max_rms: RMS_SHARE * rms,
    }
}

/// The CAD start of `prepared` within `budget` control points (see the module docs). Errors:
/// [`Error::Budget`] when the tessellation has no crease or its cage exceeds the budget (the
/// next start then fits it), [`Error::Init`] when the cage cannot be built,
/// [`Error::Interrupted`].
pub(crate) fn cad_start(
    prepared: &Prepared,
    options: &FitScanOptions,
    budget: usize,
    faceted: bool,
) -> Result<Start, Error> {
    let (target, mesh, name) = (&*prepared.target, &prepared.mesh, &prepared.name);
    let Some(recognised) = target.facets() else {
        return Err(Error::Budget(format!(
            "{name}: not a CAD tessellation (no CAD start)"
        )));
    };
    // The target merged coincident vertices again; the cage keeps the repaired mesh's own
    // (split non-manifold vertices stay split).
    let points: Vec<[f64; 3]> = mesh
        .positions
        .iter()
        .map(|&p| target.to_normalized(p))
        .collect();
    let facets = &Facets::new(
        &points,
        &mesh.faces.triangulate_fan(),
        recognised.flat_tolerance,
    );
    let points = &points[..];
    let diagonal = prepared.diagonal;
    let smooth_budget = if faceted {
        SmoothBudget::FACETED
    } else {
        smooth_budget(prepared, options)
    };
    let features = if prepared.chordal.is_some() && !faceted {
        // The chordal tolerance: the fit aims at the curved interpolant, which the facets cut
        // by their sag; a curved face is smooth whatever its deviation from the facets.
        classify_edges_chordal(points, facets)
    } else {
        classify_edges(points, facets, &smooth_budget)
    };
    if features.count(EdgeClass::Crease) == 0 {
        return Err(Error::Budget(format!(
            "{name}: a tessellation without creases (no CAD start)"
        )));
    }
    let cad_options = CadOptions {
        smooth_error: SMOOTH_CAGE_SAGS * features.threshold,
        max_control_points: budget,
        cancel: options.cancel.clone(),
    };
    let (cage, tags, report) =
        cad_cage(points, facets, &features, &cad_options).map_err(|e| match e {
            subfit_init::InitError::Interrupted => Error::Interrupted,
            e => Error::Init {
                name: name.clone(),
                source: e,
            },
        })?;
    if cage.num_vertices() > budget {
        return Err(Error::Budget(format!(
            "{name}: the CAD cage keeps {} control points, more than the budget of {budget}",
            cage.num_vertices()
        )));
    }
    let topo = topology(&cage).map_err(|e| Error::input(name, e))?;
    let stats = facets.stats(points);
    let feature_segments: Vec<[[f64; 3]; 2]> = facets
        .edges
        .iter()
        .zip(&features.class)
        .filter(|(_, c)| **c == EdgeClass::Crease)
        .map(|(e, _)| e.ends.map(|v| points[v as usize]))
        .collect();
    let (quads, triangles, quad_fraction) = face_counts(&cage.faces);
    let init = InitSummary {
        source: if faceted {
            "CadFaceted"
        } else {
            "CadTessellation"
        }
        .into(),
        control_points: cage.num_vertices(),
        faces: cage.faces.len(),
        quads,
        triangles,
        quad_fraction,
        genus_target: topo.genus,
        genus: topo.genus,
        genus_matches: true,
        boundary_loops: BoundaryLoops {
            target: topo.boundary_loops,
            cage: topo.boundary_loops,
        },
        timings_s: InitTimings {
            simplify: report.time.as_secs_f64(),
            total: report.time.as_secs_f64(),
            ..InitTimings::default()
        },
        cad: Some(CadSummary {
            flat_edge_share: stats.flat_edge_share,
            planar_regions: stats.planar_regions,
            sliver_share: stats.sliver_share,
            chord_height: features.chord_height / diagonal,
            flat_edges: features.count(EdgeClass::Flat),
            smooth_edges: features.count(EdgeClass::Smooth),
            crease_edges: features.count(EdgeClass::Crease),
            smooth_sag: features.threshold / diagonal,
            predicted_rms: features.predicted_rms / diagonal,
            vertices: report.vertices_before,
            locked_corners: report.locked_corners,
        }),
        ..InitSummary::default()
    };
    Ok(Start {
        kind: if faceted {
            StartKind::CadFaceted
        } else {
            StartKind::Cad
        },
        cage,
        tags,
        summary: init,
        feature_segments: Some(Arc::new(feature_segments)),
        warnings: Vec::new(),
        seconds: 0.0,
        init_report: None,
        curvature_report: None,
    })
}
