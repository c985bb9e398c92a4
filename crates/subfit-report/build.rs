//! Bundles the report's 3-D viewer (`viewer/src/main.js`, three.js from npm with its orbit
//! controls) into one minified script that `src/html.rs` inlines into every report.html, so
//! a report needs no network when it is opened.
//!
//! The npm packages are pinned by `viewer/package-lock.json` and installed with `npm ci` into
//! `OUT_DIR` (never into the source tree); esbuild, one of those packages, bundles them.
//! `SUBFIT_VIEWER_JS=FILE` takes an already bundled script instead (an offline build).
//! Without Node.js/npm the crate still builds: the viewer is replaced by a script that says
//! so on the page, and `subfit_report::html::VIEWER_BUILT` is false — except under `CI=true`,
//! where a missing viewer is a build error.
//!
//! All of this only with the cargo feature `viewer` (turned on by the crates that write
//! report.html: the CLI and the Python package). Without it the build runs no npm and the
//! page says the viewer was not built in: the fit engine and the library build without Node.js.

use std::env;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

fn main() {
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets it"));
    let viewer = manifest.join("viewer");
    for file in ["src/main.js", "package.json", "package-lock.json"] {
        println!("cargo:rerun-if-changed=viewer/{file}");
    }
    println!("cargo:rerun-if-env-changed=SUBFIT_VIEWER_JS");
    let target = out.join("viewer.js");
    let bundled = if env::var_os("CARGO_FEATURE_VIEWER").is_some() {
        bundle(&viewer, &out, &target)
    } else {
        Err("the cargo feature `viewer` of subfit-report was off".to_string())
    };
    let built = match bundled {
        Ok(()) => true,
        Err(why) => {
            let asked = env::var_os("CARGO_FEATURE_VIEWER").is_some();
            if asked && env::var("CI").is_ok_and(|v| v == "true") {
                panic!("the report viewer could not be bundled (CI=true): {why}");
            }
            if asked {
                println!("cargo:warning=report.html will have no 3-D viewer: {why}");
            }
            let note = format!(
                "window.SUBFIT_VIEWER_MISSING = {:?};",
                if asked {
                    format!("This subfit was built without its 3-D viewer ({why}); install Node.js and npm and rebuild.")
                } else {
                    format!(
                        "This subfit was built without its 3-D viewer ({why}); rebuild with it on."
                    )
                }
            );
            fs::write(&target, note).expect("OUT_DIR is writable");
            false
        }
    };
    fs::write(
        out.join("viewer_built.rs"),
        format!("/// Whether the 3-D viewer was bundled into this build.\npub const VIEWER_BUILT: bool = {built};\n"),
    )
    .expect("OUT_DIR is writable");
}

fn bundle(viewer: &Path, out: &Path, target: &Path) -> Result<(), String> {
    if let Some(given) = env::var_os("SUBFIT_VIEWER_JS") {
        fs::copy(&given, target)
            .map_err(|e| format!("SUBFIT_VIEWER_JS={}: {e}", Path::new(&given).display()))?;
        return Ok(());
    }
    let work = out.join("viewer-npm");
    fs::create_dir_all(&work).map_err(|e| e.to_string())?;
    let lock = fs::read(viewer.join("package-lock.json")).map_err(|e| e.to_string())?;
    let installed = work.join("package-lock.json");
    let esbuild = work.join("node_modules/.bin/esbuild");
    if fs::read(&installed).ok().as_deref() != Some(&lock[..]) || !esbuild.exists() {
        fs::copy(viewer.join("package.json"), work.join("package.json"))
            .map_err(|e| e.to_string())?;
        fs::write(&installed, &lock).map_err(|e| e.to_string())?;
        run(Command::new(npm())
            .args(["ci", "--no-audit", "--no-fund", "--loglevel=error"])
            .current_dir(&work))?;
    }
    // Bundled from a copy beside the installed packages, so `three` resolves there.
    let entry = work.join("main.js");
    fs::copy(viewer.join("src/main.js"), &entry).map_err(|e| e.to_string())?;
    run(Command::new(&esbuild)
        .arg(&entry)
        .args([
            "--bundle",
            "--minify",
            "--format=iife",
            "--target=es2020",
            "--legal-comments=inline",
            "--log-level=warning",
        ])
        .arg(format!("--outfile={}", target.display()))
        .current_dir(&work))
}

fn npm() -> &'static str {
    if cfg!(windows) {
        "npm.cmd"
    } else {
        "npm"
    }
}

fn run(command: &mut Command) -> Result<(), String> {
    let shown = format!("{command:?}");
    let output = command
        .output()
        .map_err(|e| format!("cannot run {shown}: {e}"))?;
    if output.status.success() {
        Ok(())
    } else {
        Err(format!(
            "{shown} failed ({}): {}",
            output.status,
            String::from_utf8_lossy(&output.stderr).trim()
        ))
    }
}
