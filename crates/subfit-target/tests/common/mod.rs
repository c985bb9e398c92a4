//! Analytic shapes for the tests: uniform-by-area samplers with exact normals, principal
//! curvatures (Cheng 2007 §II-D3 signs for outward normals: convex ⇒ negative) and closest points.
#![allow(dead_code)]

use std::path::PathBuf;

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};

pub fn rng(seed: u64) -> StdRng {
    StdRng::seed_from_u64(seed)
}

#[allow(unused_imports, reason = "each test binary uses some")]
pub use subfit_mesh::vec3::{add, dot, norm, scale, sub};

/// `a / |a|` by the reciprocal ([`subfit_mesh::vec3::normalize`]); NaN for a zero vector.
pub fn unit(a: [f64; 3]) -> [f64; 3] {
    subfit_mesh::vec3::normalize(a).unwrap_or([f64::NAN; 3])
}

/// A surface sample with its exact differential geometry (outward normal; `k1`, `k2` signed
/// with `|k1| ≤ |k2|`).
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    pub p: [f64; 3],
    pub n: [f64; 3],
    pub k1: f64,
    pub k2: f64,
}

pub trait Shape: Sync {
    fn sample(&self, rng: &mut StdRng) -> Sample;
    /// Exact geometry at a surface point.
    fn at(&self, p: [f64; 3]) -> Sample;
    /// Exact closest surface point to `x` (for `x` not on the medial axis).
    fn closest(&self, x: [f64; 3]) -> [f64; 3];
    fn samples(&self, n: usize, seed: u64) -> Vec<Sample> {
        let mut r = rng(seed);
        (0..n).map(|_| self.sample(&mut r)).collect()
    }
}

fn sorted(k1: f64, k2: f64) -> (f64, f64) {
    if k1.abs() <= k2.abs() {
        (k1, k2)
    } else {
        (k2, k1)
    }
}

fn unit_sphere_dir(rng: &mut StdRng) -> [f64; 3] {
    let g = Normal::new(0.0, 1.0).unwrap();
    loop {
        let v = [g.sample(rng), g.sample(rng), g.sample(rng)];
        let l = norm(v);
        if l > 1e-9 {
            return scale(v, 1.0 / l);
        }
    }
}

pub struct Sphere {
    pub c: [f64; 3],
    pub r: f64,
}
impl Shape for Sphere {
    fn sample(&self, rng: &mut StdRng) -> Sample {
        let d = unit_sphere_dir(rng);
        self.at(add(self.c, scale(d, self.r)))
    }
    fn at(&self, p: [f64; 3]) -> Sample {
        Sample {
            p,
            n: unit(sub(p, self.c)),
            k1: -1.0 / self.r,
            k2: -1.0 / self.r,
        }
    }
    fn closest(&self, x: [f64; 3]) -> [f64; 3] {
        add(self.c, scale(unit(sub(x, self.c)), self.r))
    }
}

