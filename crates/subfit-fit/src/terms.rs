//! The per-sample error terms PD, TD and SD as 3×3 PSD matrices (Cheng et al. 2007, §II-D,
//! eq. 3, 4 and 6; Cheng et al. 2004, §4.4; DESIGN.md §3.3).
//!
//! Every term is a quadratic form `f_k² = (S_k − V_k)ᵀ Q_k (S_k − V_k)` in the variable sample
//! point `S_k`, with the foot point `V_k` and the frame frozen at the current iterate:
//!
//! * PD (eq. 3): `Q = I`;
//! * TD (eq. 4): `Q = N Nᵀ`;
//! * SD (eq. 6): `Q = N Nᵀ + [α1]₊ T1 T1ᵀ + [α2]₊ T2 T2ᵀ`, `α_i = d / (d − ρ_i)`.
//!
//! Sign convention (§II-D3): `d > 0` when the sample lies on the side `N` points to; `ρ_i > 0`
//! when the centre of curvature of the normal section along `T_i` lies on that side. For a sphere
//! of radius `r` with outward normals `ρ = −r`, and a sample at distance `d > 0` outside gets
//! `α = d / (d + r)`. The `[α]₊` values come precomputed from
//! [`subfit_target::FootPoint`] (which also zeroes them beyond the focal point).

use subfit_target::FootPoint;

/// A symmetric 3×3 matrix, row-major. Units: dimensionless weights.
pub type Mat3 = [[f64; 3]; 3];

/// The error term (distance measure) used to build the quadratic model (Cheng 2007 §II-D).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Method {
    /// Point distance (eq. 3), `Q = I`: the classic alternating method, linear convergence.
    Pdm,
    /// Tangent distance (eq. 4), `Q = N Nᵀ`: a Gauss-Newton step; unstable without damping.
    Tdm,
    /// Squared distance (eq. 6), `Q = N Nᵀ + [α1]₊ T1 T1ᵀ + [α2]₊ T2 T2ᵀ`: a (modified) Newton
    /// step. The default.
    #[default]
    Sdm,
}

/// `Q_k` of `method` for one foot point (see the module docs). Cost: O(1).
pub fn error_matrix(method: Method, foot: &FootPoint) -> Mat3 {
    match method {
        Method::Pdm => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        Method::Tdm => outer(foot.normal, foot.normal, 1.0),
        Method::Sdm => {
            let mut q = outer(foot.normal, foot.normal, 1.0);
            add_outer(&mut q, foot.t1, sanitize(foot.alpha1));
            add_outer(&mut q, foot.t2, sanitize(foot.alpha2));
            q
        }
    }
}

/// `[α]₊` guarded against NaN (treated as 0, i.e. the TD term).
fn sanitize(a: f64) -> f64 {
    if a.is_finite() && a > 0.0 {
        a
    } else {
        0.0
    }
}

/// The quadratic form `eᵀ Q e`. Cost: O(1).
#[inline]
pub fn quadratic(q: &Mat3, e: [f64; 3]) -> f64 {
    let qe = mul(q, e);
    e[0] * qe[0] + e[1] * qe[1] + e[2] * qe[2]
}

/// `Q e`. Cost: O(1).
#[inline]
pub fn mul(q: &Mat3, e: [f64; 3]) -> [f64; 3] {
    [
        q[0][0] * e[0] + q[0][1] * e[1] + q[0][2] * e[2],
        q[1][0] * e[0] + q[1][1] * e[1] + q[1][2] * e[2],
        q[2][0] * e[0] + q[2][1] * e[1] + q[2][2] * e[2],
    ]
}

/// `s · a bᵀ`.
fn outer(a: [f64; 3], b: [f64; 3], s: f64) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for (r, row) in m.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v = s * a[r] * b[c];
        }
    }
    m
}

/// `q += s · t tᵀ` (skipped when `s == 0`).
fn add_outer(q: &mut Mat3, t: [f64; 3], s: f64) {
    if s == 0.0 {
        return;
    }
    for (r, row) in q.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v += s * t[r] * t[c];
        }
    }
}
