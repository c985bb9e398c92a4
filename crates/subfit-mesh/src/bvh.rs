//! Exact closest points on a set of triangles through a bounding-volume hierarchy: the closest
//! point on a mesh target (subfit-target) and the nearest triangle of a limit-surface
//! tessellation, the starting guess of the closest point on a subdivision surface
//! (subfit-subdiv).
//!
//! The hierarchy is a binary tree of axis-aligned boxes, down to leaves of at most 4 triangles.
//! [`TriangleBvh::new`] splits each node's triangles at the median of their centroids along
//! the longest axis of the centroids' box (a fast build, for a hierarchy queried about once per
//! triangle). [`TriangleBvh::with_sah`] splits by the surface area heuristic over 16 bins of
//! the centroids along that axis (Wald 2007, "On fast construction of SAH-based bounding
//! volume hierarchies", §3: the cut minimising `area(left)·#left + area(right)·#right`), down
//! to depth [`SAH_DEPTH`]: long thin triangles (tessellated CAD, aspect ratios up to 1e5) then
//! get boxes of their own instead of inflating their neighbours' — for a hierarchy built once
//! and queried many times (a mesh target's). A query descends the nearer child first and skips boxes no nearer than the
//! best distance so far. The point–triangle test is Ericson, *Real-Time Collision Detection*
//! (2005), §5.1.5 (Voronoi regions of the vertices and edges, barycentric result).
//!
//! Triangles are indexed (`#V by 3` vertices, `#T by 3` indices); a triangle soup is indexed
//! trivially ([`TriangleBvh::from_triangles`]). Leaves read copies of their triangles' corners
//! stored in leaf order, so a query touches contiguous memory.

use crate::vec3::{add, cross, dot, normalize, scale, sub};

/// Closest point on the triangles to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshClosestPoint {
    /// The closest point (same units as the vertices).
    pub point: [f64; 3],
    /// Index of the triangle in the list given to the constructor.
    pub triangle: u32,
    /// Barycentric coordinates of `point` in that triangle, for its corners in order (sum 1,
    /// all ≥ 0).
    pub barycentric: [f64; 3],
    /// Unsigned Euclidean distance from the query to `point`.
    pub distance: f64,
    /// Unit normal of the triangle (right-hand rule on its vertex order); `[0,0,0]` for a
    /// degenerate triangle. At edges and vertices this is one adjacent face's normal, so
    /// `(x − point)·normal` may have the wrong sign there.
    pub face_normal: [f64; 3],
}

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: [f64; 3],
    hi: [f64; 3],
    /// Leaf: first slot in `order`; inner: index of the left child (right = left + 1).
    first: u32,
    /// Leaf: number of triangles (> 0); inner: 0.
    count: u32,
}

const BLANK: Node = Node {
    lo: [0.0; 3],
    hi: [0.0; 3],
    first: 0,
    count: 0,
};

/// Most triangles in a leaf.
const LEAF: usize = 4;

/// Depth of the traversal stack: a depth-first traversal that pushes both children holds at
/// most one entry per level plus one. SAH splits are made down to depth [`SAH_DEPTH`] only;
/// below it a median split halves the triangles at every level (at most `log2(#T / LEAF) + 1
/// < 32` more), so the tree is under 56 deep.
const STACK: usize = 64;

/// Deepest level split by the surface area heuristic (see the module doc and [`STACK`]).
const SAH_DEPTH: usize = 24;

/// Centroid bins per axis of the SAH split.
const BINS: usize = 16;

/// A BVH over triangles. Built in O(#T log #T); a query visits O(log #T) nodes on typical
/// meshes. Memory: the vertices and indices, one copy of the corners (`72 · #T` bytes) and
/// about `2 · #T / LEAF` nodes of 56 bytes.
#[derive(Clone, Debug)]
pub struct TriangleBvh {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    /// Triangle ids in leaf order.
    order: Vec<u32>,
    /// The corners of triangle `order[s]` at slot `s`.
    corners: Vec<[[f64; 3]; 3]>,
    nodes: Vec<Node>,
}

