//! Seeded random parameters over the patches of an [`Evaluator`], and the limit points there.

use super::types::{EvalError, EvalKind, SurfaceParam, SurfacePoint};
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

/// Area weights of samples drawn by [`Evaluator::random_params`]: each sample stands for
/// `|S_u × S_v|` times its patch's domain area (½ for a triangle patch, 1 for a square), so
/// that statistics weighted by them are area-uniform over the limit surface (importance
/// sampling: the patches are drawn uniformly, whatever their size). Samples exactly at an
/// irregular vertex ([`EvalKind::Vertex`], no parametric derivatives; a null set) get the mean
/// weight of the others. `params` and `points` are parallel. Cost O(n).
pub fn area_weights(
    evaluator: &Evaluator,
    params: &[SurfaceParam],
    points: &[SurfacePoint],
) -> Vec<f64> {
    use subfit_mesh::vec3::{cross, norm};
    let mut w: Vec<f64> = params
        .iter()
        .zip(points)
        .map(|(q, p)| match p.kind {
            EvalKind::Patch => {
                let domain = if evaluator.triangle_patch(q.face) {
                    0.5
                } else {
                    1.0
                };
                domain * norm(cross(p.du, p.dv))
            }
            EvalKind::Vertex => f64::NAN,
        })
        .collect();
    let known: Vec<f64> = w.iter().copied().filter(|x| x.is_finite()).collect();
    let mean = if known.is_empty() {
        1.0
    } else {
        known.iter().sum::<f64>() / known.len() as f64
    };
    for x in &mut w {
        if !x.is_finite() {
            *x = mean;
        }
    }
    w
}
