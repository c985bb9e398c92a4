//! Sharp features of point clouds: crease curves and corners.
//!
//! A point cloud has no edges whose dihedral angle could be measured ([`crate::features`] does
//! that for meshes); its sharp features show as normal discontinuities. This module follows the
//! Gauss-map clustering of Weber, Hahmann & Hagen 2010 (*Sharp feature detection in point
//! clouds*, SMI 2010, §3: a point is a feature point when the normals of its neighbourhood form
//! more than one cluster) and the crease projection of Daniels et al. 2007 (*Robust smooth
//! feature extraction from point clouds*, SMI 2007, §3–4: points near a crease are projected onto
//! the intersection of locally fitted surfaces, then grown into polylines and smoothed):
//!
//! 1. **Feature points** (per point, in parallel): among the `k` nearest neighbours
//!    ([`CLOUD_FEATURE_K`], more on noisy scans), the target's normals are split into two
//!    clusters by 2-means on the sphere, seeded by the farthest pair (Weber §3.2 uses the Gauss
//!    map of a local triangulation; the neighbours' PCA normals serve here). Each cluster's
//!    points get a least-squares plane (not its normals: PCA normals are blended next to a
//!    crease), points are reassigned to the nearer plane once and the planes refitted. The
//!    point is a feature point when both clusters hold at least [`MIN_SHARE`] of the
//!    neighbours, the planes differ by at least [`FeatureOptions::angle_deg`], two planes
//!    explain the neighbourhood much better than one (RMS residual at most half) and fit it
//!    closely (RMS residual at most [`MAX_FIT`] of the radius plus twice the noise level: a
//!    crease, not a rounded fold), and the
//!    point lies near the planes' intersection line (within half the neighbourhood radius).
//!    It is then projected onto that line (Daniels §3); its crease direction is `n1 × n2`.
//! 2. **Thinning**: the projected points are merged greedily into nodes a step `h` apart
//!    (`h` = half the median neighbourhood radius), each the mean of the projected points
//!    within `h` whose directions agree — one node row per crease, not a ribbon.
//! 3. **Tracing**: each node links to its nearest node ahead and behind along its direction
//!    (within `2.5 h` and 30°); mutual links are kept, so the graph has degree ≤ 2; its chains
//!    and cycles are the raw curves. Chains that zigzag (mean turn above
//!    [`FeatureOptions::max_mean_turn_deg`]) are dropped, the rest smoothed (Laplacian, ends
//!    fixed) and resampled at `h`.
//! 4. **Joining and corners**: curve ends within `5 h` of each other are grouped; a pair that
//!    continues one another is joined (closing a loop if both ends are the same curve's), any
//!    other group of two or more ends is a **corner**, placed at the least-squares meeting
//!    point of the ends' tangent lines (the detector goes blind within a neighbourhood radius
//!    of a corner, where three planes meet), and the curves are extended to it.
//! 5. **Cleaning**, with the mesh detector's criteria: curves with a free end shorter than
//!    [`FeatureOptions::min_curve_length`] (or [`FeatureOptions::min_curve_edges`] steps) are
//!    spurs; connected groups of curves (through corners) whose extent is below
//!    [`FeatureOptions::min_group_length`] of the diagonal (twice that for a lone curve with two
//!    free ends) are the noise of a scan. Corners
//!    left with fewer than two curves are dropped.
//!
//! Cost: `O(P·k log P)` for the per-point tests (parallel), `O(F log F)` for the `F` feature
//! points; everything in the target's normalized units.

use rayon::prelude::*;
use subfit_mesh::vec3::{add, dot, norm, normalize, scale, sub};

use crate::features::FeatureOptions;
use crate::neighbors::PointIndex;
use crate::target::Target;

mod crease_points;

use crease_points::{crease_sample, CreaseSample};
pub use crease_points::{MAX_FIT, MIN_SHARE};

/// Neighbours per feature test (at least; [`detect_cloud_features`] uses
/// `max(36, 1.5 × the target's neighbourhood k)`, so noisy scans get wider neighbourhoods).
pub const CLOUD_FEATURE_K: usize = 36;

