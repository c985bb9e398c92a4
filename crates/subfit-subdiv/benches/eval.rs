//! Exact evaluation and closest-point throughput on ~1k-face control meshes (Loop and
//! Catmull-Clark tori with extraordinary vertices; a mixed quad/triangle torus under
//! Catmull-Clark and under the quad/triangle scheme), random parameters and queries.
//!
//! Run: `cargo bench -p subfit-subdiv --bench eval`.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use subfit_mesh::shapes::torus_mesh;
use subfit_mesh::{Polygons, Tags};
use subfit_subdiv::{ClosestOptions, ClosestPointFinder, Evaluator, Options, Scheme, SurfaceParam};

/// A torus grid with a few extra extraordinary vertices: every 7th quad (or triangle pair) is
/// split into triangles… kept simple: Loop tori get valence 5/7 pairs by flipping diagonals.
fn meshes() -> Vec<(&'static str, Scheme, Vec<[f64; 3]>, Polygons)> {
    let cc = torus_mesh(1.0, 0.35, 40, 25, false);
    let lt = torus_mesh(1.0, 0.35, 25, 20, true);
    // Flip some diagonals of the Loop torus to create valence 5 and 7 vertices.
    let mut tris: Vec<[u32; 3]> = lt.faces.iter().map(|f| [f[0], f[1], f[2]]).collect();
    let mut i = 0;
    while i + 1 < tris.len() {
        if i % 14 == 0 {
            let (a, b) = (tris[i], tris[i + 1]);
            // Two triangles sharing an edge: find it and flip.
            let shared: Vec<u32> = a.iter().copied().filter(|x| b.contains(x)).collect();
            if shared.len() == 2 {
                let pa = *a.iter().find(|x| !shared.contains(x)).unwrap();
                let pb = *b.iter().find(|x| !shared.contains(x)).unwrap();
                let ia = a.iter().position(|&x| x == pa).unwrap();
                let (s0, s1) = (a[(ia + 1) % 3], a[(ia + 2) % 3]);
                tris[i] = [pa, s0, pb];
                tris[i + 1] = [pb, s1, pa];
            }
        }
        i += 2;
    }
    // Every 7th quad of the Catmull-Clark torus cut into two triangles.
    let mut mixed = Polygons::new();
    for (k, q) in cc.faces.iter().enumerate() {
        if k % 7 == 0 {
            mixed.push(&[q[0], q[1], q[2]]);
            mixed.push(&[q[0], q[2], q[3]]);
        } else {
            mixed.push(q);
        }
    }
    vec![
        (
            "catmull-clark mixed torus (every 7th quad cut)",
            Scheme::CatmullClark,
            cc.positions.clone(),
            mixed.clone(),
        ),
        (
            "quad-tri mixed torus (every 7th quad cut)",
            Scheme::QuadTriangle,
            cc.positions.clone(),
            mixed,
        ),
        (
            "catmull-clark torus 1000 quads",
            Scheme::CatmullClark,
            cc.positions,
            cc.faces,
        ),
        (
            "loop torus 1000 triangles (valence 5/6/7)",
            Scheme::Loop,
            lt.positions,
            Polygons::from_triangles(&tris),
        ),
    ]
}

fn bench(c: &mut Criterion) {
    for (name, scheme, p, f) in meshes() {
        let ev = match Evaluator::new(&f, p.len(), &Tags::new(), &Options::new(scheme)) {
            Ok(ev) => ev,
            Err(_) => continue,
        };
        let params: Vec<SurfaceParam> = ev.random_params(1000, 1);
        // Points near extraordinary/irregular corners: 1e-6 from a corner of irregular patches.
        let near: Vec<SurfaceParam> = (0..ev.num_patches())
            .map(|i| ev.patch(i))
            .filter(|&(f, s)| !ev.is_regular(f, s))
            .take(1000)
            .map(|(face, sub)| SurfaceParam {
                face,
                sub,
                u: 1e-6,
                v: 1e-6,
            })
            .collect();
        let mut g = c.benchmark_group(name);
        g.throughput(Throughput::Elements(params.len() as u64));
        g.bench_function("evaluate random (face,u,v), 1 thread", |b| {
            b.iter(|| {
                for &q in &params {
                    std::hint::black_box(ev.evaluate(&p, q).unwrap());
                }
            })
        });
        g.bench_function("evaluate_batch random (rayon)", |b| {
            b.iter(|| std::hint::black_box(ev.evaluate_batch(&p, &params).unwrap()))
        });
        if !near.is_empty() {
            g.throughput(Throughput::Elements(near.len() as u64));
            g.bench_function("evaluate 1e-6 from irregular corners, 1 thread", |b| {
                b.iter(|| {
                    for &q in &near {
                        std::hint::black_box(ev.evaluate(&p, q).unwrap());
                    }
                })
            });
        }
        let finder = ClosestPointFinder::new(&ev, &p, ClosestOptions::default()).unwrap();
        let (lo, hi) = subfit_mesh::bounding_box(&p).unwrap();
        let mut state = 7u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let queries: Vec<[f64; 3]> = (0..200)
            .map(|_| [0, 1, 2].map(|k| lo[k] + (hi[k] - lo[k]) * rnd()))
            .collect();
        g.throughput(Throughput::Elements(queries.len() as u64));
        g.bench_function("closest point, 1 thread", |b| {
            b.iter(|| {
                for &q in &queries {
                    std::hint::black_box(finder.closest(q).unwrap());
                }
            })
        });
        g.sample_size(10);
        g.bench_function("ClosestPointFinder::new (tessellation + BVH)", |b| {
            b.iter_batched(
                || (),
                |_| ClosestPointFinder::new(&ev, &p, ClosestOptions::default()).unwrap(),
                BatchSize::SmallInput,
            )
        });
        g.bench_function("Evaluator::new", |b| {
            b.iter(|| Evaluator::new(&f, p.len(), &Tags::new(), &Options::new(scheme)).unwrap())
        });
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
