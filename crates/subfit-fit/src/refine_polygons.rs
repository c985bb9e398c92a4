//! Local refinement of polygon cages (triangles, quads, occasional `n`-gons) for Catmull-Clark
//! and every scheme other than Loop: the marked faces are split 1-to-4 (a quad into 4 quads, an
//! `n`-gon into `n` quads, a triangle into 4 triangles or 3 quads), and the faces around them are
//! closed conformingly by templates, so that no T-vertex appears (Lavoué et al. 2005 §5.2:
//! enrichment of the faces of a diffuse error field, cutting common edges; Cheng et al. 2004
//! §4.5: red-green closure, Bank, Sherman & Weiser 1983). Loop cages use
//! [`crate::remesh::refine_red_green`].
//!
//! # Templates (a face that is not marked, by its split edges)
//! | face | split edges | children |
//! | --- | --- | --- |
//! | triangle | 1 | split fully (red) when no unsplit edge borders a triangle, else 2 triangles (green bisection) |
//! | triangle | 2 or 3 | split fully (red), as red-green does |
//! | quad | 1 | 1 quad + 1 triangle (the shorter of the two new edges from the edge point) |
//! | quad | 2 opposite | 2 quads |
//! | quad | 2 adjacent | 3 quads around a new face point |
//! | quad | 3 or 4 | split fully (red): 4 quads |
//! | `n`-gon, `n ≥ 5` | ≥ 1 | split fully (red): `n` quads |
//!
//! Full splits propagate (their other edges are split too) until nothing changes, as in
//! red-green refinement. The templates keep quads wherever a quad can be kept.
//!
//! # Positions
//! Points come from one uniform refinement step of the whole cage by the scheme
//! ([`subfit_subdiv::refine`], with the cage's creases): a new edge point takes the scheme's edge
//! point, a new face point the face's centroid (Catmull-Clark's face point), an old point
//! all of whose faces are split fully takes the scheme's vertex point, and so does a boundary
//! point whose two boundary edges are split (the boundary curve depends on the boundary polygon
//! alone, so it stays where it was); other old points stay.
//! Where the split is uniform and matches the scheme's own split (Catmull-Clark splits a
//! triangle into 3 quads, which is why [`TriangleSplit::for_cage`] picks that), the limit
//! surface does not change at all; elsewhere it changes little.

use std::collections::HashMap;

use subfit_mesh::{PolyMesh, Polygons, Tags};
use subfit_subdiv::{refine, Options, Scheme, SubdivError, Topology};

use crate::remesh::RefineStats;

/// How a fully split triangle is divided.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TriangleSplit {
    /// Four triangles through the edge points (Loop's and the quad/triangle scheme's split).
    FourTriangles,
    /// Three quads through the edge points and a face point (Catmull-Clark's own split).
    ThreeQuads,
}

impl TriangleSplit {
    /// Four triangles for Loop (its own split, so the refinement is one uniform subdivision
    /// step where it is uniform); three quads for Catmull-Clark (its own split). For the
    /// quad/triangle hybrid it depends on the cage (`faces`):
    ///
    /// * a quad-dominant cage (at least half of its faces quads) splits triangles into three
    ///   quads, since the scheme's own split (four triangles) would let triangles multiply: so
    ///   refined, it stays quad-dominant (fandisk: 70% quads at 1,116 control points instead
    ///   of 47% at 1,029, both at the tolerance). The new face point is the triangle's
    ///   centroid, so the limit surface moves a little there;
    /// * a triangle-dominant cage (the default for open mesh targets: an automatic cage of
    ///   triangles) splits them into four, the scheme's own split. On triangles the scheme is
    ///   Loop, and so is its refinement: an all-triangle cage is fitted exactly as with Loop
    ///   (the armadillo with 27 holes: 1,328 control points both ways, against 1,636 with three
    ///   quads per triangle).
    pub fn for_cage(scheme: Scheme, faces: &Polygons) -> Self {
        let quad_dominant = || {
            let quads = faces.iter().filter(|f| f.len() == 4).count();
            2 * quads >= faces.len()
        };
        match scheme {
            Scheme::Loop => Self::FourTriangles,
            Scheme::CatmullClark => Self::ThreeQuads,
            Scheme::QuadTriangle if quad_dominant() => Self::ThreeQuads,
            Scheme::QuadTriangle => Self::FourTriangles,
        }
    }
}

