//! Noisy scans with outliers: outliers are dropped, clean samplings keep their
//! points, the noise level is estimated and the normals of a noisy closed shape are oriented
//! outward. Generated shapes, seeded; no timing.

mod common;
#[path = "common/noisy.rs"]
mod noisy;

use common::{dot, sub, Shape, Sphere, Torus};
use subfit_target::{NormalSource, Target, TargetOptions};

fn options() -> TargetOptions {
    TargetOptions {
        normals: NormalSource::Estimate,
        ..TargetOptions::default()
    }
}

fn points(shape: &dyn Shape, n: usize, seed: u64) -> Vec<[f64; 3]> {
    shape.samples(n, seed).into_iter().map(|s| s.p).collect()
}

const SPHERE: Sphere = Sphere {
    c: [0.0; 3],
    r: 1.0,
};
const TORUS: Torus = Torus {
    big: 1.0,
    small: 0.35,
};

#[test]
fn clean_sphere_and_torus_lose_almost_nothing() {
    for (name, shape) in [("sphere", &SPHERE as &dyn Shape), ("torus", &TORUS)] {
        let p = points(shape, 30_000, 1);
        let t = Target::from_points(&p, None, &options()).unwrap();
        let s = t.stats();
        assert!(
            s.outliers_removed * 1000 < p.len(),
            "{name}: {} of {} removed",
            s.outliers_removed,
            p.len()
        );
        assert_eq!(s.outliers_removed, t.removed_outliers().len());
        // Clean: the noise level is a small fraction of the spacing and k is not widened.
        assert!(s.noise_level < 0.05 * s.point_spacing, "{name}: {s:?}");
        assert_eq!(s.neighborhood_k, 24, "{name}");
    }
}

/// Fraction of the kept normals pointing away from the closest point of `inside` (a point
/// inside the shape along the normal, in original units).
fn outward(t: &Target, inside: impl Fn([f64; 3]) -> [f64; 3]) -> f64 {
    let ok = t
        .points()
        .iter()
        .zip(t.normals())
        .filter(|(p, n)| {
            let q = t.to_original(**p);
            dot(sub(q, inside(q)), **n) > 0.0
        })
        .count();
    ok as f64 / t.len() as f64
}

#[test]
fn noisy_sphere_drops_outliers_estimates_noise_and_orients_outward() {
    let clean = points(&SPHERE, 97_000, 2);
    let cloud = noisy::add_noise(&clean, 0.003, 0.03, 3);
    let t = Target::from_points(&cloud.points, None, &options()).unwrap();
    let s = t.stats();
    let caught = t
        .removed_outliers()
        .iter()
        .filter(|&&i| cloud.is_outlier(i as usize))
        .count();
    assert!(
        caught * 10 >= cloud.outliers * 9,
        "{caught} of {} outliers removed",
        cloud.outliers
    );
    // Few surface samples go with them (only far tails of the noise).
    let wrong = s.outliers_removed - caught;
    assert!(wrong * 100 < clean.len(), "{wrong} surface samples removed");
    // Noise: σ = 0.003 × the diagonal (2√3 here), in normalized units (scale 1/2).
    let sigma = 0.003 * 2.0 * 3f64.sqrt() * t.normalization().length_to_normalized(1.0);
    assert!(
        (s.noise_level / sigma - 1.0).abs() < 0.3,
        "noise {} vs σ {sigma}",
        s.noise_level
    );
    assert!(s.neighborhood_k > 48, "{s:?}");
    let f = outward(&t, |_| [0.0; 3]);
    assert!(f >= 0.99, "{:.4} outward", f);
    // Every input index maps to a kept point.
    assert!(t.input_to_point().iter().all(|&j| (j as usize) < t.len()));
}

