//! `subfit fit TARGET [-o DIR]`: translate the flags into [`subfit::FitScanOptions`], run
//! [`subfit::fit_scan`] with progress on stderr, and write its outputs ([`subfit::OUTPUTS`])
//! into a staging directory moved into place together (an interruption leaves none).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use subfit::fit::{FitOptions, Method, Optimizer, StageOptions, StepControl};
use subfit::init::InitOptions;
use subfit::subdiv::Scheme;
use subfit::{
    fit_scan, FitScanOptions, Fitted, InitialCage, Input, OutputOptions, Progress, Step, OUTPUTS,
};

use crate::cli::{quad_dominant_flag, FitArgs, MethodArg, OptimizerArg, SchemeArg, StepArg};

pub fn run(a: FitArgs) -> anyhow::Result<ExitCode> {
    let quiet = a.report.quiet;
    if quiet {
        crate::progress::set_hidden();
    }
    let fitted = execute(&a)?;
    let closing = fitted.closing_summary(&a.output);
    if a.report.json {
        let json = serde_json::to_string_pretty(&closing)?;
        out!("{json}");
    } else if !quiet {
        eprintln!("subfit: {}", init_line(&fitted.report.init));
        if let Some(kind) = fitted.report.tolerance_kind {
            eprintln!(
                "subfit: {} (--tolerance / --max-error set others, in unit-cube units)",
                kind.describe()
            );
        }
        out!("{}", fitted.summary());
        out!("{closing}");
        out!("look at {}", a.output.join("report.html").display());
    }
    if !quiet {
        blender_hint(&fitted);
    }
    Ok(if fitted.reached() {
        ExitCode::SUCCESS
    } else {
        if !quiet {
            eprintln!(
                "subfit: the requested tolerance was not reached {}(outputs written)",
                if a.one_sided { "" } else { "both ways " }
            );
        }
        ExitCode::from(1)
    })
}

/// The library's options for the flags of `subfit fit`.
pub fn options(a: &FitArgs) -> anyhow::Result<FitScanOptions> {
    let init = if a.init == "auto" {
        InitialCage::Auto
    } else if a.init == "qem" {
        InitialCage::Qem
    } else if a.init == "curvature-lines" {
        InitialCage::CurvatureLines
    } else {
        let path = PathBuf::from(&a.init);
        let (mesh, _) = crate::progress::load(&path)?;
        if mesh.faces.is_empty() {
            anyhow::bail!(
                "{}: has no faces; an initial control mesh is needed",
                path.display()
            );
        }
        // Creases and corners come with an OBJ cage as OpenSubdiv `t` lines.
        let tags = subfit::io::read_tags_file(&path, mesh.num_vertices())?;
        InitialCage::Given {
            mesh,
            tags,
            name: path.display().to_string(),
        }
    };
    let (method, step) = (method_of(a.method), step_of(a.step));
    let defaults = FitScanOptions::default();
    let mut o = FitScanOptions {
        init,
        control_points: a.control_points.map(|n| n as usize),
        as_points: a.as_points,
        scheme: scheme_of(a.scheme),
        quad_dominant: quad_dominant_flag(a.quad_dominant, a.no_quad_dominant),
        quads: a.quads.layout(),
        fit: FitOptions {
            sample_level: a.sample_level as usize,
            method,
            step,
            optimizer: match a.optimizer {
                OptimizerArg::GaussNewton => Optimizer::GaussNewton,
                OptimizerArg::Adam => Optimizer::Adam {
                    learning_rate: a.learning_rate,
                },
                OptimizerArg::Lbfgs => Optimizer::Lbfgs { memory: 7 },
            },
            coverage: a.coverage,
            facing: !a.no_facing,
            imls_radius: a.imls_radius,
            arap: a.arap,
            ..defaults.fit.clone()
        },
        stages: StageOptions {
            iterations_per_stage: a.stage_iterations as usize,
            max_iterations: a.max_iterations as usize,
            max_depth: a.max_depth,
            local: a.local,
            local_rings: a.local_rings as usize,
            two_sided: !a.one_sided,
            polish_power: a.polish_power,
            local_field_peak: a.local_field_peak,
            local_field_share: a.local_field_share,
            ..StageOptions::default()
        },
        error_scale: a.error_scale,
        chordal: a.chordal,
        init_options: InitOptions {
            features: a.features.options(),
            semi_sharp: a.features.semi_sharp,
            cloud_features: a.features.cloud_features,
            contour: subfit::init::ContourOptions {
                refine_levels: a.contour_refine.map_or(0, usize::from),
                ..subfit::init::ContourOptions::default()
            },
            // A level given is the level used, one-sided or not.
            one_sided_refine: a
                .contour_refine
                .map_or(defaults.init_options.one_sided_refine, usize::from),
            ..defaults.init_options.clone()
        },
        // An angle given is the angle used.
        cad_feature_angle: defaults
            .cad_feature_angle
            .filter(|_| a.features.feature_angle.is_none()),
        ..defaults
    };
    o.set_limits(
        a.tolerance,
        a.max_error,
        a.max_control_points.map(|n| n as usize),
    );
    o.set_lambda(a.lambda, a.lambda_end);
    o.set_refinement(!a.no_refine, !a.no_flips);
    Ok(o)
}

