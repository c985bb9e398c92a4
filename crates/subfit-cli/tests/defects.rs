//! Regression tests of defects found by trying `subfit fit` as a new user: a worse cage written
//! than the one reached, budgets not honoured, success judged one way only, messy meshes
//! refused.
#![allow(clippy::print_stdout)]

mod common;

use std::path::Path;

use common::subfit;
use subfit::io::{Encoding, WriteOptions};
use subfit::mesh::shapes::{cheng_ellipsoid_cage, Shape};
use subfit::mesh::PolyMesh;

fn save(path: &Path, mesh: &PolyMesh, encoding: Encoding) {
    let opts = WriteOptions {
        format: None,
        encoding,
        single_precision: false,
    };
    subfit::io::write_file(path, mesh, &opts).unwrap();
}

fn report(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap()
}

/// RMS and max of the distance of `points` (original units) to the paper's ellipsoid, to
/// first order (`|F| / |∇F|` with `F = x²/a² + y²/b² + z²/c² − 1`; exact to O(d²)).
fn ellipsoid_distance(points: &[[f64; 3]]) -> (f64, f64) {
    let (a, b, c) = (0.25f64, 0.5f64, 1.0f64);
    let d: Vec<f64> = points
        .iter()
        .map(|p| {
            let f = (p[0] / a).powi(2) + (p[1] / b).powi(2) + (p[2] / c).powi(2) - 1.0;
            let g = [
                2.0 * p[0] / (a * a),
                2.0 * p[1] / (b * b),
                2.0 * p[2] / (c * c),
            ];
            f.abs() / (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt()
        })
        .collect();
    let rms = (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt();
    (rms, d.iter().fold(0.0f64, |m, &x| m.max(x)))
}

/// Defect 1: with 10 iterations the run used to end right after a refinement and write the
/// refined, unoptimized cage (E_rms 6.0e-3 reported, 4.4e-3 measured) although 7.2e-4 had
/// been reached. Now the best cage measured is written, no refinement is made without an
/// iteration left to fit it, and the written cage's error is confirmed against the analytic
/// ellipsoid.
#[test]
fn the_best_cage_is_written_when_the_iteration_budget_ends() {
    let d = tempfile::tempdir().unwrap();
    let cloud = d.path().join("ellipsoid.ply");
    save(
        &cloud,
        &Shape::PAPER_ELLIPSOID.sample(20_000, 0.0, 3),
        Encoding::BinaryLittleEndian,
    );
    let cage = d.path().join("cage.obj");
    save(
        &cage,
        &cheng_ellipsoid_cage(0.25, 0.5, 1.0, false),
        Encoding::Ascii,
    );
    let out = d.path().join("fit");
    let r = subfit(&[
        "fit",
        cloud.to_str().unwrap(),
        "--init",
        cage.to_str().unwrap(),
        "--method",
        "sdm",
        "--step",
        "lm",
        "--lambda",
        "0",
        "--max-iterations",
        "10",
        "-o",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert!(matches!(r.status.code(), Some(0 | 1)), "{stderr}");
    let rep = report(&out);
    let e = rep["final"]["e_rms"].as_f64().unwrap();
    assert!(e < 0.002, "E_rms {e}: {rep}");
    let iterations = rep["iterations"].as_array().unwrap().len();
    assert!(iterations <= 10, "{iterations} iterations");
    let stages = rep["stages"].as_array().unwrap();
    assert!(stages.len() >= 2, "refinement is on: {stages:?}");
    // The cage written has been fitted: it is the best stage's, and the last stage did not
    // refine (no iteration was left for new points).
    let best = rep["best_stage"].as_u64().unwrap() as usize;
    assert!(stages[best]["iterations"].as_u64().unwrap() > 0);
    assert!(stages.last().unwrap()["refine"].is_null(), "{stages:?}");
    let (cage_out, _) = subfit::io::read_file(
        &out.join("control.obj"),
        &subfit::io::ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(
        cage_out.num_vertices() as u64,
        stages[best]["control_points"].as_u64().unwrap()
    );
    // Independent check on the limit tessellation written: the distance to the analytic
    // ellipsoid (original units = unit cube / 2 here, the ellipsoid being 2 long).
    let (limit, _) =
        subfit::io::read_file(&out.join("limit.ply"), &subfit::io::ReadOptions::default()).unwrap();
    let (rms, max) = ellipsoid_distance(&limit.positions);
    let unit = rep["normalized_unit_in_original_units"].as_f64().unwrap();
    let (rms, max) = (rms / unit, max / unit);
    let two = &rep["final"]["two_sided"];
    let (r2, m2) = (
        two["surface_to_data"]["rms"].as_f64().unwrap(),
        two["surface_to_data"]["max"].as_f64().unwrap(),
    );
    assert!(rms < 0.002, "measured E_rms {rms}");
    assert!(
        (rms / r2 - 1.0).abs() < 0.3,
        "measured {rms}, reported {r2}"
    );
    assert!(max <= 1.3 * m2 + 1e-4, "measured max {max}, reported {m2}");
}

/// Defect 2: `--max-control-points 75` wrote 200 control points (the initial cage ignored the
/// budget). Now the budget caps the initial cage and every refinement, and a budget that
/// cannot be honoured stops the run with exit 2, a message, and no output.
#[test]
fn the_control_point_budget_caps_everything_or_the_run_says_why() {
    let d = tempfile::tempdir().unwrap();
    let mesh = d.path().join("torus.ply");
    save(
        &mesh,
        &subfit::mesh::shapes::torus_mesh(1.0, 0.4, 64, 32, true),
        Encoding::BinaryLittleEndian,
    );
    let m = mesh.to_str().unwrap();
    let out = d.path().join("fit");
    let o = out.to_str().unwrap();
    let r = subfit(&["fit", m, "-o", o, "--max-control-points", "40"]);
    assert!(
        matches!(r.status.code(), Some(0 | 1)),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let rep = report(&out);
    assert!(
        rep["init"]["control_points"].as_u64().unwrap() <= 40,
        "{rep}"
    );
    assert!(rep["control_points"].as_u64().unwrap() <= 40, "{rep}");
    for s in rep["stages"].as_array().unwrap() {
        assert!(s["control_points"].as_u64().unwrap() <= 40);
    }
    let (cage, _) = subfit::io::read_file(&out.join("control.obj"), &Default::default()).unwrap();
    assert!(cage.num_vertices() <= 40);

    // An initial size above the budget, and a budget below what a torus needs (7 vertices):
    // exit 2, the reason on stderr, nothing written.
    for (flags, says) in [
        (
            &["--control-points", "100", "--max-control-points", "75"][..],
            "budget",
        ),
        (&["--max-control-points", "6"][..], "budget"),
    ] {
        let out = d.path().join("refused");
        let mut args = vec!["fit", m, "-o", out.to_str().unwrap()];
        args.extend_from_slice(flags);
        let r = subfit(&args);
        let stderr = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{flags:?}: {stderr}");
        assert!(stderr.contains(says), "{flags:?}: {stderr}");
        assert!(!out.exists() || std::fs::read_dir(&out).unwrap().next().is_none());
    }
}

/// A torus mesh with `holes` disc-shaped holes (faces whose centroid is near one of `holes`
/// points spread over the surface): genus 1, `holes` boundary loops.
fn holey_torus(holes: usize) -> PolyMesh {
    let t = subfit::mesh::shapes::torus_mesh(1.0, 0.4, 96, 48, true);
    let centers: Vec<[f64; 3]> = (0..holes)
        .map(|i| {
            let u = i as f64 * std::f64::consts::TAU / holes as f64;
            let v = i as f64 * 2.4;
            let r = 1.0 + 0.4 * v.cos();
            [r * u.cos(), r * u.sin(), 0.4 * v.sin()]
        })
        .collect();
    let mut faces = subfit::mesh::Polygons::new();
    for f in t.faces.iter() {
        let c: [f64; 3] = std::array::from_fn(|k| {
            f.iter().map(|&v| t.positions[v as usize][k]).sum::<f64>() / 3.0
        });
        let near = centers
            .iter()
            .any(|p| (0..3).map(|k| (p[k] - c[k]).powi(2)).sum::<f64>() < 0.12f64.powi(2));
        if !near {
            faces.push(f);
        }
    }
    PolyMesh::new(t.positions.clone(), faces)
}

/// Defect 3: success was judged surface → data only, so a mesh with holes reported a small
/// error while its rims were left uncovered (Loop boundary curves pull inward). Now both
/// directions are measured on the tessellation written, the tolerance holds only when both
/// do, and the figures agree with an independent measurement (`subfit compare`, which samples
/// both surfaces by area) within 30 %.
#[test]
fn a_mesh_with_holes_is_judged_both_ways() {
    let d = tempfile::tempdir().unwrap();
    let mesh = d.path().join("holes.ply");
    let m = holey_torus(12);
    save(&mesh, &m, Encoding::BinaryLittleEndian);
    let out = d.path().join("fit");
    let r = subfit(&["fit", mesh.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&r.stderr);
    let code = r.status.code();
    assert!(matches!(code, Some(0 | 1)), "{stderr}");
    let rep = report(&out);
    assert_eq!(rep["target_topology"]["genus"], 1);
    assert_eq!(rep["target_topology"]["boundary_loops"], 12);
    assert_eq!(rep["init"]["genus"], 1);
    assert_eq!(rep["init"]["boundary_loops"]["cage"], 12);
    let two = &rep["final"]["two_sided"];
    let f = |v: &serde_json::Value| v.as_f64().unwrap();
    let (s2d, d2s) = (
        f(&two["surface_to_data"]["rms"]),
        f(&two["data_to_surface"]["rms"]),
    );
    assert_eq!(f(&two["e_rms"]), s2d.max(d2s));
    let c = subfit(&[
        "compare",
        mesh.to_str().unwrap(),
        out.join("limit.ply").to_str().unwrap(),
        "--json",
        "--samples",
        "200000",
    ]);
    assert_eq!(c.status.code(), Some(0));
    let cmp: serde_json::Value = serde_json::from_slice(&c.stdout).unwrap();
    let unit = f(&rep["normalized_unit_in_original_units"]);
    let (ind_d2s, ind_s2d) = (
        f(&cmp["a_to_b"]["rms"]) / unit,
        f(&cmp["b_to_a"]["rms"]) / unit,
    );
    for st in rep["stages"].as_array().unwrap() {
        println!(
            "stage {}: {} cp, {} it, s2d {:.2e} d2s {:.2e} d2s max {:.2e}, {:.1} s",
            st["stage"],
            st["control_points"],
            st["iterations"],
            f(&st["two_sided"]["surface_to_data"]["rms"]),
            f(&st["two_sided"]["data_to_surface"]["rms"]),
            f(&st["two_sided"]["data_to_surface"]["max"]),
            f(&st["time_s"])
        );
    }
    println!("two-sided RMS reported: s2d {s2d:.3e} d2s {d2s:.3e}; independent: s2d {ind_s2d:.3e} d2s {ind_d2s:.3e}; exit {code:?}");
    let independent = ind_d2s.max(ind_s2d);
    assert!(
        (f(&two["e_rms"]) / independent - 1.0).abs() < 0.3,
        "reported {}, independent {independent}",
        f(&two["e_rms"])
    );
    let tol = f(&rep["options"]["tolerance_rms"]);
    assert_eq!(code == Some(0), rep["tolerance_reached"] == true);
    if code == Some(0) {
        assert!(independent <= 1.3 * tol, "exit 0 but {independent} > {tol}");
    }
}
