//! Feature-aligned contours of point clouds: the dense contour is snapped to the cloud's
//! crease curves (issue 15).
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
//! 3. **Snapping**: every path vertex is moved to the nearest point of its curve, unless the
//!    move would flip or nearly collapse one of its triangles (then it stays).
//!
//! Positions move, connectivity does not: genus, boundary loops and manifoldness are kept.
//! Cost: `O(F)` for the adjacency, `O(S log V)` for the `S` curve samples, and the Dijkstra
//! searches are local (between anchors a curve step apart).

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap, HashSet};

use subfit_mesh::vec3::{cross, dot, norm, norm2, sub};
use subfit_mesh::PolyMesh;
use subfit_target::{detect_cloud_features, CloudFeatures, FeatureOptions, PointIndex, Target};

use crate::init::{FeatureCounts, InitReport};
use crate::simplify::FeatureLock;

/// The hook of [`crate::initial_control_mesh`] for point clouds with
/// [`crate::InitOptions::features`]: detects the cloud's features, snaps `dense` (the trimmed
/// contour, normalized units) to them and fills `report.features` (edges: contour edges
/// locked).
pub(crate) fn cloud_feature_lock(
    target: &Target,
    dense: &mut PolyMesh,
    options: &FeatureOptions,
    report: &mut InitReport,
) -> FeatureLock {
    let f = detect_cloud_features(target, options);
    let (lock, snap) = snap_to_features(dense, &f);
    report.features = Some(FeatureCounts {
        edges: snap.edges,
        curves: f.curves.len(),
        corners: f.corners.len(),
        darts: f.darts,
    });
    lock
}

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
pub fn snap_to_features(
    mesh: &mut PolyMesh,
    features: &CloudFeatures,
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
        if anchors.len() < 2 {
            continue;
        }
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
                flush(&mut path, &mut lock_edges);
                path.push(from);
            }
            let closing = to == first;
            let piece = shortest_path(&mesh.positions, &adj, from, to, |v| {
                v == to
                    || (!blocked[v as usize] && !on_path.contains(&v))
                    || (closing && v == first)
            });
            let Some(piece) = piece else { continue };
            for &v in &piece[1..] {
                on_path.insert(v);
            }
            path.extend_from_slice(&piece[1..]);
        }
        flush(&mut path, &mut lock_edges);
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
    // 3. Snapping (corners first, then the path vertices).
    let mut targets: Vec<(u32, [f64; 3])> = corner_vertex
        .iter()
        .zip(&features.corners)
        .map(|(&v, &c)| (v, c))
        .collect();
    moves.sort_unstable();
    for &(v, ci) in &moves {
        let c = &features.curves[ci];
        targets.push((
            v,
            closest_on_polyline(&c.points, c.closed, mesh.positions[v as usize]),
        ));
    }
    for (v, to) in targets {
        if try_move(&mut mesh.positions, &tris, &vert_tris[v as usize], v, to) {
            report.moved += 1;
        } else {
            report.kept += 1;
        }
    }
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

/// Appends the edges of `path` to `edges` and clears it.
fn flush(path: &mut Vec<u32>, edges: &mut Vec<[u32; 2]>) {
    edges.extend(path.windows(2).map(|w| [w[0], w[1]]));
    path.clear();
}

/// Dijkstra shortest edge path from `from` to `to` through vertices `allowed` accepts; `None`
/// when unreachable within 64 settled vertices' worth of search radius (anchors are a curve
/// step apart, so paths are short).
fn shortest_path(
    pos: &[[f64; 3]],
    adj: &[Vec<u32>],
    from: u32,
    to: u32,
    allowed: impl Fn(u32) -> bool,
) -> Option<Vec<u32>> {
    let limit = 4.0 * norm(sub(pos[to as usize], pos[from as usize])).max(f64::MIN_POSITIVE);
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
        if settled > 4096 || d > limit + 1e-12 {
            continue;
        }
        for &w in &adj[v as usize] {
            if !allowed(w) {
                continue;
            }
            let nd = d + norm(sub(pos[w as usize], pos[v as usize]));
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
        dot(*n0, n1) > 0.0 && norm(n1) >= 0.1 * norm(*n0)
    });
    if !ok {
        pos[v as usize] = old;
    }
    ok
}
