//! A closed, manifold surface around a point cloud that needs **no normals**: space carving.
//!
//! The outside is everything a ball of radius `r` can reach from far away without touching a
//! data point (the complement of an `r`-offset "wrap", as in alpha wrapping; Edelsbrunner &
//! Mücke 1994 describe the related α-shapes): grid nodes farther than `r` from every point are
//! flood-filled from the grid boundary (6-connected); the rest is inside. The contour of
//! `d(x) − r` between the two (marching tetrahedra, as [`crate::contour()`]) is the wrap: it lies
//! about `r` outside the data (the fitter pulls the cage in). Moving the dense wrap's vertices
//! back along their normals was tried and folded thin parts (the simplification then stalled on
//! fold-over checks), so it is not done.
//!
//! Used as the fallback of [`crate::initial_control_mesh()`] when the IMLS contour
//! ([`crate::contour()`]) misses the expected genus: wrong normal orientations (e.g. a sparse,
//! decimated scan) make the IMLS sign unreliable, carving does not use them. Tunnels narrower
//! than about `2r` are closed, so `r` must stay below the target's real holes.
//!
//! Cost: one nearest-point query per grid node (parallel), `O(N³)` flags for an `N`-cell grid.

use subfit_mesh::{Cancel, Cancelled, HalfEdgeMesh, PolyMesh};
use subfit_target::Target;

use crate::contour::{bounds, ContourError, ContourReport};
use crate::islands::keep_components;
use crate::march::{march_grid, Grid};

/// Carves the space around the target's points with a ball of radius `radius` (normalized
/// units) on a grid of `resolution` cells along the longest side, and returns the wrap (see
/// the module docs; closed, manifold, outward-oriented, normalized units) with a report (`band_cells` holds `⌈radius / cell⌉`; `flipped` is
/// false; `enclosed_nodes` counts inside nodes farther than `radius` from the data).
///
/// Errors: [`ContourError::InvalidOption`] for a non-positive radius or a resolution below 2,
/// [`ContourError::Empty`] when no surface remains, [`ContourError::NotManifold`] (a bug).
pub fn carve(
    target: &Target,
    resolution: usize,
    radius: f64,
    min_component_fraction: f64,
) -> Result<(PolyMesh, ContourReport), ContourError> {
    carve_cancellable(
        target,
        resolution,
        radius,
        min_component_fraction,
        &Cancel::default(),
    )
}

/// Nodes per batch of nearest-point queries (`cancel` is polled between batches).
const QUERY_BATCH: usize = 1 << 16;

/// The distance of every node of `grid` to the target's points where it is at most `bound`,
/// `INFINITY` elsewhere ([`subfit_target::PointIndex::grid_distances`]: nodes far from the
/// data are mostly skipped, the bunny's 60-cell grid costs a third of a nearest query per
/// node). Polls `cancel` per [`QUERY_BATCH`] nodes' worth of slabs.
fn node_distances(
    target: &Target,
    grid: &Grid,
    bound: f64,
    cancel: &Cancel,
) -> Result<Vec<f64>, Cancelled> {
    let [nx, ny, nz] = grid.dims;
    let slab = (QUERY_BATCH / (nx * ny).max(1)).max(1);
    let mut dist: Vec<f64> = Vec::with_capacity(nx * ny * nz);
    for z0 in (0..nz).step_by(slab) {
        cancel.check()?;
        let zs = z0..(z0 + slab).min(nz);
        dist.extend(
            target
                .index()
                .grid_distances(grid.origin, grid.cell, grid.dims, zs, bound),
        );
    }
    Ok(dist)
}

/// Replaces the `INFINITY` of [`node_distances`] by the exact distance at every node with a
/// neighbour (26-neighbourhood, which holds the Kuhn edges) on the other side of `outside`:
/// the nodes of edges the wrap can cross that lie beyond the bound (an outside node next to
/// an enclosed one). Cost: one nearest query per such node, usually none.
fn exact_at_interface(target: &Target, grid: &Grid, outside: &[bool], dist: &mut [f64]) {
    let [nx, ny, nz] = grid.dims;
    let far: Vec<usize> = (0..dist.len())
        .filter(|&i| dist[i].is_infinite())
        .filter(|&i| {
            let c = grid.coords(i);
            let range = |k: usize, n: usize| c[k].saturating_sub(1)..=(c[k] + 1).min(n - 1);
            range(2, nz).any(|z| {
                range(1, ny)
                    .any(|y| range(0, nx).any(|x| outside[x + nx * (y + ny * z)] != outside[i]))
            })
        })
        .collect();
    for i in far {
        dist[i] = target.index().nearest(&grid.pos(i)).distance;
    }
}

