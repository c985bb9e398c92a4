//! The initial control mesh of [`crate::fit_scan`] (DESIGN.md §3.6), one of three:
//!
//! * **given** ([`InitialCage::Given`], `--init FILE`): checked against the target's topology
//!   and the budget, optionally paired into quads;
//! * **QEM** (`--init qem`): [`subfit_init::initial_control_mesh`], the simplification of a mesh
//!   target or the trimmed IMLS contour of a point cloud;
//! * **curvature lines** (`--init curvature-lines`): [`subfit_init::curvature_lines`], the
//!   cage of Lavoué et al. 2007 §4 whose vertices are the control points of the boundary
//!   curves, joined along the target's lines of curvature, fitted with the quad/triangle scheme
//!   unless another is asked. Open mesh targets of genus 0 only.
//!
//! `--init auto` (the default) fits from QEM, and for an open mesh target of genus 0 with at
//! most [`BOTH_INITS_POINTS`] points (CAD-like patches, not scans) from the curvature lines as
//! well, and keeps the better fit ([`better_start`]: within the tolerances with fewer control
//! points). Which start a cage came from cannot be told from the cages before they are fitted:
//! the curvature-line cage of a saddle (12 control points) is 6 % of the diagonal off after 30
//! iterations at fixed connectivity, 22 times the RMS tolerance, yet the stages' refinement
//! takes it to the tolerance with fewer points than QEM's 169 when the tolerance is loose. The
//! report's `init.source` says which start was kept, `init.curvature_lines` what the other
//! gave.

use std::time::Instant;

use subfit_init::curvature_lines::{curvature_line_cage, CurvatureLineError, CurvatureLineOptions};
use subfit_init::{pair_triangles, InitOptions, InitReport};
use subfit_mesh::{PolyMesh, Polygons, Tags};
use subfit_subdiv::Scheme;
use subfit_target::{FeatureOptions, Target};

use subfit_mesh::vec3::{norm, sub};

use crate::budget_starts::{better, fit_best_start, reborrow};
use crate::error::Error;
use crate::pipeline_report::{
    face_counts, BoundaryLoops, CurvatureLineSummary, FeatureSummary, InitAlternative, InitSummary,
    InitTimings, Report, Topology,
};
use crate::scan::topology;
use crate::{FitScanOptions, Fitted, InitialCage, Input, Progress};

/// Under `--init auto`, open mesh targets of genus 0 with at most this many points are fitted
/// from both initializers (see the module docs): CAD-like patches are small; a scan is larger,
/// and its curvature-line cage (vertices on its boundary only) is no start for it (the camel
/// head, 11k points: 704 control points outside the tolerances where QEM met them with 706;
/// fitting both took 12.7 s instead of 3.0 s).
pub const BOTH_INITS_POINTS: usize = 10_000;

