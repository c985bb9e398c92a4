//! Build time of the sampling operator `C = L_3 · M_3 M_2 M_1` for 1k- and 10k-face control
//! meshes (Loop, Catmull-Clark and quad/triangle), on torus grids with extraordinary vertices.
//! `TAGS=semi` (or `TAGS=sharp`, `TAGS=<sharpness>`) tags every 10th meridian of the torus as a
//! crease of sharpness 2.5 (infinite, the given value), to measure the cost of semi-sharp
//! creases (with sharpness > 3, some is left at level 3 and the limit rows refine locally).
#![allow(missing_docs, clippy::print_stdout, reason = "benchmark program")]

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use subfit_mesh::{Polygons, Tags};
use subfit_subdiv::{sampling_operator, Options, Scheme};

/// A torus grid of `n × m` cells: triangles with alternating diagonals (valences 5/6/7) for
/// Loop; quads with every 7th cell split into two triangles (extraordinary vertices after one
/// Catmull-Clark step) otherwise.
fn torus(n: usize, m: usize, loop_mesh: bool) -> (Vec<[f64; 3]>, Polygons) {
    let mut pts = Vec::with_capacity(n * m);
    for i in 0..n {
        for j in 0..m {
            let (u, v) = (
                std::f64::consts::TAU * i as f64 / n as f64,
                std::f64::consts::TAU * j as f64 / m as f64,
            );
            let r = 1.0 + 0.4 * v.cos();
            pts.push([r * u.cos(), r * u.sin(), 0.4 * v.sin()]);
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    let mut faces = Polygons::new();
    for i in 0..n {
        for j in 0..m {
            let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            if loop_mesh {
                if (i + j) % 3 == 0 {
                    faces.push(&[q[0], q[1], q[3]]);
                    faces.push(&[q[1], q[2], q[3]]);
                } else {
                    faces.push(&[q[0], q[1], q[2]]);
                    faces.push(&[q[0], q[2], q[3]]);
                }
            } else if (i * m + j) % 7 == 0 {
                faces.push(&[q[0], q[1], q[2]]);
                faces.push(&[q[0], q[2], q[3]]);
            } else {
                faces.push(&q);
            }
        }
    }
    (pts, faces)
}

/// Crease tags from `TAGS` (`semi`: sharpness 2.5, `sharp`: infinite, a number: that sharpness,
/// else none) on every
/// 10th meridian `i = 0, 10, …` of the `n × m` torus grid.
fn meridian_tags(n: usize, m: usize) -> Tags {
    let s = match std::env::var("TAGS").as_deref() {
        Ok("semi") => 2.5,
        Ok("sharp") => subfit_mesh::SHARPNESS_INFINITE,
        Ok(x) => match x.parse::<f64>() {
            Ok(s) => s,
            Err(_) => return Tags::new(),
        },
        _ => return Tags::new(),
    };
    let mut tags = Tags::new();
    for i in (0..n).step_by(10) {
        for j in 0..m {
            tags.set_crease((i * m + j) as u32, (i * m + (j + 1) % m) as u32, s);
        }
    }
    tags
}

/// Process CPU time (user + system, all threads) in seconds, from `/proc/self/stat` (Linux; 0
/// elsewhere). Reported beside wall time because the benchmark machine may be shared.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    let ticks: f64 = f.get(11).and_then(|s| s.parse().ok()).unwrap_or(0.0)
        + f.get(12).and_then(|s| s.parse().ok()).unwrap_or(0.0);
    ticks / 100.0
}

/// Builds timed after the first, for the warm figure: `WARM=<n>`, default 4.
fn warm_builds() -> usize {
    std::env::var("WARM")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4)
        .max(1)
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("sampling_operator_level3");
    g.sample_size(10);
    let cases = [
        ("loop_1k", Scheme::Loop, 25, 20),
        ("loop_10k", Scheme::Loop, 100, 50),
        ("catmark_1k", Scheme::CatmullClark, 40, 25),
        ("catmark_10k", Scheme::CatmullClark, 125, 80),
        // The same meshes as mixed quad/triangle cages.
        ("quadtri_1k", Scheme::QuadTriangle, 40, 25),
        ("quadtri_10k", Scheme::QuadTriangle, 125, 80),
    ];
    for (name, scheme, n, m) in cases {
        // `ONLY=<case>` times (and profiles) a single case.
        if std::env::var("ONLY").is_ok_and(|o| o != name) {
            continue;
        }
        let (pts, faces) = torus(n, m, scheme == Scheme::Loop);
        let tags = meridian_tags(n, m);
        let o = Options::new(scheme);
        let build = || sampling_operator(&faces, pts.len(), &tags, &o, 3).unwrap();
        // The first build of the process is timed on its own: it pays for fresh pages from the
        // kernel and the thread pool's start, which a user building the operator once sees.
        let (wall, cpu) = (std::time::Instant::now(), cpu_seconds());
        let mut op = build();
        let (first_wall, first_cpu) = (wall.elapsed().as_secs_f64(), cpu_seconds() - cpu);
        let warm = warm_builds();
        let (wall, cpu) = (std::time::Instant::now(), cpu_seconds());
        for _ in 0..warm {
            op = build();
        }
        let (wall, cpu) = (
            wall.elapsed().as_secs_f64() / warm as f64,
            (cpu_seconds() - cpu) / warm as f64,
        );
        println!(
            "{name}: first build: wall {:.0} ms, cpu {:.0} ms; warm build (mean of {warm}): \
             wall {:.0} ms, cpu {:.0} ms (all threads)",
            first_wall * 1e3,
            first_cpu * 1e3,
            wall * 1e3,
            cpu * 1e3
        );
        println!(
            "{name}: {} control faces, {} control points -> {} rows; nnz position {} tangent1 {} tangent2 {}",
            faces.len(),
            pts.len(),
            op.num_vertices,
            op.position.nnz(),
            op.tangent1.nnz(),
            op.tangent2.nnz()
        );
        drop(op);
        // `BUILDS_ONLY=1` skips criterion (for instruction counts under valgrind).
        if std::env::var_os("BUILDS_ONLY").is_some() {
            continue;
        }
        g.bench_function(name, |b| {
            b.iter(|| sampling_operator(black_box(&faces), pts.len(), &tags, &o, 3).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
