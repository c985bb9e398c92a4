//! Tracking of a cage by an embedded deformation graph (Sumner, Schmid & Pauly, "Embedded
//! deformation for shape manipulation", SIGGRAPH 2007, §§3–4; used for non-rigid registration
//! by Li, Adams, Guibas & Pauly, "Robust single-view geometry and motion reconstruction",
//! SIGGRAPH Asia 2009, §4): the warm start of each frame of a sequence.
//!
//! **Why.** A fit that starts from the previous frame's cage moves each point along the
//! surface's normal only: closest points say nothing about sliding. Where the frame moved
//! *along* the surface — the flanks of a bend, a twist of an elliptic section, a spin — the cage
//! stays behind, and the tracked points drift a few per cent of the diagonal per frame
//! (`subfit bench sequence`). Here the motion is a smooth field of local affine motions,
//! coupled through space, and what the frame does not show is decided by that field's
//! smoothness.
//!
//! **Model.** `m` nodes with rest positions `g_k` ([`DeformationGraph`]), each with an affine
//! map `A_k` and a translation `t_k`; a point `x` of the rest shape moves to
//! `x' = Σ_k w_k(x) (A_k (x − g_k) + g_k + t_k)` over its `s` nearest nodes,
//! `w_k ∝ (1 − ‖x − g_k‖ / d_{s+1})²` (Sumner eq. 1, 3). With the samples' foot points `y` and
//! target normals `n` on the frame, Gauss-Newton minimizes
//!
//! ```text
//! E = 1/S Σ_samples [ (nᵀ(x' − y))² + β ‖x' − y‖² ]                 (fit, Li et al. eq. 4)
//!   + γ/P Σ_(k,l) ‖A_k (g_l − g_k) + g_k + t_k − (g_l + t_l)‖²        (regularity, Sumner eq. 6)
//!   + ρ/m Σ_k Σ_(a≤b) (c_aᵀc_b − δ_ab)²                              (rigidity, Sumner eq. 5)
//!   + μ/m Σ_k Σ_(entries e) ‖(I − Π_k) a_e‖²                          (second order)
//! ```
//!
//! over the `P` directed pairs of each node and its `K` nearest nodes, `c_a` the columns of
//! `A_k`; the rigidity rows are linearized exactly, so a turn costs nothing to first order (a
//! penalty `‖A_k − R_k‖²` with `R_k` held for the step charges a turn like a shear).
//! The second-order term takes each entry `e` of the linear parts over node `k` and its
//! neighbours (`a_e`, one value a node) less its least-squares linear trend in position
//! (`Π_k`): a bend whose rate goes on across the neighbourhood costs nothing, a bend that stops
//! does — the regularity alone prefers a rigid piece past the last node the data pins down
//! (thin-plate smoothness of the deformation gradient, as in Botsch & Sorkine, "On linear
//! variational surface deformation methods", TVCG 2008, §3, for displacements). 12 unknowns a
//! node; foot points recomputed every iteration; a sample whose foot point is farther than
//! [`TrackOptions::max_distance`] or whose moved normal is more than 60° from the target's is
//! left out (Li et al. §4's pruning). The normal matrix is dense `12m × 12m`, factored by
//! Cholesky each iteration (`m` = 60 in sequences: 720 unknowns).
//!
//! **From the template, nodes inside.** A sequence maps the *template* onto every frame (the
//! motion template → frame, warm-started from the previous frames'), not the previous frame
//! onto the next: what one frame gets wrong along the surface is then not carried into the
//! next, and a body that returns to its rest pose returns its points. The nodes lie inside the
//! body ([`DeformationGraph::interior`], halfway to the shrinking-ball medial points): one node
//! then carries a whole piece of a limb, both sides at once, so a bend, a twist or a change of
//! thickness is one smooth field of affine maps, where nodes on the surface let each side
//! slide on its own (a thickness wave was followed as a slide).
//!
//! **Weights, measured** on `subfit bench sequence --vertices 8000 --control-points 500`
//! (largest drift of the tracked limit points over 30 frames, fraction of the diagonal,
//! default / large tangential motion, geometry only, no ARAP in the fit): surface nodes tracked
//! frame to frame (the previous version, with ARAP) 7.3 % on the default motion; from the
//! template with nodes inside 3.7 % / 4.8 %;
//! with the second-order term μ = 1e-6 and 12 nodes a sample 2.4 % / 3.3 % (μ = 1e-5 3.1 % /
//! 4.0 %, 1e-4 4.2 % / 6.4 %: stiffer, it bends what does not bend); nodes at depth 0.3 /
//! 0.7 / 1 (the medial points) of the way in 3.4 / 4.1 / 5.9 % (default motion, μ = 3e-5);
//! 40 / 90 nodes 4.3 / 3.7 % against 3.6 % for 60; γ = 1e-3 and 3e-5 both worse than 1e-4.
//! Fitted to the true correspondences of the bend alone, the same graph reproduces it to 0.1 %
//! of the diagonal: what is left is the choice among motions the surfaces cannot tell apart
//! (a slide over a rounded end), not the graph's reach.
//!
//! **What the frames determine** (`cargo run --release -p subfit-fit --example
//! drift_identifiability`, frame 8 of the default motion, the strongest bend, 60 nodes):
//! fitted to the true correspondences ([`fit_correspondences`]) the graph is within 0.087 %
//! of the truth and leaves 1.43e-4 point-to-plane RMS; tracking started *there* goes back to
//! the same 2.3 % drift (1.76e-4) as tracking from the template; with all priors a hundred
//! times weaker and a frame four times denser it slides 2.0 % away while fitting the frame
//! *better* than the truth (4.3e-5). With 200 nodes: the truth 6.2e-5, the weak-prior motion
//! 2.3e-5 at 4.0 % drift. Sliding the material over the surface is free as far as the frames
//! go, so the priors decide — and the generated motion is not the one a generic prior
//! prefers: its surface strain (mean squared relative change of edge length, 2.45e-2) is
//! *larger* than the tracked motion's (2.22e-2), so a least-strain (ARAP) prior would turn
//! away from it too. On the bench's sequence (8000 vertices, 500 control points, largest drift
//! over 30 frames, 2.2 % with the defaults) rigidity ×10 / ×100 / ×1000 gave 2.8 / 3.1 /
//! 3.4 %, no rigidity 2.5 %, a symmetric (trapezoidal) regularity without rigidity 2.6 %.
//! Below 1 % would need a prior built for this family of motions (cross-sections carried
//! along an axis, Barr's deformations), not a generic one — or known points: [`Marker`]s (the
//! same example: 12 markers spread over the body 1.3 %, 32 markers 0.7 %).
//!
//! **Cost** per step: `iterations × (S foot points + S·(12s)² + (12m)³/3 flops)`, plus once
//! per graph O(S log S) for the medial points and O(m·K³) for the projectors.

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
    /// Nodes each sample is skinned to (`s`). Default 12.
    pub skin: usize,
    /// Weight `γ` of the regularity term. Default 1e-4 (see the module docs).
    pub regularity: f64,
    /// Weight `ρ` of the rigidity term. Default 1e-6.
    pub rigidity: f64,
    /// Weight `μ` of the second-order term (the linear parts' departure from a linear field
    /// over each neighbourhood). Default 1e-6.
    pub second_order: f64,
    /// Weight `β` of the point-to-point part of the fit. Default 0.
    pub point_weight: f64,
    /// Weight of the markers ([`Marker`]), all together: 1 weighs them like all the samples'
    /// point-to-plane distances. Default 1.
    pub marker_weight: f64,
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
            skin: 12,
            regularity: 1e-4,
            rigidity: 1e-6,
            second_order: 1e-6,
            point_weight: 0.0,
            marker_weight: 1.0,
            max_distance: 0.1,
            stop_rms: 0.0,
        }
    }
}

