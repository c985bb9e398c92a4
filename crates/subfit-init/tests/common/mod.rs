//! Helpers shared by the integration tests.
#![allow(dead_code)]

use subfit_mesh::shapes::octahedron_mesh;
use subfit_mesh::{HalfEdgeMesh, PolyMesh, Polygons};

/// Genus, boundary-loop count and component count; panics when not an oriented manifold.
#[track_caller]
pub fn topology(m: &PolyMesh) -> (u32, usize, usize) {
    let he = HalfEdgeMesh::from_mesh(m).expect("manifold, oriented");
    (he.genus(), he.boundary_loops().len(), he.components().count)
}

/// Unnormalized face normal of a triangle.
pub fn face_normal(m: &PolyMesh, t: &[u32]) -> [f64; 3] {
    let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

/// Centroid of a face.
pub fn centroid(m: &PolyMesh, t: &[u32]) -> [f64; 3] {
    let mut c = [0.0; 3];
    for &v in t {
        for (ck, pk) in c.iter_mut().zip(m.positions[v as usize]) {
            *ck += pk / t.len() as f64;
        }
    }
    c
}

/// A closed ellipsoid mesh: the octahedron split 1→4 `levels` times, projected onto the
/// ellipsoid with semi-axes `a`, `b`, `c` (`8·4^levels` faces).
pub fn ellipsoid_mesh(a: f64, b: f64, c: f64, levels: usize) -> PolyMesh {
    let base = octahedron_mesh(1.0, 1.0, 1.0);
    let mut pos = base.positions.clone();
    let mut tris: Vec<[u32; 3]> = base.faces.triangulate_fan();
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut next = Vec::with_capacity(4 * tris.len());
        for t in &tris {
            let m = [0, 1, 2].map(|k| {
                let (u, v) = (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]));
                *mid.entry((u, v)).or_insert_with(|| {
                    let (p, q) = (pos[u as usize], pos[v as usize]);
                    pos.push([0, 1, 2].map(|i| 0.5 * (p[i] + q[i])));
                    (pos.len() - 1) as u32
                })
            });
            next.push([t[0], m[0], m[2]]);
            next.push([m[0], t[1], m[1]]);
            next.push([m[2], m[1], t[2]]);
            next.push([m[0], m[1], m[2]]);
        }
        tris = next;
    }
    for p in &mut pos {
        let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        *p = [a * p[0] / l, b * p[1] / l, c * p[2] / l];
    }
    PolyMesh::new(pos, Polygons::from_triangles(&tris))
}

/// An open `n × n` grid on the paraboloid `z = 0.2 (x² + y²)` over `[-1, 1]²`.
pub fn disk_mesh(n: usize) -> PolyMesh {
    let mut pos = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (
                2.0 * i as f64 / (n - 1) as f64 - 1.0,
                2.0 * j as f64 / (n - 1) as f64 - 1.0,
            );
            pos.push([x, y, 0.2 * (x * x + y * y)]);
        }
    }
    let id = |i: usize, j: usize| (i + n * j) as u32;
    let mut tris = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    PolyMesh::new(pos, Polygons::from_triangles(&tris))
}

/// The data directory from `SUBFIT_DATA`; `None` (with a notice) when unset outside CI.
/// Panics under `CI=true` when unset.
pub fn data_dir() -> Option<std::path::PathBuf> {
    match std::env::var_os("SUBFIT_DATA") {
        Some(d) => Some(d.into()),
        None => {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "SUBFIT_DATA must be set under CI=true"
            );
            #[allow(clippy::print_stderr)] // the skip notice is the point
            {
                eprintln!("notice: SUBFIT_DATA unset; skipping the real-data test");
            }
            None
        }
    }
}
