//! Normal orientation on real closed models (`$SUBFIT_DATA/*.{off,obj,ply}`): normals estimated
//! from the points alone (file normals and faces ignored) must agree in sign with the mesh's
//! area-weighted face normals at ≥ 99.5 % of the points.
//!
//! Without `SUBFIT_DATA`: fails when `CI=true`, else prints a notice and passes.
#![allow(clippy::print_stdout)]

mod common;

use subfit_mesh::PolyMesh;
use subfit_target::{NormalSource, Target, TargetOptions};

/// Closed models listed in shared/data/SOURCES.md. The hard one is lucy.ply (7.5k points, a
/// sparse decimation with thin parts; 94.5 % after the winding check alone): the field
/// refinement of `orient` step 5 brings it to 99.6 %.
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
    let Some(dir) = common::data_dir("the real-data orientation test") else {
        return;
    };
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
            "{name}: {} points, {:.3}% agree, {:.3}% skewed (|cos| < 0.5), components {}, ambiguous {}, winding flips {}, field: suspicious {} iterations {} flips {} redirected {}, build {:?}",
            t.len(),
            frac * 100.0,
            skew as f64 / total as f64 * 100.0,
            s.orientation_components,
            s.ambiguous_normals,
            s.winding_flips,
            s.field_suspicious,
            s.field_iterations,
            s.field_flips,
            s.field_redirected,
            s.timings.total
        );
        if frac < 0.995 {
            failures.push(format!("{name}: {:.3}% agree", frac * 100.0));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}
