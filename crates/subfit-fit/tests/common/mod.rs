//! Shared fixtures: the paper ellipsoid target and its 14-vertex initial control mesh.
#![allow(dead_code)]

use subfit_mesh::shapes::Shape;
use subfit_mesh::PolyMesh;
use subfit_target::{Target, TargetOptions};

/// Semi-axes of Cheng 2007's ellipsoid (original units).
pub const AXES: [f64; 3] = [0.25, 0.5, 1.0];

/// The ellipsoid sampled with `n` points (with normals), as a target in the unit cube.
pub fn ellipsoid_target(n: usize) -> Target {
    let cloud = Shape::PAPER_ELLIPSOID.sample(n, 0.0, 7);
    Target::from_points(
        &cloud.positions,
        cloud.normals.as_deref(),
        &TargetOptions::default(),
    )
    .expect("ellipsoid target")
}

/// A 14-vertex triangle mesh of the ellipsoid (original units): the octahedron
/// `octahedron_mesh(a, b, c)` with each of its 8 faces split 1-to-3 at its centroid, the
/// centroid pushed out radially onto the ellipsoid (6 + 8 = 14 vertices, 24 triangles; valences
/// 8 and 3). Cheng 2007 Example 1 starts from a 14-point control mesh of this kind.
pub fn fourteen_vertex_mesh() -> PolyMesh {
    let [a, b, c] = AXES;
    subfit_mesh::shapes::cheng_ellipsoid_cage(a, b, c, false)
}

/// `mesh` mapped into the target's normalized coordinates.
pub fn normalized(target: &Target, mesh: &PolyMesh) -> PolyMesh {
    let mut m = mesh.clone();
    for p in &mut m.positions {
        *p = target.to_normalized(*p);
    }
    m
}