/// Axis-aligned ellipsoid centred at the origin with semi-axes `a`.
pub struct Ellipsoid {
    pub a: [f64; 3],
}
impl Shape for Ellipsoid {
    fn sample(&self, rng: &mut StdRng) -> Sample {
        let a = self.a;
        let amin = a[0].min(a[1]).min(a[2]);
        loop {
            let u = unit_sphere_dir(rng);
            // Area element of the map u ↦ diag(a) u is ∝ |diag(a)^-1 u|.
            let g = norm([u[0] / a[0], u[1] / a[1], u[2] / a[2]]) * amin;
            if rng.random::<f64>() < g {
                return self.at([a[0] * u[0], a[1] * u[1], a[2] * u[2]]);
            }
        }
    }
    fn at(&self, p: [f64; 3]) -> Sample {
        let [a, b, c] = self.a;
        let (x, y, z) = (p[0], p[1], p[2]);
        let n = unit([x / (a * a), y / (b * b), z / (c * c)]);
        let s = x * x / a.powi(4) + y * y / b.powi(4) + z * z / c.powi(4);
        let abc2 = (a * b * c).powi(2);
        let kg = 1.0 / (abc2 * s * s);
        let h = (x * x + y * y + z * z - a * a - b * b - c * c) / (2.0 * abc2 * s.powf(1.5));
        let disc = (h * h - kg).max(0.0).sqrt();
        let (k1, k2) = sorted(h + disc, h - disc);
        Sample { p, n, k1, k2 }
    }
    fn closest(&self, x: [f64; 3]) -> [f64; 3] {
        // p_i = a_i² x_i / (a_i² + t), t the largest root of g(t) = Σ (a_i x_i / (a_i² + t))² − 1,
        // decreasing on t > −min a_i²: bisection.
        let a2 = self.a.map(|v| v * v);
        let g = |t: f64| -> f64 {
            (0..3)
                .map(|i| (self.a[i] * x[i] / (a2[i] + t)).powi(2))
                .sum::<f64>()
                - 1.0
        };
        let tmin = -a2.iter().copied().fold(f64::INFINITY, f64::min);
        let mut lo = tmin + 1e-300_f64.max(1e-15 * -tmin);
        let mut hi = 1.0;
        while g(hi) > 0.0 {
            hi *= 2.0;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if g(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let t = 0.5 * (lo + hi);
        [0, 1, 2].map(|i| a2[i] * x[i] / (a2[i] + t))
    }
}

/// Torus around the z axis: centre-line radius `big`, tube radius `small`.
pub struct Torus {
    pub big: f64,
    pub small: f64,
}
impl Shape for Torus {
    fn sample(&self, rng: &mut StdRng) -> Sample {
        let (rr, r) = (self.big, self.small);
        loop {
            let th = rng.random::<f64>() * std::f64::consts::TAU;
            let ph = rng.random::<f64>() * std::f64::consts::TAU;
            if rng.random::<f64>() * (rr + r) < rr + r * ph.cos() {
                let w = rr + r * ph.cos();
                return self.at([w * th.cos(), w * th.sin(), r * ph.sin()]);
            }
        }
    }
    fn at(&self, p: [f64; 3]) -> Sample {
        let (rr, r) = (self.big, self.small);
        let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
        let c = [rr * p[0] / rho, rr * p[1] / rho, 0.0];
        let n = unit(sub(p, c));
        let cos_ph = (rho - rr) / r;
        let (k1, k2) = sorted(-cos_ph / (rr + r * cos_ph), -1.0 / r);
        Sample { p, n, k1, k2 }
    }
    fn closest(&self, x: [f64; 3]) -> [f64; 3] {
        let rho = (x[0] * x[0] + x[1] * x[1]).sqrt();
        let c = [self.big * x[0] / rho, self.big * x[1] / rho, 0.0];
        add(c, scale(unit(sub(x, c)), self.small))
    }
}

pub fn positions(s: &[Sample]) -> Vec<[f64; 3]> {
    s.iter().map(|s| s.p).collect()
}

/// Adds isotropic Gaussian noise of standard deviation `sigma`.
pub fn jitter(p: &[[f64; 3]], sigma: f64, seed: u64) -> Vec<[f64; 3]> {
    let mut r = rng(seed);
    let g = Normal::new(0.0, sigma).unwrap();
    p.iter()
        .map(|q| {
            [
                q[0] + g.sample(&mut r),
                q[1] + g.sample(&mut r),
                q[2] + g.sample(&mut r),
            ]
        })
        .collect()
}

/// Fraction of entries satisfying `pred`.
pub fn fraction<T>(v: &[T], pred: impl Fn(&T) -> bool) -> f64 {
    v.iter().filter(|x| pred(x)).count() as f64 / v.len() as f64
}

/// `$SUBFIT_DATA` (the directory of shared/data), for the tests on real models. Without it:
/// fails when `CI=true` (CI must run them), else prints a notice naming `what` and skips.
pub fn data_dir(what: &str) -> Option<PathBuf> {
    env_dir("SUBFIT_DATA", "shared/data", what)
}

/// `$SUBFIT_CORPUS` (the directory of shared/corpus), as [`data_dir`].
#[allow(dead_code, reason = "not every test file reads the corpus")]
pub fn corpus_dir(what: &str) -> Option<PathBuf> {
    env_dir("SUBFIT_CORPUS", "shared/corpus", what)
}

#[allow(clippy::print_stdout)]
fn env_dir(var: &str, dir: &str, what: &str) -> Option<PathBuf> {
    match std::env::var_os(var) {
        Some(d) => Some(PathBuf::from(d)),
        None => {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "{var} is not set (needed on CI: the directory of {dir})"
            );
            println!("notice: {var} not set, skipping {what}");
            None
        }
    }
}
