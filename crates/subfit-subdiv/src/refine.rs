//! Uniform refinement: one level of Loop, Catmull-Clark or quad/triangle subdivision as a sparse
//! matrix.
//!
//! Loop 1987 (1→4 triangle split); Catmull & Clark 1978 (an `n`-gon becomes `n` quads); Stam &
//! Loop 2003 (triangles split as Loop's, other faces as Catmull-Clark's);
//! Hoppe et al. 1994 sharp creases and corners; DeRose, Kass & Truong 1998 semi-sharp creases
//! (OpenSubdiv's uniform creasing, [`crate::crease`]); OpenSubdiv 3.5 `Far::TopologyRefiner`
//! for the vertex rules and boundary interpolation. The masks come from [`crate::mask`].
//!
//! # Child vertex order (stable, documented)
//! With `V`, `E`, `F` the parent's vertex, edge and face counts, child vertex
//! * `v` (`0 ≤ v < V`) is the vertex point of parent vertex `v` — so control-vertex ids persist
//!   through all levels;
//! * `V + e` (`0 ≤ e < E`) is the edge point of parent edge `e`, edges numbered in order of first
//!   appearance when faces are scanned in order and each face's corners in winding order (face
//!   edge `i` joins face vertices `i` and `i + 1`), see [`Topology`];
//! * `V + E + f` (`0 ≤ f < F`, Catmull-Clark only) is the face point of parent face `f`;
//!   quad/triangle: `V + E + k` is the face point of the `k`-th non-triangle face (triangles have
//!   none).
//!
//! (OpenSubdiv orders face points, edge points, vertex points; compare point sets, not indices.)
//!
//! # Child face order
//! Children of parent face `f` are consecutive, in parent face order. Loop: triangle
//! `(a, b, c)` with edge points `ab, bc, ca` gives `(a, ab, ca)`, `(b, bc, ab)`, `(c, ca, bc)`,
//! `(ab, bc, ca)`. Catmull-Clark: face `(v_0 … v_{n−1})` with face point `F` gives, for each `i`,
//! the quad `(v_i, e_{i,i+1}, F, e_{i−1,i})`. Quad/triangle: each triangle as Loop's, each other
//! face as Catmull-Clark's. Winding is preserved.

use crate::child::ChildCorners;
use crate::crease;
use crate::error::SubdivError;
use crate::face_points::FacePoints;
use crate::mask::{FaceWeights, Mask};
use crate::scheme::{
    classify, BoundaryRule, EdgeNeighborhood, FaceKinds, Neighborhood, Options, Scheme, VertexRule,
};
use crate::stencil::{compose_rows, Stacked, StencilMatrix};
use crate::topology::Topology;
use rayon::prelude::*;
use subfit_mesh::{Polygons, Tags, SHARPNESS_INFINITE};

/// One level of uniform refinement.
#[derive(Clone, Debug)]
pub struct Refinement {
    /// The child faces (order in the module docs).
    pub faces: Polygons,
    /// Number of child vertices (`V + E` for Loop, `V + E + F` for Catmull-Clark, `V + E +`
    /// the number of non-triangles for quad/triangle).
    pub num_vertices: usize,
    /// Tags carried to the child mesh: infinitely sharp creases on both child edges of a sharp
    /// parent edge, corner tags on the same vertex ids; finite sharpness (edges and corners) in
    /// single precision and decremented by one, dropped once it reaches 0
    /// ([`crate::crease::decrement`]).
    pub tags: Tags,
    /// The refinement operator, `num_vertices × parent vertices`: child positions =
    /// `matrix.apply(parent positions)`.
    pub matrix: StencilMatrix,
}

/// Checks that `faces` suit `scheme` (Loop needs triangles) and builds their adjacency.
pub(crate) fn topology_for(
    faces: &Polygons,
    num_vertices: usize,
    scheme: Scheme,
) -> Result<Topology, SubdivError> {
    if scheme == Scheme::Loop {
        if let Some((face, f)) = faces.iter().enumerate().find(|(_, f)| f.len() != 3) {
            return Err(SubdivError::NotTriangles { face, len: f.len() });
        }
    }
    let topo = Topology::new(faces, num_vertices)?;
    if scheme == Scheme::QuadTriangle {
        for v in 0..topo.num_vertices() as u32 {
            let num_faces = topo.vertex_corners(v).len();
            if num_faces > 64 && matches!(face_kinds(&topo, v), FaceKinds::Mixed(_)) {
                return Err(SubdivError::MixedValence {
                    vertex: v,
                    num_faces,
                });
            }
        }
    }
    Ok(topo)
}

