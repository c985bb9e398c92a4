//! Preprocessing time of target analysis on a noisy 150k-point scan: 0.3 % (of the
//! bounding-box diagonal) Gaussian noise and 3 % outliers uniform in the bounding box.
//!
//! `cargo run --release -p subfit-target --example noisy_bench [-- N [SHAPE]]`, `SHAPE` one of
//! `igea` (default when `SUBFIT_DATA` is set: points sampled on `igea.ply`'s triangles),
//! `torus`, `sphere`. Prints the time of every phase, the counts of the orientation steps,
//! the outliers removed (of those injected) and the estimated noise level. Set
//! `SUBFIT_NOISY_OUT=FILE.xyz` to also write the cloud (for `subfit analyze`).
#![allow(clippy::print_stdout)]

#[path = "../tests/common/noisy.rs"]
mod noisy;

use std::time::Instant;

use subfit_target::{NormalSource, Target, TargetOptions};

fn analytic(shape: &str, n: usize) -> Vec<[f64; 3]> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let t = golden * i as f64;
            if shape == "torus" {
                // (u, v) from the Fibonacci lattice on the unit square; not exactly uniform by
                // area, which does not matter here.
                let (u, v) = (
                    t.rem_euclid(std::f64::consts::TAU),
                    (z + 1.0) * std::f64::consts::PI,
                );
                let w = 1.0 + 0.35 * v.cos();
                [w * u.cos(), w * u.sin(), 0.35 * v.sin()]
            } else {
                [r * t.cos(), r * t.sin(), z]
            }
        })
        .collect()
}

fn options() -> TargetOptions {
    TargetOptions {
        normals: NormalSource::Estimate,
        ..TargetOptions::default()
    }
}

/// `noisy_bench clean FILE...`: the files' vertices as point clouds, outliers and noise.
fn clean(files: impl Iterator<Item = String>) {
    for f in files {
        let mesh = match subfit_io::read_file(std::path::Path::new(&f), &Default::default()) {
            Ok((m, _)) => m,
            Err(e) => {
                println!("{f}: {e}");
                continue;
            }
        };
        match Target::from_points(&mesh.positions, None, &options()) {
            Ok(t) => {
                let s = t.stats();
                println!(
                    "{f}: {} points, {} outliers removed ({:.4} %), noise {:.3e} = {:.4} x spacing {:.3e}, k {}, total {:.3} s",
                    s.input_points,
                    s.outliers_removed,
                    100.0 * s.outliers_removed as f64 / s.input_points as f64,
                    s.noise_level,
                    s.noise_level / s.point_spacing,
                    s.point_spacing,
                    s.neighborhood_k,
                    s.timings.total.as_secs_f64()
                );
            }
            Err(e) => println!("{f}: {e}"),
        }
    }
}

fn main() {
    let mut args = std::env::args().skip(1).peekable();
    if args.peek().map(String::as_str) == Some("clean") {
        args.next();
        clean(args);
        return;
    }
    let n: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(150_000);
    let data = std::env::var_os("SUBFIT_DATA");
    let shape = args.next().unwrap_or_else(|| {
        if data.is_some() {
            "igea".into()
        } else {
            "torus".into()
        }
    });
    let clean_n = (n as f64 / 1.03).round() as usize;
    let clean = if shape == "igea" {
        let Some(dir) = data else {
            println!("igea needs SUBFIT_DATA");
            return;
        };
        let path = std::path::Path::new(&dir).join("igea.ply");
        let mesh = match subfit_io::read_file(&path, &subfit_io::ReadOptions::default()) {
            Ok((m, _)) => m,
            Err(e) => {
                println!("{}: {e}", path.display());
                return;
            }
        };
        let tris = mesh.faces.triangulate_fan();
        noisy::sample_triangles(&mesh.positions, &tris, clean_n, 7)
    } else {
        analytic(&shape, clean_n)
    };
    let cloud = noisy::add_noise(&clean, 0.003, 0.03, 11);
    if let Some(out) = std::env::var_os("SUBFIT_NOISY_OUT") {
        let text: String = cloud
            .points
            .iter()
            .map(|p| format!("{} {} {}\n", p[0], p[1], p[2]))
            .collect();
        if let Err(e) = std::fs::write(&out, text) {
            println!("cannot write {}: {e}", out.to_string_lossy());
        }
    }
    let t0 = Instant::now();
    let t = match Target::from_points(&cloud.points, None, &options()) {
        Ok(t) => t,
        Err(e) => {
            println!("analysis failed: {e}");
            return;
        }
    };
    let wall = t0.elapsed().as_secs_f64();
    let s = t.stats();
    let tm = &s.timings;
    let caught = t
        .removed_outliers()
        .iter()
        .filter(|&&i| cloud.is_outlier(i as usize))
        .count();
    println!(
        "{shape} noisy ({} points, {} injected outliers): total {wall:.3} s",
        cloud.points.len(),
        cloud.outliers
    );
    let sec = |d: std::time::Duration| d.as_secs_f64();
    println!(
        "  phases (s): validate {:.3}, normalize {:.3}, merge {:.3}, index {:.3}, outliers {:.3}, estimate {:.3}, orient {:.3} (propagate {:.3}, winding {:.3}, field {:.3} in {} iterations), mesh {:.3}",
        sec(tm.validate),
        sec(tm.normalize),
        sec(tm.merge),
        sec(tm.index),
        sec(tm.outliers),
        sec(tm.estimate),
        sec(tm.orient),
        sec(tm.orient_propagate),
        sec(tm.orient_winding),
        sec(tm.orient_field),
        s.field_iterations,
        sec(tm.mesh_index),
    );
    println!(
        "  outliers removed {} ({caught} of the {} injected), noise level {:.3e} ({:.3} x spacing {:.3e}), k {}",
        s.outliers_removed,
        cloud.outliers,
        s.noise_level,
        s.noise_level / s.point_spacing,
        s.point_spacing,
        s.neighborhood_k
    );
    if shape == "sphere" {
        let c = t.to_normalized([0.0; 3]);
        let out = t
            .points()
            .iter()
            .zip(t.normals())
            .filter(|(p, n)| (0..3).map(|k| (p[k] - c[k]) * n[k]).sum::<f64>() > 0.0)
            .count();
        let removed: std::collections::HashSet<u32> =
            t.removed_outliers().iter().copied().collect();
        let mut missed: Vec<f64> = (0..cloud.points.len())
            .filter(|&i| cloud.is_outlier(i) && !removed.contains(&(i as u32)))
            .map(|i| {
                let p = t.to_normalized(cloud.points[i]);
                ((0..3).map(|k| (p[k] - c[k]).powi(2)).sum::<f64>().sqrt() - 0.5).abs()
            })
            .collect();
        missed.sort_by(f64::total_cmp);
        let q = |f: f64| {
            missed
                .get(((missed.len() as f64 - 1.0) * f) as usize)
                .copied()
                .unwrap_or(0.0)
        };
        println!(
            "  missed outliers' distance to the sphere: 10% {:.4}, 50% {:.4}, 90% {:.4}, max {:.4}",
            q(0.1),
            q(0.5),
            q(0.9),
            q(1.0)
        );
        println!(
            "  normals pointing outward: {:.3} %",
            100.0 * out as f64 / t.len() as f64
        );
    }
    println!("  stats: {s:?}");
}
