//! `Target::mesh_foot_point`: the foot point on a mesh target's triangles (the exact closest
//! point, with the blended vertex normal and the curvature frame of the nearest corner).

use subfit_mesh::shapes::torus_mesh;
use subfit_mesh::{PolyMesh, Polygons};
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

/// Inside a thin tube, a point whose surface faces inwards (a wall that has sunk past the
/// middle) gets its foot point on the wall that faces the same way, not on the closer opposite
/// wall; points whose closest wall faces their way keep the plain closest point. The
/// orientation is taken by majority: with every normal reversed the answers are the same.
#[test]
fn facing_foot_points_take_the_wall_on_the_points_side() {
    let (big, small) = (0.35, 0.03);
    let mesh = torus_mesh(big, small, 256, 48, true);
    let target = Target::from_mesh(&mesh, &TargetOptions::default()).unwrap();
    let (mut xs, mut normals, mut sunk) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..120 {
        let t = i as f64 * std::f64::consts::TAU / 120.0;
        let radial = [t.cos(), t.sin(), 0.0];
        if i % 6 == 0 {
            // 0.3 of the tube radius outwards of the core line, facing the torus's centre:
            // the inner wall (0.039 away), not the outer one (0.021 away).
            xs.push(target.to_normalized(radial.map(|c| c * (big + 0.3 * small))));
            normals.push(radial.map(|c| -c));
            sunk.push(true);
        } else {
            // Just outside the outer wall, facing out.
            xs.push(target.to_normalized(radial.map(|c| c * (big + 1.2 * small))));
            normals.push(radial);
            sunk.push(false);
        }
    }
    let mut hints = vec![u32::MAX; xs.len()];
    let (feet, swapped) = target.mesh_foot_points_facing(&xs, &normals, &mut hints);
    assert_eq!(swapped, sunk.iter().filter(|&&s| s).count());
    for ((f, &x), &s) in feet.iter().zip(&xs).zip(&sunk) {
        let plain = target.mesh_foot_point(x);
        let p = target.to_original(f.point);
        let radius = p[0].hypot(p[1]);
        if s {
            // On the inner half of the tube, facing inwards (within 60°), farther than the
            // closest point (on the outer wall, 0.7 tube radii away).
            assert!(radius < big - 0.4 * small, "{radius}");
            assert!(-(f.normal[0] * p[0] + f.normal[1] * p[1]) / radius > 0.45);
            let d = target.to_original(x);
            let gap = dot(sub(d, p), sub(d, p)).sqrt();
            assert!(gap > 1.1 * small && gap < 1.31 * small, "{gap}");
        } else {
            assert_eq!(*f, plain);
        }
    }
    // The same torus with every triangle turned over: the same answers.
    let turned: Vec<[u32; 3]> = mesh.faces.iter().map(|f| [f[0], f[2], f[1]]).collect();
    let inward = PolyMesh::new(mesh.positions.clone(), Polygons::from_triangles(&turned));
    let target = Target::from_mesh(&inward, &TargetOptions::default()).unwrap();
    let mut hints = vec![u32::MAX; xs.len()];
    let (again, swapped_again) = target.mesh_foot_points_facing(&xs, &normals, &mut hints);
    assert_eq!(swapped_again, swapped);
    for (a, f) in again.iter().zip(&feet) {
        assert!(dot(sub(a.point, f.point), sub(a.point, f.point)) < 1e-20);
    }
}

/// Beyond the reach (three times the closest distance) a facing wall is not taken: a point
/// just inside the outer wall of a thick tube, facing inwards, keeps its closest point; and a
/// point outside the target (in front of its closest wall) is never moved.
#[test]
fn a_facing_wall_beyond_the_reach_or_in_front_is_not_taken() {
    let mesh = torus_mesh(0.35, 0.15, 64, 32, true);
    let target = Target::from_mesh(&mesh, &TargetOptions::default()).unwrap();
    // Many points facing out (to fix the orientation), then two facing in: one 0.01 inside
    // the outer wall (the inner wall, facing its way, is 0.29 away, beyond 3 × 0.01), one
    // 0.01 outside it.
    let mut xs: Vec<[f64; 3]> = (0..20)
        .map(|i| target.to_normalized([0.51 + 0.001 * i as f64, 0.0, 0.0]))
        .collect();
    let mut normals = vec![[1.0, 0.0, 0.0]; xs.len()];
    for r in [0.49, 0.51] {
        xs.push(target.to_normalized([r, 0.0, 0.0]));
        normals.push([-1.0, 0.0, 0.0]);
    }
    let mut hints = vec![u32::MAX; xs.len()];
    let (feet, swapped) = target.mesh_foot_points_facing(&xs, &normals, &mut hints);
    assert_eq!(swapped, 0);
    for k in [20, 21] {
        assert_eq!(feet[k], target.mesh_foot_point(xs[k]));
    }
}

/// A closed mesh encloses its inside; a box without its lid does not, and there no foot point
/// is swapped (a sheet has no inside).
#[test]
fn closed_components_are_told_from_open_ones() {
    use subfit_mesh::shapes::gridded_box;
    let closed = Target::from_mesh(&gridded_box(8, false), &TargetOptions::default()).unwrap();
    assert_eq!(closed.closed_components(), &[true]);
    let open = Target::from_mesh(&gridded_box(8, true), &TargetOptions::default()).unwrap();
    assert_eq!(open.closed_components(), &[false]);
    assert_eq!(open.triangle_components().len(), open.mesh().unwrap().len());
    // Inside, 0.4 above the floor, facing up: the floor faces the other way, and the lid
    // (0.6 away, within the reach) faces up. The closed box swaps; the open one has no lid,
    // and keeps the floor as a sheet has no inside.
    // Points under the floor facing down fix the orientation.
    for (target, expect) in [(&closed, 1), (&open, 0)] {
        let mut xs: Vec<[f64; 3]> = (0..20)
            .map(|i| target.to_normalized([0.1 + 0.04 * i as f64, 0.5, -0.01]))
            .collect();
        let mut normals = vec![[0.0, 0.0, -1.0]; xs.len()];
        xs.push(target.to_normalized([0.5, 0.5, 0.4]));
        normals.push([0.0, 0.0, 1.0]);
        let mut hints = vec![u32::MAX; xs.len()];
        let (_, swapped) = target.mesh_foot_points_facing(&xs, &normals, &mut hints);
        assert_eq!(swapped, expect);
    }
}
