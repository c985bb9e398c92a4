//! Local quadric ("jet" of degree 2, with constant and linear terms) around one data point, its
//! differential geometry, and projection of a point onto it.
//!
//! Cheng 2004 §4.1 and Cheng 2007 §II-C fit `z = k1 x² + k2 y²` in the PCA frame of a point's
//! neighbourhood; here the full quadric `h(u, v) = c0 + c1 u + c2 v + c3 u² + c4 uv + c5 v²` is
//! fitted by weighted least squares (Gaussian weights in the distance), which tolerates a tilted
//! PCA frame and noise, and the principal curvatures are those of the fitted surface (shape
//! operator from its two fundamental forms), not just `2 c3`, `2 c5`.
//!
//! Sign convention (Cheng 2007 §II-D3): with unit normal `N` (here `n` of the frame, tilted by the
//! gradient of `h`), a principal curvature `κ` is positive when the curvature centre lies on the
//! side `N` points to, and `ρ = 1/κ`. For a sphere with outward normals, `κ = −1/r`, `ρ = −r`.

use nalgebra::{Matrix3, SMatrix, SVector};

use subfit_mesh::vec3::{add, cross, dot, normalize, scale, sub};

/// A polynomial height field ("jet", degree 2 or 3) over a local orthonormal frame
/// `(e1, e2, n)` with origin at a data point: points `origin + u e1 + v e2 + h(u, v) n`.
/// Called a quadric for short; the cubic terms (Cazals & Pouget 2005, osculating jets) make
/// normals and curvatures one order more accurate on noise-free data.
///
/// `e2 = n × e1` is not stored. Units: normalized (coefficients `c1, c2` are slopes, `c3..c5`
/// have units of curvature, `c0` of length).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalQuadric {
    /// First tangent axis of the frame (unit, ⟂ `n`).
    pub e1: [f64; 3],
    /// Frame normal (unit); the surface normal at `(0,0)` is `n` tilted by `(c1, c2)`.
    pub n: [f64; 3],
    /// Coefficients `[c0, c1, c2, c3, c4, c5, c6, c7, c8, c9]` of
    /// `h(u, v) = c0 + c1 u + c2 v + c3 u² + c4 uv + c5 v² + c6 u³ + c7 u²v + c8 uv² + c9 v³`
    /// (the cubic terms are 0 for a degree-2 fit).
    pub c: [f64; 10],
}

/// Position, normal and principal frame of a [`LocalQuadric`] at one parameter `(u, v)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceFrame {
    /// Offset of the surface point from the quadric's origin (normalized units).
    pub offset: [f64; 3],
    /// Unit normal, on the side of the frame normal `n`.
    pub normal: [f64; 3],
    /// Unit principal direction of `k1` (⟂ normal).
    pub t1: [f64; 3],
    /// Unit principal direction of `k2` (⟂ normal and `t1`).
    pub t2: [f64; 3],
    /// Signed principal curvature with the smaller magnitude (`|k1| ≤ |k2|`), 1/normalized units.
    pub k1: f64,
    /// Signed principal curvature with the larger magnitude.
    pub k2: f64,
}

/// Outcome of a weighted fit, for statistics.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FitQuality {
    /// Full quadric fitted.
    Full,
    /// The neighbourhood did not determine the quadratic terms (e.g. nearly collinear in the
    /// tangent plane): a damped solution was used.
    Damped,
    /// Only the tangent plane could be used (curvatures 0).
    PlaneOnly,
}

impl LocalQuadric {
    /// The second frame axis `e2 = n × e1`.
    #[inline]
    pub fn e2(&self) -> [f64; 3] {
        cross(self.n, self.e1)
    }

    /// Local coordinates `(u, v, w)` of `x − origin`.
    #[inline]
    pub fn local(&self, rel: [f64; 3]) -> [f64; 3] {
        [dot(rel, self.e1), dot(rel, self.e2()), dot(rel, self.n)]
    }

