//! Sharp-feature detection on shapes of known features (a gridded cube: 12 crease curves and 8
//! corners; a capped cylinder: 2 circles; an L-shaped prism, fandisk-like with a concave
//! edge: 18 curves, 12 corners), robust to noise and mis-oriented faces, and nothing on smooth
//! shapes (a torus; Igea and, but for a few fair creases, the bunny from `$SUBFIT_DATA`).
#![allow(clippy::print_stdout)]

mod common;

use std::collections::HashMap;

use rand::{Rng, SeedableRng};
use subfit_mesh::shapes::{l_prism, torus_mesh};
use subfit_mesh::{PolyMesh, Polygons};
use subfit_target::{detect_features, FeatureOptions, Features};

/// Builds a triangle mesh from axis-aligned rectangular patches gridded at spacing `h`,
/// merging coincident vertices (all patch sizes are multiples of `h`).
struct Builder {
    h: f64,
    positions: Vec<[f64; 3]>,
    ids: HashMap<[i64; 3], u32>,
    faces: Polygons,
}

impl Builder {
    fn new(h: f64) -> Self {
        Self {
            h,
            positions: Vec::new(),
            ids: HashMap::new(),
            faces: Polygons::new(),
        }
    }

    fn vertex(&mut self, p: [f64; 3]) -> u32 {
        let k = p.map(|x| (x * 1e6).round() as i64);
        let n = self.positions.len() as u32;
        *self.ids.entry(k).or_insert_with(|| {
            self.positions.push(p);
            n
        })
    }

    /// The rectangle `o + s·u + t·v`, `s ∈ [0, |u|]`, `t ∈ [0, |v|]` (u, v axis vectors).
    fn patch(&mut self, o: [f64; 3], u: [f64; 3], v: [f64; 3]) {
        let len = |a: [f64; 3]| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        let (n, m) = (
            (len(u) / self.h).round() as usize,
            (len(v) / self.h).round() as usize,
        );
        let at = |i: usize, j: usize| {
            let (s, t) = (i as f64 / n as f64, j as f64 / m as f64);
            [0, 1, 2].map(|k| o[k] + s * u[k] + t * v[k])
        };
        for i in 0..n {
            for j in 0..m {
                let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]
                    .map(|p| self.vertex(p));
                self.faces.push(&[q[0], q[1], q[2]]);
                self.faces.push(&[q[0], q[2], q[3]]);
            }
        }
    }

    fn mesh(self) -> PolyMesh {
        PolyMesh::new(self.positions, self.faces)
    }
}

/// A cube `[0, 1]³` with every face a `n × n` grid of triangle pairs.
fn grid_cube(n: usize) -> PolyMesh {
    let mut b = Builder::new(1.0 / n as f64);
    let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    b.patch([0.0; 3], y, x);
    b.patch([0.0, 0.0, 1.0], x, y);
    b.patch([0.0; 3], x, z);
    b.patch([0.0, 1.0, 0.0], z, x);
    b.patch([0.0; 3], z, y);
    b.patch([1.0, 0.0, 0.0], y, z);
    b.mesh()
}

