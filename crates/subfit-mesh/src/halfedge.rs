//! A half-edge view of a manifold, consistently oriented polygon mesh, for navigation.
//!
//! The data structure is the classic doubly-connected edge list (Muller & Preparata 1978; see
//! also Botsch et al., *Polygon Mesh Processing*, 2010, §2.2) stored as flat arrays, in the
//! style of geometry-central's `SurfaceMesh`. Half-edges coincide with face corners: half-edge
//! `h` is corner `h` of the [`Polygons`] it was built from, starts at `indices[h]` and runs to the
//! next corner of its face, so face `f` owns the contiguous half-edges `offsets[f]..offsets[f+1]`
//! and its first half-edge is `offsets[f]`.
//!
//! Rotation around a vertex follows the face winding: for an outgoing half-edge `h`,
//! `twin(prev(h))` is the next outgoing half-edge counter-clockwise (for counter-clockwise faces
//! seen from outside). For a boundary vertex the stored outgoing half-edge is the clockwise-most
//! one (its twin is missing), so one counter-clockwise sweep visits the whole fan.
//!
//! The view is topology only: it never holds positions.

use crate::components::{components_by, genus, Components};
use crate::edges::{corner_faces, corner_next, group_edges};
use crate::ids::{EdgeId, FaceId, HalfEdgeId, VertexId};
use crate::polygons::{PolyMesh, Polygons};
use crate::tags::Tags;

/// Why a polygon list cannot be turned into a [`HalfEdgeMesh`]. Each variant names the first
/// offending element found (in face order for face errors, in `(min, max)` vertex order for
/// edges, in vertex order for vertices).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TopologyError {
    /// A face has fewer than three vertices.
    #[error("face {face} has {len} vertices; a face needs at least 3")]
    TooFewVertices {
        /// The face.
        face: FaceId,
        /// Its number of vertices.
        len: usize,
    },
    /// A face lists the same vertex twice.
    #[error("face {face} lists vertex {vertex} more than once")]
    RepeatedVertex {
        /// The face.
        face: FaceId,
        /// The repeated vertex.
        vertex: VertexId,
    },
    /// A face references a vertex id `>= num_vertices`.
    #[error("face {face} references vertex {vertex}, but there are only {num_vertices} vertices")]
    VertexOutOfRange {
        /// The face.
        face: FaceId,
        /// The out-of-range id.
        vertex: u32,
        /// The vertex count given.
        num_vertices: usize,
    },
    /// More than two faces share an edge.
    #[error(
        "edge {a}-{b} is shared by {count} faces (non-manifold edge), e.g. faces {f0} and {f1}"
    )]
    NonManifoldEdge {
        /// Smaller endpoint.
        a: VertexId,
        /// Larger endpoint.
        b: VertexId,
        /// Number of faces using the edge.
        count: usize,
        /// One face using it.
        f0: FaceId,
        /// Another face using it.
        f1: FaceId,
    },
    /// Two faces traverse an edge in the same direction.
    #[error(
        "faces {f0} and {f1} both traverse edge {a}->{b} in the same direction (inconsistent orientation)"
    )]
    InconsistentOrientation {
        /// Origin of the doubly used direction.
        a: VertexId,
        /// Destination.
        b: VertexId,
        /// First face.
        f0: FaceId,
        /// Second face.
        f1: FaceId,
    },
    /// The faces around a vertex form more than one fan (e.g. a bowtie).
    #[error(
        "vertex {vertex} is non-manifold: one fan around it covers {fan} of its {total} incident faces"
    )]
    NonManifoldVertex {
        /// The vertex.
        vertex: VertexId,
        /// Faces reached by one sweep around the vertex.
        fan: usize,
        /// Faces incident to the vertex.
        total: usize,
    },
    /// The mesh has too many half-edges or vertices for `u32` ids.
    #[error("mesh too large for u32 ids: {what}")]
    TooLarge {
        /// What overflowed.
        what: &'static str,
    },
}