/// Which faces around vertex `v` are triangles, in ring order. Cost O(valence).
pub(crate) fn face_kinds(topo: &Topology, v: u32) -> FaceKinds {
    FaceKinds::from_triangles(
        topo.vertex_corners(v)
            .iter()
            .map(|&c| topo.face(topo.corner_face(c) as usize).len() == 3),
    )
}

/// Whether each edge is infinitely sharp: boundary edges, and edges tagged with sharpness
/// `>= SHARPNESS_INFINITE`. Cost O(#E) (plus one hash lookup per edge when tags exist).
pub(crate) fn sharp_edges(topo: &Topology, tags: &Tags) -> Vec<bool> {
    (0..topo.num_edges() as u32)
        .map(|e| {
            topo.is_boundary_edge(e) || {
                let [a, b] = topo.edge_vertices(e);
                !tags.is_empty() && tags.is_sharp_edge(a, b)
            }
        })
        .collect()
}

/// Whether `tags` hold a finite (semi-sharp) crease or corner sharpness. Cost O(#tags).
pub(crate) fn has_semi_sharp(tags: &Tags) -> bool {
    !tags.is_empty()
        && (tags
            .creases()
            .iter()
            .any(|&(_, s)| crease::is_semi_sharp(crease::sharpness(s)))
            || tags
                .corners()
                .iter()
                .any(|&(_, s)| crease::is_semi_sharp(crease::sharpness(s))))
}

/// The finite sharpness of every edge (0 for smooth, boundary and infinitely sharp edges), or
/// an empty vector when `tags` hold no finite sharpness. Cost O(#E + #tags · valence).
pub(crate) fn semi_sharp_edges(topo: &Topology, tags: &Tags) -> Vec<f32> {
    if !has_semi_sharp(tags) {
        return Vec::new();
    }
    let mut out = vec![0.0f32; topo.num_edges()];
    for ((a, b), s) in tags.creases() {
        let s = crease::sharpness(s);
        if !crease::is_semi_sharp(s) || a as usize >= topo.num_vertices() {
            continue;
        }
        if let Some(i) = topo.vertex_ring(a).iter().position(|&u| u == b) {
            let e = topo.vertex_edges(a)[i];
            if !topo.is_boundary_edge(e) {
                out[e as usize] = s;
            }
        }
    }
    out
}

/// The finite corner sharpness of every vertex (0 where none or infinite), or an empty vector
/// when `tags` hold no finite sharpness. Cost O(#V + #tags).
pub(crate) fn semi_sharp_vertices(num_vertices: usize, tags: &Tags) -> Vec<f32> {
    if !has_semi_sharp(tags) {
        return Vec::new();
    }
    let mut out = vec![0.0f32; num_vertices];
    for (v, s) in tags.corners() {
        let s = crease::sharpness(s);
        if crease::is_semi_sharp(s) && (v as usize) < num_vertices {
            out[v as usize] = s;
        }
    }
    out
}

/// The sharpness of ring edge `e` as [`crate::crease`] reads it: [`crease::INFINITE`] for
/// boundary and infinitely sharp edges, else the finite sharpness (0 when smooth).
#[inline]
pub(crate) fn edge_sharpness(sharp: &[bool], semi: &[f32], e: u32) -> f32 {
    if sharp[e as usize] {
        crease::INFINITE
    } else {
        semi.get(e as usize).copied().unwrap_or(0.0)
    }
}