    /// Height and its first and second derivatives `(h, hu, hv, huu, huv, hvv)` at `(u, v)`.
    #[inline]
    pub fn height(&self, u: f64, v: f64) -> [f64; 6] {
        let c = &self.c;
        let (uu, uv, vv) = (u * u, u * v, v * v);
        [
            c[0] + c[1] * u
                + c[2] * v
                + c[3] * uu
                + c[4] * uv
                + c[5] * vv
                + c[6] * uu * u
                + c[7] * uu * v
                + c[8] * u * vv
                + c[9] * vv * v,
            c[1] + 2.0 * c[3] * u + c[4] * v + 3.0 * c[6] * uu + 2.0 * c[7] * uv + c[8] * vv,
            c[2] + c[4] * u + 2.0 * c[5] * v + c[7] * uu + 2.0 * c[8] * uv + 3.0 * c[9] * vv,
            2.0 * c[3] + 6.0 * c[6] * u + 2.0 * c[7] * v,
            c[4] + 2.0 * c[7] * u + 2.0 * c[8] * v,
            2.0 * c[5] + 2.0 * c[8] * u + 6.0 * c[9] * v,
        ]
    }

    /// The same surface with the opposite normal orientation (`n → −n`, hence `e2 → −e2`).
    pub fn flipped(&self) -> Self {
        let c = &self.c;
        Self {
            e1: self.e1,
            n: scale(self.n, -1.0),
            // z → −z and v → −v: the coefficient of u^a v^b gets the factor (−1)^(b+1).
            c: [
                -c[0], -c[1], c[2], -c[3], c[4], -c[5], -c[6], c[7], -c[8], c[9],
            ],
        }
    }

    /// Weighted least-squares fit over neighbours given relative to the origin.
    ///
    /// `rel[j]` is `neighbour_j − origin`, `w[j] > 0` its weight, `length` a length scale of the
    /// neighbourhood (e.g. its radius; used only for conditioning), `degree` 2 or 3 (3 falls back
    /// to 2 when the neighbourhood does not determine the cubic terms). `n` and `e1` must be unit
    /// and orthogonal. Cost O(#neighbours). Never returns non-finite coefficients.
    pub fn fit(
        n: [f64; 3],
        e1: [f64; 3],
        rel: &[[f64; 3]],
        w: &[f64],
        length: f64,
        degree: u8,
    ) -> (Self, FitQuality) {
        let mut q = Self {
            e1,
            n,
            c: [0.0; 10],
        };
        let e2 = q.e2();
        let s = if length > 0.0 && length.is_finite() {
            1.0 / length
        } else {
            1.0
        };
        let local = || {
            rel.iter()
                .zip(w)
                .map(move |(r, &wj)| [dot(*r, e1) * s, dot(*r, e2) * s, dot(*r, n) * s, wj])
        };
        let scaled = if degree >= 3 && rel.len() >= 14 {
            solve_jet::<10>(local(), FitQuality::Full)
                .or_else(|| solve_jet::<6>(local(), FitQuality::Damped))
        } else {
            solve_jet::<6>(local(), FitQuality::Full)
        };
        let Some((x, quality)) = scaled else {
            return (q, FitQuality::PlaneOnly);
        };
        // Undo the scaling: h(u, v) = length * H(u s, v s), so c_ab = x_ab s^(a+b-1).
        let l = 1.0 / s;
        let s2 = s * s;
        q.c = [
            x[0] * l,
            x[1],
            x[2],
            x[3] * s,
            x[4] * s,
            x[5] * s,
            x[6] * s2,
            x[7] * s2,
            x[8] * s2,
            x[9] * s2,
        ];
        if q.c.iter().any(|c| !c.is_finite()) {
            q.c = [0.0; 10];
            return (q, FitQuality::PlaneOnly);
        }
        (q, quality)
    }

