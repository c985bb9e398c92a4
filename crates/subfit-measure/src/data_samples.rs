//! The points the data → surface distance is measured from.
//!
//! A point cloud is its points. A mesh is its surface: the triangles are sampled uniformly by
//! area (seeded, deterministic), so that large triangles — the parts of a scan a fit is most
//! tempted to leave uncovered, such as the rim around a hole — weigh as much as their area,
//! which is what an independent measurement over the surface sees.

use serde::{Deserialize, Serialize};
use subfit_target::{boundary_vertices, Target};

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
    /// How many of the samples, at the end of [`Self::points`], are boundary vertices of a
    /// mesh target (0 for a point cloud).
    pub boundary: usize,
    /// How many of the samples, just before the boundary vertices, are the mesh target's other
    /// vertices ([`data_samples_with_vertices`]; 0 otherwise). Like the boundary vertices,
    /// they count for the largest distance only.
    pub vertices: usize,
}

impl DataSamples {
    /// How many samples at the end of [`Self::points`] count for the maximum only: the mesh
    /// vertices and the boundary vertices ([`crate::DistanceStats::of_samples`]).
    pub fn extremes(&self) -> usize {
        self.vertices + self.boundary
    }

    /// How many samples at the start of [`Self::points`] are uniform by area (or a cloud's
    /// points): those the RMS is taken over.
    pub fn uniform(&self) -> usize {
        self.points.len() - self.extremes().min(self.points.len())
    }
}

/// The seed of the area samples (fixed: the same target gives the same samples).
const SEED: u64 = 0x5eed_da7a;

/// Area samples of a mesh target at least, when the count is left to [`data_samples`]: the
/// largest data → surface distance is judged on them, and a coarse mesh's own point count
/// misses where it is (a fertility statue cut open at its base, 4,429 points: the largest
/// distance over as many area samples 3.4e-3 of the diagonal, `subfit compare` over 50,000
/// 6.7e-3).
pub const MIN_AREA_SAMPLES: usize = 50_000;

/// The data → surface samples of `target`: its points for a point cloud; for a mesh,
/// `count` points uniform by area on its triangles (`count = 0`: as many as it has points,
/// and at least [`MIN_AREA_SAMPLES`]) and its boundary vertices.
///
/// Cost: O(#triangles + count log #triangles).
pub fn data_samples(target: &Target, count: usize) -> DataSamples {
    let cloud = || DataSamples {
        points: target.points().to_vec(),
        kind: SampleKind::Points,
        boundary: 0,
        vertices: 0,
    };
    let Some(bvh) = target.mesh() else {
        return cloud();
    };
    let count = if count == 0 {
        target.len().max(MIN_AREA_SAMPLES)
    } else {
        count
    };
    let mut points = area_samples(bvh.vertices(), bvh.triangles(), count, SEED);
    if points.is_empty() {
        return cloud();
    }
    // The boundary vertices too: a rim is where an open fit misses most, and area samples
    // land on it with probability zero.
    let rim = boundary_vertices(bvh.triangles());
    points.extend(rim.iter().map(|&v| bvh.vertices()[v as usize]));
    DataSamples {
        points,
        kind: SampleKind::MeshArea,
        boundary: rim.len(),
        vertices: 0,
    }
}

/// [`data_samples`] with the mesh target's vertices that are not on its boundary inserted
/// before the boundary vertices ([`DataSamples::vertices`]): what the final measurement takes
/// the largest data → surface distance over (`subfit::measure_fit`), so that the fit's stages
/// judge their maximum as the final measure will. Without them a stage saw a tolerance
/// reached that the final measure denied at one vertex: a box fitted smooth stopped at 62
/// control points with a corner 0.83 % of the diagonal away, where the stages' area samples
/// said at most 0.6 %. A point cloud's samples are its points already (returned as
/// [`data_samples`] gives them).
///
/// Cost: [`data_samples`] and O(#vertices).
pub fn data_samples_with_vertices(target: &Target, count: usize) -> DataSamples {
    let mut data = data_samples(target, count);
    let Some(bvh) = target.mesh() else {
        return data;
    };
    if data.kind != SampleKind::MeshArea {
        return data;
    }
    let rim_from = data.points.len() - data.boundary;
    let rim: Vec<[f64; 3]> = data.points.split_off(rim_from);
    let mut on_rim = vec![false; bvh.vertices().len()];
    for v in boundary_vertices(bvh.triangles()) {
        on_rim[v as usize] = true;
    }
    let before = data.points.len();
    data.points.extend(
        bvh.vertices()
            .iter()
            .zip(&on_rim)
            .filter(|(_, &r)| !r)
            .map(|(p, _)| *p),
    );
    data.vertices = data.points.len() - before;
    data.points.extend(rim);
    data
}

