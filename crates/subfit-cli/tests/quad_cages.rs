//! Quad cages laid along a cross field (`--quads field`, the default for a quad scheme, and
//! `--quads only`): a torus, whose principal directions admit a cage without irregular
//! vertices, gets a closed genus-1 cage of quads with fewer irregular vertices than the paired
//! simplification; `--quads only` writes nothing but quads; and on the corpus's artist cage
//! (Keenan Crane's Bob, `SUBFIT_CORPUS`: skipped with a notice without it, a failure under
//! `CI=true`) the Catmull-Clark cage at the artist's count is closer to the dense mesh than the
//! artist's own on both figures, measured by `subfit compare` on both, with fewer irregular
//! vertices than the paired cage.

#![allow(clippy::print_stdout)]

mod common;

use std::path::{Path, PathBuf};

use common::{corpus_dir, subfit};
use subfit::io::{Encoding, WriteOptions};
use subfit::mesh::shapes::torus_mesh;
use subfit::mesh::PolyMesh;

/// Writes `mesh` to `dir/name` as full-precision ASCII.
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

/// Vertices and polygons of an OBJ (positions only, 0-based indices).
fn read_obj(path: &Path) -> (usize, Vec<Vec<usize>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let v = text.lines().filter(|l| l.starts_with("v ")).count();
    let f = text
        .lines()
        .filter(|l| l.starts_with("f "))
        .map(|l| {
            l.split_whitespace()
                .skip(1)
                .map(|t| t.split('/').next().unwrap().parse::<usize>().unwrap() - 1)
                .collect()
        })
        .collect();
    (v, f)
}

/// Irregular vertices of a closed polygon mesh: valence (edges at the vertex) other than 4.
fn irregular(v: usize, faces: &[Vec<usize>]) -> usize {
    let mut edges = std::collections::BTreeSet::new();
    for f in faces {
        for i in 0..f.len() {
            let (a, b) = (f[i], f[(i + 1) % f.len()]);
            edges.insert((a.min(b), a.max(b)));
        }
    }
    let mut valence = vec![0usize; v];
    for (a, b) in edges {
        valence[a] += 1;
        valence[b] += 1;
    }
    valence.iter().filter(|&&k| k != 4).count()
}

/// Euler characteristic `V − E + F` of a polygon mesh.
fn euler(v: usize, faces: &[Vec<usize>]) -> i64 {
    let e = faces.iter().map(Vec::len).sum::<usize>() / 2;
    v as i64 - e as i64 + faces.len() as i64
}