    /// Position, normal and principal curvatures/directions at `(u, v)`. Cost: a few dozen flops.
    pub fn frame_at(&self, u: f64, v: f64) -> SurfaceFrame {
        let [h, hu, hv, huu, huv, hvv] = self.height(u, v);
        let e1 = self.e1;
        let e2 = self.e2();
        let n = self.n;
        let offset = add(add(scale(e1, u), scale(e2, v)), scale(n, h));
        let w2 = 1.0 + hu * hu + hv * hv;
        let w = w2.sqrt();
        let normal = scale(sub(n, add(scale(e1, hu), scale(e2, hv))), 1.0 / w);
        // Tangents X_u = e1 + hu n, X_v = e2 + hv n; orthonormal tangent basis b1, b2.
        let xu = add(e1, scale(n, hu));
        let xv = add(e2, scale(n, hv));
        let b1 = normalize(xu).unwrap_or(e1);
        let b2 = cross(normal, b1);
        // J: parameter → (b1, b2) coordinates.
        let (j11, j21, j12, j22) = (dot(xu, b1), dot(xu, b2), dot(xv, b1), dot(xv, b2));
        let det = j11 * j22 - j12 * j21;
        // Second fundamental form in parameters: [L M; M N] = hess(h) / w.
        let (l, m, nn) = (huu / w, huv / w, hvv / w);
        // Weingarten map in the orthonormal basis: J^-T II J^-1.
        let (i11, i12, i21, i22) = (j22 / det, -j12 / det, -j21 / det, j11 / det);
        // A = II * Jinv
        let a11 = l * i11 + m * i21;
        let a12 = l * i12 + m * i22;
        let a21 = m * i11 + nn * i21;
        let a22 = m * i12 + nn * i22;
        // S = Jinv^T * A
        let s11 = i11 * a11 + i21 * a21;
        let s12 = i11 * a12 + i21 * a22;
        let s22 = i12 * a12 + i22 * a22;
        let (lam, vec) = sym2_eigen(s11, s12, s22);
        let d0 = add(scale(b1, vec[0][0]), scale(b2, vec[0][1]));
        let (mut k1, mut k2) = (lam[0], lam[1]);
        let mut t1 = normalize(d0).unwrap_or(b1);
        if k1.abs() > k2.abs() {
            std::mem::swap(&mut k1, &mut k2);
            t1 = cross(normal, t1);
        }
        let t2 = cross(normal, t1);
        let fin = |x: f64| if x.is_finite() { x } else { 0.0 };
        SurfaceFrame {
            offset,
            normal,
            t1,
            t2,
            k1: fin(k1),
            k2: fin(k2),
        }
    }

    /// Closest point of the quadric to a point with local coordinates `(u0, v0, w0)`, by Newton's
    /// method on `F(u,v) = ½‖(u,v,h(u,v)) − (u0,v0,w0)‖²` (Gauss-Newton steps where the Hessian is
    /// not positive definite). Starts at `(u0, v0)`, at most `max_iter` iterations, stops when
    /// the step is below `tol`. Returns `(u, v)`.
    pub fn project_local(&self, p: [f64; 3], max_iter: usize, tol: f64) -> (f64, f64) {
        let (u0, v0, w0) = (p[0], p[1], p[2]);
        let (mut u, mut v) = (u0, v0);
        for _ in 0..max_iter {
            let [h, hu, hv, huu, huv, hvv] = self.height(u, v);
            let r = h - w0;
            let gu = (u - u0) + r * hu;
            let gv = (v - v0) + r * hv;
            let (mut a, mut b, mut c) = (
                1.0 + hu * hu + r * huu,
                hu * hv + r * huv,
                1.0 + hv * hv + r * hvv,
            );
            if !(a > 0.0 && a * c - b * b > 1e-12 * (a * a + c * c)) {
                a = 1.0 + hu * hu;
                b = hu * hv;
                c = 1.0 + hv * hv;
            }
            let det = a * c - b * b;
            let du = -(c * gu - b * gv) / det;
            let dv = -(a * gv - b * gu) / det;
            if !(du.is_finite() && dv.is_finite()) {
                break;
            }
            u += du;
            v += dv;
            if du.abs() + dv.abs() < tol {
                break;
            }
        }
        (u, v)
    }
}

/// Weighted least squares for the first `N` monomials (1, u, v, u², uv, v², u³, u²v, uv², v³)
/// over scaled local points `[u, v, z, weight]`. A tiny ridge keeps the solve defined;
/// returns `None` when the system is numerically singular.
fn solve_jet<const N: usize>(
    pts: impl Iterator<Item = [f64; 4]>,
    quality: FitQuality,
) -> Option<([f64; 10], FitQuality)> {
    let mut a = SMatrix::<f64, N, N>::zeros();
    let mut b = SVector::<f64, N>::zeros();
    for [u, v, z, wj] in pts {
        let all = [
            1.0,
            u,
            v,
            u * u,
            u * v,
            v * v,
            u * u * u,
            u * u * v,
            u * v * v,
            v * v * v,
        ];
        let row = SVector::<f64, N>::from_fn(|i, _| all[i]);
        a.syger(wj, &row, &row, 1.0);
        b.axpy(wj * z, &row, 1.0);
    }
    let trace = a.trace();
    if !(trace > 0.0) {
        return None;
    }
    for i in 0..N {
        a[(i, i)] += 1e-12 * trace;
    }
    let ch = a.cholesky()?;
    let l = ch.l();
    let min_pivot = (0..N).map(|i| l[(i, i)]).fold(f64::INFINITY, f64::min);
    if !(min_pivot * min_pivot > 1e-10 * trace) {
        return None;
    }
    let x = ch.solve(&b);
    if !x.iter().all(|c| c.is_finite()) {
        return None;
    }
    let mut out = [0.0; 10];
    out[..N].copy_from_slice(x.as_slice());
    Some((out, quality))
}

