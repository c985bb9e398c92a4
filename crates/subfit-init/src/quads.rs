//! Quad-dominant cages by pairing triangles (Lavoué et al. 2007, §4.3: control edges follow
//! the lines of curvature, scored by their coherency with the principal directions).
//!
//! [`pair_triangles`] removes the shared diagonal of chosen pairs of adjacent triangles, so
//! that a triangle cage becomes a quad-dominant one with the same vertices. Each candidate
//! diagonal gets a score in `[0, 1]` from two parts:
//!
//! * **shape**: the quad's corner angles near 90° and the two triangles nearly coplanar;
//!   folds (dihedral above [`PairOptions::max_dihedral_deg`]), non-convex quads and corners
//!   near 180° are rejected outright;
//! * **coherency** (Lavoué §4.3, eq. 4): for each of the quad's four edges the score
//!   `SC = min(Σ θmin, Σ θmax) / n` over `n` points along the edge, where `θmin`/`θmax` are the
//!   angles between the edge and the minimum/maximum principal directions of the nearest target
//!   point, and isotropic points (umbilics, planes) count 45° for both, so they do not
//!   influence the score. The paper follows a Dijkstra path on the target between the limit
//!   positions of the edge's end points; a cage edge of a topology-preserving simplification
//!   lies close to the target, so here the points are the nearest target points to samples of
//!   the straight edge. `SC ∈ [0, 45]`; the coherency part is `1 − mean SC / 45`.
//!
//! The pairs are a near-maximum-weight matching of the dual graph: greedy by score, then
//! augmenting alternating paths (bounded breadth-first searches, blossoms not contracted)
//! that pair left-over triangles. Boundary edges and tagged crease edges are never removed,
//! and no interior vertex is left with fewer than three edges, so the genus, the boundary
//! loops, manifoldness and the faces' winding are kept; leftover triangles stay triangles
//! (Catmull-Clark and the quad/triangle scheme accept mixed cages), except that two left
//! over on either side of a quad are merged with it into two quads ([`crate::hexagons`], up
//! to four rounds; fandisk's cage 59 % → 72 % quads). Around a small hole no
//! quad gets a corner wider than 150° ([`MAX_HOLE_CORNER_DEG`]).
//!
//! Cost: `O(E log E)` for scoring and the greedy pass (plus `O(E · s · log P)` target
//! look-ups for `s` samples per edge), `O(T · L)` for the augmenting searches (`T` leftover
//! triangles, `L` = [`PairOptions::search_limit`]); deterministic (no hashing, ties broken by
//! index).

use subfit_mesh::vec3::{add, dot, norm, scale, sub};
use subfit_mesh::{HalfEdgeId, HalfEdgeMesh, PolyMesh, Polygons, Tags, TopologyError};
use subfit_target::Target;

pub use crate::quad_shape::PairOptions;
use crate::quad_shape::{shape_score, Reject};

/// What [`pair_triangles`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PairReport {
    /// Quads in the result (pairs made, plus quads of the input).
    pub quads: usize,
    /// Triangles left.
    pub triangles: usize,
    /// Faces of other sizes (kept as they were).
    pub other_faces: usize,
    /// Interior, untagged diagonals between two triangles.
    pub candidates: usize,
    /// Candidates rejected as folds (dihedral above [`PairOptions::max_dihedral_deg`]).
    pub rejected_folds: usize,
    /// Candidates rejected as non-convex or degenerate quads (a corner above
    /// [`PairOptions::max_corner_deg`], a reflex corner, a zero-length edge or area).
    pub rejected_shape: usize,
    /// Pairs made by the greedy pass.
    pub greedy_pairs: usize,
    /// Augmenting paths applied (each adds one pair).
    pub augmentations: usize,
    /// Hexagons of a quad and two left-over triangles split into two quads
    /// ([`crate::hexagons`]).
    pub hexagons: usize,
    /// Mean Lavoué coherency score `SC` (degrees, `[0, 45]`) of the new quads' edges; 45 without
    /// a target or on isotropic regions.
    pub mean_coherency_deg: f64,
}