/// The [`Neighborhood`] (rule and crease ends) of every vertex. Cost O(#corners).
pub(crate) fn neighborhoods(
    topo: &Topology,
    sharp: &[bool],
    tags: &Tags,
    boundary: BoundaryRule,
) -> Vec<Neighborhood> {
    (0..topo.num_vertices() as u32)
        .map(|v| {
            let edges = topo.vertex_edges(v);
            let corner_tag = !tags.is_empty() && tags.is_corner(v);
            let num_faces = topo.vertex_corners(v).len();
            classify(
                edges.iter().map(|&e| sharp[e as usize]),
                num_faces,
                face_kinds(topo, v),
                corner_tag,
                boundary,
            )
        })
        .collect()
}

/// Refines `faces` (over `num_vertices` vertices, with crease/corner `tags`) by one level of
/// `options.scheme`.
///
/// Errors: see [`SubdivError`] (bad topology; non-triangles for Loop). Cost O(#corners ·
/// max valence); the matrix has about `V·(1 + valence) + 4E + Σ|f|` entries.
pub fn refine(
    faces: &Polygons,
    num_vertices: usize,
    tags: &Tags,
    options: &Options,
) -> Result<Refinement, SubdivError> {
    let topo = topology_for(faces, num_vertices, options.scheme)?;
    Ok(refine_topology(&topo, tags, options))
}

/// [`refine`] on an already built adjacency (which must suit the scheme).
pub(crate) fn refine_topology(topo: &Topology, tags: &Tags, options: &Options) -> Refinement {
    Refinement {
        faces: child_faces(topo, options.scheme),
        num_vertices: ChildCorners::new(topo, options.scheme).num_vertices(),
        tags: child_tags(topo, tags),
        matrix: refine_matrix(topo, tags, options),
    }
}

/// The refinement matrix [`Refinement::matrix`] alone. Cost O(#corners · max valence), serial.
pub(crate) fn refine_matrix(topo: &Topology, tags: &Tags, options: &Options) -> StencilMatrix {
    let rows = RefineRows::new(topo, tags, options);
    let mut m = StencilMatrix::new(topo.num_vertices());
    let mut row: Vec<(u32, f64)> = Vec::with_capacity(64);
    let mut cache = VertexMaskCache::default();
    for i in 0..rows.num_rows() {
        row.clear();
        rows.row(&mut cache, i, None, |c, w| row.push((c, w)));
        m.push_row(&mut row);
    }
    m
}

/// One refinement step composed with `rhs` (`#V × n`): `M · rhs` (`#V_child × n`, the
/// [`Refinement::matrix`] of `M` times `rhs`), computed in parallel with rows of `M` generated
/// on the fly, so `M` itself is never stored (nor sorted). Cost O(Σ_i Σ_{j ∈ row i of M}
/// nnz(rhs_j)).
///
/// # Panics
/// If `rhs.nrows() != topo.num_vertices()`.
#[track_caller]
pub(crate) fn refine_compose(
    topo: &Topology,
    tags: &Tags,
    options: &Options,
    rhs: &StencilMatrix,
) -> StencilMatrix {
    assert_eq!(rhs.nrows(), topo.num_vertices(), "inner dimensions differ");
    let rows = RefineRows::new(topo, tags, options);
    let (nv, ne) = (topo.num_vertices(), topo.num_edges());
    match options.scheme {
        Scheme::Loop => {
            let [m] = compose_rows(
                rows.num_rows(),
                Stacked::one(rhs),
                VertexMaskCache::default,
                |cache, i, row| rows.row(cache, i, None, |c, w| row.push((c, [w]))),
            );
            m
        }
        Scheme::CatmullClark | Scheme::QuadTriangle => {
            // Face points first; vertex and edge points then use them as single rows instead
            // of re-expanding every face centre (about half the work).
            let [face_points] = compose_rows(
                rows.num_rows() - nv - ne,
                Stacked::one(rhs),
                VertexMaskCache::default,
                |cache, f, row| rows.row(cache, nv + ne + f, None, |c, w| row.push((c, [w]))),
            );
            let [mut m] = compose_rows(
                nv + ne,
                Stacked::two(rhs, &face_points),
                VertexMaskCache::default,
                |cache, i, row| rows.row(cache, i, Some(nv as u32), |c, w| row.push((c, [w]))),
            );
            m.append_rows(&face_points);
            m
        }
    }
}