impl TopologyError {
    /// The error with every face id `f` it names replaced by `id(f)` (e.g. the polygon a
    /// triangle of a triangulated copy came from).
    pub fn map_faces(self, id: impl Fn(FaceId) -> FaceId) -> Self {
        match self {
            Self::TooFewVertices { face, len } => Self::TooFewVertices {
                face: id(face),
                len,
            },
            Self::RepeatedVertex { face, vertex } => Self::RepeatedVertex {
                face: id(face),
                vertex,
            },
            Self::VertexOutOfRange {
                face,
                vertex,
                num_vertices,
            } => Self::VertexOutOfRange {
                face: id(face),
                vertex,
                num_vertices,
            },
            Self::NonManifoldEdge {
                a,
                b,
                count,
                f0,
                f1,
            } => Self::NonManifoldEdge {
                a,
                b,
                count,
                f0: id(f0),
                f1: id(f1),
            },
            Self::InconsistentOrientation { a, b, f0, f1 } => Self::InconsistentOrientation {
                a,
                b,
                f0: id(f0),
                f1: id(f1),
            },
            e @ (Self::NonManifoldVertex { .. } | Self::TooLarge { .. }) => e,
        }
    }
}

/// Half-edge connectivity of a manifold, consistently oriented polygon mesh.
///
/// All arrays are flat: `#H` half-edges (the total number of face corners), `#E` undirected edges,
/// `#V` vertices (including unreferenced ones, which have no outgoing half-edge), `#F` faces.
/// Memory is `24·#H + 4·#E + 4·#V + 4·#F` bytes (plus about 16 bytes per half-edge of scratch
/// during construction).
///
/// Accessors taking an id index these arrays directly and panic on an out-of-range id (a caller
/// bug, as with slice indexing); they never panic on ids obtained from the same mesh.
#[derive(Clone, Debug)]
pub struct HalfEdgeMesh {
    /// `#F + 1` offsets: face `f` owns half-edges `offsets[f]..offsets[f+1]`.
    offsets: Vec<u32>,
    /// `#H`: origin vertex.
    origin: Vec<VertexId>,
    /// `#H`: face on the left.
    face: Vec<FaceId>,
    /// `#H`: next half-edge in the face.
    next: Vec<HalfEdgeId>,
    /// `#H`: previous half-edge in the face.
    prev: Vec<HalfEdgeId>,
    /// `#H`: opposite half-edge, `INVALID` on the boundary.
    twin: Vec<HalfEdgeId>,
    /// `#H`: undirected edge.
    edge: Vec<EdgeId>,
    /// `#E`: one half-edge per edge (the one of the lower face id; the only one on the boundary).
    edge_half_edge: Vec<HalfEdgeId>,
    /// `#V`: one outgoing half-edge, the clockwise-most on the boundary; `INVALID` if isolated.
    vertex_half_edge: Vec<HalfEdgeId>,
}