/// Every vertex of a mesh target (none for a point cloud, whose samples are its points
/// already): where the final measurement takes the largest data → surface distance from, beside
/// the area samples — a spike, a thin tip or a lone vertex is where it is, and area samples land
/// there with probability zero. They count for the maximum only: the RMS stays the area-uniform
/// one (a tessellation's vertices crowd where its triangles are small). Cost O(#vertices).
pub fn mesh_vertices(target: &Target) -> &[[f64; 3]] {
    target.mesh().map_or(&[], |bvh| bvh.vertices())
}

/// `n` points uniformly by area on the triangles `tris` over `p` (seeded SplitMix64; inverse
/// CDF over the cumulative areas, then uniform barycentric coordinates). Empty when the total
/// area is zero or not finite. Cost O(T + n log T).
pub fn area_samples(p: &[[f64; 3]], tris: &[[u32; 3]], n: usize, seed: u64) -> Vec<[f64; 3]> {
    let area = |t: &[u32; 3]| {
        let (a, b, c) = (p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]);
        let (u, v) = (
            [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
            [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
        );
        let w = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        0.5 * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt()
    };
    let mut cum = Vec::with_capacity(tris.len());
    let mut total = 0.0;
    for t in tris {
        total += area(t);
        cum.push(total);
    }
    if !(total > 0.0 && total.is_finite()) {
        return Vec::new();
    }
    let mut state = seed;
    let mut next = move || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            let r = next() * total;
            let i = cum.partition_point(|&c| c < r).min(tris.len() - 1);
            let (mut s, mut t) = (next(), next());
            if s + t > 1.0 {
                (s, t) = (1.0 - s, 1.0 - t);
            }
            let [a, b, c] = tris[i].map(|v| p[v as usize]);
            std::array::from_fn(|k| a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k]))
        })
        .collect()
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
        let n = target.mesh().unwrap().vertices().len();
        assert_eq!(mesh_vertices(&target).len(), n);
        let cloud = subfit_mesh::PolyMesh::point_cloud(mesh.positions.clone(), None);
        let t = Target::from_mesh(&cloud, &TargetOptions::default()).unwrap();
        let s = data_samples(&t, 5_000);
        assert_eq!(s.kind, SampleKind::Points);
        assert_eq!(s.points, t.points());
    }

    #[test]
    fn the_stages_samples_add_every_vertex_before_the_rim() {
        let mesh = subfit_mesh::shapes::gridded_box(6, true);
        let target = Target::from_mesh(&mesh, &TargetOptions::default()).unwrap();
        let plain = data_samples(&target, 2_000);
        let with = data_samples_with_vertices(&target, 2_000);
        let bvh = target.mesh().unwrap();
        let n = bvh.vertices().len();
        assert!(plain.boundary > 0, "an open box has a rim");
        assert_eq!(with.boundary, plain.boundary);
        assert_eq!(with.vertices + with.boundary, n, "every vertex once");
        assert_eq!((with.uniform(), with.extremes()), (2_000, n));
        // The area samples first, the rim last, as they were; the vertices between.
        assert_eq!(with.points[..2_000], plain.points[..2_000]);
        assert_eq!(
            with.points[with.points.len() - with.boundary..],
            plain.points[plain.points.len() - plain.boundary..]
        );
        let mut middle: Vec<[f64; 3]> = with.points[2_000..2_000 + with.vertices].to_vec();
        middle.extend_from_slice(&with.points[with.points.len() - with.boundary..]);
        let key = |p: &[f64; 3]| p.map(f64::to_bits);
        let mut got: Vec<_> = middle.iter().map(key).collect();
        let mut all: Vec<_> = bvh.vertices().iter().map(key).collect();
        got.sort_unstable();
        all.sort_unstable();
        assert_eq!(got, all);
        // A cloud is its points, nothing added.
        let cloud = subfit_mesh::PolyMesh::point_cloud(mesh.positions.clone(), None);
        let t = Target::from_mesh(&cloud, &TargetOptions::default()).unwrap();
        let c = data_samples_with_vertices(&t, 2_000);
        assert_eq!((c.vertices, c.points.len()), (0, t.points().len()));
    }
}
