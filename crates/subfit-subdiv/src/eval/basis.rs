//! The regular patch basis (Loop's quartic box spline, Catmull-Clark's bicubic B-spline, from
//! [`crate::patch`]) and a regular patch's control points as dense rows over a few control
//! points; the affine maps from a parent face's parameters to a child's.

use super::types::{EvalKind, EvalWeights};
use crate::local::{ChildFace, Combo, LocalMesh};
use crate::patch::{bicubic_bspline, loop_box_spline};
use crate::scheme::Scheme;

/// The regular patch basis (value and five derivatives) padded to 16 entries, and its size.
fn basis(scheme: Scheme, u: f64, v: f64) -> (usize, [[f64; 16]; 6]) {
    let mut out = [[0.0; 16]; 6];
    match scheme {
        Scheme::Loop => {
            let b = loop_box_spline(u, v);
            for (o, x) in out
                .iter_mut()
                .zip([b.point, b.du, b.dv, b.duu, b.duv, b.dvv])
            {
                o[..12].copy_from_slice(&x);
            }
            (12, out)
        }
        Scheme::CatmullClark | Scheme::QuadTriangle => {
            let b = bicubic_bspline(u, v);
            (16, [b.point, b.du, b.dv, b.duu, b.duv, b.dvv])
        }
    }
}

/// A regular patch's control points as dense rows over a few control points.
#[derive(Clone, Debug)]
pub(super) struct PatchCoef {
    pub(super) cols: Vec<u32>,
    /// `npts × cols.len()`.
    pub(super) coef: Vec<f64>,
    /// Patch control points: 12 (box spline) or 16 (bicubic).
    pub(super) npts: usize,
}

impl PatchCoef {
    pub(super) fn new(mesh: &LocalMesh, combos: &[Combo]) -> Self {
        let k = mesh.k();
        let mut dense = vec![0.0; combos.len() * k];
        for (i, c) in combos.iter().enumerate() {
            for &(v, w) in &c.terms[..c.n as usize] {
                if w != 0.0 {
                    for (o, r) in dense[i * k..(i + 1) * k].iter_mut().zip(mesh.row(v)) {
                        *o += w * r;
                    }
                }
            }
        }
        Self::from_dense(&mesh.cols, &dense, combos.len())
    }

    /// From `npts × cols.len()` dense rows over control points `cols`: keeps the nonzero
    /// columns, sorted by control-point id.
    pub(super) fn from_dense(cols: &[u32], dense: &[f64], npts: usize) -> Self {
        let k = cols.len();
        let mut order: Vec<usize> = (0..k)
            .filter(|&j| (0..npts).any(|i| dense[i * k + j] != 0.0))
            .collect();
        order.sort_by_key(|&j| cols[j]);
        let mut coef = Vec::with_capacity(npts * order.len());
        for i in 0..npts {
            coef.extend(order.iter().map(|&j| dense[i * k + j]));
        }
        Self {
            cols: order.iter().map(|&j| cols[j]).collect(),
            coef,
            npts,
        }
    }

    /// Evaluates at child parameters `(u, v)` with `a` = ∂(child params)/∂(original params).
    pub(super) fn eval(
        &self,
        scheme: Scheme,
        u: f64,
        v: f64,
        a: [[f64; 2]; 2],
        depth: u32,
    ) -> EvalWeights {
        let (np, vals) = chain_basis(self.npts, scheme, u, v, a);
        let n = self.cols.len();
        let mut out = [
            vec![0.0; n],
            vec![0.0; n],
            vec![0.0; n],
            vec![0.0; n],
            vec![0.0; n],
            vec![0.0; n],
        ];
        for (i, vals) in vals.iter().enumerate().take(np) {
            let row = &self.coef[i * n..(i + 1) * n];
            for (o, &val) in out.iter_mut().zip(vals) {
                if val != 0.0 {
                    for (x, &r) in o.iter_mut().zip(row) {
                        *x += val * r;
                    }
                }
            }
        }
        patch_weights(self.cols.clone(), out, depth)
    }
}

/// The weights of a patch evaluation from its six rows (position, ∂u, ∂v, ∂uu, ∂uv, ∂vv) over
/// control points `indices`.
pub(super) fn patch_weights(indices: Vec<u32>, out: [Vec<f64>; 6], depth: u32) -> EvalWeights {
    let [position, du, dv, duu, duv, dvv] = out;
    EvalWeights {
        indices,
        position,
        du,
        dv,
        second: Some([duu, duv, dvv]),
        kind: EvalKind::Patch,
        depth,
    }
}

