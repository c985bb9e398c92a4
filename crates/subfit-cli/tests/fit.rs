//! `subfit fit` end to end on generated shapes: automatic initial mesh, multi-stage fitting with
//! local refinement, every output file, exit codes and topology checks.

mod common;

use std::path::Path;

use common::subfit;

use subfit::io::{Encoding, WriteOptions};
use subfit::mesh::shapes::{octahedron_mesh, torus_mesh, Shape};
use subfit::mesh::PolyMesh;

fn save(path: &Path, mesh: &PolyMesh) {
    let opts = WriteOptions {
        format: None,
        encoding: Encoding::BinaryLittleEndian,
        single_precision: false,
    };
    subfit::io::write_file(path, mesh, &opts).unwrap();
}

fn report(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap()
}

#[test]
fn fit_without_init_refines_a_coarse_cage_until_the_tolerance() {
    let d = tempfile::tempdir().unwrap();
    let cloud = d.path().join("ellipsoid.ply");
    save(&cloud, &Shape::PAPER_ELLIPSOID.sample(20_000, 0.0, 3));
    let out = d.path().join("fit");
    let r = subfit(&[
        "fit",
        cloud.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--control-points",
        "20",
        "--tolerance",
        "0.0001",
        "--sample-level",
        "2",
    ]);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let rep = report(&out);
    assert_eq!(rep["init"]["source"], "Contour");
    assert_eq!(rep["init"]["genus"], 0);
    assert!(rep["tolerance_reached"].as_bool().unwrap());
    let e = rep["final"]["e_rms"].as_f64().unwrap();
    assert!(e <= 0.0001, "{e}");
    // 20 control points cannot reach 1e-4 on their own (λ = 1e-3 first): stages refined.
    let stages = rep["stages"].as_array().unwrap();
    assert!(stages.len() >= 2, "{rep}");
    let n0 = stages[0]["control_points"].as_u64().unwrap();
    let n1 = rep["control_points"].as_u64().unwrap();
    assert!(n1 > n0, "{n0} -> {n1}");
    assert!(stages[1]["lambda"].as_f64().unwrap() < stages[0]["lambda"].as_f64().unwrap());
    // Every output, in the target's coordinates.
    let info = |f: &str| -> serde_json::Value {
        serde_json::from_slice(&subfit(&["info", "--json", out.join(f).to_str().unwrap()]).stdout)
            .unwrap()
    };
    let cage = info("control.obj");
    assert_eq!(cage["vertices"].as_u64().unwrap(), n1);
    assert_eq!(cage["topology"]["genus"], 0);
    let limit = info("limit.ply");
    assert_eq!(limit["normals"], true);
    let z = limit["bbox"]["max"][2].as_f64().unwrap();
    assert!((z - 1.0).abs() < 0.01, "{z}");
    let err = info("error.ply");
    assert_eq!(err["colors"], true);
    let header =
        String::from_utf8_lossy(&std::fs::read(out.join("error.ply")).unwrap()[..700]).to_string();
    assert!(header.contains("property double error\n"), "{header}");
    let usda = std::fs::read_to_string(out.join("control.usda")).unwrap();
    assert!(
        usda.contains("uniform token subdivisionScheme = \"loop\""),
        "{usda}"
    );
    let csv = std::fs::read_to_string(out.join("log.csv")).unwrap();
    let iterations: u64 = stages
        .iter()
        .map(|s| s["iterations"].as_u64().unwrap())
        .sum();
    assert_eq!(csv.lines().count() as u64, iterations + 2);
}

