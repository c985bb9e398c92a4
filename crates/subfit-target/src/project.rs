//! Foot-point queries: the closest point on the target to any point `x`, with the local frame,
//! signed distance and curvature data of the SD error term (Cheng 2007 §II-D3, eq. 5–6;
//! DESIGN.md §3.2).
//!
//! Method: the nearest data point by kd-tree, then the closest point on that point's local
//! quadric (Newton on the height function, [`LocalQuadric::project_local`]).
//!
//! Signs, quoting Cheng 2007 §II-D3: "If the sample point S_k is on the side of Γ_T pointed to by
//! N, i.e., N·(S_k⁰ − V_k⁰) > 0, then d > 0; otherwise, d ≤ 0. Similarly, if the curvature center
//! in the normal section along the tangent vector T_i is on the side of Γ_T pointed to by N, then
//! ρ_i > 0; otherwise, ρ_i ≤ 0." and "α_1 = d/(d − ρ_1) and α_2 = d/(d − ρ_2) … Denote
//! [α]₊ = max{α, 0}." So for a sphere of radius r with outward normals: ρ = −r, a point outside
//! has d > 0 and α = d/(d + r) ∈ (0, 1); a point inside has d < 0 and [α]₊ = 0.

use rayon::prelude::*;

use crate::closest::MeshClosestPoint;
use crate::quadric::LocalQuadric;
use crate::target::Target;
use crate::vec3::{add, dot, sub};

/// Newton iterations of the projection onto a quadric.
const MAX_ITER: usize = 10;
/// Newton step tolerance (normalized units).
const TOL: f64 = 1e-14;

/// Batches at least this large are processed in Morton order.
const SPATIAL_SORT_MIN: usize = 4096;

/// The foot point of a query point on the target, with everything the PD/TD/SD terms need.
/// All in normalized units.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FootPoint {
    /// The foot point `V` on the target surface.
    pub point: [f64; 3],
    /// Signed distance `d`: `|d| = ‖x − V‖`, positive on the side `normal` points to.
    pub distance: f64,
    /// Unit normal `N` at `V` (oriented like the target's normals).
    pub normal: [f64; 3],
    /// Unit principal direction `T1` (of `k1`), ⟂ `N`.
    pub t1: [f64; 3],
    /// Unit principal direction `T2` (of `k2`), ⟂ `N` and `T1`.
    pub t2: [f64; 3],
    /// Signed principal curvature `κ1 = 1/ρ1`, `|κ1| ≤ |κ2|` (1/normalized units).
    pub k1: f64,
    /// Signed principal curvature `κ2 = 1/ρ2`.
    pub k2: f64,
    /// Signed principal radius `ρ1 = 1/κ1` (±∞ when `κ1 = ±0`), `ρ < 0` when the curvature
    /// centre is on the side opposite to `N` (e.g. a sphere with outward normals).
    pub rho1: f64,
    /// Signed principal radius `ρ2 = 1/κ2`.
    pub rho2: f64,
    /// `[α1]₊ = max(d/(d − ρ1), 0)`; set to 0 when `d κ1 ≥ 1` (query beyond the focal point,
    /// where `V` is not a local closest point and eq. 5 does not hold).
    pub alpha1: f64,
    /// `[α2]₊`, as `alpha1`.
    pub alpha2: f64,
    /// Index of the nearest data point, whose quadric was used.
    pub nearest: u32,
}

/// `[α]₊` from the signed distance and curvature (see [`FootPoint::alpha1`]).
#[inline]
pub fn alpha_plus(d: f64, kappa: f64) -> f64 {
    let dk = d * kappa;
    if dk < 1.0 {
        (dk / (dk - 1.0)).max(0.0)
    } else {
        0.0
    }
}

