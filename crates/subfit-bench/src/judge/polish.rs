//! Polishing a closest point on the exact limit surface: Newton steps on `½ |S(u, v) − x|²`
//! within one patch's parameter domain, from the parameter of the closest point on the judge's
//! tessellation (Stam 1998 evaluation gives `S`, its first and second derivatives).
//!
//! The Hessian is `JᵀJ + Σ_k r_k ∇²S_k` (`J = [S_u S_v]`, `r = S − x`) when it is positive
//! definite, else the Gauss-Newton `JᵀJ`; every step is projected into the domain and halved
//! until the distance falls (a step is taken only when it does), so the result is never worse
//! than the start and is always the distance to an actual point of the limit surface.

use subfit::mesh::vec3::{dot, sub};
use subfit::subdiv::{EvalError, EvalKind, Evaluator, SurfaceParam, SurfacePoint};

/// Newton iterations at most (the start is within the tessellation's deviation of the foot
/// point, so two or three usually reach rounding).
const MAX_ITERATIONS: usize = 12;
/// Halvings of a step before giving up on it.
const MAX_HALVINGS: usize = 10;
/// A parameter this close (in parameter units) to the domain's border counts as on it: the
/// foot point may then belong to the neighbouring patch.
const BORDER: f64 = 1e-9;

/// The polished closest point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Polished {
    /// Distance from the query to the polished limit point (an upper bound on the distance to
    /// the limit surface).
    pub distance: f64,
    /// Whether the polish ended at a stationary point strictly inside the patch: then the
    /// distance is the exact distance to the local closest point.
    pub interior_stationary: bool,
    /// The final parameter.
    pub param: SurfaceParam,
}

/// Projects `(u, v)` into the domain of a triangle (`u, v ≥ 0`, `u + v ≤ 1`) or unit-square
/// patch.
fn clamp_domain(u: f64, v: f64, triangle: bool) -> (f64, f64) {
    if triangle {
        let (u, v) = (u.max(0.0), v.max(0.0));
        let s = u + v;
        if s > 1.0 {
            // Closest point of the hypotenuse, kept in its segment.
            let d = 0.5 * (s - 1.0);
            let (u, v) = ((u - d).max(0.0), (v - d).max(0.0));
            let s = u + v;
            return (u / s, v / s);
        }
        (u, v)
    } else {
        (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0))
    }
}

fn on_border(u: f64, v: f64, triangle: bool) -> bool {
    u <= BORDER || v <= BORDER || {
        if triangle {
            u + v >= 1.0 - BORDER
        } else {
            u >= 1.0 - BORDER || v >= 1.0 - BORDER
        }
    }
}

/// The Newton (or Gauss-Newton) step at `s` for residual `r`, and whether `r` is already
/// orthogonal to the tangent plane (a stationary point). `None` when the tangents are
/// degenerate.
fn newton_step(s: &SurfacePoint, r: [f64; 3]) -> Option<([f64; 2], bool)> {
    let (a11, a12, a22) = (dot(s.du, s.du), dot(s.du, s.dv), dot(s.dv, s.dv));
    let g = [dot(s.du, r), dot(s.dv, r)];
    let det_a = a11 * a22 - a12 * a12;
    // NaN tangents fail this test too.
    if det_a.is_nan() || det_a <= 1e-30 * (a11 + a22) * (a11 + a22) {
        return None;
    }
    // Tangential part of r: |t|² = gᵀ A⁻¹ g. Stationary when it is negligible against the
    // residual (relative 1e-9: the distance is then exact to ~1e-18 relative) or against the
    // patch's own scale (a query on the surface).
    let t2 = (a22 * g[0] * g[0] - 2.0 * a12 * g[0] * g[1] + a11 * g[1] * g[1]) / det_a;
    let stationary = t2 <= 1e-18 * dot(r, r) || t2 <= 1e-24 * (a11 + a22);
    let (mut h11, mut h12, mut h22) = (a11, a12, a22);
    if let (EvalKind::Patch, Some([suu, suv, svv])) = (s.kind, s.second) {
        let (n11, n12, n22) = (a11 + dot(suu, r), a12 + dot(suv, r), a22 + dot(svv, r));
        if n11 > 0.0 && n11 * n22 - n12 * n12 > 1e-12 * det_a {
            (h11, h12, h22) = (n11, n12, n22);
        }
    }
    let det = h11 * h22 - h12 * h12;
    Some((
        [
            -(h22 * g[0] - h12 * g[1]) / det,
            -(h11 * g[1] - h12 * g[0]) / det,
        ],
        stationary,
    ))
}

/// Polishes the closest point of `x` on the limit of `ev` with control points `cage`, from
/// `start` (see the module docs). Cost: a few exact evaluations.
pub(super) fn polish(
    ev: &Evaluator,
    cage: &[[f64; 3]],
    x: [f64; 3],
    start: SurfaceParam,
) -> Result<Polished, EvalError> {
    let triangle = ev.triangle_patch(start.face);
    let mut q = start;
    let mut s = ev.evaluate(cage, q)?;
    let mut d2 = dot(sub(s.position, x), sub(s.position, x));
    let mut stationary = false;
    for _ in 0..MAX_ITERATIONS {
        if d2 == 0.0 {
            stationary = true;
            break;
        }
        let Some((step, at_rest)) = newton_step(&s, sub(s.position, x)) else {
            break;
        };
        if at_rest {
            stationary = true;
            break;
        }
        let mut t = 1.0;
        let mut taken = false;
        for _ in 0..MAX_HALVINGS {
            let (u, v) = clamp_domain(q.u + t * step[0], q.v + t * step[1], triangle);
            if (u, v) == (q.u, q.v) {
                break;
            }
            let cand = SurfaceParam { u, v, ..q };
            let sc = ev.evaluate(cage, cand)?;
            let dc = dot(sub(sc.position, x), sub(sc.position, x));
            if dc < d2 {
                (q, s, d2, taken) = (cand, sc, dc, true);
                break;
            }
            t *= 0.5;
        }
        if !taken {
            break;
        }
    }
    Ok(Polished {
        distance: d2.sqrt(),
        interior_stationary: stationary && !on_border(q.u, q.v, triangle),
        param: q,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn domain_projection() {
        assert_eq!(clamp_domain(-0.5, 2.0, false), (0.0, 1.0));
        assert_eq!(clamp_domain(0.25, 0.5, true), (0.25, 0.5));
        let (u, v) = clamp_domain(1.0, 0.5, true);
        assert!((u - 0.75).abs() < 1e-15 && (v - 0.25).abs() < 1e-15);
        assert_eq!(clamp_domain(3.0, -1.0, true), (1.0, 0.0));
        assert!(on_border(0.5, 0.5, true) && !on_border(0.5, 0.5, false));
    }
}
