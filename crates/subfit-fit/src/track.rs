//! Frame-to-frame tracking of a cage by an embedded deformation graph (Sumner, Schmid & Pauly,
//! "Embedded deformation for shape manipulation", SIGGRAPH 2007, §§3–4; used for non-rigid
//! registration by Li, Adams, Guibas & Pauly, "Robust single-view geometry and motion
//! reconstruction", SIGGRAPH Asia 2009, §4): the warm start of a sequence's next frame.
//!
//! **Why.** A fit that starts from the previous frame's cage moves each point along the
//! surface's normal only: closest points say nothing about sliding. Where the new frame moved
//! *along* the surface — the flanks of a bend, a twist of an elliptic section, a spin — the cage
//! stays behind, and the tracked points drift a few per cent of the diagonal per frame
//! (`subfit bench sequence`). An ARAP term on the cage itself cannot carry the motion across:
//! its pairs are the cage's edges, a thin shell, and a shell follows a sideways motion only
//! through second-order strains. Here the motion is a smooth field of local rigid motions,
//! coupled through space: nodes on the far side of a limb move with the near side.
//!
//! **Model.** `m` nodes `g_k` (control vertices picked by farthest-point sampling of the
//! template, [`DeformationGraph::new`]), each with an affine map `A_k` and a translation `t_k`;
//! a point `x` moves to `x' = Σ_k w_k(x) (A_k (x − g_k) + g_k + t_k)` over its `s` nearest nodes,
//! `w_k ∝ (1 − ‖x − g_k‖ / d_{s+1})²` (Sumner eq. 1, 3). With the samples' foot points `y` and
//! target normals `n` on the new frame, Gauss-Newton minimizes
//!
//! ```text
//! E = 1/S Σ_samples [ (nᵀ(x' − y))² + β ‖x' − y‖² ]                 (fit, Li et al. eq. 4)
//!   + γ/P Σ_(k,l) ‖A_k (g_l − g_k) + g_k + t_k − (g_l + t_l)‖²        (regularity, Sumner eq. 6)
//!   + ρ/m Σ_k Σ_(a≤b) (c_aᵀc_b − δ_ab)²                              (rigidity, Sumner eq. 5)
//! ```
//!
//! over the `P` directed pairs of each node and its `K` nearest nodes, `c_a` the columns of
//! `A_k`; the rigidity rows are linearized exactly, so a turn costs nothing to first order (a
//! penalty `‖A_k − R_k‖²` with `R_k` held for the step charges a turn like a shear: a rigid
//! turn of the body by 0.15 rad was then followed only in part, 0.040 → 0.025 from the true
//! motion, against 4.4e-4 now, `tests/track.rs`). 12 unknowns a node; foot points
//! recomputed every iteration; a sample whose foot point is farther than
//! [`TrackOptions::max_distance`] or whose moved normal is more than 60° from the target's is
//! left out (Li et al. §4's pruning). The normal matrix is dense `12m × 12m`, factored by
//! Cholesky each iteration (`m` = 30 by default in sequences: 360 unknowns).
//!
//! **Weights, measured** (`subfit bench sequence`'s generated body, 8,000-vertex frames,
//! frame 0 → 1, whose true motion is 2.08 % of the diagonal RMS; drift left after one step
//! from rest, RMS): the regularity penalizes bending at the node spacing (`κ h²`) and the
//! rigidity the frame's change of thickness (4 % per frame), so stiff weights cannot fit the
//! frame (γ = 100, ρ = 1e-3: 1.7 % left, plane residual stuck at 4e-3). With 30 nodes and ρ =
//! 1e-4: γ = 0.1 leaves 1.18 %, 0.01 0.93 %, 1e-3 0.67 %, **1e-4 0.40 %**, 1e-5 0.49 % (the
//! middle of the body starts to slide); 15 nodes 1.18 %, 45–60 nodes 0.51–0.76 %. β > 0 pulls
//! each point to its closest point, i.e. against sliding. Stiffness annealing as in Li et
//! al. (half the iterations with γ and ρ 100–10,000 times higher, then the given weights with
//! each sample held along the surface where the stiff phase put it) made it worse, 1.44–1.69 %:
//! the stiff solution is wrong where the body bends. From rest to frame 3 (5.7 % of motion):
//! 1.5 % left. The rest of the motion along the surface is not observable by a local tracker
//! on this smooth body (most of it at the rounded ends), and it accumulates over a sequence
//! (see `subfit::sequence`). A rigid turn is followed to 1.1 % of itself (`tests/track.rs`).
//!
//! Over a sequence the one-step optimum is not the best: softer ties also let the cage slide
//! where the frame shows nothing to follow. Largest drift over 30 frames (`subfit bench
//! sequence --vertices 8000 --control-points 500`, moderate motion / the same body held
//! still): γ = 1e-4 9.50 % / 1.30 %, **1e-3 7.89 % / 0.58 %**, 0.01 10.46 % / 0.14 %, 1 13.2 %
//! / 0.04 %, against 0.023 % for the still body without tracking. What is left on a still
//! body is removed by [`TrackOptions::stop_rms`]: no iteration once the residual is what the
//! data's noise and tessellation leave anyway. A least-motion term towards the rest or the
//! predicted position (full or tangential) stopped the slide but also the twist and bend
//! (14.6 % moderate) and was not kept.
//!
//! **Cost** per step: `iterations × (S foot points + S·(12s)² + (12m)³/3 flops)`.

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use subfit_mesh::vec3::{dist2, dot as dot3, sub};
use subfit_target::Target;