impl HalfEdgeMesh {
    /// Builds the half-edge view of `faces` over `num_vertices` vertices.
    ///
    /// Requirements (each violation is a [`TopologyError`] naming the element): every face has at
    /// least 3 distinct, in-range vertices; every undirected edge is used by at most two faces,
    /// in opposite directions; the faces around every vertex form a single fan. Unreferenced
    /// vertices are allowed. Cost: `O(#V + #H)` time (a counting sort of half-edges by their
    /// smaller endpoint, then one sweep around each vertex); see `benches/topology.rs`.
    pub fn new(faces: &Polygons, num_vertices: usize) -> Result<Self, TopologyError> {
        let nh = faces.indices().len();
        if nh >= u32::MAX as usize {
            return Err(TopologyError::TooLarge { what: "half-edges" });
        }
        if num_vertices >= u32::MAX as usize {
            return Err(TopologyError::TooLarge { what: "vertices" });
        }
        validate_faces(faces, num_vertices)?;
        let next_raw = corner_next(faces);
        let groups = group_edges(faces, &next_raw, num_vertices, |_| true);
        let face: Vec<FaceId> = corner_faces(faces).into_iter().map(FaceId).collect();
        let origin: Vec<VertexId> = faces.indices().iter().map(|&v| VertexId(v)).collect();
        let mut prev = vec![HalfEdgeId::INVALID; nh];
        for (h, &n) in next_raw.iter().enumerate() {
            prev[n as usize] = HalfEdgeId(h as u32);
        }
        let next: Vec<HalfEdgeId> = next_raw.into_iter().map(HalfEdgeId).collect();

        let mut twin = vec![HalfEdgeId::INVALID; nh];
        let mut edge = vec![EdgeId::INVALID; nh];
        let mut edge_half_edge = Vec::with_capacity(groups.len());
        for e in 0..groups.len() {
            let g = groups.group(e);
            let h0 = g[0] as usize;
            match g.len() {
                1 => {}
                2 => {
                    let h1 = g[1] as usize;
                    if origin[h0] == origin[h1] {
                        return Err(TopologyError::InconsistentOrientation {
                            a: origin[h0],
                            b: origin[next[h0].idx()],
                            f0: face[h0],
                            f1: face[h1],
                        });
                    }
                    twin[h0] = HalfEdgeId(h1 as u32);
                    twin[h1] = HalfEdgeId(h0 as u32);
                }
                n => {
                    let (a, b) = (origin[h0], origin[next[h0].idx()]);
                    return Err(TopologyError::NonManifoldEdge {
                        a: a.min(b),
                        b: a.max(b),
                        count: n,
                        f0: face[h0],
                        f1: face[g[1] as usize],
                    });
                }
            }
            for &h in g {
                edge[h as usize] = EdgeId(e as u32);
            }
            edge_half_edge.push(HalfEdgeId(h0 as u32));
        }

        let mut mesh = Self {
            offsets: faces.offsets().to_vec(),
            origin,
            face,
            next,
            prev,
            twin,
            edge,
            edge_half_edge,
            vertex_half_edge: vec![HalfEdgeId::INVALID; num_vertices],
        };
        mesh.link_vertices()?;
        Ok(mesh)
    }

    /// Builds the half-edge view of a [`PolyMesh`]'s faces over its vertices; see [`Self::new`].
    pub fn from_mesh(mesh: &PolyMesh) -> Result<Self, TopologyError> {
        Self::new(&mesh.faces, mesh.num_vertices())
    }

    /// Chooses each vertex's outgoing half-edge and checks that its faces form a single fan.
    fn link_vertices(&mut self) -> Result<(), TopologyError> {
        let nv = self.vertex_half_edge.len();
        let mut out_degree = vec![0u32; nv];
        for h in 0..self.origin.len() {
            let v = self.origin[h].idx();
            out_degree[v] += 1;
            let cur = self.vertex_half_edge[v];
            // Prefer a half-edge without twin (clockwise-most of a boundary fan).
            if !cur.is_valid() || (self.twin[cur.idx()].is_valid() && !self.twin[h].is_valid()) {
                self.vertex_half_edge[v] = HalfEdgeId(h as u32);
            }
        }
        for (v, &deg) in out_degree.iter().enumerate() {
            let start = self.vertex_half_edge[v];
            if !start.is_valid() {
                continue;
            }
            let total = deg as usize;
            let mut fan = 1usize;
            let mut h = start;
            loop {
                h = self.twin[self.prev[h.idx()].idx()];
                if !h.is_valid() || h == start || fan > total {
                    break;
                }
                fan += 1;
            }
            if fan != total {
                return Err(TopologyError::NonManifoldVertex {
                    vertex: VertexId(v as u32),
                    fan: fan.min(total),
                    total,
                });
            }
        }
        Ok(())
    }

    // ---- sizes ------------------------------------------------------------------------------

    /// Number of vertices `#V` (including unreferenced ones).
    #[inline]
    pub fn num_vertices(&self) -> usize {
        self.vertex_half_edge.len()
    }