/// [`carve`] polling `cancel` per batch of nearest-point queries, during the flood fill and
/// per slab of the marching; [`ContourError::Interrupted`] once it is cancelled.
pub(crate) fn carve_cancellable(
    target: &Target,
    resolution: usize,
    radius: f64,
    min_component_fraction: f64,
    cancel: &Cancel,
) -> Result<(PolyMesh, ContourReport), ContourError> {
    if !(radius.is_finite() && radius > 0.0) {
        return Err(ContourError::InvalidOption("carving radius must be > 0"));
    }
    if resolution < 2 {
        return Err(ContourError::InvalidOption("resolution must be ≥ 2"));
    }
    if !(0.0..=1.0).contains(&min_component_fraction) {
        return Err(ContourError::InvalidOption(
            "min_component_fraction must be in [0, 1]",
        ));
    }
    let pts = target.points();
    let (lo, hi) = bounds(pts);
    let ext = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max).max(1e-12);
    let cell = ext / resolution as f64;
    let pad = (radius / cell).ceil() as usize + 2;
    let origin = [0, 1, 2].map(|k| lo[k] - pad as f64 * cell);
    let dims = [0, 1, 2].map(|k| ((hi[k] - lo[k]) / cell).ceil() as usize + 2 * pad + 1);
    let grid = Grid { dims, origin, cell };
    let n_nodes = dims[0] * dims[1] * dims[2];

    // Nodes farther than `bound` from the data are `INFINITY` for now: only the exact
    // distances on edges the zero set crosses shape the wrap, and such an edge joins an outside
    // node to one that is not; within `bound` that covers every edge ending at a node within
    // `radius` (a Kuhn edge is at most √3 cells long), beyond it `exact_at_interface` fills in.
    let bound = radius + 2.0 * cell;
    let mut dist = node_distances(target, &grid, bound, cancel)?;

    // Outside: reachable from the grid boundary through nodes farther than `radius`.
    let mut outside = vec![false; n_nodes];
    let mut stack: Vec<usize> = (0..n_nodes)
        .filter(|&i| grid.on_boundary(i) && dist[i] > radius)
        .collect();
    for &i in &stack {
        outside[i] = true;
    }
    let mut popped = 0usize;
    while let Some(i) = stack.pop() {
        popped += 1;
        if popped % (1 << 20) == 0 {
            cancel.check()?;
        }
        for j in grid.neighbors6(i) {
            if !outside[j] && dist[j] > radius {
                outside[j] = true;
                stack.push(j);
            }
        }
    }
    exact_at_interface(target, &grid, &outside, &mut dist);
    let mut enclosed = 0;
    let value: Vec<f64> = (0..n_nodes)
        .map(|i| {
            if outside[i] {
                dist[i] - radius
            } else if dist[i] > radius {
                enclosed += 1;
                -dist[i]
            } else {
                (dist[i] - radius).min(-1e-300)
            }
        })
        .collect();

    let (positions, tris) = march_grid(&grid, &value, cancel)?;
    if tris.is_empty() {
        return Err(ContourError::Empty(resolution));
    }
    let (mesh, found, kept) = keep_components(positions, &tris, min_component_fraction, None);
    let he =
        HalfEdgeMesh::from_mesh(&mesh).map_err(|e| ContourError::NotManifold(e.to_string()))?;
    let report = ContourReport {
        nodes: dims,
        resolution,
        cell_size: cell,
        band_cells: (radius / cell).ceil() as usize,
        band_nodes: 0,
        enclosed_nodes: enclosed,
        flipped: false,
        components_found: found,
        components_kept: kept,
        vertices: mesh.num_vertices(),
        faces: mesh.num_faces(),
        genus: he.genus(),
        ..ContourReport::default()
    };
    Ok((mesh, report))
}
