//! Feature-aligned contours of point clouds: the dense contour is snapped to the cloud's
//! crease curves.
//!
//! The IMLS contour of a point cloud ([`crate::contour()`]) rounds sharp edges, and its edges
//! run across them. Before simplification, each crease curve of the cloud
//! ([`subfit_target::detect_cloud_features`]) is traced on the contour as a chain of edges and
//! the chain's vertices are moved onto the curve, so that [`crate::simplify_with_features`]
//! can keep the chain as crease edges of the cage, as it does for mesh targets (Lavoué et al.
//! 2005 §6 tag patch boundaries as sharp control edges; tracing a feature curve on a mesh as
//! a shortest edge path through the vertices nearest to it follows Hoppe et al. 1994 §4, who
//! mark the sharp edges of a dense mesh before optimizing it):
//!
//! 1. **Corners**: the contour vertex nearest each cloud corner becomes a corner vertex and is
//!    moved onto the corner.
//! 2. **Paths**: for each curve, the contour vertices nearest its samples are anchors
//!    (consecutive duplicates merged; curve ends at corners anchored at the corner vertices);
//!    consecutive anchors are joined by a Dijkstra shortest edge path that avoids the vertices
//!    of paths already traced (except at corners), so the chains stay simple and meet only at
//!    corners. A piece that cannot be joined is skipped.
//! 3. **Snapping**: the contour vertices within two curve steps of a curve (away from corners)
//!    are projected onto their side of the crease — the plane through the nearest curve point
//!    spanned by the curve's tangent and the mean direction, across the curve, of the cloud
//!    points on that side — so the contour's rounded strip becomes a sharp dihedral; then the
//!    corner vertices go to the corners and every path vertex to the nearest point of its
//!    curve. A move that would flip or nearly collapse a triangle is not made.
//!
//! Positions move, connectivity does not: genus, boundary loops and manifoldness are kept.
//! Cost: `O(F)` for the adjacency, `O(S log V)` for the `S` curve samples, and the Dijkstra
//! searches are local (between anchors a curve step apart).

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap, HashSet};

use subfit_mesh::vec3::{add, cross, dot, norm, norm2, normalize, scale, sub};
use subfit_mesh::PolyMesh;
use subfit_target::{CloudFeatures, FeaturePolyline, PointIndex};

use crate::simplify::FeatureLock;

/// What [`snap_to_features`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SnapReport {
    /// Contour edges locked as creases.
    pub edges: usize,
    /// Curves traced (at least one edge).
    pub curves: usize,
    /// Corner vertices.
    pub corners: usize,
    /// Path vertices moved onto their curve.
    pub moved: usize,
    /// Path vertices left in place because moving them would fold a triangle.
    pub kept: usize,
}

/// Traces the curves of `features` (normalized units, like `mesh`) on the triangle mesh `mesh`
/// and moves the traced vertices onto them (see the module docs). Returns the lock for
/// [`crate::simplify_with_features`] (edges and corners in `mesh`'s vertex ids) and a report.
/// Faces that are not triangles are fan-triangulated for the adjacency and the fold test.
/// With `cloud` (the cloud's points and their kd-tree, same units), the contour vertices
/// within two curve steps of a curve are first flattened onto their side of the crease
/// (step 3 of the module docs).
pub fn snap_to_features(
    mesh: &mut PolyMesh,
    features: &CloudFeatures,
    cloud: Option<(&[[f64; 3]], &PointIndex)>,
) -> (FeatureLock, SnapReport) {
    let mut report = SnapReport::default();
    let nv = mesh.positions.len();
    let tris = mesh.faces.triangulate_fan();
    let Some(index) = PointIndex::new(&mesh.positions) else {
        return (FeatureLock::default(), report);
    };
    if features.is_empty() || tris.is_empty() {
        return (FeatureLock::default(), report);
    }
    let fan = Fan::new(tris, nv);
    // 1. Corners.
    let corner_vertex: Vec<u32> = features
        .corners
        .iter()
        .map(|c| index.nearest(c).index)
        .collect();
    let mut blocked = vec![false; nv];
    let mut is_corner = vec![false; nv];
    for &v in &corner_vertex {
        is_corner[v as usize] = true;
    }
    let mut lock_edges: Vec<[u32; 2]> = Vec::new();
    let mut moves: Vec<(u32, usize)> = Vec::new(); // (vertex, curve)

    // 2. Paths.
    for (ci, curve) in features.curves.iter().enumerate() {
        let anchors = curve_anchors(curve, &index, &corner_vertex, &is_corner, &blocked);
        if anchors.len() < 2 {
            continue;
        }
        let on_path = trace_path(
            &mesh.positions,
            &fan.adj,
            curve,
            features.step,
            &anchors,
            &blocked,
            &mut lock_edges,
        );
        let before = lock_edges.len();
        for &v in &on_path {
            if !is_corner[v as usize] {
                blocked[v as usize] = true;
                moves.push((v, ci));
            }
        }
        if lock_edges.len() > before || !on_path.is_empty() {
            report.curves += 1;
        }
    }
    // 3. Snapping: the sides next to the curves flattened, then the corners, then the paths.
    let targets = snap_targets(
        &mesh.positions,
        features,
        cloud,
        &blocked,
        &is_corner,
        &corner_vertex,
        moves,
    );
    apply_moves(
        &mut mesh.positions,
        &fan,
        &blocked,
        &is_corner,
        targets,
        &mut report,
    );
    feature_lock(lock_edges, corner_vertex, report)
}

