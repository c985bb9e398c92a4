//! `subfit bench convergence`: Cheng et al. 2007, §IV, Examples 1–4 and 6–10, on ellipsoids we
//! sample ourselves. Each example fits a 14-vertex Loop cage (near or far from the shape, see
//! `subfit_mesh::shapes::cheng_ellipsoid_cage`) with several methods and writes the error curves
//! (`exampleN.csv`: iteration, then `E_rms` per method, unit-cube units), a log-scale plot
//! (`exampleN.svg`, like the paper's Fig. 4, 5, 7a, 8) and `summary.json` with, per run, the
//! first iteration reaching `E_rms < 0.002` and whether the objective ever increased.

use std::fmt::Write as _;
use std::process::ExitCode;

use anyhow::{bail, Context};
use serde_json::json;
use subfit::fit::{fit, FitOptions, FitReport, Variant};
use subfit::mesh::shapes::{cheng_ellipsoid_cage, Shape};
use subfit::mesh::PolyMesh;
use subfit::target::{Target, TargetOptions};

use crate::cli::{BenchCommand, ConvergenceArgs};
use subfit::report::html::{Block, Page, Section};
use subfit::report::plot::{log_chart, Series};

/// The paper's convergence threshold on `E_rms` (unit cube).
const TOLERANCE: f64 = 0.002;

pub fn run(cmd: BenchCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        BenchCommand::Convergence(a) => convergence(a),
        BenchCommand::Fit(a) => crate::commands::bench_fit::run(a),
        BenchCommand::Sequence(a) => crate::commands::bench_sequence::run(a),
        BenchCommand::Corpus(a) => crate::commands::bench_corpus::run(a),
    }
}

/// One example: which ellipsoid, which cage, which runs `(label, variant, λ)`.
struct Example {
    number: u32,
    title: &'static str,
    axes: [f64; 3],
    far: bool,
    runs: Vec<(String, Variant, f64)>,
}

fn examples() -> Vec<Example> {
    let paper = [0.25, 0.5, 1.0];
    let three = |vs: &[Variant]| vs.iter().map(|&v| (v.name().to_string(), v, 0.0)).collect();
    use Variant::*;
    vec![
        Example {
            number: 1,
            title: "Example 1: near initial mesh",
            axes: paper,
            far: false,
            runs: three(&[Pdm, Tdm, Sdm]),
        },
        Example {
            number: 2,
            title: "Example 2: far initial mesh",
            axes: paper,
            far: true,
            runs: three(&[Pdm, Tdm, Sdm]),
        },
        Example {
            number: 3,
            title: "Example 3: elongated ellipsoid 0.125/0.25/4",
            axes: [0.125, 0.25, 4.0],
            far: false,
            runs: three(&[Pdm, Tdm, Sdm]),
        },
        Example {
            number: 4,
            title: "Example 4: TDM with smoothing, far mesh",
            axes: paper,
            far: true,
            runs: (2..=6)
                .map(|i| (format!("TDM λ=1e-{i}"), Tdm, 10f64.powi(-i)))
                .collect(),
        },
        Example {
            number: 6,
            title: "Example 6: TDM vs TDMLM, near",
            axes: paper,
            far: false,
            runs: three(&[Tdm, TdmLm]),
        },
        Example {
            number: 7,
            title: "Example 7: TDM vs TDMLM, far",
            axes: paper,
            far: true,
            runs: three(&[Tdm, TdmLm]),
        },
        Example {
            number: 8,
            title: "Example 8: SDM vs SDMLM, near",
            axes: paper,
            far: false,
            runs: three(&[Sdm, SdmLm]),
        },
        Example {
            number: 9,
            title: "Example 9: SDM vs SDMLM, far",
            axes: paper,
            far: true,
            runs: three(&[Sdm, SdmLm]),
        },
        Example {
            number: 10,
            title: "Example 10: Armijo step control, far",
            axes: paper,
            far: true,
            runs: three(&[Pdm, Tdm, Sdm, PdmSc, TdmSc, SdmSc]),
        },
    ]
}

