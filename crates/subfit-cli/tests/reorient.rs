//! A target mesh with a few faces the wrong way round (as real scans have), with faces meeting
//! only at a vertex, split along seams, with stray, repeated or collapsed faces, is repaired,
//! with a warning, by `init`, `analyze` and `fit`, instead of being refused.

mod common;

use std::path::Path;

use common::subfit;
use subfit::io::{Encoding, WriteOptions};
use subfit::mesh::shapes::torus_mesh;
use subfit::mesh::{PolyMesh, Polygons};

/// Writes `mesh` to `path` as full-precision ASCII OBJ.
fn write_obj(path: &Path, mesh: &PolyMesh) {
    let opts = WriteOptions {
        format: None,
        encoding: Encoding::Ascii,
        single_precision: false,
    };
    subfit::io::write_file(path, mesh, &opts).unwrap();
}

/// `subfit fit MESH -o OUT --control-points N`, one iteration at sample level 2 (exit 0 or 1):
/// its stderr and report.json.
fn quick_fit(mesh: &str, out: &Path, n: &str) -> (String, serde_json::Value) {
    let o = out.to_str().unwrap();
    let r = subfit(&[
        "fit",
        mesh,
        "-o",
        o,
        "--control-points",
        n,
        "--max-iterations",
        "1",
        "--sample-level",
        "2",
    ]);
    let err = String::from_utf8_lossy(&r.stderr).into_owned();
    assert!(matches!(r.status.code(), Some(0 | 1)), "{err}");
    let report = serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    (err, report)
}

/// A torus mesh (genus 1) with faces 10, 11, 500 and 900 reversed, as OBJ.
fn messy_torus(dir: &Path) -> std::path::PathBuf {
    let t = torus_mesh(1.0, 0.4, 48, 24, true);
    let mut faces = Polygons::new();
    for (f, poly) in t.faces.iter().enumerate() {
        if [10, 11, 500, 900].contains(&f) {
            let r: Vec<u32> = poly.iter().rev().copied().collect();
            faces.push(&r);
        } else {
            faces.push(poly);
        }
    }
    let path = dir.join("messy.obj");
    write_obj(&path, &PolyMesh::new(t.positions, faces));
    path
}