/// Runs the pipeline for `a` and writes its outputs; shared by `fit`, `demo` and `bench fit`.
pub fn execute(a: &FitArgs) -> anyhow::Result<Fitted> {
    if a.output.exists() && !a.output.is_dir() {
        anyhow::bail!("{}: exists and is not a directory", a.output.display());
    }
    let options = options(a)?;
    let (mesh, _) = crate::progress::load(&a.target)?;
    let input = Input::Mesh {
        mesh,
        name: a.target.display().to_string(),
    };
    let mut fitted = run_with_progress(input, &options, a.max_iterations as u64)?;
    let output = OutputOptions {
        limit_quads: a.report.limit_quads,
    };
    write_outputs(&mut fitted, &a.output, &output)?;
    Ok(fitted)
}

/// [`fit_scan`] with a spinner per step and a bar over the iterations; warnings on stderr.
pub fn run_with_progress(
    input: Input,
    options: &FitScanOptions,
    max_iterations: u64,
) -> anyhow::Result<Fitted> {
    let options = FitScanOptions {
        cancel: crate::interrupt::token(),
        ..options.clone()
    };
    let options = &options;
    let mut spinner: Option<indicatif::ProgressBar> = None;
    let mut bar: Option<indicatif::ProgressBar> = None;
    let mut on = |p: Progress<'_>| match p {
        Progress::Step(s) => {
            if let Some(sp) = spinner.take() {
                sp.finish_and_clear();
            }
            match s {
                Step::Read => {}
                Step::Analyse => {
                    spinner = Some(crate::progress::spinner("analysing the target"));
                }
                Step::Init => {
                    spinner = Some(crate::progress::spinner(
                        "building the initial control mesh",
                    ));
                }
                Step::Fit => bar = Some(crate::progress::bar(max_iterations, "fitting")),
            }
        }
        Progress::Iteration { stage, row } => {
            if let Some(b) = &bar {
                b.set_message(format!(
                    "stage {stage}: E_rms {:.3e}, E_max {:.3e}",
                    row.errors.e_rms, row.errors.e_max
                ));
                b.inc(1);
            }
        }
        Progress::Stage(_) => {}
        Progress::Warning(w) => eprintln!("subfit: warning: {w}"),
    };
    let out = fit_scan(input, options, Some(&mut on));
    if let Some(sp) = spinner.take() {
        sp.finish_and_clear();
    }
    if let Some(b) = bar.take() {
        b.finish_and_clear();
    }
    Ok(out?)
}

