//! Messy meshes get a fit, not a refusal: a sphere with a sheet glued onto it along an arc of
//! edges (three faces on each), a lens whose thin middle is a sheet of no thickness written as
//! both its sides, a Möbius strip (fitted as its points, with a warning that says why), and the
//! corpus's decimated Stanford dragon and Happy Buddha (repaired into a surface and given an
//! initial cage; `SUBFIT_CORPUS`, skipped with a notice without it, a failure under `CI=true`).

#![allow(clippy::print_stdout)]

mod common;

use std::path::{Path, PathBuf};

use common::{corpus_dir, subfit};
use subfit::io::{Encoding, WriteOptions};
use subfit::mesh::thin_shapes::two_sided_lens;
use subfit::mesh::{diagnose_mesh, PolyMesh, Polygons};

/// Writes `mesh` to `dir/name` as full-precision ASCII (OBJ or PLY by the extension).
fn write(dir: &Path, name: &str, mesh: &PolyMesh) -> PathBuf {
    let path = dir.join(name);
    let opts = WriteOptions {
        format: None,
        encoding: Encoding::Ascii,
        single_precision: false,
    };
    subfit::io::write_file(&path, mesh, &opts).unwrap();
    path
}

/// `subfit fit MESH -o OUT`, two iterations at sample level 2: exit 0 or 1 (a fit, whatever its
/// accuracy), its stderr and report.json.
fn quick_fit(mesh: &Path, out: &Path) -> (String, serde_json::Value) {
    let r = subfit(&[
        "fit",
        mesh.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--max-iterations",
        "2",
        "--sample-level",
        "2",
    ]);
    let err = String::from_utf8_lossy(&r.stderr).into_owned();
    assert!(matches!(r.status.code(), Some(0 | 1)), "{err}");
    let report = serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    (err, report)
}

