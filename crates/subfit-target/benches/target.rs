//! Benchmark of target construction and foot-point queries (plain binary, prints figures).
//!
//! `SUBFIT_DATA=../shared/data cargo bench -p subfit-target --bench target` (without
//! `SUBFIT_DATA` it measures nothing). Figures: preprocessing time (normals, curvature,
//! orientation) for Igea (134,345 points) and for 1M points sampled uniformly on Igea's
//! triangles; foot-point queries per second (parallel batch), cold (`foot_points`) and warm
//! (`foot_points_hinted` with the previous call's hints); wall and CPU time.
#![allow(clippy::print_stdout)]

use std::time::Instant;

use subfit_mesh::vec3::{cross, norm, sub};
use subfit_mesh::PolyMesh;
use subfit_target::{NormalSource, Target, TargetOptions};

/// `n` points uniformly distributed on the triangles of `mesh` (triangle chosen with probability
/// proportional to its area, uniform barycentric coordinates), from a fixed seed.
fn sample_surface(mesh: &PolyMesh, n: usize) -> Vec<[f64; 3]> {
    let mut s = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let tris = mesh.faces.triangulate_fan();
    let p = &mesh.positions;
    let mut cum = Vec::with_capacity(tris.len());
    let mut total = 0.0;
    for t in &tris {
        let [a, b, c] = t.map(|v| p[v as usize]);
        total += 0.5 * norm(cross(sub(b, a), sub(c, a)));
        cum.push(total);
    }
    (0..n)
        .map(|_| {
            let r = rnd() * total;
            let k = cum.partition_point(|&c| c < r).min(tris.len() - 1);
            let [a, b, c] = tris[k].map(|v| p[v as usize]);
            let (mut u, mut v) = (rnd(), rnd());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            [0, 1, 2].map(|i| a[i] + u * (b[i] - a[i]) + v * (c[i] - a[i]))
        })
        .collect()
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
        "{name}: {} points: total {:.3} s (validate {:.3}, normalize {:.3}, merge {:.3}, index {:.3}, estimate {:.3}, orient {:.3}, mesh {:.3}); merged {}, flipped {} (winding check {}; field: suspicious {}, iterations {}, flips {}, redirected {}), ambiguous {}, components {}",
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
        s.winding_flips,
        s.field_suspicious,
        s.field_iterations,
        s.field_flips,
        s.field_redirected,
        s.ambiguous_normals,
        s.orientation_components,
    );
}

fn queries(t: &Target, n: usize) {
    // Points near the surface: data points offset along their normals by up to ±0.02, plus a
    // small lateral jitter.
    let pts = t.points();
    let nrm = t.normals();
    let mut xs: Vec<[f64; 3]> = (0..n)
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
        "  foot points, cold (kd-tree; Morton-sorted runs): {n} in {dt:.3} s = {:.2} M/s; CPU {cpu:.2} s = {:.2} M/CPU-s (checksum {checksum:.3}, load average {})",
        n as f64 / dt / 1e6,
        n as f64 / cpu.max(1e-9) / 1e6,
        load_average()
    );
    // Warm start, as in the fitter: queries in a spatially coherent order (its samples come
    // face by face), hints from the previous call, every query moved by up to 2e-4 (normalized).
    xs.sort_by_key(|x| x.map(|c| (c.clamp(0.0, 1.0) * 64.0) as u32));
    let mut hints = vec![u32::MAX; n];
    let (t0, c0) = (Instant::now(), cpu_seconds());
    let _ = t.foot_points_hinted(&xs, &mut hints);
    let (dt0, cpu0) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
    for (i, x) in xs.iter_mut().enumerate() {
        for (k, c) in x.iter_mut().enumerate() {
            *c += 2e-4 * (((i * 13 + k * 5) % 17) as f64 / 8.0 - 1.0);
        }
    }
    let (t0, c0) = (Instant::now(), cpu_seconds());
    let g = t.foot_points_hinted(&xs, &mut hints);
    let (dt, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
    let checksum: f64 = g.iter().map(|f| f.distance).sum();
    println!(
        "  foot points, hinted: first call (no hints) {:.2} M/s, CPU {cpu0:.2} s; warm call {n} in {dt:.3} s = {:.2} M/s; CPU {cpu:.2} s = {:.2} M/CPU-s (checksum {checksum:.3}, load average {})",
        n as f64 / dt0 / 1e6,
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
    let Some(dir) = std::env::var_os("SUBFIT_DATA") else {
        println!("SUBFIT_DATA not set: nothing to measure (igea.ply is the benchmark input)");
        return;
    };
    let path = std::path::Path::new(&dir).join("igea.ply");
    let mesh = match subfit_io::read_file(&path, &subfit_io::ReadOptions::default()) {
        Ok((mesh, _)) => mesh,
        Err(e) => {
            println!("igea: cannot read {}: {e}", path.display());
            return;
        }
    };
    // Point cloud only: estimated normals (the hard case).
    let est = TargetOptions {
        normals: NormalSource::Estimate,
        ..opts.clone()
    };
    let cloud = PolyMesh::point_cloud(mesh.positions.clone(), None);
    let t = build("igea (points, estimated normals)", &cloud, &est);
    queries(&t, 2_000_000);
    drop(t);
    build("igea (mesh: face normals + BVH)", &mesh, &opts);
    let pts = sample_surface(&mesh, 1_000_000);
    let t = build(
        "igea 1M (points sampled uniformly on its triangles, estimated normals)",
        &PolyMesh::point_cloud(pts, None),
        &opts,
    );
    queries(&t, 2_000_000);
}
