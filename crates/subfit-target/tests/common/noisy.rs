//! Noisy scans for the tests and the `noisy_bench` example: clean samples plus seeded Gaussian
//! noise (a fraction of the bounding-box diagonal) and outliers scattered uniformly in the
//! bounding box. Generated, never read from files.
#![allow(dead_code)]

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};

/// A noisy cloud: the points (surface samples first, outliers last) and how many are outliers.
pub struct NoisyCloud {
    /// Points, `#P by 3`: the first `#P − outliers` are noisy surface samples.
    pub points: Vec<[f64; 3]>,
    /// Number of injected outliers (the last rows of `points`).
    pub outliers: usize,
}

impl NoisyCloud {
    /// Whether row `i` is an injected outlier.
    pub fn is_outlier(&self, i: usize) -> bool {
        i >= self.points.len() - self.outliers
    }
}

/// Adds Gaussian noise of standard deviation `noise × diagonal` to each coordinate of `clean`
/// and appends `round(outlier_fraction × #clean)` points uniform in the (clean) bounding box.
pub fn add_noise(clean: &[[f64; 3]], noise: f64, outlier_fraction: f64, seed: u64) -> NoisyCloud {
    let mut rng = StdRng::seed_from_u64(seed);
    let (lo, hi) = subfit_mesh::bounding_box(clean).expect("a clean cloud has points");
    let diag = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    let normal = Normal::new(0.0, noise * diag).expect("finite noise");
    let mut points: Vec<[f64; 3]> = clean
        .iter()
        .map(|p| p.map(|c| c + normal.sample(&mut rng)))
        .collect();
    let outliers = (outlier_fraction * clean.len() as f64).round() as usize;
    for _ in 0..outliers {
        points.push([0, 1, 2].map(|k| lo[k] + rng.random::<f64>() * (hi[k] - lo[k])));
    }
    NoisyCloud { points, outliers }
}

/// `n` points uniform by area on the triangles `tris` of `pos`, from `seed`.
pub fn sample_triangles(pos: &[[f64; 3]], tris: &[[u32; 3]], n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut cum = Vec::with_capacity(tris.len());
    let mut total = 0.0;
    for t in tris {
        let [a, b, c] = t.map(|v| pos[v as usize]);
        let e1 = [0, 1, 2].map(|k| b[k] - a[k]);
        let e2 = [0, 1, 2].map(|k| c[k] - a[k]);
        let x = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        total += 0.5 * (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        cum.push(total);
    }
    (0..n)
        .map(|_| {
            let r = rng.random::<f64>() * total;
            let k = cum.partition_point(|&c| c < r).min(tris.len() - 1);
            let [a, b, c] = tris[k].map(|v| pos[v as usize]);
            let (mut u, mut v) = (rng.random::<f64>(), rng.random::<f64>());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            [0, 1, 2].map(|i| a[i] + u * (b[i] - a[i]) + v * (c[i] - a[i]))
        })
        .collect()
}
