//! Sharp features of mesh targets: crease edges, feature curves, corners and darts.
//!
//! Cheng et al. 2007 name sharp features as future work (§V); Lavoué et al. 2005 (§6, Fig. 13)
//! segment CAD objects and tag the patch boundaries as sharp control edges; Hoppe et al. 1994
//! (*Piecewise smooth surface reconstruction*) tag sharp edges, corners and darts. This module
//! finds them on a triangle or polygon mesh, as the input of feature-aligned cages:
//!
//! 1. **Sharp edges**: interior manifold edges whose dihedral angle (the angle between the two
//!    face normals, with the faces' relative orientation taken into account, so a mis-oriented
//!    face does not fake a fold) is at least [`FeatureOptions::angle_deg`], between two faces
//!    that each have a neighbour within half that angle (a face unlike all its neighbours is
//!    scan noise, not the side of a crease).
//! 2. **Gaps bridged**: from the free end of a chain, the chain is extended along the edge
//!    whose dihedral angle is at least half the threshold and whose direction continues the
//!    chain (within 35°), for at most [`FeatureOptions::bridge_edges`] edges, and kept only if
//!    it reaches another sharp vertex (hysteresis thresholding, as in Canny's edge detector).
//! 3. **Curves**: connected groups of sharp edges spanning less than
//!    [`FeatureOptions::min_group_length`] (of the bounding-box diagonal) are dropped — the
//!    tangles the noise of a scanned mesh makes; the sharp-edge graph is cut at its nodes (vertices of feature
//!    degree ≠ 2) into chains; a chain of fewer than [`FeatureOptions::min_curve_edges`] edges
//!    or shorter than [`FeatureOptions::min_curve_length`] is removed when one of its ends is
//!    free (a spur) or both are (a fleck), an open curve that zigzags (mean turn per vertex
//!    above [`FeatureOptions::max_mean_turn_deg`]: a crease of a scan, not of a design) is
//!    removed, and the graph is rebuilt until nothing changes.
//!    Last, a connected group in which fewer than [`FeatureOptions::min_sharp_fraction`] of the
//!    edges are sharp by themselves (the rest bridged) is removed.
//! 4. **Corners**: vertices where three or more curves meet, and vertices where one curve turns
//!    by more than [`FeatureOptions::corner_turn_deg`]; **darts**: free curve ends (a feature
//!    fading into a smooth region).
//!
//! Boundary edges are not features here (they are boundaries: the target keeps them as such).
//! Cost O(#corners · log) for the edge grouping (a sort), linear after it.

use std::collections::HashMap;

use subfit_mesh::Polygons;

/// Options of [`detect_features`].
#[derive(Clone, Debug, PartialEq)]
pub struct FeatureOptions {
    /// Dihedral angle (degrees) from which an edge is sharp. Default 40.
    pub angle_deg: f64,
    /// Chains with a free end and fewer edges than this are removed (spurs, noise). Default 3.
    pub min_curve_edges: usize,
    /// A curve vertex turning by more than this (degrees) is a corner. Default 60.
    pub corner_turn_deg: f64,
    /// Open curves of at least 4 edges whose mean turning angle per vertex exceeds this
    /// (degrees) are removed: the creases of a scan zigzag from triangle to triangle, those of
    /// a designed shape run fair. Default 30.
    pub max_mean_turn_deg: f64,
    /// Longest gap (in mesh edges) bridged between two pieces of a curve. Default 3.
    pub bridge_edges: usize,
    /// Chains with a free end shorter than this fraction of the bounding-box diagonal are
    /// removed too. Default 0.01.
    pub min_curve_length: f64,
    /// Connected groups of sharp edges whose extent (the diagonal of their bounding box) is
    /// below this fraction of the mesh's diagonal are removed (the noise of a scanned mesh
    /// makes small tangles of sharp edges; a coarse scan, short folds: the 3.5k-vertex bunny's
    /// span 5–12%). Default 0.15.
    pub min_group_length: f64,
    /// After cleaning, connected groups in which fewer than this fraction of the edges reach
    /// [`Self::angle_deg`] themselves (the rest bridged) are removed: a designed crease is sharp
    /// all along, a scan's fold is not (the Stanford bunny's base and ears: 70–93%). Default
    /// 0.95.
    pub min_sharp_fraction: f64,
}

