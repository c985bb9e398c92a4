//! One start fitted (DESIGN.md §2 "Starts → fit → choose"): [`fit_start`] takes the prepared
//! input and one initial cage, chooses the scheme, sets the tolerances the fit is judged by
//! ([`crate::tolerance`]), runs the stages (Cheng 2004 §4.4–4.6, Cheng 2007 §II-F), measures
//! the cage both ways ([`crate::measure_fit`], decision 11) and returns the [`Fitted`] cage in
//! the input's coordinates with its report and typed [`Measurement`].

use std::time::Instant;

use subfit_fit::{fit_stages, judged_with_boundary, FitOptions, StageOptions, StagesResult};
use subfit_io::usda::UsdScheme;
use subfit_mesh::PolyMesh;
use subfit_subdiv::Scheme;

use crate::choose::Measurement;
use crate::error::Error;
use crate::fitted::Fitted;
use crate::measure_fit::{measure_final, usd_difference, FinalMeasure};
use crate::options::{FitScanOptions, InitialCage, QuadLayout};
use crate::outputs::usd_scheme;
use crate::prepare::Prepared;
use crate::progress::{Notify, Step};
use crate::report_build::{build_report, Judgement, ReportParts};
use crate::start::{Start, StartKind};
use crate::start_cad::{cad_applies, tessellation_budget};
use crate::start_curvature_lines::coarse_sample_level;
use crate::tolerance::{
    edge_count, noise_floored, target_tolerances, with_sampling_margin, ToleranceKind, Tolerances,
    NOISE_FLOOR_FACTOR,
};

/// Fits `start` to `prepared` under `options` within `budget` control points (see the module
/// docs), telling `notify` the steps, stages and warnings. Errors: a failed fit, a failed
/// measurement, [`Error::Interrupted`].
pub(crate) fn fit_start(
    prepared: &Prepared,
    start: Start,
    options: &FitScanOptions,
    budget: usize,
    notify: &mut Notify<'_>,
) -> Result<Fitted, Error> {
    let mut warnings = prepared.warnings.clone();
    for w in &start.warnings {
        notify.warn(&mut warnings, w.clone());
    }
    let fit = fit_options(prepared, &start, options);
    let tolerances = tolerances(prepared, &start, &fit, options, budget);
    if let Some(t) = tolerances.noise_floor {
        let stats = prepared.target.stats();
        let msg = format!(
            "{}: a noisy scan (noise level {:.2e}, {:.2} × the point spacing): the RMS tolerance is judged as √(tol² + ({NOISE_FLOOR_FACTOR} σ)²) = {t:.2e} unit cube, since the data's own noise keeps data → surface near σ",
            prepared.name,
            stats.noise_level,
            stats.noise_level / stats.point_spacing,
        );
        notify.warn(&mut warnings, msg);
    }

    notify.step(Step::Fit);
    let t_fit = Instant::now();
    // The target's maxima are met by the stages with a margin: the final tessellation is
    // finer than the stages' samples and finds higher peaks.
    let working = match tolerances.kind {
        Some(_) => with_sampling_margin(&tolerances.stages),
        None => tolerances.stages.clone(),
    };
    let mut on_event = |e: subfit_fit::StageEvent<'_>| notify.stage_event(e);
    let result = fit_stages(
        prepared.fit_target(),
        &start.cage,
        &fit,
        &working,
        Some(&mut on_event),
    )
    .map_err(|e| match e {
        subfit_fit::FitError::Interrupted => Error::Interrupted,
        e => Error::Fit {
            name: prepared.name.clone(),
            source: e,
        },
    })?;
    let fit_time = t_fit.elapsed().as_secs_f64();

    options.cancel.check().map_err(|_| Error::Interrupted)?;
    let t_measure = Instant::now();
    let measured = measure_final(
        prepared.fit_target(),
        &prepared.file_vertices,
        &result,
        &fit,
        options.stages.data_samples,
    )?;
    let usd = quad_triangle_difference(prepared, &result, &fit, &measured, notify, &mut warnings)?;
    let measure_time = t_measure.elapsed().as_secs_f64();
    let judgement = judge(&result, &measured, &tolerances.stages);
    let report = build_report(ReportParts {
        prepared,
        start: &start,
        fit: &fit,
        tolerances: &tolerances,
        result: &result,
        measured: &measured,
        judgement,
        usd_difference: usd,
        warnings,
        options,
        fit_time,
        measure_time,
    });
    let measurement = Measurement {
        reached: judgement.reached,
        control_points: result.mesh.num_vertices(),
        rms: measured.two_sided.rms(),
        max: measured.two_sided.max(),
    };
    Ok(fitted(
        prepared,
        result,
        fit,
        measured,
        report,
        measurement,
        options,
    ))
}

