//! Small vector helpers on `[f64; 3]`, the position type of every crate (DESIGN.md §3.8: numbers
//! are f64).
//!
//! Plain functions, `#[inline]`, each written out component by component in a fixed order, so a
//! result is the same bits wherever it is computed (Rust does not contract `a * b + c` into a
//! fused multiply-add). Two normalizations exist because existing results depend on their exact
//! bits: [`normalize`] multiplies by the reciprocal of the length, [`unit`](fn@unit) divides by the
//! length (one rounding per component instead of two); they differ by at most an ulp or so.

/// `a + b`.
#[inline]
pub fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a − b`.
#[inline]
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `s · a`.
#[inline]
pub fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// The dot product `a · b`, summed in the order x, y, z.
#[inline]
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The cross product `a × b` (right-handed).
#[inline]
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The squared length `a · a`.
#[inline]
pub fn norm2(a: [f64; 3]) -> f64 {
    dot(a, a)
}

/// The Euclidean length `|a|` (no scaling against overflow: fine for coordinates well inside
/// `±1e150`).
#[inline]
pub fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// The squared distance `|a − b|²`.
#[inline]
pub fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm2(sub(a, b))
}

/// The Newell normal of the polygon `face` over `positions`: twice its vector area, not
/// normalized (Newell's method, exact for planar polygons and the best-fit direction for
/// others); zero when it is not finite. Every id must be in range.
pub fn polygon_normal(positions: &[[f64; 3]], face: &[u32]) -> [f64; 3] {
    let mut n = [0.0; 3];
    for (i, &a) in face.iter().enumerate() {
        let p = positions[a as usize];
        let q = positions[face[(i + 1) % face.len()] as usize];
        n[0] += (p[1] - q[1]) * (p[2] + q[2]);
        n[1] += (p[2] - q[2]) * (p[0] + q[0]);
        n[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
    if n.iter().all(|x| x.is_finite()) {
        n
    } else {
        [0.0; 3]
    }
}

/// The unit vector `a · (1 / |a|)`, or `None` when `|a|` is zero or not finite (a zero, huge or
/// NaN vector).
#[inline]
pub fn normalize(a: [f64; 3]) -> Option<[f64; 3]> {
    let l = norm(a);
    (l > 0.0 && l.is_finite()).then(|| scale(a, 1.0 / l))
}

/// The unit vector `a / |a|` (each component divided by the length), or `None` when `|a|` is
/// zero or not finite. See the module doc for how it differs from [`normalize`].
#[inline]
pub fn unit(a: [f64; 3]) -> Option<[f64; 3]> {
    let l = norm(a);
    (l > 0.0 && l.is_finite()).then(|| [a[0] / l, a[1] / l, a[2] / l])
}

/// A unit vector orthogonal to the unit vector `n`: `x` (or `y` when `n` is near `x`) with its
/// component along `n` removed, normalized; `z` if that fails (`n` not finite).
#[inline]
pub fn any_orthogonal(n: [f64; 3]) -> [f64; 3] {
    let a = if n[0].abs() < 0.6 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    normalize(sub(a, scale(n, dot(a, n)))).unwrap_or([0.0, 0.0, 1.0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn products_and_normalizations() {
        let (a, b) = ([1.0, 2.0, 3.0], [-2.0, 0.5, 4.0]);
        assert_eq!(add(a, b), [-1.0, 2.5, 7.0]);
        assert_eq!(sub(a, b), [3.0, 1.5, -1.0]);
        assert_eq!(scale(a, 2.0), [2.0, 4.0, 6.0]);
        assert_eq!(dot(a, b), 11.0);
        let c = cross(a, b);
        assert_eq!((dot(c, a), dot(c, b)), (0.0, 0.0));
        assert_eq!(cross([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]);
        assert_eq!(norm([3.0, 4.0, 0.0]), 5.0);
        assert_eq!(dist2(a, b), 9.0 + 2.25 + 1.0);
        for f in [normalize, unit] {
            let u = f([0.0, 3.0, 4.0]).unwrap();
            assert!((norm(u) - 1.0).abs() <= 2.0 * f64::EPSILON);
            assert_eq!(f([0.0; 3]), None);
            assert_eq!(f([f64::NAN, 0.0, 0.0]), None);
            assert_eq!(f([f64::INFINITY, 0.0, 0.0]), None);
        }
        for n in [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.6, 0.8, 0.0]] {
            let t = any_orthogonal(n);
            assert!(dot(t, n).abs() < 1e-15 && (norm(t) - 1.0).abs() < 1e-15);
        }
    }
}
