//! Limit stencils: the limit position and two limit tangents of every vertex, as sparse rows over
//! the vertices of the same level.
//!
//! Position masks: Halstead, Kass & DeRose 1993 (*Efficient, fair interpolation using
//! Catmull-Clark surfaces*, §A) for Catmull-Clark; Loop 1987 for Loop; the cubic B-spline limit
//! (1/6, 2/3, 1/6) on creases and boundaries (Hoppe et al. 1994); corners are fixed. Tangent masks
//! follow OpenSubdiv 3.5 (`sdc/*Scheme.h`, `Far::PrimvarRefiner::Limit`), see [`crate::mask`].
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

use crate::error::SubdivError;
use crate::mask::Mask;
use crate::refine::{neighborhoods, refine_topology, sharp_edges, topology_for};
use crate::scheme::{Options, Scheme};
use crate::stencil::StencilMatrix;
use crate::topology::Topology;
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
    let all_quads = (0..topo.num_faces()).all(|f| topo.face(f).len() == 4);
    if options.scheme == Scheme::CatmullClark && !all_quads {
        let nv = topo.num_vertices();
        let r = refine_topology(topo, tags, options);
        let child = Topology::new(&r.faces, r.num_vertices)
            .expect("the refinement of a valid mesh is valid");
        let mut l = limit_topology(&child, &r.tags, options);
        for m in [&mut l.position, &mut l.tangent1, &mut l.tangent2] {
            m.truncate_rows(nv);
            *m = m.compose(&r.matrix);
        }
        l.tangent1.scale(2.0);
        l.tangent2.scale(2.0);
        return l;
    }
    let sharp = sharp_edges(topo, tags);
    let hoods = neighborhoods(topo, &sharp, tags, options.boundary);
    let nv = topo.num_vertices();
    let mut out = [
        StencilMatrix::new(nv),
        StencilMatrix::new(nv),
        StencilMatrix::new(nv),
    ];
    let mut masks = [Mask::default(), Mask::default(), Mask::default()];
    let mut row: Vec<(u32, f64)> = Vec::with_capacity(64);
    for v in 0..nv as u32 {
        let [p, a, b] = &mut masks;
        options.scheme.limit_masks(&hoods[v as usize], p, a, b);
        for (m, mask) in out.iter_mut().zip(&masks) {
            row.clear();
            row.push((v, mask.vertex));
            for (&u, &w) in topo.vertex_ring(v).iter().zip(&mask.edges) {
                row.push((u, w));
            }
            for (&c, &w) in topo.vertex_corners(v).iter().zip(&mask.faces) {
                // The vertex two corners away (the quad's diagonal).
                row.push((topo.corner_vertex(topo.corner_next(topo.corner_next(c))), w));
            }
            m.push_row(&mut row);
        }
    }
    let [position, tangent1, tangent2] = out;
    LimitStencils {
        position,
        tangent1,
        tangent2,
    }
}
