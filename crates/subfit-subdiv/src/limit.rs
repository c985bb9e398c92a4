//! Limit stencils: the limit position and two limit tangents of every vertex, as sparse rows over
//! the vertices of the same level.
//!
//! Position masks: Halstead, Kass & DeRose 1993 (*Efficient, fair interpolation using
//! Catmull-Clark surfaces*, §A) for Catmull-Clark; Loop 1987 for Loop; the cubic B-spline limit
//! (1/6, 2/3, 1/6) on creases and boundaries (Hoppe et al. 1994); corners are fixed. Tangent masks
//! follow OpenSubdiv 3.5 (`sdc/*Scheme.h`, `Far::PrimvarRefiner::Limit`), see [`crate::mask`].
//!
//! Semi-sharp features (finite sharpness, [`crate::crease`]): the closed-form masks hold only
//! once no finite sharpness is left at a vertex or its incident edges. The rows of such a vertex
//! are those of its vertex point after one refinement step (the same limit point), composed with
//! that step, recursively — `⌈s⌉` steps for the largest sharpness `s` around it — on its
//! one-ring faces only (module `semi_limit`). Tangents are scaled by 2 per step as below.
//! OpenSubdiv's `PrimvarRefiner::Limit` applies the crease or corner masks there instead, which
//! is not the limit.
//!
//! Exactness: limit positions are exact everywhere except at darts (an interior vertex with one
//! sharp edge), where the smooth mask is used as in OpenSubdiv; tangent directions are exact at
//! smooth vertices and regular boundaries, and at irregular creases and corners they are
//! OpenSubdiv's formulas (reproduced to round-off, see `tests/golden.rs`), which are
//! approximations there.
//!
//! Catmull-Clark limit masks need quads around the vertex. When the mesh has other faces, the
//! limit of a vertex is taken as the limit of its vertex point after one refinement step (the
//! same point, exactly), with tangents scaled by 2 to undo the halving of the ring. (OpenSubdiv's
//! `Limit` applied at level 0 instead weights "the vertex two corners away" in an `n`-gon, which
//! is not the limit; it documents that it needs one refinement to remove `n`-gons.)
//!
//! For the sampling operator the limit rows of a refined mesh are composed with the refinement
//! step that made it (`L · M`, `limit_refine_compose`) without building either factor: the
//! child's rings are read off the parent (module `child`), each limit row is expanded locally
//! by the refinement rows of its entries, and in regular Catmull-Clark regions the expanded row
//! is a fixed table over the parent's 1-rings (module `regular`).

use crate::child::{ChildCorners, ChildRing};
use crate::error::SubdivError;
use crate::limit_row::{push_limit_row, push_topology_limit_row, LimitMasks};
use crate::refine::{
    has_semi_sharp, neighborhoods, refine_topology, sharp_edges, topology_for, RefineRows,
    VertexMaskCache,
};
use crate::regular::{is_regular, Regular, Tables};
use crate::scheme::{classify, Options, Scheme};
use crate::semi_limit::{ring_faces, semi_sharp_at, semi_sharp_limit_row};
use crate::stencil::{compose_rows, MultiRows, SparseSum, Stacked, StencilMatrix};
use crate::topology::Topology;
use std::sync::atomic::{AtomicUsize, Ordering};
use subfit_mesh::{Polygons, Tags};

/// Limit stencils of every vertex of a mesh: three `#V × #V` matrices over the same vertices.
#[derive(Clone, Debug)]
pub struct LimitStencils {
    /// Limit positions: rows sum to 1.
    pub position: StencilMatrix,
    /// First limit tangent (OpenSubdiv's `tan1`): rows sum to 0. Only its direction is meaningful.
    pub tangent1: StencilMatrix,
    /// Second limit tangent (`tan2`): rows sum to 0; `normalize(t1 × t2)` is the limit normal,
    /// on the side the face winding makes the front.
    pub tangent2: StencilMatrix,
}

/// Limit stencils of the vertices of `faces` (over `num_vertices` vertices).
///
/// Errors: bad topology, or non-triangles for Loop (see [`SubdivError`]). Cost O(#corners ·
/// max valence), plus one refinement for Catmull-Clark meshes with non-quads.
pub fn limit_stencils(
    faces: &Polygons,
    num_vertices: usize,
    tags: &Tags,
    options: &Options,
) -> Result<LimitStencils, SubdivError> {
    let topo = topology_for(faces, num_vertices, options.scheme)?;
    Ok(limit_topology(&topo, tags, options))
}