/// The contour's faces fan-triangulated, with the neighbours of every vertex (sorted, no
/// repeats) and the triangles around it.
struct Fan {
    tris: Vec<[u32; 3]>,
    adj: Vec<Vec<u32>>,
    vert_tris: Vec<Vec<u32>>,
}

impl Fan {
    /// The adjacency of `tris` over `nv` vertices. `O(F)`.
    fn new(tris: Vec<[u32; 3]>, nv: usize) -> Self {
        let mut adj: Vec<Vec<u32>> = vec![Vec::new(); nv];
        let mut vert_tris: Vec<Vec<u32>> = vec![Vec::new(); nv];
        for (t, tri) in tris.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                adj[a as usize].push(b);
                adj[b as usize].push(a);
                vert_tris[a as usize].push(t as u32);
            }
        }
        for a in &mut adj {
            a.sort_unstable();
            a.dedup();
        }
        Self {
            tris,
            adj,
            vert_tris,
        }
    }
}

/// Step 2, the anchors of one curve: the contour vertices nearest its samples, curve ends at
/// corners anchored at the corner vertices, consecutive duplicates merged, vertices of paths
/// already traced (`blocked`, except corners) dropped.
fn curve_anchors(
    curve: &FeaturePolyline,
    index: &PointIndex,
    corner_vertex: &[u32],
    is_corner: &[bool],
    blocked: &[bool],
) -> Vec<u32> {
    let mut anchors: Vec<u32> = curve
        .points
        .iter()
        .map(|p| index.nearest(p).index)
        .collect();
    if !curve.closed {
        if let Some(k) = curve.ends[0] {
            anchors[0] = corner_vertex[k as usize];
        }
        if let Some(k) = curve.ends[1] {
            *anchors.last_mut().expect("a curve has points") = corner_vertex[k as usize];
        }
    }
    anchors.dedup();
    if curve.closed && anchors.len() > 1 && anchors.first() == anchors.last() {
        anchors.pop();
    }
    // Anchors of other paths (not corners) cannot be used: drop them.
    anchors.retain(|&a| is_corner[a as usize] || !blocked[a as usize]);
    anchors
}

