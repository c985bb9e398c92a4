//! The error power of the foot-point term (IRLS weights) and the stages' last step, the polish
//! of the best cage towards a lower maximum error; and the stages going on at a spent budget
//! while a stage's fit runs out of iterations with a gain.

#![allow(clippy::print_stdout)]

mod common;

use subfit_fit::{
    fit_stages, DataTerm, FitOptions, FootPointSource, FootPointTerm, FootSample, Method,
    StageOptions, StagesResult, POWER_WEIGHT_MAX, POWER_WEIGHT_MIN,
};
use subfit_mesh::shapes::torus_mesh;
use subfit_target::{Target, TargetOptions};

use common::normalized;

/// With error power `p`, each sample of a projection over all samples is weighted
/// `(e / r)^(p−2)`, clamped, `r` the RMS error of the term's first such projection — also for
/// later projections, so the objective is a function of the positions alone.
#[test]
fn the_error_power_weights_samples_by_their_error_over_the_first_rms() {
    let torus = torus_mesh(0.35, 0.15, 96, 48, true);
    let target = Target::from_mesh(&torus, &TargetOptions::default()).unwrap();
    // Points straight above the tube's outer equator, at growing heights: the foot point is
    // the equator point below, the error the height.
    let (rt, rtube) = (0.35, 0.15);
    let heights: Vec<f64> = (0..40).map(|k| 1e-3 * (k as f64 + 0.5)).collect();
    let points = |scale: f64| -> Vec<[f64; 3]> {
        heights
            .iter()
            .enumerate()
            .map(|(k, h)| {
                let a = k as f64 * 0.15;
                let r = rt + rtube + scale * h;
                target.to_normalized([r * a.cos(), r * a.sin(), 0.0])
            })
            .collect()
    };
    for p in [3.0, 4.0] {
        let term = FootPointTerm::new(&target, Method::Sdm, FootPointSource::Auto).with_power(p);
        let xs = points(1.0);
        let first = term.project(None, &xs);
        let e2: Vec<f64> = first
            .iter()
            .zip(&xs)
            .map(|(f, &x)| term.squared_error(f, x))
            .collect();
        let r2 = e2.iter().sum::<f64>() / e2.len() as f64;
        // The weight the module docs give an error `e` (squared), against `f`'s.
        let check = |f: &FootSample, e: f64| -> f64 {
            let w = (e / r2)
                .powf(0.5 * (p - 2.0))
                .clamp(POWER_WEIGHT_MIN, POWER_WEIGHT_MAX);
            assert!(
                (f.weight - w).abs() <= 1e-12 * w,
                "p {p}: {} vs {w}",
                f.weight
            );
            w
        };
        for ((f, &e), &x) in first.iter().zip(&e2).zip(&xs) {
            let w = check(f, e);
            let obj = term.objective_error(f, x);
            assert!((obj - w * e).abs() <= 1e-12 * obj.max(1e-300));
        }
        assert!(first.iter().any(|f| f.weight < 0.5) && first.iter().any(|f| f.weight > 1.5));
        // A second projection, every error doubled: weighed against the first RMS.
        let xs2 = points(2.0);
        let second = term.project(None, &xs2);
        for (f, &x) in second.iter().zip(&xs2) {
            check(f, term.squared_error(f, x));
        }
    }
    // Least squares weighs nothing.
    let term = FootPointTerm::new(&target, Method::Sdm, FootPointSource::Auto);
    assert!(term
        .project(None, &points(1.0))
        .iter()
        .all(|f| f.weight == 1.0));
}

/// A torus (radii 0.35 and 0.15) with three bumps on its tube (heights 0.03–0.05, widths
/// 0.05–0.08), as a mesh target, and a 12 × 6 triangle cage of the plain torus (72 points) at
/// a budget of 72: nothing to refine, and the bumps are too narrow for the cage, so the
/// least-squares fit leaves its largest errors there.
fn budget_fit(polish_power: f64) -> StagesResult {
    budget_fit_with(polish_power, StageOptions::default().iterations_per_stage)
}

