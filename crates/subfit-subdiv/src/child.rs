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
//! * Quad/triangle (Stam & Loop 2003): each triangle as Loop's, each other face as
//!   Catmull-Clark's. A triangle has 12 child corners and an `n`-gon `4n`, so in all three
//!   schemes the child corners of the parent face whose first corner is `c0` start at `4 c0`
//!   (Loop's `12f`, Catmull-Clark's `4c`): a child corner's parent face is that of parent
//!   corner `x / 4`, and only the pattern inside it depends on the face's size. Face points
//!   are numbered over the non-triangles ([`mod@crate::refine`]).
//!
//! Rings are then walked exactly as [`Topology::new`] walks them (counter-clockwise from the
//! leading boundary edge, or from the vertex's lowest-numbered corner), so a child ring here
//! equals the ring of the child [`Topology`], entry for entry (checked by the tests of
//! `refine`, which also check the child faces). The last level of the sampling operator uses
//! this instead of building a [`Topology`] with one entry per corner of the finest mesh, which
//! it would read only once; the levels above build theirs from it
//! ([`Topology::from_closed_form`]) instead of from a child face list.
//!
//! Cost: each query O(1) parent look-ups; a ring O(valence). Nothing is allocated but the
//! caller's [`ChildRing`] buffers.

use crate::error::SubdivError;
use crate::face_points::FacePoints;
use crate::scheme::{FaceKinds, Scheme};
use crate::topology::{ClosedForm, Topology};

const NONE: u32 = u32::MAX;

/// How the faces of a uniform parent split: Loop's 1→4 triangles, Catmull-Clark's quads, or
/// the quad/triangle scheme's mix of both (decided face by face).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Split {
    Triangles,
    Quads,
    Mixed,
}

/// Where a child corner lies in its parent face's pattern.
#[derive(Clone, Copy)]
enum Loc {
    /// Corner `i` of child triangle `j` (3: the middle one) of the parent triangle whose first
    /// corner is `c0`: child corner `4 c0 + 3 j + i`.
    Tri { c0: u32, j: u32, i: u32 },
    /// Corner `k` of the child quad of parent corner `c`: child corner `4 c + k`.
    Quad { c: u32, k: u32 },
}

/// Corner algebra of the child of `topo` under one step of `scheme`.
///
/// The parent must suit the scheme (Loop: triangles only). Child corners are numbered as
/// positions in the child face list's indices; child vertices as in [`crate::refine`]. A
/// parent triangle has 12 child corners and an `n`-gon `4n`, so the children of the face whose
/// first corner is `c0` start at child corner `4 c0` under all three schemes.
#[derive(Clone)]
pub(crate) struct ChildCorners<'a> {
    topo: &'a Topology,
    scheme: Split,
    points: FacePoints,
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
    /// Catmull-Clark and quad/triangle: the vertex two corners away in each ring face (a
    /// quad's diagonal, a triangle's next ring vertex); empty for Loop.
    pub(crate) diagonals: Vec<u32>,
}

impl<'a> ChildCorners<'a> {
    /// The child of `topo` (which must suit `scheme`). Cost O(#F) for the quad/triangle
    /// scheme's face points, O(1) otherwise.
    pub(crate) fn new(topo: &'a Topology, scheme: Scheme) -> Self {
        let split = match scheme {
            Scheme::Loop => Split::Triangles,
            Scheme::CatmullClark => Split::Quads,
            Scheme::QuadTriangle => Split::Mixed,
        };
        debug_assert!(
            split != Split::Triangles || (0..topo.num_faces()).all(|f| topo.face(f).len() == 3)
        );
        Self {
            topo,
            scheme: split,
            points: FacePoints::new(topo, scheme),
            nv: topo.num_vertices() as u32,
            ne: topo.num_edges() as u32,
        }
    }

