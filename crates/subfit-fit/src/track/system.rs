//! The dense normal system of a tracking step and the rows it is made of: the fit's
//! point-to-plane rows, the markers' point-to-point rows and the graph's priors (regularity,
//! rigidity, second order; see [`super`]'s module docs for the energy).

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use subfit_mesh::vec3::{dot as dot3, sub};

use super::model::{v, DeformationGraph, NodeMotion, Skin, PER};
use super::options::{Marker, TrackOptions};

/// A dense symmetric normal system `H x = b` over `12 m` unknowns; only the upper triangle
/// of `H` (row ≤ column) is accumulated.
pub(super) struct Normal {
    n: usize,
    h: Vec<f64>,
    b: Vec<f64>,
}

impl Normal {
    pub(super) fn new(n: usize) -> Self {
        Self {
            n,
            h: vec![0.0; n * n],
            b: vec![0.0; n],
        }
    }

    /// Solves the system with a little Levenberg damping (1e-6 of the mean diagonal, which
    /// keeps unobserved nodes put) and adds the step to `motion`; false when the factorization
    /// fails.
    pub(super) fn solve_into(&self, motion: &mut NodeMotion) -> bool {
        let nn = self.n;
        let trace: f64 = (0..nn).map(|i| self.h[i * nn + i]).sum::<f64>() / nn as f64;
        let h = Mat::<f64>::from_fn(nn, nn, |a, c| {
            self.h[a.min(c) * nn + a.max(c)] + if a == c { 1e-6 * trace.max(1e-30) } else { 0.0 }
        });
        let rhs = Mat::<f64>::from_fn(nn, 1, |a, _| self.b[a]);
        let Ok(llt) = h.llt(Side::Lower) else {
            return false;
        };
        let x = llt.solve(&rhs);
        for (k, (lin, t)) in motion
            .linear
            .iter_mut()
            .zip(&mut motion.translations)
            .enumerate()
        {
            for a in 0..3 {
                for c in 0..3 {
                    lin[(a, c)] += x[(PER * k + 3 * a + c, 0)];
                }
                t[a] += x[(PER * k + 9 + a, 0)];
            }
        }
        true
    }

    /// Adds `w (jᵀj, −jᵀr)` for one residual row `r` with sparse gradient `j` (the upper
    /// triangle of `jᵀj`).
    pub(super) fn row(&mut self, j: &[(usize, f64)], r: f64, w: f64) {
        for &(a, va) in j {
            self.b[a] -= w * va * r;
            let base = a * self.n;
            let wa = w * va;
            for &(c, vc) in j {
                if c >= a {
                    self.h[base + c] += wa * vc;
                }
            }
        }
    }

    /// Adds `other` (a system over as many unknowns) into this one.
    fn absorb(&mut self, other: &Self) {
        self.h.iter_mut().zip(&other.h).for_each(|(x, y)| *x += y);
        self.b.iter_mut().zip(&other.b).for_each(|(x, y)| *x += y);
    }
}

/// What the point-to-plane rows of one iteration need: the samples' skinning, rest and
/// moved positions, the nodes.
pub(super) struct FitRows<'a> {
    pub(super) skin: &'a Skin,
    pub(super) samples: &'a [[f64; 3]],
    pub(super) g: &'a [[f64; 3]],
    pub(super) moved: &'a [[f64; 3]],
    /// Scale `c` of the robust weights `1 / (1 + (e / c)²)` of the residuals `e` (normalized
    /// units); 0: every row at full weight.
    pub(super) robust: f64,
}

impl FitRows<'_> {
    /// Adds the rows `nᵀ(x'_i − y)` of `matches` (sample, point, normal), all together of
    /// weight `weight`, plus `beta` times their point-to-point rows.
    /// `δx'_i = Σ_k w_k (Σ_c d_c δA_k[i][c] + δt_k[i])`, `d = x − g_k`.
    pub(super) fn add(
        &self,
        sys: &mut Normal,
        matches: &[(usize, [f64; 3], [f64; 3])],
        weight: f64,
        beta: f64,
    ) {
        if matches.is_empty() || weight == 0.0 {
            return;
        }
        use rayon::prelude::*;
        let wf = weight / matches.len() as f64;
        // One partial system per thread (each 8·(12m)² bytes), summed.
        let chunk = matches.len().div_ceil(rayon::current_num_threads().max(1));
        let parts: Vec<Normal> = matches
            .par_chunks(chunk.max(1))
            .map(|part| {
                let mut local = Normal::new(sys.n);
                let mut j: Vec<(usize, f64)> = Vec::with_capacity(PER * self.skin.per);
                for &(i, y, n) in part {
                    let r = sub(self.moved[i], y);
                    let e = dot3(n, r);
                    let wf = if self.robust > 0.0 {
                        wf / (1.0 + (e / self.robust).powi(2))
                    } else {
                        wf
                    };
                    self.skin.jacobian(&mut j, i, self.samples[i], self.g, n);
                    local.row(&j, e, wf);
                    if beta > 0.0 {
                        for a in 0..3 {
                            let mut e = [0.0; 3];
                            e[a] = 1.0;
                            self.skin.jacobian(&mut j, i, self.samples[i], self.g, e);
                            local.row(&j, r[a], wf * beta);
                        }
                    }
                }
                local
            })
            .collect();
        for p in &parts {
            sys.absorb(p);
        }
    }
}

