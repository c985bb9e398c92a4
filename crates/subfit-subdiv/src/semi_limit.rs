//! Limit rows of vertices with finite sharpness around them, by local refinement.
//!
//! The closed-form limit masks ([`crate::mask`]) assume the vertex's neighbourhood is subdivided
//! with the same rules at every level, which fails while a semi-sharp crease or corner
//! ([`crate::crease`]; DeRose, Kass & Truong 1998, §3) is decaying. The limit point of a vertex
//! is the limit point of its vertex point after one refinement step, and the vertex point and
//! its one-ring depend only on the vertex's one-ring faces and on the sharpness of the vertex and
//! its incident edges. So the one-ring faces are extracted, refined once, and the child's row
//! computed the same way (recursively, on the child's one-ring) until no finite sharpness is
//! left around it; then the closed-form masks apply and the rows are composed back up. Tangents
//! are scaled by 2 per step, as [`crate::limit`] does for `n`-gons (only their directions are
//! meaningful). Cost per vertex O(⌈s⌉ · valence) for the largest finite sharpness `s` around
//! it, independent of the mesh size.

use crate::limit_row::push_topology_limit_row_for;
use crate::refine::{refine_topology, topology_for};
use crate::scheme::Options;
use crate::topology::Topology;
use subfit_mesh::{Polygons, Tags};

/// Whether vertex `v` of `topo` has a finite sharpness at it or on an incident edge in `tags`.
/// Cost O(valence) hash lookups.
pub(crate) fn semi_sharp_at(topo: &Topology, tags: &Tags, v: u32) -> bool {
    if tags.is_empty() {
        return false;
    }
    let semi = |s: f64| crate::crease::is_semi_sharp(crate::crease::sharpness(s));
    semi(tags.corner(v))
        || topo
            .vertex_ring(v)
            .iter()
            .zip(topo.vertex_edges(v))
            .any(|(&u, &e)| !topo.is_boundary_edge(e) && semi(tags.crease(v, u)))
}

/// The faces around vertex `v` of `topo` (its one-ring), with the vertex ids of `topo`.
pub(crate) fn ring_faces(topo: &Topology, v: u32) -> Polygons {
    let mut out = Polygons::new();
    for &c in topo.vertex_corners(v) {
        out.push(topo.face(topo.corner_face(c) as usize));
    }
    out
}

/// The limit row (position, tangent 1, tangent 2 weights per entry, columns ascending) of
/// vertex `v`, given the faces around it (`ring`, all of them, consistently oriented, with any
/// vertex ids) and the `tags` of the whole mesh (only those on `ring`'s edges and vertices are
/// read). Columns are the vertex ids used by `ring`.
///
/// # Panics
/// If `ring` is not a valid fan of faces around `v` for `options.scheme` (a broken invariant of
/// the caller).
#[track_caller]
pub(crate) fn semi_sharp_limit_row(
    ring: &Polygons,
    v: u32,
    tags: &Tags,
    options: &Options,
) -> Vec<(u32, [f64; 3])> {
    let mut verts: Vec<u32> = ring.indices().to_vec();
    verts.sort_unstable();
    verts.dedup();
    let local = |g: u32| verts.binary_search(&g).expect("a vertex of the ring") as u32;
    let mut faces = Polygons::new();
    let mut sub_tags = Tags::new();
    let mut buf = Vec::new();
    for f in ring.iter() {
        buf.clear();
        buf.extend(f.iter().map(|&g| local(g)));
        faces.push(&buf);
        for (i, &a) in f.iter().enumerate() {
            let b = f[(i + 1) % f.len()];
            let s = tags.crease(a, b);
            if s > 0.0 {
                sub_tags.set_crease(local(a), local(b), s);
            }
        }
    }
    for (i, &g) in verts.iter().enumerate() {
        let s = tags.corner(g);
        if s > 0.0 {
            sub_tags.set_corner(i as u32, s);
        }
    }
    let topo = topology_for(&faces, verts.len(), options.scheme)
        .expect("the one-ring of a vertex of a valid mesh is valid");
    let mut dense = vec![[0.0f64; 3]; verts.len()];
    let r = refine_topology(&topo, &sub_tags, options);
    let child = Topology::new(&r.faces, r.num_vertices).expect("the refinement of a valid mesh");
    let vl = local(v);
    // The vertex point keeps the vertex's id (module `refine`).
    let row = if semi_sharp_at(&child, &r.tags, vl) {
        semi_sharp_limit_row(&ring_faces(&child, vl), vl, &r.tags, options)
    } else {
        let mut row = Vec::new();
        push_topology_limit_row_for(&child, &r.tags, options, vl, &mut row);
        row
    };
    for (c, w) in row {
        let (cols, ws) = r.matrix.row(c as usize);
        for (&k, &m) in cols.iter().zip(ws) {
            let d = &mut dense[k as usize];
            d[0] += w[0] * m;
            d[1] += 2.0 * w[1] * m;
            d[2] += 2.0 * w[2] * m;
        }
    }
    verts
        .iter()
        .zip(dense)
        .filter(|(_, w)| w.iter().any(|&x| x != 0.0))
        .map(|(&g, w)| (g, w))
        .collect()
}