    /// The kinds of the child faces of a ring of this child (`ring.corners`).
    pub(crate) fn face_kinds(&self, ring: &ChildRing) -> FaceKinds {
        match self.scheme {
            Split::Triangles => FaceKinds::Triangles,
            Split::Quads => FaceKinds::Polygons,
            Split::Mixed => FaceKinds::from_triangles(
                ring.corners
                    .iter()
                    .map(|&x| matches!(self.locate(x), Loc::Tri { .. })),
            ),
        }
    }

    /// Number of child vertices.
    pub(crate) fn num_vertices(&self) -> usize {
        self.topo.num_vertices() + self.topo.num_edges() + self.points.len()
    }

    /// Number of child corners: four per parent corner (module docs).
    pub(crate) fn num_corners(&self) -> usize {
        4 * self.topo.face_first_corner(self.topo.num_faces())
    }

    /// Offsets of the child faces in the child corners (`#child faces + 1` entries): per parent
    /// face, four triangles for a triangle under Loop's pattern, else one quad per corner.
    /// Cost O(#child faces), serial.
    ///
    /// # Panics
    /// If the child has `u32::MAX` or more corners.
    #[track_caller]
    pub(crate) fn face_offsets(&self) -> Vec<u32> {
        let t = self.topo;
        let nc = u32::try_from(self.num_corners()).expect("more than u32::MAX child corners");
        match self.scheme {
            Split::Quads => (0..=nc / 4).map(|f| 4 * f).collect(),
            Split::Triangles => (0..=nc / 3).map(|f| 3 * f).collect(),
            Split::Mixed => {
                let mut out = Vec::with_capacity(nc as usize / 4 + 1);
                for f in 0..t.num_faces() {
                    let (c0, n) = (4 * t.face_first_corner(f) as u32, t.face(f).len() as u32);
                    let step = if n == 3 { 3 } else { 4 };
                    out.extend((c0..c0 + 4 * n).step_by(step));
                }
                out.push(nc);
                out
            }
        }
    }

    /// The first corner of parent corner `c`'s face if that face splits as a triangle.
    #[inline]
    fn triangle_of(&self, c: u32) -> Option<u32> {
        match self.scheme {
            Split::Triangles => Some(c - c % 3),
            Split::Quads => None,
            Split::Mixed => {
                let f = self.topo.corner_face(c) as usize;
                (self.topo.face(f).len() == 3).then(|| self.topo.face_first_corner(f) as u32)
            }
        }
    }

    /// Where child corner `x` lies.
    #[inline]
    fn locate(&self, x: u32) -> Loc {
        if self.scheme == Split::Triangles {
            // The general path below, with the parent triangle's first corner `3 (x / 12)`
            // known without looking up its face (Loop's every corner query goes through here).
            let l = x % 12;
            return Loc::Tri {
                c0: 3 * (x / 12),
                j: l / 3,
                i: l % 3,
            };
        }
        let c = x / 4;
        match self.triangle_of(c) {
            Some(c0) => {
                let l = x - 4 * c0;
                Loc::Tri {
                    c0,
                    j: l / 3,
                    i: l % 3,
                }
            }
            None => Loc::Quad { c, k: x % 4 },
        }
    }

    /// The child vertex of parent face `f`'s face point.
    #[inline]
    fn face_point(&self, f: u32) -> u32 {
        self.nv + self.ne + self.points.index(f as usize)
    }

    /// The child corner at parent corner `c`'s vertex on the child edge along `c`'s edge (from
    /// the vertex point to the edge point).
    #[inline]
    fn leading(&self, c: u32) -> u32 {
        match self.triangle_of(c) {
            Some(c0) => 4 * c0 + 3 * (c - c0),
            None => 4 * c,
        }
    }

    /// The child corner at the edge point of parent corner `c`'s edge on the child edge toward
    /// the next vertex of `c`'s face.
    #[inline]
    fn trailing(&self, c: u32) -> u32 {
        match self.triangle_of(c) {
            Some(c0) => 4 * c0 + 3 * ((c - c0 + 1) % 3) + 2,
            None => 4 * self.topo.corner_next(c) + 3,
        }
    }

