//! `subfit fit --optimizer adam|lbfgs`: the first-order path runs end to end,
//! is recorded in report.json, lowers the error, and a bad step size is a usage error.

mod common;

use common::subfit;

#[test]
fn first_order_optimizers_fit_and_are_reported() {
    let d = tempfile::tempdir().unwrap();
    let demo = d.path().join("demo");
    let dir = demo.to_str().unwrap();
    assert!(subfit(&["demo", "-o", dir, "--points", "4000", "--no-fit"])
        .status
        .success());
    let target = demo.join("ellipsoid.ply");
    for (name, reported) in [("adam", "Adam"), ("lbfgs", "Lbfgs")] {
        let out = d.path().join(name);
        let r = subfit(&[
            "fit",
            target.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--control-points",
            "60",
            "--no-refine",
            "--max-iterations",
            "6",
            "--optimizer",
            name,
            "--learning-rate",
            "2e-3",
        ]);
        let stderr = String::from_utf8_lossy(&r.stderr);
        // 0: tolerance reached; 1: written without reaching it.
        assert!(matches!(r.status.code(), Some(0 | 1)), "{name}: {stderr}");
        let report: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
        assert_eq!(report["options"]["optimizer"], reported);
        let e0 = report["initial"]["e_rms"].as_f64().unwrap();
        let e1 = report["final"]["e_rms"].as_f64().unwrap();
        assert!(e1 < 0.8 * e0, "{name}: E_rms {e0:e} → {e1:e}");
    }
    let out = d.path().join("bad");
    let r = subfit(&[
        "fit",
        target.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--optimizer",
        "adam",
        "--learning-rate",
        "0",
    ]);
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("learning_rate"), "{stderr}");
    assert!(!out.join("control.obj").exists());
}