/// The vertex-point mask of the last neighbourhood seen: consecutive vertices mostly share
/// their neighbourhood, so the mask is recomputed only when it changes.
#[derive(Default)]
pub(crate) struct VertexMaskCache {
    hood: Option<Neighborhood>,
    mask: Mask,
    /// The child-rule mask and ring sharpnesses of semi-sharp vertices.
    scratch: Mask,
    ring: Vec<f32>,
}

/// The rows of one level of refinement (child vertex order in the module docs), generated on
/// demand from the parent adjacency.
pub(crate) struct RefineRows<'a> {
    topo: &'a Topology,
    scheme: Scheme,
    sharp: Vec<bool>,
    /// Finite edge sharpness ([`semi_sharp_edges`]; empty without semi-sharp tags).
    semi: Vec<f32>,
    /// Finite vertex sharpness ([`semi_sharp_vertices`]; empty without semi-sharp tags).
    vsemi: Vec<f32>,
    boundary: BoundaryRule,
    hoods: Vec<Neighborhood>,
    points: FacePoints,
    smooth_triangles: bool,
}

impl<'a> RefineRows<'a> {
    /// Classifies the edges and vertices of `topo`. Cost O(#corners).
    pub(crate) fn new(topo: &'a Topology, tags: &Tags, options: &Options) -> Self {
        let sharp = sharp_edges(topo, tags);
        let hoods = neighborhoods(topo, &sharp, tags, options.boundary);
        Self {
            topo,
            scheme: options.scheme,
            sharp,
            semi: semi_sharp_edges(topo, tags),
            vsemi: semi_sharp_vertices(topo.num_vertices(), tags),
            boundary: options.boundary,
            hoods,
            points: FacePoints::new(topo, options.scheme),
            smooth_triangles: options.scheme == Scheme::CatmullClark
                && options.triangles == crate::scheme::TriangleRule::Smooth,
        }
    }

    /// The parent vertices' neighbourhoods (rule and crease ends, from the parent's infinitely
    /// sharp tags; see [`Self::semi_sharp`]).
    pub(crate) fn hoods(&self) -> &[Neighborhood] {
        &self.hoods
    }

    /// Whether any edge or vertex has a finite sharpness (then [`Self::hoods`] do not give the
    /// rules of the vertices it touches).
    pub(crate) fn semi_sharp(&self) -> bool {
        !self.semi.is_empty()
    }

    /// Whether vertex `v` or one of its edges has a finite sharpness. Cost O(valence).
    #[inline]
    pub(crate) fn semi_sharp_at(&self, v: u32) -> bool {
        !self.semi.is_empty()
            && (self.vsemi[v as usize] > 0.0
                || self
                    .topo
                    .vertex_edges(v)
                    .iter()
                    .any(|&e| self.semi[e as usize] > 0.0))
    }

    /// Number of child vertices (`V + E`, plus the face points).
    pub(crate) fn num_rows(&self) -> usize {
        self.topo.num_vertices() + self.topo.num_edges() + self.points.len()
    }