/// A closed cylinder (radius 1, height 2) with `n` segments around, `m` along, caps as fans.
fn capped_cylinder(n: usize, m: usize) -> PolyMesh {
    let mut pos = Vec::new();
    for j in 0..=m {
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            pos.push([a.cos(), a.sin(), 2.0 * j as f64 / m as f64]);
        }
    }
    let id = |i: usize, j: usize| (j * n + i % n) as u32;
    let mut faces = Polygons::new();
    for j in 0..m {
        for i in 0..n {
            faces.push(&[id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            faces.push(&[id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let (bottom, top) = (pos.len() as u32, pos.len() as u32 + 1);
    pos.push([0.0, 0.0, 0.0]);
    pos.push([0.0, 0.0, 2.0]);
    for i in 0..n {
        faces.push(&[bottom, id(i + 1, 0), id(i, 0)]);
        faces.push(&[top, id(i, m), id(i + 1, m)]);
    }
    PolyMesh::new(pos, faces)
}

fn detect(m: &PolyMesh) -> Features {
    detect_features(&m.positions, &m.faces, &FeatureOptions::default())
}

/// Every sharp edge is on exactly one curve and every curve ends at corners or darts (or is a
/// loop).
fn assert_consistent(f: &Features, what: &str) {
    let mut on_curves: Vec<[u32; 2]> = f
        .curves
        .iter()
        .flat_map(|c| {
            let mut v = c.vertices.clone();
            if c.closed {
                v.push(v[0]);
            }
            v.windows(2)
                .map(|w| [w[0].min(w[1]), w[0].max(w[1])])
                .collect::<Vec<_>>()
        })
        .collect();
    on_curves.sort_unstable();
    assert_eq!(
        on_curves, f.edges,
        "{what}: curves cover the sharp edges once"
    );
    for c in f.curves.iter().filter(|c| !c.closed) {
        for end in [c.vertices[0], *c.vertices.last().unwrap()] {
            assert!(
                f.corners.binary_search(&end).is_ok() || f.darts.binary_search(&end).is_ok(),
                "{what}: curve end {end} is neither corner nor dart"
            );
        }
    }
}

#[test]
fn cube_has_twelve_crease_curves_and_eight_corners() {
    let m = grid_cube(6);
    let f = detect(&m);
    assert_consistent(&f, "cube");
    assert_eq!(f.curves.len(), 12, "{:?}", f.curves);
    assert_eq!(f.corners.len(), 8);
    assert!(f.darts.is_empty());
    assert_eq!(f.edges.len(), 12 * 6);
}

#[test]
fn cube_features_survive_noise_and_flipped_faces() {
    let mut m = grid_cube(8);
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    // 0.2% of the edge length: dihedral noise of a few degrees on the flat faces.
    for p in &mut m.positions {
        for x in p.iter_mut() {
            *x += rng.random_range(-0.002..0.002);
        }
    }
    let mut faces = Polygons::new();
    for (i, f) in m.faces.iter().enumerate() {
        if i % 5 == 0 {
            faces.push(&[f[0], f[2], f[1]]);
        } else {
            faces.push(f);
        }
    }
    m.faces = faces;
    let f = detect(&m);
    assert_consistent(&f, "noisy cube");
    assert_eq!((f.curves.len(), f.corners.len()), (12, 8));
}

#[test]
fn capped_cylinder_has_two_circles() {
    let f = detect(&capped_cylinder(40, 10));
    assert_consistent(&f, "cylinder");
    assert_eq!(f.curves.len(), 2, "{:?}", f.curves);
    assert!(f.curves.iter().all(|c| c.closed && c.vertices.len() == 40));
    assert!(f.corners.is_empty() && f.darts.is_empty());
}

#[test]
fn l_prism_has_eighteen_curves_and_twelve_corners_with_the_concave_edge() {
    let f = detect(&l_prism(4));
    assert_consistent(&f, "L prism");
    assert_eq!(f.curves.len(), 18, "{:?}", f.curves);
    assert_eq!(f.corners.len(), 12);
    // The concave vertical edge at (1, 1) is found.
    let m = l_prism(4);
    let concave = f.curves.iter().any(|c| {
        c.vertices.iter().all(|&v| {
            let p = m.positions[v as usize];
            (p[0] - 1.0).abs() < 1e-9 && (p[1] - 1.0).abs() < 1e-9
        })
    });
    assert!(concave);
}

#[test]
fn smooth_torus_has_no_features() {
    let f = detect(&torus_mesh(1.0, 0.4, 48, 24, true));
    assert!(f.is_empty(), "{} edges", f.edges.len());
}

/// A UV sphere of 48 × 24 (triangles, fans at the poles) has no sharp feature either, at the
/// poles included, where 48 thin triangles meet.
#[test]
fn smooth_sphere_has_no_features() {
    let (nu, nv) = (48usize, 24usize);
    let mut p = vec![[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    for j in 1..nv {
        let t = std::f64::consts::PI * j as f64 / nv as f64;
        for i in 0..nu {
            let a = std::f64::consts::TAU * i as f64 / nu as f64;
            p.push([t.sin() * a.cos(), t.sin() * a.sin(), t.cos()]);
        }
    }
    let id = |j: usize, i: usize| (2 + (j - 1) * nu + i % nu) as u32;
    let mut f = Polygons::new();
    for i in 0..nu {
        f.push(&[0, id(1, i), id(1, i + 1)]);
        f.push(&[1, id(nv - 1, i + 1), id(nv - 1, i)]);
    }
    for j in 1..nv - 1 {
        for i in 0..nu {
            f.push(&[id(j, i), id(j + 1, i), id(j + 1, i + 1)]);
            f.push(&[id(j, i), id(j + 1, i + 1), id(j, i + 1)]);
        }
    }
    let f = detect(&PolyMesh::new(p, f));
    assert!(f.is_empty(), "{} edges", f.edges.len());
}

#[test]
fn a_short_gap_in_a_crease_is_bridged() {
    // One vertex of a crease pushed inward: the dihedral angles of its two crease edges fall
    // below the threshold (but stay above half of it), and the gap is bridged.
    let mut m = grid_cube(6);
    // Vertex on the crease x = 0, y = 0 at z = 0.5: pull it inward a little.
    let v = m
        .positions
        .iter()
        .position(|p| p[0].abs() < 1e-9 && p[1].abs() < 1e-9 && (p[2] - 0.5).abs() < 1e-9)
        .unwrap();
    m.positions[v] = [0.06, 0.06, 0.5];
    let f = detect(&m);
    assert_consistent(&f, "dented cube");
    assert_eq!((f.curves.len(), f.corners.len()), (12, 8), "{:?}", f.darts);
    // Without bridging the dent cuts its crease (a dart; the shorter piece may go as a spur).
    let o = FeatureOptions {
        bridge_edges: 0,
        ..FeatureOptions::default()
    };
    let unbridged = detect_features(&m.positions, &m.faces, &o);
    assert!(!unbridged.darts.is_empty(), "the dent must cut the crease");
    assert!(f.darts.is_empty());
}

#[test]
fn real_smooth_models_have_no_features_and_fandisk_has_many() {
    let Some(dir) = common::data_dir("the real-data feature test") else {
        return;
    };
    for (name, smooth) in [
        ("igea.ply", true),
        ("stanford-bunny.obj", true),
        ("bunny.off", true),
        ("armadillo.obj", true),
        ("fandisk.obj", false),
    ] {
        let m = subfit_io::read_file(&dir.join(name), &Default::default())
            .unwrap()
            .0;
        let f = detect(&m);
        let edges = subfit_mesh::HalfEdgeMesh::from_mesh(&m)
            .map(|h| h.num_edges())
            .unwrap_or(0);
        println!(
            "{name}: {} sharp edges of {edges} ({} before cleaning), {} curves, {} corners, {} darts",
            f.edges.len(),
            f.raw_edges,
            f.curves.len(),
            f.corners.len(),
            f.darts.len()
        );
        let fraction = f.edges.len() as f64 / edges.max(1) as f64;
        if smooth {
            // The scanned bunny's folds of 40°+ (its base rim, the ear's root) are pieced
            // together by the bridging or short: none survives the cleaning.
            assert!(f.edges.is_empty(), "{name}: {} sharp edges", f.edges.len());
        } else {
            assert!(fraction > 1e-2, "{name}: {} sharp edges", f.edges.len());
            assert!(f.curves.len() >= 20, "{name}: {} curves", f.curves.len());
            assert!(f.corners.len() >= 10, "{name}: {} corners", f.corners.len());
        }
    }
}