/// `subfit init TARGET --control-points N --quad-dominant --quads LAYOUT -o OUT`: the cage.
fn init(target: &Path, out: &Path, n: &str, layout: &str) -> (usize, Vec<Vec<usize>>, String) {
    let r = subfit(&[
        "init",
        target.to_str().unwrap(),
        "--control-points",
        n,
        "--quad-dominant",
        "--quads",
        layout,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let (v, f) = read_obj(out);
    (v, f, String::from_utf8_lossy(&r.stdout).into_owned())
}

#[test]
fn a_torus_cage_along_the_cross_field_has_fewer_irregular_vertices_than_the_paired_one() {
    let d = tempfile::tempdir().unwrap();
    let torus = write(d.path(), "torus.obj", &torus_mesh(1.0, 0.4, 96, 40, true));
    let (v, f, text) = init(&torus, &d.path().join("field.obj"), "200", "field");
    assert!(text.contains("along a cross field"), "{text}");
    assert!(v <= 200, "{v} vertices");
    assert_eq!(euler(v, &f), 0, "genus 1: {text}");
    let quads = f.iter().filter(|p| p.len() == 4).count();
    assert!(
        quads as f64 >= 0.9 * f.len() as f64,
        "{quads} of {}",
        f.len()
    );
    let (pv, pf, _) = init(&torus, &d.path().join("paired.obj"), "200", "paired");
    let (field, paired) = (irregular(v, &f), irregular(pv, &pf));
    println!("torus at 200: field {field} irregular of {v}, paired {paired} of {pv}");
    assert!(field < paired, "field {field}, paired {paired}");
}

#[test]
fn a_hole_smaller_than_a_cell_is_kept_as_a_hole() {
    let d = tempfile::tempdir().unwrap();
    let mut torus = torus_mesh(1.0, 0.4, 96, 40, true);
    // Two triangles out: a hole far smaller than a cell of a 200-point lattice.
    let tris: Vec<[u32; 3]> = torus
        .faces
        .iter()
        .skip(2)
        .map(|f| [f[0], f[1], f[2]])
        .collect();
    torus.faces = subfit::mesh::Polygons::from_triangles(&tris);
    let torus = write(d.path(), "holed.obj", &torus);
    let (v, f, text) = init(&torus, &d.path().join("field.obj"), "200", "field");
    assert!(text.contains("along a cross field"), "{text}");
    // Genus 1 with one boundary loop: V − E + F = 2 − 2g − b = −1 (a boundary edge counted
    // once: E = (Σ sizes + boundary edges) / 2).
    let mut edges = std::collections::BTreeMap::new();
    for p in &f {
        for i in 0..p.len() {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let boundary = edges.values().filter(|&&k| k == 1).count();
    assert!(boundary >= 3, "no hole: {text}");
    assert_eq!(v as i64 - edges.len() as i64 + f.len() as i64, -1, "{text}");
}

#[test]
fn quads_only_writes_only_quads_and_refuses_loop() {
    let d = tempfile::tempdir().unwrap();
    let torus = write(d.path(), "torus.obj", &torus_mesh(1.0, 0.4, 96, 40, true));
    let out = d.path().join("fit");
    let r = subfit(&[
        "fit",
        torus.to_str().unwrap(),
        "--quads",
        "only",
        "--max-control-points",
        "300",
        "--max-iterations",
        "6",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        matches!(r.status.code(), Some(0 | 1)),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let (v, f) = read_obj(&out.join("control.obj"));
    assert!(f.iter().all(|p| p.len() == 4), "a face that is not a quad");
    assert!(v <= 300, "{v} control points over the budget");
    assert_eq!(euler(v, &f), 0);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["control_quad_fraction"].as_f64(), Some(1.0));
    let r = subfit(&[
        "fit",
        torus.to_str().unwrap(),
        "--quads",
        "only",
        "--scheme",
        "loop",
        "-o",
        d.path().join("loop").to_str().unwrap(),
    ]);
    assert_eq!(r.status.code(), Some(2));
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("--quads only"), "{err}");
    assert!(!d.path().join("loop").join("control.obj").exists());
}

/// `subfit compare CAGE DENSE --scheme catmull-clark --json`: (two-sided RMS, Hausdorff) as
/// fractions of the diagonal.
fn compare(cage: &Path, dense: &Path) -> (f64, f64) {
    let r = subfit(&[
        "compare",
        cage.to_str().unwrap(),
        dense.to_str().unwrap(),
        "--scheme",
        "catmull-clark",
        "--samples",
        "100000",
        "--json",
    ]);
    assert_eq!(r.status.code(), Some(0));
    let j: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    (
        j["two_sided_rms_fraction"].as_f64().unwrap(),
        j["hausdorff_fraction"].as_f64().unwrap(),
    )
}

#[test]
fn the_artist_cage_pair_is_beaten_on_both_figures_at_its_count() {
    let Some(corpus) = corpus_dir() else { return };
    let (control, dense) = (
        corpus.join("cage-bob/control.obj"),
        corpus.join("cage-bob/dense.obj"),
    );
    let (cv, cf) = read_obj(&control);
    let n = cv.to_string();
    let d = tempfile::tempdir().unwrap();
    let fit = |dir: &str, layout: &str| {
        let out = d.path().join(dir);
        let r = subfit(&[
            "fit",
            dense.to_str().unwrap(),
            "--scheme",
            "catmull-clark",
            "--control-points",
            &n,
            "--max-control-points",
            &n,
            "--quads",
            layout,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(
            matches!(r.status.code(), Some(0 | 1)),
            "{}",
            String::from_utf8_lossy(&r.stderr)
        );
        out.join("control.obj")
    };
    let ours = fit("field", "field");
    let paired = fit("paired", "paired");
    let (artist_rms, artist_h) = compare(&control, &dense);
    let (rms, h) = compare(&ours, &dense);
    let (v, f) = read_obj(&ours);
    let (pv, pf) = read_obj(&paired);
    println!(
        "Bob at {n}: ours {v} points, RMS {rms:.3e}, Hausdorff {h:.3e}, {} irregular; artist RMS {artist_rms:.3e}, Hausdorff {artist_h:.3e}, {} irregular; paired {} irregular",
        irregular(v, &f),
        irregular(cv, &cf),
        irregular(pv, &pf)
    );
    assert!(v <= cv);
    assert!(rms < artist_rms && h < artist_h);
    let quads = f.iter().filter(|p| p.len() == 4).count();
    assert!(quads as f64 >= 0.9 * f.len() as f64);
    assert!(irregular(v, &f) < irregular(pv, &pf));
}
