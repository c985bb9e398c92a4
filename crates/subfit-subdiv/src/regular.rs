//! Regular Catmull-Clark neighbourhoods: the limit rows of a once-refined mesh in regular
//! regions are fixed tables over the parent vertices, computed once and reused.
//!
//! In a parent mesh refined by Catmull-Clark or the quad/triangle scheme, a child vertex whose
//! parent neighbourhood is regular — the vertex point of a smooth interior valence-4 vertex
//! all of whose faces are quads, the edge point of an interior edge between two such
//! vertices, the face point of a quad with four such corners — sees Catmull-Clark's rules
//! only (the quad/triangle scheme reduces to them where no triangle is near) and has the
//! same row of `L · M` (limit stencil of the child times one refinement step; see
//! [`crate::limit`]) up to where its parent neighbourhood sits: a bicubic B-spline patch
//! neighbourhood (Catmull & Clark 1978; the tables are OpenSubdiv's `Far::PatchTable` idea of
//! fixed weights on regular patches, here at the level of stencil rows). The neighbourhood is
//! listed as *positions* — the 1-rings (vertex, ring vertices, quad diagonals, in ring order)
//! of the one, two or four parent vertices involved — and a row is a table of weights over
//! positions, keyed by the child vertex's kind and by where its ring and its parents' rings
//! start (the ring starts fix the tangent directions). The first row of each key is computed
//! by the general path and turned into the table; later rows of that key are read from it.
//!
//! A table is only built from a row whose positions name the expected number of distinct
//! parent vertices (9, 12, 16: no unexpected identification, as in very small meshes), and
//! only applied to a row whose positions repeat where the table's did; repeats beyond those
//! are summed, as the general path sums them. So the rows are the general path's, up to the
//! order of floating-point additions (checked to 1e-14 in the tests of [`crate::limit`]).

use rayon::prelude::*;

use crate::face_points::FacePoints;
use crate::scheme::{Neighborhood, VertexRule};
use crate::stencil::SparseSum;
use crate::topology::Topology;

const NONE: u32 = u32::MAX;

/// The neighbourhood of a smooth interior vertex of valence 4 (with no sharp edge).
const REGULAR: Neighborhood = Neighborhood {
    faces: crate::scheme::FaceKinds::Polygons,
    num_edges: 4,
    num_faces: 4,
    rule: VertexRule::Smooth,
    crease_ends: [0, 0],
};

/// Number of table keys: 1 vertex-point key, 64 edge-point keys, 256 face-point keys.
const NUM_KEYS: usize = 1 + 64 + 256;

/// Whether `hood` is that of a smooth interior vertex of valence 4.
pub(crate) fn is_regular(hood: &Neighborhood) -> bool {
    *hood == REGULAR
}

/// Finds the regular neighbourhoods of the children of a parent mesh.
pub(crate) struct Regular<'a> {
    topo: &'a Topology,
    points: &'a FacePoints,
    /// Whether each parent vertex is regular: [`is_regular`] with quads only around it.
    regular: Vec<bool>,
    nv: u32,
    ne: u32,
}

/// A row of weights over positions: `(position, weights)` in the order the general path
/// produced them, and the positions that must repeat earlier ones (`(later, earlier)`).
struct Table {
    entries: Vec<(u8, [f64; 3])>,
    repeats: Vec<(u8, u8)>,
}

/// Per-worker tables, one slot per key, and the positions of the current row.
#[derive(Default)]
pub(crate) struct Tables {
    tables: Vec<Option<Table>>,
    positions: Vec<u32>,
    key: Option<usize>,
}

impl<'a> Regular<'a> {
    /// For the children of `topo` under Catmull-Clark or the quad/triangle scheme, with
    /// `hoods` its vertices' neighbourhoods and `points` its face points. Cost O(#V).
    pub(crate) fn new(
        topo: &'a Topology,
        hoods: &'a [Neighborhood],
        points: &'a FacePoints,
    ) -> Self {
        let regular = (0..topo.num_vertices() as u32)
            .into_par_iter()
            .map(|v| {
                is_regular(&hoods[v as usize])
                    && topo
                        .vertex_corners(v)
                        .iter()
                        .all(|&c| topo.face(topo.corner_face(c) as usize).len() == 4)
            })
            .collect();
        Self {
            topo,
            points,
            regular,
            nv: topo.num_vertices() as u32,
            ne: topo.num_edges() as u32,
        }
    }

    fn regular(&self, v: u32) -> bool {
        self.regular[v as usize]
    }

