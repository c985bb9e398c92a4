//! Helpers shared by the golden tests: reading OpenSubdiv reference files (format of
//! `shared/golden/opensubdiv/README.md`) and matching limit points as point sets.
#![allow(dead_code, reason = "each test binary uses a subset")]
#![allow(
    clippy::print_stdout,
    reason = "the tests report the errors they measured"
)]

use std::path::PathBuf;
use subfit_mesh::Polygons;

/// Positions to 1e-12 of the bounding-box diagonal (the README's tolerance).
pub const POS_TOL: f64 = 1e-12;
/// Normals to 1e-9 radians.
pub const ANGLE_TOL: f64 = 1e-9;

pub fn golden_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("SUBFIT_GOLDEN")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/golden/opensubdiv")
        });
    if dir.join("README.md").exists() {
        return Some(dir);
    }
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("golden directory {} missing (CI=true)", dir.display());
    }
    println!(
        "notice: golden directory {} missing; skipping",
        dir.display()
    );
    None
}

/// Reads a golden control mesh with the project's OBJ reader.
pub fn read_obj(path: &std::path::Path) -> (Vec<[f64; 3]>, Polygons) {
    let (mesh, _) = subfit_io::read_file(path, &subfit_io::ReadOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    (mesh.positions, mesh.faces)
}

/// Rows `x y z nx ny nz` after a count line.
pub fn read_lim(path: &std::path::Path) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let n: usize = lines.next().unwrap().trim().parse().unwrap();
    let (mut p, mut nrm) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let c: Vec<f64> = line
            .split_whitespace()
            .map(|s| s.parse().unwrap())
            .collect();
        p.push([c[0], c[1], c[2]]);
        nrm.push([c[3], c[4], c[5]]);
    }
    assert_eq!(p.len(), n, "{}", path.display());
    (p, nrm)
}

pub fn diag(p: &[[f64; 3]]) -> f64 {
    let (lo, hi) = subfit_mesh::bounding_box(p).unwrap();
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
}

pub fn dist(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
}

pub fn angle(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let c = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let s = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    let d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    s.atan2(d)
}

/// Matches each of `ours` to its nearest reference point (sorted by x, window search) and checks
/// the matching is one-to-one. Returns `(max position error, max normal angle)`.
pub fn compare(
    ours: &[[f64; 3]],
    our_n: &[[f64; 3]],
    refp: &[[f64; 3]],
    ref_n: &[[f64; 3]],
    scale: f64,
    what: &str,
) -> (f64, f64) {
    assert_eq!(ours.len(), refp.len(), "{what}: vertex counts differ");
    let mut order: Vec<usize> = (0..refp.len()).collect();
    order.sort_by(|&a, &b| refp[a][0].total_cmp(&refp[b][0]));
    let xs: Vec<f64> = order.iter().map(|&i| refp[i][0]).collect();
    let window = 1e-6 * scale;
    let mut used = vec![false; refp.len()];
    let (mut max_d, mut max_a) = (0.0f64, 0.0f64);
    for (i, p) in ours.iter().enumerate() {
        let lo = xs.partition_point(|&x| x < p[0] - window);
        let hi = xs.partition_point(|&x| x <= p[0] + window);
        let best = order[lo..hi]
            .iter()
            .copied()
            .min_by(|&a, &b| dist(p, &refp[a]).total_cmp(&dist(p, &refp[b])));
        let Some(j) = best else {
            panic!("{what}: no reference point near our vertex {i} {p:?}");
        };
        assert!(!used[j], "{what}: reference point {j} matched twice");
        used[j] = true;
        max_d = max_d.max(dist(p, &refp[j]) / scale);
        max_a = max_a.max(angle(&our_n[i], &ref_n[j]));
    }
    (max_d, max_a)
}