impl Default for FeatureOptions {
    fn default() -> Self {
        Self {
            angle_deg: 40.0,
            min_curve_edges: 3,
            corner_turn_deg: 60.0,
            bridge_edges: 3,
            max_mean_turn_deg: 30.0,
            min_curve_length: 0.01,
            min_group_length: 0.15,
            min_sharp_fraction: 0.95,
        }
    }
}

/// One feature curve: a chain of sharp edges between nodes (corners, darts, junctions), or a
/// closed loop.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FeatureCurve {
    /// Vertex ids along the curve (for a closed loop the first is not repeated at the end).
    pub vertices: Vec<u32>,
    /// Whether the curve is a closed loop.
    pub closed: bool,
}

/// The features of a mesh (vertex ids of the mesh given to [`detect_features`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Features {
    /// Sharp edges `(a, b)`, `a < b`, sorted.
    pub edges: Vec<[u32; 2]>,
    /// The feature curves; each sharp edge is on exactly one.
    pub curves: Vec<FeatureCurve>,
    /// Corner vertices, sorted.
    pub corners: Vec<u32>,
    /// Dart vertices (free curve ends), sorted.
    pub darts: Vec<u32>,
    /// Sharp edges found before cleaning (spurs and flecks removed, gaps bridged).
    pub raw_edges: usize,
}

impl Features {
    /// Whether nothing was found.
    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }
}

/// An interior manifold edge with its dihedral angle (degrees).
struct EdgeInfo {
    ends: [u32; 2],
    angle: f64,
    faces: [u32; 2],
}

/// Finds the sharp features of the mesh `positions`/`faces` (see the module docs). Faces of
/// fewer than 3 vertices and non-finite positions are skipped (their edges are never sharp).
pub fn detect_features(
    positions: &[[f64; 3]],
    faces: &Polygons,
    options: &FeatureOptions,
) -> Features {
    let edges = interior_edges(positions, faces);
    // A face that differs from all its neighbours by more than half the threshold is noise
    // (a spike or a flipped sliver of a scan), not the side of a crease.
    let mut smallest = vec![f64::INFINITY; faces.len()];
    for e in &edges {
        for f in e.faces {
            smallest[f as usize] = smallest[f as usize].min(e.angle);
        }
    }
    let consistent = |f: u32| smallest[f as usize] <= 0.5 * options.angle_deg;
    let mut sharp: Vec<bool> = edges
        .iter()
        .map(|e| e.angle >= options.angle_deg && e.faces.iter().all(|&f| consistent(f)))
        .collect();
    let raw_edges = sharp.iter().filter(|&&s| s).count();
    let index: HashMap<[u32; 2], usize> =
        edges.iter().enumerate().map(|(i, e)| (e.ends, i)).collect();
    let nv = positions.len();
    let mut adjacency: Vec<Vec<usize>> = vec![Vec::new(); nv];
    for (i, e) in edges.iter().enumerate() {
        adjacency[e.ends[0] as usize].push(i);
        adjacency[e.ends[1] as usize].push(i);
    }
    let graph = Graph {
        positions,
        edges: &edges,
        adjacency: &adjacency,
    };
    graph.bridge(&mut sharp, options);
    let diagonal = diagonal(positions);
    graph.remove_small_groups(&mut sharp, options.min_group_length * diagonal);
    // Spur and fleck removal until stable.
    loop {
        let curves = graph.curves(&sharp);
        let degree = graph.degrees(&sharp);
        let mut removed = false;
        for c in &curves {
            let n = c.vertices.len() - usize::from(!c.closed);
            let short = n < options.min_curve_edges
                || graph.length(&c.vertices) < options.min_curve_length * diagonal;
            let jagged = n >= 4 && graph.mean_turn_deg(&c.vertices) > options.max_mean_turn_deg;
            if jagged {
                for w in c.vertices.windows(2) {
                    sharp[index[&key(w[0], w[1])]] = false;
                }
                removed = true;
                continue;
            }
            if c.closed || !short {
                continue;
            }
            let free = |v: u32| degree[v as usize] == 1;
            if free(c.vertices[0]) || free(*c.vertices.last().expect("a chain has vertices")) {
                for w in c.vertices.windows(2) {
                    sharp[index[&key(w[0], w[1])]] = false;
                }
                removed = true;
            }
        }
        if !removed {
            break;
        }
    }
    // A designed crease is sharp all along; one the bridging had to piece together for more
    // than a few edges is a scan's fold (the bunny's base and ears).
    graph.remove_groups(&mut sharp, |group| {
        let strong = group
            .iter()
            .filter(|&&e| edges[e].angle >= options.angle_deg)
            .count();
        strong as f64 >= options.min_sharp_fraction * group.len() as f64
    });
    let curves = graph.curves(&sharp);
    let degree = graph.degrees(&sharp);
    let cos_turn = options.corner_turn_deg.to_radians().cos();
    let mut corners = Vec::new();
    let mut darts = Vec::new();
    for v in 0..nv {
        match degree[v] {
            0 => {}
            1 => darts.push(v as u32),
            2 => {
                let [a, b] = graph.sharp_neighbours2(v, &sharp);
                let p = positions[v];
                let d1 = sub(p, positions[a as usize]);
                let d2 = sub(positions[b as usize], p);
                // Turning angle > threshold ⇔ cos(turn) < cos(threshold).
                if let Some(c) = cos_between(d1, d2) {
                    if c < cos_turn {
                        corners.push(v as u32);
                    }
                }
            }
            _ => corners.push(v as u32),
        }
    }
    let mut out_edges: Vec<[u32; 2]> = edges
        .iter()
        .zip(&sharp)
        .filter(|(_, &s)| s)
        .map(|(e, _)| e.ends)
        .collect();
    out_edges.sort_unstable();
    // Curves through a turning corner are split there, so that every corner ends its curves.
    let is_corner: Vec<bool> = {
        let mut m = vec![false; nv];
        for &c in &corners {
            m[c as usize] = true;
        }
        m
    };
    let curves = curves
        .into_iter()
        .flat_map(|c| split_at(c, &is_corner))
        .collect();
    Features {
        edges: out_edges,
        curves,
        corners,
        darts,
        raw_edges,
    }
}