/// One crease curve of a point cloud: a polyline sampled about every
/// [`CloudFeatures::step`] (normalized units).
#[derive(Clone, Debug, PartialEq)]
pub struct FeaturePolyline {
    /// Positions along the curve, `#n by 3`; a closed loop does not repeat its first point.
    pub points: Vec<[f64; 3]>,
    /// Whether the curve is a closed loop.
    pub closed: bool,
    /// For an open curve: the corner (index into [`CloudFeatures::corners`]) at its first and
    /// last point, `None` for a free end (a dart).
    pub ends: [Option<u32>; 2],
}

impl FeaturePolyline {
    /// Length of the polyline (with the closing segment of a loop). `O(n)`.
    pub fn length(&self) -> f64 {
        polyline_length(&self.points, self.closed)
    }
}

/// The sharp features of a point cloud ([`detect_cloud_features`]), normalized units.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CloudFeatures {
    /// Crease curves; open curves end at corners or free ends.
    pub curves: Vec<FeaturePolyline>,
    /// Corners (where two or more curves meet at an angle), `#c by 3`.
    pub corners: Vec<[f64; 3]>,
    /// Free curve ends (a crease fading out, or reaching an open boundary).
    pub darts: usize,
    /// Points that passed the per-point test (before thinning and cleaning).
    pub feature_points: usize,
    /// The sampling step `h` of the curves (normalized units).
    pub step: f64,
}

impl CloudFeatures {
    /// Whether no curve was found.
    pub fn is_empty(&self) -> bool {
        self.curves.is_empty()
    }

    /// The curves as segments (consecutive points, and a loop's closing segment). `O(n)`.
    pub fn segments(&self) -> Vec<[[f64; 3]; 2]> {
        let mut out = Vec::new();
        for c in &self.curves {
            let n = c.points.len();
            for i in 0..n.saturating_sub(1) {
                out.push([c.points[i], c.points[i + 1]]);
            }
            if c.closed && n > 2 {
                out.push([c.points[n - 1], c.points[0]]);
            }
        }
        out
    }
}

/// The sharp features of a point-cloud target (see the module docs), with the target's
/// oriented normals as the seeds of the clustering. Works on mesh targets too (their
/// vertices as points). Normalized units. Cost `O(P·k log P)`, parallel.
pub fn detect_cloud_features(target: &Target, options: &FeatureOptions) -> CloudFeatures {
    let k = CLOUD_FEATURE_K.max(target.stats().neighborhood_k * 3 / 2);
    detect_cloud_features_in(
        target.points(),
        target.normals(),
        target.index(),
        k,
        target.stats().noise_level,
        options,
    )
}

/// [`detect_cloud_features`] on raw arrays: `points` and unit `normals` (`#P by 3`, consistently
/// oriented), `index` a kd-tree over `points`, `k` neighbours per test, `noise` the noise
/// level (standard deviation along the normal, units of `points`; 0 if unknown).
///
/// # Panics
/// If `normals` and `points` differ in length.
#[track_caller]
pub fn detect_cloud_features_in(
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    index: &PointIndex,
    k: usize,
    noise: f64,
    options: &FeatureOptions,
) -> CloudFeatures {
    assert_eq!(points.len(), normals.len(), "one normal per point");
    let cos_angle = options.angle_deg.to_radians().cos();
    let samples: Vec<CreaseSample> = (0..points.len())
        .into_par_iter()
        .filter_map(|i| crease_sample(i, points, normals, index, k, cos_angle, noise))
        .collect();
    let mut out = CloudFeatures {
        feature_points: samples.len(),
        ..CloudFeatures::default()
    };
    if samples.len() < 3 {
        return out;
    }
    let mut radii: Vec<f64> = samples.iter().map(|s| s.radius).collect();
    radii.sort_by(f64::total_cmp);
    let h = 0.5 * radii[radii.len() / 2];
    out.step = h;
    let nodes = thin(&samples, h);
    let raw = trace(&nodes, h);
    let diag = diagonal(points);
    let curves: Vec<FeaturePolyline> = raw
        .into_iter()
        .filter(|c| c.points.len() >= 3)
        .filter(|c| {
            c.points.len() < 5 || mean_turn_deg(&c.points, c.closed) <= options.max_mean_turn_deg
        })
        .map(|c| smooth_resample(c, h))
        .collect();
    let curves = join_aligned(curves, 5.0 * h);
    let (curves, corners) = make_corners(curves, 5.0 * h);
    let (curves, corners) = clean(curves, corners, h, diag, options);
    out.darts = curves
        .iter()
        .filter(|c| !c.closed)
        .map(|c| c.ends.iter().filter(|e| e.is_none()).count())
        .sum();
    out.curves = curves
        .into_iter()
        .map(|mut c| {
            c.points = resample(&c.points, c.closed, h);
            c
        })
        .collect();
    out.corners = corners;
    out
}

