//! The initial cage of a CAD tessellation: the facets' own features kept exactly, the planes
//! emptied, the curved faces coarsened only where they are smooth.
//!
//! A Loop or Catmull-Clark cage whose edges are all infinitely sharp creases and whose vertices
//! are all corners has the polyhedron itself as its limit surface (Hoppe et al. 1994's crease
//! and corner rules: a crease curve is the B-spline of its polygon, straight where the polygon
//! is, and a corner interpolates its vertex; a face's limit depends only on the control
//! points of its own sector). So a faceted region is reproduced exactly by tagging, and
//! smoothness is a choice made per edge ([`subfit_target::tessellation::classify_edges`]):
//!
//! 1. **Creases**: the edges classified as creases are locked as feature edges; boundary edges
//!    are creases by the boundary rule.
//! 2. **Corners**: a vertex with three or more crease or boundary edges; a vertex with two
//!    whose polygon bends (the vertex farther than the flat tolerance from the line through its
//!    two neighbours) unless a smooth face meets it — there the crease curve is meant to be
//!    smooth (the rim of a cylinder) and is a corner only where it turns by more than
//!    [`SMOOTH_CORNER_TURN_DEG`].
//! 3. **Simplification** ([`crate::simplify_with_features`]): collapses go on while they move
//!    the surface by at most the flat tolerance — which empties the planar regions down to their
//!    outlines and straightens collinear crease runs — and, where a smooth face is, by at most
//!    [`CadOptions::smooth_error`]. Corners are never removed, so a faceted curved face keeps
//!    every vertex.
//! 4. **Concave corners** ([`subfit_mesh::split_concave_corners_with`]): a crease into every
//!    sector wider than π, so no planar region folds over its outline (OpenSubdiv's corner
//!    rule fills a convex wedge). A decimated planar face has no vertex off its outline: the
//!    crease runs to a vertex of the outline that no smooth face meets, which becomes a corner
//!    without its polygon changing; a new point is inserted only within the control points
//!    left.
//!
//! The cage has at most the input's vertices (only concave-corner splits add any, within
//! [`CadOptions::max_control_points`]). Cost: that of the simplification, `O(E log E)`.

use std::time::{Duration, Instant};

use subfit_mesh::vec3::{cross, dot, norm, sub};
use subfit_mesh::{split_concave_corners_with, Cancel, ConcaveSplits, PolyMesh, Polygons, Tags};
use subfit_target::tessellation::{EdgeClass, FacetFeatures, Facets};

use crate::init::InitError;
use crate::simplify::{simplify_with_features, FeatureLock, SimplifyOptions, SimplifyReport};

/// A crease curve that a smooth face meets is a corner where it turns by more than this
/// (degrees): the rim of a cylinder turns by its facets' angle (below
/// [`subfit_target::tessellation::MAX_SMOOTH_ANGLE_DEG`]); where a fillet's rim meets another
/// rim the outline turns by 45° or more.
pub const SMOOTH_CORNER_TURN_DEG: f64 = 40.0;

/// Options of [`cad_cage`].
#[derive(Clone, Debug)]
pub struct CadOptions {
    /// Largest RMS distance (units of the mesh) by which a collapse may move a smooth face
    /// (the fitted limit then lies much closer than the cage's facets). Planar regions and
    /// crease runs are collapsed only within the facets' flat tolerance.
    pub smooth_error: f64,
    /// Control points the concave-corner splits may bring the cage up to.
    pub max_control_points: usize,
    /// Cancellation token.
    pub cancel: Cancel,
}

/// What [`cad_cage`] did.
#[derive(Clone, Debug, Default)]
pub struct CadReport {
    /// Vertices of the tessellation (used by its faces).
    pub vertices_before: usize,
    /// Control points of the cage.
    pub control_points: usize,
    /// Crease tags of the cage.
    pub creases: usize,
    /// Corner tags of the cage.
    pub corners: usize,
    /// Vertices locked as corners in the tessellation.
    pub locked_corners: usize,
    /// Concave sectors split.
    pub concave: ConcaveSplits,
    /// The simplification.
    pub simplify: SimplifyReport,
    /// Time taken.
    pub time: Duration,
}

