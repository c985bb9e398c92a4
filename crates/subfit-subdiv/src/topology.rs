//! The adjacency the subdivision rules need, built from a [`Polygons`] face list: numbered
//! undirected edges and, for each vertex, its ring of edges and faces in OpenSubdiv's `Vtr` order.
//!
//! Built locally (half-edges found through per-vertex lists of outgoing directed edges) so the
//! ring order matches OpenSubdiv exactly: counter-clockwise, face `i` between ring edges `i` and
//! `i + 1`, and at a boundary vertex ring edge 0 is the leading boundary edge (see
//! [`crate::Neighborhood`]).

use crate::error::SubdivError;
use rayon::prelude::*;
use subfit_mesh::Polygons;

const NONE: u32 = u32::MAX;

/// The rings of a block of consecutive vertices, with offsets relative to the block.
#[derive(Default)]
struct RingPart {
    edge_ends: Vec<u32>,
    corner_ends: Vec<u32>,
    edges: Vec<u32>,
    verts: Vec<u32>,
    corners: Vec<u32>,
}

/// A mesh whose adjacency is known in closed form, for [`Topology::from_closed_form`]: corner
/// `i` of face `f` is `face_offsets[f] + i`, and rings are in the order [`Topology::new`] gives
/// them (counter-clockwise, from the leading boundary edge or the lowest-numbered corner).
pub(crate) trait ClosedForm: Sync {
    /// Reusable buffers of [`Self::ring`].
    type Ring: Default;
    /// Number of vertices.
    fn num_vertices(&self) -> usize;
    /// Number of corners.
    fn num_corners(&self) -> usize;
    /// Where each face's corners start, and the number of corners last (`#F + 1` entries);
    /// called only with fewer than `u32::MAX` corners.
    fn face_offsets(&self) -> Vec<u32>;
    /// The vertex of corner `c`.
    fn vertex(&self, c: u32) -> u32;
    /// The next corner of `c`'s face.
    fn next(&self, c: u32) -> u32;
    /// The twin of corner `c` (the corner of the opposite directed edge), `u32::MAX` at a
    /// boundary.
    fn twin(&self, c: u32) -> u32;
    /// The ring of vertex `v`: its corners, and the far ends of its ring edges (one more than
    /// the corners at a boundary vertex), filled into `scratch`.
    fn ring<'r>(&self, v: u32, scratch: &'r mut Self::Ring) -> (&'r [u32], &'r [u32]);
}

/// Edge and vertex-ring adjacency of a manifold, consistently oriented polygon mesh.
///
/// A *corner* is a (face, vertex) incidence, numbered as positions in `Polygons::indices()`;
/// corner `c` of a face also names the directed edge from its vertex to the next vertex of the
/// face. Edges are numbered in order of first appearance when faces are scanned in order and each
/// face's corners in winding order. Memory O(#corners + #V).
#[derive(Clone, Debug, PartialEq)]
pub struct Topology {
    num_vertices: usize,
    offsets: Vec<u32>,
    indices: Vec<u32>,
    corner_face: Vec<u32>,
    next_vertex: Vec<u32>,
    corner_edge: Vec<u32>,
    edge_verts: Vec<[u32; 2]>,
    edge_corners: Vec<[u32; 2]>,
    ring_offsets: Vec<u32>,
    ring_edges: Vec<u32>,
    ring_verts: Vec<u32>,
    face_ring_offsets: Vec<u32>,
    ring_corners: Vec<u32>,
}

