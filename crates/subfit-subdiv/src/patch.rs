//! Regular patches: the polynomial pieces of the limit surface away from extraordinary vertices.
//!
//! * Loop: the quartic three-direction box spline over a regular triangle, 12 control points
//!   (Stam 1998, *Evaluation of Loop subdivision surfaces*, SIGGRAPH 98 course notes, appendix;
//!   de Boor, Höllig & Riemenschneider, *Box Splines*, 1993; Lai 1992 for the Bernstein form).
//!   The basis is written in barycentric coordinates `(w0, w1, w2)` of the triangle's corners.
//! * Catmull-Clark: the uniform bicubic B-spline patch, 16 control points (Catmull & Clark 1978;
//!   Stam 1998, *Exact evaluation of Catmull-Clark subdivision surfaces at arbitrary parameter
//!   values*, SIGGRAPH 98).
//!
//! Both functions return the basis values and their exact first and second derivatives with
//! respect to the patch parameters `(u, v)`; a position (or derivative) is `Σ_i w_i P_i` over the
//! control points in the documented order. Control point order is given as integer lattice
//! coordinates ([`LOOP_PATCH_LATTICE`], [`BSPLINE_PATCH_GRID`]), so callers can gather points by
//! walking the mesh around the patch's corners.

/// Number of control points of a regular Loop (box-spline) patch.
pub const LOOP_PATCH_POINTS: usize = 12;
/// Number of control points of a regular Catmull-Clark (bicubic B-spline) patch.
pub const BSPLINE_PATCH_POINTS: usize = 16;

/// Lattice coordinates `(a, b)` of the 12 Loop patch control points, in Stam's order.
///
/// The triangle's corners are `c0 = (0,0)` (point 3), `c1 = (1,0)` (point 6) and `c2 = (0,1)`
/// (point 7); point `(a, b)` sits at `c0 + a (c1 − c0) + b (c2 − c0)` on the regular
/// triangular lattice whose edges run along `(1,0)`, `(0,1)` and `(−1,1)`. The patch parameters
/// `(u, v)` are the barycentric weights of `c1` and `c2`.
pub const LOOP_PATCH_LATTICE: [[i32; 2]; LOOP_PATCH_POINTS] = [
    [0, -1],
    [-1, 0],
    [1, -1],
    [0, 0],
    [-1, 1],
    [2, -1],
    [1, 0],
    [0, 1],
    [-1, 2],
    [2, 0],
    [1, 1],
    [0, 2],
];

/// Grid coordinates `(i, j)` of the 16 bicubic control points: point `k` is at
/// `(k % 4 − 1, k / 4 − 1)`; the patch covers the unit square between `(0,0)` (point 5) and
/// `(1,1)` (point 10), with `u` along `i` and `v` along `j`.
pub const BSPLINE_PATCH_GRID: [[i32; 2]; BSPLINE_PATCH_POINTS] = {
    let mut g = [[0i32; 2]; 16];
    let mut k = 0;
    while k < 16 {
        g[k] = [(k % 4) as i32 - 1, (k / 4) as i32 - 1];
        k += 1;
    }
    g
};

/// Basis weights of a patch and their derivatives at one parameter point.
///
/// Each array has one entry per control point (`N` = 12 or 16) in the patch's order. Position
/// weights sum to 1, all derivative weights sum to 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchBasis<const N: usize> {
    /// Position weights.
    pub point: [f64; N],
    /// ∂/∂u weights.
    pub du: [f64; N],
    /// ∂/∂v weights.
    pub dv: [f64; N],
    /// ∂²/∂u² weights.
    pub duu: [f64; N],
    /// ∂²/∂u∂v weights.
    pub duv: [f64; N],
    /// ∂²/∂v² weights.
    pub dvv: [f64; N],
}

