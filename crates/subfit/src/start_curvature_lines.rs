//! The curvature-line start (`--init curvature-lines`): the cage of Lavoué et al. 2007 §4
//! ([`subfit_init::curvature_lines`]) whose vertices are the control points of the boundary
//! curves, joined along the target's lines of curvature; fitted with the quad/triangle scheme
//! unless another is asked, at a sample level raised for its few large faces
//! ([`coarse_sample_level`]). Open mesh targets of genus 0 only.

use std::time::Instant;

use subfit_init::curvature_lines::{curvature_line_cage, CurvatureLineError, CurvatureLineOptions};
use subfit_mesh::vec3::{norm, sub};
use subfit_mesh::{PolyMesh, Polygons};

use crate::error::Error;
use crate::options::FitScanOptions;
use crate::pipeline_report::{
    face_counts, BoundaryLoops, CurvatureLineSummary, InitSummary, InitTimings,
};
use crate::prepare::Prepared;
use crate::start::{Start, StartKind};

/// A curvature-line cage is fitted with at least this many samples: its few large faces
/// (a half-cylinder: 5 quads) at the default sample level 3 get 369 samples, too few to follow
/// the target between them (a 24 × 24 half-cylinder stayed 7.3e-3 of the diagonal off at its
/// rim and the refinement made it worse, 12 → 22 control points outside the tolerances; at
/// level 4 its 12 control points met them: two-sided RMS 5.2e-4, Hausdorff 4.5e-3).
pub const COARSE_MIN_SAMPLES: usize = 4000;

/// The sample level for a curvature-line cage of `faces` faces: `asked`, raised (to at most 4;
/// level 5 stays on as the stages refine the cage, and costs)
/// until `faces · 4^level` reaches [`COARSE_MIN_SAMPLES`].
pub(crate) fn coarse_sample_level(faces: usize, asked: usize) -> usize {
    let mut level = asked;
    while level < 4 && faces.saturating_mul(4usize.pow(level as u32)) < COARSE_MIN_SAMPLES {
        level += 1;
    }
    level
}

/// The curvature-line cage of the prepared mesh target in normalized units within `budget`
/// control points, with its corner tags and its summary; an input error saying why when it cannot be built.
/// Cost: see [`subfit_init::curvature_lines`].
pub(crate) fn curvature_line_start(
    prepared: &Prepared,
    options: &FitScanOptions,
    budget: usize,
) -> Result<Start, Error> {
    let (target, mesh, name) = (&*prepared.target, &prepared.mesh, &prepared.name);
    let t0 = Instant::now();
    if mesh.faces.is_empty() {
        return Err(Error::input(
            name,
            "--init curvature-lines needs a mesh target (faces): a point cloud has no boundary loops to start from",
        ));
    }
    let dense = PolyMesh::new(
        mesh.positions
            .iter()
            .map(|&p| target.to_normalized(p))
            .collect(),
        Polygons::from_triangles(&mesh.faces.triangulate_fan()),
    );
    let cl_options = CurvatureLineOptions {
        max_control_points: budget,
        cancel: options.cancel.clone(),
        ..CurvatureLineOptions::default()
    };
    let (cage, tags, r) =
        curvature_line_cage(target, &dense, &cl_options).map_err(|e| match e {
            CurvatureLineError::Interrupted => Error::Interrupted,
            e => Error::input(name, format!("--init curvature-lines: {e}")),
        })?;
    let diagonal =
        subfit_mesh::bounding_box(target.points()).map_or(1.0, |(lo, hi)| norm(sub(hi, lo)));
    let time = t0.elapsed().as_secs_f64();
    let summary = CurvatureLineSummary {
        used: true,
        reason: None,
        control_points: cage.num_vertices(),
        faces: cage.faces.len(),
        corners: r.corners,
        curve_control_points: r.curve_control_points.clone(),
        curve_max_error: r.curve_max_error / diagonal,
        links: r.links,
        cuts: r.cuts,
        fans: r.fans,
        alternative: None,
    };
    let (quads, triangles, quad_fraction) = face_counts(&cage.faces);
    let loops = r.boundary_loops;
    let init = InitSummary {
        source: StartKind::CurvatureLines.name().into(),
        control_points: cage.num_vertices(),
        faces: cage.faces.len(),
        quads,
        triangles,
        quad_fraction,
        genus_target: 0,
        genus: 0,
        genus_matches: true,
        boundary_loops: BoundaryLoops {
            target: loops,
            cage: loops,
        },
        timings_s: InitTimings {
            total: time,
            ..InitTimings::default()
        },
        curvature_lines: Some(summary),
        ..InitSummary::default()
    };
    Ok(Start {
        kind: StartKind::CurvatureLines,
        cage,
        tags,
        summary: init,
        feature_segments: None,
        warnings: Vec::new(),
        seconds: 0.0,
        init_report: None,
        curvature_report: Some(r),
    })
}
