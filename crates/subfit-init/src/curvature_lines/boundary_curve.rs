//! Boundary loops as closed subdivision curves: Lavoué, Dupont & Baskurt 2007, "A framework for
//! quad/triangle subdivision surface fitting: application to mechanical objects", §4.2.
//!
//! Hoppe et al.'s boundary rules: per step new points at control-segment midpoints, old points
//! move to `(P_{i-1} + 6 P_i + P_{i+1})/8` (eq. 2, a uniform cubic B-spline), corners stay (eq. 3).
//! The limit curve is linear in the control points; `L` steps and the limit mask `(1, 4, 1)/6`
//! give at `u = k/2^L` of a span the cubic B-spline basis, a corner's outer neighbour replaced by
//! its reflection through the corner (the rules commute with it), so the rows of weights over at
//! most four consecutive control points are computed in closed form. Corners are fixed at their
//! loop points: the parts between them are independent, and one without inner points is straight.
//!
//! The fit minimizes the curve version of the squared distance (Pottmann & Leopoldseder 2003;
//! Wang, Pottmann & Liu 2006) to the dense limit polyline (`L = 6`): data point `p` with foot `c`,
//! unit tangent `T`, curvature radius `ρ` and `d = (p − c)·N` costs `λ[(c − p)·T]² + |(c − p)×T|²`
//! with `λ = d/(d − ρ)` if `d < 0`, else 0, plus 0.01. Tiny damping and smoothness penalties on the
//! change keep the cyclic block-banded normal equations positive definite; Jacobi-preconditioned
//! conjugate gradients solve them without a dense matrix.

use subfit_mesh::vec3::{add, cross, dist2, dot, norm, norm2, scale, sub, unit};

/// Points per span of the dense limit polyline used for fitting (6 subdivision levels).
const PER: usize = 64;
/// Initial spans: one per 45° of turning at least, and enough that `C_ERR·R·θ⁴ ≤ tolerance`, the
/// least-squares error of a uniform cubic B-spline circle of radius `R` with spans of angle `θ`.
const TURN: f64 = std::f64::consts::FRAC_PI_4;
const C_ERR: f64 = 0.0015;
/// Squared-distance weights: tangential term, damping, smoothness of the change.
const W: [f64; 3] = [0.01, 1e-6, 1e-5];

type P3 = [f64; 3];
const EYE: Sym = [1.0, 0.0, 0.0, 1.0, 0.0, 1.0];
/// Symmetric 3×3 matrix: xx, xy, xz, yy, yz, zz.
type Sym = [f64; 6];
/// Cyclic block band: row `i`, slot `4 + o` holds the block of column `i + o`, `|o| ≤ 4`.
type Band = Vec<[Sym; 9]>;
/// A part of the loop: unwrapped start and end index (corners, or the whole loop), spans.
type Part = (usize, usize, usize);

/// A closed subdivision curve fitted to one boundary loop.
#[derive(Clone, Debug, PartialEq)]
pub struct BoundaryCurve {
    /// Control points in loop order (normalized units).
    pub control: Vec<[f64; 3]>,
    /// Per control point: a corner (Hoppe's rule, interpolated).
    pub corner: Vec<bool>,
    /// Per control point: index into the loop's points of the loop vertex nearest to its limit
    /// position; strictly increasing cyclically in loop order (i.e. the sequence, rotated to
    /// start at its minimum, is strictly increasing), all distinct. A corner's entry is its
    /// corner index.
    pub loop_index: Vec<usize>,
    /// Largest and root-mean-square distance of the loop's points from the limit curve.
    pub max_error: f64,
    /// See `max_error`.
    pub rms_error: f64,
}

/// Limit weights over control points `s−1 ..= s+2` of the point at `u` of span `s`, its ends
/// corners as flagged.
fn weights(u: f64, c0: bool, c1: bool) -> [f64; 4] {
    let (v, p, q) = (1.0 - u, (1.0 - u).powi(3), u.powi(3));
    let (a, b) = (p * ind(c0), q * ind(c1));
    let (w1, w2) = (3.0 * q - 6.0 * u * u + 4.0, 3.0 * p - 6.0 * v * v + 4.0);
    [p - a, w1 + 2.0 * a - b, w2 - a + 2.0 * b, q - b].map(|x| x / 6.0)
}

