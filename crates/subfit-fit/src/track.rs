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
//! **Large motion between frames** (a capture at a low frame rate, fast limbs): the graph is
//! laid over the surface ([`DeformationGraph::on_surface`], [`geodesic`]: node neighbours and
//! skinning by distance over the surface, so an arm beside the body or two legs side by side
//! are not tied together), each frame's points also pull the model (data → model
//! correspondences), and the step anneals from stiff with a long correspondence radius to
//! its own weights ([`backward`]; [`TrackOptions::stiffness_start`]). On the dancing figure of
//! `subfit bench sequence --motion dance --stride 5 --points 40000` (30 frames of 40k points
//! without normals, the hands moving up to about 15 % of the diagonal between frames) the
//! tracking through space lost the figure at frame 1 (two-sided RMS 0.7–1.4 % of the
//! diagonal, drift 3–6 % RMS); laid over the surface with both directions and the annealing
//! every frame is within 0.036 % two-sided, drift RMS ≤ 0.80 % and 95th percentile ≤ 1.65 %.
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

use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use subfit_mesh::vec3::{dist2, dot as dot3, sub};
use subfit_target::Target;

/// Options of [`track`].
#[derive(Clone, Debug, PartialEq)]
pub struct TrackOptions {
    /// Gauss-Newton iterations. Default 20.
    pub iterations: usize,
    /// Nodes each sample is skinned to (`s`). Default 6 (with a graph laid over the surface,
    /// [`DeformationGraph::on_surface`]; 12 with one through space smoothed a limb's motion
    /// into the body it hangs beside; 4, Sumner et al.'s, left a hand 1.4 % of the diagonal off
    /// in one frame of the dance).
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
    /// Weight of the data → model correspondences, all together against the model → data
    /// ones (1 weighs both sides alike; 0 turns them off): each of up to
    /// [`Self::backward_points`] frame points pulls the nearest moved sample whose normal
    /// agrees along the frame's normal. Where a limb moved farther than its own width, the
    /// model's samples find nothing of it nearby, but its points still find the model's limb
    /// (symmetric ICP; see [`backward`]). Used in the stiff levels of the annealing only
    /// ([`Self::stiffness_start`]). Default 1.
    pub backward_weight: f64,
    /// Frame points used by the data → model correspondences at most (an even subsample).
    /// Default 3000.
    pub backward_points: usize,
    /// Stiffness annealing (Amberg, Romdhani & Vetter, "Optimal step nonrigid ICP
    /// algorithms for surface registration", CVPR 2007, §3.2): the step starts with the
    /// regularity and rigidity weights times this and divides them by 10 every
    /// [`Self::level_iterations`] iterations down to ×1, the correspondence radius going from
    /// [`Self::reach_start`] down to [`Self::max_distance`] alike: the graph first moves piece
    /// by piece nearly rigidly onto the far-moved frame, then bends into its details. 1 turns
    /// the annealing off. Default 100.
    pub stiffness_start: f64,
    /// Iterations per stiffness level before the last (which gets the rest). Default 4.
    pub level_iterations: usize,
    /// Correspondence radius at the stiffest level (normalized units). Default 0.3.
    pub reach_start: f64,
    /// Robust weights of the last stiffness level's correspondences (iteratively reweighted
    /// least squares with Cauchy weights `1 / (1 + (e / c)²)`, Holland & Welsch, "Robust
    /// regression using iteratively reweighted least-squares", Comm. Statistics 1977), the
    /// scale `c` this multiple of the iteration's RMS point-to-plane distance; 0 turns them
    /// off. What the graph cannot explain — a part the template's cage does not reach, two
    /// parts that touched in the template's frame and come apart — then stops pulling the
    /// material around it along the surface. Default 1: on the first 12 frames of the
    /// corpus's low-poly cat (`subfit bench sequence --meshes`, 1,500 control points, no
    /// silhouette) drift RMS 1.83 % and p95 3.35 % instead of 2.50 % and 5.18 %, worst
    /// two-sided RMS 0.148 % instead of 0.162 %; on the dance of the module docs drift RMS
    /// 0.72 %, p95 1.50 % instead of 0.73 % and 1.56 % (scale 2: the cat 1.81 % / 3.83 %).
    pub robust: f64,
}