impl TriangleBvh {
    /// Builds the hierarchy over `triangles` (`#T by 3`), which index into `vertices`
    /// (`#V by 3`). Empty triangle lists give a BVH whose queries return `None`.
    ///
    /// # Panics
    /// If an index is out of range of `vertices` (not otherwise checked: mesh targets validate
    /// their indices first).
    #[track_caller]
    pub fn new(vertices: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Self {
        Self::build_with(vertices, triangles, false)
    }

    /// [`Self::new`] with surface-area-heuristic splits (see the module doc): a slower build,
    /// faster queries on meshes with long thin triangles. The same closest distances as
    /// [`Self::new`]'s (among equidistant triangles another may be met first).
    ///
    /// # Panics
    /// As [`Self::new`].
    #[track_caller]
    pub fn with_sah(vertices: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Self {
        Self::build_with(vertices, triangles, true)
    }

    #[track_caller]
    fn build_with(vertices: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>, sah: bool) -> Self {
        let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
        let cent: Vec<[f64; 3]> = triangles
            .iter()
            .map(|t| {
                let s = add(
                    add(vertices[t[0] as usize], vertices[t[1] as usize]),
                    vertices[t[2] as usize],
                );
                scale(s, 1.0 / 3.0)
            })
            .collect();
        let mut bvh = Self {
            vertices,
            triangles,
            order: Vec::new(),
            corners: Vec::new(),
            nodes: Vec::new(),
        };
        if !bvh.triangles.is_empty() {
            bvh.nodes.push(BLANK);
            let n = order.len();
            let boxes: Vec<Aabb> = bvh
                .triangles
                .iter()
                .map(|t| Aabb::of(t.map(|v| bvh.vertices[v as usize])))
                .collect();
            let depth = if sah { 0 } else { SAH_DEPTH };
            bvh.build(0, &mut order, (0, n), &cent, &boxes, depth);
        }
        bvh.corners = order
            .iter()
            .map(|&t| bvh.triangles[t as usize].map(|v| bvh.vertices[v as usize]))
            .collect();
        bvh.order = order;
        bvh
    }

    /// Builds the hierarchy over a triangle soup (`#T by 3 by 3` corner positions), indexed
    /// trivially: triangle `t` has vertices `3t, 3t + 1, 3t + 2`.
    pub fn from_triangles(triangles: Vec<[[f64; 3]; 3]>) -> Self {
        let ids = (0..triangles.len() as u32)
            .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
            .collect();
        Self::new(triangles.into_iter().flatten().collect(), ids)
    }

    /// Builds node `node` over the triangles `order[start..end]` (centroids `cent`, boxes
    /// `boxes`, by triangle id) at depth `depth`, and its subtree (SAH splits above
    /// [`SAH_DEPTH`], median splits below).
    fn build(
        &mut self,
        node: usize,
        order: &mut [u32],
        (start, end): (usize, usize),
        cent: &[[f64; 3]],
        boxes: &[Aabb],
        depth: usize,
    ) {
        let mut bounds = Aabb::EMPTY;
        let mut cbox = Aabb::EMPTY;
        for &t in &order[start..end] {
            bounds = bounds.union(&boxes[t as usize]);
            cbox = cbox.union(&Aabb::of([cent[t as usize]]));
        }
        self.nodes[node].lo = bounds.lo;
        self.nodes[node].hi = bounds.hi;
        if end - start <= LEAF {
            self.nodes[node].first = start as u32;
            self.nodes[node].count = (end - start) as u32;
            return;
        }
        let axis = cbox.longest_axis();
        let sah = if depth < SAH_DEPTH {
            sah_split(&order[start..end], cent, boxes, &cbox, axis)
        } else {
            None
        };
        let mid = match sah {
            Some(cut) => {
                let (lo, w) = (cbox.lo[axis], cbox.hi[axis] - cbox.lo[axis]);
                start
                    + partition(&mut order[start..end], |t| {
                        bin_of(cent[t as usize][axis], lo, w) <= cut
                    })
            }
            None => {
                let mid = (start + end) / 2;
                order[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
                    cent[a as usize][axis].total_cmp(&cent[b as usize][axis])
                });
                mid
            }
        };
        let left = self.nodes.len();
        self.nodes.push(BLANK);
        self.nodes.push(BLANK);
        self.nodes[node].first = left as u32;
        self.nodes[node].count = 0;
        self.build(left, order, (start, mid), cent, boxes, depth + 1);
        self.build(left + 1, order, (mid, end), cent, boxes, depth + 1);
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// Whether there are no triangles.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// The triangles (`#T by 3`, indices into [`Self::vertices`]).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The vertices (`#V by 3`).
    pub fn vertices(&self) -> &[[f64; 3]] {
        &self.vertices
    }

    /// The normal `(b − a) × (c − a)` of triangle `t` (right-hand rule on its corners' order;
    /// not normalized: its length is twice the area). Panics if `t` is out of range.
    pub fn triangle_normal(&self, t: u32) -> [f64; 3] {
        let [a, b, c] = self.triangles[t as usize].map(|v| self.vertices[v as usize]);
        cross(sub(b, a), sub(c, a))
    }

    /// The exact closest point on the triangles to `x`, or `None` when there are no
    /// triangles. Among triangles at the same distance, the first one the traversal meets wins.
    /// Allocates nothing.
    pub fn closest(&self, x: [f64; 3]) -> Option<MeshClosestPoint> {
        self.closest_bounded(x, f64::INFINITY)
    }

    /// [`Self::closest`] started from a guess: triangle `hint` (e.g. the closest one of a
    /// nearby or earlier query point) bounds the search by its own distance, so that boxes
    /// farther than it are never opened. The same result as [`Self::closest`], ties included
    /// (the traversal order is the same; only boxes that cannot hold the answer are skipped).
    /// An out-of-range `hint` is ignored.
    pub fn closest_near(&self, x: [f64; 3], hint: u32) -> Option<MeshClosestPoint> {
        let Some(t) = self.triangles.get(hint as usize) else {
            return self.closest(x);
        };
        let [a, b, c] = t.map(|v| self.vertices[v as usize]);
        let (p, _) = closest_on_triangle(x, a, b, c);
        let d = sub(x, p);
        let bound = dot(d, d);
        self.closest_bounded(x, if bound.is_nan() { f64::INFINITY } else { bound })
            .or_else(|| self.closest(x))
    }

    /// [`Self::closest`] among the triangles within squared distance `bound` (`None` when none
    /// is): nodes whose box is farther than `bound` are skipped.
    fn closest_bounded(&self, x: [f64; 3], bound: f64) -> Option<MeshClosestPoint> {
        self.closest_accepted(x, bound, |_| true)
    }

    /// [`Self::closest`] among the triangles that `accept` admits (by index) within squared
    /// distance `bound` (`None` when none is), e.g. only those facing a given direction.
    /// Boxes farther than `bound` or than the best admitted triangle so far are not opened.
    pub fn closest_accepted(
        &self,
        x: [f64; 3],
        bound: f64,
        accept: impl Fn(u32) -> bool,
    ) -> Option<MeshClosestPoint> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut best = f64::INFINITY;
        let mut best_hit: Option<(u32, [f64; 3], [f64; 3])> = None;
        let mut stack = [(0u32, 0.0f64); STACK];
        stack[0] = (0, box_dist2(&self.nodes[0], x));
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (ni, d2) = stack[top];
            if d2 >= best || d2 > bound {
                continue;
            }
            let node = self.nodes[ni as usize];
            if node.count > 0 {
                let s = node.first as usize;
                let slots = s..s + node.count as usize;
                for (&t, &[a, b, c]) in self.order[slots.clone()].iter().zip(&self.corners[slots]) {
                    if !accept(t) {
                        continue;
                    }
                    let (p, bary) = closest_on_triangle(x, a, b, c);
                    let dd = sub(x, p);
                    let dd = dot(dd, dd);
                    if dd < best && dd <= bound {
                        best = dd;
                        best_hit = Some((t, p, bary));
                    }
                }
            } else {
                let l = node.first;
                let (dl, dr) = (
                    box_dist2(&self.nodes[l as usize], x),
                    box_dist2(&self.nodes[l as usize + 1], x),
                );
                // Push the farther first so the nearer is visited first.
                let (first, second) = if dl < dr {
                    ((l + 1, dr), (l, dl))
                } else {
                    ((l, dl), (l + 1, dr))
                };
                stack[top] = first;
                stack[top + 1] = second;
                top += 2;
            }
        }
        let (t, point, barycentric) = best_hit?;
        let [a, b, c] = self.triangles[t as usize].map(|v| self.vertices[v as usize]);
        let face_normal = normalize(cross(sub(b, a), sub(c, a))).unwrap_or([0.0; 3]);
        Some(MeshClosestPoint {
            point,
            triangle: t,
            barycentric,
            distance: best.sqrt(),
            face_normal,
        })
    }
}

