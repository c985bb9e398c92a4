//! Blended foot points (the `blend` module): smooth, dense data keeps the nearest-quadric foot
//! points; over a sampling gap, blending the quadrics around the gap estimates the distance to
//! the true surface better than extrapolating the nearest point's quadric alone.
#![allow(clippy::print_stdout)]

mod common;

use common::*;
use subfit_target::project::foot_point_on;
use subfit_target::{Target, TargetOptions};

fn torus() -> Torus {
    Torus {
        big: 0.35,
        small: 0.15,
    }
}

/// The nearest-quadric foot point alone (no second query, no blending), for comparison.
fn nearest_quadric_distance(t: &Target, x: [f64; 3]) -> f64 {
    let i = t.index().nearest(&x).index as usize;
    foot_point_on(&t.quadrics()[i], t.points()[i], x, i as u32).distance
}

#[test]
fn dense_smooth_data_has_no_untrusted_quadric() {
    let pts = positions(&torus().samples(40_000, 5));
    let t = Target::from_points(&pts, None, &TargetOptions::default()).unwrap();
    assert_eq!(t.stats().untrusted_quadrics, 0);
}

/// A torus sampled with a hole on its inner (saddle) side, where one-sided extrapolation of a
/// jet is poorest: queries on and near the true surface over the hole.
#[test]
fn foot_points_over_a_sampling_gap_follow_the_true_surface() {
    let shape = torus();
    // Hole: every sample within `hole` of the inner equator point (0.2, 0, 0).
    let centre = [shape.big - shape.small, 0.0, 0.0];
    let hole = 0.06;
    let pts: Vec<[f64; 3]> = positions(&shape.samples(40_000, 7))
        .into_iter()
        .filter(|p| norm(sub(*p, centre)) > hole)
        .collect();
    let t = Target::from_points(&pts, None, &TargetOptions::default()).unwrap();
    let s = t.normalization().scale;
    let mut r = rng(11);
    let (mut worst_blend, mut worst_near) = (0.0f64, 0.0f64);
    let (mut sq_blend, mut sq_near, mut n) = (0.0, 0.0, 0usize);
    while n < 400 {
        let q = shape.sample(&mut r);
        if norm(sub(q.p, centre)) > 0.8 * hole {
            continue;
        }
        for d in [-0.01, 0.0, 0.01] {
            let x = add(q.p, scale(q.n, d));
            let truth = norm(sub(x, shape.closest(x))) * s;
            let xn = t.to_normalized(x);
            let f = t.foot_point(xn);
            let e_blend = (f.distance.abs() - truth).abs();
            let e_near = (nearest_quadric_distance(&t, xn).abs() - truth).abs();
            worst_blend = worst_blend.max(e_blend);
            worst_near = worst_near.max(e_near);
            sq_blend += e_blend * e_blend;
            sq_near += e_near * e_near;
            assert!(f.distance.is_finite() && f.point.iter().all(|v| v.is_finite()));
        }
        n += 1;
    }
    let rms = |s: f64| (s / (3 * n) as f64).sqrt();
    println!(
        "hole of radius {:.3} (normalized): distance error max {worst_blend:.2e} rms {:.2e} \
         blended; max {worst_near:.2e} rms {:.2e} nearest quadric alone",
        hole * s,
        rms(sq_blend),
        rms(sq_near)
    );
    assert!(worst_blend < worst_near, "{worst_blend} vs {worst_near}");
    assert!(rms(sq_blend) < rms(sq_near));
}
