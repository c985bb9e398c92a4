//! An interrupted `subfit fit` (SIGINT, SIGTERM) exits with 130 and leaves no partial output:
//! neither a half-written file, nor a temporary one, nor a mix of new and old outputs.
#![cfg(unix)]
#![allow(clippy::print_stdout)]

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use subfit::io::{Encoding, WriteOptions};
use subfit::mesh::shapes::Shape;

const OUTPUTS: [&str; 6] = [
    "control.obj",
    "control.usda",
    "limit.ply",
    "error.ply",
    "log.csv",
    "report.json",
];

fn cloud(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("ellipsoid.ply");
    let opts = WriteOptions {
        format: None,
        encoding: Encoding::BinaryLittleEndian,
        single_precision: false,
    };
    let pts = Shape::PAPER_ELLIPSOID.sample(20_000, 0.0, 3);
    subfit::io::write_file(&path, &pts, &opts).unwrap();
    path
}

fn start_fit(cloud: &Path, out: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_subfit"))
        .args(["fit", cloud.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .args(["--control-points", "300", "--tolerance", "1e-7"])
        .args(["--max-control-points", "4000", "--max-iterations", "200"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run subfit")
}

fn signal(child: &Child, sig: &str) {
    let ok = Command::new("kill")
        .args([sig, &child.id().to_string()])
        .status()
        .expect("run kill")
        .success();
    assert!(ok, "kill {sig} failed");
}

/// Everything in `out` (names), sorted.
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

#[test]
fn interrupted_while_fitting_exits_130_and_writes_nothing() {
    let d = tempfile::tempdir().unwrap();
    let cloud = cloud(d.path());
    let out = d.path().join("fit");
    let mut child = start_fit(&cloud, &out);
    std::thread::sleep(Duration::from_millis(1500));
    signal(&child, "-TERM");
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "{status:?}");
    assert!(listing(&out).is_empty(), "{:?}", listing(&out));
}

/// Interrupted as soon as the outputs are being written (their staging directory appears):
/// either the run is stopped before the outputs are moved into place, and none is there, or it
/// had already finished, and all are there.
#[test]
fn interrupted_while_writing_leaves_all_outputs_or_none() {
    let d = tempfile::tempdir().unwrap();
    let cloud = cloud(d.path());
    let out = d.path().join("fit");
    // A short run, so that the output phase comes soon.
    let mut child = Command::new(env!("CARGO_BIN_EXE_subfit"))
        .args(["fit", cloud.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .args(["--control-points", "300", "--max-iterations", "2"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run subfit");
    let staging = out.join(format!(".subfit-{}", child.id()));
    let t0 = Instant::now();
    let mut seen = false;
    while t0.elapsed() < Duration::from_secs(600) {
        if staging.exists() {
            seen = true;
            signal(&child, "-INT");
            break;
        }
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    let status = child.wait().unwrap();
    let files = listing(&out);
    println!("staging seen: {seen}, exit {:?}", status.code());
    if status.code() == Some(130) {
        assert!(seen);
        assert!(files.is_empty(), "{files:?}");
    } else {
        // Finished before the signal: a complete set, nothing temporary.
        assert!(matches!(status.code(), Some(0 | 1)), "{status:?}");
        let mut all: Vec<String> = OUTPUTS.iter().map(|s| s.to_string()).collect();
        all.sort();
        assert_eq!(files, all);
    }
}
