//! The linear solvers agree: Cholesky with each fill-reducing ordering and block-Jacobi PCG
//! solve the same SD system (Cheng 2007 ellipsoid, real foot points); a truncated PCG step keeps
//! the LM gain-ratio identity `rᵀδ = 0`; a fit with the PCG path converges like one with
//! Cholesky.

mod common;

use subfit_fit::internals::{
    block_amd, error_matrix, nested_dissection, BlockGraph, CholeskySolver, Laplacian, Pattern,
    PcgSolver,
};
use subfit_fit::{fit, FitOptions, LinearSolver, Variant};
use subfit_fit::{FillOrdering, Mat3, Method};
use subfit_mesh::{PolyMesh, Tags};
use subfit_subdiv::{refine, sampling_operator, Options, Scheme};

/// A deterministic pseudo-random number in [-1, 1).
fn rnd(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// The 14-vertex ellipsoid mesh refined `k` times (Loop), normalized to the target.
fn mesh(target: &subfit_target::Target, k: usize) -> PolyMesh {
    let mut m = common::normalized(target, &common::fourteen_vertex_mesh());
    for _ in 0..k {
        let r = refine(
            &m.faces,
            m.num_vertices(),
            &Tags::new(),
            &Options::new(Scheme::Loop),
        )
        .unwrap();
        m = PolyMesh::new(r.matrix.apply(&m.positions), r.faces);
    }
    m
}

/// The damped SD system `H + s·I` (λ = 1e-3, `s` = 1e-6 · mean diagonal) at the refined mesh,
/// with a seeded right-hand side. Returns (pattern, values, rhs).
fn sd_system(refinements: usize) -> (Pattern, Vec<f64>, Vec<f64>) {
    let target = common::ellipsoid_target(4_000);
    let m = mesh(&target, refinements);
    let n = m.num_vertices();
    let op = sampling_operator(&m.faces, n, &Tags::new(), &Options::new(Scheme::Loop), 2).unwrap();
    let samples = op.position.apply(&m.positions);
    let q: Vec<Mat3> = target
        .foot_points(&samples)
        .iter()
        .map(|f| error_matrix(Method::Sdm, f))
        .collect();
    let lap = Laplacian::umbrella(&m.faces, n);
    let pattern = Pattern::new(&op.position, &lap, 3);
    let mut values = vec![0.0; pattern.nnz()];
    let ns = samples.len() as f64;
    pattern.fill(&op.position, &q, 1.0 / ns, 1e-3 / n as f64, &mut values);
    let mean = pattern.diag_slots().iter().map(|&s| values[s]).sum::<f64>() / (3 * n) as f64;
    for &s in pattern.diag_slots() {
        values[s] += 1e-6 * mean;
    }
    let mut st = 9u64;
    let rhs: Vec<f64> = (0..3 * n).map(|_| rnd(&mut st)).collect();
    (pattern, values, rhs)
}

/// `A x` from the stored upper triangle.
fn apply(pattern: &Pattern, values: &[f64], x: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; x.len()];
    for (r, c, v) in pattern.triplets(values) {
        y[r] += v * x[c];
        if r != c {
            y[c] += v * x[r];
        }
    }
    y
}

