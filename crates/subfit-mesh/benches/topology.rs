//! Topology timings on a 1M-triangle torus grid: half-edge construction, diagnostics, boundary
//! loops and components.

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use subfit_mesh::{diagnose, face_components, HalfEdgeMesh, Polygons};

#[path = "../tests/common/mod.rs"]
mod common;

fn topology(c: &mut Criterion) {
    // 1000 × 500 cells, two triangles each: 1,000,000 faces, 500,000 vertices.
    let (faces, nv): (Polygons, usize) = common::torus(1000, 500, true);
    let mut g = c.benchmark_group("torus_1M_triangles");
    g.sample_size(10);
    g.bench_function("halfedge_build", |b| {
        b.iter(|| HalfEdgeMesh::new(black_box(&faces), nv).expect("valid"))
    });
    g.bench_function("diagnose", |b| {
        b.iter(|| diagnose(black_box(&faces), nv, None))
    });
    let mesh = HalfEdgeMesh::new(&faces, nv).expect("valid");
    g.bench_function("genus_from_halfedge", |b| {
        b.iter(|| black_box(&mesh).genus())
    });
    g.bench_function("face_components", |b| {
        b.iter(|| face_components(black_box(&faces), nv))
    });
    g.finish();
}

criterion_group!(benches, topology);
criterion_main!(benches);