/// Step 2, the path of one curve: consecutive `anchors` (at least two) joined by Dijkstra
/// shortest edge paths over `adj` that avoid `blocked` vertices; a piece that cannot be joined
/// is skipped and the path restarts after it. The chains' edges go to `lock_edges`; returns the
/// vertices on the path. `step`: the curves' sampling step.
fn trace_path(
    positions: &[[f64; 3]],
    adj: &[Vec<u32>],
    curve: &FeaturePolyline,
    step: f64,
    anchors: &[u32],
    blocked: &[bool],
    lock_edges: &mut Vec<[u32; 2]>,
) -> HashSet<u32> {
    let mut path: Vec<u32> = vec![anchors[0]];
    let mut on_path: HashSet<u32> = HashSet::new();
    on_path.insert(anchors[0]);
    let mut pairs: Vec<(u32, u32)> = anchors.windows(2).map(|w| (w[0], w[1])).collect();
    if curve.closed && anchors.len() > 2 {
        pairs.push((anchors[anchors.len() - 1], anchors[0]));
    }
    let first = anchors[0];
    for (from, to) in pairs {
        if *path.last().expect("non-empty") != from {
            // The previous piece failed: restart the path here.
            flush(&mut path, lock_edges);
            path.push(from);
            on_path.insert(from);
        }
        let closing = to == first;
        let allowed = |v: u32| {
            v == to || (!blocked[v as usize] && !on_path.contains(&v)) || (closing && v == first)
        };
        // Edges are dearer away from the curve, so the path hugs it and its vertices can
        // move onto it without passing over others.
        let weight = |v: u32| {
            let p = positions[v as usize];
            let d2 = norm2(sub(closest_on_polyline(&curve.points, curve.closed, p), p));
            1.0 + 4.0 * d2 / (step * step)
        };
        let piece = shortest_path(positions, adj, from, to, allowed, weight);
        let Some(piece) = piece else { continue };
        for &v in &piece[1..] {
            on_path.insert(v);
        }
        path.extend_from_slice(&piece[1..]);
    }
    flush(&mut path, lock_edges);
    on_path
}

/// Step 3, where vertices go: with the `cloud`, the free vertices near a curve onto their side
/// of the crease ([`flatten_target`]); then the corner vertices onto the corners; then the path
/// vertices (`moves`: vertex and curve) onto the nearest point of their curve.
fn snap_targets(
    positions: &[[f64; 3]],
    features: &CloudFeatures,
    cloud: Option<(&[[f64; 3]], &PointIndex)>,
    blocked: &[bool],
    is_corner: &[bool],
    corner_vertex: &[u32],
    mut moves: Vec<(u32, usize)>,
) -> Vec<(u32, [f64; 3])> {
    let nv = positions.len();
    let mut targets: Vec<(u32, [f64; 3])> = Vec::new();
    if let Some((points, cloud_index)) = cloud {
        let reach = 2.0 * features.step;
        for w in 0..nv as u32 {
            if blocked[w as usize] || is_corner[w as usize] {
                continue;
            }
            let p = positions[w as usize];
            if let Some(to) = flatten_target(p, features, points, cloud_index, reach) {
                targets.push((w, to));
            }
        }
    }
    targets.extend(
        corner_vertex
            .iter()
            .zip(&features.corners)
            .map(|(&v, &c)| (v, c)),
    );
    moves.sort_unstable();
    for &(v, ci) in &moves {
        let c = &features.curves[ci];
        targets.push((
            v,
            closest_on_polyline(&c.points, c.closed, positions[v as usize]),
        ));
    }
    targets
}

/// Step 3, the moves: each target tried in turn, a move that would flip or nearly collapse a
/// triangle not made; counts go to `report`.
fn apply_moves(
    positions: &mut [[f64; 3]],
    fan: &Fan,
    blocked: &[bool],
    is_corner: &[bool],
    mut targets: Vec<(u32, [f64; 3])>,
    report: &mut SnapReport,
) {
    let (tris, adj, vert_tris) = (&fan.tris, &fan.adj, &fan.vert_tris);
    // A move blocked by a neighbour that has not moved yet may pass once it has; one still
    // blocked gets its free neighbours (neither on a path nor a corner) relaxed to the mean of
    // theirs, to untangle the strip. A few rounds.
    for round in 0..6 {
        if round > 0 {
            for &(v, _) in &targets {
                for &w in &adj[v as usize] {
                    let wi = w as usize;
                    if blocked[wi] || is_corner[wi] || adj[wi].is_empty() {
                        continue;
                    }
                    let m = scale(
                        adj[wi]
                            .iter()
                            .fold([0.0; 3], |acc, &x| add(acc, positions[x as usize])),
                        1.0 / adj[wi].len() as f64,
                    );
                    try_move(positions, tris, &vert_tris[wi], w, m);
                }
            }
        }
        let before = targets.len();
        targets.retain(|&(v, to)| !try_move(positions, tris, &vert_tris[v as usize], v, to));
        report.moved += before - targets.len();
        if targets.is_empty() {
            break;
        }
    }
    report.kept = targets.len();
    // What still cannot move all the way goes as far as it can (halving the step).
    for &(v, to) in &targets {
        let from = positions[v as usize];
        for f in [0.75, 0.5, 0.25] {
            let p = add(from, scale(sub(to, from), f));
            if try_move(positions, tris, &vert_tris[v as usize], v, p) {
                break;
            }
        }
    }
}

