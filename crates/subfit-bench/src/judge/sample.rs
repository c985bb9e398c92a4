//! Area-uniform samples of a triangle set: a triangle drawn with probability proportional to its
//! area ([`rand::distr::weighted::WeightedIndex`]), then a uniform point of it (two uniform
//! numbers, reflected into the triangle when their sum passes 1). Drawn in one sequence from a
//! seeded generator, so the samples depend on the seed only.

use rand::distr::weighted::WeightedIndex;
use rand::distr::Distribution;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use subfit::mesh::vec3::{cross, norm, sub};

/// A point of a triangle set: the triangle and barycentric weights of its three corners.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct TrianglePoint {
    /// The triangle.
    pub triangle: u32,
    /// Weights of corners 0, 1, 2 (non-negative, sum 1).
    pub bary: [f64; 3],
}

impl TrianglePoint {
    /// The point on triangle `t` of `positions`.
    pub fn position(&self, positions: &[[f64; 3]], t: [u32; 3]) -> [f64; 3] {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        std::array::from_fn(|k| self.bary[0] * a[k] + self.bary[1] * b[k] + self.bary[2] * c[k])
    }
}

/// Area of triangle `t` of `positions`.
pub(super) fn area(positions: &[[f64; 3]], t: [u32; 3]) -> f64 {
    let [a, b, c] = t.map(|i| positions[i as usize]);
    0.5 * norm(cross(sub(b, a), sub(c, a)))
}

/// `count` area-uniform points of `triangles` over `positions`, seeded by `seed`. `None` when
/// the triangles have no area (or a non-finite one). Cost O(#T + count · log #T).
pub(super) fn area_samples(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    count: usize,
    seed: u64,
) -> Option<Vec<TrianglePoint>> {
    let areas: Vec<f64> = triangles.iter().map(|&t| area(positions, t)).collect();
    let pick = WeightedIndex::new(&areas).ok()?;
    let mut rng = StdRng::seed_from_u64(seed);
    Some(
        (0..count)
            .map(|_| {
                let triangle = pick.sample(&mut rng) as u32;
                let (mut r, mut s): (f64, f64) = (rng.random(), rng.random());
                if r + s > 1.0 {
                    (r, s) = (1.0 - r, 1.0 - s);
                }
                TrianglePoint {
                    triangle,
                    bary: [1.0 - r - s, r, s],
                }
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_follow_area() {
        // Two triangles, areas 0.5 and 1.5: about a quarter of the samples on the first.
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 3.0, 0.0],
        ];
        let tris = [[0u32, 1, 2], [0, 1, 3]];
        assert!((area(&p, tris[0]) - 0.5).abs() < 1e-15);
        assert!((area(&p, tris[1]) - 1.5).abs() < 1e-15);
        let s = area_samples(&p, &tris, 20_000, 7).unwrap();
        let first = s.iter().filter(|x| x.triangle == 0).count() as f64 / 20_000.0;
        // Binomial standard deviation sqrt(0.25 · 0.75 / 20000) ≈ 0.003: 5σ.
        assert!((first - 0.25).abs() < 0.016, "{first}");
        for x in &s {
            assert!(x.bary.iter().all(|&b| b >= 0.0));
            assert!((x.bary.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        }
        assert_eq!(s, area_samples(&p, &tris, 20_000, 7).unwrap());
        let flat = [[0.0; 3]; 3];
        assert!(area_samples(&flat, &[[0, 1, 2]], 5, 1).is_none());
    }
}