impl PairReport {
    /// Quads over all faces (0 for an empty mesh).
    pub fn quad_fraction(&self) -> f64 {
        let f = self.quads + self.triangles + self.other_faces;
        if f == 0 {
            0.0
        } else {
            self.quads as f64 / f as f64
        }
    }
}

/// Below this `|k2 − k1| · edge length` (the difference of the normal curvatures, in radians
/// turned over the edge) a target point counts as isotropic at the cage's scale.
const FLAT_TURN: f64 = 0.03;
/// Below this `|k2 − k1| / (|k1| + |k2|)` a target point counts as umbilic.
const UMBILIC_RATIO: f64 = 0.2;

/// Merges pairs of adjacent triangles of `mesh` into quads (see the module docs).
///
/// `mesh` (`#V by 3` positions, any polygons; only triangles are paired) must be an oriented
/// manifold, in the units of `target` (the normalized units of a [`Target`]) when one is given.
/// `tags`: crease edges (any sharpness > 0) are never removed; corners do not matter.
/// `target = None` scores shape only. A merged pair `(a, b, c)` + `(a, c, d)` becomes the quad
/// `(a, b, c, d)` in the triangles' winding, at the place of the lower-numbered triangle; the
/// other faces keep their order. Vertices (and so the control-point count) do not change.
///
/// Errors: the [`TopologyError`] of a mesh that is not an oriented manifold.
/// Cost: see the module docs; deterministic.
pub fn pair_triangles(
    mesh: &PolyMesh,
    tags: &Tags,
    target: Option<&Target>,
    options: &PairOptions,
) -> Result<(PolyMesh, PairReport), TopologyError> {
    let he = HalfEdgeMesh::from_mesh(mesh)?;
    let mut report = PairReport::default();
    let (cands, [folds, shape]) = candidates(&he, &mesh.positions, tags, target, options);
    report.candidates = cands.len() + folds + shape;
    report.rejected_folds = folds;
    report.rejected_shape = shape;
    let mut m = Matching::new(&he, &cands);
    report.greedy_pairs = m.greedy();
    report.augmentations = m.augment(options.search_limit);
    let faces = merged_faces(&mesh.faces, &cands, &m.mate_edge);
    // A merge makes quads that may border other left-over triangles: a few rounds.
    let mut faces = faces;
    for _ in 0..HEXAGON_ROUNDS {
        let (f, n) = crate::hexagons::merge_hexagons(&faces, &mesh.positions, tags, options);
        faces = f;
        report.hexagons += n;
        if n == 0 {
            break;
        }
    }
    let mut coherency = (0.0, 0usize);
    for (e, c) in cands.iter().enumerate() {
        if m.mate_edge[c.faces[0] as usize] == e as u32 {
            coherency.0 += c.coherency_deg;
            coherency.1 += 1;
        }
    }
    report.mean_coherency_deg = if coherency.1 > 0 {
        coherency.0 / coherency.1 as f64
    } else {
        45.0
    };
    for f in faces.iter() {
        match f.len() {
            3 => report.triangles += 1,
            4 => report.quads += 1,
            _ => report.other_faces += 1,
        }
    }
    let mut out = mesh.clone();
    out.faces = faces;
    Ok((out, report))
}

/// Rounds of [`crate::hexagons::merge_hexagons`] at most.
const HEXAGON_ROUNDS: usize = 4;

/// A diagonal that may be removed: the two triangles, the quad it leaves and its score.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    /// The triangles, lower id first.
    faces: [u32; 2],
    /// The quad `(a, b, c, d)` in the triangles' winding; the diagonal is `a`–`c`.
    quad: [u32; 4],
    /// Score in `[0, 1]`, higher is better.
    score: f64,
    /// Mean `SC` of the quad's four edges (degrees).
    coherency_deg: f64,
}

