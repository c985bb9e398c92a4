//! `Target::mesh_foot_point`: the foot point on a mesh target's triangles (the exact closest
//! point, with the blended vertex normal and the curvature frame of the nearest corner).

use subfit_mesh::shapes::torus_mesh;
use subfit_mesh::PolyMesh;
use subfit_target::{Target, TargetOptions};

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[test]
fn mesh_foot_points_lie_on_the_triangles_with_signed_distance_along_the_normal() {
    let mesh = torus_mesh(0.35, 0.15, 64, 32, true);
    let target = Target::from_mesh(&mesh, &TargetOptions::default()).unwrap();
    assert!(target.mesh().is_some());
    let bvh = target.mesh().unwrap();
    for i in 0..200 {
        let t = i as f64 * 0.1;
        let x = target.to_normalized([
            (0.35 + 0.2 * t.cos()) * (0.7 * t).cos(),
            (0.35 + 0.2 * t.cos()) * (0.7 * t).sin(),
            0.2 * t.sin(),
        ]);
        let f = target.mesh_foot_point(x);
        let c = bvh.closest(x).unwrap();
        // The exact closest point on the triangles.
        assert!(dot(sub(f.point, c.point), sub(f.point, c.point)) < 1e-24);
        // Unit normal, orthonormal frame, |d| at most the distance.
        assert!((dot(f.normal, f.normal) - 1.0).abs() < 1e-9);
        assert!(dot(f.t1, f.normal).abs() < 1e-9 && dot(f.t2, f.normal).abs() < 1e-9);
        assert!(f.distance.abs() <= c.distance + 1e-12);
        // Outside the torus tube the signed distance is positive (outward normals).
        let p = target.to_original(x);
        let r = ((p[0].hypot(p[1]) - 0.35).powi(2) + p[2].powi(2)).sqrt();
        if r > 0.16 {
            assert!(f.distance > 0.0, "{r} {}", f.distance);
        } else if r < 0.14 {
            assert!(f.distance < 0.0, "{r} {}", f.distance);
        }
    }
}

/// A point cloud has no triangles: the quadric foot point is returned.
#[test]
fn a_point_cloud_falls_back_to_the_quadric_foot_point() {
    let mesh = torus_mesh(0.35, 0.15, 64, 32, true);
    let cloud = PolyMesh::point_cloud(mesh.positions.clone(), None);
    let t = Target::from_mesh(&cloud, &TargetOptions::default()).unwrap();
    assert!(t.mesh().is_none());
    let x = t.to_normalized([0.5, 0.0, 0.0]);
    assert_eq!(t.mesh_foot_point(x), t.foot_point(x));
}
