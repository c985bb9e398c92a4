//! The stage driver's local option: after a refinement, optimize only the new and neighbouring
//! control points when the rest already fits (Cheng et al. 2004 §4.5, local subdivision).

mod common;

use subfit_fit::internals::refine_red_green;
use subfit_fit::{
    fit_stages, FitOptions, Fitter, StageOptions, StageStop, REFINE_PAYOFF, STALL_GAIN,
    STALL_STAGES, UNPAID_REFINEMENTS,
};
use subfit_mesh::shapes::Shape;
use subfit_target::{Target, TargetOptions};

use common::{ellipsoid_target, fourteen_vertex_mesh, normalized};

/// With `local`, stages after a small refinement optimize only the region around it; the
/// errors they report are still those of the whole surface, and the fit still improves.
#[test]
fn local_stages_optimize_a_region_and_report_whole_surface_errors() {
    let target = ellipsoid_target(20_000);
    // Two uniform 1-to-4 splits of the 14-point cage (194 points): large enough that a
    // refinement touches a small part of it.
    let mut mesh = normalized(&target, &fourteen_vertex_mesh());
    for _ in 0..2 {
        mesh = refine_red_green(&mesh, &vec![true; mesh.faces.len()])
            .unwrap()
            .0;
    }
    let base = FitOptions {
        sample_level: 3,
        ..FitOptions::default()
    };
    let stages = StageOptions {
        tolerance_rms: 1e-5,
        max_control_points: 400,
        growth: 0.1,
        max_stages: 10,
        local: true,
        local_rings: 1,
        ..StageOptions::default()
    };
    let out = fit_stages(&target, &mesh, &base, &stages, None).unwrap();
    let r = &out.report;
    let local: Vec<(usize, usize)> = r
        .stages
        .iter()
        .filter_map(|s| s.active_points.map(|a| (a, s.num_control_points)))
        .collect();
    let summary: Vec<_> = r
        .stages
        .iter()
        .map(|s| (s.num_control_points, s.active_points))
        .collect();
    assert!(!local.is_empty(), "no stage was local: {summary:?}");
    for &(active, all) in &local {
        assert!(
            active > 0 && 2 * active <= all,
            "{active} of {all} points active"
        );
    }
    // The first stage is always global (nothing changed before it).
    assert!(r.stages[0].active_points.is_none());
    // Every local stage's errors are over the whole surface: the final report equals a fresh
    // full evaluation of the returned cage.
    let lambda = r.stages.last().unwrap().lambda;
    let opts = FitOptions { lambda, ..base };
    let fresh = Fitter::new(&target, &out.mesh.faces, out.mesh.num_vertices(), &opts)
        .unwrap()
        .evaluate(&out.mesh.positions);
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1e-300);
    assert!(
        rel(r.last.e_rms, fresh.e_rms) < 1e-9,
        "{:?} vs {fresh:?}",
        r.last
    );
    assert!(
        rel(r.last.e_max, fresh.e_max) < 1e-9,
        "{:?} vs {fresh:?}",
        r.last
    );
    assert!(
        r.last.e_rms < 0.5 * r.initial.e_rms,
        "{:?} → {:?}",
        r.initial,
        r.last
    );
}

/// Without `local` no stage is restricted.
#[test]
fn stages_are_global_by_default() {
    let target = ellipsoid_target(5_000);
    let mesh = normalized(&target, &fourteen_vertex_mesh());
    let stages = StageOptions {
        max_control_points: 100,
        max_stages: 4,
        ..StageOptions::default()
    };
    let out = fit_stages(&target, &mesh, &FitOptions::default(), &stages, None).unwrap();
    assert!(out.report.stages.iter().all(|s| s.active_points.is_none()));
}