impl Topology {
    /// Builds the adjacency of `faces` over `num_vertices` vertices. Vertices without faces are
    /// allowed (they have empty rings).
    ///
    /// Errors: faces with fewer than 3 vertices, repeated or out-of-range vertex ids, a directed
    /// edge used twice (non-manifold edge or inconsistent orientation), a vertex whose faces form
    /// several fans. Cost O(#corners · max valence).
    pub fn new(faces: &Polygons, num_vertices: usize) -> Result<Self, SubdivError> {
        let offsets = faces.offsets().to_vec();
        let indices = faces.indices().to_vec();
        let nc = indices.len();
        if num_vertices >= NONE as usize || nc >= NONE as usize {
            return Err(SubdivError::TooLarge {
                what: "vertices or face indices",
                count: num_vertices.max(nc),
            });
        }
        let mut corner_face = vec![0u32; nc];
        for (f, w) in offsets.windows(2).enumerate() {
            let face = &indices[w[0] as usize..w[1] as usize];
            if face.len() < 3 {
                return Err(SubdivError::DegenerateFace {
                    face: f,
                    len: face.len(),
                });
            }
            for (i, &v) in face.iter().enumerate() {
                if v as usize >= num_vertices {
                    return Err(SubdivError::VertexOutOfRange {
                        face: f,
                        vertex: v,
                        num_vertices,
                    });
                }
                if face[..i].contains(&v) {
                    return Err(SubdivError::RepeatedVertex { face: f, vertex: v });
                }
            }
            corner_face[w[0] as usize..w[1] as usize].fill(f as u32);
        }
        let mut t = Topology {
            num_vertices,
            offsets,
            indices,
            corner_face,
            next_vertex: Vec::new(),
            corner_edge: vec![NONE; nc],
            edge_verts: Vec::new(),
            edge_corners: Vec::new(),
            ring_offsets: Vec::new(),
            ring_edges: Vec::new(),
            ring_verts: Vec::new(),
            face_ring_offsets: Vec::new(),
            ring_corners: Vec::new(),
        };
        t.next_vertex = (0..nc as u32)
            .into_par_iter()
            .map(|c| t.indices[t.corner_next(c) as usize])
            .collect();
        // Outgoing corners per vertex (CSR by counting sort), ascending corner order.
        let mut out_off = vec![0u32; num_vertices + 1];
        for &v in &t.indices {
            out_off[v as usize + 1] += 1;
        }
        for i in 0..num_vertices {
            out_off[i + 1] += out_off[i];
        }
        let mut fill = out_off.clone();
        let mut out = vec![0u32; nc];
        for (c, &v) in t.indices.iter().enumerate() {
            out[fill[v as usize] as usize] = c as u32;
            fill[v as usize] += 1;
        }
        drop(fill);
        let outgoing =
            |v: u32| &out[out_off[v as usize] as usize..out_off[v as usize + 1] as usize];
        let twin = t.twins(&outgoing)?;
        t.build_edges(&twin);
        t.build_rings(&outgoing, &twin)?;
        Ok(t)
    }

    /// The adjacency of a mesh given in closed form ([`ClosedForm`]: every corner's vertex,
    /// successor and twin, and every vertex's ring), equal to `Topology::new` of its faces but
    /// without the twin search, the outgoing lists or validation (the caller vouches for a
    /// valid mesh). Used for the child of a uniform refinement (module `child`).
    ///
    /// Errors: [`SubdivError::TooLarge`] if the mesh has `u32::MAX` or more vertices or
    /// corners. Cost O(#corners), parallel except for the edge numbering.
    pub(crate) fn from_closed_form<C: ClosedForm>(child: &C) -> Result<Self, SubdivError> {
        let (nv, nc) = (child.num_vertices(), child.num_corners());
        if nv >= NONE as usize || nc >= NONE as usize {
            return Err(SubdivError::TooLarge {
                what: "vertices or face indices",
                count: nv.max(nc),
            });
        }
        let offsets = child.face_offsets();
        let corners = || (0..nc as u32).into_par_iter();
        let indices: Vec<u32> = corners().map(|x| child.vertex(x)).collect();
        let next_vertex = corners().map(|x| indices[child.next(x) as usize]).collect();
        let twin: Vec<u32> = corners().map(|x| child.twin(x)).collect();
        let mut corner_face = vec![0u32; nc];
        for (f, w) in offsets.windows(2).enumerate() {
            corner_face[w[0] as usize..w[1] as usize].fill(f as u32);
        }
        let mut t = Topology {
            num_vertices: nv,
            offsets,
            indices,
            corner_face,
            next_vertex,
            corner_edge: vec![NONE; nc],
            edge_verts: Vec::new(),
            edge_corners: Vec::new(),
            ring_offsets: Vec::new(),
            ring_edges: Vec::new(),
            ring_verts: Vec::new(),
            face_ring_offsets: Vec::new(),
            ring_corners: Vec::new(),
        };
        t.build_edges(&twin);
        drop(twin);
        const CHUNK: usize = 4096;
        let this = &t;
        let parts: Vec<RingPart> = (0..nv.div_ceil(CHUNK))
            .into_par_iter()
            .map(|k| {
                let mut part = RingPart::default();
                let mut ring = C::Ring::default();
                for v in (k * CHUNK) as u32..((k + 1) * CHUNK).min(nv) as u32 {
                    let (corners, verts) = child.ring(v, &mut ring);
                    part.corners.extend_from_slice(corners);
                    part.verts.extend_from_slice(verts);
                    part.edges
                        .extend(corners.iter().map(|&c| this.corner_edge[c as usize]));
                    if let (Some(&last), true) = (corners.last(), verts.len() > corners.len()) {
                        // The closing boundary edge, entering `v`.
                        part.edges
                            .push(this.corner_edge[this.corner_prev(last) as usize]);
                    }
                    part.edge_ends.push(part.edges.len() as u32);
                    part.corner_ends.push(part.corners.len() as u32);
                }
                part
            })
            .collect();
        t.set_rings(parts);
        Ok(t)
    }

