//! The angle criterion for points on the edge of an open cloud (Bendels, Schnabel & Klein
//! 2006, "Detecting holes in point set surfaces", §3.1): project a point's `k` nearest
//! neighbours onto its tangent plane and take the widest angular gap between consecutive
//! neighbours around it ([`AngularGap`]). Used by [`crate::cloud_rim`] (through
//! `boundary_flags`) and by the outlier scan (module `outliers`).

use rayon::prelude::*;

use crate::neighbors::PointIndex;

/// Neighbours looked at per point by default.
pub const RIM_NEIGHBORS: usize = 24;

/// The default angular gap (radians, 150°) from which a point is on the edge: a straight edge
/// leaves a gap of π, a corner more; random uniform samples of a closed surface leave none
/// this wide among 24 neighbours (with 16 neighbours and 120°, 4% of them did).
pub const RIM_GAP: f64 = 150.0 * std::f64::consts::PI / 180.0;

/// [`crate::cloud_boundary_points`] on the arrays of a target: `points` and `normals` (`#P by
/// 3`, normalized units) and their kd-tree `index`. Cost: one `k + 1`-nearest query and a sort
/// of `k` angles per point, in parallel.
pub(crate) fn boundary_flags(
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    index: &PointIndex,
    k: usize,
    max_gap: f64,
) -> Vec<bool> {
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