/// Options of [`track`].
#[derive(Clone, Debug, PartialEq)]
pub struct TrackOptions {
    /// Gauss-Newton iterations. Default 20.
    pub iterations: usize,
    /// Nodes each sample is skinned to (`s`). Default 4.
    pub skin: usize,
    /// Weight `γ` of the regularity term. Default 1e-3 (see the module docs).
    pub regularity: f64,
    /// Weight `ρ` of the rigidity term. Default 1e-4.
    pub rigidity: f64,
    /// Weight `β` of the point-to-point part of the fit. Default 0.
    pub point_weight: f64,
    /// Samples whose foot point is farther than this (normalized units) are left out.
    /// Default 0.1.
    pub max_distance: f64,
    /// The iterations stop once the RMS point-to-plane distance is at or below this
    /// (normalized units; Morozov's discrepancy principle): what the data's own noise explains
    /// is not fitted with motion. Default 0 (never).
    pub stop_rms: f64,
}

impl Default for TrackOptions {
    fn default() -> Self {
        Self {
            iterations: 20,
            skin: 4,
            regularity: 1e-3,
            rigidity: 1e-4,
            point_weight: 0.0,
            max_distance: 0.1,
            stop_rms: 0.0,
        }
    }
}

/// The nodes of an embedded deformation: control-vertex indices and each node's nearest nodes
/// (fixed at construction, from the template's positions).
#[derive(Clone, Debug)]
pub struct DeformationGraph {
    nodes: Vec<u32>,
    neighbors: Vec<Vec<u32>>,
}

impl DeformationGraph {
    /// Picks `count` nodes among `template`'s points by farthest-point sampling (from point 0)
    /// and links each to its `neighbors` nearest nodes. Cost: O(n · count + count²).
    pub fn new(template: &[[f64; 3]], count: usize, neighbors: usize) -> Self {
        let n = template.len();
        let count = count.min(n).max(1.min(n));
        let mut nodes = Vec::with_capacity(count);
        let mut d2 = vec![f64::INFINITY; n];
        let mut next = 0usize;
        while nodes.len() < count {
            nodes.push(next as u32);
            let g = template[next];
            d2.par_iter_mut()
                .zip(template.par_iter())
                .for_each(|(d, &p)| *d = d.min(dist2(p, g)));
            next = (0..n).max_by(|&a, &b| d2[a].total_cmp(&d2[b])).unwrap_or(0);
            if d2[next] == 0.0 {
                break;
            }
        }
        let k = neighbors.min(nodes.len().saturating_sub(1));
        let neighbors = nodes
            .par_iter()
            .map(|&a| {
                let mut by: Vec<(f64, u32)> = nodes
                    .iter()
                    .enumerate()
                    .filter(|&(_, &b)| b != a)
                    .map(|(j, &b)| (dist2(template[a as usize], template[b as usize]), j as u32))
                    .collect();
                by.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
                by.truncate(k);
                by.into_iter().map(|(_, j)| j).collect()
            })
            .collect();
        Self { nodes, neighbors }
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// True without nodes.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }
}

/// Per-node affine motions of one tracking step: `x ↦ A_k (x − g_k) + g_k + t_k`.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeMotion {
    /// `A_k`.
    pub linear: Vec<Matrix3<f64>>,
    /// `t_k`.
    pub translations: Vec<[f64; 3]>,
}