/// A thinned crease node: mean position and direction of the samples merged into it.
#[derive(Clone, Copy, Debug)]
struct Node {
    pos: [f64; 3],
    dir: [f64; 3],
}

/// Step 2: greedy merging of the samples (most reliable first: smallest offset) into nodes at
/// least `h` apart.
fn thin(samples: &[CreaseSample], h: f64) -> Vec<Node> {
    let pts: Vec<[f64; 3]> = samples.iter().map(|s| s.pos).collect();
    let Some(index) = PointIndex::new(&pts) else {
        return Vec::new();
    };
    let mut order: Vec<usize> = (0..samples.len()).collect();
    order.sort_by(|&a, &b| samples[a].offset.total_cmp(&samples[b].offset));
    let cos_agree = 30f64.to_radians().cos();
    let mut taken = vec![false; samples.len()];
    let mut nodes = Vec::new();
    for &s in &order {
        if taken[s] {
            continue;
        }
        let seed = samples[s];
        let (mut p, mut d, mut n) = ([0.0; 3], [0.0; 3], 0.0);
        index.for_each_within(&seed.pos, h, |j| {
            let j = j as usize;
            let c = dot(samples[j].dir, seed.dir);
            if taken[j] || c.abs() < cos_agree {
                return;
            }
            taken[j] = true;
            p = add(p, samples[j].pos);
            d = add(d, scale(samples[j].dir, c.signum()));
            n += 1.0;
        });
        taken[s] = true;
        if n > 0.0 {
            if let Some(dir) = normalize(d) {
                nodes.push(Node {
                    pos: scale(p, 1.0 / n),
                    dir,
                });
            }
        }
    }
    nodes
}

/// Step 3: mutual nearest links ahead/behind each node; the chains and cycles of the graph.
fn trace(nodes: &[Node], h: f64) -> Vec<FeaturePolyline> {
    let pts: Vec<[f64; 3]> = nodes.iter().map(|n| n.pos).collect();
    let Some(index) = PointIndex::new(&pts) else {
        return Vec::new();
    };
    let cos_cone = 30f64.to_radians().cos();
    let picks: Vec<[Option<usize>; 2]> = nodes
        .par_iter()
        .enumerate()
        .map(|(a, na)| {
            let mut best = [None::<(f64, usize)>; 2];
            for nb in index.within(&na.pos, 2.5 * h) {
                let b = nb.index as usize;
                if b == a || dot(nodes[b].dir, na.dir).abs() < cos_cone {
                    continue;
                }
                let d = sub(nodes[b].pos, na.pos);
                let l = norm(d);
                if !(l > 0.0) {
                    continue;
                }
                let c = dot(d, na.dir) / l;
                let side = if c >= cos_cone {
                    0
                } else if c <= -cos_cone {
                    1
                } else {
                    continue;
                };
                if best[side].is_none_or(|(bl, _)| l < bl) {
                    best[side] = Some((l, b));
                }
            }
            best.map(|x| x.map(|(_, b)| b))
        })
        .collect();
    let mut adj: Vec<Vec<usize>> = vec![Vec::new(); nodes.len()];
    for (a, pk) in picks.iter().enumerate() {
        for b in pk.iter().flatten().copied() {
            if a < b && picks[b].contains(&Some(a)) {
                adj[a].push(b);
                adj[b].push(a);
            }
        }
    }
    chains(&adj, &pts)
}

