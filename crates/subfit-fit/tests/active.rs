//! Active sets (`Fitter::set_active`): with every point active the fit is the normal one; with
//! a subset the inactive points do not move, the objective does not increase, fewer samples
//! are worked on, and the reported errors are still those of the whole surface.

mod common;

use subfit_fit::{FitError, FitOptions, FitReport, Fitter, Variant};
use subfit_mesh::PolyMesh;
use subfit_target::Target;

fn setup() -> (Target, PolyMesh) {
    let target = common::ellipsoid_target(6_000);
    let mesh = common::normalized(&target, &common::fourteen_vertex_mesh());
    (target, mesh)
}

fn options(v: Variant) -> FitOptions {
    FitOptions::variant(v)
        .with_lambda(1e-3)
        .with_max_iterations(4)
}

fn run<'t>(
    target: &'t Target,
    mesh: &PolyMesh,
    opts: &FitOptions,
    active: Option<Vec<bool>>,
) -> (Vec<[f64; 3]>, FitReport, Fitter<'t>) {
    let mut fitter = Fitter::new(target, &mesh.faces, mesh.num_vertices(), opts).expect("fitter");
    fitter.set_active(active).expect("active set");
    let mut p = mesh.positions.clone();
    let report = fitter.run(&mut p, None).expect("fit");
    (p, report, fitter)
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(1e-300)
}

#[test]
fn all_active_equals_the_full_problem() {
    let (target, mesh) = setup();
    for v in [Variant::SdmLm, Variant::PdmSc, Variant::Tdm] {
        let opts = options(v);
        let (p_full, r_full, _) = run(&target, &mesh, &opts, None);
        let all = vec![true; mesh.num_vertices()];
        let (p_act, r_act, f) = run(&target, &mesh, &opts, Some(all));
        assert_eq!(f.num_active_samples(), f.num_samples());
        assert_eq!(r_full.iterations.len(), r_act.iterations.len(), "{v:?}");
        assert!(r_full.last().objective < r_full.initial.objective, "{v:?}");
        let scale = p_full.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
        for (a, b) in p_full.iter().flatten().zip(p_act.iter().flatten()) {
            assert!((a - b).abs() <= 1e-12 * scale, "{v:?}: {a} vs {b}");
        }
        for (a, b) in r_full.iterations.iter().zip(&r_act.iterations) {
            assert_eq!(a.accepted, b.accepted);
            assert!(
                rel(a.errors.objective, b.errors.objective) <= 1e-12,
                "{v:?}"
            );
            assert!(rel(a.errors.e_max, b.errors.e_max) <= 1e-12, "{v:?}");
        }
    }
}

#[test]
fn subset_keeps_inactive_points_and_decreases_the_objective() {
    let (target, mesh) = setup();
    // The points of the upper half (normalized z above the centre of the cage) are active.
    let zc = mesh.positions.iter().map(|p| p[2]).sum::<f64>() / mesh.num_vertices() as f64;
    let mask: Vec<bool> = mesh.positions.iter().map(|p| p[2] > zc).collect();
    assert!(mask.contains(&true) && mask.contains(&false));
    for v in [Variant::SdmLm, Variant::SdmSc] {
        let opts = options(v);
        let (p, report, fitter) = run(&target, &mesh, &opts, Some(mask.clone()));
        assert!(fitter.num_active_samples() < fitter.num_samples(), "{v:?}");
        for ((p, p0), &act) in p.iter().zip(&mesh.positions).zip(&mask) {
            if !act {
                assert_eq!(p, p0, "{v:?}: an inactive point moved");
            }
        }
        assert!(
            p.iter().zip(&mesh.positions).any(|(p, p0)| p != p0),
            "{v:?}: nothing moved"
        );
        let mut prev = report.initial.objective;
        for row in &report.iterations {
            assert!(row.errors.objective <= prev, "{v:?}: objective increased");
            prev = row.errors.objective;
        }
        assert!(report.last().objective < report.initial.objective, "{v:?}");
        // Reported errors are over the whole surface: equal to a full evaluation.
        for (reported, control) in [(report.initial, &mesh.positions), (report.last(), &p)] {
            let full = fitter.evaluate(control);
            assert!(rel(reported.objective, full.objective) <= 1e-12, "{v:?}");
            assert!(rel(reported.e_rms, full.e_rms) <= 1e-12, "{v:?}");
            assert!(rel(reported.e_max, full.e_max) <= 1e-12, "{v:?}");
        }
    }
}

/// Alternating masks on one fitter: the cached errors of the fixed samples follow points
/// moved by the previous run, so the reported errors stay exact; `None` returns to the full
/// problem.
#[test]
fn changing_the_mask_keeps_the_errors_exact() {
    let (target, mesh) = setup();
    let opts = options(Variant::SdmLm).with_max_iterations(2);
    let mut fitter = Fitter::new(&target, &mesh.faces, mesh.num_vertices(), &opts).expect("fitter");
    let n = mesh.num_vertices();
    let mut p = mesh.positions.clone();
    let first: Vec<bool> = (0..n).map(|i| i % 2 == 0).collect();
    fitter.set_active(Some(first.clone())).expect("mask");
    let r1 = fitter.run(&mut p, None).expect("fit");
    // Now move the other half: the cache of fixed samples must follow the moved points.
    let second: Vec<bool> = first.iter().map(|b| !b).collect();
    fitter.set_active(Some(second.clone())).expect("mask");
    let before = p.clone();
    let r2 = fitter.run(&mut p, None).expect("fit");
    assert!(rel(r2.initial.objective, r1.last().objective) <= 1e-12);
    assert!(rel(r2.initial.objective, fitter.evaluate(&before).objective) <= 1e-12);
    assert!(rel(r2.last().objective, fitter.evaluate(&p).objective) <= 1e-12);
    for ((a, b), &act) in p.iter().zip(&before).zip(&second) {
        if !act {
            assert_eq!(a, b);
        }
    }
    // Back to the full problem.
    fitter.set_active(None).expect("none");
    assert_eq!(fitter.active(), None);
    let r3 = fitter.run(&mut p, None).expect("fit");
    assert!(r3.last().objective <= r2.last().objective);
}

