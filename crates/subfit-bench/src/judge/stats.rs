//! One-way distance statistics ([`Direction`]), summed in input order so they do not depend on
//! the thread count.

use super::types::Direction;

/// The statistics of `d` (non-negative distances). Empty: all zero. Cost O(n) plus a selection
/// for the 95th percentile (nearest rank: the smallest value at least 95 % of `d` do not exceed).
pub(super) fn direction(d: &[f64]) -> Direction {
    if d.is_empty() {
        return Direction::default();
    }
    let (mut s, mut s2, mut max) = (0.0, 0.0, 0.0f64);
    for &x in d {
        s += x;
        s2 += x * x;
        max = max.max(x);
    }
    let n = d.len() as f64;
    let rank = ((0.95 * n).ceil() as usize).clamp(1, d.len()) - 1;
    let mut sorted = d.to_vec();
    let (_, p95, _) = sorted.select_nth_unstable_by(rank, f64::total_cmp);
    Direction {
        rms: (s2 / n).sqrt(),
        mean: s / n,
        max,
        p95: *p95,
        samples: d.len(),
    }
}

/// The statistics of distances `d` standing for the areas `w` (non-negative, same length, not
/// all zero): RMS, mean and 95th percentile weighted by area — the smallest distance such that
/// the points within it stand for at least 95 % of the area — the maximum and the count
/// unweighted. Falls back to [`direction`] when the weights do not fit. Cost O(n log n).
pub(super) fn weighted(d: &[f64], w: &[f64]) -> Direction {
    let total: f64 = w.iter().sum();
    if w.len() != d.len() || total.is_nan() || total <= 0.0 || !total.is_finite() {
        return direction(d);
    }
    let (mut s, mut s2, mut max) = (0.0, 0.0, 0.0f64);
    for (&x, &a) in d.iter().zip(w) {
        s += a * x;
        s2 += a * x * x;
        max = max.max(x);
    }
    let mut order: Vec<usize> = (0..d.len()).collect();
    order.sort_unstable_by(|&a, &b| d[a].total_cmp(&d[b]).then(a.cmp(&b)));
    let mut acc = 0.0;
    let mut p95 = max;
    for &i in &order {
        acc += w[i];
        if acc >= 0.95 * total {
            p95 = d[i];
            break;
        }
    }
    Direction {
        rms: (s2 / total).sqrt(),
        mean: s / total,
        max,
        p95,
        samples: d.len(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_of_a_known_set() {
        // 1..=100: mean 50.5, rms sqrt(338350/100), p95 the 95th value.
        let d: Vec<f64> = (1..=100).rev().map(f64::from).collect();
        let r = direction(&d);
        assert_eq!(r.samples, 100);
        assert_eq!(r.max, 100.0);
        assert_eq!(r.p95, 95.0);
        assert!((r.mean - 50.5).abs() < 1e-12);
        assert!((r.rms - (338_350.0f64 / 100.0).sqrt()).abs() < 1e-12);
        assert_eq!(direction(&[]), Direction::default());
        assert_eq!(direction(&[2.0]).p95, 2.0);
    }

    #[test]
    fn weights_count_by_area() {
        // Distance 1 over area 3, distance 3 over area 1: mean 1.5, rms sqrt(3), p95 3.
        let r = weighted(&[3.0, 1.0], &[1.0, 3.0]);
        assert!((r.mean - 1.5).abs() < 1e-15 && (r.rms - 3f64.sqrt()).abs() < 1e-15);
        assert_eq!((r.max, r.p95, r.samples), (3.0, 3.0, 2));
        let r = weighted(&[3.0, 1.0], &[1.0, 99.0]);
        assert_eq!(r.p95, 1.0);
        assert_eq!(weighted(&[1.0, 2.0], &[0.0, 0.0]), direction(&[1.0, 2.0]));
    }
}