fn convergence(a: ConvergenceArgs) -> anyhow::Result<ExitCode> {
    let all = examples();
    for e in &a.examples {
        if !all.iter().any(|x| x.number == *e) {
            bail!("--examples: there is no example {e} (available: 1-4, 6-10; 5 needs the ball-joint scan)");
        }
    }
    if a.output.exists() && !a.output.is_dir() {
        bail!("{}: exists and is not a directory", a.output.display());
    }
    std::fs::create_dir_all(&a.output)
        .with_context(|| format!("{}: cannot create directory", a.output.display()))?;
    let chosen: Vec<&Example> = all
        .iter()
        .filter(|x| a.examples.is_empty() || a.examples.contains(&x.number))
        .collect();
    let total_runs: usize = chosen.iter().map(|x| x.runs.len()).sum();
    let bar = crate::progress::bar(total_runs as u64, "fitting");
    let mut summary = Vec::new();
    let mut figures = Vec::new();
    out!(
        "{:<8} {:<14} {:>10} {:>12} {:>12} {:>10}",
        "example",
        "run",
        "iters<.002",
        "E_rms first",
        "E_rms last",
        "monotone"
    );
    for ex in chosen {
        figures.push(convergence_example(ex, &a, &bar, &mut summary)?);
    }
    bar.finish_and_clear();
    write_convergence_report(&a, &summary, figures)?;
    out!(
        "wrote {} (look at {})",
        a.output.display(),
        a.output.join("report.html").display()
    );
    Ok(ExitCode::SUCCESS)
}

/// Runs the fits of one example, prints a line and adds a summary entry per run, and writes
/// its error curves (`exampleN.csv`, `exampleN.svg` under the output directory); returns the
/// figure for the report.
fn convergence_example(
    ex: &Example,
    a: &ConvergenceArgs,
    bar: &indicatif::ProgressBar,
    summary: &mut Vec<serde_json::Value>,
) -> anyhow::Result<Block> {
    let [ax, by, cz] = ex.axes;
    let shape = Shape::Ellipsoid {
        a: ax,
        b: by,
        c: cz,
    };
    let cloud = shape.sample(a.points as usize, 0.0, 7);
    let target = Target::from_points(
        &cloud.positions,
        cloud.normals.as_deref(),
        &TargetOptions::default(),
    )
    .context("building the ellipsoid target")?;
    let cage = cheng_ellipsoid_cage(ax, by, cz, ex.far);
    let control = PolyMesh::new(
        cage.positions
            .iter()
            .map(|&p| target.to_normalized(p))
            .collect(),
        cage.faces.clone(),
    );
    let mut series = Vec::new();
    let mut reports = Vec::new();
    for (label, variant, lambda) in &ex.runs {
        let opts = FitOptions::variant(*variant)
            .with_lambda(*lambda)
            .with_max_iterations(a.iterations as usize);
        let report = fit(&target, &control, &opts)
            .with_context(|| format!("example {} {label}", ex.number))?
            .report;
        bar.inc(1);
        let curve = curve(&report);
        let reached = report.iterations_to_rms(TOLERANCE);
        let monotone = is_monotone(&report);
        bar.suspend(|| {
            out!(
                "{:<8} {:<14} {:>10} {:>12.3e} {:>12.3e} {:>10}",
                ex.number,
                label,
                reached.map_or("-".to_string(), |k| k.to_string()),
                report.initial.e_rms,
                report.last().e_rms,
                monotone
            )
        });
        summary.push(json!({
            "example": ex.number, "run": label, "variant": variant.name(), "lambda": lambda,
            "far": ex.far, "axes": ex.axes, "iterations_to_tolerance": reached,
            "tolerance": TOLERANCE, "initial_e_rms": report.initial.e_rms,
            "final_e_rms": report.last().e_rms, "objective_monotone": monotone,
            "iterations": report.iterations.len(), "stop": format!("{:?}", report.stop),
            "e_rms": curve.iter().map(|p| p.1).collect::<Vec<_>>(),
        }));
        series.push(Series {
            name: label.clone(),
            points: curve,
        });
        reports.push((label.clone(), report));
    }
    let base = a.output.join(format!("example{}", ex.number));
    crate::interrupt::watch_dir(&base.with_extension("csv"));
    subfit::io::write_atomic(&base.with_extension("csv"), csv(&reports).as_bytes())?;
    let svg = log_chart(
        ex.title,
        "iteration",
        "E_rms (unit cube)",
        &series,
        Some(TOLERANCE),
    );
    crate::interrupt::watch_dir(&base.with_extension("svg"));
    subfit::io::write_atomic(&base.with_extension("svg"), svg.as_bytes())?;
    Ok(Block::Figure {
        svg,
        caption: format!(
            "Example {}: E_rms per iteration, one line per method (exampleN.csv has the numbers).",
            ex.number
        ),
    })
}