/// Marker rows: `x'_m − p_m`, point to point, all together of weight `weight`.
pub(super) fn add_markers(
    sys: &mut Normal,
    skin: &Skin,
    markers: &[Marker],
    g: &[[f64; 3]],
    motion: &NodeMotion,
    weight: f64,
) {
    let wm = weight / markers.len().max(1) as f64;
    let mut j: Vec<(usize, f64)> = Vec::with_capacity(PER * skin.per);
    for (i, mk) in markers.iter().enumerate() {
        let r = sub(skin.apply(i, mk.rest, g, motion), mk.position);
        for a in 0..3 {
            let mut e = [0.0; 3];
            e[a] = 1.0;
            skin.jacobian(&mut j, i, mk.rest, g, e);
            sys.row(&j, r[a], wm);
        }
    }
}

/// The graph's priors: regularity and rigidity (both times `stiffness`) and the second order.
pub(super) fn add_priors(
    sys: &mut Normal,
    graph: &DeformationGraph,
    motion: &NodeMotion,
    options: &TrackOptions,
    stiffness: f64,
) {
    let g = &graph.positions;
    let m = graph.len();
    let pairs: usize = graph.neighbors.iter().map(Vec::len).sum();
    let mut j: Vec<(usize, f64)> = Vec::with_capacity(64);
    // Regularity rows: e = A_k (g_l − g_k) + g_k + t_k − g_l − t_l.
    let wr = stiffness * options.regularity / pairs.max(1) as f64;
    for (k, nb) in graph.neighbors.iter().enumerate() {
        for &l in nb {
            let l = l as usize;
            let dl = v(sub(g[l], g[k]));
            let e =
                motion.linear[k] * dl + v(motion.translations[k]) - dl - v(motion.translations[l]);
            for a in 0..3 {
                j.clear();
                for c in 0..3 {
                    j.push((PER * k + 3 * a + c, dl[c]));
                }
                j.push((PER * k + 9 + a, 1.0));
                j.push((PER * l + 9 + a, -1.0));
                sys.row(&j, e[a], wr);
            }
        }
    }
    // Rigidity rows (Sumner eq. 5): the columns c_0..c_2 of A_k orthonormal,
    // c_a·c_b = 0 (a < b) and c_a·c_a = 1. Linearized exactly, a turn costs nothing.
    let wrot = stiffness * options.rigidity / m as f64;
    for k in 0..m {
        let a = motion.linear[k];
        let col = |c: usize| [a[(0, c)], a[(1, c)], a[(2, c)]];
        for p in 0..3 {
            for q in p..3 {
                let (cp, cq) = (col(p), col(q));
                let r = dot3(cp, cq) - if p == q { 1.0 } else { 0.0 };
                j.clear();
                for x in 0..3 {
                    if p == q {
                        j.push((PER * k + 3 * x + p, 2.0 * cp[x]));
                    } else {
                        j.push((PER * k + 3 * x + p, cq[x]));
                        j.push((PER * k + 3 * x + q, cp[x]));
                    }
                }
                sys.row(&j, r, wrot);
            }
        }
    }
    // Second-order rows: each entry of the linear parts over a node's neighbourhood, less
    // its best linear trend in position. A bend that goes on at the same rate costs
    // nothing, a bend that stops does.
    let w2 = options.second_order / m as f64;
    if w2 > 0.0 {
        for (k, p) in graph.detrend.iter().enumerate() {
            if p.is_empty() {
                continue;
            }
            let ids = graph.neighbourhood(k);
            let q = ids.len();
            for e in 0..9 {
                let (a, c) = (e / 3, e % 3);
                for r in 0..q {
                    j.clear();
                    let mut res = 0.0;
                    for (s, &l) in ids.iter().enumerate() {
                        let coef = p[r * q + s];
                        res += coef * motion.linear[l][(a, c)];
                        j.push((PER * l + e, coef));
                    }
                    sys.row(&j, res, w2);
                }
            }
        }
    }
}