impl TriangleBvh {
    /// Every triangle within `radius` of `x` with its closest point, in no particular order
    /// (e.g. the other candidates when the nearest one is not enough). Cost: the nodes whose
    /// boxes are within `radius`, and one allocation.
    pub fn within(&self, x: [f64; 3], radius: f64) -> Vec<MeshClosestPoint> {
        let mut out = Vec::new();
        if self.nodes.is_empty() || radius.is_nan() || radius < 0.0 {
            return out;
        }
        let r2 = radius * radius;
        let mut stack = vec![0u32];
        while let Some(ni) = stack.pop() {
            let node = self.nodes[ni as usize];
            if box_dist2(&node, x) > r2 {
                continue;
            }
            if node.count > 0 {
                let s = node.first as usize;
                let slots = s..s + node.count as usize;
                for (&t, &[a, b, c]) in self.order[slots.clone()].iter().zip(&self.corners[slots]) {
                    let (point, barycentric) = closest_on_triangle(x, a, b, c);
                    let dd = sub(x, point);
                    let d2 = dot(dd, dd);
                    if d2 <= r2 {
                        let face_normal =
                            normalize(cross(sub(b, a), sub(c, a))).unwrap_or([0.0; 3]);
                        out.push(MeshClosestPoint {
                            point,
                            triangle: t,
                            barycentric,
                            distance: d2.sqrt(),
                            face_normal,
                        });
                    }
                }
            } else {
                stack.push(node.first);
                stack.push(node.first + 1);
            }
        }
        out
    }
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug)]
struct Aabb {
    lo: [f64; 3],
    hi: [f64; 3],
}

