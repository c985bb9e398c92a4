//! QEM simplification keeps topology, orientation and shape.

mod common;

use common::{centroid, data_dir, disk_mesh, ellipsoid_mesh, face_normal, topology};
use subfit_init::{simplify, SimplifyOptions};
use subfit_mesh::shapes::{torus_mesh, XorShift};

fn opts(n: usize) -> SimplifyOptions {
    SimplifyOptions {
        target_vertices: n,
        ..SimplifyOptions::default()
    }
}

#[test]
fn torus_keeps_genus_orientation_and_shape() {
    let (big_r, r) = (1.0, 0.35);
    let m = torus_mesh(big_r, r, 120, 60, true);
    let (out, rep) = simplify(&m, &opts(200)).unwrap();
    assert!(rep.reached_target, "{rep:?}");
    assert_eq!(out.num_vertices(), 200);
    assert_eq!(rep.vertices_before, 7200);
    assert_eq!(topology(&out), (1, 0, 1));
    let dist = |p: [f64; 3]| {
        let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
        ((rho - big_r).powi(2) + p[2] * p[2]).sqrt() - r
    };
    let max_v = out
        .positions
        .iter()
        .map(|&p| dist(p).abs())
        .fold(0.0, f64::max);
    assert!(max_v < 0.1 * r, "vertex off the torus by {max_v}");
    let mut max_c: f64 = 0.0;
    for t in out.faces.iter() {
        let c = centroid(&out, t);
        max_c = max_c.max(dist(c).abs());
        let rho = (c[0] * c[0] + c[1] * c[1]).sqrt();
        let tube = [c[0] - big_r * c[0] / rho, c[1] - big_r * c[1] / rho, c[2]];
        let n = face_normal(&out, t);
        let d = n[0] * tube[0] + n[1] * tube[1] + n[2] * tube[2];
        let ln = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let lt = (tube[0] * tube[0] + tube[1] * tube[1] + tube[2] * tube[2]).sqrt();
        assert!(d > 0.0, "face {t:?} faces inward (cos {})", d / (ln * lt));
    }
    assert!(max_c < 0.15 * r, "centroid off the torus by {max_c}");
    assert!(rep.max_error < 0.05 * r, "{rep:?}");
}

#[test]
fn open_disk_keeps_its_boundary_loop() {
    let m = disk_mesh(40);
    let (out, rep) = simplify(&m, &opts(100)).unwrap();
    assert!(rep.reached_target, "{rep:?}");
    assert_eq!(topology(&out), (0, 1, 1));
    // Boundary vertices stay on the square's sides; every normal points up.
    let he = subfit_mesh::HalfEdgeMesh::from_mesh(&out).unwrap();
    for v in &he.boundary_loops()[0] {
        let p = out.positions[v.idx()];
        let side = (p[0].abs() - 1.0).abs().min((p[1].abs() - 1.0).abs());
        assert!(side < 2e-3, "boundary vertex {p:?} left the boundary");
    }
    for t in out.faces.iter() {
        assert!(face_normal(&out, t)[2] > 0.0);
    }
}

#[test]
fn ellipsoid_keeps_genus_zero() {
    let m = ellipsoid_mesh(0.25, 0.5, 1.0, 5);
    let (out, rep) = simplify(&m, &opts(60)).unwrap();
    assert!(rep.reached_target, "{rep:?}");
    assert_eq!(topology(&out), (0, 0, 1));
    for p in &out.positions {
        let f = (p[0] / 0.25).powi(2) + (p[1] / 0.5).powi(2) + p[2] * p[2];
        assert!((f - 1.0).abs() < 0.1, "{p:?}");
    }
}

#[test]
fn link_condition_rejects_pinching_a_thin_tube() {
    // Three vertices around the tube: collapsing any ring edge would pinch the tube.
    let m = torus_mesh(1.0, 0.1, 40, 3, true);
    let (out, rep) = simplify(&m, &opts(4)).unwrap();
    assert_eq!(topology(&out), (1, 0, 1));
    assert!(!rep.reached_target);
    assert!(rep.rejected_link > 0, "{rep:?}");
    // A triangulated torus needs at least 7 vertices.
    assert!(out.num_vertices() >= 7);
}

#[test]
fn asking_for_more_vertices_than_present_changes_nothing() {
    let m = torus_mesh(1.0, 0.35, 12, 6, true);
    let (out, rep) = simplify(&m, &opts(1000)).unwrap();
    assert_eq!(out.num_vertices(), 72);
    assert_eq!(rep.collapses, 0);
    assert!(rep.reached_target);
}

#[test]
fn point_clouds_and_non_manifold_input_are_errors() {
    let pc = subfit_mesh::PolyMesh::point_cloud(vec![[0.0; 3]; 4], None);
    assert!(matches!(
        simplify(&pc, &opts(3)),
        Err(subfit_init::SimplifyError::NoFaces)
    ));
    let fan = subfit_mesh::PolyMesh::new(
        vec![
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0; 3],
        ],
        subfit_mesh::Polygons::from_triangles(&[[0, 1, 2], [0, 1, 3], [0, 1, 4]]),
    );
    assert!(matches!(
        simplify(&fan, &opts(3)),
        Err(subfit_init::SimplifyError::Topology(_))
    ));
}

