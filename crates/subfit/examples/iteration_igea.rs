//! Time per SDMLM iteration (level-3 sampling), with the phase breakdown, the sample count and
//! the factor size, for control meshes of about 1k and 10k vertices fitted to Igea
//! (`igea.ply`, 134k points, closed genus 0). The target is built from the file's points; the
//! control meshes are the Igea mesh simplified by our QEM (`subfit_init::simplify`, each size
//! from the full mesh), mapped into the target's normalized coordinates.
//!
//! ```text
//! SUBFIT_DATA=/work/shared/data RAYON_NUM_THREADS=2 \
//!     cargo run --release -p subfit --example iteration_igea
//! SUBFIT_DATA=/work/shared/data SUBFIT_SIZES=10000 SUBFIT_ITERS=5 SUBFIT_SOLVER=pcg \
//!     RAYON_NUM_THREADS=2 cargo run --release -p subfit --example iteration_igea
//! ```
//!
//! Environment: `SUBFIT_DATA` (directory holding `igea.ply`; required), `SUBFIT_SIZES`
//! (comma-separated control-point counts, default `1000,10000`), `SUBFIT_ITERS` (default 3),
//! `SUBFIT_SAMPLE_LEVEL` (default 3), `SUBFIT_LAMBDA` (default 1e-3), `SUBFIT_SOLVER`
//! (`auto`, `cholesky` or `pcg`; default `auto`), `SUBFIT_ORDERING` (`scalar-amd`,
//! `block-amd` or `nd`; default `block-amd`), `SUBFIT_PCG_TOL` (default 1e-2),
//! `SUBFIT_ACTIVE` (a fraction in (0, 1]: fit only that first fraction of the control points
//! with [`Fitter::set_active`]; default: all, the normal path). CPU time is
//! the process's user + system time from `/proc/self/stat` (Linux only; 0 elsewhere). The
//! machine is shared: run with `RAYON_NUM_THREADS=2` and note `uptime`'s load with the figures.
//!
//! Measured 2026-11-22 06:30 UTC, branch `fitspeed` against its base 053cd26 (same data,
//! both binaries run alternately three times; 2 rayon threads on the 2-core machine shared
//! with other builds, load 3.9–4.7; SDMLM, λ = 1e-3, defaults otherwise), wall per iteration:
//! 10k control points (640k samples, PCG): best run 0.64 s mean (iterations 0.62–0.68 s:
//! project 313–329 ms, assemble 182–250, solve 82–90, sample 15–23, evaluate 9–11), median of
//! the three runs' means 1.13 s, CPU 1.32–1.36 s per iteration. Base in the same conditions:
//! best run 1.24 s mean (iterations 0.89–1.53 s: assemble 346–656, solve 173–313), median
//! 1.46 s, CPU 1.69–1.89 s. 1k control points (64k samples, Cholesky): best run 108 ms mean
//! (base 189 ms).
//!
//! Measured 2026-12-01 18:00 UTC on main (quiet machine, load 1.3–1.6 from these runs alone),
//! mean wall per iteration over 3 iterations, 4 runs: 10k control points 0.29–0.42 s (CPU
//! 0.61–0.82 s; stable iterations: project 140–170 ms, assemble 49–52, solve 16–19); the
//! blended foot points of `subfit-target` (where a quadric is untrusted or extrapolated, about
//! 1.5 % of the queries here) cost 25–90 ms of it (alternate runs with blending disabled:
//! 0.23–0.26 s). 1k control points: 42–45 ms.
//! The assembly is the grouped fill of the normal matrix (see `examples/assemble_igea.rs`
//! for its CPU time alone); projection is `subfit-target`'s and dominates what is left.
#![allow(clippy::print_stdout)]

use std::time::{Duration, Instant};

use subfit_fit::{FillOrdering, FitOptions, Fitter, LinearSolver, Variant};
use subfit_init::{simplify, SimplifyOptions};
use subfit_mesh::PolyMesh;
use subfit_target::{Target, TargetOptions};

