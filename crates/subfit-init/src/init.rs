//! The initial control mesh (DESIGN.md §3.6: it has the target's topology, checked and reported).
//!
//! Mesh targets are simplified ([`crate::simplify`](mod@crate::simplify), Garland & Heckbert 1997 with the link
//! condition of Dey et al. 1999), like the method of reference 13 in Cheng et al. 2007 §I; point
//! clouds are contoured first ([`crate::contour`](mod@crate::contour): IMLS of Xie et al. 2023 on a grid, marching
//! tetrahedra) and then simplified, as Cheng et al. 2004 §4.3 (marching cubes on an octree, then
//! simplification).

use std::time::{Duration, Instant};

use subfit_mesh::{HalfEdgeMesh, PolyMesh, TopologyError};
use subfit_target::Target;

use crate::contour::{contour, ContourError, ContourOptions, ContourReport};
use crate::simplify::{simplify, SimplifyError, SimplifyOptions, SimplifyReport};

/// Options of [`initial_control_mesh`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InitOptions {
    /// Simplification options; `target_vertices` is replaced by the requested vertex count.
    pub simplify: SimplifyOptions,
    /// Contouring options (point clouds only).
    pub contour: ContourOptions,
    /// Genus the caller expects for a point cloud (compared in the report). Default `None`: the
    /// contour's genus is reported as the target's. Ignored for mesh targets (their genus is
    /// computed).
    pub expected_genus: Option<u32>,
    /// Fail with [`InitError::GenusMismatch`] when the result's genus differs from the target's.
    /// Default `false` (the mismatch is only reported).
    pub require_genus: bool,
}

/// Where the initial mesh came from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum InitSource {
    /// Simplification of the target's own mesh.
    #[default]
    Mesh,
    /// Contour of the point cloud's implicit function, then simplification.
    Contour,
}

/// Wall-clock times of the steps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct InitTimings {
    /// Contouring (zero for mesh targets).
    pub contour: Duration,
    /// Simplification.
    pub simplify: Duration,
    /// Everything, including validation.
    pub total: Duration,
}

/// What [`initial_control_mesh`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InitReport {
    /// Mesh or point-cloud path.
    pub source: InitSource,
    /// Genus of the target: the input mesh's, the caller's expectation, or (point clouds without
    /// an expectation) the contour's.
    pub genus_target: u32,
    /// Genus of the simplified mesh before simplification (input mesh or contour).
    pub genus_before: u32,
    /// Genus of the result.
    pub genus_after: u32,
    /// Boundary loops before and after simplification.
    pub boundary_loops: (usize, usize),
    /// Connected components of the result.
    pub components: usize,
    /// Whether the result's genus equals `genus_target`.
    pub genus_matches: bool,
    /// Whether the result has no boundary.
    pub closed: bool,
    /// Simplification details (vertex counts before/after, rejections, error).
    pub simplify: SimplifyReport,
    /// Contouring details (point clouds only).
    pub contour: Option<ContourReport>,
    /// Step times.
    pub timings: InitTimings,
}

/// Why [`initial_control_mesh`] failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum InitError {
    /// `n_vertices` is below 4 (no closed triangle mesh has fewer).
    #[error("at least 4 control vertices are needed, {0} requested")]
    TooFewVertices(usize),
    /// The mesh target cannot be simplified.
    #[error("simplification failed: {0}")]
    Simplify(#[from] SimplifyError),
    /// The point cloud cannot be contoured.
    #[error("contouring failed: {0}")]
    Contour(#[from] ContourError),
    /// The result is not manifold (an internal error).
    #[error("internal error: the initial mesh is not manifold: {0}")]
    Topology(#[from] TopologyError),
    /// The genus differs and [`InitOptions::require_genus`] is set.
    #[error("the initial mesh has genus {got}, the target {expected}")]
    GenusMismatch {
        /// The target's genus.
        expected: u32,
        /// The result's genus.
        got: u32,
    },
}

/// An initial triangle control mesh with about `n_vertices` vertices and the target's topology.
///
/// * `mesh = Some(m)` with faces: `m` (in the target's **original** coordinates, e.g. the mesh the
///   target was built from) is mapped into normalized units and simplified.
/// * otherwise the target's points (with their oriented normals) are contoured, then simplified.
///
/// The result is in the target's normalized units, manifold, consistently oriented (outward for
/// contours; as the input for meshes), closed when the target is; it may keep more than
/// `n_vertices` vertices when no legal collapse remains (see `report.simplify.reached_target`).
/// Cost: contouring `O(N³ + band·k)` for an `N`-cell grid, simplification `O(E log E)`.
pub fn initial_control_mesh(
    target: &Target,
    mesh: Option<&PolyMesh>,
    n_vertices: usize,
    options: &InitOptions,
) -> Result<(PolyMesh, InitReport), InitError> {
    let t0 = Instant::now();
    if n_vertices < 4 {
        return Err(InitError::TooFewVertices(n_vertices));
    }
    let mut report = InitReport::default();
    let dense = match mesh {
        Some(m) if !m.faces.is_empty() => {
            report.source = InitSource::Mesh;
            let mut m = PolyMesh::new(
                m.positions
                    .iter()
                    .map(|&p| target.to_normalized(p))
                    .collect(),
                m.faces.clone(),
            );
            m.faces = subfit_mesh::Polygons::from_triangles(&m.faces.triangulate_fan());
            m
        }
        _ => {
            report.source = InitSource::Contour;
            let t = Instant::now();
            let (m, c) = contour(target, &options.contour)?;
            report.timings.contour = t.elapsed();
            report.contour = Some(c);
            m
        }
    };
    let before = HalfEdgeMesh::from_mesh(&dense)?;
    report.genus_before = before.genus();
    report.genus_target = match (report.source, options.expected_genus) {
        (InitSource::Contour, Some(g)) => g,
        _ => report.genus_before,
    };
    let loops_before = before.boundary_loops().len();
    drop(before);

    let t = Instant::now();
    let sopt = SimplifyOptions {
        target_vertices: n_vertices,
        ..options.simplify.clone()
    };
    let (out, srep) = simplify(&dense, &sopt)?;
    report.timings.simplify = t.elapsed();
    report.simplify = srep;

    let after = HalfEdgeMesh::from_mesh(&out)?;
    report.genus_after = after.genus();
    let loops_after = after.boundary_loops().len();
    report.boundary_loops = (loops_before, loops_after);
    report.closed = loops_after == 0;
    report.components = after.components().count;
    report.genus_matches = report.genus_after == report.genus_target;
    report.timings.total = t0.elapsed();
    if options.require_genus && !report.genus_matches {
        return Err(InitError::GenusMismatch {
            expected: report.genus_target,
            got: report.genus_after,
        });
    }
    Ok((out, report))
}