/// [`budget_fit`] with `iterations` per stage.
fn budget_fit_with(polish_power: f64, iterations: usize) -> StagesResult {
    let (rt, rtube) = (0.35, 0.15);
    let mut torus = torus_mesh(rt, rtube, 160, 80, true);
    let bumps = [
        ([rt + rtube, 0.0, 0.0], 0.05, 0.06),
        ([-rt, 0.0, rtube], 0.03, 0.08),
        ([0.0, -rt + rtube * 0.5, rtube * 0.87], 0.04, 0.05),
    ];
    for p in &mut torus.positions {
        let u = p[1].atan2(p[0]);
        let c = [rt * u.cos(), rt * u.sin(), 0.0];
        let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let mut h = 0.0;
        for (b, height, width) in &bumps {
            let q: f64 = (0..3).map(|a| (p[a] - b[a]).powi(2)).sum();
            h += height * (-q / (width * width)).exp();
        }
        for a in 0..3 {
            p[a] += h * d[a] / l;
        }
    }
    let target = Target::from_mesh(&torus, &TargetOptions::default()).unwrap();
    let mesh = normalized(&target, &torus_mesh(rt, rtube, 12, 6, true));
    let stages = StageOptions {
        tolerance_rms: 1e-5,
        max_control_points: mesh.num_vertices(),
        polish_power,
        iterations_per_stage: iterations,
        ..StageOptions::default()
    };
    fit_stages(&target, &mesh, &FitOptions::default(), &stages, None).unwrap()
}

/// The polish with `p = 3` lowers the largest error (both ways) of a cage at its budget by
/// more than its threshold, at the RMS cost it allows, and the polished cage is what is
/// returned; the stages before it are those of a fit without it.
#[test]
fn the_polish_lowers_the_largest_error_of_a_cage_at_its_budget() {
    let plain = budget_fit(2.0);
    let polished = budget_fit(3.0);
    let (a, b) = (&plain.report, &polished.report);
    assert!(a.stages.iter().all(|s| s.polish.is_none()));
    let last = b.stages.last().unwrap();
    assert_eq!(last.polish, Some(true), "{:?}", last.two_sided);
    assert_eq!(b.stages.len(), a.stages.len() + 1);
    assert_eq!(b.best_stage, b.stages.len() - 1);
    let (max0, max1) = (a.two_sided.max(), b.two_sided.max());
    let (rms0, rms1) = (a.two_sided.rms(), b.two_sided.rms());
    println!("max {max0:.4e} -> {max1:.4e}, rms {rms0:.4e} -> {rms1:.4e}");
    assert!(
        max1 < (1.0 - subfit_fit::polish::POLISH_MIN_GAIN) * max0,
        "max {max0} -> {max1}"
    );
    assert!(
        rms1 <= (1.0 + subfit_fit::polish::POLISH_RMS_SLACK) * rms0,
        "rms {rms0} -> {rms1}"
    );
    assert_eq!(polished.mesh.faces, plain.mesh.faces);
    assert_ne!(polished.mesh.positions, plain.mesh.positions);
}

/// With the budget spent from the start, a stage at the end of the `λ` schedule whose fit ran
/// out of iterations with a gain is followed by another at the same `λ` (before, the stages
/// ended with the schedule).
#[test]
fn a_spent_budget_goes_on_while_a_stage_runs_out_of_iterations_with_a_gain() {
    // Three iterations a stage, so that stages end with a gain left (with six, the pull over
    // uncovered data lets this case stall within each stage).
    let out = budget_fit_with(2.0, 3);
    let r = &out.report;
    let stages = StageOptions::default();
    let rows: Vec<_> = r
        .stages
        .iter()
        .map(|s| {
            (
                s.lambda,
                s.fit.iterations.len(),
                format!("{:?}", s.fit.stop),
            )
        })
        .collect();
    let at_end: Vec<usize> = (0..r.stages.len())
        .filter(|&k| r.stages[k].lambda <= stages.lambda_end)
        .collect();
    assert!(
        at_end.len() >= 2,
        "the case must go past the λ schedule: {rows:?}"
    );
    for &k in &at_end[1..] {
        assert_eq!(
            format!("{:?}", r.stages[k - 1].fit.stop),
            "MaxIterations",
            "{rows:?}"
        );
    }
}
