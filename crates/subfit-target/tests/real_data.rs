//! Normal orientation on real closed models (`$SUBFIT_DATA/*.{off,obj,ply}`): normals estimated
//! from the points alone (file normals and faces ignored) must agree in sign with the mesh's
//! area-weighted face normals at ≥ 99.5 % of the points.
//!
//! Without `SUBFIT_DATA`: fails when `CI=true`, else prints a notice and passes.
#![allow(clippy::print_stdout)]

use std::path::PathBuf;

use subfit_mesh::PolyMesh;
use subfit_target::{NormalSource, Target, TargetOptions};

fn data_dir() -> Option<PathBuf> {
    match std::env::var_os("SUBFIT_DATA") {
        Some(d) => Some(PathBuf::from(d)),
        None => {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "SUBFIT_DATA is not set (needed on CI: the directory of shared/data)"
            );
            println!("notice: SUBFIT_DATA not set, skipping the real-data orientation test");
            None
        }
    }
}

/// Closed models listed in shared/data/SOURCES.md.
const CLOSED: &[&str] = &[
    "armadillo.obj",
    "bunny.off",
    "decimated-max.obj",
    "fandisk.obj",
    "fertility.off",
    "igea.ply",
    "lucy.ply",
    "rocker-arm.off",
];

/// Known failures, reported but not asserted (open issue 4): lucy.ply (7.5k points, a sparse
/// decimation with thin parts): ~90 % after tree propagation and consensus, ~94.5 % after the
/// global winding-number check (`orient` step 4); about 5 % of its estimated normals are more than
/// 60° off the mesh's, whatever the sign. Measured limits of the local approach there: 3.4 % of
/// lucy's points have their nearest neighbour on an opposite-facing sheet (|cos| > 0.3 the wrong
/// way; Igea 0.001 %, bunny 0.09 %); PCA directions at the best fixed k (10) are within 45° at only
/// 87 % of points (98.5 % with an oracle choice of k per point); and even with the mesh's own normal
/// directions (random signs), the MST propagation here reaches at most 98.0 % (graph k 6–16,
/// tangent penalty 0–3). The remaining errors are mostly whole regions of a few hundred points
/// that stay self-consistent under the per-point winding test (e.g. both sheets of a thin part
/// flipped together): a joint, region-level decision (or a regularized winding field, Xu et al.
/// 2023) would be next.
const KNOWN_HARD: &[&str] = &["lucy.ply"];

fn face_normals(mesh: &PolyMesh) -> Vec<[f64; 3]> {
    let mut acc = vec![[0.0; 3]; mesh.positions.len()];
    for t in mesh.faces.triangulate_fan() {
        let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
        let (u, v) = (
            [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
            [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
        );
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        for &i in &t {
            for k in 0..3 {
                acc[i as usize][k] += n[k];
            }
        }
    }
    acc
}

#[test]
fn estimated_normals_agree_with_closed_meshes() {
    let Some(dir) = data_dir() else { return };
    let mut failures = Vec::new();
    for name in CLOSED {
        let path = dir.join(name);
        if !path.exists() {
            failures.push(format!("{name}: missing"));
            continue;
        }
        let (mesh, _) = subfit_io::read_file(&path, &subfit_io::ReadOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let reference = face_normals(&mesh);
        let opts = TargetOptions {
            normals: NormalSource::Estimate,
            ..TargetOptions::default()
        };
        let cloud = PolyMesh::point_cloud(mesh.positions.clone(), None);
        let t = Target::from_mesh(&cloud, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
        let (mut agree, mut total, mut skew) = (0usize, 0usize, 0usize);
        for (i, r) in reference.iter().enumerate() {
            if r == &[0.0; 3] {
                continue; // unreferenced vertex
            }
            let n = t.normals()[t.input_to_point()[i] as usize];
            total += 1;
            let c = (n[0] * r[0] + n[1] * r[1] + n[2] * r[2])
                / (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
            if c > 0.0 {
                agree += 1;
            }
            if c.abs() < 0.5 {
                skew += 1;
            }
        }
        let frac = agree as f64 / total as f64;
        let s = t.stats();
        println!(
            "{name}: {} points, {:.3}% agree, {:.3}% skewed (|cos| < 0.5), components {}, ambiguous {}, winding flips {}, build {:?}",
            t.len(),
            frac * 100.0,
            skew as f64 / total as f64 * 100.0,
            s.orientation_components,
            s.ambiguous_normals,
            s.winding_flips,
            s.timings.total
        );
        if frac < 0.995 && !KNOWN_HARD.contains(name) {
            failures.push(format!("{name}: {:.3}% agree", frac * 100.0));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}