    /// Number of faces `#F`.
    #[inline]
    pub fn num_faces(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Number of half-edges `#H` (= total face corners).
    #[inline]
    pub fn num_half_edges(&self) -> usize {
        self.origin.len()
    }

    /// Number of undirected edges `#E`.
    #[inline]
    pub fn num_edges(&self) -> usize {
        self.edge_half_edge.len()
    }

    /// Number of vertices used by at least one face. Cost `O(#V)`.
    pub fn num_referenced_vertices(&self) -> usize {
        self.vertex_half_edge
            .iter()
            .filter(|h| h.is_valid())
            .count()
    }

    // ---- per half-edge ----------------------------------------------------------------------

    /// Origin vertex of `h`.
    #[inline]
    pub fn origin(&self, h: HalfEdgeId) -> VertexId {
        self.origin[h.idx()]
    }

    /// Destination vertex of `h` (the origin of `next(h)`).
    #[inline]
    pub fn dest(&self, h: HalfEdgeId) -> VertexId {
        self.origin[self.next[h.idx()].idx()]
    }

    /// Next half-edge around the face of `h`.
    #[inline]
    pub fn next(&self, h: HalfEdgeId) -> HalfEdgeId {
        self.next[h.idx()]
    }

    /// Previous half-edge around the face of `h`.
    #[inline]
    pub fn prev(&self, h: HalfEdgeId) -> HalfEdgeId {
        self.prev[h.idx()]
    }

    /// Opposite half-edge of `h`, or `None` when `h` is on the boundary.
    #[inline]
    pub fn twin(&self, h: HalfEdgeId) -> Option<HalfEdgeId> {
        let t = self.twin[h.idx()];
        t.is_valid().then_some(t)
    }

    /// Face on the left of `h`.
    #[inline]
    pub fn face(&self, h: HalfEdgeId) -> FaceId {
        self.face[h.idx()]
    }

    /// Undirected edge of `h`.
    #[inline]
    pub fn edge(&self, h: HalfEdgeId) -> EdgeId {
        self.edge[h.idx()]
    }

    /// Whether `h` has no twin (its edge is on the boundary).
    #[inline]
    pub fn is_boundary_half_edge(&self, h: HalfEdgeId) -> bool {
        !self.twin[h.idx()].is_valid()
    }

    /// Per half-edge origin vertex (`#H`), i.e. the polygon indices.
    #[inline]
    pub fn origins(&self) -> &[VertexId] {
        &self.origin
    }

    /// Per half-edge next half-edge (`#H`).
    #[inline]
    pub fn nexts(&self) -> &[HalfEdgeId] {
        &self.next
    }

    /// Per half-edge previous half-edge (`#H`).
    #[inline]
    pub fn prevs(&self) -> &[HalfEdgeId] {
        &self.prev
    }

    /// Per half-edge twin (`#H`), [`HalfEdgeId::INVALID`] on the boundary.
    #[inline]
    pub fn twins(&self) -> &[HalfEdgeId] {
        &self.twin
    }

    /// Per half-edge face (`#H`).
    #[inline]
    pub fn faces(&self) -> &[FaceId] {
        &self.face
    }

    /// Per half-edge undirected edge (`#H`).
    #[inline]
    pub fn edges(&self) -> &[EdgeId] {
        &self.edge
    }

    // ---- per face ---------------------------------------------------------------------------

    /// First half-edge of face `f` (`offsets[f]`); it starts at the face's first vertex.
    #[inline]
    pub fn face_half_edge(&self, f: FaceId) -> HalfEdgeId {
        HalfEdgeId(self.offsets[f.idx()])
    }

    /// Half-edges of face `f` in winding order (contiguous ids).
    #[inline]
    pub fn face_half_edges(&self, f: FaceId) -> impl ExactSizeIterator<Item = HalfEdgeId> {
        (self.offsets[f.idx()]..self.offsets[f.idx() + 1]).map(HalfEdgeId)
    }

    /// Vertices of face `f` in winding order.
    #[inline]
    pub fn face_vertices(&self, f: FaceId) -> &[VertexId] {
        &self.origin[self.offsets[f.idx()] as usize..self.offsets[f.idx() + 1] as usize]
    }

    /// Number of vertices (= edges) of face `f`.
    #[inline]
    pub fn face_degree(&self, f: FaceId) -> usize {
        (self.offsets[f.idx() + 1] - self.offsets[f.idx()]) as usize
    }

    /// Faces across the edges of `f`, in winding order (`None` across boundary edges).
    pub fn face_neighbors(&self, f: FaceId) -> impl ExactSizeIterator<Item = Option<FaceId>> + '_ {
        self.face_half_edges(f)
            .map(move |h| self.twin(h).map(|t| self.face(t)))
    }