/// The scored candidates (in half-edge order) and the numbers rejected as folds and for
/// their shape.
fn candidates(
    he: &HalfEdgeMesh,
    pos: &[[f64; 3]],
    tags: &Tags,
    target: Option<&Target>,
    o: &PairOptions,
) -> (Vec<Candidate>, [usize; 2]) {
    let mut sc = EdgeCoherency::new(he, pos, target, o.edge_samples.max(2));
    let w = if target.is_some() {
        o.coherency_weight.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let span = boundary_spans(he, pos);
    let mut out = Vec::new();
    let mut rejected = [0, 0];
    for h in 0..he.num_half_edges() {
        let h = HalfEdgeId::from_usize(h);
        let Some(t) = he.twin(h) else { continue };
        let (f, g) = (he.face(h), he.face(t));
        if f.0 >= g.0 || he.face_degree(f) != 3 || he.face_degree(g) != 3 {
            continue;
        }
        let (c, a) = (he.origin(h).0, he.dest(h).0);
        if tags.crease(a, c) > 0.0 {
            continue;
        }
        let b = he.dest(he.next(h)).0;
        let d = he.dest(he.next(t)).0;
        let quad = [a, b, c, d];
        let shape = if b == d || wide_hole_corner(pos, &span, quad) {
            Err(Reject::Shape)
        } else {
            shape_score(quad.map(|v| pos[v as usize]), o)
        };
        let shape = match shape {
            Ok(s) => s,
            Err(Reject::Fold) => {
                rejected[0] += 1;
                continue;
            }
            Err(Reject::Shape) => {
                rejected[1] += 1;
                continue;
            }
        };
        // The quad's edges a→b, b→c (in f) and c→d, d→a (in g).
        let sides = [he.next(h), he.prev(h), he.next(t), he.prev(t)];
        let coh = sides.iter().map(|&s| sc.score(s)).sum::<f64>() / 4.0;
        out.push(Candidate {
            faces: [f.0, g.0],
            quad,
            score: (1.0 - w) * shape + w * (1.0 - coh / 45.0).clamp(0.0, 1.0),
            coherency_deg: coh,
        });
    }
    (out, rejected)
}

/// Whether removing the diagonal `a`–`c` of `quad = [a, b, c, d]` makes a corner wider than
/// [`MAX_HOLE_CORNER_DEG`] at a boundary vertex (`a` or `c`) around which the faces span
/// more than [`HOLE_TURN_DEG`] (`span`, per vertex; the corner is the two triangles' angles
/// there together). Around a small hole the faces at a boundary vertex span about 300°. On
/// the armadillo with 27 holes (`hard_cases holes`), one hole's three-vertex cage
/// loop had a vertex with two quads, corners 144° and 153°; once refined, the loop tangled
/// and grew to five times the hole, and `subfit fit --scheme quad-tri` ended at 1,531 control
/// points with a Hausdorff distance of 1.01 % of the diagonal (tolerance missed). With this
/// rule: 1,499 points, 0.52 % (`--scheme catmull-clark`: 1,889 points and 1.08 % before, 1,590
/// and 0.59 % with it). Measured on the triangles' own angles,
/// since on a curved cage the quad's plane does not see the wrap; along a rim (180°) quads
/// keep the usual corners.
fn wide_hole_corner(pos: &[[f64; 3]], span: &[f64], quad: [u32; 4]) -> bool {
    let [a, b, c, d] = quad.map(|v| v as usize);
    [(a, c), (c, a)].into_iter().any(|(v, w)| {
        span[v] > HOLE_TURN_DEG
            && angle_deg(pos, v, w, b) + angle_deg(pos, v, w, d) > MAX_HOLE_CORNER_DEG
    })
}

/// The angle (degrees) at `at` between the directions to `p` and `q` (0 when degenerate).
fn angle_deg(pos: &[[f64; 3]], at: usize, p: usize, q: usize) -> f64 {
    let (u, v) = (sub(pos[p], pos[at]), sub(pos[q], pos[at]));
    let l = norm(u) * norm(v);
    if l > 0.0 {
        (dot(u, v) / l).clamp(-1.0, 1.0).acos().to_degrees()
    } else {
        0.0
    }
}

/// Per vertex: the faces' angles at a boundary vertex added up (0 for interior vertices).
fn boundary_spans(he: &HalfEdgeMesh, pos: &[[f64; 3]]) -> Vec<f64> {
    let mut span = vec![0.0; he.num_vertices()];
    for f in 0..he.num_faces() {
        let vs = he.face_vertices(subfit_mesh::FaceId::from_usize(f));
        let n = vs.len();
        for i in 0..n {
            let v = vs[i];
            if he.is_boundary_vertex(v) {
                span[v.idx()] += angle_deg(
                    pos,
                    v.idx(),
                    vs[(i + n - 1) % n].idx(),
                    vs[(i + 1) % n].idx(),
                );
            }
        }
    }
    span
}

/// A boundary vertex whose faces span more than this (degrees) borders a small hole (see
/// [`wide_hole_corner`]).
pub const HOLE_TURN_DEG: f64 = 240.0;
/// The widest corner a quad gets at a boundary vertex of a small hole (135° cost a tenth of
/// the quads on the holed armadillo and the beetle, and more control points).
pub const MAX_HOLE_CORNER_DEG: f64 = 150.0;

/// Lavoué's `SC` per cage edge, computed once per edge and cached.
struct EdgeCoherency<'a> {
    he: &'a HalfEdgeMesh,
    pos: &'a [[f64; 3]],
    target: Option<&'a Target>,
    samples: usize,
    /// Per edge id: the score, or NaN when not computed yet.
    cache: Vec<f64>,
}