impl Aabb {
    const EMPTY: Self = Self {
        lo: [f64::INFINITY; 3],
        hi: [f64::NEG_INFINITY; 3],
    };

    fn of<const N: usize>(points: [[f64; 3]; N]) -> Self {
        let mut b = Self::EMPTY;
        for p in points {
            b.lo = std::array::from_fn(|k| b.lo[k].min(p[k]));
            b.hi = std::array::from_fn(|k| b.hi[k].max(p[k]));
        }
        b
    }

    fn union(&self, o: &Self) -> Self {
        Self {
            lo: std::array::from_fn(|k| self.lo[k].min(o.lo[k])),
            hi: std::array::from_fn(|k| self.hi[k].max(o.hi[k])),
        }
    }

    /// Half the surface area (0 for an empty box).
    fn half_area(&self) -> f64 {
        let e: [f64; 3] = std::array::from_fn(|k| (self.hi[k] - self.lo[k]).max(0.0));
        e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
    }

    fn longest_axis(&self) -> usize {
        (0..3)
            .max_by(|&a, &b| (self.hi[a] - self.lo[a]).total_cmp(&(self.hi[b] - self.lo[b])))
            .unwrap_or(0)
    }
}

/// The bin (0..[`BINS`]) of centroid coordinate `c` over a centroid extent starting at `lo`
/// of width `w > 0`.
#[inline]
fn bin_of(c: f64, lo: f64, w: f64) -> usize {
    (((c - lo) / w * BINS as f64) as usize).min(BINS - 1)
}

/// The SAH split along `axis` of the triangles `ids` (centroids `cent`, boxes `boxes`, by id)
/// whose centroids span `cbox`: the last bin of the left side, or `None` when no cut between
/// bins leaves triangles on both sides (every centroid in one bin): the caller splits at the
/// median.
fn sah_split(
    ids: &[u32],
    cent: &[[f64; 3]],
    boxes: &[Aabb],
    cbox: &Aabb,
    axis: usize,
) -> Option<usize> {
    let (lo, w) = (cbox.lo[axis], cbox.hi[axis] - cbox.lo[axis]);
    if !(w > 0.0 && w.is_finite()) {
        return None;
    }
    let mut bins = [(Aabb::EMPTY, 0usize); BINS];
    for &t in ids {
        let b = &mut bins[bin_of(cent[t as usize][axis], lo, w)];
        b.0 = b.0.union(&boxes[t as usize]);
        b.1 += 1;
    }
    // Right-side areas and counts for cuts after bin i (i = 0..BINS-2).
    let mut right = [(0.0, 0usize); BINS];
    let (mut acc, mut n) = (Aabb::EMPTY, 0);
    for i in (1..BINS).rev() {
        acc = acc.union(&bins[i].0);
        n += bins[i].1;
        right[i - 1] = (acc.half_area(), n);
    }
    let mut best: Option<(f64, usize)> = None;
    let (mut acc, mut n) = (Aabb::EMPTY, 0);
    for (i, bin) in bins.iter().enumerate().take(BINS - 1) {
        acc = acc.union(&bin.0);
        n += bin.1;
        let (ra, rn) = right[i];
        if n == 0 || rn == 0 {
            continue;
        }
        let cost = acc.half_area() * n as f64 + ra * rn as f64;
        if best.is_none_or(|b| cost < b.0) {
            best = Some((cost, i));
        }
    }
    best.map(|(_, cut)| cut)
}