    // ---- per edge ---------------------------------------------------------------------------

    /// A half-edge of edge `e`: the only one on the boundary, else the one in the lower face
    /// corner.
    #[inline]
    pub fn edge_half_edge(&self, e: EdgeId) -> HalfEdgeId {
        self.edge_half_edge[e.idx()]
    }

    /// Endpoints of edge `e`, as origin and destination of [`Self::edge_half_edge`].
    #[inline]
    pub fn edge_vertices(&self, e: EdgeId) -> [VertexId; 2] {
        let h = self.edge_half_edge(e);
        [self.origin(h), self.dest(h)]
    }

    /// The faces of edge `e`: the face of [`Self::edge_half_edge`], and the other one unless `e`
    /// is on the boundary.
    #[inline]
    pub fn edge_faces(&self, e: EdgeId) -> (FaceId, Option<FaceId>) {
        let h = self.edge_half_edge(e);
        (self.face(h), self.twin(h).map(|t| self.face(t)))
    }

    /// Whether edge `e` has a single face.
    #[inline]
    pub fn is_boundary_edge(&self, e: EdgeId) -> bool {
        self.is_boundary_half_edge(self.edge_half_edge(e))
    }

    /// Number of boundary edges. Cost `O(#E)`.
    pub fn num_boundary_edges(&self) -> usize {
        self.edge_half_edge
            .iter()
            .filter(|h| !self.twin[h.idx()].is_valid())
            .count()
    }

    /// Sharpness of edge `e` in `tags` (0 when untagged; see [`Tags::crease`]). Cost: one hash
    /// lookup.
    pub fn edge_sharpness(&self, e: EdgeId, tags: &Tags) -> f64 {
        let [a, b] = self.edge_vertices(e);
        tags.crease(a.0, b.0)
    }

    /// Per-edge sharpness (`#E` values, 0 when untagged). Cost `O(#E)` hash lookups, or
    /// nothing when `tags` has no creases.
    pub fn edge_sharpness_array(&self, tags: &Tags) -> Vec<f64> {
        if tags.is_empty() {
            return vec![0.0; self.num_edges()];
        }
        (0..self.num_edges() as u32)
            .map(|e| self.edge_sharpness(EdgeId(e), tags))
            .collect()
    }

    /// Corner sharpness of vertex `v` in `tags` (0 when untagged; see [`Tags::corner`]).
    pub fn vertex_sharpness(&self, v: VertexId, tags: &Tags) -> f64 {
        tags.corner(v.0)
    }

    /// The half-edge from `a` to `b`, if any. Cost `O(valence(a))`.
    pub fn find_half_edge(&self, a: VertexId, b: VertexId) -> Option<HalfEdgeId> {
        self.outgoing(a).find(|&h| self.dest(h) == b)
    }

    /// The edge between `a` and `b`, if any. Cost `O(valence(a) + valence(b))`.
    pub fn find_edge(&self, a: VertexId, b: VertexId) -> Option<EdgeId> {
        self.find_half_edge(a, b)
            .or_else(|| self.find_half_edge(b, a))
            .map(|h| self.edge(h))
    }

    // ---- per vertex -------------------------------------------------------------------------

