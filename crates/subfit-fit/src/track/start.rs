//! Where a tracking step starts ([`super::warm_start`]): the candidate motions a caller gives
//! (the previous frame's, extrapolated or not; the rest) and rigid alignments of the rest
//! samples onto the frame, each judged by the symmetric truncated distance between the moved
//! samples and the frame's points; the nearest is the start.
//!
//! **Rigid alignments.** Trimmed symmetric ICP (Besl & McKay, "A method for registration of
//! 3-D shapes", PAMI 1992; the pairs' best rotation by Kabsch's SVD, Arun, Huang & Blostein,
//! PAMI 1987; pairs beyond the reach or with normals more than 60° apart left out, as in
//! Chetverikov et al.'s trimmed ICP, ICPR 2002), started from the principal axes of both
//! point sets matched in their four proper orientations (a turn of any size is then within
//! reach of one start) and from the rigid part of each candidate motion. A sequence whose
//! frames are unrelated poses (the corpus's seq-lion: up to 124° apart) is otherwise started
//! from the previous pose, which the stiff levels of the step do not turn out of.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use rayon::prelude::*;
#[cfg(test)]
use subfit_mesh::vec3::dist2;
use subfit_mesh::vec3::dot;
use subfit_target::neighbors::PointIndex;

use subfit_target::Target;

use super::backward;
use super::model::{v, DeformationGraph, NodeMotion, Skin};
use super::{Samples, TrackOptions};

/// A rigid motion `x ↦ R (x − from) + to`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Rigid {
    pub(super) rotation: Matrix3<f64>,
    pub(super) from: [f64; 3],
    pub(super) to: [f64; 3],
}

impl Rigid {
    fn apply(&self, x: [f64; 3]) -> [f64; 3] {
        let y = self.rotation * (v(x) - v(self.from)) + v(self.to);
        [y.x, y.y, y.z]
    }

    /// The same motion as per-node affine motions of the nodes at `g`:
    /// `A_k = R`, `t_k = R (g_k − from) + to − g_k`.
    pub(super) fn motion(&self, g: &[[f64; 3]]) -> NodeMotion {
        NodeMotion {
            linear: vec![self.rotation; g.len()],
            translations: g
                .iter()
                .map(|&p| {
                    let y = self.apply(p);
                    std::array::from_fn(|a| y[a] - p[a])
                })
                .collect(),
        }
    }
}

/// Points with unit normals.
pub(super) struct Oriented<'a> {
    pub(super) points: &'a [[f64; 3]],
    pub(super) normals: &'a [[f64; 3]],
}

/// The rigid motion that carries `p` onto `q` best in the least-squares sense (Arun et al.
/// 1987): Kabsch's rotation from the SVD of the pairs' covariance, a reflection turned into
/// the nearest rotation. `None` for fewer than three pairs. Cost O(n).
pub(super) fn best_rigid(p: &[[f64; 3]], q: &[[f64; 3]]) -> Option<Rigid> {
    if p.len() < 3 || p.len() != q.len() {
        return None;
    }
    let (cp, cq) = (centroid(p), centroid(q));
    let mut h = Matrix3::zeros();
    for (a, b) in p.iter().zip(q) {
        h += (v(*b) - v(cp)) * (v(*a) - v(cp)).transpose();
    }
    let svd = h.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let d = (u * vt).determinant().signum();
    let rotation = u * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * vt;
    Some(Rigid {
        rotation,
        from: cp,
        to: cq,
    })
}

fn centroid(p: &[[f64; 3]]) -> [f64; 3] {
    let n = p.len().max(1) as f64;
    std::array::from_fn(|a| p.iter().map(|x| x[a]).sum::<f64>() / n)
}

/// The principal axes of `p` (columns, by decreasing variance, right-handed).
fn principal_axes(p: &[[f64; 3]]) -> Matrix3<f64> {
    let c = v(centroid(p));
    let mut cov = Matrix3::zeros();
    for &x in p {
        let d = v(x) - c;
        cov += d * d.transpose();
    }
    let eig = SymmetricEigen::new(cov);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let mut e = Matrix3::from_columns(&[
        eig.eigenvectors.column(order[0]).into_owned(),
        eig.eigenvectors.column(order[1]).into_owned(),
        eig.eigenvectors.column(order[2]).into_owned(),
    ]);
    if e.determinant() < 0.0 {
        e.set_column(2, &(-e.column(2)));
    }
    e
}

/// The four rigid motions that carry the principal frame of `rest` onto that of `data` (each
/// axis matched up to sign, the frame kept right-handed).
fn principal_starts(rest: &[[f64; 3]], data: &[[f64; 3]]) -> Vec<Rigid> {
    let (er, ed) = (principal_axes(rest), principal_axes(data));
    let (from, to) = (centroid(rest), centroid(data));
    [
        [1.0, 1.0, 1.0],
        [-1.0, -1.0, 1.0],
        [-1.0, 1.0, -1.0],
        [1.0, -1.0, -1.0],
    ]
    .iter()
    .map(|s| Rigid {
        rotation: ed * Matrix3::from_diagonal(&Vector3::new(s[0], s[1], s[2])) * er.transpose(),
        from,
        to,
    })
    .collect()
}

