//! Semi-sharp creases and corners: the rules that blend a sharp and a smooth mask while a finite
//! sharpness decays by one per level.
//!
//! Sources: DeRose, Kass & Truong 1998 (*Subdivision surfaces in character animation*,
//! SIGGRAPH, §3 "Semi-sharp creases"): an edge of sharpness `s` is subdivided with the sharp
//! rules for `⌊s⌋` levels, then with a blend weighted by the fractional part, then smoothly;
//! OpenSubdiv 3.5 `sdc/crease.{h,cpp}` and `sdc/scheme.h` (`Sdc::Crease` with
//! `CREASE_UNIFORM`, `Scheme::ComputeVertexVertexMask`, `Scheme::ComputeEdgeVertexMask`) for the
//! exact form used here, so that results agree with OpenSubdiv to round-off:
//!
//! * sharpness is single precision, as OpenSubdiv (and USD) store it; a child's sharpness is
//!   `s − 1` (0 once it would drop to 0 or below; infinite, `s ≥ 10`, stays);
//! * an edge point of an edge with `s > 1` uses the crease rule (midpoint), with `0 < s ≤ 1` the
//!   blend `s · crease + (1 − s) · smooth` (face weights scaled by `1 − s`);
//! * a vertex's rule comes from how many incident edges have sharpness `> 0` and whether its
//!   own sharpness is `> 0` (a corner), as [`VertexRule::classify`]; its child's rule from the
//!   decremented sharpnesses. Smooth or dart parents use the smooth mask. When the rules
//!   differ, the vertex point is `w · parent mask + (1 − w) · child mask`, with `w` the mean
//!   of the parent sharpnesses (vertex and edges) that drop to 0 at this level (those in
//!   `(0, 1]`), at most 1 — OpenSubdiv's `ComputeFractionalWeightAtVertex`.
//!
//! Boundary edges count as infinitely sharp. Limit masks apply only where no finite sharpness
//! is left around a vertex (see [`crate::limit`] and [`crate::eval`], which refine until then).

use crate::mask::{EdgeMask, Mask};
use crate::scheme::{classify, BoundaryRule, Neighborhood, Scheme, VertexRule};
use subfit_mesh::SHARPNESS_INFINITE;

/// Infinite sharpness as stored here (OpenSubdiv's `SHARPNESS_INFINITE`); any value at least
/// this large is infinite.
pub const INFINITE: f32 = SHARPNESS_INFINITE as f32;

/// A tag's sharpness as OpenSubdiv stores it: single precision, negative and NaN values as 0.
#[inline]
pub fn sharpness(s: f64) -> f32 {
    if s > 0.0 {
        s as f32
    } else {
        0.0
    }
}

/// Whether a sharpness is finite and positive (semi-sharp).
#[inline]
pub fn is_semi_sharp(s: f32) -> bool {
    s > 0.0 && s < INFINITE
}

/// The sharpness of a child edge or vertex under uniform creasing: `s − 1`, 0 once that is
/// not positive; infinite sharpness stays.
#[inline]
pub fn decrement(s: f32) -> f32 {
    if s >= INFINITE {
        s
    } else if s > 1.0 {
        s - 1.0
    } else {
        0.0
    }
}

/// The weight of the parent mask when a vertex's rule changes between levels: the mean of the
/// sharpnesses in `(0, 1]` among the vertex's own (`vertex`) and its incident edges'
/// (`edges`), summed and divided in single precision as OpenSubdiv does, at most 1; 0 if there
/// is none. Cost O(#edges).
pub fn fractional_weight(vertex: f32, edges: &[f32]) -> f64 {
    let (mut sum, mut count) = (0.0f32, 0u32);
    for &s in std::iter::once(&vertex).chain(edges) {
        if s > 0.0 && s <= 1.0 {
            sum += s;
            count += 1;
        }
    }
    if count == 0 {
        return 0.0;
    }
    f64::from((sum / count as f32).min(1.0))
}

/// Blends a smooth edge-point mask toward the crease rule for an edge of sharpness
/// `0 < s ≤ 1`: ends `s/2 + (1 − s) · end`, faces `(1 − s) · face`. Masks of other sharpness are
/// left alone (callers use the crease rule for `s > 1`).
pub fn blend_edge_mask(mask: &mut EdgeMask, s: f32) {
    if !(s > 0.0 && s <= 1.0) {
        return;
    }
    let p = f64::from(s);
    let c = 1.0 - p;
    mask.end = p * 0.5 + c * mask.end;
    for f in &mut mask.face {
        *f *= c;
    }
}

/// The [`Neighborhood`] of a vertex with sharpness `vertex` and incident edge sharpnesses
/// `edges` (ring order; boundary edges [`INFINITE`]), from `base` (valence, face count and
/// kinds; its rule and crease ends are replaced). Cost O(valence).
pub fn neighborhood(
    base: &Neighborhood,
    vertex: f32,
    edges: &[f32],
    boundary: BoundaryRule,
) -> Neighborhood {
    debug_assert_eq!(edges.len(), base.num_edges);
    classify(
        edges.iter().map(|&s| s > 0.0),
        base.num_faces,
        base.faces,
        vertex > 0.0,
        boundary,
    )
}