    /// The child vertex of child corner `x`.
    #[inline]
    pub(crate) fn vertex(&self, x: u32) -> u32 {
        let t = self.topo;
        match self.locate(x) {
            Loc::Quad { c, k } => match k {
                0 => t.corner_vertex(c),
                1 => self.nv + t.corner_edge(c),
                2 => self.face_point(t.corner_face(c)),
                _ => self.nv + t.corner_edge(t.corner_prev(c)),
            },
            Loc::Tri { c0, j, i } => match (j, i) {
                (3, i) => self.nv + t.corner_edge(c0 + i),
                (j, 0) => t.corner_vertex(c0 + j),
                (j, 1) => self.nv + t.corner_edge(c0 + j),
                (j, _) => self.nv + t.corner_edge(c0 + (j + 2) % 3),
            },
        }
    }

    /// The corner after child corner `x` in its (child) face.
    #[inline]
    pub(crate) fn next(&self, x: u32) -> u32 {
        if self.scheme == Split::Triangles {
            // Loop's child triangles start at multiples of 3: no need to locate the parent.
            return x - x % 3 + (x + 1) % 3;
        }
        match self.locate(x) {
            Loc::Quad { c, k } => 4 * c + (k + 1) % 4,
            Loc::Tri { c0, j, i } => 4 * c0 + 3 * j + (i + 1) % 3,
        }
    }

    /// The corner before child corner `x` in its face.
    #[cfg(test)]
    #[inline]
    pub(crate) fn prev(&self, x: u32) -> u32 {
        match self.locate(x) {
            Loc::Quad { c, k } => 4 * c + (k + 3) % 4,
            Loc::Tri { c0, j, i } => 4 * c0 + 3 * j + (i + 2) % 3,
        }
    }

    /// The twin of child corner `x` (the corner of the opposite directed edge), `u32::MAX` on a
    /// boundary.
    #[inline]
    pub(crate) fn twin(&self, x: u32) -> u32 {
        let t = self.topo;
        // A child edge along a parent edge pairs with the other half-edge of the same half of
        // the parent edge, in the face across (which may split the other way).
        let across = |c: u32, f: fn(&Self, u32) -> u32| match t.corner_twin(c) {
            NONE => NONE,
            o => f(self, o),
        };
        match self.locate(x) {
            Loc::Quad { c, k } => match k {
                0 => across(c, Self::trailing),
                1 => 4 * t.corner_next(c) + 2,
                2 => 4 * t.corner_prev(c) + 1,
                _ => across(t.corner_prev(c), Self::leading),
            },
            Loc::Tri { c0, j, i } => match (j, i) {
                (3, i) => 4 * c0 + 3 * ((i + 1) % 3) + 1,
                (j, 0) => across(c0 + j, Self::trailing),
                (j, 1) => 4 * c0 + 9 + (j + 2) % 3,
                (j, _) => across(c0 + (j + 2) % 3, Self::leading),
            },
        }
    }

    /// Appends the child corners of child vertex `w` (any order) to `out`.
    #[cfg(test)]
    fn outgoing(&self, w: u32, out: &mut Vec<u32>) {
        let t = self.topo;
        let (nv, ne) = (self.nv, self.ne);
        if w < nv {
            out.extend(t.vertex_corners(w).iter().map(|&c| self.leading(c)));
        } else if w < nv + ne {
            for c in t.edge_corners(w - nv) {
                if c == NONE {
                    continue;
                }
                let mut side = [(0, 0, 0); 3];
                let n = self.edge_side(c, &mut side);
                out.extend(side[..n].iter().map(|s| s.0));
            }
        } else {
            let f = self.points.face((w - nv - ne) as usize);
            let c0 = t.face_first_corner(f) as u32;
            out.extend((c0..c0 + t.face(f).len() as u32).map(|c| 4 * c + 2));
        }
    }

