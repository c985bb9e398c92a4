//! The dense target mesh cut into regions along paths of its edges (Lavoué et al. 2007 §4.4):
//! the boundary loops and every cut made so far are *border* edges; a region is a set of
//! triangles connected across non-border edges, labelled; its contour is the walk along its
//! border edges with the region on the left. The pseudo-geodesic paths of §4.3 are Dijkstra
//! paths over the mesh edges of one region whose inner vertices are all off the border (a path
//! never touches a boundary or an earlier cut, so every cut splits a disc into two discs; the
//! paper instead penalises such paths with 90°).
//!
//! Half-edge `3f + i` of triangle `f` runs from its corner `i` to corner `i + 1`.

use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap};

use subfit_mesh::vec3::dist2;

/// No half-edge, vertex or label.
pub(super) const NONE: u32 = u32::MAX;

/// A triangle mesh with border flags and region labels.
pub(super) struct Surface {
    /// Vertex positions (normalized units).
    pub positions: Vec<[f64; 3]>,
    /// Triangles.
    pub tris: Vec<[u32; 3]>,
    /// Per half-edge: its twin, or [`NONE`] on the mesh boundary.
    twin: Vec<u32>,
    /// Per half-edge: its edge.
    edge_of: Vec<u32>,
    /// Per edge: one of its faces.
    edge_face: Vec<u32>,
    /// Per vertex, CSR offsets into `adjacent`.
    offsets: Vec<u32>,
    /// `(neighbour, edge)` pairs.
    adjacent: Vec<(u32, u32)>,
    /// Per edge: a border (mesh boundary or cut).
    pub border: Vec<bool>,
    /// Per vertex: on a border edge.
    pub on_border: Vec<bool>,
    /// Per face: its region.
    pub label: Vec<u32>,
    /// Per region: its faces.
    pub faces_of: Vec<Vec<u32>>,
}

/// A Dijkstra path: its vertices from the source to the terminal, and its edges.
#[derive(Clone, Debug, Default)]
pub(super) struct Path {
    /// Vertices, source first.
    pub vertices: Vec<u32>,
    /// Edges between consecutive vertices.
    pub edges: Vec<u32>,
}

impl Surface {
    /// The surface of a manifold, oriented triangle mesh (checked by the caller), one region
    /// (label 0) with the mesh boundary as its border. Cost `O(F)` expected.
    pub fn new(positions: Vec<[f64; 3]>, tris: Vec<[u32; 3]>) -> Self {
        let nv = positions.len();
        let nh = 3 * tris.len();
        let mut directed = HashMap::with_capacity(nh);
        for (f, t) in tris.iter().enumerate() {
            for i in 0..3 {
                directed.insert((t[i], t[(i + 1) % 3]), (3 * f + i) as u32);
            }
        }
        let mut twin = vec![NONE; nh];
        let mut edge_of = vec![NONE; nh];
        let mut edge_face = Vec::new();
        let mut ends = Vec::new();
        for h in 0..nh {
            let (a, b) = Self::ends_of(&tris, h);
            if let Some(&t) = directed.get(&(b, a)) {
                twin[h] = t;
            }
            if edge_of[h] == NONE {
                let e = edge_face.len() as u32;
                edge_of[h] = e;
                if twin[h] != NONE {
                    edge_of[twin[h] as usize] = e;
                }
                edge_face.push((h / 3) as u32);
                ends.push([a, b]);
            }
        }
        let mut degree = vec![0u32; nv + 1];
        for &[a, b] in &ends {
            degree[a as usize + 1] += 1;
            degree[b as usize + 1] += 1;
        }
        for v in 0..nv {
            degree[v + 1] += degree[v];
        }
        let offsets = degree;
        let mut fill = offsets.clone();
        let mut adjacent = vec![(0, 0); 2 * ends.len()];
        for (e, &[a, b]) in ends.iter().enumerate() {
            adjacent[fill[a as usize] as usize] = (b, e as u32);
            fill[a as usize] += 1;
            adjacent[fill[b as usize] as usize] = (a, e as u32);
            fill[b as usize] += 1;
        }
        let mut border = vec![false; ends.len()];
        let mut on_border = vec![false; nv];
        for h in 0..nh {
            if twin[h] == NONE {
                border[edge_of[h] as usize] = true;
                let (a, b) = Self::ends_of(&tris, h);
                on_border[a as usize] = true;
                on_border[b as usize] = true;
            }
        }
        let nf = tris.len();
        Self {
            positions,
            tris,
            twin,
            edge_of,
            edge_face,
            offsets,
            adjacent,
            border,
            on_border,
            label: vec![0; nf],
            faces_of: vec![(0..nf as u32).collect()],
        }
    }

