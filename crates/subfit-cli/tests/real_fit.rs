//! `subfit fit` on the real models of `$SUBFIT_DATA` (DESIGN.md §5): Igea as a point cloud and
//! the rocker arm against Cheng 2007 Table IV, genus kept through fitting on fertility (genus 4)
//! and the armadillo with E_rms ≤ 0.001,
//! and the fitted limit surface against our own QEM simplification at the same vertex count.
//!
//! Without `SUBFIT_DATA`: fails when `CI=true`, else prints a notice and passes.
#![allow(clippy::print_stdout)]

mod common;

use std::path::Path;
use std::process::Output;

use common::{artifacts, available, data_dir, run_check, subfit};

fn json_of(out: &Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)))
}

fn report(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap()
}

/// Runs `subfit fit TARGET FLAGS -o OUT`, requires exit code 0, and returns report.json with
/// its final `(E_rms, E_max)` and control-point count.
fn fit_ok(target: &Path, flags: &[&str], out: &Path) -> (serde_json::Value, f64, f64, u64) {
    let mut args = vec!["fit", target.to_str().unwrap()];
    args.extend_from_slice(flags);
    args.extend_from_slice(&["-o", out.to_str().unwrap()]);
    let r = subfit(&args);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}: {}",
        target.display(),
        String::from_utf8_lossy(&r.stderr)
    );
    let rep = report(out);
    let e_rms = rep["final"]["e_rms"].as_f64().unwrap();
    let e_max = rep["final"]["e_max"].as_f64().unwrap();
    let n = rep["control_points"].as_u64().unwrap();
    (rep, e_rms, e_max, n)
}

fn cage_topology(dir: &Path) -> serde_json::Value {
    let info = subfit(&["info", "--json", dir.join("control.obj").to_str().unwrap()]);
    json_of(&info)["topology"].clone()
}

