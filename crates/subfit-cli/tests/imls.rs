//! `subfit fit --method imls` (Xie et al. 2023 §4.1) end to end: a generated ellipsoid cloud to
//! the two-sided tolerance with ARAP on, the options recorded in report.json, flag validation,
//! and (with `$SUBFIT_DATA`) the bunny's points at Xie et al. Fig. 13's fixed 314 control points
//! against SDM at the same count.
//!
//! Without `SUBFIT_DATA` the bunny test fails when `CI=true`, else prints a notice and passes.
#![allow(clippy::print_stdout)]

mod common;

use std::path::Path;

use common::{data_dir, subfit};
use subfit::io::{Encoding, WriteOptions};
use subfit::mesh::shapes::Shape;

fn report(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap()
}

fn ellipsoid_cloud(dir: &Path) -> std::path::PathBuf {
    let cloud = dir.join("ellipsoid.ply");
    let opts = WriteOptions {
        format: None,
        encoding: Encoding::BinaryLittleEndian,
        single_precision: false,
    };
    let mesh = Shape::PAPER_ELLIPSOID.sample(20_000, 0.0, 3);
    subfit::io::write_file(&cloud, &mesh, &opts).unwrap();
    cloud
}

#[test]
fn imls_with_arap_fits_an_ellipsoid_cloud_to_the_two_sided_tolerance() {
    let d = tempfile::tempdir().unwrap();
    let cloud = ellipsoid_cloud(d.path());
    let out = d.path().join("fit");
    let r = subfit(&[
        "fit",
        cloud.to_str().unwrap(),
        "--method",
        "imls",
        "--imls-radius",
        "0.03",
        "--arap",
        "0.0001",
        "--control-points",
        "40",
        "--tolerance",
        "0.002",
        "--sample-level",
        "2",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let rep = report(&out);
    assert_eq!(rep["options"]["method"], "IMLS");
    assert_eq!(rep["options"]["imls_radius"].as_f64(), Some(0.03));
    assert_eq!(rep["options"]["arap"].as_f64(), Some(0.0001));
    assert!(
        rep["tolerance_reached_two_sided"].as_bool().unwrap(),
        "{rep}"
    );
    let e = rep["final"]["e_rms"].as_f64().unwrap();
    assert!(e <= 0.002, "{e}");
}

#[test]
fn imls_flags_are_validated_before_any_work() {
    let d = tempfile::tempdir().unwrap();
    let cloud = ellipsoid_cloud(d.path());
    let out = d.path().join("fit");
    for flags in [
        &["--imls-radius", "0.01"][..],
        &["--method", "imls", "--imls-radius", "0"],
        &["--method", "imls", "--imls-radius", "2"],
        &["--arap=-1"],
        &["--arap", "nan"],
    ] {
        let mut args = vec!["fit", cloud.to_str().unwrap(), "-o", out.to_str().unwrap()];
        args.extend_from_slice(flags);
        let r = subfit(&args);
        assert_eq!(
            r.status.code(),
            Some(2),
            "{flags:?}: {}",
            String::from_utf8_lossy(&r.stderr)
        );
        assert!(!out.exists(), "{flags:?} wrote outputs");
    }
}

/// Xie et al. Fig. 13's static setting: the bunny's points without normals, a fixed 314 control
/// points. IMLS and SDM both fit it (the pipeline measures both with the same foot points and
/// data → surface distances); neither may be more than 30 % worse than the other two-sided, and
/// both reach the two-sided RMS of 3e-3 of the diagonal. The cage is open: the mesh's
/// holes are known, so the init keeps the trimmed contour instead of a closed wrap. Measured:
/// IMLS 1.16e-3, SDM 1.15e-3 of the diagonal (3.2e-3 and 3.4e-3 unit cube with the closed wrap).
#[test]
fn bunny_points_at_314_control_points_by_imls_and_sdm() {
    let Some(data) = data_dir() else { return };
    let bunny = data.join("stanford-bunny.obj");
    let d = tempfile::tempdir().unwrap();
    let mut two = Vec::new();
    for method in ["imls", "sdm"] {
        let out = d.path().join(method);
        let r = subfit(&[
            "fit",
            bunny.to_str().unwrap(),
            "--as-points",
            "--method",
            method,
            "--control-points",
            "314",
            "--max-control-points",
            "314",
            "-o",
            out.to_str().unwrap(),
        ]);
        // The default tolerance (5e-4) is out of reach of 314 control points: exit code 1.
        assert_eq!(
            r.status.code(),
            Some(1),
            "{method}: {}",
            String::from_utf8_lossy(&r.stderr)
        );
        let rep = report(&out);
        assert_eq!(rep["control_points"].as_u64(), Some(314));
        let e = rep["final"]["two_sided"]["e_rms"].as_f64().unwrap();
        let fraction = rep["final"]["two_sided"]["e_rms_fraction_of_diagonal"]
            .as_f64()
            .unwrap();
        println!("bunny 314, {method}: two-sided E_rms {e:.3e} ({fraction:.2e} of the diagonal)");
        assert!(fraction <= 3e-3, "{method}: {fraction}");
        assert_eq!(rep["init"]["cloud_open"], true, "{method}: {}", rep["init"]);
        two.push(e);
    }
    assert!(two[0] < 1.3 * two[1] && two[1] < 1.3 * two[0], "{two:?}");
}