    /// Calls `push(parent vertex, weight)` for the entries of child row `i` (a column may
    /// repeat; exact zeros may be pushed). With `face_points = Some(base)`, a face centre
    /// (Catmull-Clark face point of parent face `f`) is pushed as the single column `base + f`
    /// instead of its vertices (`base + k` for face point `k`).
    #[inline]
    pub(crate) fn row(
        &self,
        cache: &mut VertexMaskCache,
        i: usize,
        face_points: Option<u32>,
        mut push: impl FnMut(u32, f64),
    ) {
        let topo = self.topo;
        let (nv, ne) = (topo.num_vertices(), topo.num_edges());
        if i < nv {
            let v = i as u32;
            let hood = &self.hoods[i];
            if self.semi_sharp_at(v) {
                cache.ring.clear();
                let ring = topo.vertex_edges(v).iter();
                cache
                    .ring
                    .extend(ring.map(|&e| edge_sharpness(&self.sharp, &self.semi, e)));
                let vs = if hood.rule == VertexRule::Corner {
                    crease::INFINITE
                } else {
                    self.vsemi[i]
                };
                self.scheme.semi_sharp_vertex_point_mask(
                    hood,
                    vs,
                    &cache.ring,
                    self.boundary,
                    &mut cache.mask,
                    &mut cache.scratch,
                );
                cache.hood = None;
            } else if cache.hood.as_ref() != Some(hood) {
                self.scheme.vertex_point_mask(hood, &mut cache.mask);
                cache.hood = Some(*hood);
            }
            let mask = &cache.mask;
            push(v, mask.vertex);
            for (&u, &w) in topo.vertex_ring(v).iter().zip(&mask.edges) {
                push(u, w);
            }
            debug_assert!(mask.faces.is_empty() || mask.face_weights == FaceWeights::Centers);
            for (&c, &w) in topo.vertex_corners(v).iter().zip(&mask.faces) {
                if w != 0.0 {
                    let f = topo.corner_face(c) as usize;
                    self.push_center(face_points, f, w, &mut push);
                }
            }
        } else if i < nv + ne {
            let e = (i - nv) as u32;
            let corners = topo.edge_corners(e);
            let num_faces = if corners[1] == u32::MAX { 1 } else { 2 };
            let tri = |k: usize| {
                k < num_faces && topo.face(topo.corner_face(corners[k]) as usize).len() == 3
            };
            let semi = self.semi.get(e as usize).copied().unwrap_or(0.0);
            let mut em = self.scheme.edge_point_mask(&EdgeNeighborhood {
                num_faces,
                sharp: self.sharp[e as usize] || semi > 1.0,
                triangles: [tri(0), tri(1)],
            });
            if self.smooth_triangles && num_faces == 2 && em.face[0] != 0.0 && (tri(0) || tri(1)) {
                // OpenSubdiv's TRI_SUB_SMOOTH (catmarkScheme.h): 0.47 per triangle, averaged.
                let w = |t: bool| if t { 0.47 } else { 0.25 };
                let fw = 0.5 * (w(tri(0)) + w(tri(1)));
                em.face = [fw; 2];
                em.end = 0.5 * (1.0 - 2.0 * fw);
            }
            crease::blend_edge_mask(&mut em, semi);
            let [a, b] = topo.edge_vertices(e);
            push(a, em.end);
            push(b, em.end);
            for (k, &c) in corners[..num_faces].iter().enumerate() {
                let w = em.face[k];
                if w == 0.0 {
                    continue;
                }
                match em.face_weights[k] {
                    FaceWeights::Opposite => {
                        push(topo.corner_vertex(topo.corner_prev(c)), w);
                    }
                    FaceWeights::Centers => {
                        let f = topo.corner_face(c) as usize;
                        self.push_center(face_points, f, w, &mut push);
                    }
                }
            }
        } else {
            let f = self.points.face(i - nv - ne);
            self.push_center(None, f, 1.0, &mut push);
        }
    }

    /// Pushes `w` times the centre of face `f`: its vertices, or the single column
    /// `base + k` of its face point `k` when face points are given as rows
    /// (`face_points = Some(base)`).
    #[inline]
    fn push_center(
        &self,
        face_points: Option<u32>,
        f: usize,
        w: f64,
        push: &mut impl FnMut(u32, f64),
    ) {
        if let Some(base) = face_points {
            push(base + self.points.index(f), w);
            return;
        }
        let face = self.topo.face(f);
        let wf = w / face.len() as f64;
        for &u in face {
            push(u, wf);
        }
    }

    /// The parent face of child face-point row `nv + ne + k`'s face point `k`, for callers that
    /// expand face-point columns.
    pub(crate) fn face_points(&self) -> &FacePoints {
        &self.points
    }
}

/// The faces of the child of `topo` (order in the module docs), from the child corner algebra
/// of module `child`. Cost O(#corners), parallel.
///
/// # Panics
/// If the child has `u32::MAX` or more face indices.
#[track_caller]
pub(crate) fn child_faces(topo: &Topology, scheme: Scheme) -> Polygons {
    let child = ChildCorners::new(topo, scheme);
    let offsets = child.face_offsets();
    let nc = *offsets.last().expect("offsets");
    let indices = (0..nc).into_par_iter().map(|x| child.vertex(x)).collect();
    Polygons::from_raw(offsets, indices).expect("offsets of the child faces")
}

