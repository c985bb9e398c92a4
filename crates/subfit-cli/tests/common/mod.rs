//! Helpers shared by the CLI integration tests (each test file uses a subset).
#![allow(dead_code, clippy::print_stdout)]

use std::path::PathBuf;
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