/// A latitude-longitude unit sphere (`n` around, `rings` rings, odd: one is the equator) with
/// a flat sheet in the equator's plane standing out of it along `arc` consecutive equator
/// edges, `rows` triangles pairs deep.
fn sphere_with_sheet(n: u32, rings: u32, arc: u32, rows: u32) -> PolyMesh {
    let v = |r: u32, k: u32| 2 + r * n + (k % n);
    let mut p = vec![[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    for r in 0..rings {
        let phi = std::f64::consts::PI * f64::from(r + 1) / f64::from(rings + 1);
        for k in 0..n {
            let t = std::f64::consts::TAU * f64::from(k) / f64::from(n);
            p.push([phi.sin() * t.cos(), phi.sin() * t.sin(), phi.cos()]);
        }
    }
    let mut f = Polygons::new();
    for k in 0..n {
        f.push(&[0, v(0, k), v(0, k + 1)]);
        f.push(&[1, v(rings - 1, k + 1), v(rings - 1, k)]);
    }
    for r in 0..rings - 1 {
        for k in 0..n {
            f.push(&[v(r, k), v(r + 1, k), v(r + 1, k + 1)]);
            f.push(&[v(r, k), v(r + 1, k + 1), v(r, k + 1)]);
        }
    }
    let equator = rings / 2;
    let mut grid: Vec<Vec<u32>> = Vec::new();
    for k in 0..=arc {
        let q = p[v(equator, k) as usize];
        let mut col = vec![v(equator, k)];
        for s in 1..=rows {
            let r = 1.0 + 0.1 * f64::from(s);
            p.push([q[0] * r, q[1] * r, 0.0]);
            col.push((p.len() - 1) as u32);
        }
        grid.push(col);
    }
    for k in 0..arc as usize {
        for s in 0..rows as usize {
            let q = [
                grid[k][s],
                grid[k + 1][s],
                grid[k + 1][s + 1],
                grid[k][s + 1],
            ];
            f.push(&[q[0], q[1], q[2]]);
            f.push(&[q[0], q[2], q[3]]);
        }
    }
    PolyMesh::new(p, f)
}

#[test]
fn a_sphere_with_a_sheet_glued_along_an_edge_is_fitted() {
    let d = tempfile::tempdir().unwrap();
    let mesh = sphere_with_sheet(32, 15, 8, 5);
    assert_eq!(diagnose_mesh(&mesh).non_manifold_edges, 8);
    let path = write(d.path(), "glued.obj", &mesh);
    let (err, report) = quick_fit(&path, &d.path().join("fit"));
    let cut = format!(
        "cut 8 edges of {} shared by more than two faces",
        path.display()
    );
    assert!(err.contains(&cut), "{err}");
    // The sphere, closed, and the sheet, open, come apart: genus 0 and the sheet's one rim.
    assert_eq!(report["target_topology"]["genus"], 0, "{report}");
    assert_eq!(report["target_topology"]["boundary_loops"], 1, "{report}");
    assert!(report["control_points"].as_u64().unwrap() > 0);
}

#[test]
fn a_sheet_of_no_thickness_written_on_both_sides_is_fitted_as_one_closed_surface() {
    let d = tempfile::tempdir().unwrap();
    let mesh = two_sided_lens(|i, j| (i + j) % 2 == 0);
    assert!(diagnose_mesh(&mesh).duplicate_faces >= 32);
    let path = write(d.path(), "lens.ply", &mesh);
    let (err, report) = quick_fit(&path, &d.path().join("fit"));
    assert!(!err.contains("oriented consistently"), "{err}");
    assert_eq!(report["target_topology"]["genus"], 0, "{report}");
    assert_eq!(report["target_topology"]["boundary_loops"], 0, "{report}");
    assert_eq!(report["init"]["boundary_loops"]["cage"], 0, "{report}");
}

/// A Möbius strip of `n × m` quads around a circle of radius 1, half a turn along it, width 0.6.
fn moebius(n: usize, m: usize) -> PolyMesh {
    let mut p = Vec::new();
    for i in 0..n {
        let u = std::f64::consts::TAU * i as f64 / n as f64;
        for j in 0..=m {
            let w = -0.3 + 0.6 * j as f64 / m as f64;
            let r = 1.0 + w * (u / 2.0).cos();
            p.push([r * u.cos(), r * u.sin(), w * (u / 2.0).sin()]);
        }
    }
    // Column n is column 0 turned over.
    let id = |i: usize, j: usize| (if i == n { m - j } else { i * (m + 1) + j }) as u32;
    let mut f = Polygons::new();
    for i in 0..n {
        for j in 0..m {
            f.push(&[id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    PolyMesh::new(p, f)
}

#[test]
fn a_moebius_strip_is_fitted_as_its_points_with_a_warning() {
    let d = tempfile::tempdir().unwrap();
    let mesh = moebius(64, 8);
    let path = write(d.path(), "mobius.obj", &mesh);
    let (err, report) = quick_fit(&path, &d.path().join("fit"));
    let why = format!(
        "{} cannot be oriented consistently around face",
        path.display()
    );
    assert!(err.contains(&why), "{err}");
    assert!(
        err.contains("fitting its points instead, as --as-points would"),
        "{err}"
    );
    // Fitted as a cloud of its vertices: no faces, every point kept.
    assert!(report["target_topology"].is_null(), "{report}");
    assert_eq!(report["target_points"], 64 * 9, "{report}");
    assert!(d.path().join("fit/control.obj").exists());
}

/// The repair drops a small Möbius strip lying apart from a sphere (debris it cannot orient),
/// but the report's largest data → surface distance is still measured against the file as
/// written: the strip's vertices, a unit and more from the sphere, are in it.
#[test]
fn the_reported_maximum_covers_what_the_repair_dropped() {
    let d = tempfile::tempdir().unwrap();
    let mut mesh = sphere_with_sheet(32, 15, 0, 0);
    let strip = moebius(8, 1);
    let offset = mesh.positions.len() as u32;
    mesh.positions.extend(
        strip
            .positions
            .iter()
            .map(|p| [2.5 + 0.1 * p[0], 0.1 * p[1], 0.1 * p[2]]),
    );
    for f in strip.faces.iter() {
        mesh.faces
            .push(&f.iter().map(|&v| v + offset).collect::<Vec<_>>());
    }
    let path = write(d.path(), "debris.obj", &mesh);
    let (err, report) = quick_fit(&path, &d.path().join("fit"));
    assert!(
        err.contains("non-orientable pieces"),
        "the strip is dropped: {err}"
    );
    assert_eq!(report["target_topology"]["genus"], 0, "{report}");
    // The strip's nearest vertex is 2.5 − 0.13 − 1 from the unit sphere.
    let max = report["final"]["two_sided"]["e_max_original_units"]
        .as_f64()
        .unwrap();
    assert!(
        max > 1.3,
        "largest distance {max}: the dropped strip is not measured"
    );
}

#[test]
fn the_decimated_dragon_and_buddha_are_repaired_and_get_an_initial_cage() {
    let Some(corpus) = corpus_dir() else { return };
    for name in ["scan-dragon-res3.ply", "scan-happy-res3.ply"] {
        let file = corpus.join(name);
        let (mut mesh, _) =
            subfit::io::read_file(&file, &subfit::io::ReadOptions::default()).unwrap();
        let before = diagnose_mesh(&mesh);
        assert!(before.non_manifold_edges > 1000, "{name}: {before:?}");
        let mut warnings = Vec::new();
        subfit::repair_mesh(&mut mesh, name, &mut |w| warnings.push(w))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        // A closed scan stays one closed, orientable surface with nearly all its faces: the
        // flaps the cut takes off (fins of no thickness) are at most 3 % of them.
        let d = diagnose_mesh(&mesh);
        assert!(d.is_manifold && d.is_consistently_oriented, "{name}: {d:?}");
        // The vertices of the dropped flaps go too: they are no data of the surface.
        assert_eq!(d.unreferenced_vertices, 0, "{name}: {d:?}");
        let main = d.components.iter().max_by_key(|c| c.faces).unwrap();
        assert_eq!(main.boundary_loops, 0, "{name}: {d:?}");
        assert!(
            main.faces as f64 >= 0.97 * before.num_faces as f64,
            "{name}: {} of {} faces kept\n{warnings:?}",
            main.faces,
            before.num_faces
        );
        println!("{name}: {warnings:?}\n  {d:?}");

        let cage = tempfile::tempdir().unwrap();
        let out = cage.path().join("cage.obj");
        let r = subfit(&["init", file.to_str().unwrap(), "-o", out.to_str().unwrap()]);
        let stdout = String::from_utf8_lossy(&r.stdout);
        assert_eq!(
            r.status.code(),
            Some(0),
            "{name}: {stdout}{}",
            String::from_utf8_lossy(&r.stderr)
        );
        assert!(stdout.contains("(same)"), "{name}: genus differs: {stdout}");
        assert!(out.exists());
    }
}
