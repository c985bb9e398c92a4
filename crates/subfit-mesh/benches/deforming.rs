//! Deforming-sequence timings: one frame of about 25k vertices (tessellation, projection onto
//! the rest shape and `Φ_t`), the material lookup over it, and the drift of 25k points over
//! 30 frames.

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use subfit_mesh::deforming::{DeformingParams, DeformingSequence, MaterialLookup};

fn deforming(c: &mut Criterion) {
    let seq = DeformingSequence::new(DeformingParams::large_tangential_motion()).expect("valid");
    let mut g = c.benchmark_group("deforming_25k");
    g.sample_size(20);
    g.bench_function("frame", |b| b.iter(|| seq.frame(black_box(7), 25_000, 1)));
    let first = seq.frame(0, 25_000, 1);
    g.bench_function("material_lookup_build", |b| {
        b.iter(|| MaterialLookup::new(black_box(&first)))
    });
    let lookup = MaterialLookup::new(&first);
    let tracked: Vec<Vec<[f64; 3]>> = (0..seq.len())
        .map(|t| seq.deform_all(t, &first.material))
        .collect();
    g.bench_function("drift_30_frames", |b| {
        b.iter(|| seq.drift(black_box(&tracked), &lookup))
    });
    g.finish();
}

criterion_group!(benches, deforming);
criterion_main!(benches);