/// A cage given by the caller: its topology must match the target's and it must fit the
/// budget; paired into quads when asked.
#[allow(clippy::too_many_arguments)]
pub(crate) fn given_cage(
    target: &Target,
    target_topology: Option<Topology>,
    name: &str,
    c: &PolyMesh,
    tags: &Tags,
    cname: &str,
    budget: usize,
    options: &FitScanOptions,
    init_options: &InitOptions,
) -> Result<(PolyMesh, Tags, InitSummary), Error> {
    let topo = topology(c).map_err(|e| Error::input(cname, e))?;
    if let Some(t) = target_topology {
        if t != topo {
            return Err(Error::input(
                    cname,
                    format!(
                        "the control mesh has genus {} and {} boundary loop(s), the target {name} has genus {} and {} — their topologies must match",
                        topo.genus, topo.boundary_loops, t.genus, t.boundary_loops
                    ),
                ));
        }
    }
    if c.num_vertices() > budget {
        return Err(Error::Budget(format!(
                "{cname}: the initial control mesh has {} control points, more than the budget of {budget}",
                c.num_vertices()
            )));
    }
    let mut normalized = PolyMesh::new(
        c.positions
            .iter()
            .map(|&p| target.to_normalized(p))
            .collect(),
        c.faces.clone(),
    );
    let t_pair = Instant::now();
    let paired = options.quad_dominant == Some(true);
    if paired {
        let (m, _) = pair_triangles(&normalized, tags, Some(target), &init_options.pairing)
            .map_err(|e| Error::input(cname, e))?;
        normalized = m;
    }
    let (quads, triangles, quad_fraction) = face_counts(&normalized.faces);
    let summary = InitSummary {
        source: "File".into(),
        file: Some(cname.to_string()),
        requested_control_points: None,
        open_cloud_control_points: None,
        specks: 0,
        one_sided_refined: false,
        budget_start: None,
        control_points: c.num_vertices(),
        faces: normalized.faces.len(),
        quads,
        triangles,
        quad_fraction,
        paired,
        genus_target: target_topology.map_or(topo.genus, |t| t.genus),
        genus: topo.genus,
        genus_matches: target_topology.is_none_or(|t| t.genus == topo.genus),
        boundary_loops: BoundaryLoops {
            target: target_topology.map_or(topo.boundary_loops, |t| t.boundary_loops),
            cage: topo.boundary_loops,
        },
        cloud_open: false,
        contour_faces_trimmed: 0,
        smoothed: false,
        features: None,
        timings_s: InitTimings {
            pair: t_pair.elapsed().as_secs_f64(),
            total: t_pair.elapsed().as_secs_f64(),
            ..InitTimings::default()
        },
        curvature_lines: None,
        cad: None,
    };
    Ok((normalized, tags.clone(), summary))
}

pub(crate) fn init_summary(
    r: &InitReport,
    requested: usize,
    m: &PolyMesh,
    features: Option<&FeatureOptions>,
) -> InitSummary {
    let (quads, triangles, quad_fraction) = face_counts(&m.faces);
    InitSummary {
        source: format!("{:?}", r.source),
        file: None,
        requested_control_points: Some(requested),
        open_cloud_control_points: r.open_cloud_control_points,
        specks: r.specks,
        one_sided_refined: r.one_sided_refined,
        budget_start: None,
        control_points: m.num_vertices(),
        faces: m.faces.len(),
        quads,
        triangles,
        quad_fraction,
        paired: r.pairing.is_some(),
        genus_target: r.genus_target,
        genus: r.genus_after,
        genus_matches: r.genus_matches,
        boundary_loops: BoundaryLoops {
            target: r.boundary_loops.0,
            cage: r.boundary_loops.1,
        },
        cloud_open: r.cloud_open(),
        contour_faces_trimmed: r.trim.as_ref().map_or(0, |t| t.faces_trimmed),
        smoothed: r.simplify.smoothed,
        features: r.features.zip(features).map(|(f, o)| FeatureSummary {
            angle_deg: o.angle_deg,
            edges: f.edges,
            curves: f.curves,
            corners: f.corners,
            darts: f.darts,
            concave_sectors: r.concave.creases,
            concave_points: r.concave.inserted,
        }),
        timings_s: InitTimings {
            contour: r.timings.contour.as_secs_f64(),
            simplify: r.timings.simplify.as_secs_f64(),
            pair: r.timings.pair.as_secs_f64(),
            total: r.timings.total.as_secs_f64(),
        },
        curvature_lines: None,
        cad: None,
    }
}

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

/// The curvature-line cage of the mesh target `mesh` (original coordinates) in normalized
/// units, its corner tags and its summary; an input error saying why when it cannot be built.
/// Cost: see [`subfit_init::curvature_lines`].
pub(crate) fn curvature_line_start(
    target: &Target,
    mesh: &PolyMesh,
    name: &str,
    options: &FitScanOptions,
) -> Result<(PolyMesh, Tags, InitSummary), Error> {
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
        max_control_points: options.stages.max_control_points,
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
        source: "CurvatureLines".into(),
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
    Ok((cage, tags, init))
}