#[test]
fn noisy_torus_is_analysed_with_consistent_normals() {
    let clean = points(&TORUS, 60_000, 4);
    let cloud = noisy::add_noise(&clean, 0.003, 0.03, 5);
    let t = Target::from_points(&cloud.points, None, &options()).unwrap();
    assert!(t.stats().outliers_removed > cloud.outliers / 2);
    // Inside: the closest point of the tube's centre circle.
    let f = outward(&t, |q| {
        let r = (q[0] * q[0] + q[1] * q[1]).sqrt().max(1e-12);
        [q[0] / r, q[1] / r, 0.0]
    });
    assert!(f >= 0.99, "{:.4} outward", f);
}

#[test]
fn outlier_removal_can_be_turned_off() {
    let clean = points(&SPHERE, 5_000, 6);
    let cloud = noisy::add_noise(&clean, 0.003, 0.03, 7);
    let o = TargetOptions {
        remove_outliers: false,
        ..options()
    };
    let t = Target::from_points(&cloud.points, None, &o).unwrap();
    assert_eq!(t.stats().outliers_removed, 0);
    assert_eq!(t.len(), cloud.points.len());
    assert!(t.stats().noise_level > 0.0);
}

#[test]
fn noisy_sphere_without_wider_neighbourhoods_still_orients_within_the_field_budget() {
    // k stays 24: most normals look suspicious to the field check, whose iteration is then
    // bounded by its budget of point evaluations (not timed here).
    let clean = points(&SPHERE, 20_000, 8);
    let cloud = noisy::add_noise(&clean, 0.003, 0.03, 9);
    let o = TargetOptions {
        adapt_to_noise: false,
        ..options()
    };
    let t = Target::from_points(&cloud.points, None, &o).unwrap();
    let s = t.stats();
    assert_eq!(s.neighborhood_k, 24);
    assert!(s.field_iterations <= 200, "{s:?}");
    let f = outward(&t, |_| [0.0; 3]);
    assert!(f >= 0.99, "{:.4} outward", f);
}

/// A clean range scan is sparse where the surface turns away from the scanner: one pixel apart
/// along the rim, several across it, and a single return in a gap (a bit of surface seen
/// through an occlusion). Those points are kept; points scattered in space are not.
#[test]
fn a_clean_scans_sparse_rim_is_data_and_stray_points_are_not() {
    // A plane sampled one unit apart with a 16 × 16 gap, then three rim rows six units apart
    // across, one along.
    let mut p: Vec<[f64; 3]> = Vec::new();
    let hole = |i: usize, j: usize| (32..48).contains(&i) && (32..48).contains(&j);
    for i in 0..80 {
        for j in 0..80 {
            if !hole(i, j) {
                p.push([i as f64, j as f64, 0.0]);
            }
        }
    }
    let rim_from = p.len();
    for row in 1..=3 {
        for i in 0..80 {
            p.push([i as f64, 79.0 + 6.0 * row as f64, 0.0]);
        }
    }
    // A single return in the middle of a gap in the sampling, on the plane.
    p.push([39.5, 39.5, 0.0]);
    let rim_to = p.len();
    // Stray returns, each at least 8 units from the plane and from the others.
    let strays: [[f64; 3]; 6] = [
        [10.0, 10.0, 9.0],
        [40.0, 30.0, -12.0],
        [70.0, 60.0, 15.0],
        [25.0, 70.0, -9.5],
        [55.0, 5.0, 20.0],
        [5.0, 50.0, 11.0],
    ];
    p.extend_from_slice(&strays);
    let t = Target::from_points(&p, None, &options()).unwrap();
    let removed = t.removed_outliers();
    let rim_removed = removed
        .iter()
        .filter(|&&i| (rim_from..rim_to).contains(&(i as usize)))
        .count();
    assert_eq!(rim_removed, 0, "rim points dropped: {removed:?}");
    let strays_removed = removed.iter().filter(|&&i| i as usize >= rim_to).count();
    assert_eq!(strays_removed, strays.len(), "{removed:?}");
}
