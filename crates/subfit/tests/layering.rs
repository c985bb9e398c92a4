//! The crates' layering (DESIGN.md §2): the fit engine and the measurer build without the
//! report crate (and so without npm), and the report's three.js bundling is an opt-in cargo
//! feature that only the crates writing report.html turn on.

use std::path::PathBuf;

fn manifest(krate: &str) -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(krate)
        .join("Cargo.toml");
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The names of the `[dependencies]` and `[dev-dependencies]` of a manifest.
fn dependencies(text: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut inside = false;
    for line in text.lines().map(str::trim) {
        if line.starts_with('[') {
            inside = line == "[dependencies]" || line == "[dev-dependencies]";
        } else if inside && !line.is_empty() && !line.starts_with('#') {
            if let Some((name, _)) = line.split_once(['=', '.']) {
                names.push(name.trim().to_string());
            }
        }
    }
    names
}

#[test]
fn the_fit_engine_and_the_measurer_do_not_depend_on_the_report() {
    for krate in ["subfit-fit", "subfit-measure"] {
        let deps = dependencies(&manifest(krate));
        assert!(!deps.is_empty(), "{krate}: no dependencies read");
        assert!(
            !deps.iter().any(|d| d == "subfit-report"),
            "{krate} depends on subfit-report: {deps:?}"
        );
    }
    assert!(dependencies(&manifest("subfit-fit")).contains(&"subfit-measure".to_string()));
}

#[test]
fn the_viewer_bundle_is_an_opt_in_feature() {
    let report = manifest("subfit-report");
    assert!(
        report.contains("\nviewer = []"),
        "subfit-report has no `viewer` feature"
    );
    assert!(
        !report.contains("default = ["),
        "a default feature would bundle by default"
    );
    assert!(manifest("subfit").contains("viewer = [\"subfit-report/viewer\"]"));
    assert!(manifest("subfit-cli").contains("features = [\"viewer\"]"));
}