/// Data no surface of the cage reaches — a small patch of points far beyond the ellipsoid's
/// tip, fitted one-sided so nothing pulls the surface toward it — keeps data → surface E_max
/// above its tolerance whatever refinement does: the driver gives up [`STALL_STAGES`] stages
/// after its last gain of more than [`STALL_GAIN`] instead of refining on to the budget, and
/// returns the best cage.
#[test]
fn stages_give_up_when_no_stage_improves_on_the_best() {
    let cloud = Shape::PAPER_ELLIPSOID.sample(8_000, 0.0, 7);
    let mut points = cloud.positions.clone();
    let mut normals = cloud.normals.clone().unwrap();
    // A 12 × 12 patch of points, 0.02 wide, facing +z, at twice the ellipsoid's height.
    for i in 0..12 {
        for j in 0..12 {
            points.push([0.02 * i as f64 / 11.0, 0.02 * j as f64 / 11.0, 2.0]);
            normals.push([0.0, 0.0, 1.0]);
        }
    }
    let target = Target::from_points(&points, Some(&normals), &TargetOptions::default()).unwrap();
    let mesh = normalized(&target, &fourteen_vertex_mesh());
    let stages = StageOptions {
        tolerance_rms: 1e-5,
        tolerance_max: 1e-3,
        max_control_points: 100_000,
        max_stages: 40,
        // The stall rule is the stage loop's; the polish after it has its own test.
        polish_power: 2.0,
        // So is the rule on refinements that do not pay (its own test below).
        refine_payoff: 0.0,
        ..StageOptions::default()
    };
    let out = fit_stages(&target, &mesh, &FitOptions::default(), &stages, None).unwrap();
    let r = &out.report;
    let summary: Vec<_> = r
        .stages
        .iter()
        .map(|s| (s.num_control_points, s.two_sided.data_to_surface.max))
        .collect();
    assert_eq!(r.stop, StageStop::Stalled, "{summary:?}");
    // The stall counts from the last stage that gained more than STALL_GAIN (the badness is
    // the data → surface E_max over its tolerance here); the best may come after it.
    let mut base = f64::INFINITY;
    let mut last_gain = 0;
    for (k, &(_, e)) in summary.iter().enumerate() {
        if e < base * (1.0 - STALL_GAIN) {
            base = e;
            last_gain = k;
        }
    }
    assert_eq!(r.stages.len(), last_gain + 1 + STALL_STAGES, "{summary:?}");
    assert!(r.best_stage >= last_gain, "{summary:?}");
    assert_eq!(
        out.mesh.num_vertices(),
        r.stages[r.best_stage].num_control_points,
        "the best cage is returned"
    );
}

/// A noisy cloud (an ellipsoid, 6,000 points with Gaussian noise of 0.01) under a tolerance far
/// below its noise: refinement only fits the noise, and the error creeps down by about a
/// percent per stage, then by hundredths of one. The driver stops [`STALL_STAGES`] stages after
/// the last stage that gained more than [`STALL_GAIN`] (15 stages, 1,586 control points),
/// not after the last stage that gained at all (19 stages with a gain of 0).
#[test]
fn stages_give_up_when_the_gain_is_below_the_stall_gain() {
    let (out, rms, _) = noisy_ellipsoid_stages(6_000, 0.01, 3_000);
    let r = &out.report;
    let summary: Vec<_> = r
        .stages
        .iter()
        .zip(&rms)
        .map(|(s, e)| (s.num_control_points, *e))
        .collect();
    assert_eq!(r.stop, StageStop::Stalled, "{summary:?}");
    // The last stage that gained more than STALL_GAIN, and the last that gained at all.
    let (mut base, mut last_gain) = (f64::INFINITY, 0);
    let (mut lowest, mut last_better) = (f64::INFINITY, 0);
    for (k, &e) in rms.iter().enumerate() {
        if e < base * (1.0 - STALL_GAIN) {
            (base, last_gain) = (e, k);
        }
        if e < lowest {
            (lowest, last_better) = (e, k);
        }
    }
    assert_eq!(rms.len(), last_gain + 1 + STALL_STAGES, "{summary:?}");
    // Counting every gain, however small, the driver would have gone on.
    assert!(rms.len() < last_better + 1 + STALL_STAGES, "{summary:?}");
}

