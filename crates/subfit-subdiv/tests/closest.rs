//! Closest point on the limit surface: agreement with brute-force dense sampling and convergence
//! of the residual to 1e-10, on Catmull-Clark and Loop tori and on meshes with extraordinary
//! vertices and `n`-gons.
#![allow(
    clippy::print_stdout,
    reason = "the tests report the errors they measured"
)]
#![allow(
    clippy::needless_range_loop,
    reason = "coordinate loops index several arrays"
)]

use subfit_mesh::shapes::torus_mesh;
use subfit_mesh::{Polygons, Tags};
use subfit_subdiv::{ClosestOptions, ClosestPointFinder, Evaluator, Options, Scheme, SurfaceParam};

struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn dense_samples(ev: &Evaluator, p: &[[f64; 3]], m: u32) -> Vec<[f64; 3]> {
    let mut params = Vec::new();
    for pi in 0..ev.num_patches() {
        let (face, sub) = ev.patch(pi);
        for j in 0..=m {
            for i in 0..=m {
                if ev.triangular() && i + j > m {
                    continue;
                }
                params.push(SurfaceParam {
                    face,
                    sub,
                    u: i as f64 / m as f64,
                    v: j as f64 / m as f64,
                });
            }
        }
    }
    ev.evaluate_batch(p, &params)
        .unwrap()
        .into_iter()
        .map(|s| s.position)
        .collect()
}

fn check(name: &str, scheme: Scheme, p: &[[f64; 3]], f: &Polygons, nq: usize) {
    let ev = Evaluator::new(f, p.len(), &Tags::new(), &Options::new(scheme)).unwrap();
    let finder = ClosestPointFinder::new(&ev, p, ClosestOptions::default()).unwrap();
    let m = 24;
    let dense = dense_samples(&ev, p, m);
    let (lo, hi) = subfit_mesh::bounding_box(p).unwrap();
    let diag = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
    let mut rng = Rng(42);
    let mut max_res = 0.0f64;
    let mut max_gap = 0.0f64;
    let mut max_it = 0;
    for _ in 0..nq {
        let q = [
            lo[0] + (hi[0] - lo[0]) * (1.4 * rng.f() - 0.2),
            lo[1] + (hi[1] - lo[1]) * (1.4 * rng.f() - 0.2),
            lo[2] + (hi[2] - lo[2]) * (1.4 * rng.f() - 0.2),
        ];
        let c = finder.closest(q).unwrap();
        let bf = dense
            .iter()
            .map(|x| ((x[0] - q[0]).powi(2) + (x[1] - q[1]).powi(2) + (x[2] - q[2]).powi(2)).sqrt())
            .fold(f64::INFINITY, f64::min);
        // The exact closest point is never farther than the best sample, and the best sample is
        // within the sampling error of it.
        assert!(
            c.distance <= bf + 1e-12 * diag,
            "{name}: {} > {bf}",
            c.distance
        );
        max_gap = max_gap.max((bf - c.distance) / diag);
        assert!(
            c.converged,
            "{name}: residual {} after {} iterations",
            c.residual, c.iterations
        );
        max_res = max_res.max(c.residual);
        max_it = max_it.max(c.iterations);
        // The reported point is on the surface at the reported parameters.
        let s = ev.evaluate(p, c.param).unwrap();
        for k in 0..3 {
            assert!((s.position[k] - c.position[k]).abs() < 1e-14 * diag);
        }
        assert!((c.signed_distance.abs() - c.distance).abs() < 1e-9 * diag);
    }
    println!(
        "{name}: {nq} queries, max residual {max_res:.1e}, max (sampled − exact) distance {max_gap:.1e} of diag, max iterations {max_it}"
    );
    assert!(max_gap < 1e-2, "{name}: sampling gap {max_gap}");
}

#[test]
fn catmull_clark_torus_matches_dense_sampling() {
    let t = torus_mesh(1.0, 0.4, 8, 6, false);
    check(
        "cc torus",
        Scheme::CatmullClark,
        &t.positions,
        &t.faces,
        150,
    );
}

