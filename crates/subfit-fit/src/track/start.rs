//! Where a tracking step starts ([`super::warm_starts`]): the candidate motions a caller gives
//! (the previous frame's, extrapolated or not; the rest) and rigid alignments of the rest
//! samples onto the frame, each judged by the symmetric truncated distance between the moved
//! samples and the frame's points (with normals: a point whose nearby points face the other
//! way counts as unmatched); the predicted start alone when it is near, the nearest few
//! otherwise (the caller tracks from each and keeps the result nearest the frame).
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
use subfit_mesh::vec3::dot;
use subfit_target::neighbors::PointIndex;

use subfit_target::Target;

use super::backward;
use super::model::{v, DeformationGraph, NodeMotion, Samples, Skin};
use super::options::TrackOptions;

/// A rigid motion `x ↦ R (x − from) + to`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Rigid {
    pub(super) rotation: Matrix3<f64>,
    pub(super) from: [f64; 3],
    pub(super) to: [f64; 3],
}

impl Rigid {
    fn turn(&self, n: [f64; 3]) -> [f64; 3] {
        let y = self.rotation * v(n);
        [y.x, y.y, y.z]
    }

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

/// Nearest points examined for one whose normal agrees (as [`backward`]'s matches).
const CANDIDATES: usize = 4;

/// Two symmetric truncated distances between point sets ([`chamfer`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Distances {
    /// Nearest points, whatever their normals.
    pub(super) plain: f64,
    /// Nearest points whose normals agree.
    pub(super) oriented: f64,
}