/// The per-iteration options of a fit of `start`: the scheme (asked, or Loop / quad-triangle /
/// Catmull-Clark by the cage and the target), the cage's tags and feature curves, the run's
/// cancel token, and a coarse sample level raised for a curvature-line cage.
fn fit_options(prepared: &Prepared, start: &Start, options: &FitScanOptions) -> FitOptions {
    let curvature_lines = start.kind == StartKind::CurvatureLines;
    let scheme = options.scheme.unwrap_or(if curvature_lines {
        // Lavoué's cages are quad/triangle.
        Scheme::QuadTriangle
    } else if start.cage.faces.is_triangles() {
        // Open mesh targets take the quad/triangle scheme (Lavoué et al.), whose quads come
        // from the start (the curvature-line cage); on the triangles of an automatic cage
        // it is Loop, refined as Loop ([`subfit_fit::TriangleSplit::for_cage`]).
        if prepared.is_open_mesh() && !matches!(options.init, InitialCage::Given { .. }) {
            Scheme::QuadTriangle
        } else {
            Scheme::Loop
        }
    } else {
        Scheme::CatmullClark
    });
    FitOptions {
        scheme,
        tags: start.tags.clone(),
        feature_segments: start
            .feature_segments
            .clone()
            .or_else(|| options.fit.feature_segments.clone()),
        cancel: options.cancel.clone(),
        sample_level: if curvature_lines {
            coarse_sample_level(start.cage.faces.len(), options.fit.sample_level)
        } else {
            options.fit.sample_level
        },
        ..options.fit.clone()
    }
}

/// The tolerances of a fit of `start` (see [`Tolerances`]): the options', or the target's
/// defaults by the kind of target its cage makes it, within `budget` control points.
fn tolerances(
    prepared: &Prepared,
    start: &Start,
    fit: &FitOptions,
    options: &FitScanOptions,
    budget: usize,
) -> Tolerances {
    let stats = prepared.target.stats();
    // A CAD tessellation is judged as one whichever start fitted it (crate::start_cad).
    let tessellation = cad_applies(prepared, options);
    let kind = options.target_tolerances.then(|| {
        if tessellation {
            ToleranceKind::CadPart
        } else {
            ToleranceKind::of(stats, &fit.tags, edge_count(&start.cage.faces))
        }
    });
    let mut judged = match kind {
        Some(kind) => target_tolerances(&options.stages, kind, prepared.diagonal),
        None => options.stages.clone(),
    };
    // An all-quad cage keeps its connectivity: local refinement and edge flips would bring
    // triangles back (no template closes a quad split on one edge with quads).
    if options.quads == QuadLayout::Only {
        judged.refine = false;
        judged.edge_flips = false;
    }
    // A tessellation's cage never grows past the tessellation's (distinct) vertices.
    judged.max_control_points = if tessellation {
        tessellation_budget(prepared, options, budget)
    } else {
        budget
    };
    let (stages, noise_floor) = noise_floored(&judged, stats);
    Tolerances {
        kind,
        judged,
        stages,
        noise_floor,
    }
}

/// The USD difference of a quad/triangle cage (with its warning), `None` for other schemes.
fn quad_triangle_difference(
    prepared: &Prepared,
    result: &StagesResult,
    fit: &FitOptions,
    measured: &FinalMeasure,
    notify: &mut Notify<'_>,
    warnings: &mut Vec<String>,
) -> Result<Option<crate::pipeline_report::UsdDifference>, Error> {
    if usd_scheme(fit.scheme, &result.mesh.faces) != UsdScheme::QuadTriangle {
        return Ok(None);
    }
    let unit = prepared.target.normalization().length_to_original(1.0);
    let d = usd_difference(
        &result.mesh,
        &result.tags,
        &fit.subdivision(),
        measured.tessellation.level,
        prepared.diagonal,
        unit,
    )?;
    let msg = format!(
        "USD has no quad/triangle scheme: control.usda declares Catmull-Clark with the smooth triangle rule (subfit:scheme = \"quadTriangle\" records the real one); that surface lies within {:.3}% of the diagonal of the fitted one (RMS {:.3}%, max {:.3e} input units)",
        100.0 * d.max_fraction_of_diagonal,
        100.0 * d.rms_fraction_of_diagonal,
        d.max_original_units
    );
    notify.warn(warnings, msg);
    Ok(Some(d))
}

/// Whether the cage meets `stages`' tolerances: as asked (both ways unless one-sided), one
/// way (surface → data at the stages' samples) and two ways (on the final tessellation).
fn judge(result: &StagesResult, measured: &FinalMeasure, stages: &StageOptions) -> Judgement {
    let last = result.report.last;
    let judged_two = judged_with_boundary(&measured.two_sided, measured.rim(), stages);
    Judgement {
        reached: stages.met(&last, &judged_two),
        one_sided: stages.reached(&last),
        two_sided: judged_two.within(stages.tolerance_rms, stages.tolerance_max),
    }
}

/// The [`Fitted`] of a fit: the cage mapped back to the input's coordinates.
fn fitted(
    prepared: &Prepared,
    result: StagesResult,
    fit: FitOptions,
    measured: FinalMeasure,
    report: crate::pipeline_report::Report,
    measurement: Measurement,
    options: &FitScanOptions,
) -> Fitted {
    let target = &prepared.target;
    let cage = PolyMesh::new(
        result
            .mesh
            .positions
            .iter()
            .map(|&p| target.to_original(p))
            .collect(),
        result.mesh.faces.clone(),
    );
    Fitted {
        cage,
        tags: result.tags.clone(),
        scheme: fit.scheme,
        report,
        measurement,
        target: prepared.target.clone(),
        normalized: result.mesh.clone(),
        stages: result,
        fit,
        limit: measured.tessellation.mesh,
        local_error: measured.local,
        data_error: measured.to_surface,
        cancel: options.cancel.clone(),
    }
}