/// Symmetric truncated distance between `a` and `b` (indexed by `ia`, `ib`):
/// `sqrt(½ (mean_a min(d(a, B), cap)² + mean_b min(d(b, A), cap)²))`. A part of either that
/// the other does not come near counts `cap`, whatever its distance. Cost O((|a| + |b|) log).
pub(super) fn chamfer(
    a: &[[f64; 3]],
    ia: &PointIndex,
    b: &[[f64; 3]],
    ib: &PointIndex,
    cap: f64,
) -> f64 {
    let side = |p: &[[f64; 3]], index: &PointIndex| {
        p.par_iter()
            .map(|x| index.nearest(x).distance.min(cap).powi(2))
            .sum::<f64>()
            / p.len().max(1) as f64
    };
    (0.5 * (side(a, ib) + side(b, ia))).sqrt()
}

/// Iterations of the rigid ICP at most.
const ICP_ITERATIONS: usize = 30;

/// Trimmed symmetric ICP of `rest` onto `data` from `start` with correspondence radius
/// `reach`; returns the motion and its [`chamfer`] distance (cap `reach`). Cost:
/// `ICP_ITERATIONS × O((|rest| + |data|) log)`.
pub(super) fn icp(
    rest: &Oriented<'_>,
    data: &Oriented<'_>,
    data_index: &PointIndex,
    start: Rigid,
    reach: f64,
) -> (Rigid, f64) {
    let mut t = start;
    let mut last = f64::INFINITY;
    for _ in 0..ICP_ITERATIONS {
        let moved: Vec<[f64; 3]> = rest.points.iter().map(|&x| t.apply(x)).collect();
        let Some(moved_index) = PointIndex::new(&moved) else {
            break;
        };
        let turn = |n: [f64; 3]| {
            let y = t.rotation * v(n);
            [y.x, y.y, y.z]
        };
        let (mut p, mut q) = (Vec::new(), Vec::new());
        let mut sum = 0.0;
        for (i, &x) in moved.iter().enumerate() {
            let c = data_index.nearest(&x);
            let j = c.index as usize;
            if c.distance <= reach && dot(turn(rest.normals[i]), data.normals[j]) >= 0.5 {
                p.push(rest.points[i]);
                q.push(data.points[j]);
                sum += c.distance * c.distance;
            }
        }
        for (j, &y) in data.points.iter().enumerate() {
            let c = moved_index.nearest(&y);
            let i = c.index as usize;
            if c.distance <= reach && dot(turn(rest.normals[i]), data.normals[j]) >= 0.5 {
                p.push(rest.points[i]);
                q.push(y);
                sum += c.distance * c.distance;
            }
        }
        let Some(next) = best_rigid(&p, &q) else {
            break;
        };
        t = next;
        let mean = sum / p.len().max(1) as f64;
        if mean >= last * (1.0 - 1e-4) {
            break;
        }
        last = mean;
    }
    let moved: Vec<[f64; 3]> = rest.points.iter().map(|&x| t.apply(x)).collect();
    let score = PointIndex::new(&moved).map_or(f64::INFINITY, |ix| {
        chamfer(&moved, &ix, data.points, data_index, reach)
    });
    (t, score)
}

/// The rigid part of `motion` over `rest` (the best rigid fit of the moved points to the
/// rest ones); `None` when it has no rigid fit.
pub(super) fn rigid_part(
    graph: &DeformationGraph,
    skin: &Skin,
    rest: &[[f64; 3]],
    motion: &NodeMotion,
) -> Option<Rigid> {
    let moved: Vec<[f64; 3]> = (0..rest.len())
        .map(|i| skin.apply(i, rest[i], &graph.positions, motion))
        .collect();
    best_rigid(rest, &moved)
}

/// Every `⌈n / count⌉`-th index of `0..n`.
pub(super) fn strided(n: usize, count: usize) -> Vec<usize> {
    (0..n).step_by(n.div_ceil(count.max(1)).max(1)).collect()
}

