//! The boundary points of an open point cloud (a single-view scan, a cut-off base): the classic
//! angle criterion (e.g. Bendels, Schnabel & Klein 2006, "Detecting holes in point set
//! surfaces", §3.1, the "angle criterion"): project a point's `k` nearest neighbours onto its
//! tangent plane and look at the largest angular gap between consecutive neighbours around it.
//! An interior point is surrounded (gaps of about `2π/k`); a point on the data's edge has all
//! its neighbours on one side (a gap near π); a corner of the edge, more.
//!
//! Cost: one `k`-nearest query and a sort of `k` angles per point, in parallel.
//!
//! The criterion itself (`AngularGap`, the defaults [`RIM_NEIGHBORS`] and [`RIM_GAP`]) lives
//! in module `angular_gap`, below [`Target`], so that the target and the outlier scan use it
//! without naming this module; [`cloud_boundary_points`] is its entry point on a [`Target`].

use crate::angular_gap::boundary_flags;
pub use crate::angular_gap::{RIM_GAP, RIM_NEIGHBORS};
use crate::Target;

/// Whether each of `target`'s points is on the boundary of the cloud: the largest angular gap
/// between its `k` nearest neighbours projected onto its tangent plane (the plane of its
/// normal) exceeds `max_gap` radians (defaults [`RIM_NEIGHBORS`], [`RIM_GAP`]). Points
/// without a usable normal count as interior.
pub fn cloud_boundary_points(target: &Target, k: usize, max_gap: f64) -> Vec<bool> {
    boundary_flags(
        target.points(),
        target.normals(),
        target.index(),
        k,
        max_gap,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TargetOptions;

    /// A square grid of points in the plane z = 0 (normals +z): its outer ring is the
    /// boundary, everything inside is not.
    #[test]
    fn the_edge_of_a_square_patch_and_nothing_inside() {
        let n = 40;
        let mut p = Vec::new();
        for j in 0..n {
            for i in 0..n {
                // A slight jitter so neighbours are not exactly tied.
                let jitter = 0.1 * (((i * 7 + j * 13) % 10) as f64 / 10.0 - 0.5);
                p.push([i as f64 + jitter, j as f64 - jitter, 0.0]);
            }
        }
        let normals = vec![[0.0, 0.0, 1.0]; p.len()];
        let t = Target::from_points(&p, Some(&normals), &TargetOptions::default()).unwrap();
        let rim = cloud_boundary_points(&t, RIM_NEIGHBORS, RIM_GAP);
        for j in 0..n {
            for i in 0..n {
                let edge = i == 0 || j == 0 || i == n - 1 || j == n - 1;
                let inner = i >= 2 && j >= 2 && i < n - 2 && j < n - 2;
                let k = j * n + i;
                // `Target` keeps the points in order (no duplicates, no outliers here).
                if edge {
                    assert!(rim[k], "edge point ({i}, {j}) not found");
                }
                if inner {
                    assert!(!rim[k], "inner point ({i}, {j}) taken for the edge");
                }
            }
        }
    }

    /// A closed sphere has no boundary point.
    #[test]
    fn a_sphere_has_none() {
        let cloud = subfit_mesh::shapes::Shape::PAPER_ELLIPSOID.sample(5000, 0.0, 3);
        let t = Target::from_points(
            &cloud.positions,
            cloud.normals.as_deref(),
            &TargetOptions::default(),
        )
        .unwrap();
        // Random samples leave gaps: with 16 neighbours and 120° about 4% of them pass for
        // the edge, with the defaults none.
        let rim = cloud_boundary_points(&t, RIM_NEIGHBORS, RIM_GAP);
        assert_eq!(rim.iter().filter(|&&b| b).count(), 0);
    }
}
