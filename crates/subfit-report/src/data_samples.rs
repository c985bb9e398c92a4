//! The points the data → surface distance is measured from.
//!
//! A point cloud is its points. A mesh is its surface: the triangles are sampled uniformly by
//! area (seeded, deterministic), so that large triangles — the parts of a scan a fit is most
//! tempted to leave uncovered, such as the rim around a hole — weigh as much as their area,
//! which is what an independent measurement over the surface sees.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};
use subfit_target::Target;

/// Where the data → surface samples come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SampleKind {
    /// The target's points (a point cloud).
    Points,
    /// Points on the target's triangles, uniform by area.
    MeshArea,
}

/// Data samples in the target's normalized units.
#[derive(Clone, Debug, PartialEq)]
pub struct DataSamples {
    /// The samples, `#S by 3`.
    pub points: Vec<[f64; 3]>,
    /// Their source.
    pub kind: SampleKind,
}

/// The seed of the area samples (fixed: the same target gives the same samples).
const SEED: u64 = 0x5eed_da7a;

/// The data → surface samples of `target`: its points for a point cloud; for a mesh,
/// `count` points uniform by area on its triangles (`count = 0`: as many as it has points).
///
/// Cost: O(#triangles + count).
pub fn data_samples(target: &Target, count: usize) -> DataSamples {
    let Some(bvh) = target.mesh() else {
        return DataSamples {
            points: target.points().to_vec(),
            kind: SampleKind::Points,
        };
    };
    let (v, tris) = (bvh.vertices(), bvh.triangles());
    let corner = |t: &[u32; 3]| [v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]];
    // Cumulative areas for inverse-CDF sampling.
    let mut cum = Vec::with_capacity(tris.len());
    let mut total = 0.0;
    for t in tris {
        let [a, b, c] = corner(t);
        let (e1, e2): ([f64; 3], [f64; 3]) = (
            std::array::from_fn(|k| b[k] - a[k]),
            std::array::from_fn(|k| c[k] - a[k]),
        );
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        total += 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        cum.push(total);
    }
    let count = if count == 0 { target.len() } else { count };
    if !(total > 0.0) {
        return DataSamples {
            points: target.points().to_vec(),
            kind: SampleKind::Points,
        };
    }
    let mut rng = StdRng::seed_from_u64(SEED);
    let points = (0..count)
        .map(|_| {
            let x = rng.random::<f64>() * total;
            let i = cum.partition_point(|&c| c < x).min(tris.len() - 1);
            let [a, b, c] = corner(&tris[i]);
            let (mut r1, mut r2): (f64, f64) = (rng.random(), rng.random());
            if r1 + r2 > 1.0 {
                (r1, r2) = (1.0 - r1, 1.0 - r2);
            }
            std::array::from_fn(|k| a[k] + r1 * (b[k] - a[k]) + r2 * (c[k] - a[k]))
        })
        .collect();
    DataSamples {
        points,
        kind: SampleKind::MeshArea,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfit_mesh::shapes::torus_mesh;
    use subfit_target::TargetOptions;

    #[test]
    fn area_samples_lie_on_the_mesh_and_clouds_give_their_points() {
        let mesh = torus_mesh(0.35, 0.15, 48, 24, true);
        let target = Target::from_mesh(&mesh, &TargetOptions::default()).unwrap();
        let s = data_samples(&target, 5_000);
        assert_eq!((s.kind, s.points.len()), (SampleKind::MeshArea, 5_000));
        let bvh = target.mesh().unwrap();
        for p in &s.points {
            assert!(bvh.closest(*p).unwrap().distance < 1e-12);
        }
        assert_eq!(s, data_samples(&target, 5_000), "deterministic");
        let cloud = subfit_mesh::PolyMesh::point_cloud(mesh.positions.clone(), None);
        let t = Target::from_mesh(&cloud, &TargetOptions::default()).unwrap();
        let s = data_samples(&t, 5_000);
        assert_eq!(s.kind, SampleKind::Points);
        assert_eq!(s.points, t.points());
    }
}
