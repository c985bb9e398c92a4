//! `subfit fit` without `--tolerance`, `--max-error` and `--max-control-points` judges the fit
//! by the target's tolerances (`subfit::tolerance`: fractions of its diagonal, a tighter one for
//! an open rim), reports which (`tolerance_kind`), and meets them both ways as `subfit compare`
//! measures; a budget or a tolerance given keeps the unit-cube 5e-4.

#![allow(clippy::print_stdout)]

mod common;

use std::path::Path;

use common::subfit;
use subfit::io::{write_file, WriteOptions};
use subfit::mesh::shapes::torus_mesh;
use subfit::mesh::{PolyMesh, Polygons};
use subfit::tolerance::{SCAN_BOUNDARY, SCAN_MAX, SCAN_RMS};

/// A triangulated torus with 6 holes (the faces within a small radius of 6 of its points):
/// an open scan-like mesh with 6 boundary loops.
fn holed_torus() -> PolyMesh {
    let t = torus_mesh(1.0, 0.35, 96, 36, true);
    let centres: Vec<[f64; 3]> = (0..6)
        .map(|k| t.positions[(k * 613 + 97) % t.num_vertices()])
        .collect();
    let keep: Vec<[u32; 3]> = t
        .faces
        .iter()
        .filter(|f| {
            !f.iter().any(|&v| {
                let p = t.positions[v as usize];
                centres
                    .iter()
                    .any(|c| (0..3).map(|a| (p[a] - c[a]).powi(2)).sum::<f64>() < 0.12f64.powi(2))
            })
        })
        .map(|f| [f[0], f[1], f[2]])
        .collect();
    PolyMesh::new(t.positions.clone(), Polygons::from_triangles(&keep))
}

fn fit(target: &Path, out: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["fit", target.to_str().unwrap(), "-o", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    let r = subfit(&args);
    assert!(
        r.status.code() == Some(0),
        "{extra:?}: {}",
        String::from_utf8_lossy(&r.stderr)
    );
    serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap()
}

#[test]
fn defaults_are_the_targets_and_hold_both_ways_and_at_the_rim() {
    let d = tempfile::tempdir().unwrap();
    let target = d.path().join("holed.obj");
    write_file(&target, &holed_torus(), &WriteOptions::default()).unwrap();
    let out = d.path().join("default");
    let r = fit(&target, &out, &[]);
    assert_eq!(r["tolerance_kind"], "scan");
    let diag = r["bbox_diagonal_unit_cube"].as_f64().unwrap();
    let o = &r["options"];
    assert!((o["tolerance_rms"].as_f64().unwrap() - SCAN_RMS * diag).abs() < 1e-12);
    assert!((o["tolerance_max"].as_f64().unwrap() - SCAN_MAX * diag).abs() < 1e-12);
    assert_eq!(r["tolerance_reached"], true);

    // Independently: the exact limit surface against the mesh, and against its rim.
    let c = out.join("control.obj");
    let cmp = |b: &Path| -> serde_json::Value {
        let o = subfit(&[
            "compare",
            c.to_str().unwrap(),
            b.to_str().unwrap(),
            "--scheme",
            "auto",
            "--samples",
            "50000",
            "--json",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_slice(&o.stdout).unwrap()
    };
    let all = cmp(&target);
    let mesh = holed_torus();
    let h = subfit::mesh::HalfEdgeMesh::from_mesh(&mesh).unwrap();
    let loops = h.boundary_loops();
    assert_eq!(loops.len(), 6);
    let rim: Vec<[f64; 3]> = loops
        .iter()
        .flatten()
        .map(|&v| mesh.positions[v.idx()])
        .collect();
    let rim_file = d.path().join("rim.xyz");
    write_file(
        &rim_file,
        &PolyMesh::point_cloud(rim, None),
        &WriteOptions::default(),
    )
    .unwrap();
    let to_rim = cmp(&rim_file);
    let diagonal = all["reference_diagonal"].as_f64().unwrap();
    let (rms, hausdorff, rim_max) = (
        all["two_sided_rms_fraction"].as_f64().unwrap(),
        all["hausdorff_fraction"].as_f64().unwrap(),
        to_rim["b_to_a"]["max"].as_f64().unwrap() / diagonal,
    );
    println!(
        "holed torus, defaults: {} control points, two-sided RMS {rms:.2e}, Hausdorff {hausdorff:.2e}, rim {rim_max:.2e} of the diagonal",
        r["control_points"]
    );
    // The fit's own measure is on the tessellation of its samples; the exact one is within a
    // small margin of it.
    assert!(rms <= 1.1 * SCAN_RMS, "{rms}");
    assert!(hausdorff <= 1.2 * SCAN_MAX, "{hausdorff}");
    assert!(rim_max <= 1.2 * SCAN_BOUNDARY, "{rim_max}");

    // A budget alone, or a tolerance, keeps the unit-cube default.
    for extra in [
        &["--max-control-points", "400"][..],
        &["--tolerance", "5e-4"],
    ] {
        let out = d.path().join(extra[0].trim_start_matches('-'));
        let r = fit(&target, &out, extra);
        assert!(r["tolerance_kind"].is_null(), "{extra:?}");
        assert_eq!(r["options"]["tolerance_rms"], 5e-4, "{extra:?}");
        assert!(r["options"]["tolerance_max"].is_null(), "{extra:?}");
    }
}
