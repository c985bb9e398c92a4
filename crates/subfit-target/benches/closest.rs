//! Closest point on a triangle mesh ([`subfit_target::TriangleBvh`]): build time and query
//! throughput on a 90,000-triangle torus, queries scattered within its bounding box.
//!
//! Run: `cargo bench -p subfit-target --bench closest` (`-- --quick` for a rough figure).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use subfit_mesh::shapes::torus_mesh;
use subfit_target::TriangleBvh;

fn bench(c: &mut Criterion) {
    let mesh = torus_mesh(1.0, 0.35, 300, 150, true);
    let tris = mesh.faces.triangulate_fan();
    let (lo, hi) = subfit_mesh::bounding_box(&mesh.positions).unwrap();
    let mut state = 7u64;
    let mut rnd = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let queries: Vec<[f64; 3]> = (0..10_000)
        .map(|_| [0, 1, 2].map(|k| lo[k] + (hi[k] - lo[k]) * rnd()))
        .collect();
    let bvh = TriangleBvh::new(mesh.positions.clone(), tris.clone());
    let mut g = c.benchmark_group("torus 90k triangles");
    g.throughput(Throughput::Elements(queries.len() as u64));
    g.bench_function("closest, 1 thread", |b| {
        b.iter(|| {
            for &q in &queries {
                std::hint::black_box(bvh.closest(q).unwrap());
            }
        })
    });
    g.throughput(Throughput::Elements(tris.len() as u64));
    g.sample_size(10);
    g.bench_function("TriangleBvh::new", |b| {
        b.iter(|| TriangleBvh::new(mesh.positions.clone(), tris.clone()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