/// What [`refine_polygons`] returns.
#[derive(Clone, Debug)]
pub struct PolyRefinement {
    /// The refined cage: old points keep their ids (some moved, see the module docs), new
    /// edge points follow in edge order (first appearance over faces and corners), then new face
    /// points in face order. Winding is preserved.
    pub mesh: PolyMesh,
    /// The tags carried over: a split crease edge gives two crease edges through its edge point
    /// (infinitely sharp stays so, a finite sharpness drops by one); corners keep theirs.
    pub tags: Tags,
    /// Faces marked, split fully (`red`), split by a transition template (`green`), and the
    /// points added (edge and face points).
    pub stats: RefineStats,
    /// The parent face of every output face (children of a face are consecutive, in parent
    /// order; an unsplit face is its parent's only child).
    pub parents: Vec<u32>,
    /// Every split edge `(a, b)` (`a < b`, old ids) with its edge point, in edge order.
    pub edge_points: Vec<((u32, u32), u32)>,
}

/// Whether a face of `n` sides with `k` split edges must be split fully (no template closes
/// it). `small_cluster`: the face is a triangle of a small cluster of triangles
/// ([`small_triangle_clusters`]).
///
/// A triangle of a small cluster with one split edge is split fully (3 quads under Catmull-Clark and the
/// quad/triangle scheme) instead of bisected into 2 triangles: in a quad-dominant cage the
/// full split turns a triangle into quads and the propagation stops at the quads around it
/// (fandisk, defaults: quad/tri 68% → 81% quads and 1,081 → 938 control points; Catmull-Clark
/// 72% → 80%, 1,258 → 1,027; rocker-arm 75% / 71% → 80% / 80%, 744 / 707 → 726 / 776
/// control points). A triangle of a larger cluster is bisected, as red-green does: otherwise a triangle
/// region (a cage built with `--no-quad-dominant`) would be split fully from one edge to every
/// face.
fn needs_full_split(n: usize, k: usize, small_cluster: bool) -> bool {
    match n {
        3 => k >= 2 || (k == 1 && small_cluster),
        4 => k >= 3,
        _ => k >= 1,
    }
}

/// Triangles in a cluster (triangles connected through shared edges) of at most this many
/// faces are split fully from one split edge; larger clusters are bisected.
const SMALL_CLUSTER: usize = 8;

/// For every face, whether it is a triangle in a cluster of at most [`SMALL_CLUSTER`]
/// triangles. Cost O(#faces).
fn small_triangle_clusters(topo: &Topology) -> Vec<bool> {
    let nf = topo.num_faces();
    let is_tri = |f: usize| topo.face_edges(f).len() == 3;
    let mut small = vec![false; nf];
    let mut seen = vec![false; nf];
    let mut cluster = Vec::new();
    for f0 in 0..nf {
        if seen[f0] || !is_tri(f0) {
            continue;
        }
        seen[f0] = true;
        cluster.clear();
        cluster.push(f0);
        let mut i = 0;
        while i < cluster.len() {
            let f = cluster[i];
            i += 1;
            for &e in topo.face_edges(f) {
                for c in topo.edge_corners(e) {
                    if c == u32::MAX {
                        continue;
                    }
                    let g = topo.corner_face(c) as usize;
                    if !seen[g] && is_tri(g) {
                        seen[g] = true;
                        cluster.push(g);
                    }
                }
            }
        }
        let is_small = cluster.len() <= SMALL_CLUSTER;
        for &f in &cluster {
            small[f] = is_small;
        }
    }
    small
}

