//! Simple control meshes for tests, examples and benchmarks: a torus grid, the octahedron and
//! Cheng et al. 2007's 14-vertex ellipsoid cage built on it (Examples 1–10), a geodesic
//! sphere, cubes and boxes, a capped cylinder, an L-shaped and a rounded prism. Re-exported from
//! [`crate::shapes`].

use crate::polygons::{PolyMesh, Polygons};
use crate::vec3::{dot, unit};

/// A triangulated torus grid around the z axis: `nu` segments around the axis, `nv` around the
/// tube (both ≥ 3), `2·nu·nv` triangles, outward winding. Genus 1, all vertices of valence 6.
pub fn torus_mesh(major: f64, minor: f64, nu: usize, nv: usize, triangles: bool) -> PolyMesh {
    let nu = nu.max(3);
    let nv = nv.max(3);
    let mut pos = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        let u = std::f64::consts::TAU * i as f64 / nu as f64;
        for j in 0..nv {
            let v = std::f64::consts::TAU * j as f64 / nv as f64;
            let r = major + minor * v.cos();
            pos.push([r * u.cos(), r * u.sin(), minor * v.sin()]);
        }
    }
    let id = |i: usize, j: usize| ((i % nu) * nv + (j % nv)) as u32;
    let mut faces = Polygons::with_capacity(2 * nu * nv, 6 * nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if triangles {
                faces.push(&[a, b, c]);
                faces.push(&[a, c, d]);
            } else {
                faces.push(&[a, b, c, d]);
            }
        }
    }
    PolyMesh::new(pos, faces)
}

/// An octahedron scaled to the ellipsoid with semi-axes `a`, `b`, `c`: 6 vertices, 8 triangles,
/// outward winding. A coarse closed control mesh for the ellipsoid examples.
pub fn octahedron_mesh(a: f64, b: f64, c: f64) -> PolyMesh {
    let pos = vec![
        [a, 0.0, 0.0],
        [-a, 0.0, 0.0],
        [0.0, b, 0.0],
        [0.0, -b, 0.0],
        [0.0, 0.0, c],
        [0.0, 0.0, -c],
    ];
    let tris = [
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    PolyMesh::new(pos, Polygons::from_triangles(&tris))
}

/// The unit geodesic sphere: the icosahedron (12 vertices, 20 faces) with each triangle split
/// into four through its edges' midpoints, pushed onto the sphere, `levels` times
/// (`10·4^levels + 2` vertices), outward winding.
pub fn geodesic_sphere(levels: usize) -> PolyMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let on_sphere = |p: [f64; 3]| unit(p).unwrap_or(p);
    let mut pos: Vec<[f64; 3]> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .into_iter()
    .map(on_sphere)
    .collect();
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut next = Vec::with_capacity(4 * tris.len());
        let mut m = |a: u32, b: u32, pos: &mut Vec<[f64; 3]>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (p, q) = (pos[a as usize], pos[b as usize]);
                pos.push(on_sphere([p[0] + q[0], p[1] + q[1], p[2] + q[2]]));
                pos.len() as u32 - 1
            })
        };
        for [a, b, c] in tris {
            let (ab, bc, ca) = (m(a, b, &mut pos), m(b, c, &mut pos), m(c, a, &mut pos));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    PolyMesh::new(pos, Polygons::from_triangles(&tris))
}

/// An axis-aligned cube of half-size `h` as 8 vertices and 6 outward quads.
pub fn cube_mesh(h: f64) -> PolyMesh {
    let mut pos = Vec::with_capacity(8);
    for i in 0..8u32 {
        let s = |bit: u32| if i & bit != 0 { h } else { -h };
        pos.push([s(1), s(2), s(4)]);
    }
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    PolyMesh::new(pos, Polygons::from_quads(&quads))
}

/// A closed cylinder of radius `r` and height `h` (axis z, from 0) as a CAD exporter
/// tessellates it with `m` segments: the side as `m` quads split in two (long strips), each cap
/// as a fan of `m` triangles around its centre; outward orientation, `2m + 2` vertices (the
/// rings first, bottom then top, then the two centres). The CAD-like shape of a curved face
/// cut by chords (sag `r (1 − cos(π/m))`) between two planes.
///
/// # Panics
/// If `m` is below 3.
pub fn capped_cylinder(r: f64, h: f64, m: usize) -> PolyMesh {
    assert!(m >= 3, "a cylinder needs at least 3 segments");
    let mut p = Vec::with_capacity(2 * m + 2);
    for z in [0.0, h] {
        for i in 0..m {
            let a = std::f64::consts::TAU * i as f64 / m as f64;
            p.push([r * a.cos(), r * a.sin(), z]);
        }
    }
    let (bottom, top) = (p.len() as u32, p.len() as u32 + 1);
    p.push([0.0, 0.0, 0.0]);
    p.push([0.0, 0.0, h]);
    let mut t = Vec::with_capacity(4 * m);
    for i in 0..m {
        let j = (i + 1) % m;
        let (a, b, c, d) = (i as u32, j as u32, (m + j) as u32, (m + i) as u32);
        t.extend([[a, b, c], [a, c, d], [bottom, b, a], [top, d, c]]);
    }
    PolyMesh::new(p, Polygons::from_triangles(&t))
}

