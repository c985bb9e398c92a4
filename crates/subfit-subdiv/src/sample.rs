//! The sampling operator `C = L_l · M_l ⋯ M_1` (Lavoué et al., §5.1; DESIGN §3.1): limit
//! positions and limit tangents of all level-`l` vertices as sparse rows over the control points.
//!
//! `M_k` are the refinement matrices of [`mod@crate::refine`], `L_l` the limit stencils of
//! [`crate::limit`] at level `l`. Products are accumulated right to left
//! (`P_k = M_k · P_{k−1}`), so every intermediate row is over the control points and stays
//! short (its support is the control-mesh neighbourhood of the vertex). The last two factors
//! are fused: each row of `L_l · M_l` is formed locally over the level-(`l − 1`) vertices and
//! multiplied by `P_{l−1}` ([`crate::limit`]), so neither `M_l` nor `P_l` — the largest
//! intermediate, one row per level-`l` vertex — is stored.
//!
//! Only the control mesh's adjacency is built from its face list
//! ([`Topology::new`](crate::Topology::new)); that of each finer level is read off the level
//! above (module `child`, for all three schemes) — for levels `1 … l − 1` as a
//! [`Topology`](crate::Topology), for level `l` vertex by vertex as its limit rows need it, so
//! no adjacency with one entry per corner of the finest mesh is built, and no intermediate face
//! list.
//!
//! Semi-sharp tags ([`crate::crease`]): the refinement rows blend the sharp and smooth rules.
//! Where finite sharpness is left around a level-`l` vertex its limit row is computed by local
//! refinement of its one-ring until the sharpness has decayed ([`crate::limit`]), then expanded
//! like any other row.

use crate::child::refined_topology;
use crate::error::SubdivError;
use crate::limit::{limit_refine_compose, limit_rows};
use crate::refine::{child_faces, child_tags, refine_compose, refine_matrix, topology_for};
use crate::scheme::Options;
use crate::stencil::StencilMatrix;
use subfit_mesh::{Polygons, Tags};

/// Limit stencils of the level-`l` vertices over the control points.
#[derive(Clone, Debug)]
pub struct SamplingOperator {
    /// The refinement level `l` (0 = the control mesh itself).
    pub level: usize,
    /// Faces of the level-`l` mesh (vertex ids are row indices below).
    pub faces: Polygons,
    /// Number of level-`l` vertices (rows of the matrices).
    pub num_vertices: usize,
    /// Tags of the level-`l` mesh.
    pub tags: Tags,
    /// Limit positions, `#V_l × #V_0`; rows sum to 1.
    pub position: StencilMatrix,
    /// First limit tangents, `#V_l × #V_0`; rows sum to 0.
    pub tangent1: StencilMatrix,
    /// Second limit tangents, `#V_l × #V_0`; rows sum to 0.
    pub tangent2: StencilMatrix,
}

/// Limit positions, tangents and unit normals of sample points (`#samples by 3` each).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LimitSamples {
    /// Limit positions (units of the control points).
    pub positions: Vec<[f64; 3]>,
    /// First limit tangents (direction only is meaningful).
    pub tangent1: Vec<[f64; 3]>,
    /// Second limit tangents.
    pub tangent2: Vec<[f64; 3]>,
    /// Unit normals `normalize(t1 × t2)`; zero where the tangents are parallel or zero.
    pub normals: Vec<[f64; 3]>,
}