/// The same noisy ellipsoid with the rule on refinements that do not pay
/// ([`StageOptions::refine_payoff`] at its default, [`REFINE_PAYOFF`]): the fit ends
/// ([`StageStop::Diminishing`]) at the second refinement in a row that lowers the RMS by less
/// than `n^−0.15`, far below the budget, where the stall rule alone spent 15 stages and 1,586
/// points. (A clean surface under an unreachable tolerance refines on: the local-stages test
/// above stops by the stall rule with this rule on.)
#[test]
fn stages_end_when_refinement_stops_paying() {
    let (out, rms, stages) = noisy_ellipsoid_stages_paying(6_000, 0.01, 3_000, REFINE_PAYOFF);
    let r = &out.report;
    let summary: Vec<_> = r
        .stages
        .iter()
        .zip(&rms)
        .map(|(s, e)| (s.num_control_points, *e))
        .collect();
    assert_eq!(r.stop, StageStop::Diminishing, "{summary:?}");
    // Replay the rule: refinements (stages with more points than the one before) that do not
    // pay, counted in a row; the fit ends at the first second one.
    let mut unpaid = 0;
    let mut end = None;
    for (k, w) in summary.windows(2).enumerate() {
        let ((n0, r0), (n1, r1)) = (w[0], w[1]);
        if n1 > n0 {
            let paid = r1 <= r0 * (n0 as f64 / n1 as f64).powf(REFINE_PAYOFF);
            unpaid = if paid { 0 } else { unpaid + 1 };
        }
        if unpaid == UNPAID_REFINEMENTS {
            end = Some(k + 1);
            break;
        }
    }
    assert_eq!(end, Some(summary.len() - 1), "{summary:?}");
    let last = summary.last().unwrap().0;
    assert!(last < stages.max_control_points / 4, "{summary:?}");
}

/// A fit that is of use only if it meets its tolerance within the budget
/// ([`StageOptions::must_reach`]: a start after one that did) stops at the first stage with `λ`
/// at its end from which even the best rate of approximation needs more points than the
/// budget ([`StageStop::Hopeless`]), before it spends the budget; a tolerance it can reach is
/// reached as without the rule.
#[test]
fn a_fit_that_must_reach_its_tolerance_stops_when_it_cannot() {
    // The noisy ellipsoid under a tolerance far below its noise (1e-5 against 2e-3).
    let (plain, _, _) = noisy_ellipsoid_stages(20_000, 0.002, 150);
    let (out, _, stages) = noisy_ellipsoid_stages_with(20_000, 0.002, 150, |s| s.must_reach = true);
    let r = &out.report;
    assert_eq!(r.stop, StageStop::Hopeless);
    assert!(r.stages.len() < plain.report.stages.len());
    let last = r.stages.last().unwrap();
    assert!(last.lambda <= stages.lambda_end);
    let n = last.num_control_points;
    assert!(n < stages.max_control_points, "stopped at {n} points");
    let need = stages.points_to_reach(&last.fit.last(), &last.two_sided, n);
    assert!(need > stages.max_control_points as f64, "{need}");
    // A tolerance within reach: the same fit with and without the rule.
    let loose = |s: &mut StageOptions| s.tolerance_rms = 4e-3;
    let (a, _, _) = noisy_ellipsoid_stages_with(20_000, 0.002, 150, loose);
    let (b, _, _) = noisy_ellipsoid_stages_with(20_000, 0.002, 150, |s| {
        loose(s);
        s.must_reach = true;
    });
    assert_eq!(a.report.stop, StageStop::Tolerance);
    assert_eq!(a.report.stages.len(), b.report.stages.len());
    assert_eq!(a.mesh.positions, b.mesh.positions);
}