    /// The twin of every corner (the corner of the opposite directed edge, `NONE` on a
    /// boundary), checking that no directed edge is used twice. Parallel over corners.
    fn twins<'a>(
        &self,
        outgoing: &(impl Fn(u32) -> &'a [u32] + Sync),
    ) -> Result<Vec<u32>, SubdivError> {
        let nc = self.indices.len();
        let ends = |c: usize| (self.indices[c], self.next_vertex[c]);
        let dup = (0..nc).into_par_iter().position_first(|c| {
            let (a, b) = ends(c);
            outgoing(a)
                .iter()
                .filter(|&&o| self.next_vertex[o as usize] == b)
                .nth(1)
                .is_some()
        });
        if let Some(c) = dup {
            let (a, b) = ends(c);
            return Err(SubdivError::NonManifoldEdge { a, b });
        }
        Ok((0..nc)
            .into_par_iter()
            .map(|c| {
                let (a, b) = ends(c);
                outgoing(b)
                    .iter()
                    .copied()
                    .find(|&o| self.next_vertex[o as usize] == a)
                    .unwrap_or(NONE)
            })
            .collect())
    }

    /// Numbers the edges in order of first appearance (corner order).
    fn build_edges(&mut self, twin: &[u32]) {
        for (c, &t) in twin.iter().enumerate() {
            if self.corner_edge[c] != NONE {
                continue;
            }
            let e = self.edge_verts.len() as u32;
            self.corner_edge[c] = e;
            if t != NONE {
                self.corner_edge[t as usize] = e;
            }
            self.edge_verts.push([self.indices[c], self.next_vertex[c]]);
            self.edge_corners.push([c as u32, t]);
        }
    }

    /// The counter-clockwise rings of all vertices, built in parallel over blocks of vertices
    /// and concatenated. The step around a vertex `v` from its corner `c` goes to the twin of
    /// the corner before `c` (the directed edge from `v` to the previous vertex of the face).
    fn build_rings<'a>(
        &mut self,
        outgoing: &(impl Fn(u32) -> &'a [u32] + Sync),
        twin: &[u32],
    ) -> Result<(), SubdivError> {
        const CHUNK: usize = 4096;
        let nv = self.num_vertices;
        let this = &*self;
        let parts: Vec<Result<RingPart, SubdivError>> = (0..nv.div_ceil(CHUNK))
            .into_par_iter()
            .map(|k| this.ring_part(k * CHUNK..((k + 1) * CHUNK).min(nv), outgoing, twin))
            .collect();
        let parts = parts.into_iter().collect::<Result<Vec<_>, _>>()?;
        self.set_rings(parts);
        Ok(())
    }

