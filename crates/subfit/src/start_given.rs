//! The given start (`--init FILE`, [`crate::InitialCage::Given`]): a cage the caller made,
//! checked against the target's topology (DESIGN.md §3.6) and the budget, optionally paired
//! into quads ([`subfit_init::pair_triangles`]); and the report's summary of a built cage.

use std::time::Instant;

use subfit_init::{pair_triangles, InitReport};
use subfit_mesh::{PolyMesh, Tags};
use subfit_target::FeatureOptions;

use crate::error::Error;
use crate::options::FitScanOptions;
use crate::pipeline_report::{
    face_counts, BoundaryLoops, CrossFieldSummary, FeatureSummary, InitSummary, InitTimings,
};
use crate::prepare::{topology, Prepared};
use crate::start::{Start, StartKind};

/// A cage given by the caller: its topology must match the target's and it must fit the
/// budget; paired into quads when asked.
pub(crate) fn given_start(
    prepared: &Prepared,
    c: &PolyMesh,
    tags: &Tags,
    cname: &str,
    budget: usize,
    options: &FitScanOptions,
) -> Result<Start, Error> {
    let (target, target_topology, name) = (&*prepared.target, prepared.topology, &prepared.name);
    let init_options = prepared.init_options(options);
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
        source: StartKind::Given.name().into(),
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
        cross_field: None,
    };
    Ok(Start {
        kind: StartKind::Given,
        cage: normalized,
        tags: tags.clone(),
        summary,
        feature_segments: None,
        warnings: Vec::new(),
        seconds: 0.0,
        init_report: None,
        curvature_report: None,
    })
}

/// The report's `init` for a cage [`subfit_init`] built from `requested` control points.
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
        cross_field: cross_field_summary(r),
    }
}

/// What the cross-field cage of `r` was, when it was asked.
fn cross_field_summary(r: &InitReport) -> Option<CrossFieldSummary> {
    match (&r.cross_field, &r.cross_field_failure) {
        (Some(q), _) => Some(CrossFieldSummary {
            used: true,
            failure: None,
            split: q.split,
            irregular: q.irregular,
            valences: q.valences.clone(),
            working_vertices: q.working_vertices,
            seconds: q.seconds,
        }),
        (None, Some(why)) => Some(CrossFieldSummary {
            failure: Some(why.clone()),
            ..CrossFieldSummary::default()
        }),
        (None, None) => None,
    }
}