    /// The stored outgoing half-edge of `v` (for a boundary vertex, the clockwise-most one, whose
    /// twin is missing), or `None` when `v` is unreferenced.
    #[inline]
    pub fn vertex_half_edge(&self, v: VertexId) -> Option<HalfEdgeId> {
        let h = self.vertex_half_edge[v.idx()];
        h.is_valid().then_some(h)
    }

    /// Outgoing half-edges of `v`, counter-clockwise (in winding order), starting at
    /// [`Self::vertex_half_edge`]. One per incident face. Cost `O(valence)`.
    pub fn outgoing(&self, v: VertexId) -> Outgoing<'_> {
        let start = self.vertex_half_edge[v.idx()];
        Outgoing {
            mesh: self,
            start,
            cur: start,
        }
    }

    /// Faces around `v`, counter-clockwise; for a boundary vertex from one boundary edge to
    /// the other. Cost `O(valence)`.
    pub fn vertex_faces(&self, v: VertexId) -> impl Iterator<Item = FaceId> + '_ {
        self.outgoing(v).map(move |h| self.face(h))
    }

    /// One-ring neighbours of `v`, counter-clockwise: the destinations of
    /// [`Self::outgoing`], plus, for a boundary vertex, the origin of the incoming boundary
    /// half-edge last. Neighbour `i` and `i + 1` span face `i` of [`Self::vertex_faces`].
    /// Cost `O(valence)`.
    pub fn vertex_neighbors(&self, v: VertexId) -> impl Iterator<Item = VertexId> + '_ {
        let mut it = self.outgoing(v);
        let mut last = None;
        std::iter::from_fn(move || match it.next() {
            Some(h) => {
                last = Some(h);
                Some(self.dest(h))
            }
            None => {
                let h = last.take()?;
                let p = self.prev(h);
                self.is_boundary_half_edge(p).then(|| self.origin(p))
            }
        })
    }

    /// Number of edges at `v` (neighbours in the one-ring; 0 when unreferenced). Cost
    /// `O(valence)`.
    pub fn valence(&self, v: VertexId) -> usize {
        let n = self.outgoing(v).count();
        n + usize::from(self.is_boundary_vertex(v))
    }

    /// Number of faces around `v`. Cost `O(valence)`.
    pub fn vertex_face_count(&self, v: VertexId) -> usize {
        self.outgoing(v).count()
    }

    /// Whether `v` lies on the boundary (unreferenced vertices are not). Cost `O(1)`.
    #[inline]
    pub fn is_boundary_vertex(&self, v: VertexId) -> bool {
        let h = self.vertex_half_edge[v.idx()];
        h.is_valid() && !self.twin[h.idx()].is_valid()
    }

    // ---- global -----------------------------------------------------------------------------

    /// Boundary loops as ordered vertex lists, each following the face winding (the faces are
    /// on the left of `loop[i] → loop[i+1]`). Loops are listed by their lowest boundary
    /// half-edge and start at its origin. Cost `O(#H)`.
    pub fn boundary_loops(&self) -> Vec<Vec<VertexId>> {
        let mut seen = vec![false; self.num_half_edges()];
        let mut loops = Vec::new();
        for h0 in 0..self.num_half_edges() {
            if seen[h0] || self.twin[h0].is_valid() {
                continue;
            }
            let mut lp = Vec::new();
            let mut h = HalfEdgeId(h0 as u32);
            // Each boundary vertex has exactly one outgoing boundary half-edge (single fan).
            while !seen[h.idx()] {
                seen[h.idx()] = true;
                lp.push(self.origin(h));
                h = self.vertex_half_edge[self.dest(h).idx()];
            }
            loops.push(lp);
        }
        loops
    }

    /// Connected components of the faces (see [`crate::face_components`]). Cost `O(#V + #H)`.
    pub fn components(&self) -> Components {
        components_by(self.num_vertices(), self.num_faces(), |f| {
            self.face_vertices(FaceId(f as u32)).iter().map(|v| v.0)
        })
    }

    /// Genus of each connected component (in the order of [`Self::components`]), from
    /// `g = (2 − χ − b) / 2` per component. Cost `O(#V + #H)`.
    pub fn component_genera(&self) -> Vec<u32> {
        let comps = self.components();
        let mut chi: Vec<i64> = comps.vertex_counts().iter().map(|&v| v as i64).collect();
        for &l in &comps.face_labels {
            chi[l as usize] += 1;
        }
        for &h in &self.edge_half_edge {
            chi[comps.vertex_labels[self.origin(h).idx()] as usize] -= 1;
        }
        let mut loops = vec![0usize; comps.count];
        for lp in self.boundary_loops() {
            loops[comps.vertex_labels[lp[0].idx()] as usize] += 1;
        }
        chi.iter()
            .zip(&loops)
            .map(|(&c, &b)| {
                // A manifold, consistently oriented mesh always gives an even, non-negative value.
                genus(c, 1, b).unwrap_or_else(|| {
                    unreachable!("oriented manifold component with χ = {c}, {b} loops")
                })
            })
            .collect()
    }

    /// Total genus (sum over components). Cost `O(#V + #H)`.
    pub fn genus(&self) -> u32 {
        self.component_genera().iter().sum()
    }

    /// Euler characteristic `χ = V_used − E + F` (unreferenced vertices excluded). Cost `O(#V)`.
    pub fn euler_characteristic(&self) -> i64 {
        crate::components::euler_characteristic(
            self.num_referenced_vertices(),
            self.num_edges(),
            self.num_faces(),
        )
    }
}