/// Cheng 2007 Table IV's Igea row, from the scan's points alone: E_rms ≤ 0.0005 and
/// E_max ≤ 0.0036 (unit cube, the fitter's own foot points) with ≤ 2,385 control points. Then an
/// independent check against the exact distance from the limit surface to Igea's triangles,
/// which the fit never saw: its RMS (area-weighted) within 10 % of the fit's own area-weighted
/// surface → data RMS (Cheng's E_rms counts every limit sample alike, as the fit's E_rms does:
/// 3.8e-4, where area-weighted both measure 5.6e-4); the maximum is bounded by scanner debris
/// at the base rim and a crevice under the chin that the triangles bridge (measured 0.0036 to
/// 0.0043 over stage lengths and depths; bounded here by 0.005).
#[test]
fn igea_as_a_point_cloud_reaches_table_iv_within_its_control_point_budget() {
    let Some(data) = data_dir() else { return };
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("igea");
    let igea = data.join("igea.ply");
    // Table IV's figures are Cheng's surface → data measure: judged so here (`--one-sided`),
    // both directions reported. Both ways, E_max stays above 0.0036 (4.2e-3 at the budget):
    // scan points at the bottom of a pit near the chin that the surface bridges (the foot
    // points blend across the gap; data → surface sees it). The two-sided RMS tolerance is
    // checked by a second fit below.
    let flags = [
        "--as-points",
        "--tolerance",
        "0.0005",
        "--max-error",
        "0.0036",
        "--max-control-points",
        "2385",
        "--one-sided",
    ];
    let (rep, e_rms, e_max, n) = fit_ok(&igea, &flags, &out);
    let two = &rep["final"]["two_sided"];
    let (r2, m2) = (
        two["e_rms"].as_f64().unwrap(),
        two["e_max"].as_f64().unwrap(),
    );
    println!("igea (points): {n} control points, E_rms {e_rms:.3e}, E_max {e_max:.3e}; two-sided E_rms {r2:.3e}, E_max {m2:.3e}");
    assert!(e_rms <= 0.0005, "{e_rms}");
    assert!(e_max <= 0.0036, "{e_max}");
    assert!(n <= 2385, "{n}");
    assert_eq!(rep["init"]["source"], "Contour");
    // Both ways (the default), Table IV's E_rms within the same budget.
    let both = d.path().join("igea-two-sided");
    let flags2 = [
        "--as-points",
        "--tolerance",
        "0.0005",
        "--max-control-points",
        "2385",
    ];
    let (rep2, _, _, n2) = fit_ok(&igea, &flags2, &both);
    let two2 = &rep2["final"]["two_sided"];
    let r22 = two2["e_rms"].as_f64().unwrap();
    println!(
        "igea (points, two-sided): {n2} control points, two-sided E_rms {r22:.3e} (surface → data {:.3e}, data → surface {:.3e})",
        two2["surface_to_data"]["rms"].as_f64().unwrap(),
        two2["data_to_surface"]["rms"].as_f64().unwrap()
    );
    assert!(r22 <= 0.0005, "two-sided E_rms {r22}");
    assert!(n2 <= 2385, "{n2}");
    // Its report.html stays small enough to mail and opens quickly (the time is printed, not
    // asserted: it depends on the machine).
    let html = both.join("report.html");
    let bytes = std::fs::metadata(&html).unwrap().len();
    println!("igea report.html: {:.1} MB", bytes as f64 / 1e6);
    assert!(bytes < 30_000_000, "report.html is {bytes} bytes");
    if available("playwright", Some("/usr/bin/chromium")) {
        let shot = artifacts().join("report-igea.png");
        let result = run_check(
            "browser_report.py",
            &[
                html.to_str().unwrap(),
                "--screenshot",
                shot.to_str().unwrap(),
            ],
        );
        println!(
            "igea report.html opened in {} s in headless Chromium (screenshot {})",
            result["open_s"],
            shot.display()
        );
    }
    let topo = cage_topology(&out);
    assert_eq!(topo["genus"], 0, "{topo}");
    assert_eq!(topo["manifold"], true, "{topo}");
    assert_eq!(topo["closed"], true, "{topo}");

    // Exact limit samples against the scan's triangles, in the scan's units.
    let c = subfit(&[
        "compare",
        out.join("control.obj").to_str().unwrap(),
        igea.to_str().unwrap(),
        "--scheme",
        "auto",
        "--samples",
        "20000",
        "--json",
    ]);
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
    let j = json_of(&c);
    let unit = rep["normalized_unit_in_original_units"].as_f64().unwrap();
    let (rms, max) = (
        j["a_to_b"]["rms"].as_f64().unwrap() / unit,
        j["a_to_b"]["max"].as_f64().unwrap() / unit,
    );
    // The fit's own surface → data figures, area-weighted as compare's are.
    let s2d = &rep["final"]["two_sided"]["surface_to_data"];
    let (own_rms, own_max) = (s2d["rms"].as_f64().unwrap(), s2d["max"].as_f64().unwrap());
    println!("igea (points): exact distance to the triangles RMS {rms:.3e}, max {max:.3e}; the fit's own surface -> points RMS {own_rms:.3e}, max {own_max:.3e}");
    assert!(rms <= 1.1 * own_rms, "{rms} vs {own_rms}");
    assert!(max <= 0.005, "{max}");
}