    fn ends_of(tris: &[[u32; 3]], h: usize) -> (u32, u32) {
        let t = tris[h / 3];
        (t[h % 3], t[(h % 3 + 1) % 3])
    }

    fn origin(&self, h: u32) -> u32 {
        self.tris[h as usize / 3][h as usize % 3]
    }

    fn next(h: u32) -> u32 {
        3 * (h / 3) + (h % 3 + 1) % 3
    }

    /// The border walk of `region` as the vertices it passes, in order, the region on the
    /// left; `None` when the region's border is not one loop (not a disc) or it has none.
    /// Cost `O(faces of the region)`.
    pub fn contour(&self, region: u32) -> Option<Vec<u32>> {
        let border_half = |h: u32| self.border[self.edge_of[h as usize] as usize];
        let faces = &self.faces_of[region as usize];
        let total = faces
            .iter()
            .flat_map(|&f| (0..3).map(move |i| 3 * f + i))
            .filter(|&h| border_half(h))
            .count();
        let start = faces
            .iter()
            .flat_map(|&f| (0..3).map(move |i| 3 * f + i))
            .find(|&h| border_half(h))?;
        let mut walk = Vec::new();
        let mut h = start;
        loop {
            walk.push(self.origin(h));
            if walk.len() > total {
                return None;
            }
            let mut g = Self::next(h);
            let mut turns = 0;
            while !border_half(g) {
                let t = self.twin[g as usize];
                turns += 1;
                if t == NONE || turns > self.adjacent.len() {
                    return None;
                }
                g = Self::next(t);
            }
            h = g;
            if h == start {
                break;
            }
        }
        (walk.len() == total).then_some(walk)
    }