impl Default for TrackOptions {
    fn default() -> Self {
        Self {
            iterations: 20,
            skin: 6,
            regularity: 1e-4,
            rigidity: 1e-6,
            second_order: 1e-6,
            point_weight: 0.0,
            marker_weight: 1.0,
            max_distance: 0.1,
            stop_rms: 0.0,
            backward_weight: 1.0,
            backward_points: 3000,
            stiffness_start: 100.0,
            level_iterations: 4,
            reach_start: 0.3,
            robust: 1.0,
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
    /// The skinning of the surface samples the graph was laid over, by surface distance
    /// ([`Self::on_surface`]); `None` for a graph through space.
    surface: Option<SurfaceSkin>,
}

/// The samples a graph was laid over, their skinning rows and an index to find the nearest.
#[derive(Clone, Debug)]
struct SurfaceSkin {
    rest: Vec<[f64; 3]>,
    skin: Skin,
}

impl DeformationGraph {
    /// Picks `count` nodes among `points` by farthest-point sampling (from point 0) and links
    /// each to its `neighbors` nearest nodes. Cost: O(n · count + count²).
    pub fn new(points: &[[f64; 3]], count: usize, neighbors: usize) -> Self {
        let positions: Vec<[f64; 3]> = farthest_points(points, count)
            .into_iter()
            .map(|i| points[i])
            .collect();
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
        Self::with_links(positions, neighbors, None)
    }

    fn with_links(
        positions: Vec<[f64; 3]>,
        neighbors: Vec<Vec<u32>>,
        surface: Option<SurfaceSkin>,
    ) -> Self {
        let detrend = neighbors
            .iter()
            .enumerate()
            .map(|(k, nb)| detrend(&positions, k, nb))
            .collect();
        Self {
            positions,
            neighbors,
            detrend,
            surface,
        }
    }

    /// Nodes inside a closed body laid out along its surface ([`geodesic`]): as
    /// [`Self::interior`] (`depth` of the way to the medial points, `count` nodes by
    /// farthest-point sampling), but each node's `neighbors` and each sample's `skin` nearest
    /// nodes are found by distance over the surface mesh `faces` (over the samples, e.g. the
    /// limit mesh they are the vertices of) from the sample each node was placed from (a
    /// variant that took the nearest in space among the nodes not much farther round than
    /// through — a cross-section as one piece — tracked the dance worse: drift RMS 1.10 %
    /// against 0.78 %, and the generated tube's spin no better). Points
    /// other than the samples ([`deform`], markers) take the skinning of their nearest sample.
    /// Cost: [`Self::interior`] plus one Dijkstra per node over the samples.
    ///
    /// # Panics
    /// If `samples` and `normals` differ in length.
    #[track_caller]
    pub fn on_surface(
        samples: &[[f64; 3]],
        normals: &[[f64; 3]],
        faces: &subfit_mesh::Polygons,
        depth: f64,
        (count, neighbors, skin): (usize, usize, usize),
    ) -> Self {
        assert_eq!(samples.len(), normals.len(), "one normal per sample");
        let inner = inner_points(samples, normals, depth);
        let anchors = farthest_points(&inner, count);
        let positions: Vec<[f64; 3]> = anchors.iter().map(|&i| inner[i]).collect();
        let dist = geodesic::distances_from(samples, faces, &anchors);
        let links = geodesic::neighbours(&dist, &anchors, neighbors);
        let (nodes, weights) = geodesic::skin_rows(&dist, samples, &positions, skin);
        let per = skin.min(positions.len()).max(1);
        let surface = SurfaceSkin {
            rest: samples.to_vec(),
            skin: Skin {
                nodes,
                weights,
                per,
            },
        };
        Self::with_links(positions, links, Some(surface))
    }

    /// The skinning of `points` (rest positions) over `s` nodes: the surface samples' own
    /// rows when `points` are those samples, the nearest sample's rows for other points of a
    /// graph laid over a surface, the nearest nodes in space otherwise.
    fn skin_of(&self, points: &[[f64; 3]], s: usize) -> Skin {
        match &self.surface {
            Some(sf) if sf.rest.as_slice() == points => sf.skin.clone(),
            Some(sf) => match subfit_target::neighbors::PointIndex::new(&sf.rest) {
                Some(index) => sf.skin.gather(
                    &points
                        .iter()
                        .map(|p| index.nearest(p).index as usize)
                        .collect::<Vec<_>>(),
                ),
                None => Skin::new(points, &self.positions, s),
            },
            None => Skin::new(points, &self.positions, s),
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
        Self::new(&inner_points(samples, normals, depth), count, neighbors)
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

/// The points `depth` of the way from each sample to its medial point.
fn inner_points(samples: &[[f64; 3]], normals: &[[f64; 3]], depth: f64) -> Vec<[f64; 3]> {
    medial_points(samples, normals)
        .iter()
        .zip(samples)
        .map(|(c, p)| std::array::from_fn(|a| p[a] + depth * (c[a] - p[a])))
        .collect()
}

/// `count` indices of `points` by farthest-point sampling from point 0 (fewer when points
/// coincide). Cost: O(n · count).
fn farthest_points(points: &[[f64; 3]], count: usize) -> Vec<usize> {
    let n = points.len();
    let count = count.min(n);
    let mut picks = Vec::with_capacity(count);
    let mut d2 = vec![f64::INFINITY; n];
    let mut next = 0usize;
    while picks.len() < count {
        let g = points[next];
        picks.push(next);
        d2.par_iter_mut()
            .zip(points.par_iter())
            .for_each(|(d, &p)| *d = d.min(dist2(p, g)));
        next = (0..n).max_by(|&a, &b| d2[a].total_cmp(&d2[b])).unwrap_or(0);
        if d2[next] == 0.0 {
            break;
        }
    }
    picks
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

#[derive(Clone, Debug)]
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

    /// The rows `rows` of this skin, in that order.
    fn gather(&self, rows: &[usize]) -> Self {
        let mut nodes = Vec::with_capacity(rows.len() * self.per);
        let mut weights = Vec::with_capacity(rows.len() * self.per);
        for &r in rows {
            let (n, w) = self.row(r);
            nodes.extend_from_slice(n);
            weights.extend_from_slice(w);
        }
        Self {
            nodes,
            weights,
            per: self.per,
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

/// A step of the last stiffness level that lowers the point-to-plane RMS by less than this
/// fraction ends the step (it has converged; the fit that follows refines the rest).
const STALL: f64 = 0.01;

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
    let skin = graph.skin_of(samples, options.skin);
    let marker_rest: Vec<[f64; 3]> = markers.iter().map(|k| k.rest).collect();
    let marker_skin = graph.skin_of(&marker_rest, options.skin);
    let data = backward::subsample(target, options.backward_points);
    let schedule = backward::Schedule::new(options);
    let mut previous = None;
    for it in 0..options.iterations {
        let level = schedule.level(it);
        let moved: Vec<[f64; 3]> = (0..samples.len())
            .into_par_iter()
            .map(|i| skin.apply(i, samples[i], g, &motion))
            .collect();
        let moved_normals: Vec<[f64; 3]> = (0..samples.len())
            .into_par_iter()
            .map(|i| skin.normal(i, normals[i], &motion))
            .collect();
        let forward = matches(&moved, &moved_normals, target, level.reach);
        let rms = plane_rms(&moved, &forward);
        if it == 0 {
            stats.rms_before = rms;
        }
        stats.matched = forward.len();
        stats.rms_after = rms;
        stats.marker_rms = marker_rms(&marker_skin, markers, g, &motion);
        // Explained as well as the previous frame was (at any level: a still body is not moved).
        let settled = rms <= options.stop_rms && stats.marker_rms <= options.stop_rms;
        // Stalled: the last level's previous step gained less than STALL of the distance.
        let stalled = level.last && previous.is_some_and(|p: f64| rms > (1.0 - STALL) * p);
        if forward.is_empty() || settled || stalled {
            break;
        }
        previous = level.last.then_some(rms);
        // Data → model pairs catch what moved far (the stiff levels); the last level refines
        // with the model's own samples alone: nearest-sample pairs from the frame's side see a
        // slide along the surface as no motion, and held the generated tube's spin back
        // (drift 3.2 % instead of 0.5 % of the diagonal on its first frame).
        let backward = if options.backward_weight > 0.0 && !level.last {
            backward::matches(&moved, &moved_normals, &data, level.reach)
        } else {
            Vec::new()
        };
        let mut sys = Normal::new(PER * m);
        // Robust weights in the last level only: in the stiff levels the large residuals are
        // the motion still to follow (a limb that moved far), weighting them down there left
        // the dance's limbs behind (two-sided RMS 0.065 % instead of 0.038 %).
        let rows = FitRows {
            skin: &skin,
            samples,
            g,
            moved: &moved,
            robust: if level.last {
                options.robust * rms
            } else {
                0.0
            },
        };
        rows.add(&mut sys, &forward, 1.0, options.point_weight);
        rows.add(&mut sys, &backward, options.backward_weight, 0.0);
        add_markers(
            &mut sys,
            &marker_skin,
            markers,
            g,
            &motion,
            options.marker_weight,
        );
        add_priors(&mut sys, graph, &motion, options, level.stiffness);
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
    let sk = graph.skin_of(points, skin);
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

fn v(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

mod backward;
mod correspond;
mod geodesic;
mod system;

pub use correspond::plane_rms_to;
use correspond::{matches, plane_rms};

use system::{add_markers, add_priors, FitRows, Normal, PER};

#[cfg(test)]
mod tests;