/// Cheng 2007 Table IV's rocker arm row (genus 1): E_rms ≤ 0.0003, E_max ≤ 0.0029 with ≤ 950
/// control points, the genus kept — reached both ways (the default), the data → surface
/// maximum taken over every input vertex as well as the area samples.
#[test]
fn rocker_arm_reaches_table_iv_within_its_control_point_budget() {
    let Some(data) = data_dir() else { return };
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("rocker");
    // Fitted one-sided (`--one-sided`, Cheng's measure) the fit stops at 780 control points
    // with surface → data within Table IV but an input vertex 4.2e-3 from the surface: the
    // two-sided fit is the one that reaches the table's figures as a user measures them.
    let flags = [
        "--tolerance",
        "0.0003",
        "--max-error",
        "0.0029",
        "--max-control-points",
        "950",
    ];
    let (rep, e_rms, e_max, n) = fit_ok(&data.join("rocker-arm.off"), &flags, &out);
    let two = &rep["final"]["two_sided"];
    let (r2, m2) = (
        two["e_rms"].as_f64().unwrap(),
        two["e_max"].as_f64().unwrap(),
    );
    println!("rocker-arm: {n} control points, E_rms {e_rms:.3e}, E_max {e_max:.3e}; two-sided E_rms {r2:.3e}, E_max {m2:.3e}");
    assert!(e_rms <= 0.0003, "{e_rms}");
    assert!(e_max <= 0.0029, "{e_max}");
    assert!(n <= 950, "{n}");
    assert!(r2 <= 0.0003, "two-sided {r2}");
    assert!(m2 <= 0.0029, "two-sided {m2}");
    let topo = cage_topology(&out);
    assert_eq!(topo["genus"], 1, "{topo}");
    assert_eq!(topo["manifold"], true, "{topo}");
}

#[test]
fn fitting_keeps_the_genus_of_fertility_and_the_armadillo() {
    let Some(data) = data_dir() else { return };
    let d = tempfile::tempdir().unwrap();
    for (file, genus) in [("fertility.off", 4), ("armadillo.obj", 0)] {
        let out = d.path().join(file);
        let flags = ["--tolerance", "0.001", "--max-control-points", "1500"];
        let (_, e_rms, _, n) = fit_ok(&data.join(file), &flags, &out);
        println!("{file}: {n} control points, E_rms {e_rms:.3e}");
        assert!(e_rms <= 0.001, "{file}: {e_rms}");
        let topo = cage_topology(&out);
        assert_eq!(topo["genus"], genus, "{file}: {topo}");
        assert_eq!(topo["manifold"], true, "{file}: {topo}");
        assert_eq!(topo["boundary_loops"], 0, "{file}: {topo}");
    }
}

#[test]
fn the_fitted_limit_surface_beats_qem_simplification_at_equal_vertex_count() {
    let Some(data) = data_dir() else { return };
    let d = tempfile::tempdir().unwrap();
    for file in ["bunny.off", "armadillo.obj"] {
        let target = data.join(file);
        let qem = d.path().join(format!("{file}.qem.obj"));
        let r = subfit(&[
            "init",
            target.to_str().unwrap(),
            "--control-points",
            "300",
            "-o",
            qem.to_str().unwrap(),
        ]);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        // The QEM mesh is the initial cage; fit it without changing its connectivity.
        let out = d.path().join(format!("{file}.fit"));
        let r = subfit(&[
            "fit",
            target.to_str().unwrap(),
            "--init",
            qem.to_str().unwrap(),
            "--no-refine",
            "--tolerance",
            "0.00001",
            "--max-iterations",
            "12",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(
            matches!(r.status.code(), Some(0 | 1)),
            "{}",
            String::from_utf8_lossy(&r.stderr)
        );
        assert_eq!(report(&out)["control_points"], 300);
        let compare = |a: &Path| -> f64 {
            let r = subfit(&[
                "compare",
                a.to_str().unwrap(),
                target.to_str().unwrap(),
                "--json",
            ]);
            json_of(&r)["two_sided_rms"].as_f64().unwrap()
        };
        let (e_fit, e_qem) = (compare(&out.join("limit.ply")), compare(&qem));
        println!("{file}: two-sided RMS, limit of the fitted 300-point cage {e_fit:.3e}, QEM 300 vertices {e_qem:.3e}");
        assert!(e_fit < e_qem, "{file}: {e_fit} vs {e_qem}");
    }
}