impl<'a> EdgeCoherency<'a> {
    fn new(
        he: &'a HalfEdgeMesh,
        pos: &'a [[f64; 3]],
        target: Option<&'a Target>,
        samples: usize,
    ) -> Self {
        Self {
            he,
            pos,
            target,
            samples,
            cache: vec![f64::NAN; he.num_edges()],
        }
    }

    /// `SC` (degrees) of the edge of half-edge `h`; 45 without a target.
    fn score(&mut self, h: HalfEdgeId) -> f64 {
        let Some(target) = self.target else {
            return 45.0;
        };
        let e = self.he.edge(h).idx();
        if self.cache[e].is_nan() {
            let (u, v) = (self.he.origin(h).idx(), self.he.dest(h).idx());
            self.cache[e] = coherency_score(target, self.pos[u], self.pos[v], self.samples);
        }
        self.cache[e]
    }
}

/// Lavoué eq. 4 for the segment `p`–`q` (normalized units), with `samples ≥ 2` points along it:
/// `min(Σ θmin, Σ θmax) / n` in degrees, isotropic points counting 45° for both.
pub fn coherency_score(target: &Target, p: [f64; 3], q: [f64; 3], samples: usize) -> f64 {
    let d = sub(q, p);
    let len = norm(d);
    let n = samples.max(2);
    let (mut s1, mut s2) = (0.0, 0.0);
    for j in 0..n {
        let x = add(p, scale(d, j as f64 / (n - 1) as f64));
        let i = target.index().nearest(&x).index as usize;
        let f = target.quadrics()[i].frame_at(0.0, 0.0);
        let (a1, a2) = direction_angles(d, len, &f);
        s1 += a1;
        s2 += a2;
    }
    s1.min(s2) / n as f64
}

/// Angles (degrees, `[0, 90]`) between the segment direction `d` (length `len`) projected
/// into the tangent plane and the lines of `t1`, `t2`; `(45, 45)` where the frame is isotropic
/// at the scale `len` or the segment is along the normal.
pub(crate) fn direction_angles(
    d: [f64; 3],
    len: f64,
    f: &subfit_target::SurfaceFrame,
) -> (f64, f64) {
    let spread = (f.k2 - f.k1).abs();
    if !(spread * len > FLAT_TURN && spread > UMBILIC_RATIO * (f.k1.abs() + f.k2.abs())) {
        return (45.0, 45.0);
    }
    let dt = sub(d, scale(f.normal, dot(d, f.normal)));
    let l = norm(dt);
    if !(l > 1e-3 * len) {
        return (45.0, 45.0);
    }
    let angle = |t: [f64; 3]| (dot(dt, t).abs() / l).clamp(0.0, 1.0).acos().to_degrees();
    (angle(f.t1), angle(f.t2))
}