impl NodeMotion {
    /// The identity motion of `m` nodes.
    pub fn identity(m: usize) -> Self {
        Self {
            linear: vec![Matrix3::identity(); m],
            translations: vec![[0.0; 3]; m],
        }
    }

    /// The same motion once more, from where this one ended (constant velocity): a node that
    /// moved by `(A, t)` moves by `(A, A t)` — exact for a steady spin about a fixed axis.
    pub fn repeated(&self) -> Self {
        Self {
            linear: self.linear.clone(),
            translations: self
                .linear
                .iter()
                .zip(&self.translations)
                .map(|(a, &t)| {
                    let x = a * v(t);
                    [x.x, x.y, x.z]
                })
                .collect(),
        }
    }
}

/// What one tracking step measured.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrackStats {
    /// Samples with a foot point at the end.
    pub matched: usize,
    /// RMS point-to-plane distance of those (normalized units) before and after.
    pub rms_before: f64,
    /// After.
    pub rms_after: f64,
    /// Gauss-Newton iterations run.
    pub iterations: usize,
}

struct Skin {
    nodes: Vec<u32>,
    weights: Vec<f64>,
    per: usize,
}

impl Skin {
    fn new(points: &[[f64; 3]], g: &[[f64; 3]], s: usize) -> Self {
        let per = s.min(g.len()).max(1);
        let rows: Vec<(Vec<u32>, Vec<f64>)> = points
            .par_iter()
            .map(|&x| {
                let mut by: Vec<(f64, u32)> = g
                    .iter()
                    .enumerate()
                    .map(|(k, &gk)| (dist2(x, gk), k as u32))
                    .collect();
                let take = (per + 1).min(by.len());
                by.select_nth_unstable_by(take - 1, |a, b| a.0.total_cmp(&b.0));
                by.truncate(take);
                by.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
                let dmax = by.last().map_or(1.0, |e| e.0.sqrt()).max(1e-12);
                let used = per.min(by.len());
                let mut w: Vec<f64> = by[..used]
                    .iter()
                    .map(|e| (1.0 - e.0.sqrt() / dmax).max(0.0).powi(2))
                    .collect();
                let sum: f64 = w.iter().sum();
                if sum > 0.0 {
                    w.iter_mut().for_each(|v| *v /= sum);
                } else {
                    w.iter_mut().for_each(|v| *v = 1.0 / used as f64);
                }
                let mut ids: Vec<u32> = by[..used].iter().map(|e| e.1).collect();
                while ids.len() < per {
                    ids.push(ids[0]);
                    w.push(0.0);
                }
                (ids, w)
            })
            .collect();
        let mut nodes = Vec::with_capacity(points.len() * per);
        let mut weights = Vec::with_capacity(points.len() * per);
        for (i, w) in rows {
            nodes.extend(i);
            weights.extend(w);
        }
        Self {
            nodes,
            weights,
            per,
        }
    }

    fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let r = i * self.per..(i + 1) * self.per;
        (&self.nodes[r.clone()], &self.weights[r])
    }

    fn apply(&self, i: usize, x: [f64; 3], g: &[[f64; 3]], m: &NodeMotion) -> [f64; 3] {
        let (ids, w) = self.row(i);
        let mut out = Vector3::zeros();
        for (&k, &wk) in ids.iter().zip(w) {
            let k = k as usize;
            let gk = v(g[k]);
            out += wk * (m.linear[k] * (v(x) - gk) + gk + v(m.translations[k]));
        }
        [out.x, out.y, out.z]
    }

    /// The moved normal (cofactor of the blended linear part), unit.
    fn normal(&self, i: usize, n: [f64; 3], m: &NodeMotion) -> [f64; 3] {
        let (ids, w) = self.row(i);
        let mut a = Matrix3::zeros();
        for (&k, &wk) in ids.iter().zip(w) {
            a += wk * m.linear[k as usize];
        }
        let c = a.try_inverse().map_or(a, |inv| inv.transpose());
        let out = c * v(n);
        let l = out.norm();
        if l > 0.0 {
            [out.x / l, out.y / l, out.z / l]
        } else {
            n
        }
    }
}