/// The foot point of `x` (normalized coordinates) on one quadric with origin `origin`.
pub fn foot_point_on(
    quadric: &LocalQuadric,
    origin: [f64; 3],
    x: [f64; 3],
    nearest: u32,
) -> FootPoint {
    let loc = quadric.local(sub(x, origin));
    let (u, v) = quadric.project_local(loc, MAX_ITER, TOL);
    let f = quadric.frame_at(u, v);
    let point = add(origin, f.offset);
    let distance = dot(sub(x, point), f.normal);
    FootPoint {
        point,
        distance,
        normal: f.normal,
        t1: f.t1,
        t2: f.t2,
        k1: f.k1,
        k2: f.k2,
        rho1: 1.0 / f.k1,
        rho2: 1.0 / f.k2,
        alpha1: alpha_plus(distance, f.k1),
        alpha2: alpha_plus(distance, f.k2),
        nearest,
    }
}

impl Target {
    /// The foot point of `x` (normalized coordinates). Cost: one nearest-neighbour query (≈1 µs)
    /// plus a few Newton steps. Accurate where the nearest data point's quadric represents the
    /// surface (dense sampling, `|d|` well below the local radii of curvature); not checked.
    ///
    /// When the data point nearest to the first foot point may differ from the one nearest to
    /// `x` (queries far from the surface or near strong curvature), the projection is redone once
    /// on that point's quadric, which represents the surface better there. That second query is
    /// skipped when the foot point lies within half the nearest-neighbour spacing of the data
    /// point (then no other data point can be nearer to it: triangle inequality), so the result
    /// is the same as with the second query.
    pub fn foot_point(&self, x: [f64; 3]) -> FootPoint {
        let i = self.index().nearest(&x).index;
        let pi = self.points()[i as usize];
        let f = foot_point_on(&self.quadrics()[i as usize], pi, x, i);
        let d = sub(f.point, pi);
        let h = 0.5 * self.foot_shortcut_diameters()[i as usize];
        if dot(d, d) < h * h {
            return f;
        }
        let j = self.index().nearest(&f.point).index;
        if j == i {
            return f;
        }
        foot_point_on(
            &self.quadrics()[j as usize],
            self.points()[j as usize],
            x,
            j,
        )
    }

    /// [`Self::foot_point`] for many points, in parallel (rayon); `#Q` results in order.
    /// Large batches are processed in Morton (Z-curve) order of the queries for cache locality.
    pub fn foot_points(&self, xs: &[[f64; 3]]) -> Vec<FootPoint> {
        let mut out = vec![FootPoint::default(); xs.len()];
        self.foot_points_into(xs, &mut out);
        out
    }

    /// [`Self::foot_points`] into a caller-owned buffer (`out.len()` must equal `xs.len()`).
    ///
    /// # Panics
    /// If the lengths differ.
    #[track_caller]
    pub fn foot_points_into(&self, xs: &[[f64; 3]], out: &mut [FootPoint]) {
        assert_eq!(xs.len(), out.len(), "foot_points_into: length mismatch");
        if xs.len() < SPATIAL_SORT_MIN {
            out.par_iter_mut()
                .zip(xs.par_iter())
                .for_each(|(o, &x)| *o = self.foot_point(x));
            return;
        }
        let order = crate::neighbors::morton_order(xs);
        let sorted: Vec<FootPoint> = order
            .par_iter()
            .map(|&q| self.foot_point(xs[q as usize]))
            .collect();
        let mut rank = vec![0u32; xs.len()];
        for (r, &q) in order.iter().enumerate() {
            rank[q as usize] = r as u32;
        }
        out.par_iter_mut()
            .zip(rank.par_iter())
            .for_each(|(o, &r)| *o = sorted[r as usize]);
    }

    /// Exact closest point on the target's triangles (mesh targets only; `None` for point
    /// clouds or when the BVH was not built). Normalized coordinates.
    pub fn mesh_closest_point(&self, x: [f64; 3]) -> Option<MeshClosestPoint> {
        self.mesh()?.closest(x)
    }

    /// [`Self::mesh_closest_point`] for many points, in parallel.
    pub fn mesh_closest_points(&self, xs: &[[f64; 3]]) -> Option<Vec<MeshClosestPoint>> {
        let bvh = self.mesh()?;
        xs.par_iter().map(|&x| bvh.closest(x)).collect()
    }
}