/// Splits the `marked` faces of a polygon cage 1-to-4 and closes the transition conformingly
/// (templates in the module docs), for `options.scheme` (any scheme that accepts polygons; the
/// triangle split is [`TriangleSplit::for_cage`]). `tags` are the cage's creases and corners,
/// used for the positions and carried to the result. `marked` may be shorter than the face
/// list (missing entries: not marked).
///
/// Errors: those of [`Topology::new`] and [`subfit_subdiv::refine`] (non-manifold or
/// inconsistently oriented cage; Loop with non-triangles). Cost O(#corners · max valence) for
/// the uniform refinement step and the closure, times the number of closure rounds (the
/// depth of the propagation, usually 1–3).
pub fn refine_polygons(
    mesh: &PolyMesh,
    tags: &Tags,
    marked: &[bool],
    options: &Options,
) -> Result<PolyRefinement, SubdivError> {
    let nv = mesh.num_vertices();
    let nf = mesh.faces.len();
    let topo = Topology::new(&mesh.faces, nv)?;
    let ne = topo.num_edges();
    let tri_split = TriangleSplit::for_cage(options.scheme, &mesh.faces);
    let (red, split) = closure(&topo, marked);

    // One uniform step of the scheme gives every candidate point (documented child order:
    // vertex points, then edge points).
    let uniform = refine(&mesh.faces, nv, tags, options)?;
    assert!(
        uniform.num_vertices >= nv + ne,
        "edge points follow vertex points"
    );
    let child = uniform.matrix.apply(&mesh.positions);

    let mut positions = mesh.positions.clone();
    let mut all_red = vec![true; nv];
    let mut used = vec![false; nv];
    for (f, face) in mesh.faces.iter().enumerate() {
        for &v in face {
            all_red[v as usize] &= red[f];
            used[v as usize] = true;
        }
    }
    for v in 0..nv {
        if all_red[v] && used[v] || boundary_both_split(&topo, tags, &split, v as u32) {
            positions[v] = child[v];
        }
    }
    let mut edge_point = vec![u32::MAX; ne];
    let mut edge_points = Vec::new();
    for e in 0..ne {
        if split[e] {
            edge_point[e] = positions.len() as u32;
            positions.push(child[nv + e]);
            let [a, b] = topo.edge_vertices(e as u32);
            edge_points.push(((a.min(b), a.max(b)), edge_point[e]));
        }
    }

    let mut stats = RefineStats {
        marked: marked.iter().take(nf).filter(|&&m| m).count(),
        new_points: edge_points.len(),
        ..RefineStats::default()
    };
    let mut out = Out {
        old: &mesh.positions,
        positions,
        faces: Polygons::with_capacity(nf + 4 * edge_points.len(), mesh.faces.indices().len()),
    };
    let mut parents = Vec::with_capacity(nf + 4 * edge_points.len());
    let mut mids: Vec<Option<u32>> = Vec::new();
    for (f, face) in mesh.faces.iter().enumerate() {
        mids.clear();
        mids.extend(topo.face_edges(f).iter().map(|&e| {
            let m = edge_point[e as usize];
            (m != u32::MAX).then_some(m)
        }));
        let k = mids.iter().filter(|m| m.is_some()).count();
        let before = out.faces.len();
        if red[f] {
            stats.red += 1;
            split_full(face, &mids, tri_split, &mut out);
        } else if k == 0 {
            out.faces.push(face);
        } else {
            stats.green += 1;
            split_transition(face, &mids, &mut out);
        }
        parents.resize(parents.len() + out.faces.len() - before, f as u32);
    }
    stats.new_points = out.positions.len() - nv;

    let tags = carry(tags, &edge_points);
    Ok(PolyRefinement {
        mesh: PolyMesh::new(out.positions, out.faces),
        tags,
        stats,
        parents,
        edge_points,
    })
}