/// The chains (from degree-1 nodes) and cycles of a graph of degree ≤ 2.
fn chains(adj: &[Vec<usize>], pts: &[[f64; 3]]) -> Vec<FeaturePolyline> {
    let mut seen = vec![false; adj.len()];
    let mut out = Vec::new();
    let walk = |start: usize, seen: &mut Vec<bool>| -> (Vec<usize>, bool) {
        let mut path = vec![start];
        seen[start] = true;
        let (mut prev, mut at) = (usize::MAX, start);
        loop {
            let next = adj[at].iter().copied().find(|&w| w != prev && !seen[w]);
            match next {
                Some(w) => {
                    seen[w] = true;
                    path.push(w);
                    prev = at;
                    at = w;
                }
                None => {
                    let closed = path.len() > 2 && adj[at].contains(&start);
                    return (path, closed);
                }
            }
        }
    };
    for v in 0..adj.len() {
        if !seen[v] && adj[v].len() == 1 {
            let (p, _) = walk(v, &mut seen);
            out.push((p, false));
        }
    }
    for v in 0..adj.len() {
        if !seen[v] && adj[v].len() == 2 {
            out.push(walk(v, &mut seen));
        }
    }
    out.into_iter()
        .map(|(p, closed)| FeaturePolyline {
            points: p.iter().map(|&i| pts[i]).collect(),
            closed,
            ends: [None, None],
        })
        .collect()
}

/// Laplacian smoothing (5 passes, ends of open curves fixed), then resampling at `h`.
fn smooth_resample(mut c: FeaturePolyline, h: f64) -> FeaturePolyline {
    let n = c.points.len();
    for _ in 0..5 {
        let old = c.points.clone();
        for i in 0..n {
            let (prev, next) = if c.closed {
                ((i + n - 1) % n, (i + 1) % n)
            } else if i == 0 || i == n - 1 {
                continue;
            } else {
                (i - 1, i + 1)
            };
            let avg = scale(add(old[prev], old[next]), 0.5);
            c.points[i] = add(scale(old[i], 0.5), scale(avg, 0.5));
        }
    }
    c.points = resample(&c.points, c.closed, h);
    c
}

