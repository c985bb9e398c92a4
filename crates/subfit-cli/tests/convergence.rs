//! Cheng et al. 2007's convergence study through `subfit bench convergence`: assertions on
//! iteration counts (never on time).

use std::process::Command;

fn run_study() -> serde_json::Value {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("conv");
    let r = Command::new(env!("CARGO_BIN_EXE_subfit"))
        .args([
            "bench",
            "convergence",
            "-o",
            out.to_str().unwrap(),
            "--points",
            "12000",
        ])
        .args(["--iterations", "50", "--examples", "1,2,6,7,8,9,10"])
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    for n in [1, 2, 6, 7, 8, 9, 10] {
        let svg = std::fs::read_to_string(out.join(format!("example{n}.svg"))).unwrap();
        assert!(svg.contains("<polyline"));
        let csv = std::fs::read_to_string(out.join(format!("example{n}.csv"))).unwrap();
        assert!(csv.starts_with("iteration,"));
    }
    // One page with every example's curves, self-contained.
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(
        html.matches("<figure>").count() >= 1,
        "no plots in report.html"
    );
    assert!(!html.contains("src=\"http"));
    serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap()
}

fn find<'a>(s: &'a serde_json::Value, example: u64, run: &str) -> &'a serde_json::Value {
    s["runs"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["example"] == example && r["run"] == run)
        .unwrap_or_else(|| panic!("no run {run} in example {example}"))
}

#[test]
fn sdm_converges_fast_pdm_slowly_and_tdm_needs_step_control() {
    let s = run_study();
    let iters = |e, r| find(&s, e, r)["iterations_to_tolerance"].as_u64();
    // SDM and SDMLM reach E_rms < 0.002 within 10 iterations from the near (Examples 1, 8) and
    // far (Examples 2, 9, 10) meshes; so does SDM with Armijo step control.
    for (e, r) in [
        (1, "SDM"),
        (2, "SDM"),
        (8, "SDMLM"),
        (9, "SDMLM"),
        (10, "SDM"),
        (10, "SDMSC"),
    ] {
        let k = iters(e, r).unwrap_or_else(|| panic!("example {e} {r} did not converge"));
        assert!(k <= 10, "example {e} {r}: {k} iterations");
    }
    // PDM has not reached it after 50 iterations.
    for e in [1, 2, 10] {
        assert_eq!(iters(e, "PDM"), None, "example {e}: PDM converged");
        assert_eq!(find(&s, e, "PDM")["iterations"], 50);
    }
    // TDM without step control does not converge from the far mesh, or is not monotone ...
    let tdm = find(&s, 2, "TDM");
    assert!(
        tdm["iterations_to_tolerance"].is_null() || tdm["objective_monotone"] == false,
        "{tdm}"
    );
    // ... while TDMLM and TDMSC converge, and LM / Armijo never increase the objective.
    for (e, r) in [
        (6, "TDMLM"),
        (7, "TDMLM"),
        (8, "SDMLM"),
        (9, "SDMLM"),
        (10, "TDMSC"),
    ] {
        assert!(iters(e, r).is_some(), "example {e} {r} did not converge");
        assert_eq!(
            find(&s, e, r)["objective_monotone"],
            true,
            "example {e} {r}"
        );
    }
}