/// The span and limit weights of dense point `k` with `per` points per span.
fn row(corner: &[bool], k: usize, per: usize) -> (usize, [f64; 4]) {
    let (n, s, u) = (corner.len(), k / per, (k % per) as f64 / per as f64);
    (s, weights(u, corner[s % n], corner[(s + 1) % n]))
}

fn eval(control: &[P3], corner: &[bool], per: usize) -> Vec<P3> {
    let n = control.len();
    let term = |s: usize, w: [f64; 4], a: usize| scale(control[(s + n - 1 + a) % n], w[a]);
    let point = |(s, w)| (0..4).map(|a| term(s, w, a)).fold([0.0; 3], add);
    (0..n * per).map(|k| point(row(corner, k, per))).collect()
}

/// The limit curve of a closed control polygon with corner flags, as `2^levels` points per
/// control segment (positions on the limit curve), in order starting at control point 0's limit
/// position. Missing corner flags count as `false`. Cost `O(n·2^levels)`.
pub fn limit_points(control: &[[f64; 3]], corner: &[bool], levels: u32) -> Vec<[f64; 3]> {
    let mut flags = corner.to_vec();
    flags.resize(control.len(), false);
    eval(control, &flags, 1 << levels)
}

fn sym_mul(m: &Sym, v: P3) -> P3 {
    let r = |a: usize, b: usize, c: usize| m[a] * v[0] + m[b] * v[1] + m[c] * v[2];
    [r(0, 1, 2), r(1, 3, 4), r(2, 4, 5)]
}

fn band_add(a: &mut Band, i: usize, j: usize, w: f64, m: &Sym) {
    let (n, o) = (a.len(), (j + a.len() - i) % a.len());
    let slot = if o <= 4 { o + 4 } else { o + 4 - n };
    a[i][slot].iter_mut().zip(m).for_each(|(x, y)| *x += w * y);
}

/// `A·x`, zero in the rows of fixed control points.
fn band_mul(a: &Band, x: &[P3], free: &[bool]) -> Vec<P3> {
    let n = a.len();
    let col = |i: usize, s: usize| sym_mul(&a[i][s], x[(i + s + 4 * n - 4) % n]);
    let row = |i: usize| (0..9).fold([0.0; 3], |y, s| add(y, col(i, s)));
    (0..n).map(|i| scale(row(i), ind(free[i]))).collect()
}

fn vdot(a: &[P3], b: &[P3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| dot(*x, *y)).sum()
}

/// Solves `A x = b` over the free entries of `x` (the others stay) by Jacobi-preconditioned
/// conjugate gradients.
fn solve_cg(a: &Band, b: &[P3], x: &mut [P3], free: &[bool]) {
    let dinv: Vec<P3> = a.iter().map(|r| [0, 3, 5].map(|d| 1.0 / r[4][d])).collect();
    let pre1 = |r: &P3, d: &P3| [r[0] * d[0], r[1] * d[1], r[2] * d[2]];
    let pre = |r: &[P3]| {
        r.iter()
            .zip(&dinv)
            .map(|(r, d)| pre1(r, d))
            .collect::<Vec<_>>()
    };
    let ax = band_mul(a, x, free);
    let r0 = |i: usize| scale(sub(b[i], ax[i]), ind(free[i]));
    let mut r: Vec<P3> = (0..x.len()).map(r0).collect();
    let mut p = pre(&r);
    let (mut rz, mut iters) = (vdot(&r, &p), 0);
    let stop = rz * 1e-16;
    while rz > stop && iters < 12 * x.len() + 50 {
        let ap = band_mul(a, &p, free);
        let alpha = rz / vdot(&p, &ap);
        if !(alpha > 0.0 && alpha.is_finite()) {
            break;
        }
        for ((x, r), (p, ap)) in x.iter_mut().zip(&mut r).zip(p.iter().zip(&ap)) {
            (*x, *r) = (add(*x, scale(*p, alpha)), sub(*r, scale(*ap, alpha)));
        }
        let z = pre(&r);
        let beta = vdot(&r, &z) / rz;
        for (p, z) in p.iter_mut().zip(&z) {
            *p = add(*z, scale(*p, beta));
        }
        (rz, iters) = (rz * beta, iters + 1);
    }
}

fn ind(b: bool) -> f64 {
    f64::from(u8::from(b))
}