#[test]
fn inconsistently_oriented_faces_are_repaired_with_a_warning() {
    let d = tempfile::tempdir().unwrap();
    let messy = messy_torus(d.path());
    let m = messy.to_str().unwrap();
    let warning = format!("subfit: warning: re-oriented 4 faces in 1 components of {m}");

    let cage = d.path().join("cage.obj");
    let r = subfit(&[
        "init",
        m,
        "--control-points",
        "60",
        "-o",
        cage.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    assert!(err.contains(&warning), "{err}");
    let info: serde_json::Value =
        serde_json::from_slice(&subfit(&["info", "--json", cage.to_str().unwrap()]).stdout)
            .unwrap();
    assert_eq!(info["topology"]["genus"], 1, "{info}");

    let r = subfit(&["analyze", m]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    assert!(err.contains(&warning), "{err}");

    let (err, report) = quick_fit(m, &d.path().join("fit"), "60");
    assert!(err.contains(&warning), "{err}");
    assert_eq!(report["target_topology"]["genus"], 1, "{report}");
    // The repair is in the report too, beside the warning.
    assert_eq!(report["reoriented"]["faces_flipped"], 4, "{report}");
    assert_eq!(report["reoriented"]["components_changed"], 1, "{report}");
    assert!(report["warnings"][0]
        .as_str()
        .unwrap()
        .contains("re-oriented 4 faces"));
}

/// A torus mesh (genus 1) with two faces at vertex 100 removed that share only that vertex:
/// two triangular holes touching at it, a non-manifold vertex (a bowtie), as cutting holes
/// into a scan can leave.
fn bowtie_torus(dir: &Path) -> std::path::PathBuf {
    let t = torus_mesh(1.0, 0.4, 48, 24, true);
    let at: Vec<usize> = (0..t.faces.len())
        .filter(|&f| t.faces.iter().nth(f).unwrap().contains(&100))
        .collect();
    let shares_edge = |a: usize, b: usize| {
        let (fa, fb) = (
            t.faces.iter().nth(a).unwrap(),
            t.faces.iter().nth(b).unwrap(),
        );
        fa.iter().filter(|v| fb.contains(v)).count() > 1
    };
    let b = at[1..]
        .iter()
        .copied()
        .find(|&b| !shares_edge(at[0], b))
        .unwrap();
    let mut faces = Polygons::new();
    for (f, poly) in t.faces.iter().enumerate() {
        if f != at[0] && f != b {
            faces.push(poly);
        }
    }
    let path = dir.join("bowtie.obj");
    write_obj(&path, &PolyMesh::new(t.positions, faces));
    path
}

#[test]
fn a_non_manifold_vertex_is_split_with_a_warning() {
    let d = tempfile::tempdir().unwrap();
    let bowtie = bowtie_torus(d.path());
    let m = bowtie.to_str().unwrap();
    let warning = format!(
        "subfit: warning: split 1 non-manifold vertices of {m} (faces meeting only at a vertex, e.g. vertex 100) into one vertex per fan"
    );
    let info: serde_json::Value =
        serde_json::from_slice(&subfit(&["info", "--json", m]).stdout).unwrap();
    assert_eq!(info["topology"]["non_manifold_vertices"], 1, "{info}");

    let cage = d.path().join("cage.obj");
    let r = subfit(&[
        "init",
        m,
        "--control-points",
        "80",
        "-o",
        cage.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    assert!(err.contains(&warning), "{err}");

    let (err, report) = quick_fit(m, &d.path().join("fit"), "80");
    assert!(err.contains(&warning), "{err}");
    // Split, the two holes are one boundary loop through the two copies of the vertex.
    assert_eq!(report["target_topology"]["boundary_loops"], 1, "{report}");
    assert_eq!(report["target_topology"]["genus"], 1, "{report}");
    assert!(report["warnings"][0]
        .as_str()
        .unwrap()
        .contains("split 1 non-manifold vertices"));
}

/// A torus mesh exported with its vertices split along a seam (the faces with `x < 0` have
/// their own copies of every vertex they share with the rest), as texture-mapped exports are:
/// two open patches on file, one closed torus once welded.
fn seamed_torus(dir: &Path) -> std::path::PathBuf {
    let t = torus_mesh(1.0, 0.4, 48, 24, true);
    let mut positions = t.positions.clone();
    let mut copy = vec![u32::MAX; t.positions.len()];
    let mut faces = Polygons::new();
    for poly in t.faces.iter() {
        let left = poly
            .iter()
            .map(|&v| t.positions[v as usize][0])
            .sum::<f64>()
            < 0.0;
        let f: Vec<u32> = poly
            .iter()
            .map(|&v| {
                if !left {
                    return v;
                }
                if copy[v as usize] == u32::MAX {
                    copy[v as usize] = positions.len() as u32;
                    positions.push(t.positions[v as usize]);
                }
                copy[v as usize]
            })
            .collect();
        faces.push(&f);
    }
    let path = dir.join("seamed.obj");
    write_obj(&path, &PolyMesh::new(positions, faces));
    path
}

#[test]
fn a_mesh_split_along_seams_is_welded_with_a_warning() {
    let d = tempfile::tempdir().unwrap();
    let seamed = seamed_torus(d.path());
    let m = seamed.to_str().unwrap();
    let info: serde_json::Value =
        serde_json::from_slice(&subfit(&["info", "--json", m]).stdout).unwrap();
    assert_eq!(info["topology"]["components"], 2, "{info}");
    assert_eq!(info["topology"]["coincident_vertices"], 48, "{info}");

    let (err, report) = quick_fit(m, &d.path().join("fit"), "80");
    let welded = format!("subfit: warning: welded 48 vertices of {m} at the same position");
    assert!(err.contains(&welded), "{err}");
    assert_eq!(report["target_topology"]["genus"], 1, "{report}");
    assert_eq!(report["target_topology"]["boundary_loops"], 0, "{report}");
    assert_eq!(report["init"]["boundary_loops"]["cage"], 0, "{report}");
}

/// A torus mesh with what exports and scanners leave behind: three stray triangles (fins)
/// standing on edges of the surface (edges with three faces), two faces written twice (once
/// turned), and two collapsed faces (a vertex repeated). The face written again in the same
/// turn is a duplicate; the one written again turned could be the other side of a sheet, so it
/// is kept for the cut, which finds it continues nothing and takes it off as a flap.
fn littered_torus(dir: &Path) -> std::path::PathBuf {
    let t = torus_mesh(1.0, 0.4, 48, 24, true);
    let mut positions = t.positions.clone();
    let mut faces = Polygons::new();
    for poly in t.faces.iter() {
        faces.push(poly);
    }
    let polys: Vec<Vec<u32>> = t.faces.iter().map(<[u32]>::to_vec).collect();
    for f in [7, 300, 811] {
        let (a, b) = (polys[f][0], polys[f][1]);
        let (pa, pb) = (positions[a as usize], positions[b as usize]);
        positions.push([
            (pa[0] + pb[0]) / 2.0,
            (pa[1] + pb[1]) / 2.0,
            (pa[2] + pb[2]) / 2.0 + 0.2,
        ]);
        faces.push(&[b, a, (positions.len() - 1) as u32]);
    }
    faces.push(&polys[40]);
    let turned: Vec<u32> = polys[41].iter().rev().copied().collect();
    faces.push(&turned);
    faces.push(&[polys[50][0], polys[50][1], polys[50][1]]);
    faces.push(&[polys[60][0], polys[60][0], polys[60][0]]);
    let path = dir.join("littered.obj");
    write_obj(&path, &PolyMesh::new(positions, faces));
    path
}

#[test]
fn stray_repeated_and_collapsed_faces_are_repaired_with_a_warning() {
    let d = tempfile::tempdir().unwrap();
    let littered = littered_torus(d.path());
    let m = littered.to_str().unwrap();
    let info: serde_json::Value =
        serde_json::from_slice(&subfit(&["info", "--json", m]).stdout).unwrap();
    assert!(
        info["topology"]["non_manifold_edges"].as_u64().unwrap() >= 3,
        "{info}"
    );

    let (err, report) = quick_fit(m, &d.path().join("fit"), "80");
    let faces = format!(
        "subfit: warning: repaired faces of {m}: 2 dropped with fewer than three distinct vertices, 1 dropped as duplicates of an earlier face"
    );
    let cut = format!("subfit: warning: cut 6 edges of {m} shared by more than two faces");
    assert!(err.contains(&faces), "{err}");
    assert!(err.contains(&cut), "{err}");
    assert!(
        err.contains("4 faces of flaps that came off dropped"),
        "{err}"
    );
    // What is left is the closed torus.
    assert_eq!(report["target_topology"]["genus"], 1, "{report}");
    assert_eq!(report["target_topology"]["boundary_loops"], 0, "{report}");
    assert_eq!(report["init"]["boundary_loops"]["cage"], 0, "{report}");
}

/// A torus with two vertices no face uses, one far outside it: they are dropped with a
/// warning, so the diagonal the tolerances are relative to is the torus's own.
#[test]
fn vertices_no_face_uses_are_dropped_with_a_warning() {
    let d = tempfile::tempdir().unwrap();
    let t = torus_mesh(1.0, 0.4, 48, 24, true);
    let clean = d.path().join("clean.obj");
    write_obj(&clean, &t);
    let mut littered = t.clone();
    littered.positions.insert(5, [0.5, 0.0, 0.0]);
    littered.positions.push([30.0, 30.0, 30.0]);
    for v in littered.faces.indices_mut() {
        if *v >= 5 {
            *v += 1;
        }
    }
    let path = d.path().join("unreferenced.obj");
    write_obj(&path, &littered);
    let m = path.to_str().unwrap();
    let (err, report) = quick_fit(m, &d.path().join("fit"), "80");
    let warning =
        format!("subfit: warning: dropped 2 vertices of {m} that no face uses (e.g. vertex 5)");
    assert!(err.contains(&warning), "{err}");
    let (_, clean_report) = quick_fit(clean.to_str().unwrap(), &d.path().join("fit0"), "80");
    assert_eq!(report["target_points"], clean_report["target_points"]);
    assert_eq!(
        report["bbox_diagonal_unit_cube"], clean_report["bbox_diagonal_unit_cube"],
        "{report}"
    );
    assert_eq!(
        report["normalized_unit_in_original_units"],
        clean_report["normalized_unit_in_original_units"]
    );
}