/// Stam's 12 box-spline basis functions as coefficients (over 12) of the 15 quartic monomials
/// `w0^a w1^b w2^c` listed in [`MONOMIALS`]; `w0 = 1 − u − v` is the weight of corner `c0`.
const LOOP_COEFFS: [[f64; 15]; 12] = {
    // Monomial order: see MONOMIALS.
    // (a,b,c): 400 310 301 220 211 202 130 121 112 103 040 031 022 013 004
    [
        [1., 2., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0.],
        [1., 0., 2., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0.],
        [1., 6., 2., 12., 6., 0., 6., 6., 0., 0., 1., 2., 0., 0., 0.],
        [
            6., 24., 24., 24., 60., 24., 8., 36., 36., 8., 1., 6., 12., 6., 1.,
        ],
        [1., 2., 6., 0., 6., 12., 0., 0., 6., 6., 0., 0., 0., 2., 1.],
        [0., 0., 0., 0., 0., 0., 2., 0., 0., 0., 1., 0., 0., 0., 0.],
        [
            1., 8., 6., 24., 36., 12., 24., 60., 36., 6., 6., 24., 24., 8., 1.,
        ],
        [
            1., 6., 8., 12., 36., 24., 6., 36., 60., 24., 1., 8., 24., 24., 6.,
        ],
        [0., 0., 0., 0., 0., 0., 0., 0., 0., 2., 0., 0., 0., 0., 1.],
        [0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 1., 2., 0., 0., 0.],
        [0., 0., 0., 0., 0., 0., 2., 6., 6., 2., 1., 6., 12., 6., 1.],
        [0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 2., 1.],
    ]
};

/// Exponents `(a, b, c)` of the quartic monomials `w0^a w1^b w2^c`.
const MONOMIALS: [[i32; 3]; 15] = [
    [4, 0, 0],
    [3, 1, 0],
    [3, 0, 1],
    [2, 2, 0],
    [2, 1, 1],
    [2, 0, 2],
    [1, 3, 0],
    [1, 2, 1],
    [1, 1, 2],
    [1, 0, 3],
    [0, 4, 0],
    [0, 3, 1],
    [0, 2, 2],
    [0, 1, 3],
    [0, 0, 4],
];

/// `x^k` and its first two derivatives for `k ≤ 4` (0 for negative exponents), from the
/// powers `pw = [1, x, x², x³, x⁴]` of [`powers`].
#[inline]
fn pow_d(pw: &[f64; 5], k: i32) -> [f64; 3] {
    let p = |e: i32| if e < 0 { 0.0 } else { pw[e as usize] };
    let kf = k as f64;
    [p(k), kf * p(k - 1), kf * (kf - 1.0) * p(k - 2)]
}

/// `[1, x, x², x³, x⁴]`, rounded as `f64::powi` rounds them (`x²·x`, `x²·x²`), without its
/// library call per power.
#[inline]
fn powers(x: f64) -> [f64; 5] {
    let x2 = x * x;
    [1.0, x, x2, x2 * x, x2 * x2]
}

/// The quartic box-spline basis of the regular Loop patch at barycentric parameters `(u, v)`.
///
/// `u`, `v` are the weights of corners `c1` and `c2` (see [`LOOP_PATCH_LATTICE`]); the domain is
/// `u, v ≥ 0`, `u + v ≤ 1`, but the polynomial is evaluated as is outside it. At a corner the
/// weights are the regular limit mask (1/2 at the corner, 1/12 at its six neighbours).
/// Cost: about 300 flops.
pub fn loop_box_spline(u: f64, v: f64) -> PatchBasis<LOOP_PATCH_POINTS> {
    let w0 = 1.0 - u - v;
    // For each monomial: value and partials in (w0, w1, w2), then chain rule with
    // ∂/∂u = ∂/∂w1 − ∂/∂w0 and ∂/∂v = ∂/∂w2 − ∂/∂w0.
    let mut m = [[0.0f64; 6]; 15];
    let (p0, p1, p2) = (powers(w0), powers(u), powers(v));
    for (k, e) in MONOMIALS.iter().enumerate() {
        let (a, b, c) = (pow_d(&p0, e[0]), pow_d(&p1, e[1]), pow_d(&p2, e[2]));
        let f = a[0] * b[0] * c[0];
        let f0 = a[1] * b[0] * c[0];
        let f1 = a[0] * b[1] * c[0];
        let f2 = a[0] * b[0] * c[1];
        let f00 = a[2] * b[0] * c[0];
        let f11 = a[0] * b[2] * c[0];
        let f22 = a[0] * b[0] * c[2];
        let f01 = a[1] * b[1] * c[0];
        let f02 = a[1] * b[0] * c[1];
        let f12 = a[0] * b[1] * c[1];
        m[k] = [
            f,
            f1 - f0,
            f2 - f0,
            f11 - 2.0 * f01 + f00,
            f12 - f01 - f02 + f00,
            f22 - 2.0 * f02 + f00,
        ];
    }
    let mut out = PatchBasis {
        point: [0.0; 12],
        du: [0.0; 12],
        dv: [0.0; 12],
        duu: [0.0; 12],
        duv: [0.0; 12],
        dvv: [0.0; 12],
    };
    for (i, coeffs) in LOOP_COEFFS.iter().enumerate() {
        let mut acc = [0.0f64; 6];
        for (c, mk) in coeffs.iter().zip(&m) {
            if *c != 0.0 {
                for d in 0..6 {
                    acc[d] += c * mk[d];
                }
            }
        }
        let s = 1.0 / 12.0;
        out.point[i] = acc[0] * s;
        out.du[i] = acc[1] * s;
        out.dv[i] = acc[2] * s;
        out.duu[i] = acc[3] * s;
        out.duv[i] = acc[4] * s;
        out.dvv[i] = acc[5] * s;
    }
    out
}

