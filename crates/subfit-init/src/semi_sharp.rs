//! Semi-sharp crease tags from the data's fillet widths (`--semi-sharp`).
//!
//! A feature-aligned cage tags its feature curves as infinitely sharp creases. A rounded edge
//! of the data — a fillet a few triangles wide ([`subfit_target::fillet_widths`]) — is better
//! served by a finite OpenSubdiv sharpness `s`: the crease rules apply for `s` levels, after
//! which the smooth rules round the edge over about a level-`s` edge length (DeRose, Kass and
//! Truong 1998, §3; the semi-sharp rules of OpenSubdiv's `Sdc::Crease`, uniform creasing). A
//! cage crease edge of length `L` on a curve of fillet width `w` therefore gets
//!
//! ```text
//! s = log2(c · L / w),   clamped to [0, SHARPNESS_INFINITE)
//! ```
//!
//! with `c` = [`ROUNDING_WIDTH`] (the rounding width of a sharpness-0 crease in edge lengths),
//! and stays infinitely sharp for `w = 0` (a designed crease). A corner tag takes the largest
//! sharpness of its creases, so a rounded box gets rounded corners too.

use subfit_mesh::vec3::dist2;
use subfit_mesh::{PolyMesh, Tags, SHARPNESS_INFINITE};
use subfit_target::{Features, PointIndex};

/// The width, in cage edge lengths, over which the limit surface rounds a crease of sharpness
/// 0 (see the module docs).
pub const ROUNDING_WIDTH: f64 = 0.6;

/// The OpenSubdiv sharpness of a crease edge of length `edge_length` standing for a fillet of
/// width `width` (same units): infinite for `width ≤ 0`, else `log2(ROUNDING_WIDTH · L / w)`
/// clamped to `[0, SHARPNESS_INFINITE)` (just below infinite at the top).
pub fn sharpness_for(width: f64, edge_length: f64) -> f64 {
    if !(width > 0.0) {
        return SHARPNESS_INFINITE;
    }
    let s = (ROUNDING_WIDTH * edge_length / width).log2();
    if s.is_finite() {
        s.clamp(0.0, SHARPNESS_INFINITE - 1e-6)
    } else {
        SHARPNESS_INFINITE
    }
}

/// `tags` (creases of the cage `cage`, in the units of `dense`) with each crease's sharpness
/// set from the fillet width of the data curve it follows: `features` and `widths` (one per
/// curve, `None`: unknown, left infinitely sharp) on the mesh `dense`. A crease follows the
/// curve of the feature vertex nearest its midpoint. Corner tags take the largest sharpness of
/// their creases. Cost O((#feature vertices + #creases) log).
pub fn semi_sharp_tags(
    cage: &PolyMesh,
    tags: &Tags,
    dense: &PolyMesh,
    features: &Features,
    widths: &[Option<f64>],
) -> Tags {
    let mut points = Vec::new();
    let mut curve_of = Vec::new();
    for (c, curve) in features.curves.iter().enumerate() {
        for &v in &curve.vertices {
            if let Some(&p) = dense.positions.get(v as usize) {
                points.push(p);
                curve_of.push(c);
            }
        }
    }
    let Some(index) = PointIndex::new(&points) else {
        return tags.clone();
    };
    let mut out = Tags::new();
    let mut corner_max = std::collections::HashMap::<u32, f64>::new();
    for ((a, b), s) in tags.creases() {
        let (pa, pb) = (cage.positions[a as usize], cage.positions[b as usize]);
        let mid = std::array::from_fn(|k| 0.5 * (pa[k] + pb[k]));
        let curve = curve_of[index.nearest(&mid).index as usize];
        let sharp = if s >= SHARPNESS_INFINITE {
            match widths.get(curve).copied().flatten() {
                Some(w) => sharpness_for(w, dist2(pa, pb).sqrt()),
                None => s,
            }
        } else {
            s
        };
        out.set_crease(a, b, sharp);
        for v in [a, b] {
            let m = corner_max.entry(v).or_insert(0.0);
            *m = m.max(sharp);
        }
    }
    for (v, s) in tags.corners() {
        let sharp = match corner_max.get(&v) {
            Some(&m) if s >= SHARPNESS_INFINITE => m,
            _ => s,
        };
        out.set_corner(v, sharp);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sharpness_falls_with_the_width() {
        assert_eq!(sharpness_for(0.0, 1.0), SHARPNESS_INFINITE);
        assert!((sharpness_for(0.25, 1.0) - (4.0 * ROUNDING_WIDTH).log2().max(0.0)).abs() < 1e-12);
        assert!(sharpness_for(0.01, 1.0) > sharpness_for(0.1, 1.0));
        assert_eq!(sharpness_for(100.0, 1.0), 0.0);
        assert!(sharpness_for(1e-300, 1.0) < SHARPNESS_INFINITE);
    }
}
