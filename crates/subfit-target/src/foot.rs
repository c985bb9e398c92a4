//! The foot point on one local quadric: the projection of `x` onto the quadric fitted at a
//! data point, with the signed distance, frame, curvatures and `[α]₊` of the SD error term
//! (Cheng 2007 §II-D3, eq. 5–6). The target-level queries that choose the quadric are in
//! [`crate::project`].
//!
//! Signs, quoting Cheng 2007 §II-D3: "If the sample point S_k is on the side of Γ_T pointed to by
//! N, i.e., N·(S_k⁰ − V_k⁰) > 0, then d > 0; otherwise, d ≤ 0. Similarly, if the curvature center
//! in the normal section along the tangent vector T_i is on the side of Γ_T pointed to by N, then
//! ρ_i > 0; otherwise, ρ_i ≤ 0." and "α_1 = d/(d − ρ_1) and α_2 = d/(d − ρ_2) … Denote
//! `[α]₊ = max{α, 0}`." So for a sphere of radius r with outward normals: ρ = −r, a point outside
//! has d > 0 and α = d/(d + r) ∈ (0, 1); a point inside has d < 0 and `[α]₊ = 0`.

use crate::quadric::LocalQuadric;
use subfit_mesh::vec3::{add, dot, norm2, sub};

/// Newton iterations of the projection onto a quadric.
const MAX_ITER: usize = 10;
/// Newton step tolerance (normalized units).
const TOL: f64 = 1e-14;

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

/// A quadric foot point may be at most this factor farther from the query than the data
/// point it was fitted at; beyond, the data point's tangent plane is used.
const FALLBACK_SLACK: f64 = 1.1;

/// The foot point of `x` (normalized coordinates) on one quadric with origin `origin`.
pub fn foot_point_on(
    quadric: &LocalQuadric,
    origin: [f64; 3],
    x: [f64; 3],
    nearest: u32,
) -> FootPoint {
    let loc = quadric.local(sub(x, origin));
    let (u, v) = quadric.project_local(loc, MAX_ITER, TOL);
    let mut f = quadric.frame_at(u, v);
    let mut point = add(origin, f.offset);
    // The data point itself lies on the surface, so the true foot point is no farther from `x`
    // than it. A quadric projection that lands farther (the jet extrapolated far outside its
    // support, for queries far from the data or in thin parts) is replaced by the projection
    // onto the tangent plane of the data point's own frame.
    let (dq, dp) = (norm2(sub(x, point)), norm2(sub(x, origin)));
    if !(dq.is_finite() && dq <= FALLBACK_SLACK * FALLBACK_SLACK * dp) {
        f = quadric.frame_at(0.0, 0.0);
        let base = add(origin, f.offset);
        let h = dot(sub(x, base), f.normal);
        point = std::array::from_fn(|k| x[k] - h * f.normal[k]);
    }
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