    /// The 1-ring of parent vertex `v` as positions: `v`, its ring vertices, its quads'
    /// diagonal vertices. `v` must be regular (4 edges, 4 faces).
    #[inline]
    fn push_block(&self, v: u32, out: &mut Vec<u32>) {
        let t = self.topo;
        out.push(v);
        out.extend_from_slice(t.vertex_ring(v));
        out.extend(
            t.vertex_corners(v)
                .iter()
                .map(|&c| t.corner_vertex(t.corner_next(t.corner_next(c)))),
        );
    }

    /// Position of corner `c` among the corners of its vertex.
    fn corner_index(&self, c: u32) -> usize {
        let corners = self.topo.vertex_corners(self.topo.corner_vertex(c));
        corners
            .iter()
            .position(|&x| x == c)
            .expect("a corner is among its vertex's corners")
    }

    /// Whether child vertex `w` has a regular parent neighbourhood; if so, its positions
    /// (into `tables.positions`) and its key. Child tags are not looked at: the caller checks
    /// the child vertex's own neighbourhood when there are tags.
    pub(crate) fn find(&self, w: u32, tables: &mut Tables) -> bool {
        let t = self.topo;
        let pos = &mut tables.positions;
        pos.clear();
        tables.key = None;
        let (nv, ne) = (self.nv, self.ne);
        let key = if w < nv {
            if !self.regular(w) {
                return false;
            }
            self.push_block(w, pos);
            0
        } else if w < nv + ne {
            let [c0, c1] = t.edge_corners(w - nv);
            if c1 == NONE {
                return false;
            }
            let (n0, n1) = (t.corner_next(c0), t.corner_next(c1));
            let (a, b) = (t.corner_vertex(c0), t.corner_vertex(n0));
            if !self.regular(a) || !self.regular(b) {
                return false;
            }
            // The child ring's start: its lowest corner (module `child`; the quad/triangle
            // child numbers the corners of the same four child quads in the same order).
            let cycle = [4 * n0 + 3, 4 * c0 + 1, 4 * n1 + 3, 4 * c1 + 1];
            let r = (0..4).min_by_key(|&i| cycle[i]).expect("four corners");
            self.push_block(a, pos);
            self.push_block(b, pos);
            1 + r * 16 + self.corner_index(c0) * 4 + self.corner_index(c1)
        } else {
            let f = self.points.face((w - nv - ne) as usize);
            if t.face(f).len() != 4 {
                return false;
            }
            let c0 = t.face_first_corner(f) as u32;
            let mut key = 0;
            for k in (0..4).rev() {
                let v = t.corner_vertex(c0 + k);
                if !self.regular(v) {
                    return false;
                }
                key = 4 * key + self.corner_index(c0 + k);
            }
            for k in 0..4 {
                self.push_block(t.corner_vertex(c0 + k), pos);
            }
            65 + key
        };
        tables.key = Some(key);
        true
    }
}

impl Tables {
    /// Adds the tabulated row of the vertex last passed to [`Regular::find`] to `sum`, if its
    /// table exists and its positions repeat as the table's did. Returns whether it did.
    pub(crate) fn apply(&self, sum: &mut SparseSum) -> bool {
        let Some(Some(table)) = self
            .key
            .map(|k| self.tables.get(k).and_then(Option::as_ref))
        else {
            return false;
        };
        let pos = &self.positions;
        if table
            .repeats
            .iter()
            .any(|&(p, q)| pos[p as usize] != pos[q as usize])
        {
            return false;
        }
        for &(p, w) in &table.entries {
            sum.add(pos[p as usize], w);
        }
        true
    }

    /// Records `entries` (the general path's row over parent vertices) as the table of the
    /// vertex last passed to [`Regular::find`], unless it has one or its positions are
    /// degenerate (fewer distinct parent vertices than a regular neighbourhood has).
    pub(crate) fn record(&mut self, entries: &[(u32, [f64; 3])]) {
        let Some(key) = self.key else {
            return;
        };
        if self.tables.len() < NUM_KEYS {
            self.tables.resize_with(NUM_KEYS, || None);
        }
        if self.tables[key].is_some() {
            return;
        }
        let pos = &self.positions;
        let expected = match pos.len() {
            9 => 9,
            18 => 12,
            _ => 16,
        };
        let first = |p: usize| pos.iter().position(|&x| x == pos[p]).expect("present");
        let repeats: Vec<(u8, u8)> = (0..pos.len())
            .filter_map(|p| {
                let q = first(p);
                (q != p).then_some((p as u8, q as u8))
            })
            .collect();
        if pos.len() - repeats.len() != expected {
            return;
        }
        let mut table = Table {
            entries: Vec::with_capacity(entries.len()),
            repeats,
        };
        for &(c, w) in entries {
            let Some(p) = pos.iter().position(|&x| x == c) else {
                return;
            };
            table.entries.push((p as u8, w));
        }
        self.tables[key] = Some(table);
    }
}
