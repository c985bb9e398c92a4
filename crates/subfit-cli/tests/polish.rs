//! `subfit fit --polish-power P`: the last stage polishes the best cage towards a lower maximum
//! error by default (report.json: the last stage's `polish_kept`, `options.polish_power`), 2
//! turns it off, and a power outside [2, 8] is a usage error.

mod common;

use common::subfit;

#[test]
fn the_max_error_polish_is_on_by_default_and_can_be_turned_off() {
    let d = tempfile::tempdir().unwrap();
    let demo = d.path().join("demo");
    assert!(subfit(&[
        "demo",
        "-o",
        demo.to_str().unwrap(),
        "--points",
        "4000",
        "--no-fit"
    ])
    .status
    .success());
    let target = demo.join("ellipsoid.ply");
    let fit = |name: &str, extra: &[&str]| {
        let out = d.path().join(name);
        let mut args = vec![
            "fit",
            target.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--control-points",
            "40",
            "--max-control-points",
            "40",
        ];
        args.extend_from_slice(extra);
        let r = subfit(&args);
        assert!(
            matches!(r.status.code(), Some(0 | 1)),
            "{name}: {}",
            String::from_utf8_lossy(&r.stderr)
        );
        let report: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
        let said =
            String::from_utf8_lossy(&r.stdout).to_string() + &String::from_utf8_lossy(&r.stderr);
        (report, said)
    };
    let (on, said) = fit("on", &[]);
    assert_eq!(on["options"]["polish_power"], 3.0);
    let stages = on["stages"].as_array().unwrap();
    assert!(
        stages.last().unwrap()["polish_kept"].is_boolean(),
        "{stages:?}"
    );
    assert!(stages[..stages.len() - 1]
        .iter()
        .all(|s| s.get("polish_kept").is_none()));
    assert!(said.contains("max-error polish"), "{said}");
    let (off, said) = fit("off", &["--polish-power", "2"]);
    assert_eq!(off["options"]["polish_power"], 2.0);
    assert!(off["stages"]
        .as_array()
        .unwrap()
        .iter()
        .all(|s| s.get("polish_kept").is_none()));
    assert!(!said.contains("polish"), "{said}");
    let bad = d.path().join("bad");
    let r = subfit(&[
        "fit",
        target.to_str().unwrap(),
        "-o",
        bad.to_str().unwrap(),
        "--polish-power",
        "1.5",
    ]);
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("polish-power"), "{stderr}");
    assert!(!bad.join("control.obj").exists());
}
