//! Quadric error metrics (Garland & Heckbert 1997): the squared-distance quadric of a
//! plane, their sums, their value at a point and the point minimizing them.

use subfit_mesh::vec3::{cross, dot};

/// Symmetric 4×4 quadric, upper triangle row by row:
/// `[a00 a01 a02 a03 a11 a12 a13 a22 a23 a33]`.
pub(super) type Quadric = [f64; 10];

/// The quadric of the plane through `p` with unit normal `n`, weighted by `w`: the squared
/// distance to the plane times `w`.
pub(super) fn plane_quadric(n: [f64; 3], p: [f64; 3], w: f64) -> Quadric {
    let d = -dot(n, p);
    let v = [n[0], n[1], n[2], d];
    let mut q = [0.0; 10];
    let mut k = 0;
    for i in 0..4 {
        for j in i..4 {
            q[k] = w * v[i] * v[j];
            k += 1;
        }
    }
    q
}

/// `a += b`.
pub(super) fn add_q(a: &mut Quadric, b: &Quadric) {
    for (x, y) in a.iter_mut().zip(b) {
        *x += y;
    }
}

/// `[p 1] Q [p 1]ᵀ`: the weighted sum of squared distances of `p` to the quadric's planes.
pub(super) fn eval_q(q: &Quadric, p: [f64; 3]) -> f64 {
    let [x, y, z] = p;
    q[0] * x * x
        + 2.0 * q[1] * x * y
        + 2.0 * q[2] * x * z
        + 2.0 * q[3] * x
        + q[4] * y * y
        + 2.0 * q[5] * y * z
        + 2.0 * q[6] * y
        + q[7] * z * z
        + 2.0 * q[8] * z
        + q[9]
}

/// Total plane weight (trace of the 3×3 block, since plane normals are unit).
pub(super) fn q_weight(q: &Quadric) -> f64 {
    q[0] + q[4] + q[7]
}

/// Minimizer of the quadric: solves `A p = −b`; `None` when `A` is ill-conditioned.
pub(super) fn q_minimizer(q: &Quadric) -> Option<[f64; 3]> {
    let a = [[q[0], q[1], q[2]], [q[1], q[4], q[5]], [q[2], q[5], q[7]]];
    let b = [-q[3], -q[6], -q[8]];
    let c0 = cross(a[1], a[2]);
    let det = dot(a[0], c0);
    let tr = q[0] + q[4] + q[7];
    if !(det.abs() > 1e-9 * tr * tr * tr) {
        return None;
    }
    // Cramer's rule via the adjugate (rows of the inverse are the cross products of columns).
    let c1 = cross(a[2], a[0]);
    let c2 = cross(a[0], a[1]);
    let inv = 1.0 / det;
    let p = [0, 1, 2].map(|k| (c0[k] * b[0] + c1[k] * b[1] + c2[k] * b[2]) * inv);
    p.iter().all(|x| x.is_finite()).then_some(p)
}