fn env<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// User + system CPU time of this process (all threads), from `/proc/self/stat`.
fn cpu_time() -> Duration {
    let Ok(s) = std::fs::read_to_string("/proc/self/stat") else {
        return Duration::ZERO;
    };
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let rest = s.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<u64> = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|x| x.parse().ok())
        .collect();
    // Linux reports clock ticks of 1/100 s (USER_HZ).
    Duration::from_millis(10 * f.iter().sum::<u64>())
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn main() {
    let Some(dir) = std::env::var_os("SUBFIT_DATA") else {
        println!("SUBFIT_DATA not set (the directory holding igea.ply): nothing to measure");
        return;
    };
    let sizes: Vec<usize> = std::env::var("SUBFIT_SIZES")
        .unwrap_or_else(|_| "1000,10000".into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let iters = env("SUBFIT_ITERS", 3usize);
    let level = env("SUBFIT_SAMPLE_LEVEL", 3usize);
    let lambda = env("SUBFIT_LAMBDA", 1e-3f64);
    let pcg_tol = env("SUBFIT_PCG_TOL", 1e-2f64);
    let active = std::env::var("SUBFIT_ACTIVE")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .filter(|f| *f > 0.0 && *f <= 1.0);
    let solver = match std::env::var("SUBFIT_SOLVER").as_deref() {
        Ok("cholesky") => LinearSolver::Cholesky,
        Ok("pcg") => LinearSolver::Pcg,
        _ => LinearSolver::Auto,
    };
    let ordering = match std::env::var("SUBFIT_ORDERING").as_deref() {
        Ok("scalar-amd") => FillOrdering::ScalarAmd,
        Ok("nd") => FillOrdering::NestedDissection,
        _ => FillOrdering::BlockAmd,
    };

    let path = std::path::Path::new(&dir).join("igea.ply");
    let (mesh, _) =
        subfit_io::read_file(&path, &subfit_io::ReadOptions::default()).expect("read igea.ply");
    let t0 = Instant::now();
    let target = Target::from_points(
        &mesh.positions,
        mesh.normals.as_deref(),
        &TargetOptions::default(),
    )
    .expect("target");
    println!(
        "target: {} points, built in {:.2?}; rayon threads: {}",
        target.len(),
        t0.elapsed(),
        rayon::current_num_threads()
    );

    // Each size simplified from the full mesh (simplifying the 10k cage further gets stuck
    // early on its quality checks).
    let mut cages: Vec<(usize, PolyMesh)> = Vec::new();
    for &n in &sizes {
        let t = Instant::now();
        let opts = SimplifyOptions {
            target_vertices: n,
            ..SimplifyOptions::default()
        };
        let (cage, rep) = simplify(&mesh, &opts).expect("simplify");
        println!(
            "QEM: {} → {} vertices in {:.2?}",
            rep.vertices_before,
            rep.vertices_after,
            t.elapsed()
        );
        cages.push((n, cage));
    }

    for &n in &sizes {
        let cage = &cages.iter().find(|(k, _)| *k == n).expect("simplified").1;
        let positions: Vec<[f64; 3]> = cage
            .positions
            .iter()
            .map(|&p| target.to_normalized(p))
            .collect();
        let opts = FitOptions {
            linear_solver: solver,
            fill_ordering: ordering,
            pcg_tolerance: pcg_tol,
            ..FitOptions::variant(Variant::SdmLm)
                .with_lambda(lambda)
                .with_sample_level(level)
                .with_max_iterations(iters)
        };
        let (c0, t) = (cpu_time(), Instant::now());
        let mut fitter =
            Fitter::new(&target, &cage.faces, cage.num_vertices(), &opts).expect("fitter");
        let (setup, setup_cpu) = (t.elapsed(), cpu_time() - c0);
        println!(
            "\n{} control points, {} samples (level {level}), H: {} scalar nonzeros (upper), \
             setup {:.0} ms (CPU {:.0} ms)",
            positions.len(),
            fitter.num_samples(),
            fitter.normal_matrix_nnz(),
            ms(setup),
            ms(setup_cpu)
        );
        if let Some(frac) = active {
            // The first fraction of the control points (QEM keeps the order spatially local).
            let k = (frac * positions.len() as f64).ceil() as usize;
            let mask: Vec<bool> = (0..positions.len()).map(|i| i < k).collect();
            let t = Instant::now();
            fitter.set_active(Some(mask)).expect("active set");
            println!(
                "active set: {k} of {} control points, {} of {} samples, built in {:.0} ms",
                positions.len(),
                fitter.num_active_samples(),
                fitter.num_samples(),
                ms(t.elapsed())
            );
        }
        let mut p = positions.clone();
        let (c0, t) = (cpu_time(), Instant::now());
        let report = fitter.run(&mut p, None).expect("fit");
        let (wall, cpu) = (t.elapsed(), cpu_time() - c0);
        println!(
            "solver: {solver:?}, ordering {ordering:?}; factor: {}; initial E_rms {:.6} E_max {:.6}",
            match fitter.factor_len() {
                Some(f) => format!(
                    "{f} values ({:.1}× nnz(H))",
                    f as f64 / fitter.normal_matrix_nnz() as f64
                ),
                None => "none (PCG)".into(),
            },
            report.initial.e_rms,
            report.initial.e_max
        );
        println!("iter acc  E_rms     E_max     total_ms sample project assemble  solve evaluate");
        for row in &report.iterations {
            let t = row.timings;
            println!(
                "{:>4} {:>3} {:.6} {:.6} {:>8.1} {:>6.1} {:>7.1} {:>8.1} {:>6.1} {:>8.1}",
                row.iteration,
                if row.accepted { "y" } else { "n" },
                row.errors.e_rms,
                row.errors.e_max,
                ms(t.total()),
                ms(t.sample),
                ms(t.project),
                ms(t.assemble),
                ms(t.solve),
                ms(t.evaluate)
            );
        }
        if let Some(st) = fitter.last_pcg() {
            println!(
                "last PCG solve: {} iterations, relative residual {:.1e}",
                st.iterations, st.relative_residual
            );
        }
        let k = report.iterations.len().max(1) as f64;
        println!(
            "mean per iteration: {:.1} ms wall, {:.1} ms CPU (whole run incl. initial evaluation: \
             {:.0} ms wall, {:.0} ms CPU)",
            ms(report.iterations.iter().map(|r| r.timings.total()).sum()) / k,
            ms(cpu) / k,
            ms(wall),
            ms(cpu)
        );
    }
}