/// Limit stencils on an already built adjacency.
pub(crate) fn limit_topology(topo: &Topology, tags: &Tags, options: &Options) -> LimitStencils {
    let [position, tangent1, tangent2] = limit_rows(topo, tags, options).split();
    LimitStencils {
        position,
        tangent1,
        tangent2,
    }
}

fn needs_refinement(topo: &Topology, options: &Options) -> bool {
    match options.scheme {
        Scheme::Loop => false,
        Scheme::CatmullClark => (0..topo.num_faces()).any(|f| topo.face(f).len() != 4),
        Scheme::QuadTriangle => (0..topo.num_faces()).any(|f| topo.face(f).len() > 4),
    }
}

/// Whether child vertex `w` (ring `ring`) has a finite sharpness at it or on a ring edge in
/// `tags`. Cost O(valence) hash lookups.
fn child_semi_sharp_at(w: u32, ring: &ChildRing, tags: &Tags) -> bool {
    let semi = |s: f64| crate::crease::is_semi_sharp(crate::crease::sharpness(s));
    semi(tags.corner(w))
        || ring
            .verts
            .iter()
            .zip(&ring.boundary)
            .any(|(&u, &b)| !b && semi(tags.crease(w, u)))
}

/// The faces of the child mesh around a child vertex whose ring is `ring` (child ids).
fn child_ring_faces(child: &ChildCorners<'_>, ring: &ChildRing) -> Polygons {
    let mut out = Polygons::new();
    let mut face = Vec::new();
    for &c in &ring.corners {
        face.clear();
        let mut x = c;
        loop {
            face.push(child.vertex(x));
            x = child.next(x);
            if x == c {
                break;
            }
        }
        out.push(&face);
    }
    out
}

/// Limit position and tangent weights sharing one support per vertex (`#V` rows over the same
/// `#V` vertices).
pub(crate) fn limit_rows(topo: &Topology, tags: &Tags, options: &Options) -> MultiRows<3> {
    if needs_refinement(topo, options) {
        return limit_rows_via_refinement(topo, tags, options);
    }
    let sharp = sharp_edges(topo, tags);
    let hoods = neighborhoods(topo, &sharp, tags, options.boundary);
    let nv = topo.num_vertices();
    // Vertices with finite sharpness at them or on an incident edge have no closed-form limit
    // mask yet: their rows come from local refinement until it has decayed (module docs).
    let semi = has_semi_sharp(tags);
    let affected = |v: u32| semi && semi_sharp_at(topo, tags, v);
    let mut rows = MultiRows {
        ncols: nv,
        offsets: Vec::with_capacity(nv + 1),
        cols: Vec::new(),
        weights: Vec::new(),
    };
    rows.offsets.push(0);
    let mut masks = LimitMasks::default();
    let mut row = Vec::new();
    for (v, hood) in hoods.iter().enumerate() {
        row.clear();
        if affected(v as u32) {
            row = semi_sharp_limit_row(&ring_faces(topo, v as u32), v as u32, tags, options);
        } else {
            push_topology_limit_row(topo, options.scheme, hood, &mut masks, v as u32, &mut row);
        }
        for &(c, w) in &row {
            rows.cols.push(c);
            rows.weights.push(w);
        }
        rows.offsets.push(rows.cols.len());
    }
    rows
}

/// The three products `L' · M · rhs`: `M` one step of refinement of `parent` (with crease and
/// corner tags `parent_tags`), `L'` the limit stencils (position, tangent 1, tangent 2) of the
/// child mesh (tags `child_tags`), `rhs` with one row per parent vertex. Neither `L'`, `M` nor
/// `M · rhs` is stored: each child vertex's limit row is built from its ring, read off the
/// parent's adjacency ([`crate::child`]); each of its entries is expanded by the refinement row
/// of that child vertex into parent vertices (repeats summed in a small per-worker table); and
/// the resulting row over the parent vertices (9–16 entries in regular regions) is multiplied
/// by `rhs`. In regular Catmull-Clark regions (quads around, under Catmull-Clark or the
/// quad/triangle scheme) the row over the parent vertices is read from a table instead, built from the first such row ([`crate::regular`]).
/// Rows in the child vertex order of [`crate::refine`].
///
/// Cost O(Σ_child rows (|L' row| · |M row| + |L'M row| · |rhs row|)); per worker scratch one
/// `u32` per parent vertex and one dense row of `rhs.ncols`.
///
/// # Panics
/// If `rhs.nrows()` is not the parent's vertex count.
#[track_caller]
pub(crate) fn limit_refine_compose(
    parent: &Topology,
    parent_tags: &Tags,
    child_tags: &Tags,
    options: &Options,
    rhs: &StencilMatrix,
) -> [StencilMatrix; 3] {
    limit_refine_compose_with(parent, parent_tags, child_tags, options, rhs, true, None)
}

