//! The shape test of a candidate quad made of two triangles (Lavoué et al. 2007, §4.3, the
//! shape part of the pairing score) and the options of triangle pairing it reads: used by the
//! pairing itself ([`crate::quads`]) and by the hexagon merge ([`crate::hexagons`]).

use subfit_mesh::vec3::{add, cross, dot, norm, scale, sub};

/// Options of [`pair_triangles`](crate::quads::pair_triangles).
#[derive(Clone, Debug, PartialEq)]
pub struct PairOptions {
    /// Largest angle between the two triangles' normals (degrees) for which they may become a
    /// quad; larger angles are folds (sharp features of the target stay edges). Default 60.
    pub max_dihedral_deg: f64,
    /// Largest corner angle of a quad (degrees); near 180° the quad degenerates into a
    /// triangle with a vertex on an edge. Such quads score low (they are paired only when
    /// nothing better is left), but on QEM cages of CAD parts, whose vertices line up along
    /// the features, they pair many triangles that would stay alone. Default 175.
    pub max_corner_deg: f64,
    /// Weight of the coherency part of the score, in `[0, 1]` (the shape part gets the rest).
    /// Default 0.5. Ignored without a target.
    pub coherency_weight: f64,
    /// Points per edge (end points included) at which the principal directions are looked up
    /// (the paper's path vertices). Default 5, at least 2.
    pub edge_samples: usize,
    /// Most dual-graph nodes visited by one augmenting-path search. Default 400.
    pub search_limit: usize,
}

impl Default for PairOptions {
    fn default() -> Self {
        Self {
            max_dihedral_deg: 60.0,
            max_corner_deg: 175.0,
            coherency_weight: 0.5,
            edge_samples: 5,
            search_limit: 400,
        }
    }
}

/// Why a candidate is not a quad.
pub(crate) enum Reject {
    Fold,
    Shape,
}

/// Shape score in `[0, 1]` of the quad `p` (corners in order, diagonal `p0`–`p2`), or why it
/// is rejected (a fold, a non-convex or degenerate quad): `(1 − (mean + max corner deviation from
/// 90°) / 180°) · (1 − ½ dihedral / max dihedral)`.
pub(crate) fn shape_score(p: [[f64; 3]; 4], o: &PairOptions) -> Result<f64, Reject> {
    let n1 = cross(sub(p[1], p[0]), sub(p[2], p[0]));
    let n2 = cross(sub(p[2], p[0]), sub(p[3], p[0]));
    let (l1, l2) = (norm(n1), norm(n2));
    if !(l1 > 0.0 && l2 > 0.0) {
        return Err(Reject::Shape);
    }
    let dihedral = (dot(n1, n2) / (l1 * l2))
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees();
    if !(dihedral <= o.max_dihedral_deg) {
        return Err(Reject::Fold);
    }
    let n = add(scale(n1, 1.0 / l1), scale(n2, 1.0 / l2));
    let (mut sum, mut worst) = (0.0, 0.0f64);
    for i in 0..4 {
        let (prev, cur, next) = (p[(i + 3) % 4], p[i], p[(i + 1) % 4]);
        let (u, v) = (sub(prev, cur), sub(next, cur));
        let (lu, lv) = (norm(u), norm(v));
        if !(lu > 0.0 && lv > 0.0) || dot(cross(sub(cur, prev), v), n) <= 0.0 {
            return Err(Reject::Shape); // a zero-length edge, or a reflex corner
        }
        let angle = (dot(u, v) / (lu * lv)).clamp(-1.0, 1.0).acos().to_degrees();
        if angle > o.max_corner_deg {
            return Err(Reject::Shape);
        }
        let dev = (angle - 90.0).abs();
        sum += dev;
        worst = worst.max(dev);
    }
    let angles = 1.0 - (sum / 4.0 + worst) / 180.0;
    Ok(angles * (1.0 - 0.5 * dihedral / o.max_dihedral_deg.max(1e-9)))
}
