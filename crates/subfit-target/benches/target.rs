//! Benchmark of target construction and foot-point queries (plain binary, prints figures).
//!
//! `cargo bench -p subfit-target --bench target` — with `SUBFIT_DATA` set, also Igea
//! (134,345 points). Figures: preprocessing time (normals, curvature, orientation) for Igea and
//! for 1M points (a jittered-sampled torus), foot-point queries per second (parallel batch).
#![allow(clippy::print_stdout)]

use std::time::Instant;

use subfit_mesh::PolyMesh;
use subfit_target::{NormalSource, Target, TargetOptions};

fn torus_points(n: usize) -> Vec<[f64; 3]> {
    // Deterministic low-discrepancy-ish sampling of a torus R = 0.35, r = 0.15, with jitter.
    let mut s = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let (rr, r) = (0.35, 0.15);
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let th = rnd() * std::f64::consts::TAU;
        let ph = rnd() * std::f64::consts::TAU;
        if rnd() * (rr + r) < rr + r * ph.cos() {
            let w = rr + r * ph.cos();
            out.push([w * th.cos(), w * th.sin(), r * ph.sin()]);
        }
    }
    out
}

/// Process CPU time (user + system, all threads) in seconds, from `/proc/self/stat` (Linux; 0
/// elsewhere). Wall times are noisy on a shared machine: CPU time is printed beside them.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // Fields after the command name (which ends with ')'): utime and stime are fields 14, 15.
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11..13).map_or(0.0, |v| {
        v.iter().filter_map(|x| x.parse::<f64>().ok()).sum()
    });
    ticks / 100.0 // USER_HZ
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_default()
}

fn build(name: &str, mesh: &PolyMesh, opts: &TargetOptions) -> Target {
    let c0 = cpu_seconds();
    let t = Target::from_mesh(mesh, opts).expect(name);
    let cpu = cpu_seconds() - c0;
    report(name, &t);
    println!("  build CPU {cpu:.2} s (load average {})", load_average());
    t
}

fn report(name: &str, t: &Target) {
    let s = t.stats();
    let tm = &s.timings;
    println!(
        "{name}: {} points: total {:.3} s (validate {:.3}, normalize {:.3}, merge {:.3}, index {:.3}, estimate {:.3}, orient {:.3}, mesh {:.3}); merged {}, flipped {}, ambiguous {}, components {}",
        t.len(),
        tm.total.as_secs_f64(),
        tm.validate.as_secs_f64(),
        tm.normalize.as_secs_f64(),
        tm.merge.as_secs_f64(),
        tm.index.as_secs_f64(),
        tm.estimate.as_secs_f64(),
        tm.orient.as_secs_f64(),
        tm.mesh_index.as_secs_f64(),
        s.merged_duplicates,
        s.flipped_normals,
        s.ambiguous_normals,
        s.orientation_components,
    );
}

fn queries(t: &Target, n: usize) {
    // Points near the surface: data points offset along their normals by up to ±0.02.
    let pts = t.points();
    let nrm = t.normals();
    let xs: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let j = (i * 7919) % pts.len();
            let d = 0.02 * (((i * 31) % 101) as f64 / 50.0 - 1.0);
            [0, 1, 2].map(|k| pts[j][k] + d * nrm[j][k] + 0.001 * (((i + k) % 7) as f64 - 3.0))
        })
        .collect();
    let _ = t.foot_points(&xs[..xs.len().min(10_000)]); // warm-up
    let (t0, c0) = (Instant::now(), cpu_seconds());
    let f = t.foot_points(&xs);
    let (dt, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
    let checksum: f64 = f.iter().map(|f| f.distance).sum();
    println!(
        "  foot points: {n} in {dt:.3} s = {:.2} M/s; CPU {cpu:.2} s = {:.2} M/CPU-s (checksum {checksum:.3}, load average {})",
        n as f64 / dt / 1e6,
        n as f64 / cpu.max(1e-9) / 1e6,
        load_average()
    );
    let (t0, c0) = (Instant::now(), cpu_seconds());
    let v = t.imls_batch(&xs[..n / 4]);
    let (dt, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
    println!(
        "  IMLS: {} in {dt:.3} s = {:.2} M/s; CPU {cpu:.2} s (h = {:.4}, {} fallbacks)",
        n / 4,
        (n / 4) as f64 / dt / 1e6,
        t.imls_radius(),
        v.iter().filter(|v| v.fallback).count()
    );
}

fn main() {
    let opts = TargetOptions::default();
    if let Some(dir) = std::env::var_os("SUBFIT_DATA") {
        let path = std::path::Path::new(&dir).join("igea.ply");
        match subfit_io::read_file(&path, &subfit_io::ReadOptions::default()) {
            Ok((mesh, _)) => {
                // Point cloud only: estimated normals (the hard case).
                let cloud = PolyMesh::point_cloud(mesh.positions.clone(), None);
                let est = TargetOptions {
                    normals: NormalSource::Estimate,
                    ..opts.clone()
                };
                let t = build("igea (points, estimated normals)", &cloud, &est);
                queries(&t, 2_000_000);
                build("igea (mesh: face normals + BVH)", &mesh, &opts);
            }
            Err(e) => println!("igea: cannot read {}: {e}", path.display()),
        }
    } else {
        println!("SUBFIT_DATA not set: skipping igea");
    }
    let pts = torus_points(1_000_000);
    let t = build(
        "torus 1M (estimated normals)",
        &PolyMesh::point_cloud(pts, None),
        &opts,
    );
    queries(&t, 2_000_000);
}