/// The lock for [`crate::simplify_with_features`]: the traced edges and the corner vertices,
/// sorted and without repeats, their counts in `report`.
fn feature_lock(
    mut lock_edges: Vec<[u32; 2]>,
    corner_vertex: Vec<u32>,
    mut report: SnapReport,
) -> (FeatureLock, SnapReport) {
    for e in &mut lock_edges {
        e.sort_unstable();
    }
    lock_edges.sort_unstable();
    lock_edges.dedup();
    let mut corners = corner_vertex;
    corners.sort_unstable();
    corners.dedup();
    report.edges = lock_edges.len();
    report.corners = corners.len();
    (
        FeatureLock {
            edges: lock_edges,
            corners,
        },
        report,
    )
}

/// Where a contour vertex `w` within `reach` of a curve (and not within `2 reach` of a
/// corner) goes to lie on its side of the crease: the cloud points within `2 reach` of the
/// nearest curve point `c` are split into the crease's two sides by the direction of their
/// offsets from `c` across the curve tangent `t` (2-means, seeded by the most opposed pair); the
/// side `w` lies on is the plane through `c` spanned by `t` and that side's mean direction,
/// and `w` is projected onto it. `None` when `w` is farther, the sides are not clear, or the
/// move would exceed `reach`.
fn flatten_target(
    w: [f64; 3],
    features: &CloudFeatures,
    points: &[[f64; 3]],
    index: &PointIndex,
    reach: f64,
) -> Option<[f64; 3]> {
    if features
        .corners
        .iter()
        .any(|c| norm2(sub(*c, w)) < 4.0 * reach * reach)
    {
        return None;
    }
    let (c, t) = features
        .curves
        .iter()
        .filter_map(|cv| closest_with_tangent(&cv.points, cv.closed, w))
        .min_by(|a, b| norm2(sub(a.0, w)).total_cmp(&norm2(sub(b.0, w))))?;
    if norm2(sub(c, w)) > reach * reach {
        return None;
    }
    let across = |q: [f64; 3]| {
        let d = sub(q, c);
        let a = sub(d, scale(t, dot(d, t)));
        normalize(a).filter(|_| norm(a) > 0.25 * reach)
    };
    let dirs: Vec<[f64; 3]> = index
        .within(&c, 2.0 * reach)
        .iter()
        .filter_map(|n| across(points[n.index as usize]))
        .collect();
    if dirs.len() < 6 {
        return None;
    }
    let mut best = (f64::INFINITY, 0, 0);
    for (i, a) in dirs.iter().enumerate() {
        for (j, b) in dirs.iter().enumerate().skip(i + 1) {
            let d = dot(*a, *b);
            if d < best.0 {
                best = (d, i, j);
            }
        }
    }
    let mut centre = [dirs[best.1], dirs[best.2]];
    for _ in 0..3 {
        let mut sum = [[0.0; 3]; 2];
        for d in &dirs {
            let k = usize::from(dot(*d, centre[1]) > dot(*d, centre[0]));
            sum[k] = add(sum[k], *d);
        }
        centre = [normalize(sum[0])?, normalize(sum[1])?];
    }
    // The two sides' directions are opposite where the surface is flat: no crease to sharpen
    // (less than ~25°).
    if dot(centre[0], centre[1]) < -0.9 {
        return None;
    }
    let u = across(w)?;
    let side = centre[usize::from(dot(u, centre[1]) > dot(u, centre[0]))];
    let n = normalize(cross(t, side))?;
    let to = sub(w, scale(n, dot(sub(w, c), n)));
    (norm2(sub(to, w)) <= reach * reach).then_some(to)
}

/// The nearest point to `p` on the polyline and the unit tangent there. `O(n)`.
fn closest_with_tangent(
    points: &[[f64; 3]],
    closed: bool,
    p: [f64; 3],
) -> Option<([f64; 3], [f64; 3])> {
    let n = points.len();
    let segs = if closed { n } else { n.saturating_sub(1) };
    let mut best: Option<(f64, [f64; 3], [f64; 3])> = None;
    for i in 0..segs {
        let (a, b) = (points[i], points[(i + 1) % n]);
        let ab = sub(b, a);
        let l2 = norm2(ab);
        if !(l2 > 0.0) {
            continue;
        }
        let s = (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0);
        let q = add(a, scale(ab, s));
        let d = norm2(sub(p, q));
        if best.is_none_or(|b| d < b.0) {
            best = Some((d, q, ab));
        }
    }
    let (_, q, ab) = best?;
    Some((q, normalize(ab)?))
}