/// [`limit_refine_compose`], with the regular tables of [`crate::regular`] (Catmull-Clark and
/// quad/triangle) used when `tables`; rows read from a table are counted in `tabulated`.
fn limit_refine_compose_with(
    parent: &Topology,
    parent_tags: &Tags,
    child_tags: &Tags,
    options: &Options,
    rhs: &StencilMatrix,
    tables: bool,
    tabulated: Option<&AtomicUsize>,
) -> [StencilMatrix; 3] {
    assert_eq!(
        rhs.nrows(),
        parent.num_vertices(),
        "inner dimensions differ"
    );
    let child = ChildCorners::new(parent, options.scheme);
    let refine = RefineRows::new(parent, parent_tags, options);
    let regular = match options.scheme {
        // The tables assume the rules of the parent's infinitely sharp tags only.
        Scheme::CatmullClark | Scheme::QuadTriangle if tables && !refine.semi_sharp() => {
            Some(Regular::new(parent, refine.hoods(), refine.face_points()))
        }
        _ => None,
    };
    let tagged = !child_tags.is_empty();
    let child_semi = has_semi_sharp(child_tags);
    let nv = parent.num_vertices();
    compose_rows(
        child.num_vertices(),
        Stacked::one(rhs),
        || LimitRefineScratch::new(nv + parent.num_faces()),
        |st, w, row| {
            let w = w as u32;
            let LimitRefineScratch {
                masks,
                ring,
                child_row,
                vertex_masks,
                sum,
                tables,
            } = st;
            let mut hood = None;
            if child_semi {
                child.ring(w, ring);
                if child_semi_sharp_at(w, ring, child_tags) {
                    // Finite sharpness left around the child vertex: its limit row over the
                    // child vertices comes from local refinement of its one-ring.
                    let faces = child_ring_faces(&child, ring);
                    *child_row = semi_sharp_limit_row(&faces, w, child_tags, options);
                    accumulate_child_row(parent, &refine, child_row, vertex_masks, sum);
                    sum.drain_into(row);
                    return;
                }
            }
            let child_hood = |ring: &mut ChildRing| {
                child.ring(w, ring);
                let kinds = child.face_kinds(ring);
                // As `sharp_edges` and `neighborhoods` on the child: boundary edges and edges
                // tagged infinitely sharp.
                let sharp = ring
                    .verts
                    .iter()
                    .zip(&ring.boundary)
                    .map(|(&u, &b)| b || (tagged && child_tags.is_sharp_edge(w, u)));
                let corner_tag = tagged && child_tags.is_corner(w);
                classify(
                    sharp,
                    ring.corners.len(),
                    kinds,
                    corner_tag,
                    options.boundary,
                )
            };
            // A regular parent neighbourhood: without tags the child vertex is regular too;
            // with tags, check.
            let fast = regular.as_ref().is_some_and(|r| r.find(w, tables))
                && (!tagged || is_regular(hood.insert(child_hood(ring))));
            if fast && tables.apply(sum) {
                if let Some(n) = tabulated {
                    n.fetch_add(1, Ordering::Relaxed);
                }
                sum.drain_into(row);
                return;
            }
            let hood = match hood {
                Some(h) => h,
                None => child_hood(ring),
            };
            let diagonals = &ring.diagonals;
            let diagonal = |i: usize| diagonals[i];
            child_row.clear();
            push_limit_row(
                options.scheme,
                &hood,
                masks,
                w,
                &ring.verts,
                diagonal,
                child_row,
            );
            // Face centres are summed as columns `nv + f` and expanded once per face.
            accumulate_child_row(parent, &refine, child_row, vertex_masks, sum);
            if fast {
                tables.record(sum.entries());
            }
            sum.drain_into(row);
        },
    )
}

/// Expands a limit row over child vertices (`child_row`) by the refinement rows into `sum`, over
/// the parent vertices (face centres summed as columns `nv + f` and expanded once per face).
fn accumulate_child_row(
    parent: &Topology,
    refine: &RefineRows<'_>,
    child_row: &[(u32, [f64; 3])],
    vertex_masks: &mut VertexMaskCache,
    sum: &mut SparseSum,
) {
    let nv = parent.num_vertices();
    for &(j, l) in child_row {
        refine.row(vertex_masks, j as usize, Some(nv as u32), |k, m| {
            sum.add(k, [l[0] * m, l[1] * m, l[2] * m]);
        });
    }
    let points = refine.face_points();
    sum.expand_faces(nv as u32, |k| parent.face(points.face(k as usize)));
}

