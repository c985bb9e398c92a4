//! Time per SDM iteration, with the phase breakdown, for control meshes of about 1k and 10k
//! control points on the Cheng 2007 ellipsoid (the 14-vertex mesh of the tests refined 3 and 5
//! times by Loop subdivision: 770 and 12,290 control points).
//!
//! ```text
//! cargo run --release -p subfit-fit --example iteration
//! SUBFIT_POINTS=200000 SUBFIT_SAMPLE_LEVEL=3 SUBFIT_ITERS=5 cargo run --release -p subfit-fit --example iteration
//! ```
//!
//! Environment: `SUBFIT_POINTS` (target points, default 100,000), `SUBFIT_SAMPLE_LEVEL`
//! (default 2), `SUBFIT_ITERS` (default 3), `SUBFIT_REFINE` (comma-separated refinement
//! counts, default `3,5`).
#![allow(clippy::print_stdout)]

use std::time::Instant;

use subfit_fit::{FitOptions, Fitter, Variant};
use subfit_mesh::shapes::{cheng_ellipsoid_cage, Shape};
use subfit_mesh::{PolyMesh, Tags};
use subfit_subdiv::{refine, Options, Scheme};
use subfit_target::{Target, TargetOptions};

fn env(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn main() {
    let points = env("SUBFIT_POINTS", 100_000);
    let level = env("SUBFIT_SAMPLE_LEVEL", 2);
    let iters = env("SUBFIT_ITERS", 3);
    let refines: Vec<usize> = std::env::var("SUBFIT_REFINE")
        .unwrap_or_else(|_| "3,5".into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let t0 = Instant::now();
    let cloud = Shape::PAPER_ELLIPSOID.sample(points, 0.0, 1);
    let target = Target::from_points(
        &cloud.positions,
        cloud.normals.as_deref(),
        &TargetOptions::default(),
    )
    .expect("target");
    println!(
        "target: {} points, built in {:.2?}; threads: {}",
        target.len(),
        t0.elapsed(),
        rayon::current_num_threads()
    );
    for r in refines {
        let mut mesh = cheng_ellipsoid_cage(0.25, 0.5, 1.0, false);
        for _ in 0..r {
            let rf = refine(
                &mesh.faces,
                mesh.num_vertices(),
                &Tags::new(),
                &Options::new(Scheme::Loop),
            )
            .expect("refine");
            let positions = rf.matrix.apply(&mesh.positions);
            mesh = PolyMesh::new(positions, rf.faces);
        }
        for p in &mut mesh.positions {
            *p = target.to_normalized(*p);
        }
        let opts = FitOptions::variant(Variant::SdmLm)
            .with_lambda(1e-5)
            .with_sample_level(level)
            .with_max_iterations(iters);
        let t = Instant::now();
        let mut fitter =
            Fitter::new(&target, &mesh.faces, mesh.num_vertices(), &opts).expect("fitter");
        let setup = t.elapsed();
        println!(
            "\n{} control points, {} samples (level {level}), H: {} nonzeros (upper), setup {:.2?}",
            mesh.num_vertices(),
            fitter.num_samples(),
            fitter.normal_matrix_nnz(),
            setup
        );
        let mut p = mesh.positions.clone();
        let report = fitter.run(&mut p, None).expect("fit");
        println!(
            "initial E_rms {:.5} E_max {:.5}; Cholesky factor: {} values ({:.1}× nnz(H))",
            report.initial.e_rms,
            report.initial.e_max,
            fitter.factor_len().unwrap_or(0),
            fitter.factor_len().unwrap_or(0) as f64 / fitter.normal_matrix_nnz() as f64
        );
        println!(
            "iter acc   E_rms     E_max     total    sample  project assemble  solve  evaluate"
        );
        for row in &report.iterations {
            let t = row.timings;
            println!(
                "{:>4} {:>3} {:.6} {:.6} {:>8.1?} {:>7.1?} {:>7.1?} {:>7.1?} {:>7.1?} {:>7.1?}",
                row.iteration,
                if row.accepted { "y" } else { "n" },
                row.errors.e_rms,
                row.errors.e_max,
                t.total(),
                t.sample,
                t.project,
                t.assemble,
                t.solve,
                t.evaluate
            );
        }
    }
}