/// Circumcircle curvature at loop vertex `v` (unwrapped) from the vertices about `h` of arc
/// length away on either side, within the unwrapped range `lo..=hi`.
fn turn_curvature(pts: &[P3], edge: &[f64], v: usize, (lo, hi): (usize, usize), h: f64) -> f64 {
    let (m, mut i, mut k, mut l, mut r) = (pts.len(), v, v, 0.0, 0.0);
    while i > lo && l < h {
        (i, l) = (i - 1, l + edge[(i - 1) % m]);
    }
    while k < hi && r < h {
        (k, r) = (k + 1, r + edge[k % m]);
    }
    let (p, q) = (sub(pts[v % m], pts[i % m]), sub(pts[k % m], pts[v % m]));
    (2.0 * norm(cross(p, q)) / (norm(p) * norm(q) * norm(add(p, q)))).max(0.0)
}

/// Fitting state: control points (corners with their loop index), and per loop point the foot
/// parameter on the curve (span + fraction, in `[0, n)`) and the distance.
#[derive(Default)]
struct Fitter<'a> {
    pts: &'a [P3],
    control: Vec<P3>,
    fixed: Vec<Option<usize>>,
    t: Vec<f64>,
    err: Vec<f64>,
}

impl Fitter<'_> {
    /// Control points equally spaced in the measure `mu` (per segment) along the closed polyline
    /// `poly` over each part (its start at corner `cs[p]`; no corners: one periodic part), pushed
    /// outwards so their limit positions start near the polyline. Returns the curve parameter of
    /// each polyline point.
    fn place(&mut self, poly: &[P3], mu: &[f64], parts: &[Part], cs: &[usize]) -> Vec<f64> {
        let (len, n) = (poly.len(), parts.iter().map(|p| p.2).sum::<usize>());
        let mut t = vec![0.0; len];
        (self.control, self.fixed) = (Vec::new(), Vec::new());
        for (p, &(a, e, sp)) in parts.iter().enumerate() {
            let mut c = vec![0.0];
            (a..e).for_each(|v| c.push(c[v - a] + mu[v % len]));
            let (total, start) = (c[e - a], self.control.len());
            if let Some(&k) = cs.get(p) {
                self.control.push(poly[a % len]);
                self.fixed.push(Some(k));
            }
            for q in usize::from(!cs.is_empty())..sp {
                let target = total * q as f64 / sp as f64;
                let v = c.partition_point(|&x| x <= target).clamp(1, e - a);
                let u = ((target - c[v - 1]) / (c[v] - c[v - 1]).max(1e-300)).clamp(0.0, 1.0);
                let (p0, p1) = (poly[(a + v - 1) % len], poly[(a + v) % len]);
                self.control.push(add(p0, scale(sub(p1, p0), u)));
                self.fixed.push(None);
            }
            for v in a..e {
                t[v % len] = (start as f64 + (c[v - a] / total * sp as f64).max(0.0)) % n as f64;
            }
        }
        let old = self.control.clone();
        for (i, p) in self.control.iter_mut().enumerate() {
            let nb = add(old[(i + n - 1) % n], old[(i + 1) % n]);
            let lap = sub(scale(old[i], 2.0), nb);
            *p = add(*p, scale(lap, ind(self.fixed[i].is_none()) / 6.0));
        }
        t
    }

    fn corner(&self) -> Vec<bool> {
        self.fixed.iter().map(Option::is_some).collect()
    }

    fn dense(&self) -> Vec<P3> {
        eval(&self.control, &self.corner(), PER)
    }

    fn max_error(&self) -> f64 {
        self.err.iter().fold(0.0, |a, &e| a.max(e))
    }

    /// Foot points: nearest points of the dense polyline within half a span of the last foot,
    /// the window extended while the distance keeps falling at its end.
    fn feet(&mut self, dense: &[P3]) {
        let nn = dense.len();
        let seg = |k: usize, p: P3| {
            let (a, ab) = (dense[k], sub(dense[(k + 1) % nn], dense[k]));
            let u = (dot(sub(p, a), ab) / norm2(ab).max(1e-300)).clamp(0.0, 1.0);
            (dist2(add(a, scale(ab, u)), p), u, k)
        };
        let len = nn.min(PER + 1);
        for (j, &p) in self.pts.iter().enumerate() {
            let first = ((self.t[j] * PER as f64) as usize + nn - len / 2) % nn;
            let scan = (0..len).map(|o| seg((first + o) % nn, p));
            let mut best = scan.reduce(|x, y| if y.0 < x.0 { y } else { x }).unwrap();
            let o = (best.2 + nn - first) % nn;
            let walk = len < nn && (o == 0 || o + 1 == len);
            let step = if o == 0 { nn - 1 } else { 1 };
            for _ in 0..nn * usize::from(walk) {
                let next = seg((best.2 + step) % nn, p);
                if next.0 >= best.0 {
                    break;
                }
                best = next;
            }
            (self.t[j], self.err[j]) = ((best.2 as f64 + best.1) / PER as f64, best.0.sqrt());
        }
    }

    /// One squared-distance-minimization step; returns the largest control-point move.
    fn step(&mut self, dense: &[P3]) -> f64 {
        let (n, nn, corner) = (self.control.len(), dense.len(), self.corner());
        let (mut a, mut b) = (vec![[[0.0; 6]; 9]; n], vec![[0.0; 3]; n]);
        let curvature = |k: usize| {
            let (p, q, r) = (dense[(k + nn - 1) % nn], dense[k % nn], dense[(k + 1) % nn]);
            let (h1, h2) = (norm(sub(q, p)).max(1e-300), norm(sub(r, q)).max(1e-300));
            let dt = sub(scale(sub(r, q), 1.0 / h2), scale(sub(q, p), 1.0 / h1));
            scale(dt, 2.0 / (h1 + h2))
        };
        let mut ws: Vec<(usize, f64)> = Vec::with_capacity(8);
        for (&p, &t) in self.pts.iter().zip(&self.t) {
            let (k, u) = ((t * PER as f64) as usize % nn, (t * PER as f64).fract());
            let (q0, q1) = (dense[k], dense[(k + 1) % nn]);
            let tn = unit(sub(q1, q0)).unwrap_or_default();
            let kv = add(scale(curvature(k), 1.0 - u), scale(curvature(k + 1), u));
            let kd = dot(sub(p, add(q0, scale(sub(q1, q0), u))), kv); // d/ρ
            let l = if kd < 0.0 { kd / (kd - 1.0) } else { 0.0 } + W[0] - 1.0;
            let ij = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];
            let m: Sym = ij.map(|(i, j)| ind(i == j) + l * tn[i] * tn[j]);
            ws.clear();
            for (kk, fr) in [(k, 1.0 - u), ((k + 1) % nn, u)] {
                let (s, w) = row(&corner, kk, PER);
                for (c, w) in (0..4).map(|o| ((s + n - 1 + o) % n, fr * w[o])) {
                    match ws.iter_mut().find(|e| e.0 == c) {
                        Some(e) => e.1 += w,
                        None => ws.push((c, w)),
                    }
                }
            }
            for &(ca, wa) in &ws {
                b[ca] = add(b[ca], scale(sym_mul(&m, p), wa));
                ws.iter()
                    .for_each(|&(cb, wb)| band_add(&mut a, ca, cb, wa * wb, &m));
            }
        }
        // Damping and smoothness of the change: no residual at the current control points.
        let (avg, eye) = (self.pts.len() as f64 / n as f64, EYE);
        for i in 0..n {
            band_add(&mut a, i, i, W[1] * avg, &eye);
            b[i] = add(b[i], scale(self.control[i], W[1] * avg));
            let (s, c) = ([(i + n - 1) % n, i, (i + 1) % n], [1.0, -2.0, 1.0]);
            let dd = (0..3).fold([0.0; 3], |acc, q| add(acc, scale(self.control[s[q]], c[q])));
            for q in 0..3 {
                b[s[q]] = add(b[s[q]], scale(dd, W[2] * avg * c[q]));
                (0..3).for_each(|r| band_add(&mut a, s[q], s[r], W[2] * avg * c[q] * c[r], &eye));
            }
        }
        let (mut x, free): (_, Vec<bool>) =
            (self.control.clone(), corner.iter().map(|&c| !c).collect());
        solve_cg(&a, &b, &mut x, &free);
        let moved = x.iter().zip(&self.control).map(|(a, b)| dist2(*a, *b));
        let moved = moved.fold(0.0, f64::max).sqrt();
        self.control = x;
        moved
    }

    /// Up to 10 rounds of foot points and a step, until the control points move less than
    /// `eps`; then the foot points and errors of the result.
    fn run(&mut self, eps: f64) {
        for _ in 0..10 {
            let dense = self.dense();
            self.feet(&dense);
            if self.step(&dense) < eps {
                break;
            }
        }
        self.feet(&self.dense());
    }

    /// The loop vertex nearest to each limit position among the loop points with feet in the
    /// adjacent spans, made strictly increasing cyclically around the corners (or control 0).
    fn loop_index(&self) -> Vec<usize> {
        let (n, m, dense) = (self.control.len(), self.pts.len(), self.dense());
        let mut near: Vec<Option<usize>> = self.fixed.clone();
        for (j, &x) in self.t.iter().enumerate() {
            for i in [x as usize % n, (x as usize + 1) % n] {
                let d = |j: usize| dist2(self.pts[j], dense[i * PER]);
                if self.fixed[i].is_none() && near[i].is_none_or(|k| d(j) < d(k)) {
                    near[i] = Some(j);
                }
            }
        }
        let a0 = self.fixed.iter().position(Option::is_some).unwrap_or(0);
        let (base, mi) = (near[a0].unwrap_or(0), m as isize);
        let (raw, mut prev, mut last) = (|j: usize| ((j + m - base) % m) as isize, 0, base);
        let mut offs: Vec<(isize, bool)> = (0..n)
            .map(|q| {
                let i = (a0 + q) % n;
                last = near[i].unwrap_or(last);
                let d = (raw(last) - prev + mi / 2).rem_euclid(mi) - mi / 2;
                let anchor = q == 0 || self.fixed[i].is_some();
                prev = if anchor { raw(last) } else { prev + d };
                (prev, anchor)
            })
            .collect();
        let (mut lo, mut hi) = (-1, mi);
        for (x, anchor) in offs.iter_mut() {
            *x = if *anchor { *x } else { (*x).max(lo + 1) };
            lo = *x;
        }
        for (x, anchor) in offs.iter_mut().rev() {
            *x = if *anchor { *x } else { (*x).min(hi - 1) };
            hi = *x;
        }
        let at = |i: usize| (base + offs[(i + n - a0) % n].0 as usize) % m;
        (0..n).map(at).collect()
    }
}