/// Per-worker state of [`limit_refine_compose`].
struct LimitRefineScratch {
    masks: LimitMasks,
    ring: ChildRing,
    child_row: Vec<(u32, [f64; 3])>,
    vertex_masks: VertexMaskCache,
    sum: SparseSum,
    tables: Tables,
}

impl LimitRefineScratch {
    /// Scratch for rows over `ncols` columns (parent vertices, then parent faces).
    fn new(ncols: usize) -> Self {
        Self {
            masks: LimitMasks::default(),
            ring: ChildRing::default(),
            child_row: Vec::with_capacity(32),
            vertex_masks: VertexMaskCache::default(),
            tables: Tables::default(),
            sum: SparseSum::new(ncols),
        }
    }
}

/// Catmull-Clark with non-quads: limit rows of the vertex points after one refinement, composed
/// with the refinement matrix; tangents scaled by 2.
fn limit_rows_via_refinement(topo: &Topology, tags: &Tags, options: &Options) -> MultiRows<3> {
    let nv = topo.num_vertices();
    let r = refine_topology(topo, tags, options);
    let child =
        Topology::new(&r.faces, r.num_vertices).expect("the refinement of a valid mesh is valid");
    let mut fine = limit_rows(&child, &r.tags, options);
    fine.offsets.truncate(nv + 1);
    let nnz = fine.offsets[nv];
    fine.cols.truncate(nnz);
    fine.weights.truncate(nnz);
    for w in &mut fine.weights {
        w[1] *= 2.0;
        w[2] *= 2.0;
    }
    let [p, a, b] = fine.compose(&r.matrix);
    let mut rows = MultiRows {
        ncols: nv,
        offsets: vec![0],
        cols: Vec::new(),
        weights: Vec::new(),
    };
    for i in 0..nv {
        let mut entries: Vec<(u32, [f64; 3])> = Vec::new();
        for (k, m) in [&p, &a, &b].into_iter().enumerate() {
            let (c, w) = m.row(i);
            for (&c, &w) in c.iter().zip(w) {
                let mut x = [0.0; 3];
                x[k] = w;
                entries.push((c, x));
            }
        }
        entries.sort_by_key(|e| e.0);
        for (c, w) in entries {
            rows.cols.push(c);
            rows.weights.push(w);
        }
        rows.offsets.push(rows.cols.len());
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::refine::refine;
    use crate::scheme::BoundaryRule;
    use subfit_mesh::{Polygons, SHARPNESS_INFINITE};

    /// An `n × m` grid of quads, closed into a torus or open (a boundary), with every 5th
    /// cell split into two triangles (extraordinary vertices after one step).
    fn grid(n: u32, m: u32, closed: bool) -> (usize, Polygons) {
        let (rows, cols) = if closed { (n, m) } else { (n + 1, m + 1) };
        let id = |i: u32, j: u32| (i % rows) * cols + (j % cols);
        let mut faces = Polygons::new();
        for i in 0..n {
            for j in 0..m {
                let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
                if (i * m + j) % 5 == 0 {
                    faces.push(&[q[0], q[1], q[2]]);
                    faces.push(&[q[0], q[2], q[3]]);
                } else {
                    faces.push(&q);
                }
            }
        }
        ((rows * cols) as usize, faces)
    }

    /// `faces` in a scrambled order, each rotated to start at a scrambled corner (seeded), so
    /// that rings start at varied places.
    fn scramble(faces: &Polygons, seed: u64) -> Polygons {
        let mut x = seed;
        let mut next = move || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 33) as usize
        };
        let mut order: Vec<usize> = (0..faces.len()).collect();
        for i in (1..order.len()).rev() {
            order.swap(i, next() % (i + 1));
        }
        let mut out = Polygons::new();
        for f in order {
            let mut face = faces.iter().nth(f).expect("face").to_vec();
            let k = next() % face.len();
            face.rotate_left(k);
            out.push(&face);
        }
        out
    }

    /// Entry by entry `|a − b| ≤ tol`, patterns allowed to differ by entries below `tol`.
    fn assert_close(a: &StencilMatrix, b: &StencilMatrix, tol: f64, what: &str) {
        assert_eq!((a.nrows(), a.ncols()), (b.nrows(), b.ncols()), "{what}");
        let mut dense = vec![0.0f64; a.ncols()];
        for i in 0..a.nrows() {
            let ((ca, wa), (cb, wb)) = (a.row(i), b.row(i));
            ca.iter()
                .zip(wa)
                .for_each(|(&c, &w)| dense[c as usize] += w);
            cb.iter()
                .zip(wb)
                .for_each(|(&c, &w)| dense[c as usize] -= w);
            for &c in ca.iter().chain(cb) {
                let d = std::mem::take(&mut dense[c as usize]);
                assert!(d.abs() <= tol, "{what}: row {i} column {c} differs by {d}");
            }
        }
    }

    /// `faces` with every `k`-th quad cut into two triangles (a mixed quad/triangle mesh).
    fn cut(faces: &Polygons, k: usize) -> Polygons {
        let mut out = Polygons::new();
        for (f, q) in faces.iter().enumerate() {
            if f % k == 0 && q.len() == 4 {
                out.push(&[q[0], q[1], q[2]]);
                out.push(&[q[0], q[2], q[3]]);
            } else {
                out.push(q);
            }
        }
        out
    }

    /// The tabulated rows of regular neighbourhoods equal the general path's (to 1e-14) on
    /// meshes with extraordinary vertices, boundaries, creases and corners, under both
    /// boundary rules, at the control mesh and one and two levels below it, for
    /// Catmull-Clark and the quad/triangle scheme (also on mixed meshes); and tables are used.
    #[test]
    fn regular_tables_give_the_general_rows() {
        let mut tags = Tags::new();
        for j in 3..9 {
            tags.set_crease(j, j + 1, SHARPNESS_INFINITE);
        }
        tags.set_corner(40, SHARPNESS_INFINITE);
        let (tn, tf) = grid(8, 9, true);
        let (gn, gf) = grid(8, 8, false);
        let meshes = [
            ("torus", (tn, tf.clone()), Tags::new()),
            ("torus creased", (tn, tf.clone()), tags.clone()),
            ("open grid creased", (gn, gf.clone()), tags.clone()),
            ("torus scrambled", (tn, scramble(&tf, 1)), Tags::new()),
            ("open grid scrambled", (gn, scramble(&gf, 2)), tags.clone()),
            ("mixed torus", (tn, cut(&tf, 7)), Tags::new()),
            ("mixed open grid creased", (gn, cut(&gf, 5)), tags.clone()),
            (
                "mixed torus scrambled",
                (tn, scramble(&cut(&tf, 6), 3)),
                tags,
            ),
        ];
        for (name, (nv, faces), tags) in meshes {
            for (scheme, boundary) in [
                (Scheme::CatmullClark, BoundaryRule::EdgeOnly),
                (Scheme::CatmullClark, BoundaryRule::EdgeAndCorner),
                (Scheme::QuadTriangle, BoundaryRule::EdgeOnly),
                (Scheme::QuadTriangle, BoundaryRule::EdgeAndCorner),
            ] {
                let o = Options::new(scheme).with_boundary(boundary);
                let (mut f, mut n, mut t) = (faces.clone(), nv, tags.clone());
                for level in 0..=2 {
                    if level > 0 {
                        let r = refine(&f, n, &t, &o).unwrap();
                        (f, n, t) = (r.faces, r.num_vertices, r.tags);
                    }
                    let parent = Topology::new(&f, n).unwrap();
                    let child_tags = refine(&f, n, &t, &o).unwrap().tags;
                    let id = StencilMatrix::identity(n);
                    let count = AtomicUsize::new(0);
                    let fast = limit_refine_compose_with(
                        &parent,
                        &t,
                        &child_tags,
                        &o,
                        &id,
                        true,
                        Some(&count),
                    );
                    let general =
                        limit_refine_compose_with(&parent, &t, &child_tags, &o, &id, false, None);
                    let what = format!("{name} {scheme:?} {boundary:?} parent level {level}");
                    let used = count.load(Ordering::Relaxed);
                    // At the control mesh most keys see their first row (computed, not read).
                    let least = if level == 0 { 1 } else { fast[0].nrows() / 8 };
                    assert!(
                        used >= least,
                        "{what}: {used} of {} rows from tables",
                        fast[0].nrows()
                    );
                    for (a, b) in fast.iter().zip(&general) {
                        assert_close(a, b, 1e-14, &what);
                    }
                }
            }
        }
    }
}
