//! PLY parsing throughput: a ~4 MB binary little-endian file and a ~4 MB ascii file, both
//! triangulated grids made here, plus `igea.ply` (binary tristrips) when `SUBFIT_DATA` is set.
//! Criterion reports MB/s (`Throughput::Bytes`).

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use subfit_io::{ply, Encoding};
use subfit_mesh::{PolyMesh, Polygons};

/// A wavy `n × n` grid split into triangles.
fn grid(n: u32) -> PolyMesh {
    let mut positions = Vec::with_capacity((n * n) as usize);
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            positions.push([x, y, 0.05 * (7.0 * x).sin() * (5.0 * y).cos()]);
        }
    }
    let mut faces = Polygons::with_capacity(2 * (n * n) as usize, 6 * (n * n) as usize);
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let v = j * n + i;
            faces.push(&[v, v + 1, v + n + 1]);
            faces.push(&[v, v + n + 1, v + n]);
        }
    }
    PolyMesh::new(positions, faces)
}

fn encode(mesh: &PolyMesh, enc: Encoding, single: bool) -> Vec<u8> {
    let mut out = Vec::new();
    ply::write(mesh, enc, single, &mut out).expect("writing to memory");
    out
}

fn bench(c: &mut Criterion) {
    let path = Path::new("bench.ply");
    // float coordinates: 12 bytes per vertex + 13 per triangle ≈ 38 bytes per vertex.
    let binary = encode(&grid(325), Encoding::BinaryLittleEndian, true);
    // shortest f64 decimals: ≈ 100 bytes per vertex with its two triangles.
    let ascii = encode(&grid(200), Encoding::Ascii, false);
    let mut cases = vec![("binary_le_4MB", binary), ("ascii_4MB", ascii)];
    if let Some(dir) = std::env::var_os("SUBFIT_DATA") {
        if let Ok(bytes) = std::fs::read(Path::new(&dir).join("igea.ply")) {
            cases.push(("igea_tristrips", bytes));
        }
    }
    let mut group = c.benchmark_group("ply_read");
    for (name, bytes) in &cases {
        group.throughput(Throughput::Bytes(bytes.len() as u64));
        group.bench_function(*name, |b| {
            b.iter(|| ply::read(black_box(bytes), path, &mut Vec::new()).expect("valid PLY"))
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench
}
criterion_main!(benches);