    /// Concatenates the rings of consecutive blocks of vertices (all vertices, in order).
    fn set_rings(&mut self, parts: Vec<RingPart>) {
        let nv = self.num_vertices;
        let mut ring_offsets = Vec::with_capacity(nv + 1);
        let mut face_ring_offsets = Vec::with_capacity(nv + 1);
        ring_offsets.push(0);
        face_ring_offsets.push(0);
        let mut ring_edges = Vec::with_capacity(self.indices.len() + nv);
        let mut ring_verts = Vec::with_capacity(self.indices.len() + nv);
        let mut ring_corners = Vec::with_capacity(self.indices.len());
        for part in parts {
            let (e0, c0) = (ring_edges.len() as u32, ring_corners.len() as u32);
            ring_offsets.extend(part.edge_ends.iter().map(|&x| x + e0));
            face_ring_offsets.extend(part.corner_ends.iter().map(|&x| x + c0));
            ring_edges.extend_from_slice(&part.edges);
            ring_verts.extend_from_slice(&part.verts);
            ring_corners.extend_from_slice(&part.corners);
        }
        self.ring_offsets = ring_offsets;
        self.face_ring_offsets = face_ring_offsets;
        self.ring_edges = ring_edges;
        self.ring_verts = ring_verts;
        self.ring_corners = ring_corners;
    }