/// Fits a closed subdivision curve to the closed polyline `loop_points` (in order, last not
/// repeated, ≥ 3 points; fewer are returned as their own control polygon) with corners at the
/// loop indices `corners` (any order, may be empty, out-of-range entries ignored), within
/// `tolerance` (largest distance of a loop point from the curve, same units) if it can with at
/// most `max_control` control points.
///
/// The count is at least 3 and at most `max(3, min(max_control, loop_points.len() / 2))`, but
/// every corner is a control point; a part between consecutive corners may have no inner control
/// point, then it is the exact straight edge. A part starts with one span per 45° of its turning
/// (on chords of `25·tolerance`, 3 to 20 mean edges) or, if more, what a circle of the local
/// curvature needs within `tolerance`, placed by that curvature-weighted arc length. While the
/// largest error exceeds `tolerance`, each part with such errors grows by `(error/tolerance)^¼`
/// (at least one point, at most 1.5 times), the control points are placed anew along the current
/// curve, denser in spans with errors well above the part's median, and the loop is refitted.
/// Distances are to the limit polyline with 64 points per span (off the curve by its sagitta).
///
/// Cost: near-linear in the loop's points per iteration (foot search over about 65 dense
/// segments around the last foot, a banded conjugate-gradient solve in the control points), at
/// most 10 iterations per round, the count growing geometrically over the rounds.
pub fn fit_boundary_curve(
    loop_points: &[[f64; 3]],
    corners: &[usize],
    tolerance: f64,
    max_control: usize,
) -> BoundaryCurve {
    let (pts, m) = (loop_points, loop_points.len());
    if m < 3 {
        let (control, loop_index, corner) = (pts.to_vec(), (0..m).collect(), vec![false; m]);
        return BoundaryCurve {
            control,
            corner,
            loop_index,
            max_error: 0.0,
            rms_error: 0.0,
        };
    }
    let mut cs: Vec<usize> = corners.iter().copied().filter(|&c| c < m).collect();
    cs.sort_unstable();
    cs.dedup();
    let periodic = cs.is_empty();
    let cap = max_control.min(m / 2).max(3).max(cs.len());
    let len = |j: usize| norm(sub(pts[(j + 1) % m], pts[j]));
    let edge: Vec<f64> = (0..m).map(len).collect();
    let total: f64 = edge.iter().sum();
    let tol = tolerance.max(1e-9 * total).max(f64::MIN_POSITIVE);
    let h = (25.0 * tol).clamp(3.0 * total / m as f64, 20.0 * total / m as f64);
    let ends = |i: usize| (cs[i], *cs.get(i + 1).unwrap_or(&(cs[0] + m)));
    let mut parts: Vec<Part> = match periodic {
        true => vec![(0, m, 3)],
        false => (0..cs.len()).map(|i| (ends(i).0, ends(i).1, 1)).collect(),
    };
    let (mut g, mut mu) = (vec![0.0; m], vec![0.0; m]);
    for (a, e, sp) in &mut parts {
        let (a, e) = (*a, *e);
        for v in a + usize::from(!periodic)..e {
            let lo = if periodic { v + m / 2 } else { a + m };
            let hi = if periodic { v + m + m / 2 } else { e + m };
            let k = turn_curvature(pts, &edge, v + m, (lo, hi), h);
            g[v % m] = (k / TURN).max((C_ERR * k.powi(3) / tol).powf(0.25));
        }
        let gv = |v: usize| edge[v % m] * (g[v % m] + g[(v + 1) % m]) / 2.0;
        let est: f64 = (a..e).map(gv).sum();
        let base = 0.25 * est.max(1.0) / (a..e).map(|v| edge[v % m]).sum::<f64>().max(1e-300);
        (a..e).for_each(|v| mu[v % m] = gv(v) + base * edge[v % m]);
        *sp = (est.round() as usize).clamp(*sp, e - a);
    }
    let (n, k) = (parts.iter().map(|p| p.2).sum::<usize>(), parts.len());
    for p in &mut parts {
        p.2 = (1 + (p.2 - 1) * (cap - k) / (n - k).max(1)).min(p.2);
    }
    while parts.iter().map(|p| p.2).sum::<usize>() < 3 {
        let room = |p: &Part| p.1 - p.0 - p.2;
        let p = (0..k).max_by_key(|&p| room(&parts[p])).unwrap_or(0);
        parts[p].2 += 1;
    }
    let mut f = Fitter::default();
    (f.pts, f.err) = (pts, vec![f64::INFINITY; m]);
    f.t = f.place(pts, &mu, &parts, &cs);
    let eps = 5e-2 * tolerance.clamp(1e-9 * total, 1e-2 * total);
    f.run(eps);
    while f.max_error() > tolerance && f.control.len() < cap {
        // Per part: the new count, and a density over its spans raised where errors are high.
        let n = f.control.len();
        let (mut err, mut mu, mut budget) = (vec![0.0f64; n], vec![1.0; n * PER], cap - n);
        for (&t, &e) in f.t.iter().zip(&f.err) {
            err[t as usize % n] = err[t as usize % n].max(e);
        }
        let (mut start, mut new) = (0, Vec::new());
        for &(a, e, sp) in &parts {
            let mut s = err[start..start + sp].to_vec();
            s.sort_by(f64::total_cmp);
            let (med, worst) = (s[sp / 2], s[sp - 1]);
            for i in (start..start + sp).filter(|&i| err[i] > tol.max(1.5 * med)) {
                mu[i * PER..(i + 1) * PER].fill((err[i] / med).sqrt().min(1.5));
            }
            let grown = (sp as f64 * (worst / tol).powf(0.25).min(1.5)).ceil() as usize;
            let add = (grown.max(sp + 1).min(e - a) - sp).min(budget) * usize::from(worst > tol);
            new.push((start * PER, (start + sp) * PER, sp + add));
            (start, budget) = (start + sp, budget - add);
        }
        if budget == cap - n {
            break;
        }
        let t = f.place(&f.dense(), &mu, &new, &cs);
        let nf = f.control.len() as f64;
        for x in &mut f.t {
            let y = *x * PER as f64;
            let (k, u) = (y as usize % t.len(), y.fract());
            let t1 = t[(k + 1) % t.len()] + nf * ind(t[(k + 1) % t.len()] < t[k]);
            *x = (t[k] + u * (t1 - t[k])) % nf;
        }
        parts.iter_mut().zip(&new).for_each(|(p, q)| p.2 = q.2);
        f.run(eps);
    }
    let rms_error = (f.err.iter().map(|e| e * e).sum::<f64>() / m as f64).sqrt();
    let (loop_index, max_error, corner) = (f.loop_index(), f.max_error(), f.corner());
    BoundaryCurve {
        control: f.control,
        corner,
        loop_index,
        max_error,
        rms_error,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Seeded xorshift, uniform in [−1, 1).
    fn rand(s: &mut u64) -> f64 {
        *s ^= *s << 13;
        *s ^= *s >> 7;
        *s ^= *s << 17;
        (*s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// A unit circle in a tilted plane with per-coordinate noise up to `noise`.
    fn circle(m: usize, noise: f64) -> Vec<P3> {
        let (mut s, a) = (0x5eed, |j: usize| {
            std::f64::consts::TAU * j as f64 / m as f64
        });
        let mut noisy =
            |a: f64| [0.8 * a.cos(), a.sin(), 0.6 * a.cos()].map(|x| x + noise * rand(&mut s));
        (0..m).map(|j| noisy(a(j))).collect()
    }

    fn seg_dist(a: P3, b: P3, p: P3) -> f64 {
        let u = (dot(sub(p, a), sub(b, a)) / norm2(sub(b, a))).clamp(0.0, 1.0);
        dist2(add(a, scale(sub(b, a), u)), p).sqrt()
    }

    /// Eq. 2 (`w = 6`) or the limit mask (`w = 4`) at `i`, corners staying.
    fn mask(q: &[P3], c: &[bool], i: usize, w: f64) -> P3 {
        let k = q.len();
        let v = add(add(q[(i + k - 1) % k], scale(q[i], w)), q[(i + 1) % k]);
        [scale(v, 1.0 / (w + 2.0)), q[i]][usize::from(c[i])]
    }

    /// The invariants, and the errors against a brute-force recomputation on level 7 `within`.
    fn check(c: &BoundaryCurve, pts: &[P3], corners: &[usize], within: f64) {
        let (n, li) = (c.control.len(), &c.loop_index);
        let s = (0..n).min_by_key(|&i| li[i]).unwrap();
        assert!(
            (1..n).all(|i| li[(s + i) % n] > li[(s + i - 1) % n]),
            "{li:?}"
        );
        assert!(n >= 3 && c.corner.len() == n && li.len() == n);
        let at = |k: &usize| li.iter().position(|x| x == k).filter(|&i| c.corner[i]);
        assert!(corners
            .iter()
            .all(|k| at(k).is_some_and(|i| c.control[i] == pts[*k])));
        assert_eq!(c.corner.iter().filter(|&&x| x).count(), corners.len());
        let (fine, m) = (limit_points(&c.control, &c.corner, 7), pts.len() as f64);
        let seg = |p: P3, k: usize| seg_dist(fine[k], fine[(k + 1) % fine.len()], p);
        let d = |&p: &P3| (0..fine.len()).map(|k| seg(p, k)).fold(1e9, f64::min);
        let errs: Vec<f64> = pts.iter().map(d).collect();
        let max = errs.iter().fold(0.0, |a: f64, &e| a.max(e));
        let rms = (errs.iter().map(|e| e * e).sum::<f64>() / m).sqrt();
        assert!(
            (max - c.max_error).abs().max((rms - c.rms_error).abs()) < within,
            "{max}"
        );
    }

    #[test]
    fn limit_points_follow_the_subdivision_rules() {
        let mut s = 7;
        let p: Vec<P3> = (0..7).map(|_| [0; 3].map(|_| rand(&mut s))).collect();
        let corner = [false, true, false, false, true, true, false];
        // Eq. 2 and 3 applied four times, then the limit mask.
        let (mut q, mut c) = (p.clone(), corner.to_vec());
        for _ in 0..4 {
            let k = q.len();
            let mid = |i: usize| scale(add(q[i], q[(i + 1) % k]), 0.5);
            let next = |i: usize| [mask(&q, &c, i / 2, 6.0), mid(i / 2)][i % 2];
            let nq = (0..2 * k).map(next).collect();
            (q, c) = (nq, (0..2 * k).map(|i| i % 2 == 0 && c[i / 2]).collect());
        }
        let (k, l4, l6) = (
            q.len(),
            limit_points(&p, &corner, 4),
            limit_points(&p, &corner, 6),
        );
        assert!((0..k).all(|i| dist2(l4[i], mask(&q, &c, i, 4.0)) < 1e-24));
        assert!((0..k).all(|i| dist2(l4[i], l6[4 * i]) < 1e-24) && l4[16] == p[1]);
        assert!(dist2(l4[0], mask(&p, &[false; 7], 0, 4.0)) < 1e-24);
        let near = |i: usize| seg_dist(l4[i / 4], l4[(i / 4 + 1) % k], l6[i]) < 2e-3;
        assert!((0..4 * k).all(near));
        let q = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [3.0, 0.0, 0.0],
            [1.0, 2.0, 0.5],
        ];
        let l = limit_points(&q, &[true, false, true], 4);
        assert!(l[..32]
            .iter()
            .all(|p| p[1] == 0.0 && p[2] == 0.0 && (0.0..=3.0).contains(&p[0])));
    }

    #[test]
    fn circles_need_few_control_points() {
        let pts = circle(400, 0.0);
        let c = fit_boundary_curve(&pts, &[], 1e-3, 200);
        check(&c, &pts, &[], 2e-5);
        assert!(
            c.max_error <= 1e-3 && (6..=12).contains(&c.control.len()),
            "{c:?}"
        );
        let c = fit_boundary_curve(&pts, &[], 1e-5, 200);
        check(&c, &pts, &[], 2e-5);
        assert!(c.max_error <= 1e-5 && c.control.len() <= 30, "{c:?}");
        let pts = circle(400, 1e-3);
        let c = fit_boundary_curve(&pts, &[], 4e-3, 100);
        check(&c, &pts, &[], 2e-5);
        assert!(c.max_error <= 4e-3 && c.control.len() <= 12, "{c:?}");
        let c = fit_boundary_curve(&pts, &[], 1e-6, 20);
        check(&c, &pts, &[], 2e-5);
        assert!(c.control.len() == 20 && c.max_error > 1e-6);
    }

    #[test]
    fn corners_stay_and_straight_edges_are_exact() {
        let sq = |i: usize| {
            [
                [-1.0, 1.0, 1.0, -1.0][i % 4],
                [-1.0, -1.0, 1.0, 1.0][i % 4],
                0.0,
            ]
        };
        let side = |j: usize| scale(sub(sq(j / 100 + 1), sq(j / 100)), (j % 100) as f64 / 100.0);
        let pts: Vec<P3> = (0..400).map(|j| add(sq(j / 100), side(j))).collect();
        let c = fit_boundary_curve(&pts, &[300, 0, 100, 200], 1e-3, 50);
        check(&c, &pts, &[0, 100, 200, 300], 2e-5);
        assert!(c.control.len() == 4 && c.max_error < 1e-12);
        // Two half circles of radius 0.5 joined by straight edges of length 1, corners between.
        let arc = |j: usize, x: f64, a: f64| {
            let a = std::f64::consts::PI * (j as f64 / 78.0 + a);
            [x + 0.5 * a.cos(), 0.5 * a.sin(), 0.0]
        };
        let mut pts: Vec<P3> = (0..50).map(|j| [j as f64 / 50.0, -0.5, 0.0]).collect();
        pts.extend((0..78).map(|j| arc(j, 1.0, -0.5)));
        pts.extend((0..50).map(|j| [1.0 - j as f64 / 50.0, 0.5, 0.0]));
        pts.extend((0..78).map(|j| arc(j, 0.0, 0.5)));
        let c = fit_boundary_curve(&pts, &[0, 50, 128, 178], 1e-3, 100);
        check(&c, &pts, &[0, 50, 128, 178], 2e-5);
        let (n, li) = (c.control.len(), &c.loop_index);
        assert!(c.max_error <= 1e-3 && n <= 20, "{c:?}");
        let next = |k: usize| li[(li.iter().position(|&x| x == k).unwrap() + 1) % n];
        assert!(
            next(0) == 50 && next(128) == 178,
            "no inner points on the straight edges"
        );
    }

    #[test]
    fn tiny_loops_work() {
        let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.5]];
        for corners in [&[][..], &[1], &[0, 2], &[2, 1, 0], &[1, 1, 7]] {
            let c = fit_boundary_curve(&tri, corners, 1e-3, 10);
            let mut cs: Vec<usize> = corners.iter().copied().filter(|&k| k < 3).collect();
            cs.dedup();
            check(&c, &tri, &cs, 1e-4); // coarse spans: the chords' sagitta
            assert!(c.control.len() == 3 && c.max_error < 1e-9);
        }
    }
}