/// The tags of the child of `topo` (see [`Refinement::tags`]). Cost O(#tags · valence).
pub(crate) fn child_tags(topo: &Topology, tags: &Tags) -> Tags {
    let mut out = Tags::new();
    let nv = topo.num_vertices() as u32;
    for ((a, b), s) in tags.creases() {
        let child_s = if s >= SHARPNESS_INFINITE {
            s
        } else {
            f64::from(crease::decrement(crease::sharpness(s)))
        };
        if child_s <= 0.0 || a as usize >= topo.num_vertices() {
            continue;
        }
        let ring = topo.vertex_ring(a);
        if let Some(i) = ring.iter().position(|&u| u == b) {
            let ep = nv + topo.vertex_edges(a)[i];
            out.set_crease(a, ep, child_s);
            out.set_crease(ep, b, child_s);
        }
    }
    for (v, s) in tags.corners() {
        if s >= SHARPNESS_INFINITE {
            out.set_corner(v, s);
        } else {
            out.set_corner(v, f64::from(crease::decrement(crease::sharpness(s))));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    //! The child adjacency read off the parent (module `child`) against the topology of the
    //! refined faces: here, in the module that depends on both.
    use super::*;
    use crate::child::{refined_topology, ChildCorners, ChildRing};
    use subfit_mesh::Polygons;

    /// The child faces as the module docs of [`crate::refine`] list them, face by face.
    fn child_faces_by_pattern(topo: &Topology, scheme: Scheme) -> Polygons {
        let (nv, ne) = (topo.num_vertices() as u32, topo.num_edges() as u32);
        let mut out = Polygons::new();
        for f in 0..topo.num_faces() {
            let v = topo.face(f);
            let e = topo.face_edges(f);
            let n = v.len();
            if scheme == Scheme::Loop || (scheme == Scheme::QuadTriangle && n == 3) {
                let (ab, bc, ca) = (nv + e[0], nv + e[1], nv + e[2]);
                out.push(&[v[0], ab, ca]);
                out.push(&[v[1], bc, ab]);
                out.push(&[v[2], ca, bc]);
                out.push(&[ab, bc, ca]);
            } else {
                // Face points of the faces that have one, in face order.
                let fp = nv
                    + ne
                    + (0..f)
                        .filter(|&g| scheme == Scheme::CatmullClark || topo.face(g).len() != 3)
                        .count() as u32;
                for i in 0..n {
                    out.push(&[v[i], nv + e[i], fp, nv + e[(i + n - 1) % n]]);
                }
            }
        }
        out
    }

    /// An open grid of `n × n` quads (or triangles) with one vertex left out of all faces.
    fn grid(n: u32, tris: bool) -> (usize, Polygons) {
        let id = |i: u32, j: u32| i * (n + 1) + j;
        let mut faces = Polygons::new();
        for i in 0..n {
            for j in 0..n {
                let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
                if tris {
                    faces.push(&[q[0], q[1], q[2]]);
                    faces.push(&[q[0], q[2], q[3]]);
                } else {
                    faces.push(&q);
                }
            }
        }
        (((n + 1) * (n + 1) + 1) as usize, faces)
    }

    /// An open grid of `n × n` cells, every third a pair of triangles, with a pentagon (a
    /// boundary vertex added on the first cell's lower edge): the three kinds of quad/triangle
    /// parent faces side by side, in both orders along edges.
    fn mixed_grid(n: u32) -> (usize, Polygons) {
        let id = |i: u32, j: u32| i * (n + 1) + j;
        let extra = (n + 1) * (n + 1);
        let mut faces = Polygons::new();
        for i in 0..n {
            for j in 0..n {
                let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
                if i == 0 && j == 0 {
                    faces.push(&[q[0], extra, q[1], q[2], q[3]]);
                } else if (i * n + j) % 3 == 1 {
                    faces.push(&[q[0], q[1], q[2]]);
                    faces.push(&[q[0], q[2], q[3]]);
                } else {
                    faces.push(&q);
                }
            }
        }
        (extra as usize + 1, faces)
    }

    /// A closed cube-like mesh with a pentagon, a triangle and valence-3 and -5 vertices (an
    /// octahedron for Loop).
    fn closed(tris: bool) -> (usize, Polygons) {
        if tris {
            let f = [
                [0, 1, 2],
                [0, 2, 3],
                [0, 3, 4],
                [0, 4, 1],
                [5, 2, 1],
                [5, 3, 2],
                [5, 4, 3],
                [5, 1, 4],
            ];
            return (6, Polygons::from_triangles(&f));
        }
        // A cube with a vertex added on one edge (two pentagons) and a side split in two
        // triangles.
        let mut p = Polygons::new();
        p.push(&[0, 3, 2, 1]);
        p.push(&[0, 1, 5]);
        p.push(&[0, 5, 4]);
        p.push(&[1, 2, 6, 5]);
        p.push(&[2, 3, 7, 8, 6]);
        p.push(&[3, 0, 4, 7]);
        p.push(&[4, 5, 6, 8, 7]);
        (9, p)
    }

    #[test]
    fn child_corners_rings_and_refined_topology_equal_the_child_topology() {
        for scheme in [Scheme::Loop, Scheme::CatmullClark, Scheme::QuadTriangle] {
            let tris = scheme == Scheme::Loop;
            let meshes = [grid(3, tris), closed(tris), mixed_grid(4)];
            for (nv, faces) in meshes
                .into_iter()
                .filter(|(_, f)| !tris || f.iter().all(|f| f.len() == 3))
            {
                let o = Options::new(scheme);
                let parent = Topology::new(&faces, nv).unwrap();
                let r = refine(&faces, nv, &Tags::new(), &o).unwrap();
                // Two levels: the second parent has only regular faces.
                let child_topo = Topology::new(&r.faces, r.num_vertices).unwrap();
                let r2 = refine(&r.faces, r.num_vertices, &Tags::new(), &o).unwrap();
                let grandchild = Topology::new(&r2.faces, r2.num_vertices).unwrap();
                for (p, c, faces) in [
                    (&parent, &child_topo, &r.faces),
                    (&child_topo, &grandchild, &r2.faces),
                ] {
                    assert_eq!(faces, &child_faces_by_pattern(p, scheme), "{scheme:?}");
                    assert_eq!(&refined_topology(p, scheme).unwrap(), c, "{scheme:?}");
                    let k = ChildCorners::new(p, scheme);
                    assert_eq!(k.num_vertices(), c.num_vertices());
                    let nc = faces.indices().len() as u32;
                    for x in 0..nc {
                        assert_eq!(k.vertex(x), c.corner_vertex(x), "{scheme:?} corner {x}");
                        assert_eq!(k.next(x), c.corner_next(x));
                        assert_eq!(k.prev(x), c.corner_prev(x));
                        assert_eq!(k.twin(x), c.corner_twin(x), "{scheme:?} twin of {x}");
                    }
                    let mut ring = ChildRing::default();
                    for w in 0..c.num_vertices() as u32 {
                        let b: Vec<bool> = c
                            .vertex_edges(w)
                            .iter()
                            .map(|&e| c.is_boundary_edge(e))
                            .collect();
                        let d: Vec<u32> = match scheme {
                            Scheme::CatmullClark | Scheme::QuadTriangle => c
                                .vertex_corners(w)
                                .iter()
                                .map(|&x| c.corner_vertex(c.corner_next(c.corner_next(x))))
                                .collect(),
                            _ => Vec::new(),
                        };
                        for walk in [false, true] {
                            if walk {
                                k.ring_by_walk(w, &mut ring);
                            } else {
                                k.ring(w, &mut ring);
                            }
                            let what = format!("{scheme:?} vertex {w} (walk: {walk})");
                            assert_eq!(ring.verts, c.vertex_ring(w), "{what}");
                            assert_eq!(ring.corners, c.vertex_corners(w), "{what}");
                            assert_eq!(ring.boundary, b, "{what}");
                            assert_eq!(ring.diagonals, d, "{what}");
                            // (Loop and Catmull-Clark name their one kind even for a vertex
                            // without faces.)
                            if scheme == Scheme::QuadTriangle {
                                assert_eq!(k.face_kinds(&ring), face_kinds(c, w), "{what}");
                            }
                        }
                    }
                }
            }
        }
    }
}
