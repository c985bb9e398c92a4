//! Helpers shared by the CLI integration tests (each test file uses a subset).
#![allow(dead_code, clippy::print_stdout)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the `subfit` binary built for these tests.
pub fn subfit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_subfit"))
        .args(args)
        .output()
        .expect("run subfit")
}

/// The shared data directory from `SUBFIT_DATA`. Without it: a failure when `CI=true` (CI must
/// run these tests), else a printed notice and `None` (the caller returns early).
pub fn data_dir() -> Option<PathBuf> {
    match std::env::var_os("SUBFIT_DATA") {
        Some(d) => Some(PathBuf::from(d)),
        None => {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "SUBFIT_DATA is not set (needed on CI: the directory of shared/data)"
            );
            println!("notice: SUBFIT_DATA not set, skipping a test that needs the shared data");
            None
        }
    }
}

/// The corpus of real models from `SUBFIT_CORPUS` (`shared/corpus`), as [`data_dir`] does for
/// `SUBFIT_DATA`: a failure when `CI=true`, else a printed notice and `None`.
pub fn corpus_dir() -> Option<PathBuf> {
    match std::env::var_os("SUBFIT_CORPUS") {
        Some(d) => Some(PathBuf::from(d)),
        None => {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "SUBFIT_CORPUS is not set (needed on CI: the directory of shared/corpus)"
            );
            println!("notice: SUBFIT_CORPUS not set, skipping a test that needs the corpus");
            None
        }
    }
}

pub fn checks() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/checks")
}

/// Where screenshots are kept for CI to collect: `SUBFIT_ARTIFACTS`, else `target/artifacts`.
pub fn artifacts() -> PathBuf {
    std::env::var_os("SUBFIT_ARTIFACTS")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_TARGET_TMPDIR")).join("../artifacts"))
}

/// Whether `python3` can import `module` (and, for the browser, Chromium is installed); a
/// failure under `CI=true`, where `.ci/run` installs them.
pub fn available(module: &str, program: Option<&str>) -> bool {
    let imports = Command::new("python3")
        .args(["-c", &format!("import {module}")])
        .output()
        .is_ok_and(|o| o.status.success());
    let program_ok = program.is_none_or(|p| Path::new(p).exists());
    if imports && program_ok {
        return true;
    }
    let what = format!(
        "python3 module {module}{}",
        program.map(|p| format!(" and {p}")).unwrap_or_default()
    );
    assert!(
        std::env::var("CI").as_deref() != Ok("true"),
        "CI=true but {what} is missing (.ci/run installs it)"
    );
    println!("notice: {what} not installed; skipping this check");
    false
}

/// Runs a check script; panics with its output when it fails.
pub fn run_check(script: &str, args: &[&str]) -> serde_json::Value {
    let out = Command::new("python3")
        .arg(checks().join(script))
        .args(args)
        .output()
        .expect("run python3");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{script} failed ({}):\n{stdout}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let line = stdout
        .lines()
        .rev()
        .find(|l| l.starts_with('{'))
        .unwrap_or("{}");
    println!("{script}: {line}");
    serde_json::from_str(line).expect("the check prints JSON")
}
