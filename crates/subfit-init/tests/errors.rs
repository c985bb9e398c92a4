//! Bad inputs give typed errors naming what is wrong; the topology bound is Heawood's.

use subfit_init::{
    default_control_points, initial_control_mesh, min_vertices_for_topology, InitError, InitOptions,
};
use subfit_mesh::shapes::torus_mesh;
use subfit_mesh::{PolyMesh, Polygons};
use subfit_target::{Target, TargetOptions};

#[test]
fn topology_bound_is_heawoods() {
    // Closed: 4 (tetrahedron), 7 (Möbius-Császár torus), 10 for genus 2..3, 11 for genus 4.
    let closed: Vec<usize> = (0..=4).map(|g| min_vertices_for_topology(g, 0)).collect();
    assert_eq!(closed, [4, 7, 10, 10, 11]);
    assert_eq!(min_vertices_for_topology(0, 1), 3);
    assert_eq!(min_vertices_for_topology(0, 5), 15);
    assert_eq!(min_vertices_for_topology(1, 1), 7);
    assert_eq!(default_control_points(134_345), 550);
    assert_eq!(default_control_points(100), 200);
    assert_eq!(default_control_points(10_000_000), 2000);
}

#[test]
fn too_few_vertices_for_the_genus_is_an_error() {
    let m = torus_mesh(1.0, 0.35, 24, 12, true);
    let t = Target::from_mesh(&m, &TargetOptions::default()).unwrap();
    let err = initial_control_mesh(&t, Some(&m), 6, &InitOptions::default()).unwrap_err();
    assert_eq!(
        err,
        InitError::TooFewForTopology {
            requested: 6,
            minimum: 7,
            genus: 1,
            boundary_loops: 0,
            components: 1
        }
    );
    assert!(err.to_string().contains("genus 1"), "{err}");
    assert!(initial_control_mesh(&t, Some(&m), 7, &InitOptions::default()).is_ok());
}

#[test]
fn non_manifold_mesh_target_names_the_edge() {
    // Three triangles on the edge 0-1 (a fin), plus enough points for a target.
    let mut positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 1.0, 0.0],
        [0.5, -1.0, 0.0],
        [0.5, 0.0, 1.0],
    ];
    for i in 0..10 {
        positions.push([0.1 * i as f64, 0.3, 0.05 * i as f64]);
    }
    let faces = Polygons::from_triangles(&[[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
    let m = PolyMesh::new(positions, faces);
    let t = Target::from_mesh(&m, &TargetOptions::default()).unwrap();
    let err = initial_control_mesh(&t, Some(&m), 4, &InitOptions::default()).unwrap_err();
    match &err {
        InitError::InvalidMesh(e) => assert!(e.to_string().contains("edge 0-1"), "{e}"),
        other => panic!("expected InvalidMesh, got {other:?}"),
    }
}
