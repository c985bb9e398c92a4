//! `subfit fit TARGET --init CONTROL -o DIR`: fit the limit surface of a control mesh to a
//! target with PDM, TDM or SDM (Cheng et al. 2007) and write the cage, a limit tessellation
//! with normals, the per-iteration log and a JSON report, all in the target's coordinates.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context};
use serde_json::json;
use subfit::fit::{FitOptions, FitReport, Fitter, IterationRow, Method, StepControl, StopReason};
use subfit::io::{Encoding, WriteOptions};
use subfit::mesh::{PolyMesh, Polygons, Tags};
use subfit::subdiv::{sampling_operator, Options, Scheme};
use subfit::target::{Target, TargetOptions};

use crate::cli::{FitArgs, MethodArg, StepArg};
use crate::commands::subdivide::pick_scheme;

/// Finest tessellation level tried for `limit.ply`.
const MAX_TESSELLATION_LEVEL: usize = 6;
/// Largest tessellation (vertices) written to `limit.ply`.
const MAX_TESSELLATION_VERTICES: usize = 4_000_000;

pub fn run(a: FitArgs) -> anyhow::Result<ExitCode> {
    // Validate every flag before touching a file.
    if !(a.lambda.is_finite() && a.lambda >= 0.0) {
        bail!("--lambda must be a finite number ≥ 0, got {}", a.lambda);
    }
    for (name, v) in [("--tolerance", a.tolerance), ("--max-error", a.max_error)] {
        if let Some(v) = v {
            if !(v.is_finite() && v > 0.0 && v < 1.0) {
                bail!("{name} must be in (0, 1) (unit-cube units), got {v}");
            }
        }
    }
    if a.output.exists() && !a.output.is_dir() {
        bail!("{}: exists and is not a directory", a.output.display());
    }
    let (method, step) = (method_of(a.method), step_of(a.step));

    let t0 = Instant::now();
    let (target_mesh, _) = crate::progress::load(&a.target)?;
    let (control, _) = crate::progress::load(&a.init)?;
    if control.faces.is_empty() {
        bail!(
            "{}: has no faces; an initial control mesh is needed",
            a.init.display()
        );
    }
    let scheme = pick_scheme(a.scheme, &control);
    let options = FitOptions {
        scheme,
        sample_level: a.sample_level as usize,
        method,
        step,
        lambda: a.lambda,
        max_iterations: a.max_iterations as usize,
        tolerance_rms: a.tolerance.unwrap_or(0.0),
        tolerance_max: a.max_error.unwrap_or(0.0),
        ..FitOptions::default()
    };
    let read_time = t0.elapsed();

    let sp = crate::progress::spinner("analysing the target");
    let target = Target::build(&target_mesh, &TargetOptions::default(), None)
        .with_context(|| format!("{}: cannot use as a target", a.target.display()))?;
    sp.finish_and_clear();
    let preprocess = target.stats().timings.total;

    let mut points: Vec<[f64; 3]> = control
        .positions
        .iter()
        .map(|&p| target.to_normalized(p))
        .collect();
    let t_fit = Instant::now();
    let mut fitter = Fitter::new(
        &target,
        &control.faces,
        points.len(),
        &Tags::new(),
        &options,
    )
    .with_context(|| format!("{}: cannot fit this control mesh", a.init.display()))?;
    let bar = crate::progress::bar(options.max_iterations as u64, "fitting");
    let mut on_iteration = |row: &IterationRow| {
        bar.set_message(format!("fitting: E_rms {:.3e}", row.errors.e_rms));
        bar.inc(1);
    };
    let report = fitter
        .run(&mut points, Some(&mut on_iteration))
        .with_context(|| format!("{}: fitting failed", a.target.display()))?;
    bar.finish_and_clear();
    let fit_time = t_fit.elapsed();

    // Outputs, in the target's original coordinates.
    std::fs::create_dir_all(&a.output)
        .with_context(|| format!("{}: cannot create directory", a.output.display()))?;
    let last = report.last();
    let cage = PolyMesh::new(
        points.iter().map(|&p| target.to_original(p)).collect(),
        control.faces.clone(),
    );
    let obj = WriteOptions {
        format: None,
        encoding: Encoding::Ascii,
        single_precision: false,
    };
    subfit::io::write_file(&a.output.join("control.obj"), &cage, &obj)?;
    let (limit, level, chord) = limit_tessellation(&control.faces, &points, scheme, last.e_rms)?;
    let limit = PolyMesh {
        positions: limit
            .positions
            .iter()
            .map(|&p| target.to_original(p))
            .collect(),
        ..limit
    };
    let ply = WriteOptions {
        format: None,
        encoding: Encoding::BinaryLittleEndian,
        single_precision: false,
    };
    subfit::io::write_file(&a.output.join("limit.ply"), &limit, &ply)?;
    subfit::io::write_atomic(&a.output.join("log.csv"), log_csv(&report).as_bytes())?;
    let reached = tolerance_reached(&report, &options);
    let doc = json!({
        "target": a.target.display().to_string(),
        "init": a.init.display().to_string(),
        "options": {
            "scheme": format!("{scheme:?}"),
            "method": format!("{method:?}").to_uppercase(),
            "step": format!("{step:?}"),
            "lambda": options.lambda,
            "sample_level": options.sample_level,
            "max_iterations": options.max_iterations,
            "tolerance_rms": a.tolerance,
            "tolerance_max": a.max_error,
        },
        "target_points": target.len(),
        "normalized_unit_in_original_units": target.normalization().length_to_original(1.0),
        "control_points": points.len(),
        "control_faces": control.faces.len(),
        "samples": report.num_samples,
        "initial": stats_json(&report.initial),
        "final": stats_json(&last),
        "stop": format!("{:?}", report.stop),
        "tolerance_reached": reached,
        "iterations": report.iterations.iter().map(row_json).collect::<Vec<_>>(),
        "limit_tessellation": { "level": level, "estimated_chordal_error": chord },
        "timings_s": {
            "read": read_time.as_secs_f64(),
            "preprocess": preprocess.as_secs_f64(),
            "setup": report.setup.as_secs_f64(),
            "fit": fit_time.as_secs_f64(),
            "total": t0.elapsed().as_secs_f64(),
        },
    });
    subfit::io::write_atomic(
        &a.output.join("report.json"),
        (serde_json::to_string_pretty(&doc)? + "\n").as_bytes(),
    )?;
    println!(
        "{} control points, {} iterations ({:?}): E_rms {:.3e} → {:.3e}, E_max {:.3e} → {:.3e} (unit cube); wrote {}",
        points.len(),
        report.iterations.len(),
        report.stop,
        report.initial.e_rms,
        last.e_rms,
        report.initial.e_max,
        last.e_max,
        a.output.display()
    );
    Ok(if reached {
        ExitCode::SUCCESS
    } else {
        eprintln!("subfit: the requested tolerance was not reached (outputs written)");
        ExitCode::from(1)
    })
}