/// The largest squared distance of `b` to its nearest of `a`, for tests.
#[cfg(test)]
pub(super) fn farthest2(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    b.iter()
        .map(|y| {
            a.iter()
                .map(|x| dist2(*x, *y))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

/// Where [`warm_start`] started a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Start {
    /// The candidate of this index among those given.
    Given(usize),
    /// A rigid alignment of the rest samples onto the frame.
    Rigid,
}

/// What [`warm_start`] chose and why.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StartStats {
    /// The start chosen.
    pub start: Start,
    /// Its symmetric truncated distance to the frame (normalized units; the cap
    /// [`TrackOptions::reach_start`]).
    pub distance: f64,
    /// The nearest given candidate's (infinite when none was given).
    pub given_distance: f64,
}

/// Points of each side used to judge the starts and in the rigid ICP.
const JUDGE_POINTS: usize = 1500;

/// The start of a tracking step on `target`: the first of the `candidates` (motions of
/// `graph`'s nodes, the preferred first: e.g. the previous frame's extrapolated, then as it
/// was, then the rest) when its moved `samples` lie within `near` of the frame by the
/// symmetric truncated distance ([`chamfer`], cap [`TrackOptions::reach_start`]: what the
/// step's stiffest level does not reach counts alike however far); otherwise the nearest of
/// the candidates and of rigid alignments of the rest samples onto the frame (trimmed ICP
/// from the matched principal axes and from each candidate's rigid part). `near` is meant as
/// a multiple of what the previous frame's fitted cage leaves on its own frame
/// ([`distance_to`]): near the prediction, the prediction is kept (the distance cannot tell
/// motions within the points' spacing apart). Candidates with another node count are
/// skipped. Cost: O(P log P) for a kept start, O(#starts · ICP iterations · P log P)
/// otherwise, P = 1,500.
pub fn warm_start(
    graph: &DeformationGraph,
    samples: Samples<'_>,
    target: &Target,
    candidates: &[NodeMotion],
    near: f64,
    options: &TrackOptions,
) -> (NodeMotion, StartStats) {
    let m = graph.len();
    let given: Vec<(usize, &NodeMotion)> = candidates
        .iter()
        .enumerate()
        .filter(|(_, c)| c.linear.len() == m)
        .collect();
    let fallback = || {
        let (i, c) = given
            .first()
            .map_or((0, NodeMotion::identity(m)), |(i, c)| (*i, (*c).clone()));
        let stats = StartStats {
            start: Start::Given(i),
            distance: f64::INFINITY,
            given_distance: f64::INFINITY,
        };
        (c, stats)
    };
    let data = backward::subsample(target, JUDGE_POINTS);
    let pick = strided(samples.positions.len(), JUDGE_POINTS);
    let rest_points: Vec<[f64; 3]> = pick.iter().map(|&i| samples.positions[i]).collect();
    let rest_normals: Vec<[f64; 3]> = pick.iter().map(|&i| samples.normals[i]).collect();
    let (Some(data_index), false) = (PointIndex::new(&data.points), m == 0 || pick.is_empty())
    else {
        return fallback();
    };
    let cap = options.reach_start.max(options.max_distance);
    let skin = graph.skin_of(&rest_points, options.skin);
    let judge = |motion: &NodeMotion| {
        let moved: Vec<[f64; 3]> = (0..rest_points.len())
            .into_par_iter()
            .map(|i| skin.apply(i, rest_points[i], &graph.positions, motion))
            .collect();
        PointIndex::new(&moved).map_or(f64::INFINITY, |ix| {
            chamfer(&moved, &ix, &data.points, &data_index, cap)
        })
    };
    let mut best: Option<(NodeMotion, StartStats)> = None;
    let mut given_distance = f64::INFINITY;
    for &(i, c) in &given {
        let d = judge(c);
        given_distance = given_distance.min(d);
        if best.as_ref().is_none_or(|b| d < b.1.distance) {
            let start = Start::Given(i);
            best = Some((
                c.clone(),
                StartStats {
                    start,
                    distance: d,
                    given_distance,
                },
            ));
        }
        if best.as_ref().is_some_and(|b| b.1.distance <= near) {
            return best.expect("set");
        }
    }
    let mut starts = principal_starts(&rest_points, &data.points);
    starts.extend(
        given
            .iter()
            .filter_map(|(_, c)| rigid_part(graph, &skin, &rest_points, c)),
    );
    let rest = Oriented {
        points: &rest_points,
        normals: &rest_normals,
    };
    let frame = Oriented {
        points: &data.points,
        normals: &data.normals,
    };
    let aligned: Vec<Rigid> = starts
        .into_par_iter()
        .map(|s| icp(&rest, &frame, &data_index, s, cap).0)
        .collect();
    for r in aligned {
        let motion = r.motion(&graph.positions);
        let d = judge(&motion);
        if best.as_ref().is_none_or(|b| d < b.1.distance) {
            let start = Start::Rigid;
            best = Some((
                motion,
                StartStats {
                    start,
                    distance: d,
                    given_distance,
                },
            ));
        }
    }
    let (motion, mut stats) = best.unwrap_or_else(fallback);
    stats.given_distance = given_distance;
    (motion, stats)
}

/// The symmetric truncated distance ([`chamfer`], cap [`TrackOptions::reach_start`]) of
/// `samples` (points of a surface, e.g. a fitted cage's limit samples) to `target`, on the
/// point subsets [`warm_start`] judges with: what a start on a frame the cage already fits
/// scores (the points' spacing and the fit's error), the scale of its `near`.
pub fn distance_to(samples: &[[f64; 3]], target: &Target, options: &TrackOptions) -> f64 {
    let data = backward::subsample(target, JUDGE_POINTS);
    let pick: Vec<[f64; 3]> = strided(samples.len(), JUDGE_POINTS)
        .into_iter()
        .map(|i| samples[i])
        .collect();
    let cap = options.reach_start.max(options.max_distance);
    match (PointIndex::new(&pick), PointIndex::new(&data.points)) {
        (Some(ia), Some(ib)) => chamfer(&pick, &ia, &data.points, &ib, cap),
        _ => f64::INFINITY,
    }
}
