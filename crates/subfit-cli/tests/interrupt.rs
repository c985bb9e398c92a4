//! An interrupted run (SIGINT, SIGTERM) exits with 130 and leaves no partial output: neither a
//! half-written file, nor a temporary one, nor a mix of new and old outputs; and every long
//! phase stops when interrupted (the commands poll a cancellation token; a safety net in the
//! signal handler covers the rest). Each test has the run interrupt itself at a named phase
//! (`SUBFIT_INTERRUPT_AT=PHASE:SIGNAL`: the run sends itself the signal through `kill` when the
//! phase starts and goes on once the handler has cancelled it), so the signal path is exercised
//! at a known step, with no sleeps and no bound on the time.
#![cfg(unix)]
#![allow(clippy::print_stdout)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use subfit::io::{Encoding, WriteOptions};
use subfit::mesh::shapes::Shape;
use subfit::mesh::PolyMesh;

const OUTPUTS: [&str; 9] = [
    "control.obj",
    "control.usda",
    "control.tags.json",
    "limit.ply",
    "error.ply",
    "log.csv",
    "preview.png",
    "report.html",
    "report.json",
];

/// Writes `cloud` as a binary PLY into `dir`.
fn save(dir: &Path, name: &str, cloud: &PolyMesh) -> PathBuf {
    let path = dir.join(name);
    let opts = WriteOptions {
        format: None,
        encoding: Encoding::BinaryLittleEndian,
        single_precision: false,
    };
    subfit::io::write_file(&path, cloud, &opts).unwrap();
    path
}

/// The paper's ellipsoid, 20k points with normals.
fn cloud(dir: &Path) -> PathBuf {
    save(
        dir,
        "ellipsoid.ply",
        &Shape::PAPER_ELLIPSOID.sample(20_000, 0.0, 3),
    )
}

/// 400k slightly noisy points without normals on a thin ellipsoid (semi-axes 0.25, 0.5,
/// 0.02): estimating and orienting the normals takes long (the orientation's field
/// refinement most of it: minutes in a debug build).
fn large_thin_cloud(dir: &Path) -> PathBuf {
    let shape = Shape::Ellipsoid {
        a: 0.25,
        b: 0.5,
        c: 0.02,
    };
    let s = shape.sample(400_000, 0.0005, 4);
    save(dir, "thin.ply", &PolyMesh::point_cloud(s.positions, None))
}

/// Runs `subfit ARGS`, interrupted by `sig` (`INT`, `TERM`) when `phase` starts.
fn run_interrupted(args: &[&str], phase: &str, sig: &str) -> Output {
    Command::new(env!("CARGO_BIN_EXE_subfit"))
        .args(args)
        .env("SUBFIT_INTERRUPT_AT", format!("{phase}:{sig}"))
        .env("SUBFIT_PHASE_LOG", "1")
        .output()
        .expect("run subfit")
}

/// Everything in `out` (names, hidden ones included), sorted.
fn listing(out: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(out)
        .map(|r| {
            r.flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// Interrupts `args` when it starts `phase`; checks that the phase was reached, exit 130 and
/// that `out` holds nothing but what `keep` names.
fn interrupt_in_phase(args: &[&str], phase: &str, sig: &str, out: &Path, keep: &[String]) {
    let run = run_interrupted(args, phase, sig);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains(&format!("subfit: phase: {phase}\n")),
        "the run never reached {phase:?}: {stderr}"
    );
    let how = if stderr.contains("did not stop in time") {
        "safety net"
    } else {
        "cancelled"
    };
    println!(
        "{} interrupted by SIG{sig} in {phase:?}: exit {:?} ({how})",
        args[0],
        run.status.code()
    );
    assert_eq!(run.status.code(), Some(130), "{stderr}");
    assert_eq!(listing(out), keep, "{stderr}");
}

#[test]
fn interrupted_while_fitting_exits_130_and_writes_nothing() {
    let d = tempfile::tempdir().unwrap();
    let cloud = cloud(d.path());
    let out = d.path().join("fit");
    let args = [
        "fit",
        cloud.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--control-points",
        "300",
        "--tolerance",
        "1e-7",
        "--max-control-points",
        "4000",
        "--max-iterations",
        "200",
    ];
    interrupt_in_phase(&args, "analysing the target", "INT", &out, &[]);
    interrupt_in_phase(&args, "building the initial control mesh", "INT", &out, &[]);
    interrupt_in_phase(&args, "fitting", "TERM", &out, &[]);
}

/// Interrupted once the outputs are being written into their staging directory: the output
/// directory ends up with none of them and nothing hidden or temporary, exit 130; a run that
/// is not interrupted writes all of them.
#[test]
fn interrupted_while_writing_leaves_no_outputs() {
    let d = tempfile::tempdir().unwrap();
    let cloud = cloud(d.path());
    let out = d.path().join("fit");
    let args = [
        "fit",
        cloud.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--control-points",
        "300",
        "--max-iterations",
        "2",
    ];
    interrupt_in_phase(&args, "writing the outputs", "INT", &out, &[]);
    let whole = Command::new(env!("CARGO_BIN_EXE_subfit"))
        .args(args)
        .output()
        .expect("run subfit");
    assert!(matches!(whole.status.code(), Some(0 | 1)), "{whole:?}");
    let mut all: Vec<String> = OUTPUTS.iter().map(|s| s.to_string()).collect();
    all.sort();
    assert_eq!(listing(&out), all);
}

/// A large cloud without normals, interrupted in each step of the target analysis (`fit`
/// when it starts analysing, `analyze` at the start of the per-point fits and of the
/// orientation): exit 130, nothing written.
#[test]
fn interrupted_during_the_analysis_of_a_large_cloud_exits_130() {
    let d = tempfile::tempdir().unwrap();
    let cloud = large_thin_cloud(d.path());
    let out = d.path().join("fit");
    let fit = ["fit", cloud.to_str().unwrap(), "-o", out.to_str().unwrap()];
    interrupt_in_phase(&fit, "analysing the target", "TERM", &out, &[]);

    let ply = d.path().join("analysis").join("points.ply");
    std::fs::create_dir_all(ply.parent().unwrap()).unwrap();
    let analyze = [
        "analyze",
        cloud.to_str().unwrap(),
        "-o",
        ply.to_str().unwrap(),
    ];
    let dir = ply.parent().unwrap();
    for phase in ["fitting normals and curvatures", "orienting normals"] {
        interrupt_in_phase(&analyze, phase, "TERM", dir, &[]);
    }
}