/// Eigen-decomposition of the symmetric 2×2 matrix `[[a, b], [b, c]]`: eigenvalues ascending and
/// unit eigenvectors (rows).
#[inline]
pub(crate) fn sym2_eigen(a: f64, b: f64, c: f64) -> ([f64; 2], [[f64; 2]; 2]) {
    let m = 0.5 * (a + c);
    let d = (0.25 * (a - c) * (a - c) + b * b).sqrt();
    let (lo, hi) = (m - d, m + d);
    // Eigenvector of `hi`: (b, hi - a) or (hi - c, b), the better conditioned.
    let (x1, y1) = (b, hi - a);
    let (x2, y2) = (hi - c, b);
    let (x, y) = if x1 * x1 + y1 * y1 >= x2 * x2 + y2 * y2 {
        (x1, y1)
    } else {
        (x2, y2)
    };
    let len = (x * x + y * y).sqrt();
    let vhi = if len > 0.0 && len.is_finite() {
        [x / len, y / len]
    } else {
        [1.0, 0.0]
    };
    let vlo = [-vhi[1], vhi[0]];
    ([lo, hi], [vlo, vhi])
}

/// Symmetric 3×3 eigen-decomposition: eigenvalues ascending and unit eigenvectors (columns as
/// `[f64; 3]`), via nalgebra.
pub(crate) fn sym3_eigen(m: [[f64; 3]; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let mat = Matrix3::from_fn(|i, j| m[i][j]);
    let e = mat.symmetric_eigen();
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&i, &j| e.eigenvalues[i].total_cmp(&e.eigenvalues[j]));
    let vals = idx.map(|i| e.eigenvalues[i]);
    let vecs = idx.map(|i| {
        let c = e.eigenvectors.column(i);
        [c[0], c[1], c[2]]
    });
    (vals, vecs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_cap_curvature_sign() {
        // Upper cap of a sphere radius 2 centred at (0,0,-2): outward normal +z, h ≈ -(u²+v²)/4.
        let r = 2.0;
        let mut rel = Vec::new();
        for i in -3i32..=3 {
            for j in -3i32..=3 {
                let (u, v) = (0.05 * i as f64, 0.05 * j as f64);
                rel.push([u, v, (r * r - u * u - v * v).sqrt() - r]);
            }
        }
        let w = vec![1.0; rel.len()];
        let (q, qual) = LocalQuadric::fit([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], &rel, &w, 0.15, 3);
        assert_eq!(qual, FitQuality::Full);
        let f = q.frame_at(0.0, 0.0);
        assert!(
            (f.k1 + 0.5).abs() < 2e-3 && (f.k2 + 0.5).abs() < 2e-3,
            "{f:?}"
        );
        let g = q.flipped().frame_at(0.0, 0.0);
        assert!((g.k1 - 0.5).abs() < 2e-3 && g.normal[2] < -0.999);
        // Tilted evaluation stays on the sphere to 2nd order.
        let f = q.frame_at(0.1, 0.05);
        let p = add([0.0, 0.0, r], f.offset);
        assert!(((dot(p, p)).sqrt() - r).abs() < 1e-4);
    }

    #[test]
    fn projection_onto_paraboloid() {
        let q = LocalQuadric {
            e1: [1.0, 0.0, 0.0],
            n: [0.0, 0.0, 1.0],
            c: [0.0, 0.0, 0.0, 0.5, 0.0, 0.25, 0.1, -0.2, 0.0, 0.05],
        };
        let x = [0.3, -0.2, 0.4];
        let (u, v) = q.project_local(x, 20, 1e-14);
        let f = q.frame_at(u, v);
        let d = sub(x, f.offset);
        // x - V is along the normal.
        assert!(norm_cross(d, f.normal) < 1e-12);
        fn norm_cross(a: [f64; 3], b: [f64; 3]) -> f64 {
            let c = cross(a, b);
            dot(c, c).sqrt()
        }
    }
}