/// Symmetric truncated distances between `a` and `b` (indexed by `ia`, `ib`):
/// `sqrt(½ (mean_a e(a, B)² + mean_b e(b, A)²))`, `e(x, Y)` the distance from `x` to its
/// nearest point in `Y` (plain) or to the nearest of its [`CANDIDATES`] nearest whose normal
/// is within 60° of its own (oriented), `cap` when that is farther or there is none. A part
/// of either that the other does not come near counts `cap`, whatever its distance; the
/// oriented distance counts a part that lies on the other facing the other way alike (a body
/// turned upside down or end to end over a frame of similar extent), the plain one does not
/// depend on the normals (thin parts whose sides lie within the candidates of each other).
/// Cost O((|a| + |b|) log).
pub(super) fn chamfer(
    a: &Oriented<'_>,
    ia: &PointIndex,
    b: &Oriented<'_>,
    ib: &PointIndex,
    cap: f64,
) -> Distances {
    let side = |p: &Oriented<'_>, q: &Oriented<'_>, index: &PointIndex| {
        let (plain, oriented) = (0..p.points.len())
            .into_par_iter()
            .map(|i| {
                let near = index.k_nearest(&p.points[i], CANDIDATES);
                let plain = near.first().map_or(cap, |c| c.distance.min(cap));
                let oriented = near
                    .into_iter()
                    .take_while(|c| c.distance < cap)
                    .find(|c| dot(p.normals[i], q.normals[c.index as usize]) >= 0.5)
                    .map_or(cap, |c| c.distance);
                (plain * plain, oriented * oriented)
            })
            .reduce(|| (0.0, 0.0), |x, y| (x.0 + y.0, x.1 + y.1));
        let n = p.points.len().max(1) as f64;
        (plain / n, oriented / n)
    };
    let (x, y) = (side(a, b, ib), side(b, a, ia));
    Distances {
        plain: (0.5 * (x.0 + y.0)).sqrt(),
        oriented: (0.5 * (x.1 + y.1)).sqrt(),
    }
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
        let turn = |n: [f64; 3]| t.turn(n);
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
    let turned: Vec<[f64; 3]> = rest.normals.iter().map(|&n| t.turn(n)).collect();
    let moved = Oriented {
        points: &moved,
        normals: &turned,
    };
    let score = PointIndex::new(moved.points).map_or(f64::INFINITY, |ix| {
        chamfer(&moved, &ix, data, data_index, reach).oriented
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

/// Where [`warm_starts`] started a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Start {
    /// The candidate of this index among those given.
    Given(usize),
    /// A rigid alignment of the rest samples onto the frame.
    Rigid,
}

/// What [`warm_starts`] chose and why.
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

/// The frame's points and the rest samples a start is judged on ([`chamfer`], cap
/// [`TrackOptions::reach_start`]: what the step's stiffest level does not reach counts alike
/// however far).
struct Judge<'a> {
    graph: &'a DeformationGraph,
    data: backward::DataPoints,
    index: PointIndex,
    rest_points: Vec<[f64; 3]>,
    rest_normals: Vec<[f64; 3]>,
    skin: Skin,
    cap: f64,
}

impl<'a> Judge<'a> {
    fn new(
        graph: &'a DeformationGraph,
        samples: Samples<'_>,
        target: &Target,
        options: &TrackOptions,
    ) -> Option<Self> {
        let data = backward::subsample(target, JUDGE_POINTS);
        let pick = strided(samples.positions.len(), JUDGE_POINTS);
        if graph.is_empty() || pick.is_empty() {
            return None;
        }
        let rest_points: Vec<[f64; 3]> = pick.iter().map(|&i| samples.positions[i]).collect();
        let rest_normals = pick.iter().map(|&i| samples.normals[i]).collect();
        let skin = graph.skin_of(&rest_points, options.skin);
        Some(Self {
            graph,
            index: PointIndex::new(&data.points)?,
            data,
            rest_points,
            rest_normals,
            skin,
            cap: options.reach_start.max(options.max_distance),
        })
    }

    fn distances(&self, motion: &NodeMotion) -> Distances {
        let n = self.rest_points.len();
        let g = &self.graph.positions;
        let points: Vec<[f64; 3]> = (0..n)
            .into_par_iter()
            .map(|i| self.skin.apply(i, self.rest_points[i], g, motion))
            .collect();
        let normals: Vec<[f64; 3]> = (0..n)
            .into_par_iter()
            .map(|i| self.skin.normal(i, self.rest_normals[i], motion))
            .collect();
        let moved = Oriented {
            points: &points,
            normals: &normals,
        };
        let frame = Oriented {
            points: &self.data.points,
            normals: &self.data.normals,
        };
        PointIndex::new(&points).map_or(
            Distances {
                plain: f64::INFINITY,
                oriented: f64::INFINITY,
            },
            |ix| chamfer(&moved, &ix, &frame, &self.index, self.cap),
        )
    }

    /// Rigid alignments of the rest samples onto the frame by trimmed ICP from `starts`.
    fn aligned(&self, starts: Vec<Rigid>) -> Vec<Rigid> {
        let rest = Oriented {
            points: &self.rest_points,
            normals: &self.rest_normals,
        };
        let frame = Oriented {
            points: &self.data.points,
            normals: &self.data.normals,
        };
        starts
            .into_par_iter()
            .map(|s| icp(&rest, &frame, &self.index, s, self.cap).0)
            .collect()
    }
}

/// Two starts whose rigid parts turn less than this apart (radians, 30°) are one start.
const DISTINCT: f64 = std::f64::consts::PI / 6.0;

/// The starts of a tracking step on `target`, nearest first, at most `count`: the first of
/// the `candidates` (motions of `graph`'s nodes, the preferred first: e.g. the previous
/// frame's extrapolated, then as it was, then the rest) alone when its moved `samples` lie
/// within `near` of the frame by the plain symmetric truncated distance ([`chamfer`]);
/// otherwise the first candidate and the nearest of the others and of rigid alignments of the
/// rest samples onto the frame (trimmed ICP from the matched principal axes and from each
/// candidate's rigid part) by the oriented distance, one of each group whose rigid parts turn
/// less than 30° apart. `near` is
/// meant as a multiple of what a fitted cage leaves on its own frame ([`distance_to`]): near
/// the prediction, the prediction is kept (the distance cannot tell motions within the
/// points' spacing apart). Far from it, the distances before the step cannot tell a pose from
/// one turned end to end when limbs moved as far as the body's width (seq-lion), so the
/// caller tracks from several ([`motion_distance`] judges the results). Candidates with
/// another node count are skipped. Cost: O(P log P) for a kept start,
/// O(#starts · ICP iterations · P log P) otherwise, P = 1,500.
pub fn warm_starts(
    graph: &DeformationGraph,
    samples: Samples<'_>,
    target: &Target,
    candidates: &[NodeMotion],
    near: f64,
    count: usize,
    options: &TrackOptions,
) -> Vec<(NodeMotion, StartStats)> {
    let m = graph.len();
    let given: Vec<(usize, &NodeMotion)> = candidates
        .iter()
        .enumerate()
        .filter(|(_, c)| c.linear.len() == m)
        .collect();
    let Some(judge) = Judge::new(graph, samples, target, options) else {
        let (i, c) = given
            .first()
            .map_or((0, NodeMotion::identity(m)), |(i, c)| (*i, (*c).clone()));
        let stats = StartStats {
            start: Start::Given(i),
            distance: f64::INFINITY,
            given_distance: f64::INFINITY,
        };
        return vec![(c, stats)];
    };
    let mut all: Vec<(NodeMotion, Start, f64)> = Vec::new();
    for &(i, c) in &given {
        let d = judge.distances(c);
        if d.plain <= near {
            let stats = StartStats {
                start: Start::Given(i),
                distance: d.oriented,
                given_distance: d.oriented,
            };
            return vec![(c.clone(), stats)];
        }
        all.push((c.clone(), Start::Given(i), d.oriented));
    }
    let given_distance = all.iter().map(|x| x.2).fold(f64::INFINITY, f64::min);
    let mut starts = principal_starts(&judge.rest_points, &judge.data.points);
    starts.extend(
        given
            .iter()
            .filter_map(|(_, c)| rigid_part(graph, &judge.skin, &judge.rest_points, c)),
    );
    for r in judge.aligned(starts) {
        let motion = r.motion(&graph.positions);
        let d = judge.distances(&motion).oriented;
        all.push((motion, Start::Rigid, d));
    }
    all.sort_by(|a, b| a.2.total_cmp(&b.2));
    let mut kept: Vec<(NodeMotion, StartStats, Option<Rigid>)> = Vec::new();
    // The prediction is always tracked (its distance before the step says little when limbs
    // moved far); the others are kept apart from each other only.
    if let Some(first) = given.first().map(|g| Start::Given(g.0)) {
        if let Some(k) = all.iter().position(|x| x.1 == first) {
            let (motion, start, distance) = all.remove(k);
            let stats = StartStats {
                start,
                distance,
                given_distance,
            };
            kept.push((motion, stats, None));
        }
    }
    for (motion, start, distance) in all {
        if kept.len() >= count.max(1) {
            break;
        }
        let r = rigid_part(graph, &judge.skin, &judge.rest_points, &motion);
        let apart = |k: &Option<Rigid>| match (k, &r) {
            (Some(a), Some(b)) => turn_between(a, b) >= DISTINCT,
            _ => true,
        };
        if kept.iter().all(|k| apart(&k.2)) {
            let stats = StartStats {
                start,
                distance,
                given_distance,
            };
            kept.push((motion, stats, r));
        }
    }
    kept.into_iter().map(|(m, s, _)| (m, s)).collect()
}

/// The angle (radians) of the turn between two rigid motions' rotations.
fn turn_between(a: &Rigid, b: &Rigid) -> f64 {
    let d = a.rotation * b.rotation.transpose();
    (0.5 * (d.trace() - 1.0)).clamp(-1.0, 1.0).acos()
}

/// The oriented symmetric truncated distance ([`chamfer`], cap [`TrackOptions::reach_start`])
/// of the rest `samples` moved by `motion` to `target`, on the points [`warm_starts`] judges
/// with: how the results of steps from several starts are compared. Cost O(P log P), P =
/// 1,500.
pub fn motion_distance(
    graph: &DeformationGraph,
    samples: Samples<'_>,
    target: &Target,
    motion: &NodeMotion,
    options: &TrackOptions,
) -> f64 {
    Judge::new(graph, samples, target, options)
        .filter(|_| motion.linear.len() == graph.len())
        .map_or(f64::INFINITY, |j| j.distances(motion).oriented)
}

/// The plain symmetric truncated distance ([`chamfer`], cap [`TrackOptions::reach_start`]) of
/// `samples` (points of a surface with their unit `normals`, e.g. a fitted cage's limit
/// samples) to `target`, on the point subsets [`warm_starts`] judges with: what a start on a
/// frame the cage already fits scores (the points' spacing and the fit's error), the scale of
/// its `near`.
///
/// # Panics
/// If `samples` and `normals` differ in length.
#[track_caller]
pub fn distance_to(
    samples: &[[f64; 3]],
    normals: &[[f64; 3]],
    target: &Target,
    options: &TrackOptions,
) -> f64 {
    assert_eq!(samples.len(), normals.len(), "one normal per sample");
    let data = backward::subsample(target, JUDGE_POINTS);
    let pick = strided(samples.len(), JUDGE_POINTS);
    let points: Vec<[f64; 3]> = pick.iter().map(|&i| samples[i]).collect();
    let normals: Vec<[f64; 3]> = pick.iter().map(|&i| normals[i]).collect();
    let cap = options.reach_start.max(options.max_distance);
    let (a, b) = (
        Oriented {
            points: &points,
            normals: &normals,
        },
        Oriented {
            points: &data.points,
            normals: &data.normals,
        },
    );
    match (PointIndex::new(a.points), PointIndex::new(b.points)) {
        (Some(ia), Some(ib)) => chamfer(&a, &ia, &b, &ib, cap).plain,
        _ => f64::INFINITY,
    }
}
