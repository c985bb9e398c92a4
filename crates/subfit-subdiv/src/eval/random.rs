//! Seeded random parameters over the patches of an [`Evaluator`], and the limit points there.

use super::types::{EvalError, SurfaceParam, SurfacePoint};
use super::Evaluator;

impl Evaluator {
    /// `n` random parameters from a seeded generator (SplitMix64): a patch chosen uniformly,
    /// then a point uniform over its parameter domain (triangle or square). Deterministic for a
    /// given seed. Not area-uniform on the surface. Cost O(n).
    pub fn random_params(&self, n: usize, seed: u64) -> Vec<SurfaceParam> {
        let mut rng = SplitMix64(seed);
        let np = self.num_patches();
        if np == 0 {
            return Vec::new();
        }
        (0..n)
            .map(|_| {
                let p = (rng.next_f64() * np as f64) as usize;
                let (face, sub) = self.patch(p.min(np - 1));
                let (mut u, mut v) = (rng.next_f64(), rng.next_f64());
                if self.triangle_patch(face) && u + v > 1.0 {
                    (u, v) = (1.0 - u, 1.0 - v);
                }
                SurfaceParam { face, sub, u, v }
            })
            .collect()
    }
}

/// SplitMix64 (Steele, Lea & Flood 2014): a tiny seeded generator for reproducible samples.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// `n` random parameters of `evaluator` and the exact limit points and unit normals there, for
/// `subfit eval CONTROL --samples N` (see [`Evaluator::random_params`]). Parallel.
///
/// Errors: as [`Evaluator::evaluate`].
pub fn random_samples(
    evaluator: &Evaluator,
    positions: &[[f64; 3]],
    n: usize,
    seed: u64,
) -> Result<(Vec<SurfaceParam>, Vec<SurfacePoint>), EvalError> {
    let params = evaluator.random_params(n, seed);
    let pts = evaluator.evaluate_batch(positions, &params)?;
    Ok((params, pts))
}