/// Unknowns per node: `A` row-major (9), then `t` (3).
const PER: usize = 12;

/// A dense symmetric normal system `H x = b` over `12 m` unknowns.
struct Normal {
    n: usize,
    h: Vec<f64>,
    b: Vec<f64>,
}

impl Normal {
    fn new(n: usize) -> Self {
        Self {
            n,
            h: vec![0.0; n * n],
            b: vec![0.0; n],
        }
    }

    /// Adds `w (jᵀj, −jᵀr)` for one residual row `r` with sparse gradient `j`.
    fn row(&mut self, j: &[(usize, f64)], r: f64, w: f64) {
        for &(a, va) in j {
            self.b[a] -= w * va * r;
            let base = a * self.n;
            for &(c, vc) in j {
                self.h[base + c] += w * va * vc;
            }
        }
    }
}

/// Moves `cage` (the previous frame's control points, normalized units) onto `target` (the new
/// frame): an embedded deformation fitted to bring `samples` (points of the previous frame's
/// limit surface, with unit `normals`) onto the target; returns the moved cage, the node
/// motion (to predict the next frame) and figures. `initial`: the motion to start from (e.g.
/// a constant-velocity prediction, [`NodeMotion::repeated`]); `None` starts from rest.
///
/// # Panics
/// If `samples` and `normals` differ in length, or the graph's nodes are not among `cage`.
#[track_caller]
pub fn track(
    graph: &DeformationGraph,
    cage: &[[f64; 3]],
    samples: &[[f64; 3]],
    normals: &[[f64; 3]],
    target: &Target,
    initial: Option<&NodeMotion>,
    options: &TrackOptions,
) -> (Vec<[f64; 3]>, NodeMotion, TrackStats) {
    assert_eq!(samples.len(), normals.len(), "one normal per sample");
    let m = graph.len();
    let g: Vec<[f64; 3]> = graph.nodes.iter().map(|&i| cage[i as usize]).collect();
    let mut motion = initial
        .filter(|x| x.linear.len() == m)
        .cloned()
        .unwrap_or_else(|| NodeMotion::identity(m));
    let mut stats = TrackStats::default();
    if m == 0 || samples.is_empty() {
        return (cage.to_vec(), motion, stats);
    }
    let skin = Skin::new(samples, &g, options.skin);
    let pairs: usize = graph.neighbors.iter().map(Vec::len).sum();
    for it in 0..options.iterations {
        let moved: Vec<[f64; 3]> = (0..samples.len())
            .into_par_iter()
            .map(|i| skin.apply(i, samples[i], &g, &motion))
            .collect();
        let moved_normals: Vec<[f64; 3]> = (0..samples.len())
            .into_par_iter()
            .map(|i| skin.normal(i, normals[i], &motion))
            .collect();
        let matches = matches(&moved, &moved_normals, target, options.max_distance);
        let rms = plane_rms(&moved, &matches);
        if it == 0 {
            stats.rms_before = rms;
        }
        stats.matched = matches.len();
        stats.rms_after = rms;
        if matches.is_empty() || rms <= options.stop_rms {
            break;
        }
        let mut sys = Normal::new(PER * m);
        let wf = 1.0 / matches.len() as f64;
        let beta = options.point_weight;
        let mut j: Vec<(usize, f64)> = Vec::with_capacity(PER * options.skin);
        // Fit rows: δx'_i = Σ_k w_k (Σ_c d_c δA_k[i][c] + δt_k[i]), d = x − g_k.
        for &(i, y, n) in &matches {
            let (ids, w) = skin.row(i);
            let r = sub(moved[i], y);
            let row = |j: &mut Vec<(usize, f64)>, dir: [f64; 3]| {
                j.clear();
                for (&k, &wk) in ids.iter().zip(w) {
                    if wk == 0.0 {
                        continue;
                    }
                    let k = k as usize;
                    let d = sub(samples[i], g[k]);
                    for (a, &da) in dir.iter().enumerate() {
                        if da == 0.0 {
                            continue;
                        }
                        for (c, &dc) in d.iter().enumerate() {
                            j.push((PER * k + 3 * a + c, wk * da * dc));
                        }
                        j.push((PER * k + 9 + a, wk * da));
                    }
                }
            };
            row(&mut j, n);
            sys.row(&j, dot3(n, r), wf);
            if beta > 0.0 {
                for a in 0..3 {
                    let mut e = [0.0; 3];
                    e[a] = 1.0;
                    row(&mut j, e);
                    sys.row(&j, r[a], wf * beta);
                }
            }
        }
        // Regularity rows: e = A_k (g_l − g_k) + g_k + t_k − g_l − t_l.
        let wr = options.regularity / pairs.max(1) as f64;
        for (k, nb) in graph.neighbors.iter().enumerate() {
            for &l in nb {
                let l = l as usize;
                let dl = v(sub(g[l], g[k]));
                let e = motion.linear[k] * dl + v(motion.translations[k])
                    - dl
                    - v(motion.translations[l]);
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
        let wrot = options.rigidity / m as f64;
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
        // A little Levenberg damping keeps unobserved nodes put.
        let nn = sys.n;
        let trace: f64 = (0..nn).map(|i| sys.h[i * nn + i]).sum::<f64>() / nn as f64;
        let h = Mat::<f64>::from_fn(nn, nn, |a, c| {
            sys.h[a * nn + c] + if a == c { 1e-6 * trace.max(1e-30) } else { 0.0 }
        });
        let rhs = Mat::<f64>::from_fn(nn, 1, |a, _| sys.b[a]);
        let Ok(llt) = h.llt(Side::Lower) else {
            break;
        };
        let x = llt.solve(&rhs);
        for k in 0..m {
            for a in 0..3 {
                for c in 0..3 {
                    motion.linear[k][(a, c)] += x[(PER * k + 3 * a + c, 0)];
                }
                motion.translations[k][a] += x[(PER * k + 9 + a, 0)];
            }
        }
        stats.iterations = it + 1;
    }
    let cage_skin = Skin::new(cage, &g, options.skin);
    let moved_cage = (0..cage.len())
        .into_par_iter()
        .map(|i| cage_skin.apply(i, cage[i], &g, &motion))
        .collect();
    (moved_cage, motion, stats)
}

/// The RMS point-to-plane distance of `samples` (unit `normals`) to `target`, over the samples
/// that [`track`] would match (foot point within `max_distance`, normals within 60°), and
/// their number: the floor a tracking step cannot go below on a frame the cage already fits
/// (the data's noise and tessellation; see [`TrackOptions::stop_rms`]).
///
/// # Panics
/// If `samples` and `normals` differ in length.
#[track_caller]
pub fn plane_rms_to(
    samples: &[[f64; 3]],
    normals: &[[f64; 3]],
    target: &Target,
    max_distance: f64,
) -> (f64, usize) {
    assert_eq!(samples.len(), normals.len(), "one normal per sample");
    let m = matches(samples, normals, target, max_distance);
    (plane_rms(samples, &m), m.len())
}

/// The samples with a usable foot point on `target`: (sample, foot point, target normal).
/// Pruned as in Li et al. §4: foot points farther than `max_distance`, or whose normal is
/// more than 60° from the sample's.
fn matches(
    samples: &[[f64; 3]],
    normals: &[[f64; 3]],
    target: &Target,
    max_distance: f64,
) -> Vec<(usize, [f64; 3], [f64; 3])> {
    let feet = target.foot_points(samples);
    (0..samples.len())
        .into_par_iter()
        .filter_map(|i| {
            let f = &feet[i];
            if !f.distance.is_finite() || f.distance.abs() > max_distance {
                return None;
            }
            (dot3(normals[i], f.normal) >= 0.5).then_some((i, f.point, f.normal))
        })
        .collect()
}

/// RMS of `nᵀ(x − y)` over `matches`.
fn plane_rms(samples: &[[f64; 3]], matches: &[(usize, [f64; 3], [f64; 3])]) -> f64 {
    (matches
        .iter()
        .map(|&(i, y, n)| dot3(n, sub(samples[i], y)).powi(2))
        .sum::<f64>()
        / matches.len().max(1) as f64)
        .sqrt()
}

fn v(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}
