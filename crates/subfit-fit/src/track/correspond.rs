//! The step's model → data correspondences (Li, Adams, Guibas & Pauly 2009, §4): each
//! sample's foot point on the frame, pruned by distance and normal agreement, and the RMS
//! point-to-plane distance over them.

use rayon::prelude::*;
use subfit_mesh::vec3::{dot as dot3, sub};
use subfit_target::Target;

/// The RMS point-to-plane distance of `samples` (unit `normals`) to `target`, over the samples
/// that [`super::track`] would match (foot point within `max_distance`, normals within 60°), and
/// their number: the floor a tracking step cannot go below on a frame the cage already fits
/// (the data's noise and tessellation; see [`super::TrackOptions::stop_rms`]).
///
/// # Panics
/// If `samples` and `normals` differ in length.
#[track_caller]
pub fn plane_rms_to(
    samples: &[[f64; 3]],
    normals: &[[f64; 3]],
    target: &Target,
    max_distance: f64,
) -> (f64, usize) {
    assert_eq!(samples.len(), normals.len(), "one normal per sample");
    let m = matches(samples, normals, target, max_distance);
    (plane_rms(samples, &m), m.len())
}

/// The samples with a usable foot point on `target`: (sample, foot point, target normal).
/// Pruned as in Li et al. §4: foot points farther than `max_distance`, or whose normal is
/// more than 60° from the sample's.
pub(super) fn matches(
    samples: &[[f64; 3]],
    normals: &[[f64; 3]],
    target: &Target,
    max_distance: f64,
) -> Vec<(usize, [f64; 3], [f64; 3])> {
    let feet = foot_points(target, samples);
    (0..samples.len())
        .into_par_iter()
        .filter_map(|i| {
            let f = &feet[i];
            if !f.distance.is_finite() || f.distance.abs() > max_distance {
                return None;
            }
            (dot3(normals[i], f.normal) >= 0.5).then_some((i, f.point, f.normal))
        })
        .collect()
}

/// The foot points of `xs` on `target`: the exact closest points on its triangles when it is
/// a mesh (as the fit's own term takes them, [`crate::FootPointTerm::foot_points`]), its local
/// quadrics otherwise. The quadrics of a mesh are fitted to its vertices alone: on a low-poly
/// frame (a 398-vertex cat) they stray from its faces by about 1 % of the unit cube, which
/// the step then took for the data's noise and stopped at once ([`super::TrackOptions::stop_rms`]).
fn foot_points(target: &Target, xs: &[[f64; 3]]) -> Vec<subfit_target::FootPoint> {
    if target.mesh().is_some() {
        xs.par_iter().map(|&x| target.mesh_foot_point(x)).collect()
    } else {
        target.foot_points(xs)
    }
}

/// RMS of `nᵀ(x − y)` over `matches`.
pub(super) fn plane_rms(samples: &[[f64; 3]], matches: &[(usize, [f64; 3], [f64; 3])]) -> f64 {
    (matches
        .iter()
        .map(|&(i, y, n)| dot3(n, sub(samples[i], y)).powi(2))
        .sum::<f64>()
        / matches.len().max(1) as f64)
        .sqrt()
}
