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
//! **Where a step starts** ([`warm_starts`]): the prediction (the previous frames' motion
//! extrapolated) while it lies near the frame — within [`distance_to`]'s scale of what a fitted
//! cage leaves on its own frame —, otherwise several starts: the previous motion, the rest, and
//! rigid alignments (trimmed ICP from the matched principal axes), judged by a symmetric
//! truncated distance that counts points facing the other way as unmatched; the caller tracks
//! from each and keeps the result nearest the frame ([`motion_distance`]). On the corpus's
//! seq-lion (10 unrelated poses of one lion, up to 124° apart and 7–25 % of the diagonal
//! apart after rigid alignment) the step started from the extrapolated previous motion and
//! its stiff levels did not turn out of it: 5 of 9 fitted frames ended turned 141–179° from
//! the frame's true rotation and 2 about 100°, worst frame two-sided RMS 2.05 % / Hausdorff 9.73 % of the
//! diagonal (`subfit bench corpus --category seq`). Starting from the nearest start by distance
//! alone: 1.39 % / 8.86 %, still 6 of 9 turned end to end or upside down (the limbs moved as
//! far as the body's width, so a pose turned over scores as near before the step); with
//! normals in the distance and three starts tracked: 1.12 % / 6.79 %, 7 of 9 within 14° (one
//! frame still turned over, one 31° off), drift of the worst frame 45.8 % RMS / 61.4 % p95
//! (40.8 % / 81.3 % before); with the prediction always among the three tracked: the same
//! worst frame, no frame turned over (the worst 56° off), drift 20.3 % / 38.8 %. The dance below and the corpus's cat keep the
//! prediction on every frame but the first: their figures are unchanged. Three starts or five,
//! 12 candidates instead of 4 in the oriented distance, or laxer normal agreement in the stiff
//! levels (90°, none) did no better on seq-lion.
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

use rayon::prelude::*;
use subfit_mesh::vec3::dist2;
use subfit_target::Target;

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

/// A step of the last stiffness level that lowers the point-to-plane RMS by less than this
/// fraction ends the step (it has converged; the fit that follows refines the rest).
const STALL: f64 = 0.01;

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

mod backward;
mod correspond;
mod geodesic;
mod model;
mod options;
mod start;
mod system;

pub use correspond::plane_rms_to;
use correspond::{matches, plane_rms};

pub use model::{medial_points, DeformationGraph, NodeMotion, Samples};
use model::{Skin, PER};
pub use options::{Marker, TrackOptions};
pub use start::{distance_to, motion_distance, warm_starts, Start, StartStats};
use system::{add_markers, add_priors, FitRows, Normal};

#[cfg(test)]
mod tests;