fn method_of(m: MethodArg) -> Method {
    match m {
        MethodArg::Pdm => Method::Pdm,
        MethodArg::Tdm => Method::Tdm,
        MethodArg::Sdm => Method::Sdm,
    }
}

fn step_of(s: StepArg) -> StepControl {
    match s {
        StepArg::None => StepControl::None,
        StepArg::Lm => StepControl::LevenbergMarquardt,
        StepArg::Armijo => StepControl::Armijo,
    }
}

/// Whether every tolerance asked for is met by the final errors (true when none was asked).
fn tolerance_reached(r: &FitReport, o: &FitOptions) -> bool {
    let last = r.last();
    (o.tolerance_rms <= 0.0 || last.e_rms <= o.tolerance_rms)
        && (o.tolerance_max <= 0.0 || last.e_max <= o.tolerance_max)
        || r.stop == StopReason::Tolerance
}

fn stats_json(s: &subfit::fit::ErrorStats) -> serde_json::Value {
    json!({
        "e_max": s.e_max, "e_rms": s.e_rms,
        "e_max_fraction_of_diagonal": s.e_max_diag, "e_rms_fraction_of_diagonal": s.e_rms_diag,
        "objective": s.objective,
    })
}

fn row_json(r: &IterationRow) -> serde_json::Value {
    json!({
        "iteration": r.iteration, "accepted": r.accepted, "errors": stats_json(&r.errors),
        "trial_objective": r.trial_objective, "damping": r.damping, "step_length": r.step_length,
        "gain_ratio": r.gain_ratio,
        "timings_s": {
            "sample": r.timings.sample.as_secs_f64(), "project": r.timings.project.as_secs_f64(),
            "assemble": r.timings.assemble.as_secs_f64(), "solve": r.timings.solve.as_secs_f64(),
            "evaluate": r.timings.evaluate.as_secs_f64(),
        },
    })
}