/// Uniform cubic B-spline basis at `t` with first and second derivatives: `[values, d, dd]`.
#[inline]
fn cubic_bspline(t: f64) -> [[f64; 4]; 3] {
    let s = 1.0 - t;
    let (t2, t3) = (t * t, t * t * t);
    [
        [
            s * s * s / 6.0,
            (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
            (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
            t3 / 6.0,
        ],
        [
            -0.5 * s * s,
            1.5 * t2 - 2.0 * t,
            -1.5 * t2 + t + 0.5,
            0.5 * t2,
        ],
        [s, 3.0 * t - 2.0, -3.0 * t + 1.0, t],
    ]
}

/// The bicubic uniform B-spline basis of the regular Catmull-Clark patch at `(u, v) ∈ [0,1]²`.
///
/// Control point order: [`BSPLINE_PATCH_GRID`]. At a corner the weights are the regular limit
/// mask (4/9 at the corner, 1/9 at its edge neighbours, 1/36 at its diagonal neighbours).
/// Cost: about 150 flops.
#[allow(
    clippy::needless_range_loop,
    reason = "tensor indices i, j read clearer"
)]
pub fn bicubic_bspline(u: f64, v: f64) -> PatchBasis<BSPLINE_PATCH_POINTS> {
    let bu = cubic_bspline(u);
    let bv = cubic_bspline(v);
    let mut out = PatchBasis {
        point: [0.0; 16],
        du: [0.0; 16],
        dv: [0.0; 16],
        duu: [0.0; 16],
        duv: [0.0; 16],
        dvv: [0.0; 16],
    };
    for j in 0..4 {
        for i in 0..4 {
            let k = 4 * j + i;
            out.point[k] = bu[0][i] * bv[0][j];
            out.du[k] = bu[1][i] * bv[0][j];
            out.dv[k] = bu[0][i] * bv[1][j];
            out.duu[k] = bu[2][i] * bv[0][j];
            out.duv[k] = bu[1][i] * bv[1][j];
            out.dvv[k] = bu[0][i] * bv[2][j];
        }
    }
    out
}

#[cfg(test)]
#[allow(clippy::needless_range_loop, reason = "indices pair several arrays")]
mod tests {
    use super::*;

