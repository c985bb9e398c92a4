//! `subfit fit TARGET --init CONTROL -o DIR`: fit the limit surface of a control mesh to a
//! target with PDM, TDM or SDM (Cheng et al. 2007) and write the cage, a limit tessellation
//! with normals, the per-iteration log and a JSON report, all in the target's coordinates.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context};
use serde_json::json;
use std::path::PathBuf;

use subfit::fit::{
    fit_stages, FitOptions, IterationRow, Method, StageEvent, StageOptions, StageReport,
    StagesReport, StepControl,
};
use subfit::init::{default_control_points, initial_control_mesh, InitOptions};
use subfit::io::ply::VertexProperty;
use subfit::io::usda::{UsdBoundary, UsdScheme};
use subfit::io::{Encoding, WriteOptions};
use subfit::mesh::{HalfEdgeMesh, PolyMesh, Polygons, Tags};
use subfit::subdiv::{sampling_operator, Options, Scheme};
use subfit::target::{Target, TargetOptions};

use crate::cli::{FitArgs, MethodArg, StepArg};
use crate::commands::subdivide::pick_scheme;

/// Finest tessellation level tried for `limit.ply`.
const MAX_TESSELLATION_LEVEL: usize = 6;
/// Largest tessellation (vertices) written to `limit.ply`.
const MAX_TESSELLATION_VERTICES: usize = 1_000_000;

/// The files `subfit fit` writes, in the order they are moved into place (the report last).
const OUTPUTS: [&str; 6] = [
    "control.obj",
    "control.usda",
    "limit.ply",
    "error.ply",
    "log.csv",
    "report.json",
];

pub fn run(a: FitArgs) -> anyhow::Result<ExitCode> {
    let out = execute(&a)?;
    println!("{}", out.summary);
    Ok(if out.reached {
        ExitCode::SUCCESS
    } else {
        eprintln!("subfit: the requested tolerance was not reached (outputs written)");
        ExitCode::from(1)
    })
}

/// What one run of the pipeline gives back to its callers (`fit`, `demo`, `bench fit`).
pub struct Outcome {
    /// Whether every tolerance was reached.
    pub reached: bool,
    /// A one-line summary.
    pub summary: String,
    /// The content of `report.json`.
    pub report: serde_json::Value,
}