/// Whether `v` is a boundary point of two boundary edges, both split, with no crease or
/// corner tag on it or its edges: its scheme's boundary vertex point (1/8, 3/4, 1/8 of the
/// boundary polygon) then keeps the boundary curve where the split is uniform, whatever its
/// interior faces do (the curve depends on the boundary polygon alone).
fn boundary_both_split(topo: &Topology, tags: &Tags, split: &[bool], v: u32) -> bool {
    if !topo.is_boundary_vertex(v) || tags.is_corner(v) {
        return false;
    }
    let edges = topo.vertex_edges(v);
    let mut boundary = 0;
    for &e in edges {
        let [a, b] = topo.edge_vertices(e);
        if tags.crease(a, b) > 0.0 {
            return false;
        }
        if topo.is_boundary_edge(e) {
            if !split[e as usize] {
                return false;
            }
            boundary += 1;
        }
    }
    boundary == 2 && edges.len() > 2
}

/// Red faces (marked, or closed by a full split) and split edges, by propagation until no
/// face needs a full split that does not have one.
fn closure(topo: &Topology, marked: &[bool]) -> (Vec<bool>, Vec<bool>) {
    let nf = topo.num_faces();
    let small = small_triangle_clusters(topo);
    let mut red: Vec<bool> = (0..nf)
        .map(|f| marked.get(f).copied().unwrap_or(false))
        .collect();
    let mut split = vec![false; topo.num_edges()];
    let mut todo: Vec<usize> = (0..nf).filter(|&f| red[f]).collect();
    // A new red face splits its edges; only the faces across them can turn red.
    while let Some(f) = todo.pop() {
        for &e in topo.face_edges(f) {
            if split[e as usize] {
                continue;
            }
            split[e as usize] = true;
            for c in topo.edge_corners(e) {
                if c == u32::MAX {
                    continue;
                }
                let g = topo.corner_face(c) as usize;
                if red[g] {
                    continue;
                }
                let es = topo.face_edges(g);
                let k = es.iter().filter(|&&x| split[x as usize]).count();
                if needs_full_split(es.len(), k, small[g]) {
                    red[g] = true;
                    todo.push(g);
                }
            }
        }
    }
    (red, split)
}

/// The refined cage being built: its points (old ids first) and faces, beside the cage's
/// points before any moved.
struct Out<'a> {
    old: &'a [[f64; 3]],
    positions: Vec<[f64; 3]>,
    faces: Polygons,
}

impl Out<'_> {
    /// Appends the centroid of `face` in the cage (Catmull-Clark's face point) and returns its
    /// id.
    fn face_point(&mut self, face: &[u32]) -> u32 {
        let inv = 1.0 / face.len() as f64;
        let old = self.old;
        let c =
            std::array::from_fn(|k| face.iter().map(|&v| old[v as usize][k]).sum::<f64>() * inv);
        self.positions.push(c);
        (self.positions.len() - 1) as u32
    }

    fn dist2(&self, p: u32, q: u32) -> f64 {
        let (p, q) = (self.positions[p as usize], self.positions[q as usize]);
        (0..3).map(|k| (p[k] - q[k]).powi(2)).sum()
    }
}

/// The full split of a face whose every edge has an edge point (`mids[i]` on edge `i`, from
/// corner `i` to `i + 1`): `n` quads around a face point, or 4 triangles for a triangle under
/// [`TriangleSplit::FourTriangles`].
fn split_full(face: &[u32], mids: &[Option<u32>], tri_split: TriangleSplit, out: &mut Out<'_>) {
    let n = face.len();
    let m: Vec<u32> = mids
        .iter()
        .map(|m| m.expect("a red face has every edge split"))
        .collect();
    if n == 3 && tri_split == TriangleSplit::FourTriangles {
        let [a, b, c] = [face[0], face[1], face[2]];
        let [ab, bc, ca] = [m[0], m[1], m[2]];
        for t in [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]] {
            out.faces.push(&t);
        }
        return;
    }
    let fp = out.face_point(face);
    for i in 0..n {
        out.faces.push(&[face[i], m[i], fp, m[(i + n - 1) % n]]);
    }
}

