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
    let t0 = Instant::now();
    let f = t.foot_points(&xs);
    let dt = t0.elapsed().as_secs_f64();
    let checksum: f64 = f.iter().map(|f| f.distance).sum();
    println!(
        "  foot points: {n} in {dt:.3} s = {:.2} M/s (checksum {checksum:.3})",
        n as f64 / dt / 1e6
    );
    let t0 = Instant::now();
    let v = t.imls_batch(&xs[..n / 4]);
    let dt = t0.elapsed().as_secs_f64();
    println!(
        "  IMLS: {} in {dt:.3} s = {:.2} M/s (h = {:.4}, {} fallbacks)",
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
                let t = Target::from_mesh(&cloud, &est).expect("igea");
                report("igea (points, estimated normals)", &t);
                queries(&t, 2_000_000);
                let t = Target::from_mesh(&mesh, &opts).expect("igea mesh");
                report("igea (mesh: face normals + BVH)", &t);
            }
            Err(e) => println!("igea: cannot read {}: {e}", path.display()),
        }
    } else {
        println!("SUBFIT_DATA not set: skipping igea");
    }
    let pts = torus_points(1_000_000);
    let t = Target::from_points(&pts, None, &opts).expect("torus");
    report("torus 1M (estimated normals)", &t);
    queries(&t, 2_000_000);
}