#[test]
fn bad_masks_are_typed_errors() {
    let (target, mesh) = setup();
    let mut fitter = Fitter::new(
        &target,
        &mesh.faces,
        mesh.num_vertices(),
        &options(Variant::SdmLm),
    )
    .expect("fitter");
    let n = mesh.num_vertices();
    assert!(matches!(
        fitter.set_active(Some(vec![true; n + 1])),
        Err(FitError::BadInput(_))
    ));
    assert!(matches!(
        fitter.set_active(Some(vec![false; n])),
        Err(FitError::BadInput(_))
    ));
    assert_eq!(fitter.active(), None);
}

/// Solves the dense system `a x = b` (`a` row-major `d × d`) by Gaussian elimination with
/// partial pivoting.
fn dense_solve(mut a: Vec<f64>, mut b: Vec<f64>) -> Vec<f64> {
    let d = b.len();
    for c in 0..d {
        let p = (c..d)
            .max_by(|&i, &j| a[i * d + c].abs().total_cmp(&a[j * d + c].abs()))
            .expect("rows");
        for k in 0..d {
            a.swap(c * d + k, p * d + k);
        }
        b.swap(c, p);
        for r in c + 1..d {
            let f = a[r * d + c] / a[c * d + c];
            for k in c..d {
                a[r * d + k] -= f * a[c * d + k];
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = vec![0.0; d];
    for r in (0..d).rev() {
        let s: f64 = (r + 1..d).map(|k| a[r * d + k] * x[k]).sum();
        x[r] = (b[r] - s) / a[r * d + r];
    }
    x
}

/// One SDM step (no step control, no ridge) over a subset equals the elimination of the fixed
/// variables from the full model, built independently: `H_aa δ_a = −g_a` with `H` and `g` of
/// the whole problem (smoothing included) assembled by `Pattern` and solved densely.
#[test]
fn subset_step_solves_the_eliminated_full_system() {
    use subfit_fit::internals::{error_matrix, weighted_residuals, Laplacian, Pattern};
    use subfit_fit::Method;

    let (target, mesh) = setup();
    let n = mesh.num_vertices();
    let lambda = 1e-2;
    let opts = FitOptions {
        ridge: 0.0,
        ..FitOptions::variant(Variant::Sdm)
            .with_lambda(lambda)
            .with_max_iterations(1)
    };
    let mask: Vec<bool> = (0..n).map(|i| i % 3 != 0).collect();
    let (p, _, fitter) = run(&target, &mesh, &opts, Some(mask.clone()));

    let p0 = &mesh.positions;
    let op = &fitter.sampling_operator().position;
    let s = op.apply(p0);
    let feet = fitter.term().foot_points(&s);
    let q: Vec<_> = feet.iter().map(|f| error_matrix(Method::Sdm, f)).collect();
    let v: Vec<[f64; 3]> = feet.iter().map(|f| f.point).collect();
    let pattern = Pattern::new(op, &Laplacian::umbrella(&mesh.faces, n), 3);
    let mut values = vec![0.0; pattern.nnz()];
    let (w_e, w_s) = (1.0 / s.len() as f64, lambda / n as f64);
    pattern.fill(op, &q, w_e, w_s, &mut values);
    let g = pattern.gradient(&weighted_residuals(&s, &v, Some(&q)), p0, w_e, w_s);

    let act: Vec<usize> = (0..n).filter(|&i| mask[i]).collect();
    let mut local = vec![usize::MAX; 3 * n];
    for (l, &i) in act.iter().enumerate() {
        for a in 0..3 {
            local[3 * i + a] = 3 * l + a;
        }
    }
    let d = 3 * act.len();
    let mut h = vec![0.0; d * d];
    for (r, c, x) in pattern.triplets(&values) {
        let (lr, lc) = (local[r], local[c]);
        if lr != usize::MAX && lc != usize::MAX {
            h[lr * d + lc] = x;
            h[lc * d + lr] = x;
        }
    }
    let rhs: Vec<f64> = act.iter().flat_map(|&i| g[i].map(|x| -x)).collect();
    let delta = dense_solve(h, rhs);
    let scale = delta.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    assert!(scale > 0.0);
    for (l, &i) in act.iter().enumerate() {
        for a in 0..3 {
            let step = p[i][a] - p0[i][a];
            assert!(
                (step - delta[3 * l + a]).abs() <= 1e-9 * scale,
                "point {i}: {step} vs {}",
                delta[3 * l + a]
            );
        }
    }
}
