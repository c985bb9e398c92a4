//! CPU time of the assembly of one SDM iteration's normal equations on Igea (level-3 sampling,
//! control meshes of about 1k and 10k vertices simplified by our QEM): the per-sample `Q_k`,
//! the fill of `H`, the weighted residuals, the gradient, the fused fill + gradient the fitter
//! uses, and a PCG solve to relative residual
//! 1e-2 (the default), each repeated and timed.
//! CPU time (user + system of the process, `/proc/self/stat`) is less sensitive than wall time
//! to other work on a shared machine; run single-threaded to compare code, two-threaded to see
//! the parallel speed-up.
//!
//! ```text
//! SUBFIT_DATA=/work/shared/data RAYON_NUM_THREADS=1 \
//!     cargo run --release -p subfit --example assemble_igea
//! ```
//!
//! Environment: `SUBFIT_DATA` (directory holding `igea.ply`; required), `SUBFIT_SIZES`
//! (default `1000,10000`), `SUBFIT_REPEAT` (fills per measurement, default 5).
#![allow(clippy::print_stdout)]

use std::time::{Duration, Instant};

use subfit_fit::internals::{
    error_matrix, weighted_residuals, FillScratch, Laplacian, Pattern, PcgSolver,
};
use subfit_fit::{FitOptions, Fitter, Method, Variant};
use subfit_init::{simplify, SimplifyOptions};
use subfit_target::{Target, TargetOptions};

/// User + system CPU time of this process (all threads), from `/proc/self/stat`.
fn cpu_time() -> Duration {
    let Ok(s) = std::fs::read_to_string("/proc/self/stat") else {
        return Duration::ZERO;
    };
    let rest = s.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<u64> = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|x| x.parse().ok())
        .collect();
    Duration::from_millis(10 * f.iter().sum::<u64>())
}

/// Runs `f` `reps` times; returns (wall, CPU) per run in ms.
fn time(reps: usize, mut f: impl FnMut()) -> (f64, f64) {
    let (c0, t0) = (cpu_time(), Instant::now());
    for _ in 0..reps {
        f();
    }
    let k = reps.max(1) as f64;
    (
        t0.elapsed().as_secs_f64() * 1e3 / k,
        (cpu_time() - c0).as_secs_f64() * 1e3 / k,
    )
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
    let reps: usize = std::env::var("SUBFIT_REPEAT")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(5);
    let path = std::path::Path::new(&dir).join("igea.ply");
    let (mesh, _) =
        subfit_io::read_file(&path, &subfit_io::ReadOptions::default()).expect("read igea.ply");
    let target = Target::from_points(
        &mesh.positions,
        mesh.normals.as_deref(),
        &TargetOptions::default(),
    )
    .expect("target");
    println!("rayon threads: {}", rayon::current_num_threads());
    for &n in &sizes {
        let opts = SimplifyOptions {
            target_vertices: n,
            ..SimplifyOptions::default()
        };
        let (cage, _) = simplify(&mesh, &opts).expect("simplify");
        let p: Vec<[f64; 3]> = cage
            .positions
            .iter()
            .map(|&x| target.to_normalized(x))
            .collect();
        let fopts = FitOptions::variant(Variant::SdmLm).with_sample_level(3);
        let fitter = Fitter::new(&target, &cage.faces, p.len(), &fopts).expect("fitter");
        let op = &fitter.sampling_operator().position;
        let s = op.apply(&p);
        let feet = fitter.term().foot_points(&s);
        let v: Vec<[f64; 3]> = feet.iter().map(|f| f.point).collect();
        let lap = Laplacian::umbrella(&cage.faces, p.len());
        let t0 = Instant::now();
        let pattern = Pattern::new(op, &lap, 3);
        let build = t0.elapsed();
        let (w_e, w_s) = (1.0 / s.len() as f64, 1e-3 / p.len() as f64);
        let mut q = Vec::new();
        let tq = time(reps, || {
            q = feet.iter().map(|f| error_matrix(Method::Sdm, f)).collect();
        });
        let mut values = vec![0.0; pattern.nnz()];
        let mut scratch = FillScratch::default();
        let tf = time(reps, || {
            pattern.fill_with(op, &q, w_e, w_s, &mut values, &mut scratch)
        });
        let mut r = Vec::new();
        let tr = time(reps, || r = weighted_residuals(&s, &v, Some(&q)));
        let mut g = Vec::new();
        let tg = time(reps, || g = pattern.gradient(&r, &p, w_e, w_s));
        let mut gf = Vec::new();
        let tfg = time(reps, || {
            gf = pattern.fill_with_gradient(op, &q, &r, &p, w_e, w_s, &mut values, &mut scratch)
        });
        let rhs: Vec<f64> = g.iter().flatten().map(|x| -x).collect();
        let mut pcg = PcgSolver::new(&pattern);
        let mut its = 0;
        let ts = time(reps, || {
            let mut x = rhs.clone();
            its = pcg
                .solve(&pattern, &values, &mut x, 1, 1e-2, 1000)
                .expect("SPD")
                .iterations;
        });
        let checksum: f64 = values.iter().sum::<f64>() + gf.iter().flatten().sum::<f64>();
        println!(
            "{} control points, {} samples: pattern {:.0} ms; per call wall/CPU ms — Q {:.1}/{:.1}, \
             fill {:.1}/{:.1}, residuals {:.1}/{:.1}, gradient {:.1}/{:.1}, fused fill + gradient {:.1}/{:.1}; PCG to 1e-2 {:.1}/{:.1} \
             ({its} iterations) (checksum {checksum:.6e})",
            p.len(),
            s.len(),
            build.as_secs_f64() * 1e3,
            tq.0,
            tq.1,
            tf.0,
            tf.1,
            tr.0,
            tr.1,
            tg.0,
            tg.1,
            tfg.0,
            tfg.1,
            ts.0,
            ts.1
        );
    }
}
