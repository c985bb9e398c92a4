//! Blended foot points where one local quadric is not to be trusted: a partition of unity of
//! the neighbouring data points' quadrics (Ohtake et al. 2003, "Multi-level partition of unity
//! implicits", §3: local quadric approximations blended with smooth weights), used only where
//! the nearest point's quadric alone is unreliable.
//!
//! The foot point of [`crate::project`] is the projection on the quadric of the data point
//! nearest to the query. That is a good surface estimate where the neighbourhood is smooth and
//! densely sampled, but it is one quadric, extrapolated, and two situations of real scans break
//! it:
//! - **sampling gaps** (holes, long scanner triangles bridging a crevice): the query's nearest
//!   data point is far along the surface, and its quadric is extrapolated well outside its
//!   support;
//! - **creases and scanner debris** (a sharp rim, a thin jagged fin): the quadrics of
//!   neighbouring points disagree with one another, and whichever is nearest decides.
//!
//! Measured on Igea's 134k points against the exact distance to its own triangles, over the
//! 610k limit vertices of a fit: the nearest-quadric distance was off by up to 6.4e-3 (unit
//! cube) in a few such spots (RMS 1.18e-4 over all); with blending where marked below, by up
//! to 3.8e-3 (RMS 1.13e-4), blending at 0.6 % of the data points and a few % of the queries.
//!
//! So a data point is marked **untrusted** at build time when the quadrics of its graph
//! neighbours (same-side ones: normals within 90°) pass farther than [`DISAGREEMENT`] times its
//! neighbourhood radius from it; and a foot point is over a **gap** when it lies farther than
//! [`GAP_OFFSET`] times that point's radius from the data point whose quadric gave it. Only
//! then is the foot point blended, so in smooth, dense regions results are exactly the
//! nearest-quadric ones (and as fast).

use rayon::prelude::*;

use crate::foot::{alpha_plus, foot_point_on, FootPoint};
use crate::layout::QueryLayout;
use crate::quadric::LocalQuadric;
use subfit_mesh::vec3::{cross, dot, normalize, scale, sub};

/// Data points blended at a query (its nearest ones).
pub(crate) const BLEND_K: usize = 16;
/// Blend weight `exp(−|x − p_j|² / (BLEND_SCALE · R_j)²)`, `R_j` the neighbourhood radius.
const BLEND_SCALE: f64 = 0.5;
/// A foot point is over a sampling gap when it lies farther from the data point whose quadric
/// gave it than this fraction of that point's neighbourhood radius. In a dense sampling the
/// foot point of a query near the surface is within about the spacing (≈ R/4 for the 24-point
/// neighbourhood) of its data point, since the quadric of the data point nearest to the foot
/// point is the one used.
const GAP_OFFSET: f64 = 0.4;
/// A data point is untrusted when a same-side neighbour's quadric passes farther from it than
/// this fraction of its neighbourhood radius (first-order distance). On smooth data the
/// quadrics agree to about the noise level (Igea: median about 0.006 R, 99th percentile about
/// 0.05 R; 0.6 % of its points are above 0.1 R).
pub(crate) const DISAGREEMENT: f64 = 0.1;

/// First-order distance of the point `x` to `quadric` (origin `origin`):
/// `(w − h(u, v)) / √(1 + |∇h|²)` in the quadric's frame. Cost: a dozen flops.
#[inline]
fn first_order_distance(quadric: &LocalQuadric, origin: [f64; 3], x: [f64; 3]) -> f64 {
    let l = quadric.local(sub(x, origin));
    let h = quadric.height(l[0], l[1]);
    (l[2] - h[0]) / (1.0 + h[1] * h[1] + h[2] * h[2]).sqrt()
}

