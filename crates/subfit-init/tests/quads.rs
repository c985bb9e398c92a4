//! Pairing triangles into quads (Lavoué et al. 2007 §4.3): the topology, the boundaries, the
//! tagged creases and the winding are kept; a triangulated quad grid is recovered exactly; on a
//! cylinder the quads follow the principal directions; the real initial cages become
//! quad-dominant.

mod common;

use std::collections::HashSet;

use common::topology;
use subfit_init::{initial_control_mesh, pair_triangles, InitOptions, PairOptions};
use subfit_mesh::shapes::{torus_mesh, Shape};
use subfit_mesh::{diagnose_mesh, HalfEdgeMesh, PolyMesh, Polygons, Tags};
use subfit_target::{Target, TargetOptions};

/// Directed edges of every face.
fn directed_edges(m: &PolyMesh) -> Vec<(u32, u32)> {
    m.faces
        .iter()
        .flat_map(|f| (0..f.len()).map(move |k| (f[k], f[(k + 1) % f.len()])))
        .collect()
}

fn undirected(e: (u32, u32)) -> (u32, u32) {
    (e.0.min(e.1), e.0.max(e.1))
}

/// Everything pairing must keep: vertices, Euler characteristic, genus, boundary loops,
/// manifoldness, the winding (each directed edge of the result is one of the input's, used
/// once; interior edges once each way), boundary and tagged edges.
#[track_caller]
fn check_invariants(before: &PolyMesh, after: &PolyMesh, tags: &Tags) {
    assert_eq!(before.positions, after.positions);
    let (hb, ha) = (
        HalfEdgeMesh::from_mesh(before).unwrap(),
        HalfEdgeMesh::from_mesh(after).expect("the result is an oriented manifold"),
    );
    assert_eq!(hb.euler_characteristic(), ha.euler_characteristic());
    assert_eq!(topology(before), topology(after));
    let d = diagnose_mesh(after);
    assert!(d.is_manifold && d.is_consistently_oriented, "{d:?}");
    let old: HashSet<(u32, u32)> = directed_edges(before).into_iter().collect();
    let new = directed_edges(after);
    let new_set: HashSet<(u32, u32)> = new.iter().copied().collect();
    assert_eq!(new.len(), new_set.len(), "a directed edge is used twice");
    for &(a, b) in &new {
        assert!(
            old.contains(&(a, b)),
            "edge {a}→{b} is not in the input's winding"
        );
    }
    let new_und: HashSet<(u32, u32)> = new.iter().map(|&e| undirected(e)).collect();
    for &(a, b) in &old {
        let boundary = !old.contains(&(b, a));
        if boundary {
            assert!(new_set.contains(&(a, b)), "boundary edge {a}→{b} removed");
        } else {
            assert!(
                new_set.contains(&(a, b)) == new_set.contains(&(b, a)),
                "interior edge {a}–{b} used in one direction only"
            );
        }
        if tags.crease(a, b) > 0.0 {
            assert!(
                new_und.contains(&undirected((a, b))),
                "crease {a}–{b} removed"
            );
        }
    }
    // No interior vertex of valence 2 was created.
    for v in 0..ha.num_vertices() {
        let v = subfit_mesh::VertexId::from_usize(v);
        if !ha.is_boundary_vertex(v) && hb.valence(v) >= 3 {
            assert!(ha.valence(v) >= 3, "vertex {v} left with valence 2");
        }
    }
}

fn quad_fraction(m: &PolyMesh) -> f64 {
    m.faces.iter().filter(|f| f.len() == 4).count() as f64 / m.faces.len() as f64
}

/// A triangulated `nx × ny` grid of unit squares mapped by `at(i, j)`; the cells in `hole`
/// (`i0..i1, j0..j1`) are left out; the diagonal of cell `(i, j)` goes from `(i, j)` to
/// `(i+1, j+1)` unless `flip(i, j)`.
fn grid(
    nx: usize,
    ny: usize,
    hole: Option<(usize, usize, usize, usize)>,
    flip: impl Fn(usize, usize) -> bool,
    at: impl Fn(usize, usize) -> [f64; 3],
) -> PolyMesh {
    let id = |i: usize, j: usize| (i + (nx + 1) * j) as u32;
    let mut pos = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            pos.push(at(i, j));
        }
    }
    let mut tris = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            if hole.is_some_and(|(i0, i1, j0, j1)| (i0..i1).contains(&i) && (j0..j1).contains(&j)) {
                continue;
            }
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if flip(i, j) {
                tris.push([a, b, d]);
                tris.push([b, c, d]);
            } else {
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            }
        }
    }
    PolyMesh::new(pos, Polygons::from_triangles(&tris))
}

