//! The adjacency of a once-refined mesh, read off its parent's [`Topology`] without building the
//! child's.
//!
//! Uniform refinement replaces every parent element by a fixed pattern of child elements, so
//! every child corner, its successor in its face and its twin are closed-form functions of
//! the parent's corners, edges and twins — the construction of OpenSubdiv's
//! `Vtr::QuadRefinement` / `Vtr::TriRefinement`, which derive each child level from its parent
//! instead of searching for twins. With the child face order of [`crate::refine`]:
//!
//! * Catmull-Clark: the child quad of parent corner `c` (vertex `v`, face `f`, edges `e_c`
//!   leaving and `e_p` entering `v`) has index `c` and corners `4c … 4c+3` at the vertex point
//!   of `v`, the edge points of `e_c`, the face point of `f`, the edge point of `e_p`.
//! * Loop: parent triangle `f` with corners `3f + k` and edges `e_k` has children `4f + k`
//!   `= (v_k, e_k, e_{k−1})` and `4f + 3 = (e_0, e_1, e_2)`; child corner `3(4f + j) + i`.
//!
//! Rings are then walked exactly as [`Topology::new`] walks them (counter-clockwise from the
//! leading boundary edge, or from the vertex's lowest-numbered corner), so a child ring here
//! equals the ring of the child [`Topology`], entry for entry (checked by the tests of `refine`, which also check the child faces).
//! The last level of the sampling operator uses this instead of building a [`Topology`] with
//! one entry per corner of the finest mesh, which it would read only once.
//!
//! Cost: each query O(1) parent look-ups; a ring O(valence). Nothing is allocated but the
//! caller's [`ChildRing`] buffers.

use crate::error::SubdivError;
use crate::scheme::Scheme;
use crate::topology::{ClosedForm, Topology};

const NONE: u32 = u32::MAX;

/// How every face of a uniform parent splits: Loop's 1→4 triangles or Catmull-Clark's quads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Split {
    Triangles,
    Quads,
}

/// Corner algebra of the child of `topo` under one step of `scheme`.
///
/// The parent must suit the scheme (Loop: triangles only). Child corners are numbered as
/// positions in the child face list's indices; child vertices as in [`crate::refine`].
#[derive(Clone, Copy)]
pub(crate) struct ChildCorners<'a> {
    topo: &'a Topology,
    scheme: Split,
    nv: u32,
    ne: u32,
}

/// The ring of one child vertex, as [`Topology::vertex_ring`] and [`Topology::vertex_corners`]
/// of the child mesh would give it, with whether each ring edge is a boundary edge. Buffers are
/// reused from vertex to vertex.
#[derive(Clone, Debug, Default)]
pub(crate) struct ChildRing {
    /// The vertex's corners, counter-clockwise (one per incident face).
    pub(crate) corners: Vec<u32>,
    /// Far ends of the ring edges (one more than `corners` at a boundary vertex).
    pub(crate) verts: Vec<u32>,
    /// Whether each ring edge has a single face.
    pub(crate) boundary: Vec<bool>,
    /// Catmull-Clark: the vertex two corners away in each ring face (the quad's diagonal);
    /// empty for Loop.
    pub(crate) diagonals: Vec<u32>,
}

impl<'a> ChildCorners<'a> {
    /// The child of `topo` (which must suit `scheme`).
    ///
    /// # Panics
    /// For [`Scheme::QuadTriangle`], whose children are not of one size (its child adjacency is
    /// built by [`refined_topology`]).
    #[track_caller]
    pub(crate) fn new(topo: &'a Topology, scheme: Scheme) -> Self {
        let scheme = match scheme {
            Scheme::Loop => Split::Triangles,
            Scheme::CatmullClark => Split::Quads,
            Scheme::QuadTriangle => panic!("the quad/triangle child has no closed form"),
        };
        debug_assert!(
            scheme == Split::Quads || (0..topo.num_faces()).all(|f| topo.face(f).len() == 3)
        );
        Self {
            topo,
            scheme,
            nv: topo.num_vertices() as u32,
            ne: topo.num_edges() as u32,
        }
    }

    /// Whether the children are triangles (Loop) rather than quads (Catmull-Clark).
    pub(crate) fn triangles(&self) -> bool {
        self.scheme == Split::Triangles
    }

    /// Number of child vertices.
    pub(crate) fn num_vertices(&self) -> usize {
        let t = self.topo;
        t.num_vertices()
            + t.num_edges()
            + match self.scheme {
                Split::Quads => t.num_faces(),
                Split::Triangles => 0,
            }
    }