impl Scheme {
    /// The vertex-point mask of a vertex with (possibly semi-sharp) sharpness `vertex` and
    /// incident edge sharpnesses `edges` (ring order of [`Neighborhood`], boundary edges
    /// [`INFINITE`]), blending the parent's and the child's rules (module docs). `base` gives
    /// the valence, face count and face kinds; `scratch` is reused for the child mask. With no
    /// finite sharpness this is [`Scheme::vertex_point_mask`] of the classified neighbourhood.
    /// Cost O(valence).
    pub fn semi_sharp_vertex_point_mask(
        self,
        base: &Neighborhood,
        vertex: f32,
        edges: &[f32],
        boundary: BoundaryRule,
        mask: &mut Mask,
        scratch: &mut Mask,
    ) {
        let parent = neighborhood(base, vertex, edges, boundary);
        self.vertex_point_mask(&parent, mask);
        if matches!(parent.rule, VertexRule::Smooth | VertexRule::Dart) {
            return;
        }
        let child_edges: Vec<f32> = edges.iter().map(|&s| decrement(s)).collect();
        let child = neighborhood(base, decrement(vertex), &child_edges, boundary);
        if child.rule == parent.rule {
            return;
        }
        self.vertex_point_mask(&child, scratch);
        let p = fractional_weight(vertex, edges);
        let c = 1.0 - p;
        mask.vertex = p * mask.vertex + c * scratch.vertex;
        for (m, s) in mask.edges.iter_mut().zip(&scratch.edges) {
            *m = p * *m + c * s;
        }
        if mask.faces.is_empty() {
            mask.faces.extend(scratch.faces.iter().map(|s| c * s));
            mask.face_weights = scratch.face_weights;
        } else {
            for (m, s) in mask.faces.iter_mut().zip(&scratch.faces) {
                *m = p * *m + c * s;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::{EdgeNeighborhood, FaceKinds};

    fn base(n: usize, nf: usize) -> Neighborhood {
        Neighborhood {
            num_edges: n,
            num_faces: nf,
            rule: VertexRule::Smooth,
            crease_ends: [0, 0],
            faces: FaceKinds::Polygons,
        }
    }

    #[test]
    fn decrement_and_fractional_weight_follow_opensubdiv() {
        assert_eq!(decrement(2.5), 1.5);
        assert_eq!(decrement(1.0), 0.0);
        assert_eq!(decrement(0.3), 0.0);
        assert_eq!(decrement(INFINITE), INFINITE);
        // Only sharpnesses that vanish at this level count; the vertex's own too.
        assert_eq!(fractional_weight(0.0, &[0.5, 2.0, 0.0, INFINITE]), 0.5);
        assert_eq!(fractional_weight(0.25, &[0.75]), 0.5);
        assert_eq!(fractional_weight(0.0, &[3.0]), 0.0);
        assert_eq!(f64::from(sharpness(2.3)), f64::from(2.3f32));
    }

    #[test]
    fn semi_sharp_masks_blend_between_the_rules_and_sum_to_one() {
        let (mut m, mut s) = (Mask::default(), Mask::default());
        for scheme in [Scheme::Loop, Scheme::CatmullClark] {
            let b = base(5, 5);
            // Smooth parent: smooth mask whatever the child.
            scheme.semi_sharp_vertex_point_mask(
                &b,
                0.0,
                &[0.5, 0.0, 0.0, 0.0, 0.0],
                BoundaryRule::EdgeOnly,
                &mut m,
                &mut s,
            );
            let mut smooth = Mask::default();
            scheme.vertex_point_mask(&b, &mut smooth);
            assert_eq!(m, smooth);
            // Crease → smooth with weight 0.5 (two edges of 0.5).
            let e = [0.5, 0.0, 0.5, 0.0, 0.0];
            scheme.semi_sharp_vertex_point_mask(
                &b,
                0.0,
                &e,
                BoundaryRule::EdgeOnly,
                &mut m,
                &mut s,
            );
            assert!((m.sum() - 1.0).abs() < 1e-15);
            assert!((m.vertex - (0.5 * 0.75 + 0.5 * smooth.vertex)).abs() < 1e-15);
            assert!((m.edges[0] - (0.5 * 0.125 + 0.5 * smooth.edges[0])).abs() < 1e-15);
            // Sharpness > 1 on both: the crease rule, unblended.
            scheme.semi_sharp_vertex_point_mask(
                &b,
                0.0,
                &[2.0, 0.0, 1.5, 0.0, 0.0],
                BoundaryRule::EdgeOnly,
                &mut m,
                &mut s,
            );
            assert_eq!((m.vertex, m.edges[0], m.edges[2]), (0.75, 0.125, 0.125));
            // A vertex sharpness of 1.5 on a crease of infinite edges stays a corner.
            let inf = [INFINITE, 0.0, INFINITE, 0.0, 0.0];
            scheme.semi_sharp_vertex_point_mask(
                &b,
                1.5,
                &inf,
                BoundaryRule::EdgeOnly,
                &mut m,
                &mut s,
            );
            assert_eq!(m.vertex, 1.0);
            // ... and at 0.25 blends corner (0.25) and crease (0.75).
            scheme.semi_sharp_vertex_point_mask(
                &b,
                0.25,
                &inf,
                BoundaryRule::EdgeOnly,
                &mut m,
                &mut s,
            );
            assert!((m.vertex - (0.25 + 0.75 * 0.75)).abs() < 1e-15);
            let mut em = scheme.edge_point_mask(&EdgeNeighborhood {
                num_faces: 2,
                sharp: false,
                triangles: [scheme == Scheme::Loop; 2],
            });
            blend_edge_mask(&mut em, 0.25);
            let total = 2.0 * em.end + em.face[0] + em.face[1];
            assert!((total - 1.0).abs() < 1e-15);
        }
    }
}