/// With the control-point budget spent and `λ` at its end, a stage only flips edges: the first
/// such stage that does not gain more than [`STALL_GAIN`] over the last stage that did ends the
/// fit ([`StageStop::Budget`]), where before it went on as long as any stage gained at all (the
/// noisy Lucy: 0.1 % for its last 7 s). A noisy ellipsoid (20,000 points, noise 0.002) under a
/// tolerance far below its noise spends a budget of 55 in 4 stages; its 5th, at 55 points,
/// gains 0.1 %. (With a budget of 150 it now stops Stalled at 148 points first: measured to the
/// data's local surface, its error is at the noise's floor from 55 points on.)
#[test]
fn a_spent_budget_ends_at_the_first_stage_without_a_real_gain() {
    let (out, rms, stages) = noisy_ellipsoid_stages(20_000, 0.002, 55);
    let r = &out.report;
    let summary: Vec<_> = r
        .stages
        .iter()
        .zip(&rms)
        .map(|(s, e)| (s.num_control_points, s.lambda, *e))
        .collect();
    assert_eq!(r.stop, StageStop::Budget, "{summary:?}");
    // The first stage with the budget spent and λ at its end that gains no more than
    // STALL_GAIN over the last stage that did is the last stage.
    let mut base = f64::INFINITY;
    let mut end = None;
    for (k, &(n, lambda, e)) in summary.iter().enumerate() {
        let gained = e < base * (1.0 - STALL_GAIN);
        if gained {
            base = e;
        }
        if n >= stages.max_control_points && lambda <= stages.lambda_end && !gained {
            end = Some(k);
            break;
        }
    }
    assert_eq!(Some(r.stages.len() - 1), end, "{summary:?}");
    assert!(out.mesh.num_vertices() <= stages.max_control_points);
}

/// Stages on a noisy sample of the paper ellipsoid (`points`, Gaussian noise `noise` × the
/// diagonal, seed 5) from the 14-point cage, under a tolerance far below the noise, with the
/// budget `budget`: the result, each stage's judged two-sided RMS, and the stage options.
fn noisy_ellipsoid_stages(
    points: usize,
    noise: f64,
    budget: usize,
) -> (subfit_fit::StagesResult, Vec<f64>, StageOptions) {
    noisy_ellipsoid_stages_with(points, noise, budget, |_| {})
}

/// [`noisy_ellipsoid_stages`] with [`StageOptions::refine_payoff`] `payoff`.
fn noisy_ellipsoid_stages_paying(
    points: usize,
    noise: f64,
    budget: usize,
    payoff: f64,
) -> (subfit_fit::StagesResult, Vec<f64>, StageOptions) {
    noisy_ellipsoid_stages_with(points, noise, budget, |s| s.refine_payoff = payoff)
}

/// [`noisy_ellipsoid_stages`] with its stage options changed by `change`.
fn noisy_ellipsoid_stages_with(
    points: usize,
    noise: f64,
    budget: usize,
    change: impl FnOnce(&mut StageOptions),
) -> (subfit_fit::StagesResult, Vec<f64>, StageOptions) {
    let cloud = Shape::PAPER_ELLIPSOID.sample(points, noise, 5);
    let target = Target::from_points(
        &cloud.positions,
        cloud.normals.as_deref(),
        &TargetOptions::default(),
    )
    .unwrap();
    let mesh = normalized(&target, &fourteen_vertex_mesh());
    let mut stages = StageOptions {
        tolerance_rms: 1e-5,
        max_control_points: budget,
        max_stages: 40,
        // The stall rules are the stage loop's; the polish after it has its own test.
        polish_power: 2.0,
        refine_payoff: 0.0,
        // The figures in the tests' docs were taken at this depth (at 5 the 150-point budget
        // is not quite spent: the fit stalls at 148).
        max_depth: 4,
        ..StageOptions::default()
    };
    change(&mut stages);
    let out = fit_stages(&target, &mesh, &FitOptions::default(), &stages, None).unwrap();
    let rms = out
        .report
        .stages
        .iter()
        .map(|s| {
            s.two_sided
                .data_to_surface
                .rms
                .max(s.two_sided.surface_to_data.rms)
        })
        .collect();
    (out, rms, stages)
}