    /// The child edges leaving the edge point of parent corner `c`'s edge into `c`'s face, in
    /// counter-clockwise order about the edge point, as `(child corner, far end, diagonal)`
    /// written to the front of `out`; returns how many (2 or 3). Under Catmull-Clark's pattern
    /// they go toward the vertex point of `next(c)`'s vertex and toward the face point; under
    /// Loop's (corner `c0 + k`), toward the vertex point of `v_{k+1}` and the edge points of
    /// `e_{k+1}` and `e_{k+2}`.
    #[inline]
    fn edge_side(&self, c: u32, out: &mut [(u32, u32, u32)]) -> usize {
        let t = self.topo;
        let nv = self.nv;
        match self.triangle_of(c) {
            Some(c0) => {
                let k = c - c0;
                let (k1, k2) = (c0 + (k + 1) % 3, c0 + (k + 2) % 3);
                let (e1, e2) = (nv + t.corner_edge(k1), nv + t.corner_edge(k2));
                out[..3].copy_from_slice(&[
                    (4 * c0 + 3 * (k1 - c0) + 2, t.corner_vertex(k1), e1),
                    (4 * c0 + 9 + k, e1, e2),
                    (4 * c0 + 3 * k + 1, e2, t.corner_vertex(c)),
                ]);
                3
            }
            None => {
                let n = t.corner_next(c);
                out[..2].copy_from_slice(&[
                    (4 * n + 3, t.corner_vertex(n), nv + t.corner_edge(n)),
                    (
                        4 * c + 1,
                        self.face_point(t.corner_face(c)),
                        nv + t.corner_edge(t.corner_prev(c)),
                    ),
                ]);
                2
            }
        }
    }

    /// The ring of child vertex `w` into `ring` (cleared first), as [`Topology::new`] would
    /// build it for the child mesh, in closed form from the parent's ring, edge or face (the
    /// walk of [`Self::ring_by_walk`], worked out per kind of child vertex). Cost O(valence).
    pub(crate) fn ring(&self, w: u32, ring: &mut ChildRing) {
        ring.clear();
        let t = self.topo;
        let (nv, ne) = (self.nv, self.ne);
        if w < nv {
            // Vertex point: the parent ring, edge for edge (child corners increase with parent
            // corners, so the lowest child corner and the boundary corner are those of the
            // parent's lowest and boundary corners).
            for &c in t.vertex_corners(w) {
                ring.corners.push(self.leading(c));
                if self.scheme != Split::Triangles {
                    ring.diagonals.push(match self.triangle_of(c) {
                        Some(_) => nv + t.corner_edge(t.corner_prev(c)),
                        None => self.face_point(t.corner_face(c)),
                    });
                }
            }
            for &e in t.vertex_edges(w) {
                ring.verts.push(nv + e);
                ring.boundary.push(t.is_boundary_edge(e));
            }
        } else if w < nv + ne {
            let [c0, c1] = t.edge_corners(w - nv);
            let mut sides = [(0, 0, 0); 6];
            let n0 = self.edge_side(c0, &mut sides);
            if c1 == NONE {
                ring.push_rotated(&sides[..n0], false);
                ring.verts.push(t.corner_vertex(c0));
                ring.boundary[0] = true;
                ring.boundary.push(true);
            } else {
                let n1 = self.edge_side(c1, &mut sides[n0..]);
                ring.push_rotated(&sides[..n0 + n1], true);
            }
        } else {
            // Face point (not a triangle): one child edge per parent edge, starting at the
            // face's first corner.
            let f = self.points.face((w - nv - ne) as usize);
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
        if self.scheme == Split::Triangles {
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
            if self.scheme != Split::Triangles {
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

    fn num_corners(&self) -> usize {
        ChildCorners::num_corners(self)
    }

    fn face_offsets(&self) -> Vec<u32> {
        ChildCorners::face_offsets(self)
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
/// Cost O(#child corners), parallel except for the edge numbering and the face offsets.
pub(crate) fn refined_topology(parent: &Topology, scheme: Scheme) -> Result<Topology, SubdivError> {
    Topology::from_closed_form(&ChildCorners::new(parent, scheme))
}
