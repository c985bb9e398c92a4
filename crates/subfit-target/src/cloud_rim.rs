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
            let near = index
                .k_nearest(&p, k + 1)
                .into_iter()
                .filter(|nb| nb.index as usize != i)
                .map(|nb| points[nb.index as usize]);
            AngularGap::around(p, normals[i], near).is_some_and(|g| g.width > max_gap)
        })
        .collect()
}

/// The widest angular gap around a point between its neighbours, projected onto its tangent
/// plane (the angle criterion above).
#[derive(Clone, Copy, Debug)]
pub(crate) struct AngularGap {
    u: [f64; 3],
    v: [f64; 3],
    /// Angle (radians, in the tangent frame) where the gap starts, counter-clockwise.
    start: f64,
    /// Width of the gap (radians).
    pub width: f64,
}

impl AngularGap {
    /// The widest gap around `p` in the plane normal to `n` between `neighbours` (those
    /// projecting onto `p` ignored). `None` for a zero normal or fewer than 3 neighbours.
    pub(crate) fn around(
        p: [f64; 3],
        n: [f64; 3],
        neighbours: impl IntoIterator<Item = [f64; 3]>,
    ) -> Option<Self> {
        let (u, v) = tangent_basis(n)?;
        let angle = |q: [f64; 3]| {
            let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
            let (x, y) = (dot(d, u), dot(d, v));
            (x * x + y * y > 0.0).then(|| y.atan2(x))
        };
        let mut angles: Vec<f64> = neighbours.into_iter().filter_map(angle).collect();
        if angles.len() < 3 {
            return None;
        }
        angles.sort_by(f64::total_cmp);
        let last = angles[angles.len() - 1];
        let mut gap = (last, angles[0] + std::f64::consts::TAU - last);
        for w in angles.windows(2) {
            if w[1] - w[0] > gap.1 {
                gap = (w[0], w[1] - w[0]);
            }
        }
        Some(Self {
            u,
            v,
            start: gap.0,
            width: gap.1,
        })
    }

    /// Whether the direction from `p` (the point the gap is around) to `q`, projected onto the
    /// tangent plane, lies inside the gap (false when `q` projects onto `p`).
    pub(crate) fn contains(&self, p: [f64; 3], q: [f64; 3]) -> bool {
        let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
        let (x, y) = (dot(d, self.u), dot(d, self.v));
        if x * x + y * y == 0.0 {
            return false;
        }
        let rel = (y.atan2(x) - self.start).rem_euclid(std::f64::consts::TAU);
        rel < self.width
    }
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