/// [`untrusted`] for every slot of `l`, over its descent-graph rows. Parallel, O(#P · 16).
pub(crate) fn mark_untrusted(l: &QueryLayout) -> Vec<bool> {
    (0..l.points.len())
        .into_par_iter()
        .map(|s| {
            untrusted(
                &l.points,
                &l.quadrics,
                l.radius[s],
                s,
                l.descent.row(s as u32),
            )
        })
        .collect()
}

/// Whether point `s`'s quadric disagrees with those of its graph neighbours (see
/// [`DISAGREEMENT`]). `row`: its neighbours (slots, `u32::MAX` padding). O(#row).
pub(crate) fn untrusted(
    points: &[[f64; 3]],
    quadrics: &[LocalQuadric],
    radius: f64,
    s: usize,
    row: &[u32],
) -> bool {
    let p = points[s];
    let n = quadrics[s].n;
    let limit = DISAGREEMENT * radius;
    row.iter()
        .take_while(|&&j| j != u32::MAX)
        .map(|&j| j as usize)
        .filter(|&j| dot(quadrics[j].n, n) > 0.0)
        .any(|j| first_order_distance(&quadrics[j], points[j], p).abs() > limit)
}

/// Whether the foot point `f`, computed on the quadric of slot `s`, should be replaced by the
/// blended one: `s` is untrusted, or `f` lies farther from `s`'s data point than
/// [`GAP_OFFSET`] times its neighbourhood radius (the quadric was extrapolated: a sampling gap).
#[inline]
pub(crate) fn needs_blend(l: &QueryLayout, s: usize, f: &FootPoint) -> bool {
    if l.untrusted[s] {
        return true;
    }
    let r = sub(f.point, l.points[s]);
    let g = GAP_OFFSET * l.radius[s];
    dot(r, r) > g * g
}

/// The blended foot point of `x`: the projections of `x` on the quadrics of its
/// `neighbours` (slots; the nearest data point first) that face the same way as `near`'s
/// normal, their signed distances and normals averaged with weights
/// `exp(−|x − p_j|² / (BLEND_SCALE · R_j)²)`; the foot point is `x − d N`. The curvature frame
/// is that of the most heavily weighted projection, turned into the plane ⟂ `N`. `near` (the
/// nearest-quadric foot point) is returned when no neighbour qualifies.
pub(crate) fn blended(
    l: &QueryLayout,
    x: [f64; 3],
    neighbours: impl Iterator<Item = usize>,
    near: FootPoint,
) -> FootPoint {
    let (mut sw, mut sd) = (0.0, 0.0);
    let mut sn = [0.0; 3];
    let mut best: Option<(f64, FootPoint)> = None;
    for j in neighbours {
        let f = foot_point_on(&l.quadrics[j], l.points[j], x, l.point[j]);
        if dot(f.normal, near.normal) <= 0.0 {
            continue; // another sheet of a thin part
        }
        let r = sub(x, l.points[j]);
        let h = BLEND_SCALE * l.radius[j];
        let w = if h > 0.0 {
            (-dot(r, r) / (h * h)).exp()
        } else {
            0.0
        };
        if !(w > 0.0) {
            continue;
        }
        sw += w;
        sd += w * f.distance;
        for (s, nk) in sn.iter_mut().zip(f.normal) {
            *s += w * nk;
        }
        if best.as_ref().is_none_or(|(bw, _)| w > *bw) {
            best = Some((w, f));
        }
    }
    let (Some((_, frame)), Some(n)) = (best, normalize(sn)) else {
        return near;
    };
    let d = sd / sw;
    let t1 = normalize(sub(frame.t1, scale(n, dot(frame.t1, n)))).unwrap_or(frame.t1);
    let t2 = cross(n, t1);
    FootPoint {
        point: std::array::from_fn(|k| x[k] - d * n[k]),
        distance: d,
        normal: n,
        t1,
        t2,
        alpha1: alpha_plus(d, frame.k1),
        alpha2: alpha_plus(d, frame.k2),
        nearest: near.nearest,
        ..frame
    }
}