/// The nodes of an embedded deformation: their rest positions and each node's nearest nodes
/// (fixed at construction).
#[derive(Clone, Debug)]
pub struct DeformationGraph {
    positions: Vec<[f64; 3]>,
    neighbors: Vec<Vec<u32>>,
    /// Per node, the projector `I − Π` (row-major, `q × q` over the node and its neighbours)
    /// that removes a field's best linear trend in position (the second-order term).
    detrend: Vec<Vec<f64>>,
}

impl DeformationGraph {
    /// Picks `count` nodes among `points` by farthest-point sampling (from point 0) and links
    /// each to its `neighbors` nearest nodes. Cost: O(n · count + count²).
    pub fn new(points: &[[f64; 3]], count: usize, neighbors: usize) -> Self {
        let n = points.len();
        let count = count.min(n).max(1.min(n));
        let mut positions = Vec::with_capacity(count);
        let mut d2 = vec![f64::INFINITY; n];
        let mut next = 0usize;
        while positions.len() < count {
            let g = points[next];
            positions.push(g);
            d2.par_iter_mut()
                .zip(points.par_iter())
                .for_each(|(d, &p)| *d = d.min(dist2(p, g)));
            next = (0..n).max_by(|&a, &b| d2[a].total_cmp(&d2[b])).unwrap_or(0);
            if d2[next] == 0.0 {
                break;
            }
        }
        let k = neighbors.min(positions.len().saturating_sub(1));
        let neighbors: Vec<Vec<u32>> = positions
            .par_iter()
            .map(|&a| {
                let mut by: Vec<(f64, u32)> = positions
                    .iter()
                    .enumerate()
                    .map(|(j, &b)| (dist2(a, b), j as u32))
                    .filter(|&(d, _)| d > 0.0)
                    .collect();
                by.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
                by.truncate(k);
                by.into_iter().map(|(_, j)| j).collect()
            })
            .collect();
        let detrend = neighbors
            .iter()
            .enumerate()
            .map(|(k, nb)| detrend(&positions, k, nb))
            .collect();
        Self {
            positions,
            neighbors,
            detrend,
        }
    }