#[test]
fn loop_torus_matches_dense_sampling() {
    let t = torus_mesh(1.0, 0.4, 8, 6, true);
    check("loop torus", Scheme::Loop, &t.positions, &t.faces, 150);
}

#[test]
fn extraordinary_vertices_and_ngons() {
    // A pentagonal prism (n-gon caps, valence-3 corners) and an octahedron (Loop valence 4).
    let n = 5u32;
    let mut p = Vec::new();
    for z in [0.0, 1.0] {
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            p.push([a.cos(), a.sin(), z]);
        }
    }
    let mut f = Polygons::new();
    f.push(&(0..n).rev().collect::<Vec<_>>());
    f.push(&(n..2 * n).collect::<Vec<_>>());
    for i in 0..n {
        let j = (i + 1) % n;
        f.push(&[i, j, n + j, n + i]);
    }
    check("cc pentagonal prism", Scheme::CatmullClark, &p, &f, 300);
    let o = subfit_mesh::shapes::octahedron_mesh(1.0, 0.7, 1.3);
    check("loop octahedron", Scheme::Loop, &o.positions, &o.faces, 300);
}

/// An open `n × n` grid patch over `[0, n]²` with a smooth height field: quads, or each quad
/// split into two triangles.
fn open_grid(n: u32, tris: bool) -> (Vec<[f64; 3]>, Polygons) {
    let mut p = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64, j as f64);
            p.push([x, y, 0.4 * (0.9 * x).sin() * (0.7 * y).cos()]);
        }
    }
    let id = |i: u32, j: u32| j * (n + 1) + i;
    let mut f = Polygons::new();
    for j in 0..n {
        for i in 0..n {
            let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            if tris {
                f.push(&[q[0], q[1], q[2]]);
                f.push(&[q[0], q[2], q[3]]);
            } else {
                f.push(&q);
            }
        }
    }
    (p, f)
}

/// Queries beside an open grid (outside its boundary, and beyond its corners) have their
/// closest points on the boundary curve of the limit surface: the search converges there (the
/// residual projected on the boundary reaches the tolerance) and agrees with dense sampling.
#[test]
fn open_grid_boundary_closest_points_converge() {
    for (name, scheme, tris) in [
        ("cc open grid", Scheme::CatmullClark, false),
        ("loop open grid", Scheme::Loop, true),
    ] {
        let (p, f) = open_grid(4, tris);
        let ev = Evaluator::new(&f, p.len(), &Tags::new(), &Options::new(scheme)).unwrap();
        let finder = ClosestPointFinder::new(&ev, &p, ClosestOptions::default()).unwrap();
        let dense = dense_samples(&ev, &p, 48);
        let mut rng = Rng(7);
        let mut on_boundary = 0;
        for k in 0..120 {
            // Beside one of the four sides (k % 4) or beyond a corner (every 5th query).
            let t = 0.2 + 3.6 * rng.f();
            let out = 0.3 + 1.5 * rng.f();
            let z = 1.0 * rng.f() - 0.5;
            let q = if k % 5 == 4 {
                let c = [(k / 5) % 2, (k / 10) % 2].map(|b| if b == 0 { -out } else { 4.0 + out });
                [c[0], c[1], z]
            } else {
                match k % 4 {
                    0 => [t, -out, z],
                    1 => [4.0 + out, t, z],
                    2 => [t, 4.0 + out, z],
                    _ => [-out, t, z],
                }
            };
            let c = finder.closest(q).unwrap();
            assert!(
                c.converged,
                "{name}: query {q:?}: residual {} after {} iterations at {:?}",
                c.residual, c.iterations, c.param
            );
            let bf = dense
                .iter()
                .map(|x| {
                    ((x[0] - q[0]).powi(2) + (x[1] - q[1]).powi(2) + (x[2] - q[2]).powi(2)).sqrt()
                })
                .fold(f64::INFINITY, f64::min);
            assert!(
                c.distance <= bf + 1e-12,
                "{name}: {q:?}: {} > {bf} at {:?} after {} iterations",
                c.distance,
                c.param,
                c.iterations
            );
            assert!(
                bf - c.distance < 2e-3,
                "{name}: sampling gap {}",
                bf - c.distance
            );
            let (u, v) = (c.param.u, c.param.v);
            let on_edge = [u, v, 1.0 - u, 1.0 - v, 1.0 - u - v]
                .iter()
                .any(|x| x.abs() < 1e-12);
            on_boundary += usize::from(on_edge);
        }
        // The queries do exercise the boundary case.
        assert!(
            on_boundary >= 100,
            "{name}: only {on_boundary} boundary foot points"
        );
    }
}