#[test]
fn a_cage_of_the_wrong_topology_is_rejected_before_fitting() {
    let d = tempfile::tempdir().unwrap();
    let torus = d.path().join("torus.ply");
    save(&torus, &torus_mesh(0.35, 0.15, 48, 24, true));
    let octa = d.path().join("octa.ply");
    save(&octa, &octahedron_mesh(0.5, 0.5, 0.15));
    let out = d.path().join("fit");
    let r = subfit(&[
        "fit",
        torus.to_str().unwrap(),
        "--init",
        octa.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(r.status.code(), Some(2));
    let msg = String::from_utf8_lossy(&r.stderr);
    assert!(msg.contains("genus 0") && msg.contains("genus 1"), "{msg}");
    assert!(!out.join("control.obj").exists());
    // A curvature-line cage needs an open surface of genus 0 (Lavoué et al. §4).
    let r = subfit(&[
        "fit",
        torus.to_str().unwrap(),
        "--init",
        "curvature-lines",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(r.status.code(), Some(2));
    let msg = String::from_utf8_lossy(&r.stderr);
    assert!(
        msg.contains("curvature-lines") && msg.contains("genus 1"),
        "{msg}"
    );
    assert!(!out.join("control.obj").exists());
    // --control-points belongs to the automatic initial mesh.
    let r = subfit(&[
        "fit",
        torus.to_str().unwrap(),
        "--init",
        octa.to_str().unwrap(),
        "--control-points",
        "50",
    ]);
    assert_eq!(r.status.code(), Some(2));
    // λ_end above λ.
    let r = subfit(&[
        "fit",
        torus.to_str().unwrap(),
        "--lambda",
        "1e-4",
        "--lambda-end",
        "1e-3",
    ]);
    assert_eq!(r.status.code(), Some(2));
}

#[test]
fn a_torus_mesh_keeps_its_genus_through_refinement() {
    let d = tempfile::tempdir().unwrap();
    let torus = d.path().join("torus.ply");
    save(&torus, &torus_mesh(0.35, 0.15, 96, 48, true));
    let out = d.path().join("fit");
    let r = subfit(&[
        "fit",
        torus.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--control-points",
        "60",
        "--tolerance",
        "0.0015",
        "--sample-level",
        "2",
    ]);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let rep = report(&out);
    assert_eq!(rep["init"]["source"], "Mesh");
    assert_eq!(rep["target_topology"]["genus"], 1);
    let cage: serde_json::Value = serde_json::from_slice(
        &subfit(&["info", "--json", out.join("control.obj").to_str().unwrap()]).stdout,
    )
    .unwrap();
    assert_eq!(cage["topology"]["genus"], 1, "{cage}");
    assert_eq!(cage["topology"]["boundary_loops"], 0, "{cage}");
}

#[test]
fn demo_fits_the_builtin_shapes_end_to_end() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("demo");
    let r = subfit(&["demo", "-o", out.to_str().unwrap(), "--points", "10000"]);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let table = String::from_utf8_lossy(&r.stdout);
    for (shape, genus) in [("ellipsoid", 0), ("torus", 1), ("genus2", 2)] {
        let rep = report(&out.join(format!("fit-{shape}")));
        assert!(rep["tolerance_reached"].as_bool().unwrap(), "{shape}");
        assert_eq!(rep["init"]["genus"], genus, "{shape}");
        assert!(table.contains(shape), "{table}");
        assert!(out.join(format!("fit-{shape}/control.usda")).exists());
    }
}

#[test]
fn bad_targets_exit_with_2_and_write_nothing() {
    let d = tempfile::tempdir().unwrap();
    let empty = d.path().join("empty.xyz");
    std::fs::write(&empty, b"").unwrap();
    let five = d.path().join("five.xyz");
    std::fs::write(&five, b"0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n").unwrap();
    // (A Möbius strip is not refused: it is fitted as its points, tests/repair.rs.)
    for (target, needle) in [(&empty, "empty.xyz"), (&five, "five.xyz")] {
        let out = d.path().join("out");
        let r = subfit(&["fit", target.to_str().unwrap(), "-o", out.to_str().unwrap()]);
        assert_eq!(r.status.code(), Some(2), "{}", target.display());
        let msg = String::from_utf8_lossy(&r.stderr);
        assert!(msg.contains(needle), "{msg}");
        assert!(!out.join("control.obj").exists() && !out.join("report.json").exists());
    }
}

#[test]
fn compare_measures_the_exact_limit_surface_of_a_cage() {
    let d = tempfile::tempdir().unwrap();
    let cage = d.path().join("torus.ply");
    save(&cage, &torus_mesh(0.35, 0.15, 12, 6, true));
    let fine = d.path().join("limit.ply");
    let r = subfit(&[
        "subdivide",
        cage.to_str().unwrap(),
        "--levels",
        "5",
        "--limit",
        "-o",
        fine.to_str().unwrap(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let compare = |extra: &[&str]| -> serde_json::Value {
        let mut args = vec![
            "compare",
            cage.to_str().unwrap(),
            fine.to_str().unwrap(),
            "--samples",
            "4000",
            "--json",
        ];
        args.extend_from_slice(extra);
        let r = subfit(&args);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        serde_json::from_slice(&r.stdout).unwrap()
    };
    // The cage itself lies far from its limit surface; the exact limit surface coincides with
    // the fine limit tessellation up to its chordal error (vertices exact, ~1e-4 between).
    let as_mesh = compare(&[])["hausdorff"].as_f64().unwrap();
    let as_limit = compare(&["--scheme", "loop"]);
    let h = as_limit["hausdorff"].as_f64().unwrap();
    assert!(as_mesh > 0.01, "{as_mesh}");
    assert!(h < 1e-3 && h < as_mesh / 20.0, "{as_limit}");
    // A point cloud cannot be evaluated as a limit surface.
    let cloud = d.path().join("cloud.xyz");
    std::fs::write(&cloud, "0 0 0\n1 0 0\n0 1 0\n0 0 1\n".repeat(4)).unwrap();
    let r = subfit(&[
        "compare",
        cloud.to_str().unwrap(),
        fine.to_str().unwrap(),
        "--scheme",
        "loop",
    ]);
    assert_eq!(r.status.code(), Some(2));
}

/// `--local`: stages after a refinement that touched a small region optimize only that region
/// (their `active_points` in report.json), and the fit still reaches the tolerance.
#[test]
fn fit_local_optimizes_only_around_refinements() {
    let d = tempfile::tempdir().unwrap();
    let cloud = d.path().join("torus.ply");
    save(&cloud, &Shape::DEFAULT_TORUS.sample(30_000, 0.0, 5));
    let out = d.path().join("fit");
    let r = subfit(&[
        "fit",
        cloud.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--control-points",
        "300",
        "--tolerance",
        "0.00001",
        "--max-control-points",
        "1200",
        "--sample-level",
        "2",
        "--local",
        "--local-rings",
        "1",
    ]);
    assert!(
        matches!(r.status.code(), Some(0 | 1)),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let rep = report(&out);
    assert_eq!(rep["options"]["local"], true, "{}", rep["options"]);
    let stages = rep["stages"].as_array().unwrap();
    assert!(stages[0]["active_points"].is_null());
    let local: Vec<(u64, u64)> = stages
        .iter()
        .filter_map(|s| {
            let a = s["active_points"].as_u64()?;
            Some((a, s["control_points"].as_u64().unwrap()))
        })
        .collect();
    let summary: Vec<_> = stages
        .iter()
        .map(|s| (s["control_points"].clone(), s["active_points"].clone()))
        .collect();
    assert!(!local.is_empty(), "no local stage: {summary:?}");
    assert!(local.iter().all(|&(a, n)| a > 0 && 2 * a <= n), "{local:?}");
    let (e0, e1) = (
        rep["initial"]["e_rms"].as_f64().unwrap(),
        rep["final"]["e_rms"].as_f64().unwrap(),
    );
    assert!(e1 < e0, "{e0} -> {e1}");
}

/// Runs `subfit fit CLOUD --scheme catmull-clark -o DIR EXTRA…` and returns report.json.
fn fit_cc(cloud: &Path, dir: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "fit",
        cloud.to_str().unwrap(),
        "--scheme",
        "catmull-clark",
        "-o",
        dir.to_str().unwrap(),
    ];
    args.extend(extra);
    let r = subfit(&args);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    report(dir)
}

#[test]
fn catmull_clark_fits_start_from_a_quad_dominant_cage() {
    let d = tempfile::tempdir().unwrap();
    let cloud = d.path().join("ellipsoid.ply");
    save(&cloud, &Shape::PAPER_ELLIPSOID.sample(8_000, 0.0, 3));
    let quads = fit_cc(&cloud, &d.path().join("quads"), &["--quads", "paired"]);
    let tris = fit_cc(&cloud, &d.path().join("tris"), &["--no-quad-dominant"]);
    // The cage is paired before the fit, with the same control points (`--quads paired`: the
    // default also lays a cage along a cross field, tests/quad_cages.rs).
    assert_eq!(quads["init"]["paired"], true);
    assert!(
        quads["init"]["quad_fraction"].as_f64().unwrap() >= 0.85,
        "{}",
        quads["init"]
    );
    assert!(quads["control_quad_fraction"].as_f64().unwrap() >= 0.7);
    assert_eq!(
        quads["init"]["control_points"],
        tris["init"]["control_points"]
    );
    assert_eq!(tris["init"]["paired"], false);
    assert_eq!(tris["control_quad_fraction"].as_f64().unwrap(), 0.0);
    let q = quads["init"]["quads"].as_u64().unwrap();
    let t = quads["init"]["triangles"].as_u64().unwrap();
    assert_eq!(q + t, quads["init"]["faces"].as_u64().unwrap());
    // Both reach the default tolerance both ways; the quad cage fits about as well.
    for rep in [&quads, &tris] {
        assert!(
            rep["tolerance_reached_two_sided"].as_bool().unwrap(),
            "{rep}"
        );
    }
    let e = |r: &serde_json::Value| r["final"]["two_sided"]["e_rms"].as_f64().unwrap();
    assert!(e(&quads) <= 1.5 * e(&tris), "{} vs {}", e(&quads), e(&tris));
    // Without a scheme the all-triangle automatic cage is fitted with Loop, unpaired.
    let auto = d.path().join("auto");
    let r = subfit(&["fit", cloud.to_str().unwrap(), "-o", auto.to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(0));
    let rep = report(&auto);
    assert_eq!(rep["options"]["scheme"], "Loop");
    assert_eq!(rep["init"]["paired"], false);
    // Quads and Loop do not mix.
    let r = subfit(&[
        "fit",
        cloud.to_str().unwrap(),
        "--scheme",
        "loop",
        "--quad-dominant",
        "-o",
        d.path().join("bad").to_str().unwrap(),
    ]);
    assert_eq!(r.status.code(), Some(2));
}

/// `--facing` (the default) and `--no-facing` reach the fit (report.json `options.facing`) and a thin limb — a capsule 6 %
/// of its length thick — is fitted within the tolerance with it, genus kept.
#[test]
fn facing_foot_points_are_an_option_of_fit() {
    let d = tempfile::tempdir().unwrap();
    let limb = d.path().join("limb.ply");
    save(&limb, &subfit::mesh::thin_shapes::capsule(0.03, 0.9, 32));
    for facing in [false, true] {
        let out = d.path().join(format!("fit-{facing}"));
        let mut args = vec![
            "fit",
            limb.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--sample-level",
            "2",
        ];
        // `--facing` is the default and still accepted; `--no-facing` turns it off.
        args.push(if facing { "--facing" } else { "--no-facing" });
        let r = subfit(&args);
        assert_eq!(
            r.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&r.stderr)
        );
        let rep = report(&out);
        assert_eq!(rep["options"]["facing"], facing);
        assert_eq!(rep["target_topology"]["genus"], 0);
    }
}

/// `--chordal` reaches the fit of a CAD export (report.json `options.chordal_levels`, a
/// warning with the facets' distance), and a mesh that is not a tessellation is fitted as
/// given, with a warning that says so.
#[test]
fn the_chordal_tolerance_is_an_option_of_fit() {
    let d = tempfile::tempdir().unwrap();
    let part = d.path().join("cylinder.stl");
    save(
        &part,
        &subfit::mesh::shapes::capped_cylinder(10.0, 20.0, 24),
    );
    // A scanned torus: its vertices off the grid's planes (no planar regions: not a
    // tessellation; the exact grid would be one, of a torus).
    let mut torus = torus_mesh(1.0, 0.4, 48, 24, true);
    for (i, p) in torus.positions.iter_mut().enumerate() {
        let s = 1.0 + 2e-3 * (17.0 * i as f64).sin();
        *p = p.map(|x| x * s);
    }
    let scan = d.path().join("torus.ply");
    save(&scan, &torus);
    for (input, levels) in [(&part, Some(4)), (&scan, None)] {
        let out = d.path().join("fit");
        let r = subfit(&[
            "fit",
            input.to_str().unwrap(),
            "--chordal",
            "-o",
            out.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&r.stderr);
        assert!(r.status.code().is_some_and(|c| c <= 1), "{stderr}");
        let rep = report(&out);
        match levels {
            Some(l) => {
                assert_eq!(rep["options"]["chordal_levels"], l);
                assert!(
                    stderr.contains("curved interpolant of the facets"),
                    "{stderr}"
                );
            }
            None => {
                assert!(rep["options"]["chordal_levels"].is_null());
                assert!(
                    stderr.contains("the chordal tolerance does not apply"),
                    "{stderr}"
                );
            }
        }
    }
}