/// The polyline resampled at (about) `step`, keeping its ends (a loop keeps its first point).
pub(crate) fn resample(points: &[[f64; 3]], closed: bool, step: f64) -> Vec<[f64; 3]> {
    let mut pts = points.to_vec();
    if closed && !pts.is_empty() {
        pts.push(pts[0]);
    }
    let total = polyline_length(&pts, false);
    if pts.len() < 2 || !(total > 0.0) || !(step > 0.0) {
        return points.to_vec();
    }
    let min_segments = if closed { 3 } else { 1 };
    let segments = ((total / step).round() as usize).max(min_segments);
    let mut out = Vec::with_capacity(segments + 1);
    let (mut seg, mut acc) = (0usize, 0.0);
    for s in 0..=segments {
        if closed && s == segments {
            break;
        }
        let target = total * s as f64 / segments as f64;
        loop {
            let l = norm(sub(pts[seg + 1], pts[seg]));
            if acc + l >= target || seg + 2 >= pts.len() {
                let t = if l > 0.0 {
                    ((target - acc) / l).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                out.push(add(pts[seg], scale(sub(pts[seg + 1], pts[seg]), t)));
                break;
            }
            acc += l;
            seg += 1;
        }
    }
    if !closed {
        if let (Some(o), Some(&p)) = (out.last_mut(), pts.last()) {
            *o = p;
        }
    }
    out
}

fn polyline_length(points: &[[f64; 3]], closed: bool) -> f64 {
    let mut l: f64 = points.windows(2).map(|w| norm(sub(w[1], w[0]))).sum();
    if closed && points.len() > 2 {
        l += norm(sub(points[0], points[points.len() - 1]));
    }
    l
}

/// Mean turning angle (degrees) at the interior vertices.
fn mean_turn_deg(points: &[[f64; 3]], closed: bool) -> f64 {
    let n = points.len();
    let range = if closed { 0..n } else { 1..n.saturating_sub(1) };
    let mut sum = 0.0;
    let mut count = 0usize;
    for i in range {
        let a = points[(i + n - 1) % n];
        let b = points[i];
        let c = points[(i + 1) % n];
        if let (Some(u), Some(v)) = (normalize(sub(b, a)), normalize(sub(c, b))) {
            sum += dot(u, v).clamp(-1.0, 1.0).acos().to_degrees();
            count += 1;
        }
    }
    if count == 0 {
        0.0
    } else {
        sum / count as f64
    }
}

/// The free ends of the open curves.
fn curve_ends(curves: &[FeaturePolyline]) -> Vec<EndInfo> {
    let mut out = Vec::new();
    for (ci, c) in curves.iter().enumerate() {
        if c.closed || c.points.len() < 2 {
            continue;
        }
        let n = c.points.len();
        let back = 3.min(n - 1);
        for (e, (at, from)) in [(0, back), (n - 1, n - 1 - back)].into_iter().enumerate() {
            if c.ends[e].is_some() {
                continue;
            }
            if let Some(t) = normalize(sub(c.points[at], c.points[from])) {
                out.push(((ci, e), c.points[at], t));
            }
        }
    }
    out
}

/// Pairs of ends (indices into `ends`) closer than `reach`, nearest first. `O(E log E)` with a
/// kd-tree over the ends.
fn close_end_pairs(ends: &[EndInfo], reach: f64) -> Vec<(f64, usize, usize)> {
    let pts: Vec<[f64; 3]> = ends.iter().map(|e| e.1).collect();
    let Some(index) = PointIndex::new(&pts) else {
        return Vec::new();
    };
    let mut pairs = Vec::new();
    for (i, p) in pts.iter().enumerate() {
        for nb in index.within(p, reach) {
            let j = nb.index as usize;
            if i < j {
                pairs.push((nb.distance, i, j));
            }
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    pairs
}

/// An end of an open curve: (curve, which end), position, outward unit tangent.
type EndInfo = ((usize, usize), [f64; 3], [f64; 3]);

/// Joins pairs of free ends within `reach` that continue one another (the outward tangent of
/// each points at the other within 35°), nearest pairs first, each end at most once; a chain
/// of joins that comes back to its start closes a loop.
fn join_aligned(curves: Vec<FeaturePolyline>, reach: f64) -> Vec<FeaturePolyline> {
    let cos_align = 35f64.to_radians().cos();
    let ends = curve_ends(&curves);
    // link[curve][end] = (other curve, its end)
    let mut link: Vec<[Option<(usize, usize)>; 2]> = vec![[None, None]; curves.len()];
    for (l, i, j) in close_end_pairs(&ends, reach) {
        let (a, b) = (&ends[i], &ends[j]);
        let ((ca, ea), (cb, eb)) = (a.0, b.0);
        if link[ca][ea].is_some() || link[cb][eb].is_some() {
            continue;
        }
        let d = sub(b.1, a.1);
        let aligned = l < 1e-12
            || (dot(a.2, d) / l >= cos_align && -dot(b.2, d) / l >= cos_align)
            || (-dot(a.2, b.2) >= cos_align && l < 0.5 * reach);
        if aligned && (ca != cb || curves[ca].points.len() > 2) {
            link[ca][ea] = Some((cb, eb));
            link[cb][eb] = Some((ca, ea));
        }
    }
    // Walk the chains of linked curves: from curves with a free end first, then the loops.
    let mut used = vec![false; curves.len()];
    let mut out = Vec::new();
    let walk = |start: usize, entry: usize, used: &mut Vec<bool>| -> FeaturePolyline {
        let (mut c, mut e) = (start, entry);
        let mut pts: Vec<[f64; 3]> = Vec::new();
        loop {
            used[c] = true;
            let mut p = curves[c].points.clone();
            if e == 1 {
                p.reverse();
            }
            pts.extend(p);
            match link[c][1 - e] {
                Some((n, ne)) if !used[n] => (c, e) = (n, ne),
                Some((n, _)) if n == start => {
                    return FeaturePolyline {
                        points: pts,
                        closed: true,
                        ends: [None, None],
                    }
                }
                _ => {
                    return FeaturePolyline {
                        points: pts,
                        closed: false,
                        ends: [None, None],
                    }
                }
            }
        }
    };
    for c in 0..curves.len() {
        if used[c] || curves[c].closed {
            continue;
        }
        if link[c][0].is_none() {
            out.push(walk(c, 0, &mut used));
        } else if link[c][1].is_none() {
            out.push(walk(c, 1, &mut used));
        }
    }
    for c in 0..curves.len() {
        if !used[c] {
            if curves[c].closed {
                used[c] = true;
                out.push(curves[c].clone());
            } else {
                out.push(walk(c, 0, &mut used));
            }
        }
    }
    out
}

/// Groups the free ends within `reach` (single linkage); each group of two or more becomes a
/// corner at the least-squares meeting point of the ends' tangent lines, and its curves are
/// extended to it.
fn make_corners(
    mut curves: Vec<FeaturePolyline>,
    reach: f64,
) -> (Vec<FeaturePolyline>, Vec<[f64; 3]>) {
    let ends = curve_ends(&curves);
    let n = ends.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for (_, i, j) in close_end_pairs(&ends, reach) {
        if ends[i].0 .0 != ends[j].0 .0 {
            let (a, b) = (find(&mut parent, i), find(&mut parent, j));
            parent[a] = b;
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for i in 0..n {
        let r = find(&mut parent, i);
        groups.entry(r).or_default().push(i);
    }
    let mut corners = Vec::new();
    for g in groups.values().filter(|g| g.len() >= 2) {
        let lines: Vec<([f64; 3], [f64; 3])> = g.iter().map(|&i| (ends[i].1, ends[i].2)).collect();
        let centroid = scale(
            lines.iter().fold([0.0; 3], |a, l| add(a, l.0)),
            1.0 / lines.len() as f64,
        );
        let c = lines_meeting_point(&lines)
            .filter(|x| norm(sub(*x, centroid)) <= reach)
            .unwrap_or(centroid);
        let id = corners.len() as u32;
        corners.push(c);
        for &i in g {
            let (ci, e) = ends[i].0;
            let cv = &mut curves[ci];
            if e == 0 {
                cv.points.insert(0, c);
            } else {
                cv.points.push(c);
            }
            cv.ends[e] = Some(id);
        }
    }
    (curves, corners)
}

/// The point nearest (least squares) to the lines `(point, unit direction)`; `None` when they
/// are (nearly) parallel.
fn lines_meeting_point(lines: &[([f64; 3], [f64; 3])]) -> Option<[f64; 3]> {
    let mut a = nalgebra::Matrix3::<f64>::zeros();
    let mut b = nalgebra::Vector3::<f64>::zeros();
    for (p, d) in lines {
        let d = nalgebra::Vector3::from(*d);
        let m = nalgebra::Matrix3::identity() - d * d.transpose();
        a += m;
        b += m * nalgebra::Vector3::from(*p);
    }
    let e = a.symmetric_eigen();
    let min = e.eigenvalues.iter().copied().fold(f64::INFINITY, f64::min);
    if !(min > 0.05 * lines.len() as f64) {
        return None;
    }
    let x = a.lu().solve(&b)?;
    Some([x[0], x[1], x[2]])
}

/// Step 5 of the module docs: spurs and small groups removed, corners re-indexed.
fn clean(
    mut curves: Vec<FeaturePolyline>,
    corners: Vec<[f64; 3]>,
    h: f64,
    diag: f64,
    o: &FeatureOptions,
) -> (Vec<FeaturePolyline>, Vec<[f64; 3]>) {
    let min_len = (o.min_curve_length * diag).max(o.min_curve_edges as f64 * h);
    loop {
        let mut degree = vec![0usize; corners.len()];
        for c in &curves {
            for e in c.ends.iter().flatten() {
                degree[*e as usize] += 1;
            }
        }
        let before = curves.len();
        // A curve whose end is a corner no other curve reaches has a free end there.
        for c in &mut curves {
            for e in &mut c.ends {
                if e.is_some_and(|k| degree[k as usize] < 2) {
                    *e = None;
                }
            }
        }
        curves.retain(|c| c.closed || c.ends.iter().all(Option::is_some) || c.length() >= min_len);
        if curves.len() == before {
            break;
        }
    }
    // Connected groups through corners.
    let nc = curves.len();
    let mut group: Vec<usize> = (0..nc).collect();
    let mut by_corner: std::collections::HashMap<u32, usize> = Default::default();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for (i, c) in curves.iter().enumerate() {
        for &k in c.ends.iter().flatten() {
            if let Some(&j) = by_corner.get(&k) {
                let (a, b) = (find(&mut group, i), find(&mut group, j));
                group[a] = b;
            } else {
                by_corner.insert(k, i);
            }
        }
    }
    let mut extent: std::collections::HashMap<usize, Vec<[f64; 3]>> = Default::default();
    for (i, c) in curves.iter().enumerate() {
        let r = find(&mut group, i);
        extent.entry(r).or_default().extend(&c.points);
    }
    // A lone open curve with two free ends must span twice as much: the folds of a scan that
    // pass the sharpness test do so in isolated stretches (Igea's face).
    let mut members: std::collections::HashMap<usize, usize> = Default::default();
    for i in 0..nc {
        *members.entry(find(&mut group, i)).or_default() += 1;
    }
    let keep: Vec<bool> = (0..nc)
        .map(|i| {
            let r = find(&mut group, i);
            let c = &curves[i];
            let lone = members[&r] == 1 && !c.closed && c.ends.iter().all(Option::is_none);
            let factor = if lone { 2.0 } else { 1.0 };
            diagonal(&extent[&r]) >= factor * o.min_group_length * diag
        })
        .collect();
    let mut it = keep.iter();
    curves.retain(|_| *it.next().unwrap_or(&false));
    // Re-index the corners still in use.
    let mut new_id = vec![None; corners.len()];
    let mut kept = Vec::new();
    for c in &mut curves {
        for e in c.ends.iter_mut() {
            if let Some(k) = *e {
                let id = *new_id[k as usize].get_or_insert_with(|| {
                    kept.push(corners[k as usize]);
                    (kept.len() - 1) as u32
                });
                *e = Some(id);
            }
        }
    }
    (curves, kept)
}

/// The bounding-box diagonal of `points` (0 for none).
fn diagonal(points: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let d = norm(sub(hi, lo));
    if d.is_finite() {
        d
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resample_keeps_ends_and_spacing() {
        let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]];
        let r = resample(&pts, false, 0.1);
        assert_eq!(r.len(), 21);
        assert_eq!(r[0], pts[0]);
        assert_eq!(*r.last().unwrap(), pts[2]);
        // A loop: uniform in arclength, so its three corners are cut by less than a step each.
        let closed = resample(&pts, true, 0.1);
        let l = polyline_length(&closed, true);
        assert!(
            l <= 2.0 + 2f64.sqrt() + 1e-12 && l > 2.0 + 2f64.sqrt() - 0.15,
            "{l}"
        );
    }

    #[test]
    fn three_lines_meet_at_a_corner() {
        let lines = [
            ([0.9, 0.0, 0.0], [-1.0, 0.0, 0.0]),
            ([0.0, 0.8, 0.0], [0.0, -1.0, 0.0]),
            ([0.0, 0.0, 0.7], [0.0, 0.0, -1.0]),
        ];
        let x = lines_meeting_point(&lines).unwrap();
        assert!(norm(x) < 1e-12);
    }
}