    /// The rings of the vertices `range` (see [`Self::build_rings`]).
    fn ring_part<'a>(
        &self,
        range: std::ops::Range<usize>,
        outgoing: &impl Fn(u32) -> &'a [u32],
        twin: &[u32],
    ) -> Result<RingPart, SubdivError> {
        let mut part = RingPart::default();
        for v in range.start as u32..range.end as u32 {
            let outs = outgoing(v);
            if let Some(&first) = outs.first() {
                // A boundary vertex starts at the face whose leading edge has no twin.
                let start = outs
                    .iter()
                    .copied()
                    .find(|&c| twin[c as usize] == NONE)
                    .unwrap_or(first);
                let mut cur = start;
                let mut count = 0usize;
                loop {
                    count += 1;
                    if count > outs.len() {
                        return Err(SubdivError::NonManifoldVertex { vertex: v });
                    }
                    part.corners.push(cur);
                    part.edges.push(self.corner_edge[cur as usize]);
                    part.verts.push(self.next_vertex[cur as usize]);
                    let pc = self.corner_prev(cur);
                    match twin[pc as usize] {
                        NONE => {
                            part.edges.push(self.corner_edge[pc as usize]);
                            part.verts.push(self.indices[pc as usize]);
                            break;
                        }
                        c2 if c2 == start => break,
                        c2 => cur = c2,
                    }
                }
                if count != outs.len() {
                    return Err(SubdivError::NonManifoldVertex { vertex: v });
                }
            }
            part.edge_ends.push(part.edges.len() as u32);
            part.corner_ends.push(part.corners.len() as u32);
        }
        Ok(part)
    }

    /// Number of vertices.
    #[inline]
    pub fn num_vertices(&self) -> usize {
        self.num_vertices
    }

    /// Number of faces.
    #[inline]
    pub fn num_faces(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Number of undirected edges.
    #[inline]
    pub fn num_edges(&self) -> usize {
        self.edge_verts.len()
    }

    /// Vertex ids of face `f` in winding order.
    #[inline]
    pub fn face(&self, f: usize) -> &[u32] {
        &self.indices[self.offsets[f] as usize..self.offsets[f + 1] as usize]
    }

    /// Index of the first corner of face `f` (its corners are consecutive).
    #[inline]
    pub fn face_first_corner(&self, f: usize) -> usize {
        self.offsets[f] as usize
    }

    /// Edge ids of face `f`: entry `i` joins face vertices `i` and `i + 1`.
    #[inline]
    pub fn face_edges(&self, f: usize) -> &[u32] {
        &self.corner_edge[self.offsets[f] as usize..self.offsets[f + 1] as usize]
    }

    /// The face containing corner `c`.
    #[inline]
    pub fn corner_face(&self, c: u32) -> u32 {
        self.corner_face[c as usize]
    }

    /// The vertex of corner `c`.
    #[inline]
    pub fn corner_vertex(&self, c: u32) -> u32 {
        self.indices[c as usize]
    }

    /// The corner after `c` in its face's winding.
    #[inline]
    pub fn corner_next(&self, c: u32) -> u32 {
        let f = self.corner_face[c as usize] as usize;
        if c + 1 == self.offsets[f + 1] {
            self.offsets[f]
        } else {
            c + 1
        }
    }

    /// The corner before `c` in its face's winding.
    #[inline]
    pub fn corner_prev(&self, c: u32) -> u32 {
        let f = self.corner_face[c as usize] as usize;
        if c == self.offsets[f] {
            self.offsets[f + 1] - 1
        } else {
            c - 1
        }
    }

    /// The vertex after corner `c`'s vertex in its face.
    #[inline]
    pub fn corner_next_vertex(&self, c: u32) -> u32 {
        self.next_vertex[c as usize]
    }

    /// The edge of corner `c` (joining its vertex to the next vertex of its face).
    #[inline]
    pub(crate) fn corner_edge(&self, c: u32) -> u32 {
        self.corner_edge[c as usize]
    }

    /// The twin of corner `c`: the corner of the opposite directed edge, `u32::MAX` on a
    /// boundary.
    #[inline]
    pub(crate) fn corner_twin(&self, c: u32) -> u32 {
        let [a, b] = self.edge_corners[self.corner_edge[c as usize] as usize];
        if a == c {
            b
        } else {
            a
        }
    }

    /// End vertices of edge `e`, in the direction of the first face that uses it.
    #[inline]
    pub fn edge_vertices(&self, e: u32) -> [u32; 2] {
        self.edge_verts[e as usize]
    }

    /// The (one or two) corners whose directed edge is `e`: `[c, u32::MAX]` on a boundary.
    #[inline]
    pub fn edge_corners(&self, e: u32) -> [u32; 2] {
        self.edge_corners[e as usize]
    }

    /// Whether edge `e` has a single face.
    #[inline]
    pub fn is_boundary_edge(&self, e: u32) -> bool {
        self.edge_corners[e as usize][1] == NONE
    }

    /// Ring edges of vertex `v`, counter-clockwise (see [`crate::Neighborhood`]).
    #[inline]
    pub fn vertex_edges(&self, v: u32) -> &[u32] {
        let (a, b) = (
            self.ring_offsets[v as usize],
            self.ring_offsets[v as usize + 1],
        );
        &self.ring_edges[a as usize..b as usize]
    }

    /// Far ends of the ring edges of `v` (same order as [`Self::vertex_edges`]).
    #[inline]
    pub fn vertex_ring(&self, v: u32) -> &[u32] {
        let (a, b) = (
            self.ring_offsets[v as usize],
            self.ring_offsets[v as usize + 1],
        );
        &self.ring_verts[a as usize..b as usize]
    }

    /// Corners of `v` in its incident faces, counter-clockwise: entry `i` is face `i` of the ring.
    #[inline]
    pub fn vertex_corners(&self, v: u32) -> &[u32] {
        let (a, b) = (
            self.face_ring_offsets[v as usize],
            self.face_ring_offsets[v as usize + 1],
        );
        &self.ring_corners[a as usize..b as usize]
    }

    /// Whether `v` lies on the boundary (it has more ring edges than faces).
    #[inline]
    pub fn is_boundary_vertex(&self, v: u32) -> bool {
        self.vertex_edges(v).len() > self.vertex_corners(v).len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rings_are_counter_clockwise_and_boundaries_start_at_the_leading_edge() {
        // Two triangles sharing edge 1-2: 0 1 2, 2 1 3.
        let p = Polygons::from_triangles(&[[0, 1, 2], [2, 1, 3]]);
        let t = Topology::new(&p, 4).unwrap();
        assert_eq!(t.num_edges(), 5);
        // Vertex 1 starts at face 1, whose leading edge 1->3 is a boundary edge.
        assert_eq!(t.vertex_ring(1), &[3, 2, 0]);
        assert!(t.is_boundary_vertex(1));
        let bad = Polygons::from_triangles(&[[0, 1, 2], [0, 1, 3]]);
        assert!(matches!(
            Topology::new(&bad, 4),
            Err(SubdivError::NonManifoldEdge { .. })
        ));
        let bowtie = Polygons::from_triangles(&[[0, 1, 2], [0, 3, 4]]);
        assert!(matches!(
            Topology::new(&bowtie, 5),
            Err(SubdivError::NonManifoldVertex { vertex: 0 })
        ));
    }
}