    /// The number of vertices of every child face (4 for Catmull-Clark, 3 for Loop).
    pub(crate) fn face_size(&self) -> u32 {
        match self.scheme {
            Split::Quads => 4,
            Split::Triangles => 3,
        }
    }

    /// Number of child faces (one per parent corner for Catmull-Clark, four per parent
    /// triangle for Loop).
    pub(crate) fn num_faces(&self) -> usize {
        match self.scheme {
            Split::Quads => self.topo.face_first_corner(self.topo.num_faces()),
            Split::Triangles => 4 * self.topo.num_faces(),
        }
    }

    /// The child vertex of child corner `x`.
    #[inline]
    pub(crate) fn vertex(&self, x: u32) -> u32 {
        let t = self.topo;
        match self.scheme {
            Split::Quads => {
                let c = x / 4;
                match x % 4 {
                    0 => t.corner_vertex(c),
                    1 => self.nv + t.corner_edge(c),
                    2 => self.nv + self.ne + t.corner_face(c),
                    _ => self.nv + t.corner_edge(t.corner_prev(c)),
                }
            }
            Split::Triangles => {
                let (f, j, i) = (x / 12, (x % 12) / 3, x % 3);
                match (j, i) {
                    (3, i) => self.nv + t.corner_edge(3 * f + i),
                    (j, 0) => t.corner_vertex(3 * f + j),
                    (j, 1) => self.nv + t.corner_edge(3 * f + j),
                    (j, _) => self.nv + t.corner_edge(3 * f + (j + 2) % 3),
                }
            }
        }
    }

    /// The corner after child corner `x` in its (child) face.
    #[inline]
    pub(crate) fn next(&self, x: u32) -> u32 {
        match self.scheme {
            Split::Quads => (x & !3) | ((x + 1) & 3),
            Split::Triangles => x - x % 3 + (x + 1) % 3,
        }
    }

    /// The corner before child corner `x` in its face.
    #[cfg(test)]
    #[inline]
    pub(crate) fn prev(&self, x: u32) -> u32 {
        match self.scheme {
            Split::Quads => (x & !3) | ((x + 3) & 3),
            Split::Triangles => x - x % 3 + (x + 2) % 3,
        }
    }

    /// The twin of child corner `x` (the corner of the opposite directed edge), `u32::MAX` on a
    /// boundary.
    #[inline]
    pub(crate) fn twin(&self, x: u32) -> u32 {
        let t = self.topo;
        match self.scheme {
            Split::Quads => {
                let c = x / 4;
                match x % 4 {
                    // Vertex point → edge point of e_c: back along e_c in the other face.
                    0 => match t.corner_twin(c) {
                        NONE => NONE,
                        o => 4 * t.corner_next(o) + 3,
                    },
                    1 => 4 * t.corner_next(c) + 2,
                    2 => 4 * t.corner_prev(c) + 1,
                    _ => match t.corner_twin(t.corner_prev(c)) {
                        NONE => NONE,
                        o => 4 * o,
                    },
                }
            }
            Split::Triangles => {
                let (f, j, i) = (x / 12, (x % 12) / 3, x % 3);
                match (j, i) {
                    (3, i) => 12 * f + 3 * ((i + 1) % 3) + 1,
                    (j, 0) => match t.corner_twin(3 * f + j) {
                        NONE => NONE,
                        o => 12 * (o / 3) + 3 * ((o % 3 + 1) % 3) + 2,
                    },
                    (j, 1) => 12 * f + 9 + (j + 2) % 3,
                    (j, _) => match t.corner_twin(3 * f + (j + 2) % 3) {
                        NONE => NONE,
                        o => 12 * (o / 3) + 3 * (o % 3),
                    },
                }
            }
        }
    }

    /// Appends the child corners of child vertex `w` (any order) to `out`.
    #[cfg(test)]
    fn outgoing(&self, w: u32, out: &mut Vec<u32>) {
        let t = self.topo;
        let (nv, ne) = (self.nv, self.ne);
        if w < nv {
            let first = |c: u32| match self.scheme {
                Split::Quads => 4 * c,
                Split::Triangles => 12 * (c / 3) + 3 * (c % 3),
            };
            out.extend(t.vertex_corners(w).iter().map(|&c| first(c)));
        } else if w < nv + ne {
            for c in t.edge_corners(w - nv) {
                if c == NONE {
                    continue;
                }
                match self.scheme {
                    Split::Quads => {
                        out.extend([4 * c + 1, 4 * t.corner_next(c) + 3]);
                    }
                    Split::Triangles => {
                        let (f, k) = (c / 3, c % 3);
                        out.extend([
                            12 * f + 3 * k + 1,
                            12 * f + 3 * ((k + 1) % 3) + 2,
                            12 * f + 9 + k,
                        ]);
                    }
                }
            }
        } else {
            let f = (w - nv - ne) as usize;
            let c0 = t.face_first_corner(f) as u32;
            out.extend((c0..c0 + t.face(f).len() as u32).map(|c| 4 * c + 2));
        }
    }