#[test]
fn real_meshes_keep_their_genus() {
    let Some(dir) = data_dir() else { return };
    for (file, n, genus) in [("rocker-arm.off", 900, 1), ("fertility.off", 1000, 4)] {
        let (m, _) =
            subfit_io::read_file(&dir.join(file), &subfit_io::ReadOptions::default()).unwrap();
        let (g0, b0, _) = topology(&m);
        assert_eq!((g0, b0), (genus, 0), "{file}");
        let (out, rep) = simplify(&m, &opts(n)).unwrap();
        assert!(rep.reached_target, "{file}: {rep:?}");
        assert_eq!(topology(&out).0, genus, "{file}");
        assert_eq!(topology(&out).1, 0, "{file}");
    }
}

#[test]
fn result_is_invariant_to_scale() {
    let m = torus_mesh(1.0, 0.35, 40, 20, true);
    let (ref_out, ref_rep) = simplify(&m, &opts(150)).unwrap();
    let scaled = |s: f64| {
        let mut ms = m.clone();
        for p in &mut ms.positions {
            *p = p.map(|c| c * s);
        }
        simplify(&ms, &opts(150)).unwrap()
    };
    // Powers of two scale exactly: the same collapses in the same order.
    for s in [2f64.powi(-20), 2f64.powi(20)] {
        let (out, rep) = scaled(s);
        assert_eq!(out.faces, ref_out.faces, "scale {s}");
        for (p, q) in out.positions.iter().zip(&ref_out.positions) {
            assert_eq!(p.map(|c| c / s), *q);
        }
        assert_eq!(rep.max_error / s, ref_rep.max_error);
    }
    // Other factors round differently (and the regular torus has many cost ties), so only the
    // outcome is compared.
    for s in [1e-6, 1e6] {
        let (out, rep) = scaled(s);
        assert_eq!(out.num_vertices(), 150);
        assert_eq!(topology(&out), (1, 0, 1));
        let rel = (rep.max_error / s / ref_rep.max_error - 1.0).abs();
        assert!(rel < 0.5, "scale {s}: {rep:?}");
    }
}

/// Valence-3 vertices (a vertex inserted in each octahedron face) must be removable: a collapse
/// `k → r` with `k` of valence 3 turns the face `(k, c, d)` into `(r, c, d)`, which is legal
/// unless `(r, c, d)` exists too. Rejecting it stalled point-cloud contours (regression).
#[test]
fn valence_three_vertices_are_collapsible() {
    let base = subfit_mesh::shapes::octahedron_mesh(1.0, 1.0, 1.0);
    let mut positions = base.positions.clone();
    let mut tris = Vec::new();
    for t in base.faces.iter() {
        let c = centroid(&base, t);
        let len = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        // Slightly outside the face, so that no collapse is a fold.
        positions.push(c.map(|x| x * 1.1 / (len * 3f64.sqrt())));
        let m = (positions.len() - 1) as u32;
        tris.extend([[t[0], t[1], m], [t[1], t[2], m], [t[2], t[0], m]]);
    }
    let m = subfit_mesh::PolyMesh::new(positions, subfit_mesh::Polygons::from_triangles(&tris));
    assert_eq!(topology(&m), (0, 0, 1));
    for n in [6, 4] {
        let (out, rep) = simplify(&m, &opts(n)).unwrap();
        assert!(rep.reached_target, "target {n}: {rep:?}");
        assert_eq!(out.num_vertices(), n);
        assert_eq!(topology(&out), (0, 0, 1));
    }
}

/// A mesh whose vertex noise is comparable to its edge length (crumpled triangles: a raw
/// scanner mesh) stops the simplification far above its target, every collapse turning some
/// face too far; the simplification then runs on a smoothed copy and reaches the target with
/// the topology kept and the vertices near the surface. A clean mesh does not need the copy.
#[test]
fn a_noisy_mesh_is_simplified_from_a_smoothed_copy() {
    let (big_r, r) = (1.0, 0.35);
    let clean = torus_mesh(big_r, r, 200, 100, true);
    let (_, rep) = simplify(&clean, &opts(200)).unwrap();
    assert!(rep.reached_target && !rep.smoothed, "{rep:?}");

    // Gaussian noise of 0.02 per coordinate; the edges are 0.022–0.031 long.
    let mut noisy = clean.clone();
    let mut rng = XorShift::new(3);
    for p in &mut noisy.positions {
        for c in p.iter_mut() {
            *c += 0.02 * rng.normal();
        }
    }
    let (out, rep) = simplify(&noisy, &opts(200)).unwrap();
    assert!(rep.smoothed && rep.reached_target, "{rep:?}");
    assert_eq!(out.num_vertices(), 200);
    assert_eq!(topology(&out), (1, 0, 1));
    let off = out
        .positions
        .iter()
        .map(|p| {
            let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
            (((rho - big_r).powi(2) + p[2] * p[2]).sqrt() - r).abs()
        })
        .fold(0.0, f64::max);
    assert!(off < 0.1 * r, "vertex off the torus by {off}");
}