/// A latitude-longitude sphere of radius 1: two poles, `rings` rings of `seg` vertices.
fn uv_sphere(rings: usize, seg: usize) -> PolyMesh {
    let mut pos = vec![[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    for r in 0..rings {
        let th = std::f64::consts::PI * (r + 1) as f64 / (rings + 1) as f64;
        for s in 0..seg {
            let ph = std::f64::consts::TAU * s as f64 / seg as f64;
            pos.push([th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()]);
        }
    }
    let id = |r: usize, s: usize| (2 + r * seg + s % seg) as u32;
    let mut tris = Vec::new();
    for s in 0..seg {
        tris.push([0, id(0, s), id(0, s + 1)]);
        tris.push([1, id(rings - 1, s + 1), id(rings - 1, s)]);
        for r in 0..rings - 1 {
            tris.push([id(r, s), id(r + 1, s), id(r + 1, s + 1)]);
            tris.push([id(r, s), id(r + 1, s + 1), id(r, s + 1)]);
        }
    }
    PolyMesh::new(pos, Polygons::from_triangles(&tris))
}

/// A seeded pseudo-random bit per cell.
fn hash_bit(i: usize, j: usize) -> bool {
    let mut x = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (j as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    x ^= x >> 29;
    x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    (x >> 32) & 1 == 1
}

#[test]
fn sphere_torus_and_holed_grid_keep_topology_and_winding() {
    let holed = grid(12, 10, Some((4, 8, 3, 7)), hash_bit, |i, j| {
        [i as f64, j as f64, 0.02 * (i * j) as f64]
    });
    assert_eq!(topology(&holed), (0, 2, 1));
    let cases = [
        ("sphere", uv_sphere(9, 16)),
        ("torus", torus_mesh(1.0, 0.35, 24, 12, true)),
        ("holed grid", holed),
    ];
    for (name, m) in cases {
        let (q, rep) = pair_triangles(&m, &Tags::new(), None, &PairOptions::default()).unwrap();
        check_invariants(&m, &q, &Tags::new());
        assert_eq!(rep.quads + rep.triangles, q.faces.len());
        assert!((rep.quad_fraction() - quad_fraction(&q)).abs() < 1e-12);
        assert!(rep.quad_fraction() >= 0.85, "{name}: {rep:?}");
        // Deterministic.
        let (q2, _) = pair_triangles(&m, &Tags::new(), None, &PairOptions::default()).unwrap();
        assert_eq!(q.faces, q2.faces, "{name}");
    }
}

#[test]
fn tagged_creases_and_boundaries_are_never_removed() {
    let m = torus_mesh(1.0, 0.35, 16, 8, true);
    // Tag a ring around the tube and every third diagonal (the edges pairing would remove).
    let nv = 8u32;
    let mut tags = Tags::new();
    for j in 0..nv {
        tags.set_crease(j, (j + 1) % nv, subfit_mesh::SHARPNESS_INFINITE);
    }
    for (_, f) in m.faces.iter().enumerate().filter(|(k, _)| k % 6 == 0) {
        tags.set_crease(f[0], f[2], 1.0);
    }
    let (q, rep) = pair_triangles(&m, &tags, None, &PairOptions::default()).unwrap();
    check_invariants(&m, &q, &tags);
    // Tagged edges are not even candidates (all 384 edges of the torus are between triangles).
    assert!(rep.quads > 0, "{rep:?}");
    assert_eq!(rep.candidates, 384 - tags.creases().len(), "{rep:?}");

    let open = grid(
        6,
        5,
        Some((2, 4, 2, 3)),
        |_, _| false,
        |i, j| [i as f64, j as f64, 0.0],
    );
    let (q, _) = pair_triangles(&open, &tags, None, &PairOptions::default()).unwrap();
    check_invariants(&open, &q, &Tags::new());
}

/// Points on the plane `z = 0` over `[-0.5, n + 0.5]²`, a flat target.
fn flat_target(n: usize) -> Target {
    let k = 6 * n;
    let pts: Vec<[f64; 3]> = (0..=k)
        .flat_map(|j| (0..=k).map(move |i| (i, j)))
        .map(|(i, j)| {
            let s = (n as f64 + 1.0) / k as f64;
            [i as f64 * s - 0.5, j as f64 * s - 0.5, 0.0]
        })
        .collect();
    Target::from_points(&pts, None, &TargetOptions::default()).unwrap()
}

#[test]
fn triangulated_quad_grid_on_a_flat_target_pairs_back_into_its_squares() {
    let n = 10;
    let target = flat_target(n);
    for flip in [
        Box::new(|_, _| false) as Box<dyn Fn(usize, usize) -> bool>,
        Box::new(hash_bit),
    ] {
        let m = grid(n, n, None, &flip, |i, j| {
            target.to_normalized([i as f64, j as f64, 0.0])
        });
        let (q, rep) =
            pair_triangles(&m, &Tags::new(), Some(&target), &PairOptions::default()).unwrap();
        check_invariants(&m, &q, &Tags::new());
        assert_eq!(rep.triangles, 0, "{rep:?}");
        assert_eq!(rep.quads, n * n);
        // Every quad is a grid square: no grid edge was removed.
        let id = |i: usize, j: usize| (i + (n + 1) * j) as u32;
        let mut squares: HashSet<Vec<u32>> = HashSet::new();
        for j in 0..n {
            for i in 0..n {
                let mut s = vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
                s.sort_unstable();
                squares.insert(s);
            }
        }
        for f in q.faces.iter() {
            let mut s = f.to_vec();
            s.sort_unstable();
            assert!(squares.contains(&s), "{f:?} is not a grid square");
        }
        // Isotropic (flat) target: neutral coherency.
        assert!((rep.mean_coherency_deg - 45.0).abs() < 1e-9, "{rep:?}");
    }
}

/// A cylinder target of radius 1 around the z axis, `z ∈ [-1, h + 1]`, with radial normals.
fn cylinder_target(h: f64) -> Target {
    let (nu, nz) = (160, (40.0 * (h + 2.0)) as usize);
    let mut pts = Vec::new();
    let mut nrm = Vec::new();
    for k in 0..=nz {
        for i in 0..nu {
            let t = std::f64::consts::TAU * (i as f64 + 0.5 * (k % 2) as f64) / nu as f64;
            pts.push([t.cos(), t.sin(), -1.0 + (h + 2.0) * k as f64 / nz as f64]);
            nrm.push([t.cos(), t.sin(), 0.0]);
        }
    }
    Target::from_points(&pts, Some(&nrm), &TargetOptions::default()).unwrap()
}

/// Mean angle (degrees) between the edges of the quads and the nearer of the axis and the
/// circumference at the edge's midpoint (original coordinates of `target`).
fn mean_quad_edge_angle(m: &PolyMesh, target: &Target) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for f in m.faces.iter().filter(|f| f.len() == 4) {
        for k in 0..4 {
            let p = target.to_original(m.positions[f[k] as usize]);
            let q = target.to_original(m.positions[f[(k + 1) % 4] as usize]);
            let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let mid = [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
            let r = (mid[0] * mid[0] + mid[1] * mid[1]).sqrt();
            let circ = [-mid[1] / r, mid[0] / r];
            let axis = (d[2].abs() / l).min(1.0).acos();
            let around = ((d[0] * circ[0] + d[1] * circ[1]).abs() / l)
                .min(1.0)
                .acos();
            sum += axis.min(around).to_degrees();
            n += 1;
        }
    }
    sum / n as f64
}

#[test]
fn quads_on_a_cylinder_follow_the_axis_and_the_circumference() {
    let (seg, rings) = (24usize, 8usize);
    let step = std::f64::consts::TAU / seg as f64;
    let target = cylinder_target(rings as f64 * step);
    // (a) A grid of near-squares cut by diagonals: the squares come back, aligned.
    let m = grid(seg, rings, None, hash_bit, |i, j| {
        let t = step * i as f64;
        target.to_normalized([t.cos(), t.sin(), step * j as f64])
    });
    // Close the grid around the axis: vertex (seg, j) is vertex (0, j).
    let m = close_around(m, seg, rings);
    let (q, rep) =
        pair_triangles(&m, &Tags::new(), Some(&target), &PairOptions::default()).unwrap();
    check_invariants(&m, &q, &Tags::new());
    assert_eq!(rep.triangles, 0, "{rep:?}");
    let angle = mean_quad_edge_angle(&q, &target);
    assert!(angle < 2.0, "mean angle {angle}°");
    assert!(rep.mean_coherency_deg < 5.0, "{rep:?}");

    // (b) An equilateral lattice with rows along the circumference: every pairing gives a
    // 60°/120° rhombus; only the curvature directions tell the rhombi with two edges along
    // the circumference (mean angle 15°) from those with four slanted edges (30°), which are
    // flatter and so preferred by shape alone. Compared on the greedy pass (the augmenting
    // paths then pair the rows at the open ends, which here flips whole columns).
    let h = 0.5 * 3f64.sqrt() * step;
    let lattice = lattice_cylinder(seg, rings, h, &target);
    let greedy = PairOptions {
        search_limit: 0,
        ..PairOptions::default()
    };
    let (with, rw) = pair_triangles(&lattice, &Tags::new(), Some(&target), &greedy).unwrap();
    let (without, ro) = pair_triangles(&lattice, &Tags::new(), None, &greedy).unwrap();
    check_invariants(&lattice, &with, &Tags::new());
    let (aw, ao) = (
        mean_quad_edge_angle(&with, &target),
        mean_quad_edge_angle(&without, &target),
    );
    assert!(
        aw < 17.0 && ao > 28.0,
        "with the target {aw}°, without {ao}°; {rw:?} {ro:?}"
    );
    let (full, rf) = pair_triangles(
        &lattice,
        &Tags::new(),
        Some(&target),
        &PairOptions::default(),
    )
    .unwrap();
    check_invariants(&lattice, &full, &Tags::new());
    assert!(rf.quad_fraction() >= 0.95, "{rf:?}");
    assert!(mean_quad_edge_angle(&full, &target) < 17.0, "{rf:?}");
}

/// `grid` output with column `seg` merged into column 0.
fn close_around(m: PolyMesh, seg: usize, rings: usize) -> PolyMesh {
    let old = |i: usize, j: usize| i + (seg + 1) * j;
    let mut map = vec![0u32; m.num_vertices()];
    let mut pos = Vec::new();
    for j in 0..=rings {
        for i in 0..seg {
            map[old(i, j)] = pos.len() as u32;
            pos.push(m.positions[old(i, j)]);
        }
        map[old(seg, j)] = map[old(0, j)];
    }
    let tris: Vec<[u32; 3]> = m
        .faces
        .iter()
        .map(|f| [map[f[0] as usize], map[f[1] as usize], map[f[2] as usize]])
        .collect();
    PolyMesh::new(pos, Polygons::from_triangles(&tris))
}

/// An open cylinder of radius 1 triangulated by an equilateral lattice: `rings + 1` rings of
/// `seg` vertices, ring `j` turned by half a step per ring, `h` apart; normalized into `target`.
fn lattice_cylinder(seg: usize, rings: usize, h: f64, target: &Target) -> PolyMesh {
    let step = std::f64::consts::TAU / seg as f64;
    let mut pos = Vec::new();
    for j in 0..=rings {
        for i in 0..seg {
            let t = step * (i as f64 + 0.5 * j as f64);
            pos.push(target.to_normalized([t.cos(), t.sin(), h * j as f64]));
        }
    }
    let id = |i: usize, j: usize| (i % seg + seg * j) as u32;
    let mut tris = Vec::new();
    for j in 0..rings {
        for i in 0..seg {
            tris.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
            tris.push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    PolyMesh::new(pos, Polygons::from_triangles(&tris))
}

#[test]
fn cages_of_the_real_initialisation_are_quad_dominant() {
    let opts = InitOptions {
        quad_dominant: true,
        ..InitOptions::default()
    };
    // An ellipsoid point cloud (contour + simplification).
    let cloud = Shape::PAPER_ELLIPSOID.sample(6000, 0.0, 7);
    let t = Target::from_points(
        &cloud.positions,
        cloud.normals.as_deref(),
        &TargetOptions::default(),
    )
    .unwrap();
    let (m, rep) = initial_control_mesh(&t, None, 200, &opts).unwrap();
    let p = rep.pairing.clone().expect("paired");
    assert_eq!(topology(&m), (0, 0, 1));
    assert!(rep.genus_matches && rep.closed);
    assert!(p.quad_fraction() >= 0.85, "ellipsoid: {p:?}");
    assert!((p.quad_fraction() - quad_fraction(&m)).abs() < 1e-12);
    let (tri, _) = initial_control_mesh(&t, None, 200, &InitOptions::default()).unwrap();
    assert_eq!(tri.num_vertices(), m.num_vertices());
    assert!(tri.faces.is_triangles());

    // A torus mesh target (simplification).
    let m0 = torus_mesh(1.0, 0.35, 40, 20, true);
    let t = Target::from_mesh(&m0, &TargetOptions::default()).unwrap();
    let (m, rep) = initial_control_mesh(&t, Some(&m0), 150, &opts).unwrap();
    let p = rep.pairing.expect("paired");
    assert_eq!(topology(&m), (1, 0, 1));
    assert!(p.quad_fraction() >= 0.85, "torus: {p:?}");
}

/// The corner (degrees) of face `f` at its vertex `v`.
fn corner_deg(m: &PolyMesh, f: &[u32], v: u32) -> f64 {
    let k = f.iter().position(|&x| x == v).unwrap();
    let p = |i: usize| m.positions[f[i % f.len()] as usize];
    let (a, c, b) = (p(k + f.len() - 1), p(k), p(k + 1));
    let (u, w) = (
        [a[0] - c[0], a[1] - c[1], a[2] - c[2]],
        [b[0] - c[0], b[1] - c[1], b[2] - c[2]],
    );
    let dot = u[0] * w[0] + u[1] * w[1] + u[2] * w[2];
    let l = (u.iter().map(|x| x * x).sum::<f64>() * w.iter().map(|x| x * x).sum::<f64>()).sqrt();
    (dot / l).acos().to_degrees()
}

/// A small hole in a coarse cage: a triangle of radius 1 inside a hexagon of radius 3, the ring
/// between them in twelve triangles, so that each hole vertex has four faces spanning 300°.
/// Pairing the two triangles that fan from a hole vertex would give a quad whose corner there
/// is 158° — within the general 175° limit, but such quads around holes made the limit
/// boundary tangle once refined (a 27-hole armadillo, Hausdorff 1 % of the diagonal under
/// quad/tri). No quad gets a corner above 150° at a hole vertex; the ring still pairs (two quads).
#[test]
fn quads_do_not_wrap_around_a_small_hole() {
    let at = |r: f64, deg: f64| {
        let a = deg.to_radians();
        [r * a.cos(), r * a.sin(), 0.0]
    };
    // Hole vertices 0, 1, 2 at 90°, 210°, 330°; outer vertices 3 + j at 30° + 60° j.
    let mut positions: Vec<[f64; 3]> = [90.0, 210.0, 330.0].iter().map(|&d| at(1.0, d)).collect();
    positions.extend((0..6).map(|j| at(3.0, 30.0 + 60.0 * j as f64)));
    let o = |j: u32| 3 + j % 6;
    let mut faces = Vec::new();
    for i in 0..3u32 {
        // Hole vertex i sits at outer vertex 2i + 1's angle; its fan covers outer 2i..2i+2.
        let (b, next) = (i, (i + 1) % 3);
        faces.push([b, o(2 * i), o(2 * i + 1)]);
        faces.push([b, o(2 * i + 1), o(2 * i + 2)]);
        faces.push([b, o(2 * i + 2), next]);
    }
    let mesh = PolyMesh::new(positions, Polygons::from_triangles(&faces));
    let hole_span: f64 = mesh
        .faces
        .iter()
        .filter(|f| f.contains(&0))
        .map(|f| corner_deg(&mesh, f, 0))
        .sum();
    assert!((hole_span - 300.0).abs() < 1e-9, "{hole_span}");
    let tags = Tags::default();
    let (paired, report) = pair_triangles(&mesh, &tags, None, &PairOptions::default()).unwrap();
    check_invariants(&mesh, &paired, &tags);
    assert!(report.quads >= 2, "{report:?}");
    for f in paired.faces.iter().filter(|f| f.len() == 4) {
        for v in f.iter().filter(|&&v| v < 3) {
            let c = corner_deg(&paired, f, *v);
            assert!(c <= 150.0, "quad {f:?}: {c:.1}° at hole vertex {v}");
        }
    }
}

/// The paired cage's edge rotations (`InitOptions::rotate_edges`): on a torus they leave fewer
/// irregular vertices at the same count and topology.
#[test]
fn rotations_of_the_paired_cage_lower_irregular_vertices() {
    use subfit_init::cross_field::irregular_vertices;
    let with = InitOptions {
        quad_dominant: true,
        ..InitOptions::default()
    };
    let without = InitOptions {
        rotate_edges: false,
        ..with.clone()
    };
    let m0 = torus_mesh(1.0, 0.35, 60, 30, true);
    let t = Target::from_mesh(&m0, &TargetOptions::default()).unwrap();
    let (rotated, _) = initial_control_mesh(&t, Some(&m0), 300, &with).unwrap();
    let (paired, _) = initial_control_mesh(&t, Some(&m0), 300, &without).unwrap();
    assert_eq!(rotated.num_vertices(), paired.num_vertices());
    assert_eq!(topology(&rotated), (1, 0, 1));
    let (r, p) = (irregular_vertices(&rotated), irregular_vertices(&paired));
    assert!(r < p, "irregular vertices: {r} rotated, {p} paired");
}