    /// The ring of child vertex `w` into `ring` (cleared first), as [`Topology::new`] would
    /// build it for the child mesh, in closed form from the parent's ring, edge or face (the
    /// walk of [`Self::ring_by_walk`], worked out per kind of child vertex). Cost O(valence).
    pub(crate) fn ring(&self, w: u32, ring: &mut ChildRing) {
        ring.clear();
        let t = self.topo;
        let (nv, ne) = (self.nv, self.ne);
        let scheme = self.scheme;
        if w < nv {
            // Vertex point: the parent ring, edge for edge (the lowest child corner and the
            // boundary corner are those of the parent's lowest and boundary corners).
            for &c in t.vertex_corners(w) {
                match scheme {
                    Split::Quads => {
                        ring.corners.push(4 * c);
                        ring.diagonals.push(nv + ne + t.corner_face(c));
                    }
                    Split::Triangles => ring.corners.push(12 * (c / 3) + 3 * (c % 3)),
                }
            }
            for &e in t.vertex_edges(w) {
                ring.verts.push(nv + e);
                ring.boundary.push(t.is_boundary_edge(e));
            }
        } else if w < nv + ne {
            let [c0, c1] = t.edge_corners(w - nv);
            match scheme {
                Split::Quads => {
                    // Per side (corner c of the edge, n = next(c)): the child edges toward
                    // the vertex point of n's vertex and toward the face point.
                    let side = |c: u32| {
                        let n = t.corner_next(c);
                        [
                            (4 * n + 3, t.corner_vertex(n), nv + t.corner_edge(n)),
                            (
                                4 * c + 1,
                                nv + ne + t.corner_face(c),
                                nv + t.corner_edge(t.corner_prev(c)),
                            ),
                        ]
                    };
                    if c1 == NONE {
                        ring.push_rotated(&side(c0), false);
                        ring.verts.push(t.corner_vertex(c0));
                        ring.boundary[0] = true;
                        ring.boundary.push(true);
                    } else {
                        let ([a, b], [c, d]) = (side(c0), side(c1));
                        ring.push_rotated(&[a, b, c, d], true);
                    }
                }
                Split::Triangles => {
                    // Per side (corner 3f + k of the edge): the child edges toward the vertex
                    // point of v_{k+1} and the edge points of e_{k+1} and e_{k+2}.
                    let side = |c: u32| {
                        let (f, k) = (c / 3, c % 3);
                        let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
                        [
                            (12 * f + 3 * k1 + 2, t.corner_vertex(3 * f + k1), NONE),
                            (12 * f + 9 + k, nv + t.corner_edge(3 * f + k1), NONE),
                            (12 * f + 3 * k + 1, nv + t.corner_edge(3 * f + k2), NONE),
                        ]
                    };
                    if c1 == NONE {
                        ring.push_rotated(&side(c0), false);
                        ring.verts.push(t.corner_vertex(c0));
                        ring.boundary[0] = true;
                        ring.boundary.push(true);
                    } else {
                        let ([a, b, c], [d, e, f]) = (side(c0), side(c1));
                        ring.push_rotated(&[a, b, c, d, e, f], true);
                    }
                }
            }
        } else {
            // Face point (Catmull-Clark): one child edge per parent edge, starting at the
            // face's first corner.
            let f = (w - nv - ne) as usize;
            let c0 = t.face_first_corner(f) as u32;
            let n = t.face(f).len() as u32;
            for i in 0..n {
                let c = c0 + i;
                ring.corners.push(4 * c + 2);
                ring.verts.push(nv + t.corner_edge(c0 + (i + n - 1) % n));
                ring.boundary.push(false);
                ring.diagonals.push(t.corner_vertex(c));
            }
        }
        if scheme == Split::Triangles {
            ring.diagonals.clear();
        }
    }