    /// The edges of `region` at `u` that are not border: `(neighbour, edge, length)`.
    fn inner_edges(&self, region: u32, u: u32) -> impl Iterator<Item = (u32, u32, f64)> + '_ {
        let (lo, hi) = (
            self.offsets[u as usize] as usize,
            self.offsets[u as usize + 1] as usize,
        );
        self.adjacent[lo..hi]
            .iter()
            .filter(move |&&(_, e)| {
                !self.border[e as usize]
                    && self.label[self.edge_face[e as usize] as usize] == region
            })
            .map(move |&(w, e)| {
                (
                    w,
                    e,
                    dist2(self.positions[u as usize], self.positions[w as usize]).sqrt(),
                )
            })
    }

    /// Dijkstra in `region` from `source` (a border vertex): shortest edge paths whose inner
    /// vertices are off the border, ending at border vertices. Fills `dist` and `pred`
    /// (per vertex: distance and `(previous vertex, edge)`; `dist` must come in all infinite,
    /// and the touched entries are listed in `touched` for the caller to reset).
    /// Cost `O(E log E)` over the region's edges.
    pub fn dijkstra(
        &self,
        region: u32,
        source: u32,
        dist: &mut [f64],
        pred: &mut [(u32, u32)],
        touched: &mut Vec<u32>,
    ) {
        let mut heap = BinaryHeap::new();
        dist[source as usize] = 0.0;
        touched.push(source);
        heap.push(Entry(0.0, source));
        while let Some(Entry(d, u)) = heap.pop() {
            if d > dist[u as usize] {
                continue;
            }
            if u != source && self.on_border[u as usize] {
                continue;
            }
            for (w, e, len) in self.inner_edges(region, u) {
                let nd = d + len;
                if nd < dist[w as usize] {
                    if dist[w as usize].is_infinite() {
                        touched.push(w);
                    }
                    dist[w as usize] = nd;
                    pred[w as usize] = (u, e);
                    heap.push(Entry(nd, w));
                }
            }
        }
    }

    /// Distance along the edges of `region` from every one of its vertices to its border
    /// (multi-source Dijkstra from the border vertices); `INFINITY` off the region. Cost
    /// `O(E log E)` over the region's edges.
    pub fn border_distance(&self, region: u32) -> Vec<f64> {
        let mut dist = vec![f64::INFINITY; self.positions.len()];
        let mut heap = BinaryHeap::new();
        for &f in &self.faces_of[region as usize] {
            for &v in &self.tris[f as usize] {
                if self.on_border[v as usize] && dist[v as usize] > 0.0 {
                    dist[v as usize] = 0.0;
                    heap.push(Entry(0.0, v));
                }
            }
        }
        while let Some(Entry(d, u)) = heap.pop() {
            if d > dist[u as usize] {
                continue;
            }
            for (w, _, len) in self.inner_edges(region, u) {
                let nd = d + len;
                if nd < dist[w as usize] {
                    dist[w as usize] = nd;
                    heap.push(Entry(nd, w));
                }
            }
        }
        dist
    }

    /// The path to `terminal` found by [`Self::dijkstra`] from `source`, or `None` when it was
    /// not reached. Cost `O(path)`.
    pub fn path_to(source: u32, terminal: u32, dist: &[f64], pred: &[(u32, u32)]) -> Option<Path> {
        if terminal == source || !dist[terminal as usize].is_finite() {
            return None;
        }
        let mut p = Path::default();
        let mut v = terminal;
        while v != source {
            p.vertices.push(v);
            let (u, e) = pred[v as usize];
            p.edges.push(e);
            v = u;
        }
        p.vertices.push(source);
        p.vertices.reverse();
        p.edges.reverse();
        Some(p)
    }

    /// Cuts `region` along `path` (from [`Self::dijkstra`] in it): its edges become border, and
    /// the region's faces on one side get a new label, which is returned. When the path does
    /// not split the region into exactly two parts, nothing changes and `None` is returned.
    /// Cost `O(faces of the region)`.
    pub fn cut(&mut self, region: u32, path: &Path) -> Option<u32> {
        let saved: Vec<bool> = path
            .vertices
            .iter()
            .map(|&v| self.on_border[v as usize])
            .collect();
        for &e in &path.edges {
            self.border[e as usize] = true;
        }
        for &v in &path.vertices {
            self.on_border[v as usize] = true;
        }
        let faces = std::mem::take(&mut self.faces_of[region as usize]);
        let new = self.faces_of.len() as u32;
        // The side of the first face; exactly two parts: the rest must be connected too.
        let side = self.flood(&faces);
        let (a, b): (Vec<u32>, Vec<u32>) = faces.iter().partition(|f| side[f]);
        let two = !b.is_empty() && self.flood(&b).values().all(|&s| s);
        if !two {
            for &e in &path.edges {
                self.border[e as usize] = false;
            }
            for (&v, &s) in path.vertices.iter().zip(&saved) {
                self.on_border[v as usize] = s;
            }
            self.faces_of[region as usize] = faces;
            return None;
        }
        for &f in &b {
            self.label[f as usize] = new;
        }
        self.faces_of[region as usize] = a;
        self.faces_of.push(b);
        Some(new)
    }

    /// The faces of `faces` (not empty) reached from the first across non-border edges
    /// (`true`) and the others (`false`).
    fn flood(&self, faces: &[u32]) -> HashMap<u32, bool> {
        let mut reached: HashMap<u32, bool> = faces.iter().map(|&f| (f, false)).collect();
        let mut stack = vec![faces[0]];
        reached.insert(faces[0], true);
        while let Some(f) = stack.pop() {
            for i in 0..3 {
                let h = 3 * f + i;
                if self.border[self.edge_of[h as usize] as usize] {
                    continue;
                }
                let g = self.twin[h as usize] / 3;
                if let Some(r) = reached.get_mut(&g) {
                    if !*r {
                        *r = true;
                        stack.push(g);
                    }
                }
            }
        }
        reached
    }

    /// Makes `path`'s edges border without splitting anything (a link between two boundary
    /// loops, §4.4's topological contour). Cost `O(path)`.
    pub fn mark(&mut self, path: &Path) {
        for &e in &path.edges {
            self.border[e as usize] = true;
        }
        for &v in &path.vertices {
            self.on_border[v as usize] = true;
        }
    }
}

/// A heap entry ordered by smallest distance first.
#[derive(PartialEq)]
struct Entry(f64, u32);

impl Eq for Entry {}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        other.0.total_cmp(&self.0).then(other.1.cmp(&self.1))
    }
}
