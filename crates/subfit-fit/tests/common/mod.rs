//! Shared fixtures: the paper ellipsoid target and its 14-vertex initial control mesh.
#![allow(dead_code)]

use std::collections::HashMap;
use subfit_mesh::shapes::Shape;

use subfit_mesh::{PolyMesh, Polygons};
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

/// A cube of `n × n` quads per side projected onto the unit sphere (outward winding): a closed
/// all-quad cage with 8 valence-3 vertices.
pub fn quad_sphere(n: usize) -> PolyMesh {
    let mut ids: HashMap<[i64; 3], u32> = HashMap::new();
    let mut pos = Vec::new();
    let mut faces = Polygons::new();
    let h = n as i64;
    // Each side: a fixed axis at ±n, two running axes (u, v) with u × v pointing outward.
    let sides: [(usize, i64, usize, usize); 6] = [
        (0, 1, 1, 2),
        (0, -1, 2, 1),
        (1, 1, 2, 0),
        (1, -1, 0, 2),
        (2, 1, 0, 1),
        (2, -1, 1, 0),
    ];
    for &(axis, sign, u, v) in &sides {
        let mut id = |i: i64, j: i64| {
            // The cube [-n, n]³ with grid spacing 2 on the running axes.
            let mut key = [0i64; 3];
            key[axis] = sign * h;
            key[u] = 2 * i - h;
            key[v] = 2 * j - h;
            *ids.entry(key).or_insert_with(|| {
                let p = key.map(|x| x as f64);
                let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
                pos.push(p.map(|x| x / r));
                (pos.len() - 1) as u32
            })
        };
        for i in 0..h {
            for j in 0..h {
                let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
                faces.push(&q);
            }
        }
    }
    PolyMesh::new(pos, faces)
}

/// A seeded linear congruential generator (Knuth's MMIX constants) for reproducible test
/// inputs without a dependency.
pub struct Lcg(pub u64);

impl Lcg {
    /// The next value, uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}