/// The initial cage in one line: control points, faces, quads and triangles.
pub fn init_line(i: &subfit::pipeline_report::InitSummary) -> String {
    format!(
        "initial cage ({}): {} control points, {} faces: {} quads, {} triangles ({:.0}% quads{}){}",
        i.source,
        i.control_points,
        i.faces,
        i.quads,
        i.triangles,
        100.0 * i.quad_fraction,
        match &i.cross_field {
            Some(c) if c.used =>
                format!(", along a cross field: {} irregular vertices", c.irregular),
            _ if i.paired => ", triangles paired".to_string(),
            _ => String::new(),
        },
        if i.cloud_open {
            format!(
                "; open cloud: {} contour faces trimmed{}, {} boundary loop(s){}{}",
                i.contour_faces_trimmed,
                if i.one_sided_refined {
                    " (one-sided: contoured finer)"
                } else {
                    ""
                },
                i.boundary_loops.cage,
                match (i.open_cloud_control_points, i.requested_control_points) {
                    (Some(o), Some(r)) => format!(", started from {o} control points, not {r}"),
                    _ => String::new(),
                },
                match i.specks {
                    0 => String::new(),
                    k => format!(", {k} speck(s) for lone returns no piece of the surface reaches"),
                }
            )
        } else {
            String::new()
        }
    ) + &match i.features {
        Some(f) if f.concave_sectors > 0 => format!(
            "; {} concave corner sector(s) split by a crease ({} control point(s) added)",
            f.concave_sectors, f.concave_points
        ),
        _ => String::new(),
    } + &match &i.curvature_lines {
        Some(c) => match (c.used, c.alternative, &c.reason) {
            (true, Some(q), _) => format!(
                "; kept over the QEM start ({} → {} control points, {})",
                q.initial_control_points,
                q.control_points,
                if q.tolerance_reached {
                    "within the tolerances"
                } else {
                    "outside them"
                }
            ),
            (false, _, Some(why)) => format!("; not the curvature-line start: {why}"),
            _ => String::new(),
        },
        None => String::new(),
    }
}

/// Blender subdivides Catmull-Clark meshes only: says so when a cage is written as Loop (a
/// Loop cage, or a quad/triangle cage of triangles only).
pub fn blender_hint(fitted: &Fitted) {
    if subfit::usd_scheme(fitted.scheme, &fitted.cage.faces) == subfit::io::usda::UsdScheme::Loop {
        eprintln!(
            "subfit: hint: Blender subdivides only Catmull-Clark cages; this cage's control.usda declares the Loop scheme and imports into Blender as a plain mesh (usdview, Houdini and OpenSubdiv show its limit surface). Use --scheme catmull-clark for Blender."
        );
    }
}

/// Writes the outputs into a staging directory inside `dir` and moves them into place
/// together.
pub fn write_outputs(
    fitted: &mut Fitted,
    dir: &std::path::Path,
    options: &OutputOptions,
) -> anyhow::Result<()> {
    let stage = crate::interrupt::Staging::new(dir)
        .with_context(|| format!("{}: cannot create directory", dir.display()))?;
    crate::progress::phase("writing the outputs");
    fitted.write_into_with(&stage.path(""), options)?;
    stage
        .commit(&OUTPUTS)
        .with_context(|| format!("{}: cannot move the outputs into place", dir.display()))?;
    Ok(())
}

/// The scheme asked by `--scheme` (`None`: automatic).
pub(crate) fn scheme_of(s: SchemeArg) -> Option<Scheme> {
    match s {
        SchemeArg::Auto => None,
        SchemeArg::Loop => Some(Scheme::Loop),
        SchemeArg::CatmullClark => Some(Scheme::CatmullClark),
        SchemeArg::QuadTri => Some(Scheme::QuadTriangle),
    }
}

pub(crate) fn method_of(m: MethodArg) -> Method {
    match m {
        MethodArg::Pdm => Method::Pdm,
        MethodArg::Tdm => Method::Tdm,
        MethodArg::Sdm => Method::Sdm,
        MethodArg::Imls => Method::Imls,
    }
}

fn step_of(s: StepArg) -> StepControl {
    match s {
        StepArg::None => StepControl::None,
        StepArg::Lm => StepControl::LevenbergMarquardt,
        StepArg::Armijo => StepControl::Armijo,
    }
}
