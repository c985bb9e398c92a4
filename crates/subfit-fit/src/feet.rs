//! Where the fitter takes its foot points from (Cheng 2007 §II-D3; DESIGN.md §3.2 item 2).
//!
//! A point cloud has only its local quadrics: the foot point of a sample is its projection on
//! the quadric of the nearest data point ([`Target::foot_points`]). A mesh target also has its
//! triangles, and then the exact closest point on them is a better foot point
//! ([`Target::mesh_foot_point`]): on a sparse or decimated mesh (a few thousand vertices) a
//! quadric fitted to a handful of neighbours is off by more than the fitting tolerance, and a
//! fit that follows it ends farther from the mesh than a plain QEM simplification.

use rayon::prelude::*;
use subfit_target::{FootPoint, Target};

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
            xs.par_iter().map(|&x| target.mesh_foot_point(x)).collect()
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

#[cfg(test)]
mod tests {
    use super::*;
    use subfit_mesh::shapes::torus_mesh;
    use subfit_target::TargetOptions;

    /// A point cloud has no triangles: `Auto` takes the quadric foot points (the triangle foot
    /// points are tested with `Target::mesh_foot_point` in subfit-target).
    #[test]
    fn a_point_cloud_takes_the_quadric_foot_points() {
        let mesh = torus_mesh(0.35, 0.15, 64, 32, true);
        let cloud = subfit_mesh::PolyMesh::point_cloud(mesh.positions.clone(), None);
        let t2 = Target::from_mesh(&cloud, &TargetOptions::default()).unwrap();
        let xs = [t2.to_normalized([0.5, 0.0, 0.0])];
        assert_eq!(
            foot_points(&t2, FootPointSource::Auto, &xs)[0].point,
            t2.foot_points(&xs)[0].point
        );
    }
}