/// The unit cube `[0, 1]³` with an `n × n` grid of triangle pairs on each side (outward
/// orientation, shared vertices), without its top side (`z = 1`) when `open_top`: the CAD-like
/// shape of sharp features (12 crease curves and 8 corners; open: 8 curves, 4 corners and a
/// square rim).
///
/// # Panics
/// If `n` is 0.
pub fn gridded_box(n: usize, open_top: bool) -> PolyMesh {
    assert!(n > 0, "a grid needs at least one cell per side");
    let mut grid = Grid::new(n);
    // (origin, u, v) with u × v outward.
    let mut sides = vec![
        ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
        ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
        ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
    ];
    if !open_top {
        sides.push(([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]));
    }
    for (o, u, v) in sides {
        grid.patch(o, u, v);
    }
    grid.mesh()
}

/// A closed L-shaped prism (an angle bracket): the profile (0,0) (2,0) (2,1) (1,1) (1,2) (0,2),
/// height 1, every side an `n`-per-unit grid of triangle pairs (outward orientation, shared
/// vertices). The CAD-like shape of concave features: 18 crease curves, 12 corners, one concave
/// edge (x = y = 1) whose two ends are concave corners of the top and bottom faces.
///
/// # Panics
/// If `n` is 0.
pub fn l_prism(n: usize) -> PolyMesh {
    assert!(n > 0, "a grid needs at least one cell per unit");
    let mut grid = Grid::new(n);
    let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    let (x2, y2) = ([2.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
    // (origin, u, v) with u × v outward.
    let sides = [
        ([0.0, 0.0, 0.0], y, x2), // bottom, y ∈ [0, 1]
        ([0.0, 1.0, 0.0], y, x),  // bottom, y ∈ [1, 2]
        ([0.0, 0.0, 1.0], x2, y), // top, y ∈ [0, 1]
        ([0.0, 1.0, 1.0], x, y),  // top, y ∈ [1, 2]
        ([0.0, 0.0, 0.0], x2, z), // y = 0
        ([2.0, 0.0, 0.0], y, z),  // x = 2
        ([1.0, 1.0, 0.0], z, x),  // y = 1, x ∈ [1, 2]
        ([1.0, 1.0, 0.0], y, z),  // x = 1, y ∈ [1, 2]
        ([0.0, 2.0, 0.0], z, x),  // y = 2
        ([0.0, 0.0, 0.0], z, y2), // x = 0
    ];
    for (o, u, v) in sides {
        grid.patch(o, u, v);
    }
    grid.mesh()
}

/// Rectangles gridded in triangle pairs at `1/n`, sharing the vertices on their common edges
/// (keyed by grid coordinates, which are exact multiples of `1/n`).
struct Grid {
    n: usize,
    index: std::collections::HashMap<[i64; 3], u32>,
    positions: Vec<[f64; 3]>,
    tris: Vec<[u32; 3]>,
}

impl Grid {
    fn new(n: usize) -> Self {
        Self {
            n,
            index: std::collections::HashMap::new(),
            positions: Vec::new(),
            tris: Vec::new(),
        }
    }

    /// The rectangle `o + s·u + t·v`, `s, t ∈ [0, 1]` (`|u|`, `|v|` whole units), faces
    /// wound so that `u × v` is outward.
    fn patch(&mut self, o: [f64; 3], u: [f64; 3], v: [f64; 3]) {
        let k = self.n as f64;
        let cells = |w: [f64; 3]| (dot(w, w).sqrt() * k).round() as usize;
        let (nu, nv) = (cells(u), cells(v));
        let mut vertex = |i: usize, j: usize| {
            let p: [f64; 3] = std::array::from_fn(|c| {
                o[c] + u[c] * i as f64 / nu as f64 + v[c] * j as f64 / nv as f64
            });
            let key = p.map(|x| (x * k).round() as i64);
            *self.index.entry(key).or_insert_with(|| {
                self.positions.push(p);
                (self.positions.len() - 1) as u32
            })
        };
        let mut tris = Vec::with_capacity(2 * nu * nv);
        for i in 0..nu {
            for j in 0..nv {
                let (a, b) = (vertex(i, j), vertex(i + 1, j));
                let (c, d) = (vertex(i + 1, j + 1), vertex(i, j + 1));
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            }
        }
        self.tris.extend(tris);
    }

    fn mesh(self) -> PolyMesh {
        PolyMesh::new(self.positions, Polygons::from_triangles(&self.tris))
    }
}

/// A closed prism over the unit square `[0, 1]²`, height 1, whose four long edges are rounded
/// with radius `r` by quarter arcs of two segments each (a filleted CAD part: each fillet is two
/// rows of triangles, 2·r·sin 45° = r·√2 wide across the edge), the sides gridded in `nz` rows
/// and 16 columns per straight side, the flat caps fanned from their centres (sharp rims).
///
/// # Panics
/// If `nz` is 0 or `r` is not in `(0, 0.5)`.
pub fn rounded_prism(r: f64, nz: usize) -> PolyMesh {
    assert!(
        nz > 0 && r > 0.0 && r < 0.5,
        "rounded_prism: nz > 0, 0 < r < 0.5"
    );
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
    let centres = [[1.0 - r, 1.0 - r], [r, 1.0 - r], [r, r], [1.0 - r, r]];
    let mut profile: Vec<[f64; 2]> = Vec::new();
    for (c, centre) in centres.iter().enumerate() {
        let a0 = c as f64 * FRAC_PI_2;
        for k in 0..3 {
            let a = a0 + k as f64 * FRAC_PI_4;
            profile.push([centre[0] + r * a.cos(), centre[1] + r * a.sin()]);
        }
        let end = profile[profile.len() - 1];
        let next = centres[(c + 1) % 4];
        let a1 = a0 + FRAC_PI_2;
        let start = [next[0] + r * a1.cos(), next[1] + r * a1.sin()];
        for k in 1..16 {
            let t = k as f64 / 16.0;
            profile.push([
                end[0] + t * (start[0] - end[0]),
                end[1] + t * (start[1] - end[1]),
            ]);
        }
    }
    let m = profile.len();
    let mut pos = Vec::with_capacity((nz + 1) * m + 2);
    for j in 0..=nz {
        let z = j as f64 / nz as f64;
        pos.extend(profile.iter().map(|q| [q[0], q[1], z]));
    }
    let mut tris = Vec::new();
    let id = |j: usize, i: usize| (j * m + i % m) as u32;
    for j in 0..nz {
        for i in 0..m {
            tris.push([id(j, i), id(j, i + 1), id(j + 1, i + 1)]);
            tris.push([id(j, i), id(j + 1, i + 1), id(j + 1, i)]);
        }
    }
    let (bottom, top) = (pos.len() as u32, pos.len() as u32 + 1);
    pos.push([0.5, 0.5, 0.0]);
    pos.push([0.5, 0.5, 1.0]);
    for i in 0..m {
        tris.push([bottom, id(0, i + 1), id(0, i)]);
        tris.push([top, id(nz, i), id(nz, i + 1)]);
    }
    PolyMesh::new(pos, Polygons::from_triangles(&tris))
}

/// A 14-vertex initial control mesh for an ellipsoid with semi-axes `a`, `b`, `c` in the style
/// of Cheng et al. 2007, Examples 1–10: the octahedron [`octahedron_mesh`] with each face split
/// 1-to-3 at its centroid, the centroid pushed out radially onto the ellipsoid (6 + 8 = 14
/// vertices, 24 triangles; valences 8 and 3). `far = false` gives the mesh "near the shape"
/// (Example 1: all vertices on the ellipsoid); `far = true` moves it farther away (Example 2):
/// the vertices are scaled by 2.0, 0.5 and 1.8 along x, y, z and shifted by 0.15·(a, b, c).
pub fn cheng_ellipsoid_cage(a: f64, b: f64, c: f64, far: bool) -> PolyMesh {
    let octa = octahedron_mesh(a, b, c);
    let mut pos = octa.positions.clone();
    let mut faces = Polygons::with_capacity(24, 72);
    for f in octa.faces.iter() {
        let cen: [f64; 3] = std::array::from_fn(|k| {
            (octa.positions[f[0] as usize][k]
                + octa.positions[f[1] as usize][k]
                + octa.positions[f[2] as usize][k])
                / 3.0
        });
        let s = ((cen[0] / a).powi(2) + (cen[1] / b).powi(2) + (cen[2] / c).powi(2)).sqrt();
        let id = pos.len() as u32;
        pos.push([cen[0] / s, cen[1] / s, cen[2] / s]);
        faces.push(&[f[0], f[1], id]);
        faces.push(&[f[1], f[2], id]);
        faces.push(&[f[2], f[0], id]);
    }
    if far {
        for p in &mut pos {
            *p = [
                2.0 * p[0] + 0.15 * a,
                0.5 * p[1] + 0.15 * b,
                1.8 * p[2] + 0.15 * c,
            ];
        }
    }
    PolyMesh::new(pos, faces)
}

#[cfg(test)]
mod cage_tests {
    use super::*;
    use crate::shapes::Shape;

    #[test]
    fn cheng_cage_has_14_vertices_on_the_ellipsoid() {
        let near = cheng_ellipsoid_cage(0.25, 0.5, 1.0, false);
        assert_eq!(near.positions.len(), 14);
        assert_eq!(near.faces.len(), 24);
        let s = Shape::PAPER_ELLIPSOID;
        assert!(near.positions.iter().all(|&p| s.implicit(p).abs() < 1e-12));
        let far = cheng_ellipsoid_cage(0.25, 0.5, 1.0, true);
        assert!(far.positions.iter().all(|&p| s.implicit(p).abs() > 0.05));
    }
}