/// Iterator over the outgoing half-edges of a vertex, counter-clockwise; see
/// [`HalfEdgeMesh::outgoing`].
#[derive(Clone, Debug)]
pub struct Outgoing<'a> {
    mesh: &'a HalfEdgeMesh,
    start: HalfEdgeId,
    cur: HalfEdgeId,
}

impl Iterator for Outgoing<'_> {
    type Item = HalfEdgeId;

    #[inline]
    fn next(&mut self) -> Option<HalfEdgeId> {
        if !self.cur.is_valid() {
            return None;
        }
        let h = self.cur;
        let n = self.mesh.twin[self.mesh.prev[h.idx()].idx()];
        self.cur = if n == self.start {
            HalfEdgeId::INVALID
        } else {
            n
        };
        Some(h)
    }
}

/// Checks face sizes, vertex ranges and repeated vertices. Cost `O(#H)` (faces above 16
/// vertices are sorted).
pub(crate) fn validate_faces(faces: &Polygons, num_vertices: usize) -> Result<(), TopologyError> {
    let mut scratch = Vec::new();
    for (f, poly) in faces.iter().enumerate() {
        let face = FaceId(f as u32);
        if poly.len() < 3 {
            return Err(TopologyError::TooFewVertices {
                face,
                len: poly.len(),
            });
        }
        if let Some(&v) = poly.iter().find(|&&v| v as usize >= num_vertices) {
            return Err(TopologyError::VertexOutOfRange {
                face,
                vertex: v,
                num_vertices,
            });
        }
        if let Some(v) = repeated_vertex(poly, &mut scratch) {
            return Err(TopologyError::RepeatedVertex {
                face,
                vertex: VertexId(v),
            });
        }
    }
    Ok(())
}

/// A vertex listed twice in `poly`, if any. `O(n²)` for `n ≤ 16`, else `O(n log n)`.
pub(crate) fn repeated_vertex(poly: &[u32], scratch: &mut Vec<u32>) -> Option<u32> {
    if poly.len() <= 16 {
        for i in 1..poly.len() {
            if poly[..i].contains(&poly[i]) {
                return Some(poly[i]);
            }
        }
        None
    } else {
        scratch.clear();
        scratch.extend_from_slice(poly);
        scratch.sort_unstable();
        scratch.windows(2).find(|w| w[0] == w[1]).map(|w| w[0])
    }
}