/// The regular patch basis of an `npts`-point patch at child parameters `(u, v)`, chained to
/// the original parameters by `a` = ∂(child)/∂(original): per patch point, its weight in the
/// position, ∂u, ∂v, ∂uu, ∂uv and ∂vv. Returns the number of points and the rows.
pub(super) fn chain_basis(
    npts: usize,
    scheme: Scheme,
    u: f64,
    v: f64,
    a: [[f64; 2]; 2],
) -> (usize, [[f64; 6]; 16]) {
    // A 12-point patch is Loop's box spline (a triangle), a 16-point one the bicubic
    // B-spline, whatever the mesh's scheme (the quad/triangle scheme has both).
    let patch = if npts == 12 { Scheme::Loop } else { scheme };
    let (np, [p, du, dv, duu, duv, dvv]) = basis(patch, u, v);
    let mut out = [[0.0; 6]; 16];
    // Chain rule: ∂f/∂x_j = Σ_i a[i][j] ∂f/∂c_i; H_x = aᵀ H_c a.
    for (i, o) in out.iter_mut().enumerate().take(np) {
        let (gu, gv) = (du[i], dv[i]);
        let hx = [[duu[i], duv[i]], [duv[i], dvv[i]]];
        let g = [a[0][0] * gu + a[1][0] * gv, a[0][1] * gu + a[1][1] * gv];
        let mut h = [[0.0; 2]; 2];
        for (j, hj) in h.iter_mut().enumerate() {
            for (l, hjl) in hj.iter_mut().enumerate() {
                let mut s = 0.0;
                for (r, hr) in hx.iter().enumerate() {
                    for (c, hrc) in hr.iter().enumerate() {
                        s += a[r][j] * hrc * a[c][l];
                    }
                }
                *hjl = s;
            }
        }
        *o = [p[i], g[0], g[1], h[0][0], h[0][1], h[1][1]];
    }
    (np, out)
}

pub(super) fn mul2(a: [[f64; 2]; 2], b: [[f64; 2]; 2]) -> [[f64; 2]; 2] {
    [
        [
            a[0][0] * b[0][0] + a[0][1] * b[1][0],
            a[0][0] * b[0][1] + a[0][1] * b[1][1],
        ],
        [
            a[1][0] * b[0][0] + a[1][1] * b[1][0],
            a[1][0] * b[0][1] + a[1][1] * b[1][1],
        ],
    ]
}

/// The affine map from a parent face's parameters to a child's, precomputed from the child's
/// corner parameters (triangle: affine on corners 0, 1, 2; quad: on corners 0, 1, 3).
#[derive(Clone, Copy, Debug)]
pub(super) struct ChildMap {
    p0: [f64; 2],
    /// ∂(child)/∂(parent).
    inv: [[f64; 2]; 2],
    tri: bool,
}

impl ChildMap {
    pub(super) fn new(params: &[[f64; 2]]) -> Self {
        let p0 = params[0];
        let e1 = [params[1][0] - p0[0], params[1][1] - p0[1]];
        let tri = params.len() == 3;
        let q = if tri { params[2] } else { params[3] };
        let e2 = [q[0] - p0[0], q[1] - p0[1]];
        // parent = p0 + s e1 + t e2 ⇒ (s, t) = M⁻¹ (parent − p0), M = [e1 e2].
        let det = e1[0] * e2[1] - e2[0] * e1[1];
        let inv = [[e2[1] / det, -e2[0] / det], [-e1[1] / det, e1[0] / det]];
        Self { p0, inv, tri }
    }

    /// Local parameters of parent point `(u, v)` in the child, and ∂(child)/∂(parent).
    pub(super) fn local(&self, u: f64, v: f64) -> (f64, f64, [[f64; 2]; 2]) {
        let (inv, p0) = (self.inv, self.p0);
        let (du, dv) = (u - p0[0], v - p0[1]);
        let s = inv[0][0] * du + inv[0][1] * dv;
        let t = inv[1][0] * du + inv[1][1] * dv;
        (s, t, inv)
    }

    /// How far inside the child's domain `(u, v)` is (its smallest barycentric or box margin).
    fn margin(&self, u: f64, v: f64) -> f64 {
        let (s, t, _) = self.local(u, v);
        if self.tri {
            s.min(t).min(1.0 - s - t)
        } else {
            s.min(t).min(1.0 - s).min(1.0 - t)
        }
    }
}

/// The maps of children `ch` (triangles and quads; empty for `n`-gon sub-patches).
pub(super) fn child_maps(ch: &[ChildFace]) -> Vec<ChildMap> {
    ch.iter()
        .filter(|c| c.params.len() >= 3)
        .map(|c| ChildMap::new(&c.params))
        .collect()
}

/// Local parameters of parent point `(u, v)` in a child with corner parameters `params`
/// (triangle: affine on corners 0, 1, 2; quad: on corners 0, 1, 3), and ∂(child)/∂(parent).
pub(super) fn child_local(params: &[[f64; 2]], u: f64, v: f64) -> (f64, f64, [[f64; 2]; 2]) {
    ChildMap::new(params).local(u, v)
}

/// The child whose domain contains `(u, v)` best (largest minimum barycentric / box margin).
pub(super) fn best_child(ch: &[ChildFace], u: f64, v: f64) -> usize {
    best_of(ch.iter().map(|c| ChildMap::new(&c.params)), u, v)
}

/// [`best_child`] from precomputed maps.
pub(super) fn best_map(maps: &[ChildMap], u: f64, v: f64) -> usize {
    best_of(maps.iter().copied(), u, v)
}

fn best_of(maps: impl Iterator<Item = ChildMap>, u: f64, v: f64) -> usize {
    let mut best = (f64::NEG_INFINITY, 0);
    for (i, m) in maps.enumerate() {
        let margin = m.margin(u, v);
        if margin > best.0 {
            best = (margin, i);
        }
    }
    best.1
}
