//! The typed report of one fit ([`Report`], report.json): written from the prepared input,
//! the start, the stages' report and the final measurement once the fit is done, and never
//! read back to decide anything (STYLE.md rule 12).

use subfit_fit::{FitOptions, StagesResult};

use crate::measure_fit::FinalMeasure;
use crate::options::FitScanOptions;
use crate::pipeline_report::{
    face_counts, Errors, FinalErrors, IterationSummary, LargestErrorAt, OptionsSummary, Report,
    RmsMax, StageSummary, TagCounts, TessellationSummary, Timings, TwoSidedErrors, UsdDifference,
};
use crate::prepare::Prepared;
use crate::start::Start;
use crate::tolerance::Tolerances;

/// Whether a fitted cage meets its tolerances, three ways.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Judgement {
    /// As asked: both ways unless one-sided.
    pub(crate) reached: bool,
    /// Surface → data at the stages' samples.
    pub(crate) one_sided: bool,
    /// Both ways on the final tessellation.
    pub(crate) two_sided: bool,
}

/// What [`build_report`] writes the report from.
pub(crate) struct ReportParts<'a> {
    pub(crate) prepared: &'a Prepared,
    pub(crate) start: &'a Start,
    pub(crate) fit: &'a FitOptions,
    pub(crate) tolerances: &'a Tolerances,
    pub(crate) result: &'a StagesResult,
    pub(crate) measured: &'a FinalMeasure,
    pub(crate) judgement: Judgement,
    pub(crate) usd_difference: Option<UsdDifference>,
    pub(crate) warnings: Vec<String>,
    pub(crate) options: &'a FitScanOptions,
    pub(crate) fit_time: f64,
    pub(crate) measure_time: f64,
}

/// The report of one fit (its `budget_starts` empty and its total time 0: the choice among
/// starts fills them).
pub(crate) fn build_report(p: ReportParts<'_>) -> Report {
    let (prepared, result) = (p.prepared, p.result);
    let target = &prepared.target;
    let tessellation = &p.measured.tessellation;
    let unit = target.normalization().length_to_original(1.0);
    let diagonal = prepared.diagonal;
    let last = result.report.last;
    let two = TwoSidedErrors::new(&p.measured.two_sided, diagonal, unit);
    Report {
        target: prepared.name.clone(),
        target_points: target.len(),
        target_outliers_removed: target.stats().outliers_removed,
        target_noise_level: target.stats().noise_level,
        target_point_spacing: target.stats().point_spacing,
        noise_floored_tolerance: p.tolerances.noise_floor,
        tolerance_kind: p.tolerances.kind,
        target_topology: prepared.topology,
        reoriented: prepared.reoriented.clone(),
        normalized_unit_in_original_units: unit,
        bbox_diagonal_unit_cube: diagonal,
        data_samples: match result.report.data_samples {
            subfit_measure::SampleKind::Points => "points".into(),
            subfit_measure::SampleKind::MeshArea => "mesh_area".into(),
        },
        init: p.start.summary.clone(),
        options: options_summary(&p),
        control_points: result.mesh.num_vertices(),
        control_faces: result.mesh.faces.len(),
        control_quad_fraction: face_counts(&result.mesh.faces).2,
        tags: TagCounts {
            creases: result.tags.creases().len(),
            corners: result.tags.corners().len(),
        },
        initial: (&result.report.initial).into(),
        initial_two_sided: TwoSidedErrors::new(&result.report.initial_two_sided, diagonal, unit),
        r#final: {
            let e = Errors::from(&last);
            FinalErrors {
                e_max: e.e_max,
                e_rms: e.e_rms,
                e_max_fraction_of_diagonal: e.e_max_fraction_of_diagonal,
                e_rms_fraction_of_diagonal: e.e_rms_fraction_of_diagonal,
                objective: e.objective,
                two_sided: two,
                largest_at: {
                    let at = &p.measured.largest_at;
                    LargestErrorAt {
                        surface_to_data: target.to_original(at.surface_to_data),
                        data_to_surface: target.to_original(at.data_to_surface),
                    }
                },
            }
        },
        best_stage: result.report.best_stage,
        stop: format!("{:?}", result.report.stop),
        tolerance_reached: p.judgement.reached,
        tolerance_reached_surface_to_data: p.judgement.one_sided,
        tolerance_reached_two_sided: p.judgement.two_sided,
        warnings: p.warnings,
        usd_difference: p.usd_difference,
        stages: result
            .report
            .stages
            .iter()
            .map(StageSummary::from)
            .collect(),
        iterations: result
            .report
            .stages
            .iter()
            .flat_map(|s| {
                s.fit
                    .iterations
                    .iter()
                    .map(move |r| IterationSummary::new(s.stage, r))
            })
            .collect(),
        limit_tessellation: {
            let c = tessellation.chordal;
            TessellationSummary {
                level: tessellation.level,
                vertices: tessellation.mesh.positions.len(),
                predicted_chordal_error: RmsMax {
                    max: c.max,
                    rms: c.rms,
                },
                goal: RmsMax {
                    max: 0.1 * last.e_max,
                    rms: 0.1 * last.e_rms,
                },
                goal_met: c.max <= 0.1 * last.e_max && c.rms <= 0.1 * last.e_rms,
            }
        },
        error_color_scale_unit_cube: p.options.error_scale.unwrap_or(0.0),
        budget_starts: Vec::new(),
        timings_s: Timings {
            read: prepared.read_seconds,
            preprocess: prepared.preprocess_seconds,
            init: p.start.seconds,
            fit: p.fit_time,
            measure: p.measure_time,
            output: 0.0,
            total: 0.0,
        },
    }
}

/// The options as the fit used them (the report's `options`).
fn options_summary(p: &ReportParts<'_>) -> OptionsSummary {
    let (fit, st) = (p.fit, &p.tolerances.judged);
    OptionsSummary {
        scheme: format!("{:?}", fit.scheme),
        method: format!("{:?}", fit.method).to_uppercase(),
        step: format!("{:?}", fit.step),
        lambda_start: st.lambda_start,
        lambda_end: st.lambda_end,
        lambda_factor: st.lambda_factor,
        sample_level: fit.sample_level,
        max_iterations: st.max_iterations,
        stage_iterations: st.iterations_per_stage,
        tolerance_rms: st.tolerance_rms,
        tolerance_max: (st.tolerance_max > 0.0).then_some(st.tolerance_max),
        two_sided: st.two_sided,
        max_control_points: p.options.stages.max_control_points,
        refine: st.refine,
        edge_flips: st.edge_flips,
        max_depth: st.max_depth,
        local: st.local,
        local_rings: st.local_rings,
        local_field_peak: st.local_field_peak,
        local_field_share: st.local_field_share,
        polish_power: st.polish_power,
        imls_radius: (fit.method == subfit_fit::Method::Imls)
            .then(|| subfit_fit::ImlsTerm::from_options(&p.prepared.target, fit).radius()),
        arap: fit.arap,
        facing: fit.facing,
        optimizer: match fit.optimizer {
            subfit_fit::Optimizer::GaussNewton => "GaussNewton",
            subfit_fit::Optimizer::Adam { .. } => "Adam",
            subfit_fit::Optimizer::Lbfgs { .. } => "Lbfgs",
        }
        .into(),
        chordal_levels: p.prepared.chordal.as_ref().map(|c| c.levels),
    }
}