/// The cage of the tessellation whose vertices are `positions` (`#V by 3`) and whose triangles
/// and edges are `facets`', with the edge classes of `features` (see the module docs):
/// positions, faces (triangles), tags and report. Errors: the mesh is not an oriented manifold
/// ([`InitError::Simplify`]), or the run was cancelled.
pub fn cad_cage(
    positions: &[[f64; 3]],
    facets: &Facets,
    features: &FacetFeatures,
    options: &CadOptions,
) -> Result<(PolyMesh, Tags, CadReport), InitError> {
    let t0 = Instant::now();
    let mut report = CadReport {
        vertices_before: used_vertices(&facets.triangles, positions.len()),
        ..CadReport::default()
    };
    let lock = feature_lock(positions, facets, features);
    report.locked_corners = lock.corners.len();
    let dense = PolyMesh::new(
        positions.to_vec(),
        Polygons::from_triangles(&facets.triangles),
    );
    // The smooth faces may move by `smooth_error`, the rest only within the flat tolerance:
    // the simplification's bound is the smooth one, and a planar region's or a faceted
    // face's vertices are held by their locks (a collapse in a plane costs nothing, one across
    // a faceted face is refused by its corners).
    let error = if features.count(EdgeClass::Smooth) > 0 {
        options.smooth_error.max(facets.flat_tolerance)
    } else {
        facets.flat_tolerance
    };
    let sopt = SimplifyOptions {
        // Never aim below what the surface allows: past the count, only collapses within the
        // error bound are made.
        target_vertices: positions.len(),
        exact_error: error,
        cancel: options.cancel.clone(),
        ..SimplifyOptions::default()
    };
    let (mut cage, mut tags, srep) = simplify_with_features(&dense, &lock, &sopt)?;
    let room = options
        .max_control_points
        .min(report.vertices_before)
        .saturating_sub(cage.num_vertices());
    let smooth = smooth_vertices(&cage, &tags, facets.flat_tolerance);
    report.concave =
        split_concave_corners_with(&mut cage, &mut tags, room, &|v| !smooth[v as usize]);
    report.simplify = srep;
    report.control_points = cage.num_vertices();
    report.creases = tags.creases().len();
    report.corners = tags.corners().len();
    report.time = t0.elapsed();
    Ok((cage, tags, report))
}

/// Per vertex of `cage`: whether an edge at it is smooth (neither tagged nor between coplanar
/// faces): its crease curves, if any, are meant to be smooth.
fn smooth_vertices(cage: &PolyMesh, tags: &Tags, tol: f64) -> Vec<bool> {
    let tris = cage.faces.triangulate_fan();
    let f = Facets::new(&cage.positions, &tris, tol);
    let mut smooth = vec![false; cage.num_vertices()];
    for e in f.edges.iter().filter(|e| !e.flat) {
        let [a, b] = e.ends;
        if tags.crease(a, b) <= 0.0 {
            smooth[a as usize] = true;
            smooth[b as usize] = true;
        }
    }
    smooth
}

fn used_vertices(triangles: &[[u32; 3]], n: usize) -> usize {
    let mut used = vec![false; n];
    for t in triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    used.iter().filter(|&&u| u).count()
}

/// The crease edges and corner vertices of the tessellation (steps 1–2 of the module docs).
fn feature_lock(positions: &[[f64; 3]], facets: &Facets, features: &FacetFeatures) -> FeatureLock {
    let n = positions.len();
    // Per vertex: its crease and boundary neighbours, and whether a smooth edge meets it.
    let mut sharp: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut smooth = vec![false; n];
    let mut edges = Vec::new();
    for (e, class) in facets.edges.iter().zip(&features.class) {
        let [a, b] = e.ends;
        match class {
            EdgeClass::Crease => {
                sharp[a as usize].push(b);
                sharp[b as usize].push(a);
                edges.push(e.ends);
            }
            EdgeClass::Smooth => {
                smooth[a as usize] = true;
                smooth[b as usize] = true;
            }
            EdgeClass::Flat => {}
        }
    }
    for &[a, b] in &facets.boundary {
        sharp[a as usize].push(b);
        sharp[b as usize].push(a);
    }
    let max_turn = SMOOTH_CORNER_TURN_DEG.to_radians();
    let corners = (0..n as u32)
        .filter(|&v| {
            let s = &sharp[v as usize];
            match s.len() {
                0 | 1 => false,
                2 => {
                    let [p, a, b] = [v, s[0], s[1]].map(|u| positions[u as usize]);
                    if smooth[v as usize] {
                        turn(sub(p, a), sub(b, p)) > max_turn
                    } else {
                        line_distance(p, a, b) > facets.flat_tolerance
                    }
                }
                _ => true,
            }
        })
        .collect();
    FeatureLock { edges, corners }
}

/// The angle between two directions (radians).
fn turn(u: [f64; 3], w: [f64; 3]) -> f64 {
    let c = dot(u, w) / (norm(u) * norm(w)).max(f64::MIN_POSITIVE);
    c.clamp(-1.0, 1.0).acos()
}

/// Distance of `p` from the line through `a` and `b`.
fn line_distance(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = sub(b, a);
    let l = norm(d);
    if l > 0.0 {
        norm(cross(sub(p, a), d)) / l
    } else {
        norm(sub(p, a))
    }
}