/// The dual graph's matching: per face, the candidate it is paired by.
struct Matching<'a> {
    cands: &'a [Candidate],
    /// Per face: candidate ids of its diagonals (at most 3).
    adjacent: Vec<[u32; 3]>,
    /// Per face: the candidate id of its pair, or `NONE`.
    mate_edge: Vec<u32>,
    /// Per vertex: edges left when all chosen diagonals are removed, for interior vertices;
    /// `u32::MAX` for boundary vertices (never constrained).
    edges_left: Vec<u32>,
}

const NONE: u32 = u32::MAX;
/// An interior vertex keeps at least this many edges (no valence-2 vertices, no two faces
/// sharing two consecutive edges).
const MIN_INTERIOR_VALENCE: u32 = 3;

impl<'a> Matching<'a> {
    fn new(he: &HalfEdgeMesh, cands: &'a [Candidate]) -> Self {
        let mut adjacent = vec![[NONE; 3]; he.num_faces()];
        for (e, c) in cands.iter().enumerate() {
            for f in c.faces {
                let slot = adjacent[f as usize]
                    .iter_mut()
                    .find(|s| **s == NONE)
                    .expect("a triangle has at most three diagonals");
                *slot = e as u32;
            }
        }
        let edges_left = (0..he.num_vertices())
            .map(|v| {
                let v = subfit_mesh::VertexId::from_usize(v);
                if he.is_boundary_vertex(v) {
                    u32::MAX
                } else {
                    he.valence(v) as u32
                }
            })
            .collect();
        Self {
            cands,
            adjacent,
            mate_edge: vec![NONE; he.num_faces()],
            edges_left,
        }
    }

    fn diagonal(&self, e: u32) -> [usize; 2] {
        let q = self.cands[e as usize].quad;
        [q[0] as usize, q[2] as usize]
    }

    fn can_remove(&self, e: u32) -> bool {
        self.diagonal(e)
            .iter()
            .all(|&v| self.edges_left[v] > MIN_INTERIOR_VALENCE)
    }

    fn set_removed(&mut self, e: u32, removed: bool) {
        for v in self.diagonal(e) {
            if self.edges_left[v] != u32::MAX {
                if removed {
                    self.edges_left[v] -= 1;
                } else {
                    self.edges_left[v] += 1;
                }
            }
        }
    }

    fn link(&mut self, e: u32) {
        let [f, g] = self.cands[e as usize].faces;
        self.mate_edge[f as usize] = e;
        self.mate_edge[g as usize] = e;
        self.set_removed(e, true);
    }

    fn unlink(&mut self, e: u32) {
        let [f, g] = self.cands[e as usize].faces;
        self.mate_edge[f as usize] = NONE;
        self.mate_edge[g as usize] = NONE;
        self.set_removed(e, false);
    }

    /// The face across candidate `e` from `f`.
    fn other(&self, e: u32, f: u32) -> u32 {
        let [a, b] = self.cands[e as usize].faces;
        if a == f {
            b
        } else {
            a
        }
    }

    /// Greedy maximum-weight pass; returns the pairs made.
    fn greedy(&mut self) -> usize {
        let mut order: Vec<u32> = (0..self.cands.len() as u32).collect();
        order.sort_by(|&x, &y| {
            self.cands[y as usize]
                .score
                .total_cmp(&self.cands[x as usize].score)
                .then(x.cmp(&y))
        });
        let mut pairs = 0;
        for e in order {
            let [f, g] = self.cands[e as usize].faces;
            if self.mate_edge[f as usize] == NONE
                && self.mate_edge[g as usize] == NONE
                && self.can_remove(e)
            {
                self.link(e);
                pairs += 1;
            }
        }
        pairs
    }

    /// Augmenting passes over the unpaired triangles until one adds nothing; returns the
    /// augmentations applied.
    fn augment(&mut self, limit: usize) -> usize {
        let mut total = 0;
        let mut stamp = vec![0u32; self.mate_edge.len()];
        let mut round = 0u32;
        for _pass in 0..4 {
            let mut added = 0;
            for f in 0..self.mate_edge.len() as u32 {
                if self.mate_edge[f as usize] != NONE || self.adjacent[f as usize][0] == NONE {
                    continue;
                }
                round += 1;
                if self.augment_from(f, limit, &mut stamp, round) {
                    added += 1;
                }
            }
            total += added;
            if added == 0 {
                break;
            }
        }
        total
    }