    fn check_basis<const N: usize>(f: impl Fn(f64, f64) -> PatchBasis<N>, pts: &[(f64, f64)]) {
        let h = 1e-4;
        for &(u, v) in pts {
            let b = f(u, v);
            assert!((b.point.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            for d in [&b.du, &b.dv, &b.duu, &b.duv, &b.dvv] {
                assert!(d.iter().sum::<f64>().abs() < 1e-12);
            }
            let (pu, mu) = (f(u + h, v), f(u - h, v));
            let (pv, mv) = (f(u, v + h), f(u, v - h));
            for i in 0..N {
                let fd_u = (pu.point[i] - mu.point[i]) / (2.0 * h);
                let fd_v = (pv.point[i] - mv.point[i]) / (2.0 * h);
                assert!((fd_u - b.du[i]).abs() < 1e-7, "du {i}");
                assert!((fd_v - b.dv[i]).abs() < 1e-7, "dv {i}");
                let fd_uu = (pu.du[i] - mu.du[i]) / (2.0 * h);
                let fd_uv = (pv.du[i] - mv.du[i]) / (2.0 * h);
                let fd_vv = (pv.dv[i] - mv.dv[i]) / (2.0 * h);
                assert!((fd_uu - b.duu[i]).abs() < 1e-7, "duu {i}");
                assert!((fd_uv - b.duv[i]).abs() < 1e-7, "duv {i}");
                assert!((fd_vv - b.dvv[i]).abs() < 1e-7, "dvv {i}");
            }
        }
    }

    const PTS: [(f64, f64); 5] = [(0.2, 0.3), (0.0, 0.0), (0.5, 0.25), (0.1, 0.8), (1.0, 0.0)];

    #[test]
    fn loop_basis_is_partition_of_unity_with_consistent_derivatives() {
        check_basis(loop_box_spline, &PTS);
    }

    #[test]
    fn bspline_basis_is_partition_of_unity_with_consistent_derivatives() {
        check_basis(bicubic_bspline, &PTS);
    }

    /// Linear functions of the lattice coordinates are reproduced exactly.
    #[test]
    fn patches_reproduce_linear_functions() {
        for &(u, v) in &PTS {
            let b = loop_box_spline(u, v);
            let (mut x, mut y) = (0.0, 0.0);
            let (mut xu, mut yv) = (0.0, 0.0);
            for i in 0..12 {
                let [a, c] = LOOP_PATCH_LATTICE[i];
                x += b.point[i] * a as f64;
                y += b.point[i] * c as f64;
                xu += b.du[i] * a as f64;
                yv += b.dv[i] * c as f64;
            }
            assert!((x - u).abs() < 1e-14 && (y - v).abs() < 1e-14);
            assert!((xu - 1.0).abs() < 1e-13 && (yv - 1.0).abs() < 1e-13);
            let b = bicubic_bspline(u, v);
            let (mut x, mut y) = (0.0, 0.0);
            for i in 0..16 {
                let [a, c] = BSPLINE_PATCH_GRID[i];
                x += b.point[i] * a as f64;
                y += b.point[i] * c as f64;
            }
            assert!((x - u).abs() < 1e-14 && (y - v).abs() < 1e-14);
        }
    }

    /// At the corners the patches give the regular limit masks.
    #[test]
    fn corners_are_regular_limit_masks() {
        let corners = [(0.0, 0.0, [0, 0]), (1.0, 0.0, [1, 0]), (0.0, 1.0, [0, 1])];
        for (u, v, c) in corners {
            let b = loop_box_spline(u, v);
            for i in 0..12 {
                let [a, bb] = LOOP_PATCH_LATTICE[i];
                let (da, db) = (a - c[0], bb - c[1]);
                let want = if (da, db) == (0, 0) {
                    0.5
                } else if [(1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1)].contains(&(da, db)) {
                    1.0 / 12.0
                } else {
                    0.0
                };
                assert!((b.point[i] - want).abs() < 1e-15, "corner {c:?} point {i}");
            }
        }
        for (u, v) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            let b = bicubic_bspline(u, v);
            for i in 0..16 {
                let [a, bb] = BSPLINE_PATCH_GRID[i];
                let (da, db) = ((a as f64 - u).abs(), (bb as f64 - v).abs());
                let want = match (da as i32, db as i32) {
                    (0, 0) => 4.0 / 9.0,
                    (1, 0) | (0, 1) => 1.0 / 9.0,
                    (1, 1) => 1.0 / 36.0,
                    _ => 0.0,
                };
                assert!((b.point[i] - want).abs() < 1e-15);
            }
        }
    }

    /// The box spline is symmetric under the lattice rotation that cycles the corners.
    #[test]
    fn loop_basis_is_rotation_symmetric() {
        // Rotation c0 → c1 → c2 → c0: lattice (a, b) ↦ (1 − a − b, a), parameters
        // (w0, w1, w2) ↦ (w2, w0, w1).
        let (u, v) = (0.21, 0.37);
        let b = loop_box_spline(u, v);
        let r = loop_box_spline(1.0 - u - v, u);
        for i in 0..12 {
            let [a, c] = LOOP_PATCH_LATTICE[i];
            let j = LOOP_PATCH_LATTICE
                .iter()
                .position(|&p| p == [1 - a - c, a])
                .unwrap();
            assert!((b.point[i] - r.point[j]).abs() < 1e-15, "{i} -> {j}");
        }
    }

    #[test]
    fn power_table_rounds_as_powi() {
        for x in [
            0.0,
            1.0,
            0.3,
            1.0 / 3.0,
            0.999_999_9,
            1e-9,
            0.123_456_789,
            -0.7,
        ] {
            // Runtime values: the compiler may fold `powi` of constants differently.
            let x = std::hint::black_box(x);
            for (e, &p) in powers(x).iter().enumerate() {
                let e = std::hint::black_box(e as i32);
                assert_eq!(p.to_bits(), x.powi(e).to_bits(), "{x}^{e}");
            }
        }
    }
}
