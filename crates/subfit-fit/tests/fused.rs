//! The fused fill + gradient (`Pattern::fill_with_gradient`, grouped by shared support) equals
//! the separate fill and gradient, and is bitwise identical on 1 and 2 threads.

mod common;

use subfit_fit::internals::{error_matrix, weighted_residuals, FillScratch, Laplacian, Pattern};
use subfit_fit::{Mat3, Method};
use subfit_mesh::Tags;
use subfit_subdiv::{sampling_operator, Options, Scheme};

type System = (Vec<f64>, Vec<[f64; 3]>, Vec<f64>, Vec<[f64; 3]>);

/// (fused values, fused gradient, separate values, separate gradient) on the ellipsoid's
/// 14-vertex cage, SD, sample level `level`, λ = 1e-2.
fn systems(level: usize) -> System {
    let target = common::ellipsoid_target(4_000);
    let m = common::normalized(&target, &common::fourteen_vertex_mesh());
    let n = m.num_vertices();
    let op = sampling_operator(
        &m.faces,
        n,
        &Tags::new(),
        &Options::new(Scheme::Loop),
        level,
    )
    .expect("operator");
    let s = op.position.apply(&m.positions);
    let feet = target.foot_points(&s);
    let q: Vec<Mat3> = feet.iter().map(|f| error_matrix(Method::Sdm, f)).collect();
    let v: Vec<[f64; 3]> = feet.iter().map(|f| f.point).collect();
    let r = weighted_residuals(&s, &v, Some(&q));
    let pattern = Pattern::new(&op.position, &Laplacian::umbrella(&m.faces, n), 3);
    let (w_e, w_s) = (1.0 / s.len() as f64, 1e-2 / n as f64);
    let mut fused = vec![0.0; pattern.nnz()];
    let mut scratch = FillScratch::default();
    let g_fused = pattern.fill_with_gradient(
        &op.position,
        &q,
        &r,
        &m.positions,
        w_e,
        w_s,
        &mut fused,
        &mut scratch,
    );
    let mut separate = vec![0.0; pattern.nnz()];
    pattern.fill(&op.position, &q, w_e, w_s, &mut separate);
    let g = pattern.gradient(&r, &m.positions, w_e, w_s);
    (fused, g_fused, separate, g)
}

#[test]
fn fused_fill_and_gradient_match_the_separate_ones() {
    for level in [1, 3] {
        let (h1, g1, h2, g2) = systems(level);
        let hmax = h2.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for (a, b) in h1.iter().zip(&h2) {
            assert!((a - b).abs() <= 1e-12 * hmax, "H: {a} vs {b}");
        }
        let gmax = g2.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
        assert!(gmax > 0.0);
        for (a, b) in g1.iter().flatten().zip(g2.iter().flatten()) {
            assert!((a - b).abs() <= 1e-12 * gmax, "g: {a} vs {b}");
        }
    }
}

#[test]
fn fused_fill_is_bitwise_deterministic_across_thread_counts() {
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| systems(3))
    };
    let (h1, g1, _, _) = run(1);
    let (h2, g2, _, _) = run(2);
    assert!(h1.iter().zip(&h2).all(|(a, b)| a.to_bits() == b.to_bits()));
    assert!(g1
        .iter()
        .flatten()
        .zip(g2.iter().flatten())
        .all(|(a, b)| a.to_bits() == b.to_bits()));
}