    /// One bounded breadth-first search for an alternating path from the unpaired face `root`
    /// to another unpaired face; applies the first one that keeps every interior vertex's
    /// valence. `stamp[f] == round` marks faces visited in this search.
    fn augment_from(&mut self, root: u32, limit: usize, stamp: &mut [u32], round: u32) -> bool {
        // `even[i] = (face, index into odd)`: the root, or the mate of a reached face;
        // `odd[j] = (face, candidate reaching it, index into even of the face it came from)`.
        let mut even: Vec<(u32, usize)> = vec![(root, usize::MAX)];
        let mut odd: Vec<(u32, u32, usize)> = Vec::new();
        stamp[root as usize] = round;
        let mut head = 0;
        while head < even.len() && even.len() + odd.len() < limit {
            let (u, _) = even[head];
            let at = head;
            head += 1;
            for e in self.by_score(u) {
                let v = self.other(e, u);
                if stamp[v as usize] == round {
                    continue;
                }
                let mate = self.mate_edge[v as usize];
                if mate == NONE {
                    let path = self.path_to(&even, &odd, at, e);
                    if self.try_flip(&path) {
                        return true;
                    }
                    continue;
                }
                stamp[v as usize] = round;
                let w = self.other(mate, v);
                if stamp[w as usize] == round {
                    continue;
                }
                stamp[w as usize] = round;
                odd.push((v, e, at));
                even.push((w, odd.len() - 1));
            }
        }
        false
    }

    /// The candidates of face `u` other than its current pair, best score first.
    fn by_score(&self, u: u32) -> Vec<u32> {
        let mut adj: Vec<u32> = self.adjacent[u as usize]
            .iter()
            .copied()
            .filter(|&e| e != NONE && e != self.mate_edge[u as usize])
            .collect();
        adj.sort_by(|&x, &y| {
            self.cands[y as usize]
                .score
                .total_cmp(&self.cands[x as usize].score)
                .then(x.cmp(&y))
        });
        adj
    }

    /// The candidates of the alternating path that ends with `last` leaving the even face
    /// `even[at]`: new pairs at even positions, current pairs at odd ones.
    fn path_to(
        &self,
        even: &[(u32, usize)],
        odd: &[(u32, u32, usize)],
        at: usize,
        last: u32,
    ) -> Vec<u32> {
        let mut path = vec![last];
        let mut at = at;
        while even[at].1 != usize::MAX {
            let (w, j) = even[at];
            let (_, e, from) = odd[j];
            path.push(self.mate_edge[w as usize]);
            path.push(e);
            at = from;
        }
        path
    }

    /// Flips the alternating `path` (new, old, new, …, new) when every interior vertex keeps
    /// enough edges; undoes it otherwise.
    fn try_flip(&mut self, path: &[u32]) -> bool {
        for (i, &e) in path.iter().enumerate() {
            if i % 2 == 1 {
                self.unlink(e);
            }
        }
        let mut ok = true;
        let mut linked = 0;
        for (i, &e) in path.iter().enumerate() {
            if i % 2 == 0 {
                if !self.can_remove(e) {
                    ok = false;
                    break;
                }
                self.link(e);
                linked = i + 1;
            }
        }
        if !ok {
            for (i, &e) in path.iter().enumerate().take(linked) {
                if i % 2 == 0 {
                    self.unlink(e);
                }
            }
            for (i, &e) in path.iter().enumerate() {
                if i % 2 == 1 {
                    self.link(e);
                }
            }
        }
        ok
    }
}

/// The faces with each pair merged into its quad at the place of its lower triangle.
fn merged_faces(faces: &Polygons, cands: &[Candidate], mate_edge: &[u32]) -> Polygons {
    let mut out = Polygons::with_capacity(faces.len(), faces.indices().len());
    for (f, face) in faces.iter().enumerate() {
        match mate_edge[f] {
            NONE => out.push(face),
            e if cands[e as usize].faces[0] as usize == f => out.push(&cands[e as usize].quad),
            _ => {}
        }
    }
    out
}
