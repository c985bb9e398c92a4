//! The QEM start (DESIGN.md §3.6, Cheng et al. 2007 §II-A): [`subfit_init::initial_control_mesh`]
//! — the topology-preserving simplification of a mesh target, or the trimmed IMLS contour of a
//! point cloud, simplified — at the default size from the target's point count, the count
//! asked, or a fraction of a budget that caps a quad scheme ([`crate::starts::BUDGET_STARTS`]).
//! A CAD part's features are detected again from a smaller angle
//! ([`crate::tolerance::CAD_FEATURE_ANGLE`]).

use std::sync::Arc;

use subfit_init::{default_control_points, initial_control_mesh, InitOptions};
use subfit_subdiv::Scheme;

use crate::error::Error;
use crate::options::{FitScanOptions, QuadLayout};
use crate::pipeline_report::InitSummary;
use crate::prepare::Prepared;
use crate::start::{Start, StartKind};
use crate::start_given::init_summary;
use crate::tolerance::{edge_count, ToleranceKind, SCAN_RMS};

/// The QEM start of `prepared` under `options` within `budget` control points; a quad scheme
/// whose default size exceeds the budget starts at `fraction` of it. Errors: a count asked
/// above the budget, a target whose topology needs more points than the budget, a failed
/// simplification or contour, [`Error::Interrupted`].
pub(crate) fn qem_start(
    prepared: &Prepared,
    options: &FitScanOptions,
    budget: usize,
    fraction: f64,
    cross_field: bool,
) -> Result<Start, Error> {
    let (target, name) = (&*prepared.target, &prepared.name);
    let mut init_options = prepared.init_options(options);
    // The layout of a quad cage: along a cross field, or the simplification paired (and with
    // `--quads only` split into quads).
    let only = options.quads == QuadLayout::Only;
    init_options.cross_field = (cross_field && init_options.quad_dominant).then(|| {
        subfit_init::cross_field::QuadCageOptions {
            quads_only: only,
            ..Default::default()
        }
    });
    init_options.split_into_quads = only && init_options.quad_dominant;
    let mut budget_start = None;
    let n = match options.control_points {
        Some(n) if n > budget => {
            return Err(Error::Budget(format!(
                "{n} initial control points asked for, more than the budget of {budget} (--max-control-points)"
            )))
        }
        Some(n) => n,
        // An all-quad cage is not refined: a budget given is its size.
        None if options.quads == QuadLayout::Only => {
            let given = budget < subfit_fit::StageOptions::default().max_control_points;
            if given {
                budget
            } else {
                default_control_points(target.len()).min(budget)
            }
        }
        None => {
            let (n, f) = start_control_points(
                default_control_points(target.len()),
                budget,
                options.scheme,
                fraction,
            );
            budget_start = f;
            n
        }
    };
    let dense = (!prepared.mesh.faces.is_empty()).then_some(&prepared.mesh);
    // The default start of a cloud found open is larger (subfit_init::OPEN_CLOUD_SCALE)
    // unless its noise is half a scan's RMS tolerance or more: the extra points would
    // fit noise (a view of the bunny with range noise 2e-3: 642 → 1,303 control points
    // for a surface 5 % closer to the true mesh). A count asked for, or a start the
    // budget set, is kept.
    let quiet = target.stats().noise_level < 0.5 * SCAN_RMS * prepared.diagonal;
    if options.control_points.is_none() && budget_start.is_none() && quiet {
        init_options.open_cloud_scale = subfit_init::OPEN_CLOUD_SCALE;
    }
    // Concave corners may add points within the budget, not to a count asked for.
    init_options.max_control_points = if options.control_points.is_some() {
        n
    } else {
        budget
    };
    let build = |init_options: &InitOptions| {
        initial_control_mesh(target, dense, n, init_options).map_err(|e| match e {
            subfit_init::InitError::TooFewForTopology { .. } if options.control_points.is_none() => {
                Error::Budget(format!("{name}: the budget of {budget} control points is too small for this target: {e}"))
            }
            subfit_init::InitError::Interrupted => Error::Interrupted,
            e => Error::Init { name: name.clone(), source: e },
        })
    };
    let (mut m, mut r) = build(&init_options)?;
    // A CAD part: its features again from a smaller angle (the facets of a coarsely
    // tessellated fillet meet at kinks the default angle leaves to the smooth surface).
    let cad_angle = options
        .cad_feature_angle
        .filter(|_| options.target_tolerances)
        .filter(|&a| {
            init_options
                .features
                .as_ref()
                .is_some_and(|f| f.angle_deg > a)
        });
    if let Some(angle) = cad_angle {
        let kind = ToleranceKind::of(target.stats(), &r.tags, edge_count(&m.faces));
        if kind == ToleranceKind::CadPart {
            let mut again = init_options.clone();
            if let Some(f) = again.features.as_mut() {
                f.angle_deg = angle;
            }
            // A cage the smaller angle cannot give within the budget (too many
            // feature curves for it) leaves the first one.
            match build(&again) {
                Ok(second) if second.0.num_vertices() <= budget => {
                    (m, r) = second;
                    init_options = again;
                }
                Err(Error::Interrupted) => return Err(Error::Interrupted),
                _ => {}
            }
        }
    }
    if m.num_vertices() > budget {
        return Err(Error::Budget(format!(
            "{name}: the initial control mesh keeps {} control points (no legal simplification below it for this topology), more than the budget of {budget}",
            m.num_vertices()
        )));
    }
    let mut warnings = Vec::new();
    if r.simplify.smoothed {
        warnings.push("the mesh is too noisy to simplify as it is (crumpled triangles): the initial cage comes from a smoothed copy".into());
    }
    if !r.genus_matches {
        warnings.push(format!(
            "the initial control mesh has genus {}, the target {}",
            r.genus_after, r.genus_target
        ));
    }
    let summary = InitSummary {
        budget_start,
        ..init_summary(&r, n, &m, init_options.features.as_ref())
    };
    let feature_segments =
        (!r.feature_segments.is_empty()).then(|| Arc::new(std::mem::take(&mut r.feature_segments)));
    let tags = std::mem::take(&mut r.tags);
    Ok(Start {
        kind: StartKind::Qem {
            budget_fraction: budget_start,
            cross_field,
        },
        cage: m,
        tags,
        summary,
        feature_segments,
        warnings,
        seconds: 0.0,
        init_report: Some(r),
        curvature_report: None,
    })
}

/// The automatic initial size: `default` (from the target's size), capped by `budget`; a quad
/// scheme capped by the budget starts at `start` of it (the fraction returned too).
pub(crate) fn start_control_points(
    default: usize,
    budget: usize,
    scheme: Option<Scheme>,
    start: f64,
) -> (usize, Option<f64>) {
    let quads = matches!(scheme, Some(Scheme::CatmullClark | Scheme::QuadTriangle));
    if quads && default >= budget {
        let n = ((start * budget as f64).round() as usize).clamp(4, budget);
        (n, Some(start))
    } else {
        (default.min(budget), None)
    }
}