/// The whole pipeline of `subfit fit`; writes every output, returns the outcome.
pub fn execute(a: &FitArgs) -> anyhow::Result<Outcome> {
    // Validate every flag before touching a file.
    if !(a.lambda.is_finite() && a.lambda >= 0.0) {
        bail!("--lambda must be a finite number ≥ 0, got {}", a.lambda);
    }
    let lambda_end = a.lambda_end.unwrap_or(a.lambda.min(1e-5));
    if !(lambda_end.is_finite() && lambda_end >= 0.0 && lambda_end <= a.lambda) {
        bail!(
            "--lambda-end must be a finite number in [0, --lambda = {}], got {lambda_end}",
            a.lambda
        );
    }
    for (name, v) in [
        ("--tolerance", Some(a.tolerance)),
        ("--max-error", a.max_error),
        ("--error-scale", a.error_scale),
    ] {
        if let Some(v) = v {
            if !(v.is_finite() && v > 0.0 && v < 1.0) {
                bail!("{name} must be in (0, 1) (unit-cube units), got {v}");
            }
        }
    }
    if a.output.exists() && !a.output.is_dir() {
        bail!("{}: exists and is not a directory", a.output.display());
    }
    let init_file = (a.init != "auto").then(|| PathBuf::from(&a.init));
    if init_file.is_some() && a.control_points.is_some() {
        bail!("--control-points sets the size of the automatic initial mesh; it cannot be used with --init FILE");
    }
    let (method, step) = (method_of(a.method), step_of(a.step));

    let t0 = Instant::now();
    let (mut target_mesh, _) = crate::progress::load(&a.target)?;
    crate::commands::reorient_target(&mut target_mesh, &a.target);
    // With --as-points the file's faces are dropped, but their genus still tells the initial
    // mesh what topology to aim for.
    let mut expected_genus = None;
    if a.as_points && !target_mesh.faces.is_empty() {
        expected_genus = mesh_topology(&target_mesh).ok().flatten().map(|t| t.genus);
        target_mesh.faces = Polygons::new();
    }
    let given = match &init_file {
        Some(path) => {
            let (control, _) = crate::progress::load(path)?;
            if control.faces.is_empty() {
                bail!(
                    "{}: has no faces; an initial control mesh is needed",
                    path.display()
                );
            }
            Some(control)
        }
        None => None,
    };
    let read_time = t0.elapsed();

    let target_topology = mesh_topology(&target_mesh)
        .with_context(|| format!("{}: the target mesh is not usable", a.target.display()))?;
    let sp = crate::progress::spinner("analysing the target");
    let target_options = TargetOptions {
        cancel: crate::interrupt::token(),
        ..TargetOptions::default()
    };
    let target = Target::build(&target_mesh, &target_options, None)
        .with_context(|| format!("{}: cannot use as a target", a.target.display()))?;
    sp.finish_and_clear();
    let preprocess = target.stats().timings.total;

    // The initial control mesh, in normalized units.
    let t_init = Instant::now();
    let (control, init_json) = match given {
        Some(c) => {
            let path = init_file.as_ref().expect("given implies a file");
            let topo = mesh_topology(&c)
                .with_context(|| format!("{}: not a usable control mesh", path.display()))?
                .expect("a control mesh has faces");
            if let Some(t) = &target_topology {
                if (t.genus, t.boundary_loops) != (topo.genus, topo.boundary_loops) {
                    bail!(
                        "{}: the control mesh has genus {} and {} boundary loop(s), the target {} has genus {} and {} — their topologies must match",
                        path.display(),
                        topo.genus,
                        topo.boundary_loops,
                        a.target.display(),
                        t.genus,
                        t.boundary_loops
                    );
                }
            }
            let normalized = PolyMesh::new(
                c.positions
                    .iter()
                    .map(|&p| target.to_normalized(p))
                    .collect(),
                c.faces.clone(),
            );
            let j = json!({ "file": path.display().to_string(), "genus": topo.genus,
                "boundary_loops": topo.boundary_loops });
            (normalized, j)
        }
        None => {
            let n = a
                .control_points
                .map(|n| n as usize)
                .unwrap_or_else(|| default_control_points(target.len()));
            let sp = crate::progress::spinner("building the initial control mesh");
            let mesh = (!target_mesh.faces.is_empty()).then_some(&target_mesh);
            let init_options = InitOptions {
                expected_genus,
                cancel: crate::interrupt::token(),
                ..InitOptions::default()
            };
            let (m, r) =
                initial_control_mesh(&target, mesh, n, &init_options).with_context(|| {
                    format!(
                        "{}: cannot build an initial control mesh",
                        a.target.display()
                    )
                })?;
            sp.finish_and_clear();
            if !r.genus_matches {
                eprintln!(
                    "subfit: warning: the initial control mesh has genus {}, the target {}",
                    r.genus_after, r.genus_target
                );
            }
            let j = json!({
                "source": format!("{:?}", r.source),
                "requested_control_points": n,
                "control_points": m.num_vertices(),
                "faces": m.faces.len(),
                "genus_target": r.genus_target,
                "genus": r.genus_after,
                "genus_matches": r.genus_matches,
                "boundary_loops": { "target": r.boundary_loops.0, "cage": r.boundary_loops.1 },
                "timings_s": { "contour": r.timings.contour.as_secs_f64(),
                    "simplify": r.timings.simplify.as_secs_f64(), "total": r.timings.total.as_secs_f64() },
            });
            (m, j)
        }
    };
    let init_time = t_init.elapsed();

    let scheme = pick_scheme(a.scheme, &control);
    let options = FitOptions {
        scheme,
        sample_level: a.sample_level as usize,
        method,
        step,
        cancel: crate::interrupt::token(),
        ..FitOptions::default()
    };
    let stages = StageOptions {
        lambda_start: a.lambda,
        lambda_end,
        iterations_per_stage: a.stage_iterations as usize,
        max_iterations: a.max_iterations as usize,
        tolerance_rms: a.tolerance,
        tolerance_max: a.max_error.unwrap_or(0.0),
        max_control_points: a.max_control_points as usize,
        refine: !a.no_refine,
        edge_flips: !(a.no_refine || a.no_flips),
        max_depth: a.max_depth,
        local: a.local,
        local_rings: a.local_rings as usize,
        ..StageOptions::default()
    };
    if !a.no_refine && scheme != Scheme::Loop {
        eprintln!("subfit: note: local refinement is implemented for Loop cages only; this Catmull-Clark cage keeps its connectivity");
    }

    let t_fit = Instant::now();
    let bar = crate::progress::bar(stages.max_iterations as u64, "fitting");
    let mut on_event = |e: StageEvent<'_>| match e {
        StageEvent::Iteration { stage, row } => {
            bar.set_message(format!(
                "stage {stage}: E_rms {:.3e}, E_max {:.3e}",
                row.errors.e_rms, row.errors.e_max
            ));
            bar.inc(1);
        }
        StageEvent::Stage(_) => {}
    };
    let result = fit_stages(&target, &control, &options, &stages, Some(&mut on_event))
        .with_context(|| format!("{}: fitting failed", a.target.display()))?;
    bar.finish_and_clear();
    let fit_time = t_fit.elapsed();
    let report = &result.report;
    let fitted = &result.mesh;
    let last = report.last;

    // Outputs, in the target's original coordinates: written into a staging directory inside
    // the output directory, then moved into place together (an interruption leaves none).
    let t_out = Instant::now();
    let stage = crate::interrupt::Staging::new(&a.output)
        .with_context(|| format!("{}: cannot create directory", a.output.display()))?;
    let cage = PolyMesh::new(
        fitted
            .positions
            .iter()
            .map(|&p| target.to_original(p))
            .collect(),
        fitted.faces.clone(),
    );
    let obj = WriteOptions {
        format: None,
        encoding: Encoding::Ascii,
        single_precision: false,
    };
    subfit::io::write_file(&stage.path("control.obj"), &cage, &obj)?;
    let usd_scheme = match scheme {
        Scheme::Loop => UsdScheme::Loop,
        _ => UsdScheme::CatmullClark,
    };
    subfit::io::write_usda_file(
        &stage.path("control.usda"),
        &cage,
        &Tags::new(),
        usd_scheme,
        UsdBoundary::EdgeOnly,
    )?;
    let (limit, level, chord) = limit_tessellation(
        &fitted.faces,
        &fitted.positions,
        scheme,
        last.e_rms,
        last.e_max,
    )?;
    let limit_vertices = limit.positions.len();
    // Local error of every limit vertex: its distance to the target (unit-cube units).
    let local: Vec<f64> =
        subfit::fit::feet::foot_points(&target, options.foot_points, &limit.positions)
            .iter()
            .zip(&limit.positions)
            .map(|(f, p)| {
                (0..3)
                    .map(|k| (p[k] - f.point[k]).powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .collect();
    let scale = a.error_scale.unwrap_or(last.e_max).max(f64::MIN_POSITIVE);
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
    subfit::io::write_file(&stage.path("limit.ply"), &limit, &ply)?;
    let to_original = target.normalization().length_to_original(1.0);
    let error_original: Vec<f64> = local.iter().map(|e| e * to_original).collect();
    let colored = PolyMesh {
        colors: Some(local.iter().map(|&e| error_color(e / scale)).collect()),
        ..limit
    };
    subfit::io::write_ply_with_properties(
        &stage.path("error.ply"),
        &colored,
        &[
            VertexProperty {
                name: "error",
                values: &error_original,
            },
            VertexProperty {
                name: "error_unit_cube",
                values: &local,
            },
        ],
        &ply,
    )?;
    subfit::io::write_atomic(&stage.path("log.csv"), log_csv(report).as_bytes())?;
    let reached = stages.reached(&last);
    let output_time = t_out.elapsed();
    let doc = json!({
        "target": a.target.display().to_string(),
        "target_points": target.len(),
        "target_topology": target_topology.map(|t| json!({"genus": t.genus, "boundary_loops": t.boundary_loops})),
        "normalized_unit_in_original_units": to_original,
        "bbox_diagonal_unit_cube": last.e_rms / last.e_rms_diag.max(f64::MIN_POSITIVE),
        "init": init_json,
        "options": {
            "scheme": format!("{scheme:?}"),
            "method": format!("{method:?}").to_uppercase(),
            "step": format!("{step:?}"),
            "lambda_start": stages.lambda_start,
            "lambda_end": stages.lambda_end,
            "lambda_factor": stages.lambda_factor,
            "sample_level": options.sample_level,
            "max_iterations": stages.max_iterations,
            "stage_iterations": stages.iterations_per_stage,
            "tolerance_rms": stages.tolerance_rms,
            "tolerance_max": a.max_error,
            "max_control_points": stages.max_control_points,
            "refine": stages.refine,
            "edge_flips": stages.edge_flips,
            "max_depth": stages.max_depth,
            "local": stages.local,
            "local_rings": stages.local_rings,
        },
        "control_points": fitted.num_vertices(),
        "control_faces": fitted.faces.len(),
        "initial": stats_json(&report.initial),
        "final": stats_json(&last),
        "stop": format!("{:?}", report.stop),
        "tolerance_reached": reached,
        "stages": report.stages.iter().map(stage_json).collect::<Vec<_>>(),
        "iterations": report.stages.iter().flat_map(|s| s.fit.iterations.iter().map(move |r| row_json(s.stage, r))).collect::<Vec<_>>(),
        "limit_tessellation": {
            "level": level,
            "vertices": limit_vertices,
            "predicted_chordal_error": { "max": chord.max, "rms": chord.rms },
            "goal": { "max": 0.1 * last.e_max, "rms": 0.1 * last.e_rms },
            "goal_met": chord.max <= 0.1 * last.e_max && chord.rms <= 0.1 * last.e_rms,
        },
        "error_color_scale_unit_cube": scale,
        "timings_s": {
            "read": read_time.as_secs_f64(),
            "preprocess": preprocess.as_secs_f64(),
            "init": init_time.as_secs_f64(),
            "fit": fit_time.as_secs_f64(),
            "output": output_time.as_secs_f64(),
            "total": t0.elapsed().as_secs_f64(),
        },
    });
    subfit::io::write_atomic(
        &stage.path("report.json"),
        (serde_json::to_string_pretty(&doc)? + "\n").as_bytes(),
    )?;
    stage
        .commit(&OUTPUTS)
        .with_context(|| format!("{}: cannot move the outputs into place", a.output.display()))?;
    let summary = format!(
        "{} → {} control points, {} stages, {} iterations ({:?}): E_rms {:.3e} → {:.3e}, E_max {:.3e} → {:.3e} (unit cube); {:.1} s; wrote {}",
        control.num_vertices(),
        fitted.num_vertices(),
        report.stages.len(),
        report.iterations(),
        report.stop,
        report.initial.e_rms,
        last.e_rms,
        report.initial.e_max,
        last.e_max,
        t0.elapsed().as_secs_f64(),
        a.output.display()
    );
    Ok(Outcome {
        reached,
        summary,
        report: doc,
    })
}

/// Genus and boundary loops of a mesh (`None` for a point cloud).
struct Topo {
    genus: u32,
    boundary_loops: usize,
}

fn mesh_topology(m: &PolyMesh) -> anyhow::Result<Option<Topo>> {
    if m.faces.is_empty() {
        return Ok(None);
    }
    let h = HalfEdgeMesh::from_mesh(m)?;
    Ok(Some(Topo {
        genus: h.genus(),
        boundary_loops: h.boundary_loops().len(),
    }))
}

/// The papers' error colours (Cheng 2007 §IV-D): blue, green, yellow, red at 0, ⅓, ⅔ and 1 of
/// the scale, linear in between, red beyond.
pub fn error_color(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 4] = [
        [0.0, 0.0, 255.0],
        [0.0, 255.0, 0.0],
        [255.0, 255.0, 0.0],
        [255.0, 0.0, 0.0],
    ];
    let x = if t.is_finite() {
        t.clamp(0.0, 1.0) * 3.0
    } else {
        3.0
    };
    let i = (x.floor() as usize).min(2);
    let f = x - i as f64;
    std::array::from_fn(|k| (STOPS[i][k] + f * (STOPS[i + 1][k] - STOPS[i][k])).round() as u8)
}

fn stage_json(s: &StageReport) -> serde_json::Value {
    json!({
        "stage": s.stage,
        "lambda": s.lambda,
        "control_points": s.num_control_points,
        "faces": s.num_faces,
        "iterations": s.fit.iterations.len(),
        "stop": format!("{:?}", s.fit.stop),
        "initial": stats_json(&s.fit.initial),
        "final": stats_json(&s.fit.last()),
        "samples": s.fit.num_samples,
        "setup_s": s.fit.setup.as_secs_f64(),
        "flips_tried": s.flips_tried,
        "flips_kept": s.flips_kept,
        "active_points": s.active_points,
        "refine": s.refine.map(|r| json!({"marked": r.marked, "red": r.red, "green": r.green, "new_points": r.new_points})),
        "time_s": s.time.as_secs_f64(),
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

fn stats_json(s: &subfit::fit::ErrorStats) -> serde_json::Value {
    json!({
        "e_max": s.e_max, "e_rms": s.e_rms,
        "e_max_fraction_of_diagonal": s.e_max_diag, "e_rms_fraction_of_diagonal": s.e_rms_diag,
        "objective": s.objective,
    })
}

fn row_json(stage: usize, r: &IterationRow) -> serde_json::Value {
    json!({
        "stage": stage, "iteration": r.iteration, "accepted": r.accepted, "errors": stats_json(&r.errors),
        "trial_objective": r.trial_objective, "damping": r.damping, "step_length": r.step_length,
        "gain_ratio": r.gain_ratio,
        "timings_s": {
            "sample": r.timings.sample.as_secs_f64(), "project": r.timings.project.as_secs_f64(),
            "assemble": r.timings.assemble.as_secs_f64(), "solve": r.timings.solve.as_secs_f64(),
            "evaluate": r.timings.evaluate.as_secs_f64(),
        },
    })
}

/// The per-iteration table of all stages as CSV (unit-cube units; times in seconds): a row
/// for the initial mesh (iteration 0), then one per iteration, numbered across stages.
pub fn log_csv(r: &StagesReport) -> String {
    let mut s = String::from(
        "stage,iteration,lambda,control_points,accepted,e_max,e_rms,e_max_diag,e_rms_diag,objective,trial_objective,damping,step_length,gain_ratio,t_sample,t_project,t_assemble,t_solve,t_evaluate\n",
    );
    let i = &r.initial;
    let (lambda0, n0) = r
        .stages
        .first()
        .map_or((0.0, 0), |s| (s.lambda, s.num_control_points));
    let _ = writeln!(
        s,
        "0,0,{lambda0},{n0},true,{},{},{},{},{},{},,,,,,,,",
        i.e_max, i.e_rms, i.e_max_diag, i.e_rms_diag, i.objective, i.objective
    );
    let mut k = 0;
    for st in &r.stages {
        for row in &st.fit.iterations {
            k += 1;
            let e = &row.errors;
            let t = &row.timings;
            let _ = writeln!(
                s,
                "{},{k},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                st.stage,
                st.lambda,
                st.num_control_points,
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
    }
    s
}

/// Chordal error of a tessellation (normalized units): the largest and the RMS, over its
/// edges, of the distance from the limit point of the edge's midpoint to the chord.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chordal {
    /// Largest over the edges.
    pub max: f64,
    /// Root mean square over the edges.
    pub rms: f64,
}

impl Chordal {
    fn scaled(self, s: f64) -> Self {
        Self {
            max: self.max * s,
            rms: self.rms * s,
        }
    }
}

/// The limit surface tessellated at the coarsest level whose chordal error is below a tenth of
/// the fitting error in the same norm — RMS chordal error ≤ `e_rms / 10` and largest chordal
/// error ≤ `e_max / 10` — or the finest level with at most [`MAX_TESSELLATION_VERTICES`]
/// vertices (up to level [`MAX_TESSELLATION_LEVEL`]). The chordal error of level 1 is measured
/// (between the level-2 limit point of each edge and the midpoint of the limit points of its
/// ends) and divided by 4 per level, as it shrinks with the square of the edge length on a
/// smooth surface; so only levels 1, 2 and the chosen one are built. Returns the mesh
/// (positions, limit normals, faces), the level and the predicted chordal error.
pub fn limit_tessellation(
    faces: &Polygons,
    control: &[[f64; 3]],
    scheme: Scheme,
    e_rms: f64,
    e_max: f64,
) -> anyhow::Result<(PolyMesh, usize, Chordal)> {
    let opts = Options::new(scheme);
    let tags = Tags::new();
    let one = sampling_operator(faces, control.len(), &tags, &opts, 1)?;
    let two = sampling_operator(faces, control.len(), &tags, &opts, 2)?;
    let chord1 = chordal_estimate(&one.faces, one.num_vertices, &two.position.apply(control));
    let at = |level: usize| chord1.scaled(0.25f64.powi(level as i32 - 1));
    let fine_enough = |c: Chordal| c.rms <= 0.1 * e_rms && c.max <= 0.1 * e_max;
    let mut level = 1;
    let mut vertices = one.num_vertices;
    while level < MAX_TESSELLATION_LEVEL
        && !fine_enough(at(level))
        && vertices.saturating_mul(4) <= MAX_TESSELLATION_VERTICES
    {
        level += 1;
        vertices = vertices.saturating_mul(4);
    }
    let op = match level {
        1 => one,
        2 => two,
        l => sampling_operator(faces, control.len(), &tags, &opts, l)?,
    };
    let s = op.evaluate(control);
    let mesh = PolyMesh {
        positions: s.positions,
        normals: Some(s.normals),
        colors: None,
        faces: op.faces,
    };
    Ok((mesh, level, at(level)))
}

/// Largest and RMS `|fine[V + e] − (fine[a] + fine[b]) / 2|` over the edges `e = (a, b)` of
/// the coarse faces, numbered in order of first appearance (the refinement's child order:
/// vertex points keep their ids, then one edge point per edge).
fn chordal_estimate(faces: &Polygons, nv: usize, fine: &[[f64; 3]]) -> Chordal {
    let mut ids: HashMap<(u32, u32), usize> = HashMap::with_capacity(faces.indices().len());
    let (mut worst, mut sum2): (f64, f64) = (0.0, 0.0);
    for f in faces.iter() {
        for i in 0..f.len() {
            let (a, b) = (f[i], f[(i + 1) % f.len()]);
            let key = (a.min(b), a.max(b));
            let next = ids.len();
            let e = *ids.entry(key).or_insert(next);
            if e != next {
                continue; // seen from the other side
            }
            let (pa, pb, pe) = (fine[a as usize], fine[b as usize], fine[nv + e]);
            let d2: f64 = (0..3)
                .map(|k| (pe[k] - 0.5 * (pa[k] + pb[k])).powi(2))
                .sum();
            worst = worst.max(d2.sqrt());
            sum2 += d2;
        }
    }
    Chordal {
        max: worst,
        rms: (sum2 / ids.len().max(1) as f64).sqrt(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfit::mesh::shapes::torus_mesh;

    /// The chordal error predicted from level 1 (÷ 4 per level) against the one measured at
    /// level 3 (level-3 chords against level-4 limit points), on a torus cage.
    #[test]
    fn predicted_chordal_error_matches_the_measured_one() {
        let cage = torus_mesh(1.0, 0.4, 12, 8, true);
        let (faces, p) = (&cage.faces, &cage.positions);
        let opts = Options::new(Scheme::Loop);
        let op = |l| sampling_operator(faces, p.len(), &Tags::new(), &opts, l).unwrap();
        let (one, two, three, four) = (op(1), op(2), op(3), op(4));
        let c1 = chordal_estimate(&one.faces, one.num_vertices, &two.position.apply(p));
        let c3 = chordal_estimate(&three.faces, three.num_vertices, &four.position.apply(p));
        let predicted = c1.scaled(1.0 / 16.0);
        for (m, q) in [(c3.max, predicted.max), (c3.rms, predicted.rms)] {
            assert!(
                m > 0.0 && (m / q - 1.0).abs() < 0.25,
                "measured {m}, predicted {q}"
            );
        }
        // RMS below max; the tessellation goal picks the first level meeting both norms.
        assert!(c1.rms < c1.max);
        let (_, level, chord) = limit_tessellation(faces, p, Scheme::Loop, c1.rms, c1.max).unwrap();
        assert_eq!(level, 3);
        assert!(chord.rms <= 0.1 * c1.rms && chord.max <= 0.1 * c1.max);
    }
}