/// The bounding-box diagonal of the finite positions (0 if there are none).
fn diagonal(positions: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in positions.iter().filter(|p| p.iter().all(|x| x.is_finite())) {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let d = sub(hi, lo);
    let l = dot(d, d).sqrt();
    if l.is_finite() {
        l
    } else {
        0.0
    }
}

fn key(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cosine of the angle between `a` and `b`; `None` if either vanishes.
fn cos_between(a: [f64; 3], b: [f64; 3]) -> Option<f64> {
    let l = (dot(a, a) * dot(b, b)).sqrt();
    (l > 0.0 && l.is_finite()).then(|| (dot(a, b) / l).clamp(-1.0, 1.0))
}

/// The interior manifold edges (exactly two faces) with their dihedral angles, sorted by
/// endpoints. An edge both faces traverse the same way (inconsistent orientation) compares
/// one normal with the other's opposite.
fn interior_edges(positions: &[[f64; 3]], faces: &Polygons) -> Vec<EdgeInfo> {
    let nv = positions.len() as u32;
    let normals: Vec<[f64; 3]> = faces
        .iter()
        .map(|f| {
            if f.len() >= 3 && f.iter().all(|&v| v < nv) {
                subfit_mesh::vec3::polygon_normal(positions, f)
            } else {
                [0.0; 3]
            }
        })
        .collect();
    // (key, face, forward)
    let mut half: Vec<([u32; 2], u32, bool)> = Vec::with_capacity(faces.indices().len());
    for (f, face) in faces.iter().enumerate() {
        if face.len() < 3 || face.iter().any(|&v| v >= nv) {
            continue;
        }
        for (i, &a) in face.iter().enumerate() {
            let b = face[(i + 1) % face.len()];
            if a != b {
                half.push((key(a, b), f as u32, a < b));
            }
        }
    }
    half.sort_unstable_by_key(|h| (h.0, h.1));
    let mut out = Vec::new();
    let mut i = 0;
    while i < half.len() {
        let mut j = i + 1;
        while j < half.len() && half[j].0 == half[i].0 {
            j += 1;
        }
        if j - i == 2 {
            let (k, f, fwd) = half[i];
            let (_, g, gwd) = half[i + 1];
            let (n1, mut n2) = (normals[f as usize], normals[g as usize]);
            if fwd == gwd {
                n2 = [-n2[0], -n2[1], -n2[2]];
            }
            if let Some(c) = cos_between(n1, n2) {
                out.push(EdgeInfo {
                    ends: k,
                    angle: c.acos().to_degrees(),
                    faces: [f, g],
                });
            }
        }
        i = j;
    }
    out
}

/// The edge graph of the mesh, for walking the sharp edges.
struct Graph<'a> {
    positions: &'a [[f64; 3]],
    edges: &'a [EdgeInfo],
    adjacency: &'a [Vec<usize>],
}

impl Graph<'_> {
    fn other(&self, e: usize, v: usize) -> usize {
        let [a, b] = self.edges[e].ends;
        if a as usize == v {
            b as usize
        } else {
            a as usize
        }
    }

    fn degrees(&self, sharp: &[bool]) -> Vec<usize> {
        self.adjacency
            .iter()
            .map(|es| es.iter().filter(|&&e| sharp[e]).count())
            .collect()
    }

    /// The two sharp neighbours of a vertex of feature degree 2.
    fn sharp_neighbours2(&self, v: usize, sharp: &[bool]) -> [u32; 2] {
        let mut it = self.adjacency[v]
            .iter()
            .filter(|&&e| sharp[e])
            .map(|&e| self.other(e, v) as u32);
        [it.next().unwrap_or(v as u32), it.next().unwrap_or(v as u32)]
    }

    /// Length of the polyline through `vertices`.
    fn length(&self, vertices: &[u32]) -> f64 {
        vertices
            .windows(2)
            .map(|w| {
                let d = sub(self.positions[w[0] as usize], self.positions[w[1] as usize]);
                dot(d, d).sqrt()
            })
            .sum()
    }

    /// Mean turning angle (degrees) at the interior vertices of the polyline `vertices`.
    fn mean_turn_deg(&self, vertices: &[u32]) -> f64 {
        let turns: Vec<f64> = vertices
            .windows(3)
            .filter_map(|w| {
                let [a, b, c] = [w[0], w[1], w[2]].map(|v| self.positions[v as usize]);
                cos_between(sub(b, a), sub(c, b)).map(|x| x.acos().to_degrees())
            })
            .collect();
        if turns.is_empty() {
            0.0
        } else {
            turns.iter().sum::<f64>() / turns.len() as f64
        }
    }

    /// Unmarks every connected group of sharp edges whose extent (bounding-box diagonal) is
    /// below `min`.
    fn remove_small_groups(&self, sharp: &mut [bool], min: f64) {
        self.remove_groups(sharp, |group| {
            let ends: Vec<[f64; 3]> = group
                .iter()
                .flat_map(|&e| self.edges[e].ends)
                .map(|v| self.positions[v as usize])
                .collect();
            diagonal(&ends) >= min
        });
    }

    /// Unmarks every connected group of sharp edges for which `keep` (given the group's edge
    /// indices) is false.
    fn remove_groups(&self, sharp: &mut [bool], keep: impl Fn(&[usize]) -> bool) {
        let nv = self.adjacency.len();
        let mut seen = vec![false; nv];
        let mut stack = Vec::new();
        let mut group = Vec::new();
        for v0 in 0..nv {
            if seen[v0] || !self.adjacency[v0].iter().any(|&e| sharp[e]) {
                continue;
            }
            seen[v0] = true;
            stack.push(v0);
            group.clear();
            while let Some(v) = stack.pop() {
                for &e in &self.adjacency[v] {
                    if !sharp[e] {
                        continue;
                    }
                    let w = self.other(e, v);
                    if v < w {
                        group.push(e);
                    }
                    if !seen[w] {
                        seen[w] = true;
                        stack.push(w);
                    }
                }
            }
            if !keep(&group) {
                for &e in &group {
                    sharp[e] = false;
                }
            }
        }
    }

    /// Extends free chain ends along weaker, well-aligned edges to another sharp vertex.
    fn bridge(&self, sharp: &mut [bool], o: &FeatureOptions) {
        if o.bridge_edges == 0 {
            return;
        }
        let weak = 0.5 * o.angle_deg;
        let cos_align = 35f64.to_radians().cos();
        let degree = self.degrees(sharp);
        let ends: Vec<usize> = (0..degree.len()).filter(|&v| degree[v] == 1).collect();
        let on_feature = |sharp: &[bool], v: usize| self.adjacency[v].iter().any(|&e| sharp[e]);
        for start in ends {
            // The incoming direction of the chain at its end.
            let Some(&e0) = self.adjacency[start].iter().find(|&&e| sharp[e]) else {
                continue;
            };
            let mut prev = self.other(e0, start);
            let mut at = start;
            let mut path = Vec::new();
            let mut reached = false;
            for _ in 0..o.bridge_edges {
                let dir = sub(self.positions[at], self.positions[prev]);
                let next = self.adjacency[at]
                    .iter()
                    .copied()
                    .filter(|&e| !sharp[e] && self.edges[e].angle >= weak)
                    .filter_map(|e| {
                        let w = self.other(e, at);
                        let c = cos_between(dir, sub(self.positions[w], self.positions[at]))?;
                        (c >= cos_align).then_some((c, e, w))
                    })
                    .max_by(|a, b| a.0.total_cmp(&b.0));
                let Some((_, e, w)) = next else {
                    break;
                };
                path.push(e);
                if on_feature(sharp, w) {
                    reached = true;
                    break;
                }
                prev = at;
                at = w;
            }
            if reached {
                for e in path {
                    sharp[e] = true;
                }
            }
        }
    }

    /// The chains of sharp edges between nodes (feature degree ≠ 2), and the closed loops.
    fn curves(&self, sharp: &[bool]) -> Vec<FeatureCurve> {
        let degree = self.degrees(sharp);
        let mut used = vec![false; self.edges.len()];
        let mut out = Vec::new();
        let walk = |start: usize, e0: usize, used: &mut [bool]| -> (Vec<u32>, bool) {
            let mut verts = vec![start as u32];
            let (mut at, mut e) = (start, e0);
            loop {
                used[e] = true;
                let w = self.other(e, at);
                if w == start {
                    return (verts, true);
                }
                verts.push(w as u32);
                if degree[w] != 2 {
                    return (verts, false);
                }
                let Some(&n) = self.adjacency[w].iter().find(|&&x| sharp[x] && !used[x]) else {
                    return (verts, false);
                };
                at = w;
                e = n;
            }
        };
        for (v, &d) in degree.iter().enumerate() {
            if d == 0 || d == 2 {
                continue;
            }
            for &e in &self.adjacency[v] {
                if sharp[e] && !used[e] {
                    let (vertices, closed) = walk(v, e, &mut used);
                    out.push(FeatureCurve { vertices, closed });
                }
            }
        }
        // What is left are loops of degree-2 vertices.
        for (v, &d) in degree.iter().enumerate() {
            if d != 2 {
                continue;
            }
            if let Some(&e) = self.adjacency[v].iter().find(|&&e| sharp[e] && !used[e]) {
                let (vertices, closed) = walk(v, e, &mut used);
                out.push(FeatureCurve { vertices, closed });
            }
        }
        out
    }
}

/// Splits `curve` at the interior vertices marked in `corner` (a closed loop with corners
/// becomes open chains from corner to corner).
fn split_at(curve: FeatureCurve, corner: &[bool]) -> Vec<FeatureCurve> {
    let v = &curve.vertices;
    let is = |x: u32| corner[x as usize];
    if curve.closed {
        let Some(s) = v.iter().position(|&x| is(x)) else {
            return vec![curve];
        };
        let mut rotated: Vec<u32> = v[s..].iter().chain(&v[..s]).copied().collect();
        rotated.push(v[s]);
        return split_open(&rotated, &is);
    }
    split_open(v, &is)
}

fn split_open(v: &[u32], is: &impl Fn(u32) -> bool) -> Vec<FeatureCurve> {
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..v.len() {
        if i == v.len() - 1 || is(v[i]) {
            out.push(FeatureCurve {
                vertices: v[start..=i].to_vec(),
                closed: false,
            });
            start = i;
        }
    }
    out
}