    /// The ring of child vertex `w` by walking the child corners, as [`Topology::new`] does:
    /// from the leading boundary corner or else the lowest-numbered corner, to the twin of the
    /// previous corner, until the start or a boundary. The reference for [`Self::ring`].
    #[cfg(test)]
    pub(crate) fn ring_by_walk(&self, w: u32, ring: &mut ChildRing) {
        ring.clear();
        let mut outgoing = Vec::new();
        self.outgoing(w, &mut outgoing);
        let Some(&min) = outgoing.iter().min() else {
            return;
        };
        // At most one outgoing corner of a manifold vertex lacks a twin: the leading boundary
        // edge.
        let start = outgoing
            .iter()
            .copied()
            .find(|&x| self.twin(x) == NONE)
            .unwrap_or(min);
        let mut cur = start;
        loop {
            ring.corners.push(cur);
            ring.verts.push(self.vertex(self.next(cur)));
            ring.boundary.push(self.twin(cur) == NONE);
            if self.scheme == Split::Quads {
                ring.diagonals.push(self.vertex(self.next(self.next(cur))));
            }
            let pc = self.prev(cur);
            match self.twin(pc) {
                NONE => {
                    ring.verts.push(self.vertex(pc));
                    ring.boundary.push(true);
                    break;
                }
                x if x == start => break,
                x => cur = x,
            }
            assert!(ring.corners.len() <= outgoing.len());
        }
        assert_eq!(ring.corners.len(), outgoing.len());
    }
}

impl ChildRing {
    fn clear(&mut self) {
        self.corners.clear();
        self.verts.clear();
        self.boundary.clear();
        self.diagonals.clear();
    }

    /// Appends `(corner, far end, diagonal)` triples in cyclic order, starting at the lowest
    /// corner when `rotate` (an interior vertex) or at the first.
    #[inline]
    fn push_rotated(&mut self, entries: &[(u32, u32, u32)], rotate: bool) {
        let start = if rotate {
            (0..entries.len())
                .min_by_key(|&i| entries[i].0)
                .expect("entries")
        } else {
            0
        };
        for i in (start..entries.len()).chain(0..start) {
            let (c, v, d) = entries[i];
            self.corners.push(c);
            self.verts.push(v);
            self.boundary.push(false);
            self.diagonals.push(d);
        }
    }
}

/// The child mesh as a [`ClosedForm`] for [`Topology::from_closed_form`].
impl ClosedForm for ChildCorners<'_> {
    type Ring = ChildRing;

    fn num_vertices(&self) -> usize {
        ChildCorners::num_vertices(self)
    }

    fn num_faces(&self) -> usize {
        ChildCorners::num_faces(self)
    }

    fn face_size(&self) -> u32 {
        ChildCorners::face_size(self)
    }

    fn vertex(&self, c: u32) -> u32 {
        ChildCorners::vertex(self, c)
    }

    fn next(&self, c: u32) -> u32 {
        ChildCorners::next(self, c)
    }

    fn twin(&self, c: u32) -> u32 {
        ChildCorners::twin(self, c)
    }

    fn ring<'r>(&self, v: u32, scratch: &'r mut ChildRing) -> (&'r [u32], &'r [u32]) {
        ChildCorners::ring(self, v, scratch);
        (&scratch.corners, &scratch.verts)
    }
}

/// The adjacency of the once-refined `parent` (child face and vertex order of
/// [`crate::refine`]), equal to `Topology::new` of the child's faces but read off the parent's
/// corners in closed form ([`ChildCorners`]) instead of searched for: no twin search, no outgoing
/// lists, no validation (the child of a valid mesh is valid). The parent must suit `scheme`
/// (Loop: triangles only).
///
/// Errors: [`SubdivError::TooLarge`] if the child has `u32::MAX` or more vertices or corners.
/// Cost O(#child corners), parallel except for the edge numbering.
///
/// The quad/triangle scheme's children vary in size from face to face, so its child adjacency
/// is built from the child face list ([`Topology::new`]) instead of the closed form.
pub(crate) fn refined_topology(parent: &Topology, scheme: Scheme) -> Result<Topology, SubdivError> {
    if scheme == Scheme::QuadTriangle {
        let faces = crate::refine::child_faces(parent, scheme);
        return Topology::new(&faces, crate::refine::child_num_vertices(parent, scheme));
    }
    Topology::from_closed_form(&ChildCorners::new(parent, scheme))
}

impl ChildRing {
    /// The ring of vertex `w` of a built adjacency, as [`ChildCorners::ring`] gives it for a
    /// closed-form child.
    pub(crate) fn from_topology(topo: &Topology, w: u32, ring: &mut ChildRing) {
        ring.corners.clear();
        ring.corners.extend_from_slice(topo.vertex_corners(w));
        ring.verts.clear();
        ring.verts.extend_from_slice(topo.vertex_ring(w));
        ring.boundary.clear();
        ring.boundary.extend(
            topo.vertex_edges(w)
                .iter()
                .map(|&e| topo.is_boundary_edge(e)),
        );
        ring.diagonals.clear();
        ring.diagonals.extend(
            topo.vertex_corners(w)
                .iter()
                .map(|&c| topo.corner_vertex(topo.corner_next(topo.corner_next(c)))),
        );
    }
}