/// Moves the ids for which `left` holds to the front (unstable); returns how many there are.
fn partition(ids: &mut [u32], left: impl Fn(u32) -> bool) -> usize {
    let mut i = 0;
    for j in 0..ids.len() {
        if left(ids[j]) {
            ids.swap(i, j);
            i += 1;
        }
    }
    i
}

/// Squared distance from `x` to the box of node `n` (0 inside).
#[inline]
fn box_dist2(n: &Node, x: [f64; 3]) -> f64 {
    let e = |k: usize| (n.lo[k] - x[k]).max(0.0).max(x[k] - n.hi[k]);
    let (e0, e1, e2) = (e(0), e(1), e(2));
    e0 * e0 + e1 * e1 + e2 * e2
}

/// Closest point of triangle `abc` to `p`, and its barycentric coordinates for `a, b, c`
/// (Ericson 2005, §5.1.5). A degenerate (zero-area) triangle that reaches the interior case
/// gives its nearest corner. Cost: a few dozen flops.
#[allow(
    clippy::neg_cmp_op_on_partial_ord,
    reason = "`!(x > 0.0)` is true for NaN, which must take the fallback"
)]
pub fn closest_on_triangle(
    p: [f64; 3],
    a: [f64; 3],
    b: [f64; 3],
    c: [f64; 3],
) -> ([f64; 3], [f64; 3]) {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (add(a, scale(ab, v)), [1.0 - v, v, 0.0]);
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (add(a, scale(ac, w)), [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (add(b, scale(sub(c, b), w)), [0.0, 1.0 - w, w]);
    }
    let denom = va + vb + vc;
    if !(denom.abs() > 0.0) || !denom.is_finite() {
        // Degenerate (zero-area) triangle that slipped through the tests above: nearest vertex.
        let cands = [
            (a, [1.0, 0.0, 0.0]),
            (b, [0.0, 1.0, 0.0]),
            (c, [0.0, 0.0, 1.0]),
        ];
        return cands
            .into_iter()
            .min_by(|x, y| {
                let dx = sub(p, x.0);
                let dy = sub(p, y.0);
                dot(dx, dx).total_cmp(&dot(dy, dy))
            })
            .unwrap_or((a, [1.0, 0.0, 0.0]));
    }
    let inv = 1.0 / denom;
    let v = vb * inv;
    let w = vc * inv;
    (add(a, add(scale(ab, v), scale(ac, w))), [1.0 - v - w, v, w])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vec3::dist2;

    /// Indexed mesh: a small bumpy grid (from subfit-target's mesh closest-point tests).
    #[test]
    fn brute_force_agrees() {
        let m = 12;
        let mut v = Vec::new();
        for i in 0..=m {
            for j in 0..=m {
                let (x, y) = (i as f64 / m as f64, j as f64 / m as f64);
                v.push([x, y, 0.1 * (7.0 * x).sin() * (5.0 * y).cos()]);
            }
        }
        let mut t = Vec::new();
        for i in 0..m {
            for j in 0..m {
                let a = (i * (m + 1) + j) as u32;
                let b = a + (m + 1) as u32;
                t.push([a, b, a + 1]);
                t.push([a + 1, b, b + 1]);
            }
        }
        let bvh = TriangleBvh::new(v.clone(), t.clone());
        let mut s = 12345u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..200 {
            let x = [rnd() * 1.4 - 0.2, rnd() * 1.4 - 0.2, rnd() - 0.5];
            // `within` finds exactly the triangles a scan of all finds within the radius.
            let radius = 0.05 + 0.2 * rnd();
            let mut near: Vec<u32> = bvh.within(x, radius).iter().map(|h| h.triangle).collect();
            near.sort_unstable();
            let all: Vec<u32> = (0..t.len() as u32)
                .filter(|&k| {
                    let tr = t[k as usize];
                    let (p, _) = closest_on_triangle(
                        x,
                        v[tr[0] as usize],
                        v[tr[1] as usize],
                        v[tr[2] as usize],
                    );
                    dist2(x, p) <= radius * radius
                })
                .collect();
            assert_eq!(near, all);
            let hit = bvh.closest(x).unwrap();
            let brute = t
                .iter()
                .map(|tr| {
                    let (p, _) = closest_on_triangle(
                        x,
                        v[tr[0] as usize],
                        v[tr[1] as usize],
                        v[tr[2] as usize],
                    );
                    let d = sub(x, p);
                    dot(d, d).sqrt()
                })
                .fold(f64::INFINITY, f64::min);
            assert!((hit.distance - brute).abs() < 1e-12);
            let b = hit.barycentric;
            assert!((b[0] + b[1] + b[2] - 1.0).abs() < 1e-12);
        }
    }

    /// Triangle soup: 300 random small triangles (from subfit-subdiv's tessellation BVH tests).
    #[test]
    fn nearest_matches_brute_force() {
        let mut s = 1u64;
        let mut r = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let tris: Vec<[[f64; 3]; 3]> = (0..300)
            .map(|_| {
                let c = [r(), r(), r()];
                [0, 1, 2].map(|_| [c[0] + 0.1 * r(), c[1] + 0.1 * r(), c[2] + 0.1 * r()])
            })
            .collect();
        let bvh = TriangleBvh::from_triangles(tris.clone());
        for _ in 0..200 {
            let q = [1.4 * r() - 0.2, 1.4 * r() - 0.2, 1.4 * r() - 0.2];
            let n = bvh.closest(q).unwrap();
            let bf = tris
                .iter()
                .map(|&[a, b, c]| dist2(q, closest_on_triangle(q, a, b, c).0))
                .fold(f64::INFINITY, f64::min);
            assert!((dist2(q, n.point) - bf).abs() <= 1e-15);
            let t = &tris[n.triangle as usize];
            let b = n.barycentric;
            for (k, pk) in n.point.iter().enumerate() {
                let x = b[0] * t[0][k] + b[1] * t[1][k] + b[2] * t[2][k];
                assert!((x - pk).abs() < 1e-14);
            }
        }
        assert!(TriangleBvh::from_triangles(Vec::new())
            .closest([0.0; 3])
            .is_none());
    }

    /// Slivers (aspect ratios up to 1e6, as in tessellated CAD) among ordinary triangles: the
    /// SAH tree finds the brute-force closest point, and a query started from any hint
    /// ([`TriangleBvh::closest_near`]) returns exactly what [`TriangleBvh::closest`] does.
    #[test]
    fn slivers_and_hints_agree_with_brute_force() {
        let mut s = 7u64;
        let mut r = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut tris: Vec<[[f64; 3]; 3]> = Vec::new();
        for i in 0..400 {
            let c = [r(), r(), r()];
            if i % 3 == 0 {
                // A sliver: long along a random axis, 1e-6 wide.
                let len = 0.3 + 0.7 * r();
                let a = [r() - 0.5, r() - 0.5, r() - 0.5];
                let b = [c[0] + len * a[0], c[1] + len * a[1], c[2] + len * a[2]];
                tris.push([c, b, [c[0] + 1e-6, c[1], c[2] + 1e-6]]);
            } else {
                tris.push(
                    [0, 1, 2].map(|_| [c[0] + 0.05 * r(), c[1] + 0.05 * r(), c[2] + 0.05 * r()]),
                );
            }
        }
        let bvh = TriangleBvh::from_triangles(tris.clone());
        let corners: Vec<[f64; 3]> = tris.iter().flatten().copied().collect();
        let ids = (0..tris.len() as u32)
            .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
            .collect();
        let sah = TriangleBvh::with_sah(corners, ids);
        for _ in 0..300 {
            let q = [1.4 * r() - 0.2, 1.4 * r() - 0.2, 1.4 * r() - 0.2];
            let n = bvh.closest(q).unwrap();
            let bf = tris
                .iter()
                .map(|&[a, b, c]| dist2(q, closest_on_triangle(q, a, b, c).0))
                .fold(f64::INFINITY, f64::min);
            assert!((dist2(q, n.point) - bf).abs() <= 1e-15);
            let m = sah.closest(q).unwrap();
            assert!((dist2(q, m.point) - bf).abs() <= 1e-15);
            assert_eq!(sah.closest_near(q, m.triangle), Some(m));
            let hint = (r() * tris.len() as f64) as u32;
            assert_eq!(bvh.closest_near(q, hint), Some(n));
            assert_eq!(bvh.closest_near(q, n.triangle), Some(n));
            assert_eq!(bvh.closest_near(q, u32::MAX), Some(n));
        }
    }
}
