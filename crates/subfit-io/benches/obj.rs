//! OBJ parsing throughput on a ~4 MB file made here (a wavy triangulated grid written with
//! shortest f64 decimals, with and without `vn`/`//n` corners), plus `armadillo.obj` (4 MB)
//! when `SUBFIT_DATA` is set. Criterion reports MB/s (`Throughput::Bytes`).

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use subfit_io::obj;
use subfit_mesh::{PolyMesh, Polygons};

/// A wavy `n × n` grid split into triangles, with unit-ish normals.
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

fn encode(mesh: &PolyMesh) -> Vec<u8> {
    let mut out = Vec::new();
    obj::write(mesh, &mut out).expect("writing to memory");
    out
}

fn bench(c: &mut Criterion) {
    let path = Path::new("bench.obj");
    // ≈ 100 bytes per vertex (one `v` line and two `f` lines).
    let plain = encode(&grid(200));
    let mut with_normals = grid(150);
    with_normals.normals = Some(
        with_normals
            .positions
            .iter()
            .map(|p| [-0.3 * p[2], 0.1 * p[0], 1.0])
            .collect(),
    );
    let normals = encode(&with_normals);
    let mut cases = vec![("grid_4MB", plain), ("grid_normals_4MB", normals)];
    if let Some(dir) = std::env::var_os("SUBFIT_DATA") {
        if let Ok(bytes) = std::fs::read(Path::new(&dir).join("armadillo.obj")) {
            cases.push(("armadillo", bytes));
        }
    }
    let mut group = c.benchmark_group("obj_read");
    group.sample_size(20);
    for (name, bytes) in &cases {
        group.throughput(Throughput::Bytes(bytes.len() as u64));
        group.bench_function(*name, |b| {
            b.iter(|| obj::read(black_box(bytes), path, &mut Vec::new()).expect("valid OBJ"))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