/// The transition templates for a face that is not split fully (module docs): a triangle with
/// one split edge, a quad with one or two.
fn split_transition(face: &[u32], mids: &[Option<u32>], out: &mut Out<'_>) {
    let n = face.len();
    let at = |i: usize| face[i % n];
    let split: Vec<usize> = (0..n).filter(|&i| mids[i].is_some()).collect();
    match (n, split.as_slice()) {
        (3, &[i]) => {
            let m = mids[i].unwrap();
            let (a, b, c) = (at(i), at(i + 1), at(i + 2));
            out.faces.push(&[a, m, c]);
            out.faces.push(&[m, b, c]);
        }
        (4, &[i]) => {
            let m = mids[i].unwrap();
            let (a, b, c, d) = (at(i), at(i + 1), at(i + 2), at(i + 3));
            if out.dist2(m, d) <= out.dist2(m, c) {
                out.faces.push(&[m, b, c, d]);
                out.faces.push(&[a, m, d]);
            } else {
                out.faces.push(&[a, m, c, d]);
                out.faces.push(&[m, b, c]);
            }
        }
        (4, &[i, j]) if j == i + 2 => {
            let (m0, m2) = (mids[i].unwrap(), mids[j].unwrap());
            let (a, b, c, d) = (at(i), at(i + 1), at(i + 2), at(i + 3));
            out.faces.push(&[a, m0, m2, d]);
            out.faces.push(&[m0, b, c, m2]);
        }
        (4, &[i, j]) => {
            // Adjacent: edges (i, i+1) split with i the first of the pair around the face.
            let i = if j == i + 1 { i } else { j };
            let (m0, m1) = (mids[i].unwrap(), mids[(i + 1) % 4].unwrap());
            let (a, b, c, d) = (at(i), at(i + 1), at(i + 2), at(i + 3));
            let fp = out.face_point(face);
            out.faces.push(&[a, m0, fp, d]);
            out.faces.push(&[m0, b, m1, fp]);
            out.faces.push(&[fp, m1, c, d]);
        }
        _ => unreachable!("face of {n} sides with split edges {split:?} is closed by a full split"),
    }
}

/// The sharpness of each half of a split cage edge of sharpness `s`: infinite stays infinite; a
/// finite one drops by one, as OpenSubdiv's uniform creasing does per level — a semi-sharp
/// crease rounds over about `L / 2^s` of its edge length `L`, so halving `L` and keeping the
/// rounding width takes `s − 1` (0 removes the tag).
pub(crate) fn split_sharpness(s: f64) -> f64 {
    if s >= subfit_mesh::SHARPNESS_INFINITE {
        s
    } else {
        (s - 1.0).max(0.0)
    }
}

/// `tags` with every split crease edge replaced by its two halves ([`split_sharpness`]).
fn carry(tags: &Tags, edge_points: &[((u32, u32), u32)]) -> Tags {
    if tags.is_empty() {
        return Tags::new();
    }
    let by_edge: HashMap<(u32, u32), u32> = edge_points.iter().copied().collect();
    let mut out = Tags::new();
    for ((a, b), s) in tags.creases() {
        match by_edge.get(&(a.min(b), a.max(b))) {
            Some(&m) => {
                out.set_crease(a, m, split_sharpness(s));
                out.set_crease(m, b, split_sharpness(s));
            }
            None => out.set_crease(a, b, s),
        }
    }
    for (v, s) in tags.corners() {
        out.set_corner(v, s);
    }
    out
}