/// Appends the edges of `path` to `edges` and clears it.
fn flush(path: &mut Vec<u32>, edges: &mut Vec<[u32; 2]>) {
    edges.extend(path.windows(2).map(|w| [w[0], w[1]]));
    path.clear();
}

/// Dijkstra shortest edge path from `from` to `to` through vertices `allowed` accepts, an edge
/// costing its length times `weight` of its far end; `None` when unreachable within 4096
/// settled vertices (anchors are a curve step apart, so paths are short).
fn shortest_path(
    pos: &[[f64; 3]],
    adj: &[Vec<u32>],
    from: u32,
    to: u32,
    allowed: impl Fn(u32) -> bool,
    weight: impl Fn(u32) -> f64,
) -> Option<Vec<u32>> {
    let mut dist: HashMap<u32, (f64, u32)> = HashMap::new();
    let mut heap = BinaryHeap::new();
    dist.insert(from, (0.0, from));
    heap.push(Reverse((Ordered(0.0), from)));
    let mut settled = 0usize;
    while let Some(Reverse((Ordered(d), v))) = heap.pop() {
        if dist.get(&v).is_some_and(|&(best, _)| d > best) {
            continue;
        }
        if v == to {
            let mut path = vec![to];
            let mut at = to;
            while at != from {
                at = dist[&at].1;
                path.push(at);
            }
            path.reverse();
            return Some(path);
        }
        settled += 1;
        if settled > 4096 {
            return None;
        }
        for &w in &adj[v as usize] {
            if !allowed(w) {
                continue;
            }
            let nd = d + norm(sub(pos[w as usize], pos[v as usize])) * weight(w);
            if dist.get(&w).is_none_or(|&(best, _)| nd < best) {
                dist.insert(w, (nd, v));
                heap.push(Reverse((Ordered(nd), w)));
            }
        }
    }
    None
}

/// `f64` with a total order, for the heap.
#[derive(Clone, Copy, PartialEq)]
struct Ordered(f64);
impl Eq for Ordered {}
impl PartialOrd for Ordered {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Ordered {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&o.0)
    }
}

/// The nearest point to `p` on the polyline. `O(n)`.
fn closest_on_polyline(points: &[[f64; 3]], closed: bool, p: [f64; 3]) -> [f64; 3] {
    let n = points.len();
    let segs = if closed { n } else { n.saturating_sub(1) };
    let mut best = (f64::INFINITY, points.first().copied().unwrap_or(p));
    for i in 0..segs {
        let (a, b) = (points[i], points[(i + 1) % n]);
        let ab = sub(b, a);
        let l2 = norm2(ab);
        let t = if l2 > 0.0 {
            (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = [0, 1, 2].map(|k| a[k] + t * ab[k]);
        let d = norm2(sub(p, q));
        if d < best.0 {
            best = (d, q);
        }
    }
    best.1
}

/// Moves `v` to `to` unless one of its triangles would flip (normal turning by more than 90°)
/// or shrink below a tenth of its area; returns whether it moved.
fn try_move(pos: &mut [[f64; 3]], tris: &[[u32; 3]], around: &[u32], v: u32, to: [f64; 3]) -> bool {
    let area_normal = |pos: &[[f64; 3]], t: [u32; 3]| {
        let [a, b, c] = t.map(|i| pos[i as usize]);
        cross(sub(b, a), sub(c, a))
    };
    let before: Vec<[f64; 3]> = around
        .iter()
        .map(|&t| area_normal(pos, tris[t as usize]))
        .collect();
    let old = pos[v as usize];
    pos[v as usize] = to;
    let ok = around.iter().zip(&before).all(|(&t, n0)| {
        let n1 = area_normal(pos, tris[t as usize]);
        dot(*n0, n1) > 0.0 && norm(n1) >= 0.01 * norm(*n0)
    });
    if !ok {
        pos[v as usize] = old;
    }
    ok
}
