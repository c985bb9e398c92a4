//! The boundary points of an open point cloud (a single-view scan, a cut-off base): the classic
//! angle criterion (e.g. Bendels, Schnabel & Klein 2006, "Detecting holes in point set
//! surfaces", §3.1, the "angle criterion"): project a point's `k` nearest neighbours onto its
//! tangent plane and look at the largest angular gap between consecutive neighbours around it.
//! An interior point is surrounded (gaps of about `2π/k`); a point on the data's edge has all
//! its neighbours on one side (a gap near π); a corner of the edge, more.
//!
//! Cost: one `k`-nearest query and a sort of `k` angles per point, in parallel.

use rayon::prelude::*;

use crate::Target;

/// Neighbours looked at per point by default.
pub const RIM_NEIGHBORS: usize = 24;

/// The default angular gap (radians, 150°) from which a point is on the edge: a straight edge
/// leaves a gap of π, a corner more; random uniform samples of a closed surface leave none
/// this wide among 24 neighbours (with 16 neighbours and 120°, 4% of them did).
pub const RIM_GAP: f64 = 150.0 * std::f64::consts::PI / 180.0;

/// Whether each of `target`'s points is on the boundary of the cloud: the largest angular gap
/// between its `k` nearest neighbours projected onto its tangent plane (the plane of its
/// normal) exceeds `max_gap` radians (defaults [`RIM_NEIGHBORS`], [`RIM_GAP`]). Points
/// without a usable normal count as interior.
pub fn cloud_boundary_points(target: &Target, k: usize, max_gap: f64) -> Vec<bool> {
    let points = target.points();
    let normals = target.normals();
    let index = target.index();
    (0..points.len())
        .into_par_iter()
        .map(|i| {
            let p = points[i];
            let n = normals[i];
            let Some((u, v)) = tangent_basis(n) else {
                return false;
            };
            let mut angles: Vec<f64> = index
                .k_nearest(&p, k + 1)
                .iter()
                .filter(|nb| nb.index as usize != i)
                .filter_map(|nb| {
                    let q = points[nb.index as usize];
                    let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
                    let (x, y) = (dot(d, u), dot(d, v));
                    (x * x + y * y > 0.0).then(|| y.atan2(x))
                })
                .collect();
            if angles.len() < 3 {
                return false;
            }
            angles.sort_by(f64::total_cmp);
            let wrap = angles[0] + std::f64::consts::TAU - angles[angles.len() - 1];
            let gap = angles.windows(2).map(|w| w[1] - w[0]).fold(wrap, f64::max);
            gap > max_gap
        })
        .collect()
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Two unit vectors spanning the plane normal to `n` (None for a zero normal).
fn tangent_basis(n: [f64; 3]) -> Option<([f64; 3], [f64; 3])> {
    let l = dot(n, n).sqrt();
    if !(l > 1e-12) {
        return None;
    }
    let n = n.map(|c| c / l);
    let a = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let u = [
        n[1] * a[2] - n[2] * a[1],
        n[2] * a[0] - n[0] * a[2],
        n[0] * a[1] - n[1] * a[0],
    ];
    let lu = dot(u, u).sqrt();
    let u = u.map(|c| c / lu);
    let v = [
        n[1] * u[2] - n[2] * u[1],
        n[2] * u[0] - n[0] * u[2],
        n[0] * u[1] - n[1] * u[0],
    ];
    Some((u, v))
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