/// Builds the sampling operator of `faces` (over `num_vertices` control points, with `tags`) at
/// refinement `level`.
///
/// Errors: bad topology, or non-triangles for Loop (see [`SubdivError`]).
/// Cost: one adjacency build from faces and `l − 1` from the level above (parallel), and `l`
/// parallel sparse products whose left rows are generated on the fly (refinement rows for
/// `P_k = M_k · P_{k−1}`, `k < l`, Catmull-Clark face points first and then reused as single
/// rows; rows of `L_l · M_l` for the last, fused product giving the three matrices, read from
/// tables in regular Catmull-Clark regions); memory about `3 · #V_l · s` entries with `s` ≈ 12
/// (Loop) – 15 (Catmull-Clark) control points per row, plus `P_{l−1}` (about a quarter of one
/// of them). Measured (`benches/stencils.rs`, 2 threads, quiet machine): a 10k-face
/// Catmull-Clark control mesh at level 3 (686k rows, 30M entries) in ≈ 0.37 s, the first build
/// of a process included; the quad/triangle scheme on the same mesh with every 7th quad split
/// in two triangles within ≈ 10 % of that (CPU time; shared machine). Most of the time is the last product (scattered reads of `P_{l−1}`
/// rows and scattered accumulation) and the page faults on the ~0.4 GB output. Each level-`l`
/// vertex with finite sharpness left around it costs one local refinement of its one-ring per
/// remaining unit of sharpness (module docs).
pub fn sampling_operator(
    faces: &Polygons,
    num_vertices: usize,
    tags: &Tags,
    options: &Options,
    level: usize,
) -> Result<SamplingOperator, SubdivError> {
    let mut topo = topology_for(faces, num_vertices, options.scheme)?;
    if level == 0 {
        let [position, tangent1, tangent2] = limit_rows(&topo, tags, options).split();
        return Ok(SamplingOperator {
            level,
            faces: faces.clone(),
            num_vertices,
            tags: tags.clone(),
            position,
            tangent1,
            tangent2,
        });
    }
    // P_{l−1} = M_{l−1} ⋯ M_1 over the control points, with the level-(l−1) adjacency.
    let mut product = StencilMatrix::identity(num_vertices);
    let mut level_tags = tags.clone();
    for k in 1..level {
        product = if k == 1 {
            refine_matrix(&topo, &level_tags, options)
        } else {
            refine_compose(&topo, &level_tags, options, &product)
        };
        level_tags = child_tags(&topo, &level_tags);
        topo = refined_topology(&topo, options.scheme)?;
    }
    let child_tags = child_tags(&topo, &level_tags);
    // The last level: C = L_l · M_l · P_{l−1}, with neither M_l nor its product stored and the
    // level-l adjacency read off level l − 1.
    let [position, tangent1, tangent2] =
        limit_refine_compose(&topo, &level_tags, &child_tags, options, &product);
    Ok(SamplingOperator {
        level,
        faces: child_faces(&topo, options.scheme),
        num_vertices: position.nrows(),
        tags: child_tags,
        position,
        tangent1,
        tangent2,
    })
}

impl SamplingOperator {
    /// Applies the operator to control points (`#V_0 by 3`). Cost O(nnz).
    ///
    /// # Panics
    /// If `control.len()` differs from the control-point count.
    #[track_caller]
    pub fn evaluate(&self, control: &[[f64; 3]]) -> LimitSamples {
        let positions = self.position.apply(control);
        let tangent1 = self.tangent1.apply(control);
        let tangent2 = self.tangent2.apply(control);
        let normals = normals_from_tangents(&tangent1, &tangent2);
        LimitSamples {
            positions,
            tangent1,
            tangent2,
            normals,
        }
    }
}

/// Unit normals `normalize(t1 × t2)` row by row; a zero vector where the cross product vanishes.
///
/// # Panics
/// If the slices differ in length.
#[track_caller]
pub fn normals_from_tangents(t1: &[[f64; 3]], t2: &[[f64; 3]]) -> Vec<[f64; 3]> {
    assert_eq!(t1.len(), t2.len(), "tangent arrays differ in length");
    t1.iter()
        .zip(t2)
        .map(|(a, b)| {
            let n = [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ];
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if len > 0.0 && len.is_finite() {
                [n[0] / len, n[1] / len, n[2] / len]
            } else {
                [0.0; 3]
            }
        })
        .collect()
}