/// The per-iteration table as CSV (unit-cube units; times in seconds).
pub fn log_csv(r: &FitReport) -> String {
    let mut s = String::from(
        "iteration,accepted,e_max,e_rms,e_max_diag,e_rms_diag,objective,trial_objective,damping,step_length,gain_ratio,t_sample,t_project,t_assemble,t_solve,t_evaluate\n",
    );
    let i = &r.initial;
    let _ = writeln!(
        s,
        "0,true,{},{},{},{},{},{},,,,,,,,",
        i.e_max, i.e_rms, i.e_max_diag, i.e_rms_diag, i.objective, i.objective
    );
    for row in &r.iterations {
        let e = &row.errors;
        let t = &row.timings;
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            row.iteration,
            row.accepted,
            e.e_max,
            e.e_rms,
            e.e_max_diag,
            e.e_rms_diag,
            e.objective,
            row.trial_objective,
            row.damping,
            row.step_length,
            row.gain_ratio,
            t.sample.as_secs_f64(),
            t.project.as_secs_f64(),
            t.assemble.as_secs_f64(),
            t.solve.as_secs_f64(),
            t.evaluate.as_secs_f64()
        );
    }
    s
}

/// The limit surface tessellated at the coarsest level whose chordal error, estimated as the
/// largest distance between the level-`L+1` limit point of an edge and the midpoint of the
/// limit points of its ends, is at most a tenth of `e_rms` (or the finest level allowed).
/// Returns the mesh (positions, limit normals, faces), the level and the estimate.
pub fn limit_tessellation(
    faces: &Polygons,
    control: &[[f64; 3]],
    scheme: Scheme,
    e_rms: f64,
) -> anyhow::Result<(PolyMesh, usize, f64)> {
    let opts = Options::new(scheme);
    let tags = Tags::new();
    let goal = 0.1 * e_rms;
    let mut level = 1;
    let mut current = sampling_operator(faces, control.len(), &tags, &opts, level)?;
    loop {
        let next = sampling_operator(faces, control.len(), &tags, &opts, level + 1)?;
        let fine = next.position.apply(control);
        let chord = chordal_estimate(&current.faces, current.num_vertices, &fine);
        let too_big = next.num_vertices > MAX_TESSELLATION_VERTICES;
        if chord <= goal || level + 1 > MAX_TESSELLATION_LEVEL || too_big {
            let s = current.evaluate(control);
            let mesh = PolyMesh {
                positions: s.positions,
                normals: Some(s.normals),
                colors: None,
                faces: current.faces,
            };
            return Ok((mesh, level, chord));
        }
        current = next;
        level += 1;
    }
}

/// Largest `|fine[V + e] − (fine[a] + fine[b]) / 2|` over the edges `e = (a, b)` of the coarse
/// faces, numbered in order of first appearance (the refinement's child order: vertex points
/// keep their ids, then one edge point per edge).
fn chordal_estimate(faces: &Polygons, nv: usize, fine: &[[f64; 3]]) -> f64 {
    let mut ids: HashMap<(u32, u32), usize> = HashMap::with_capacity(faces.indices().len());
    let mut worst: f64 = 0.0;
    for f in faces.iter() {
        for i in 0..f.len() {
            let (a, b) = (f[i], f[(i + 1) % f.len()]);
            let key = (a.min(b), a.max(b));
            let next = ids.len();
            let e = *ids.entry(key).or_insert(next);
            let (pa, pb, pe) = (fine[a as usize], fine[b as usize], fine[nv + e]);
            let d2: f64 = (0..3)
                .map(|k| (pe[k] - 0.5 * (pa[k] + pb[k])).powi(2))
                .sum();
            worst = worst.max(d2.sqrt());
        }
    }
    worst
}