/// [`crate::fit_scan`]'s work under `--init auto`: the QEM fit ([`fit_best_start`]), and for
/// an open mesh target of genus 0 with at most [`BOTH_INITS_POINTS`] points (no count asked,
/// not Loop, not as points) the curvature-line fit too, the better kept ([`better_start`]);
/// `init.curvature_lines` of the report kept says what the other gave.
pub(crate) fn fit_best_init(
    input: Input,
    options: &FitScanOptions,
    mut progress: Option<&mut dyn FnMut(Progress<'_>)>,
) -> Result<Fitted, Error> {
    let small = match &input {
        Input::File(_) => true,
        Input::Mesh { mesh, .. } => {
            !mesh.faces.is_empty() && mesh.positions.len() <= BOTH_INITS_POINTS
        }
    };
    let both = matches!(options.init, InitialCage::Auto)
        && options.control_points.is_none()
        && options.scheme != Some(Scheme::Loop)
        && !options.as_points
        && small;
    let again = both.then(|| input.clone());
    let t = Instant::now();
    let mut first = fit_best_start(input, options, reborrow(&mut progress))?;
    let open_disc = first
        .report
        .target_topology
        .is_some_and(|t| t.genus == 0 && t.boundary_loops > 0);
    let Some(again) =
        again.filter(|_| open_disc && first.report.target_points <= BOTH_INITS_POINTS)
    else {
        return Ok(first);
    };
    let first_time = t.elapsed().as_secs_f64();
    let t = Instant::now();
    // When QEM met the tolerances, the curvature-line start can only win with fewer control
    // points: it stops at one fewer (a scan's boundary-only cage would otherwise refine far).
    let mut o = FitScanOptions {
        init: InitialCage::CurvatureLines,
        ..options.clone()
    };
    if first.report.tolerance_reached {
        o.stages.max_control_points = o
            .stages
            .max_control_points
            .min(first.report.control_points.saturating_sub(1));
    }
    let mut second = match fit_best_start(again, &o, progress) {
        Ok(mut s) => {
            s.report.options.max_control_points = options.stages.max_control_points;
            s
        }
        Err(Error::Interrupted) => return Err(Error::Interrupted),
        Err(e) => {
            first.report.init.curvature_lines = Some(CurvatureLineSummary {
                used: false,
                reason: Some(e.to_string()),
                ..CurvatureLineSummary::default()
            });
            return Ok(first);
        }
    };
    let second_time = t.elapsed().as_secs_f64();
    let brief = |f: &Fitted| InitAlternative {
        initial_control_points: f.report.init.control_points,
        control_points: f.report.control_points,
        rms_fraction_of_diagonal: f.report.r#final.two_sided.e_rms_fraction_of_diagonal,
        max_fraction_of_diagonal: f.report.r#final.two_sided.e_max_fraction_of_diagonal,
        tolerance_reached: f.report.tolerance_reached,
    };
    let (qem, cl) = (brief(&first), brief(&second));
    let total = first_time + second_time;
    if better_start(&second.report, &first.report) {
        if let Some(s) = second.report.init.curvature_lines.as_mut() {
            s.alternative = Some(qem);
        }
        second.report.timings_s.total = total;
        Ok(second)
    } else {
        let reason = format!(
            "the QEM start gave {} control points ({}), the curvature-line start {} ({})",
            qem.control_points,
            reached(qem.tolerance_reached),
            cl.control_points,
            reached(cl.tolerance_reached)
        );
        let mut summary = second
            .report
            .init
            .curvature_lines
            .take()
            .unwrap_or_default();
        summary.used = false;
        summary.reason = Some(reason);
        summary.alternative = Some(cl);
        first.report.init.curvature_lines = Some(summary);
        first.report.timings_s.total = total;
        Ok(first)
    }
}

fn reached(r: bool) -> &'static str {
    if r {
        "within the tolerances"
    } else {
        "outside the tolerances"
    }
}

/// Whether the fit reported in `a` is better than `b`'s: one that meets the tolerances beats
/// one that does not; of two that do, the one with fewer control points (the point of a
/// compact cage; equal counts go to [`better`]); of two that do not, [`better`].
pub(crate) fn better_start(a: &Report, b: &Report) -> bool {
    if a.tolerance_reached && b.tolerance_reached && a.control_points != b.control_points {
        return a.control_points < b.control_points;
    }
    better(a, b)
}
