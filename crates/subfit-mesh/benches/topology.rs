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
    // Same mesh with vertex ids randomly permuted (scans are rarely stored in grid order).
    let shuffled = shuffle_vertices(&faces, nv);
    g.bench_function("halfedge_build_shuffled", |b| {
        b.iter(|| HalfEdgeMesh::new(black_box(&shuffled), nv).expect("valid"))
    });
    g.bench_function("diagnose_shuffled", |b| {
        b.iter(|| diagnose(black_box(&shuffled), nv, None))
    });
    g.finish();
}

/// Relabels the vertices by a seeded random permutation (xorshift64, Fisher–Yates).
fn shuffle_vertices(faces: &Polygons, nv: usize) -> Polygons {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut perm: Vec<u32> = (0..nv as u32).collect();
    for i in (1..nv).rev() {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        perm.swap(i, (state % (i as u64 + 1)) as usize);
    }
    let mut out = faces.clone();
    for v in out.indices_mut() {
        *v = perm[*v as usize];
    }
    out
}

criterion_group!(benches, topology);
criterion_main!(benches);