    /// Nodes inside a closed body: [`Self::new`] over the points `depth` of the way from each
    /// sample (unit outward `normals`) to its medial point ([`medial_points`]); `depth` 0 puts
    /// them on the surface. Inner nodes carry a cross-section as one piece (its bend, twist,
    /// change of thickness), where nodes on the surface let each side slide on its own.
    ///
    /// # Panics
    /// If `samples` and `normals` differ in length.
    #[track_caller]
    pub fn interior(
        samples: &[[f64; 3]],
        normals: &[[f64; 3]],
        depth: f64,
        count: usize,
        neighbors: usize,
    ) -> Self {
        assert_eq!(samples.len(), normals.len(), "one normal per sample");
        let inner: Vec<[f64; 3]> = medial_points(samples, normals)
            .iter()
            .zip(samples)
            .map(|(c, p)| std::array::from_fn(|a| p[a] + depth * (c[a] - p[a])))
            .collect();
        Self::new(&inner, count, neighbors)
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// True without nodes.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// The nodes' rest positions.
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.positions
    }

    /// Node `k` and its neighbours, in the order of its second-order projector.
    fn neighbourhood(&self, k: usize) -> Vec<usize> {
        neighbourhood(k, &self.neighbors[k])
    }
}

fn neighbourhood(k: usize, nb: &[u32]) -> Vec<usize> {
    std::iter::once(k)
        .chain(nb.iter().map(|&l| l as usize))
        .collect()
}

/// `I − Π` over node `k` and its neighbours `nb`, `Π` the least-squares projector onto the
/// fields linear in position (`1, x, y, z`), from the thin SVD of that basis over the nodes
/// (directions with a singular value below 1e-6 of the largest are dropped: on a flat
/// neighbourhood the fields linear in its plane); empty with fewer than 5 nodes.
fn detrend(g: &[[f64; 3]], k: usize, nb: &[u32]) -> Vec<f64> {
    let ids = neighbourhood(k, nb);
    let q = ids.len();
    if q < 5 {
        return Vec::new();
    }
    let scale = ids
        .iter()
        .map(|&l| dist2(g[l], g[k]))
        .fold(0.0, f64::max)
        .sqrt()
        .max(1e-300);
    let b = nalgebra::DMatrix::<f64>::from_fn(q, 4, |r, c| {
        if c == 0 {
            1.0
        } else {
            (g[ids[r]][c - 1] - g[k][c - 1]) / scale
        }
    });
    let svd = b.svd(true, false);
    let Some(u) = svd.u else {
        return Vec::new();
    };
    let top = svd.singular_values.max();
    let kept: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&c| svd.singular_values[c] > 1e-6 * top)
        .collect();
    (0..q * q)
        .map(|e| {
            let (r, c) = (e / q, e % q);
            let pi: f64 = kept.iter().map(|&m| u[(r, m)] * u[(c, m)]).sum();
            f64::from(u8::from(r == c)) - pi
        })
        .collect()
}

