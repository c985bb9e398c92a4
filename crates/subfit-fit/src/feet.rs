//! Where the fitter takes its foot points from (Cheng 2007 §II-D3; DESIGN.md §3.2 item 2).
//!
//! A point cloud has only its local quadrics: the foot point of a sample is its projection on
//! the quadric of the nearest data point ([`Target::foot_points`]). A mesh target also has its
//! triangles, and then the exact closest point on them is a better foot point: on a sparse or
//! decimated mesh (a few thousand vertices) a quadric fitted to a handful of neighbours is
//! off by more than the fitting tolerance, and a fit that follows it ends farther from the
//! mesh than a plain QEM simplification. The normal there is the barycentric blend of the
//! vertex normals; the principal curvatures and directions (needed by SDM's `[α]₊` terms) are
//! those of the quadric at the nearest corner, turned into the tangent plane of that normal.

use rayon::prelude::*;
use subfit_target::{alpha_plus, FootPoint, Target};

/// The source of foot points.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FootPointSource {
    /// The exact closest point on the target's triangles when it has them, else the quadrics.
    #[default]
    Auto,
    /// Always the local quadrics of the data points.
    Quadric,
}

/// Foot points of `xs` (normalized coordinates) from `source`.
pub fn foot_points(target: &Target, source: FootPointSource, xs: &[[f64; 3]]) -> Vec<FootPoint> {
    match source {
        FootPointSource::Auto if target.mesh().is_some() => {
            xs.par_iter().map(|&x| mesh_foot_point(target, x)).collect()
        }
        _ => target.foot_points(xs),
    }
}

/// Squared distances `|x − V(x)|²` of `xs` to their foot points from `source`, in parallel.
pub fn squared_errors(target: &Target, source: FootPointSource, xs: &[[f64; 3]]) -> Vec<f64> {
    let feet = foot_points(target, source, xs);
    xs.par_iter()
        .zip(feet.par_iter())
        .map(|(s, f)| (0..3).map(|a| (s[a] - f.point[a]).powi(2)).sum())
        .collect()
}

/// [`foot_points`] warm-started for samples that moved little since the last call: `hints`
/// holds, per sample, the nearest data point found last time (resized to `xs.len()` with
/// "no hint"; updated). Same results as [`foot_points`] (the quadric path certifies every
/// warm-started nearest point or falls back to the kd-tree; see
/// [`Target::foot_points_hinted`]); the triangle path needs no hints.
pub fn foot_points_hinted(
    target: &Target,
    source: FootPointSource,
    xs: &[[f64; 3]],
    hints: &mut Vec<u32>,
) -> Vec<FootPoint> {
    match source {
        FootPointSource::Auto if target.mesh().is_some() => foot_points(target, source, xs),
        _ => {
            hints.resize(xs.len(), u32::MAX);
            target.foot_points_hinted(xs, hints)
        }
    }
}

/// The foot point of `x` on the target's triangles (falls back to the quadric foot point when
/// the target has no triangles or the closest triangle is degenerate).
pub fn mesh_foot_point(target: &Target, x: [f64; 3]) -> FootPoint {
    let Some(c) = target.mesh().and_then(|bvh| bvh.closest(x)) else {
        return target.foot_point(x);
    };
    let Some(bvh) = target.mesh() else {
        return target.foot_point(x);
    };
    let tri = bvh.triangles()[c.triangle as usize];
    let normals = target.normals();
    let mut n = [0.0; 3];
    for (&v, &b) in tri.iter().zip(&c.barycentric) {
        for (k, nk) in n.iter_mut().enumerate() {
            *nk += b * normals[v as usize][k];
        }
    }
    let len = dot(n, n).sqrt();
    let n = if len > 1e-12 {
        n.map(|a| a / len)
    } else if dot(c.face_normal, c.face_normal) > 0.5 {
        c.face_normal
    } else {
        return target.foot_point(x);
    };
    // The corner with the largest barycentric weight lends its curvature frame.
    let k = (0..3)
        .max_by(|&i, &j| c.barycentric[i].total_cmp(&c.barycentric[j]))
        .unwrap_or(0);
    let corner = tri[k];
    let f = target.quadrics()[corner as usize].frame_at(0.0, 0.0);
    // Curvature signs are relative to the frame's normal: flip them if it faces the other way.
    let s = if dot(f.normal, n) < 0.0 { -1.0 } else { 1.0 };
    let (k1, k2) = (s * f.k1, s * f.k2);
    // t1 projected into the tangent plane of n, t2 = n × t1.
    let t1p = sub(f.t1, scale(n, dot(f.t1, n)));
    let l1 = dot(t1p, t1p).sqrt();
    let t1 = if l1 > 1e-9 {
        t1p.map(|a| a / l1)
    } else {
        any_perpendicular(n)
    };
    let t2 = cross(n, t1);
    let distance = dot(sub(x, c.point), n);
    FootPoint {
        point: c.point,
        distance,
        normal: n,
        t1,
        t2,
        k1,
        k2,
        rho1: 1.0 / k1,
        rho2: 1.0 / k2,
        alpha1: alpha_plus(distance, k1),
        alpha2: alpha_plus(distance, k2),
        nearest: corner,
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    a.map(|x| x * s)
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn any_perpendicular(n: [f64; 3]) -> [f64; 3] {
    let a = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let p = sub(a, scale(n, dot(a, n)));
    let l = dot(p, p).sqrt();
    p.map(|x| x / l)
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfit_mesh::shapes::torus_mesh;
    use subfit_target::TargetOptions;

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
            let f = mesh_foot_point(&target, x);
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
        // A point cloud has no triangles: the quadric foot points are used.
        let cloud = subfit_mesh::PolyMesh::point_cloud(mesh.positions.clone(), None);
        let t2 = Target::from_mesh(&cloud, &TargetOptions::default()).unwrap();
        let xs = [t2.to_normalized([0.5, 0.0, 0.0])];
        assert_eq!(
            foot_points(&t2, FootPointSource::Auto, &xs)[0].point,
            t2.foot_points(&xs)[0].point
        );
    }
}