fn norm(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

fn is_permutation(p: &[usize], n: usize) -> bool {
    let mut seen = vec![false; n];
    p.len() == n
        && p.iter()
            .all(|&i| i < n && !std::mem::replace(&mut seen[i], true))
}

#[test]
fn orderings_are_permutations() {
    let (pattern, _, _) = sd_system(2);
    let n = pattern.num_points();
    assert!(is_permutation(&block_amd(&pattern).unwrap(), n));
    let g = BlockGraph::from_pattern(&pattern);
    assert_eq!(g.len(), n);
    for leaf in [1, 8, 64, 10_000] {
        assert!(
            is_permutation(&nested_dissection(&g, leaf), n),
            "leaf {leaf}"
        );
    }
}

/// Every ordering gives the same Cholesky solution (to 1e-10 relative), and PCG run to a
/// relative residual of 1e-12 matches it to 1e-7 relative (the system's condition number is
/// below 1e5 here).
#[test]
fn pcg_and_orderings_match_cholesky() {
    let (pattern, values, rhs) = sd_system(2);
    let solve = |ord: FillOrdering| {
        let mut x = rhs.clone();
        CholeskySolver::with_ordering(ord)
            .solve(&pattern, &values, &mut x, 1)
            .expect("SPD");
        x
    };
    let reference = solve(FillOrdering::ScalarAmd);
    let r = apply(&pattern, &values, &reference);
    let res: Vec<f64> = r.iter().zip(&rhs).map(|(a, b)| a - b).collect();
    assert!(norm(&res) <= 1e-10 * norm(&rhs), "Cholesky residual");
    for ord in [FillOrdering::BlockAmd, FillOrdering::NestedDissection] {
        let x = solve(ord);
        let d: Vec<f64> = x.iter().zip(&reference).map(|(a, b)| a - b).collect();
        assert!(norm(&d) <= 1e-10 * norm(&reference), "{ord:?}");
    }
    let mut x = rhs.clone();
    let stats = PcgSolver::new(&pattern)
        .solve(&pattern, &values, &mut x, 1, 1e-12, 100_000)
        .expect("SPD");
    assert!(stats.relative_residual <= 1e-12, "{stats:?}");
    let d: Vec<f64> = x.iter().zip(&reference).map(|(a, b)| a - b).collect();
    assert!(
        norm(&d) <= 1e-7 * norm(&reference),
        "PCG vs Cholesky: {:e} relative ({stats:?})",
        norm(&d) / norm(&reference)
    );
}

/// Truncated PCG from zero: the residual is orthogonal to the iterate (so the LM predicted
/// decrease `−gᵀδ + s‖δ‖²` is exact) and the step is a descent direction (`bᵀx > 0`).
#[test]
fn truncated_pcg_keeps_the_gain_ratio_identity() {
    let (pattern, values, rhs) = sd_system(2);
    for tol in [0.3, 0.1, 1e-2] {
        let mut x = rhs.clone();
        let stats = PcgSolver::new(&pattern)
            .solve(&pattern, &values, &mut x, 1, tol, 10_000)
            .expect("SPD");
        assert!(stats.iterations >= 1 && stats.relative_residual <= tol);
        let ax = apply(&pattern, &values, &x);
        let r: Vec<f64> = rhs.iter().zip(&ax).map(|(b, a)| b - a).collect();
        // Relative to the model decrease bᵀx, i.e. the relative error of the predicted
        // decrease: rounding erodes the orthogonality (measured 6e-7 at tol 0.1); a warm start
        // or a wrong recurrence would give an error of the order of `tol`.
        assert!(
            dot(&r, &x).abs() <= 1e-5 * dot(&rhs, &x),
            "tol {tol}: rᵀx = {:e}, bᵀx = {:e}",
            dot(&r, &x),
            dot(&rhs, &x)
        );
        assert!(dot(&rhs, &x) > 0.0, "tol {tol}: not a descent direction");
    }
}

/// Cheng 2007 Example 1 with λ = 0 and SDMLM: forced PCG reaches E_rms < 0.002 within 10
/// iterations like Cholesky, and its final E_rms is within 10% of Cholesky's.
#[test]
fn fit_with_pcg_converges_like_cholesky() {
    let target = common::ellipsoid_target(12_000);
    let m = common::normalized(&target, &common::fourteen_vertex_mesh());
    let run = |s: LinearSolver| {
        let opts = FitOptions {
            linear_solver: s,
            pcg_tolerance: 1e-6,
            ..FitOptions::variant(Variant::SdmLm)
                .with_lambda(0.0)
                .with_max_iterations(10)
        };
        fit(&target, &m, &opts).expect("fit").report
    };
    let chol = run(LinearSolver::Cholesky);
    let pcg = run(LinearSolver::Pcg);
    let k = pcg
        .iterations_to_rms(0.002)
        .expect("PCG path reaches 0.002");
    assert!(k <= 10, "PCG path took {k}");
    let (a, b) = (chol.last().e_rms, pcg.last().e_rms);
    assert!((a - b).abs() <= 0.1 * a, "Cholesky {a} vs PCG {b}");
    let mut prev = pcg.initial.objective;
    for row in &pcg.iterations {
        assert!(row.errors.objective <= prev, "objective increased");
        prev = row.errors.objective;
    }
}

/// The whole system (target, foot points, fill) and the PCG solution are bit-identical on 1 and
/// 2 threads (PCG's reductions are summed per fixed chunk, then serially; each column of `H` is
/// filled by one task).
#[test]
fn pcg_is_bitwise_deterministic_across_thread_counts() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let (pattern, values, rhs) = sd_system(2);
            let mut x = rhs.clone();
            PcgSolver::new(&pattern)
                .solve(&pattern, &values, &mut x, 1, 1e-8, 10_000)
                .expect("SPD");
            (values, x)
        })
    };
    let (v1, x1) = run(1);
    let (v2, x2) = run(2);
    assert!(
        v1.iter().zip(&v2).all(|(a, b)| a.to_bits() == b.to_bits()),
        "fill"
    );
    assert!(
        x1.iter().zip(&x2).all(|(a, b)| a.to_bits() == b.to_bits()),
        "PCG"
    );
}