/// Shrinking-ball medial points (Ma, Bae & Mukherjee, "3D medial axis point approximation
/// using nearest neighbors and the normal field", Visual Computer 2012): for each sample `p`
/// with unit outward normal `n`, the centre `p − r n` of the largest ball touching `p` that
/// holds no other sample, `r` shrunk from half the samples' diagonal by
/// `r = ‖p − q‖² / (2 nᵀ(p − q))` through the nearest sample `q` to the centre until `p` itself
/// is nearest. A sample whose ball never touches another (the open side of a sheet) is its own
/// medial point.
/// Cost: O(n log n) for the kd-tree, then a few nearest-point queries per sample (parallel).
///
/// # Panics
/// If `samples` and `normals` differ in length.
#[track_caller]
pub fn medial_points(samples: &[[f64; 3]], normals: &[[f64; 3]]) -> Vec<[f64; 3]> {
    assert_eq!(samples.len(), normals.len(), "one normal per sample");
    let Some(index) = subfit_target::neighbors::PointIndex::new(samples) else {
        return samples.to_vec();
    };
    let bound =
        subfit_mesh::bounding_box(samples).map_or(0.0, |(lo, hi)| 0.5 * dist2(lo, hi).sqrt());
    (0..samples.len())
        .into_par_iter()
        .map(|i| {
            let (p, n) = (samples[i], normals[i]);
            let mut r = bound;
            let mut touched = false;
            for _ in 0..64 {
                let c = std::array::from_fn(|a| p[a] - r * n[a]);
                let q = index.nearest(&c);
                let j = q.index as usize;
                if j == i || q.distance >= r * (1.0 - 1e-9) {
                    break;
                }
                let d = sub(p, samples[j]);
                let den = 2.0 * dot3(n, d);
                if den <= 0.0 {
                    break;
                }
                let shrunk = dot3(d, d) / den;
                if shrunk >= r {
                    break;
                }
                r = shrunk;
                touched = true;
            }
            if !touched {
                return p;
            }
            std::array::from_fn(|a| p[a] - r * n[a])
        })
        .collect()
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

    /// The motion one step on at constant velocity, from `before` (the previous step's
    /// motion) through this one: each node's `A` and `t` extrapolated linearly (a turn by
    /// `δ` a step is predicted to `O(δ²)`).
    ///
    /// # Panics
    /// If the two have different numbers of nodes.
    #[track_caller]
    pub fn extrapolated(&self, before: &Self) -> Self {
        assert_eq!(self.linear.len(), before.linear.len(), "same nodes");
        Self {
            linear: self
                .linear
                .iter()
                .zip(&before.linear)
                .map(|(a, b)| 2.0 * a - b)
                .collect(),
            translations: self
                .translations
                .iter()
                .zip(&before.translations)
                .map(|(a, b)| std::array::from_fn(|k| 2.0 * a[k] - b[k]))
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
    /// RMS distance of the markers to their positions in the frame (normalized units; 0
    /// without markers), measured with `rms_after`.
    pub marker_rms: f64,
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

impl Skin {
    /// The gradient of `dirᵀx'` for point `i` at rest position `x` (sparse, into `j`):
    /// `δx' = Σ_k w_k (δA_k (x − g_k) + δt_k)`.
    fn jacobian(
        &self,
        j: &mut Vec<(usize, f64)>,
        i: usize,
        x: [f64; 3],
        g: &[[f64; 3]],
        dir: [f64; 3],
    ) {
        j.clear();
        let (ids, w) = self.row(i);
        for (&k, &wk) in ids.iter().zip(w) {
            if wk == 0.0 {
                continue;
            }
            let k = k as usize;
            let d = sub(x, g[k]);
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

    /// Solves the system with a little Levenberg damping (1e-6 of the mean diagonal, which
    /// keeps unobserved nodes put) and adds the step to `motion`; false when the factorization
    /// fails.
    fn solve_into(&self, motion: &mut NodeMotion) -> bool {
        let nn = self.n;
        let trace: f64 = (0..nn).map(|i| self.h[i * nn + i]).sum::<f64>() / nn as f64;
        let h = Mat::<f64>::from_fn(nn, nn, |a, c| {
            self.h[a * nn + c] + if a == c { 1e-6 * trace.max(1e-30) } else { 0.0 }
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

/// Points of the rest surface that [`track`] brings onto the frame, with their unit normals.
#[derive(Clone, Copy, Debug)]
pub struct Samples<'a> {
    /// Positions in the graph's rest configuration.
    pub positions: &'a [[f64; 3]],
    /// Unit outward normals, one per position.
    pub normals: &'a [[f64; 3]],
}

/// A point whose place in the frame is known (a motion-capture marker, a tracked texture
/// feature): where it is on the rest shape and where it is in this frame. [`track`] pulls it
/// there point to point, which pins what the surfaces alone leave free — sliding along them
/// (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Marker {
    /// Position in the graph's rest configuration.
    pub rest: [f64; 3],
    /// Position in the frame.
    pub position: [f64; 3],
}

/// Moves `cage` (control points in the graph's rest configuration, normalized units: in a
/// sequence the template's) onto `target` (the frame): an embedded deformation of the graph's
/// rest positions fitted to bring `samples` (points of the rest limit surface, with unit
/// `normals`) onto the target; returns the moved cage, the node motion (the warm start of the
/// next frame) and figures. `markers`: points whose place in the frame is known (may be
/// empty). `initial`: the motion to start from (e.g. the previous frame's,
/// [`NodeMotion::extrapolated`]); `None` starts from rest.
///
/// # Panics
/// If the samples' positions and normals differ in length.
#[track_caller]
pub fn track(
    graph: &DeformationGraph,
    cage: &[[f64; 3]],
    samples: Samples<'_>,
    target: &Target,
    markers: &[Marker],
    initial: Option<&NodeMotion>,
    options: &TrackOptions,
) -> (Vec<[f64; 3]>, NodeMotion, TrackStats) {
    let Samples {
        positions: samples,
        normals,
    } = samples;
    assert_eq!(samples.len(), normals.len(), "one normal per sample");
    let m = graph.len();
    let g = &graph.positions;
    let mut motion = initial
        .filter(|x| x.linear.len() == m)
        .cloned()
        .unwrap_or_else(|| NodeMotion::identity(m));
    let mut stats = TrackStats::default();
    if m == 0 || samples.is_empty() {
        return (cage.to_vec(), motion, stats);
    }
    let skin = Skin::new(samples, g, options.skin);
    let marker_rest: Vec<[f64; 3]> = markers.iter().map(|k| k.rest).collect();
    let marker_skin = Skin::new(&marker_rest, g, options.skin);
    let pairs: usize = graph.neighbors.iter().map(Vec::len).sum();
    for it in 0..options.iterations {
        let moved: Vec<[f64; 3]> = (0..samples.len())
            .into_par_iter()
            .map(|i| skin.apply(i, samples[i], g, &motion))
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
        stats.marker_rms = marker_rms(&marker_skin, markers, g, &motion);
        if matches.is_empty() || (rms <= options.stop_rms && stats.marker_rms <= options.stop_rms) {
            break;
        }
        let mut sys = Normal::new(PER * m);
        let wf = 1.0 / matches.len() as f64;
        let beta = options.point_weight;
        let mut j: Vec<(usize, f64)> = Vec::with_capacity(PER * options.skin);
        // Fit rows: δx'_i = Σ_k w_k (Σ_c d_c δA_k[i][c] + δt_k[i]), d = x − g_k.
        for &(i, y, n) in &matches {
            let r = sub(moved[i], y);
            skin.jacobian(&mut j, i, samples[i], g, n);
            sys.row(&j, dot3(n, r), wf);
            if beta > 0.0 {
                for a in 0..3 {
                    let mut e = [0.0; 3];
                    e[a] = 1.0;
                    skin.jacobian(&mut j, i, samples[i], g, e);
                    sys.row(&j, r[a], wf * beta);
                }
            }
        }
        // Marker rows: x'_m − p_m, point to point.
        let wm = options.marker_weight / markers.len().max(1) as f64;
        for (i, mk) in markers.iter().enumerate() {
            let r = sub(marker_skin.apply(i, mk.rest, g, &motion), mk.position);
            for a in 0..3 {
                let mut e = [0.0; 3];
                e[a] = 1.0;
                marker_skin.jacobian(&mut j, i, mk.rest, g, e);
                sys.row(&j, r[a], wm);
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
        if !sys.solve_into(&mut motion) {
            break;
        }
        stats.iterations = it + 1;
    }
    (deform(graph, cage, &motion, options.skin), motion, stats)
}

/// `points` (in the graph's rest configuration) moved by `motion`, each skinned to its `skin`
/// nearest nodes as in [`track`]. Cost: O(#points · m).
pub fn deform(
    graph: &DeformationGraph,
    points: &[[f64; 3]],
    motion: &NodeMotion,
    skin: usize,
) -> Vec<[f64; 3]> {
    if graph.is_empty() || motion.linear.len() != graph.len() {
        return points.to_vec();
    }
    let sk = Skin::new(points, &graph.positions, skin);
    (0..points.len())
        .into_par_iter()
        .map(|i| sk.apply(i, points[i], &graph.positions, motion))
        .collect()
}

/// The motion of `graph` that carries `points` (rest positions) closest to `targets` in the
/// least-squares sense, each point skinned to its `skin` nearest nodes: known
/// correspondences (markers, or a generator's ground truth), no smoothness term, only
/// [`track`]'s slight damping. It is what the graph can represent at best, the reference a
/// tracker's drift is measured against (`examples/drift_identifiability.rs`). One linear
/// solve: O(#points · (12 skin)² + (12 m)³).
///
/// # Panics
/// If `points` and `targets` differ in length.
#[track_caller]
pub fn fit_correspondences(
    graph: &DeformationGraph,
    points: &[[f64; 3]],
    targets: &[[f64; 3]],
    skin: usize,
) -> NodeMotion {
    assert_eq!(points.len(), targets.len(), "one target per point");
    let m = graph.len();
    let mut motion = NodeMotion::identity(m);
    if m == 0 || points.is_empty() {
        return motion;
    }
    let g = &graph.positions;
    let sk = Skin::new(points, g, skin);
    let mut sys = Normal::new(PER * m);
    let w = 1.0 / points.len() as f64;
    let mut j = Vec::with_capacity(PER * skin);
    for (i, (&x, &y)) in points.iter().zip(targets).enumerate() {
        // At rest x' = x: the residual is x − y, the problem linear.
        for a in 0..3 {
            let mut e = [0.0; 3];
            e[a] = 1.0;
            sk.jacobian(&mut j, i, x, g, e);
            sys.row(&j, x[a] - y[a], w);
        }
    }
    sys.solve_into(&mut motion);
    motion
}

/// The RMS distance of the moved markers to their positions in the frame (0 without markers).
fn marker_rms(skin: &Skin, markers: &[Marker], g: &[[f64; 3]], motion: &NodeMotion) -> f64 {
    if markers.is_empty() {
        return 0.0;
    }
    let sum: f64 = markers
        .iter()
        .enumerate()
        .map(|(i, mk)| dist2(skin.apply(i, mk.rest, g, motion), mk.position))
        .sum();
    (sum / markers.len() as f64).sqrt()
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

#[cfg(test)]
mod tests;