/// A washer-like Loop cage: four rings (inner and outer radius, bottom and top) of `counts`
/// vertices, neighbouring rings joined by triangles advancing along whichever ring is behind
/// (irregular valences where the counts differ), the four ring loops creased (a CAD part's
/// sharp rims, the cage a fit writes for them).
fn creased_washer(counts: [usize; 4]) -> (Vec<[f64; 3]>, Polygons, Tags) {
    let rings = [(0.45, 0.0), (1.0, 0.0), (1.0, 0.5), (0.45, 0.5)];
    let mut pos = Vec::new();
    let mut start = [0usize; 4];
    for (k, &(r, z)) in rings.iter().enumerate() {
        start[k] = pos.len();
        for i in 0..counts[k] {
            let t = 2.0 * std::f64::consts::PI * (i as f64 + 0.3 * k as f64) / counts[k] as f64;
            pos.push([r * t.cos(), r * t.sin(), z]);
        }
    }
    let id = |ring: usize, i: usize| (start[ring] + i % counts[ring]) as u32;
    let angle = |ring: usize, i: usize| (i as f64 + 0.3 * ring as f64) / counts[ring] as f64;
    let mut tris = Vec::new();
    let mut tags = Tags::new();
    for a in 0..4 {
        let b = (a + 1) % 4;
        let (mut i, mut j) = (0, 0);
        while i < counts[a] || j < counts[b] {
            let advance_a = j >= counts[b] || (i < counts[a] && angle(a, i + 1) <= angle(b, j + 1));
            if advance_a {
                tris.push([id(a, i), id(b, j), id(a, i + 1)]);
                i += 1;
            } else {
                tris.push([id(a, i), id(b, j), id(b, j + 1)]);
                j += 1;
            }
        }
        for i in 0..counts[a] {
            tags.set_crease(id(a, i), id(a, i + 1), 10.0);
        }
    }
    (pos, Polygons::from_triangles(&tris), tags)
}

#[test]
fn near_a_crease_the_search_never_ends_farther_than_a_known_surface_point() {
    let (pos, faces, tags) = creased_washer([11, 37, 29, 13]);
    let ev = Evaluator::new(&faces, pos.len(), &tags, &Options::new(Scheme::Loop)).unwrap();
    let finder = ClosestPointFinder::new(&ev, &pos, ClosestOptions::default()).unwrap();
    let params = ev.random_params(4000, 7);
    let points = ev.evaluate_batch(&pos, &params).unwrap();
    let mut worst: f64 = 0.0;
    for (k, s) in points.iter().enumerate() {
        // Just off the surface, on either side: the known point is 1e-3 away.
        let side = if k % 2 == 0 { 1e-3 } else { -1e-3 };
        let q: [f64; 3] = std::array::from_fn(|c| s.position[c] + side * s.normal[c]);
        let c = finder.closest(q).unwrap();
        worst = worst.max(c.distance - 1e-3);
    }
    println!("creased washer: closest distance at most {worst:.2e} beyond the known point's");
    assert!(worst <= 1e-9, "{worst}");
}
