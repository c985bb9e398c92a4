//! Corner tags where the target's boundary turns sharply (Lavoué et al. 2005 §4.2, eq. 3: the
//! corner rule at a boundary curve's sharp turns; issue 14).
//!
//! A smooth boundary rule makes the limit boundary a B-spline of the control boundary: it
//! rounds every corner of a cut patch, and no position of the control points lets it reach
//! the data's corner. The corners of the target's boundary loops
//! ([`subfit_target::boundary_corners`]) are therefore matched to the nearest boundary vertex
//! of the automatic cage, which is moved onto the corner and tagged as an infinitely sharp
//! corner (OpenSubdiv semantics): the limit surface then interpolates it, and the tag travels
//! through refinement and into control.usda.

use subfit_mesh::{HalfEdgeMesh, PolyMesh, Tags, SHARPNESS_INFINITE};
use subfit_target::{boundary_corners, Target};

/// Smallest turn of a boundary corner (radians): 40°, the feature angle of
/// [`subfit_target::FeatureOptions`].
const MIN_TURN_DEG: f64 = 40.0;
/// Arc length of the chords a turn is measured with, as a fraction of the bounding-box
/// diagonal: turns of scan teeth below it are not corners.
const CHORD_FRACTION: f64 = 0.02;
/// A target corner farther than this fraction of the diagonal from every cage boundary vertex
/// is left untagged (the cage has no vertex for it).
const MATCH_FRACTION: f64 = 0.05;

/// Tags (and moves onto the target's corner) the cage boundary vertices nearest to the
/// corners of a mesh target's boundary loops; returns how many were tagged. Nothing for point
/// clouds or closed targets. Cost: O(#target triangles log) + O(#corners · #cage boundary
/// vertices).
pub fn tag_boundary_corners(target: &Target, cage: &mut PolyMesh, tags: &mut Tags) -> usize {
    let Some(bvh) = target.mesh() else { return 0 };
    let Some((lo, hi)) = subfit_mesh::bounding_box(target.points()) else {
        return 0;
    };
    let diag = subfit_mesh::vec3::dist2(lo, hi).sqrt();
    let found = boundary_corners(
        bvh.vertices(),
        bvh.triangles(),
        MIN_TURN_DEG.to_radians(),
        CHORD_FRACTION * diag,
    );
    if found.corners.is_empty() {
        return 0;
    }
    let Ok(h) = HalfEdgeMesh::new(&cage.faces, cage.num_vertices()) else {
        return 0;
    };
    let rim: Vec<u32> = h
        .boundary_loops()
        .into_iter()
        .flatten()
        .map(|v| v.0)
        .collect();
    let mut taken = vec![false; cage.num_vertices()];
    let mut count = 0;
    for &c in &found.corners {
        let pc = bvh.vertices()[c as usize];
        let best = rim
            .iter()
            .filter(|&&v| !taken[v as usize])
            .map(|&v| (subfit_mesh::vec3::dist2(cage.positions[v as usize], pc), v))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((d2, v)) = best {
            if d2.sqrt() <= MATCH_FRACTION * diag {
                taken[v as usize] = true;
                cage.positions[v as usize] = pc;
                tags.set_corner(v, SHARPNESS_INFINITE);
                count += 1;
            }
        }
    }
    count
}