/// Writes `report.html` (a table of the runs and the error curves) and `summary.json` into
/// the output directory.
fn write_convergence_report(
    a: &ConvergenceArgs,
    summary: &[serde_json::Value],
    figures: Vec<Block>,
) -> anyhow::Result<()> {
    let rows = summary
        .iter()
        .map(|r| {
            let cell = |k: &str| match &r[k] {
                serde_json::Value::Null => "-".to_string(),
                serde_json::Value::String(s) => s.clone(),
                serde_json::Value::Number(n) => n
                    .as_f64()
                    .map_or_else(|| n.to_string(), subfit::report::html::number),
                v => v.to_string(),
            };
            [
                "example",
                "run",
                "iterations_to_tolerance",
                "initial_e_rms",
                "final_e_rms",
                "objective_monotone",
            ]
            .map(cell)
            .to_vec()
        })
        .collect();
    let page = Page {
        title: "subfit bench convergence: Cheng et al. 2007 on the ellipsoid".into(),
        headline: format!(
            "Iterations to E_rms < {TOLERANCE} from the paper's initial cages, {} sampled points.",
            a.points
        ),
        scene: None,
        sections: vec![
            Section {
                heading: "Runs".into(),
                blocks: vec![Block::Table {
                    header: [
                        "example",
                        "run",
                        "iterations to tolerance",
                        "initial E_rms",
                        "final E_rms",
                        "objective monotone",
                    ]
                    .map(String::from)
                    .to_vec(),
                    rows,
                }],
            },
            Section {
                heading: "Error curves".into(),
                blocks: figures,
            },
        ],
    };
    crate::interrupt::watch_dir(&a.output.join("report.html"));
    subfit::io::write_atomic(
        &a.output.join("report.html"),
        subfit::report::html::render(&page).as_bytes(),
    )?;
    let doc = json!({ "tolerance": TOLERANCE, "points": a.points, "runs": summary });
    crate::interrupt::watch_dir(&a.output.join("summary.json"));
    subfit::io::write_atomic(
        &a.output.join("summary.json"),
        (serde_json::to_string_pretty(&doc)? + "\n").as_bytes(),
    )?;
    Ok(())
}

/// `(iteration, E_rms)` of the current (best accepted) control points after each iteration,
/// starting with iteration 0 (the initial mesh).
fn curve(r: &FitReport) -> Vec<(f64, f64)> {
    std::iter::once((0.0, r.initial.e_rms))
        .chain(
            r.iterations
                .iter()
                .map(|row| (row.iteration as f64, row.errors.e_rms)),
        )
        .collect()
}

/// Whether the objective of the current control points never increased.
fn is_monotone(r: &FitReport) -> bool {
    let mut prev = r.initial.objective;
    for row in &r.iterations {
        if row.errors.objective > prev * (1.0 + 1e-12) {
            return false;
        }
        prev = row.errors.objective;
    }
    true
}

fn csv(reports: &[(String, FitReport)]) -> String {
    let mut s = String::from("iteration");
    for (label, _) in reports {
        let _ = write!(s, ",{label}");
    }
    s.push('\n');
    let curves: Vec<Vec<(f64, f64)>> = reports.iter().map(|(_, r)| curve(r)).collect();
    let rows = curves.iter().map(Vec::len).max().unwrap_or(0);
    for i in 0..rows {
        let _ = write!(s, "{i}");
        for c in &curves {
            match c.get(i) {
                Some(p) => {
                    let _ = write!(s, ",{}", p.1);
                }
                None => s.push(','),
            }
        }
        s.push('\n');
    }
    s
}
