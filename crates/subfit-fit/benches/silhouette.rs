//! The soft silhouette loss on a fitter-sized mesh: a 29,700-triangle sphere (radius 1) seen
//! by 8 orthographic views of 128², default options, against the same sphere scaled by 1.02 and
//! shifted by 0.01 (a fitter's state near convergence); then the same with 7,350 triangles.
//! Times the target rendering, the loss and the loss with its gradient, on all cores and on one.
//!
//! Run: `cargo bench -p subfit-fit --bench silhouette`.

#[path = "../tests/common/sphere.rs"]
mod sphere;

use criterion::{criterion_group, criterion_main, Criterion};
use sphere::uv_sphere;
use subfit_fit::silhouette::{cameras_around, Silhouette, SoftOptions};

fn bench(c: &mut Criterion) {
    // 29.7k triangles of about 2 × 2.5 pixels, and 7.35k of about 4 × 5 (the cheaper choice for
    // a predicted surface, see the module documentation).
    for (n_lon, n_lat) in [(150, 100), (75, 50)] {
        bench_sphere(c, n_lon, n_lat);
    }
}

fn bench_sphere(c: &mut Criterion, n_lon: usize, n_lat: usize) {
    let (target, triangles) = uv_sphere(1.0, [0.0; 3], n_lon, n_lat);
    let cameras = cameras_around([0.0; 3], 1.0, 8, 128);
    let silhouette =
        Silhouette::from_mesh(cameras.clone(), &target, &triangles, SoftOptions::default());
    let predicted: Vec<[f64; 3]> = target.iter().map(|p| p.map(|x| 1.02 * x + 0.01)).collect();
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool");

    let mut g = c.benchmark_group(format!(
        "silhouette {} triangles, 8 × 128²",
        triangles.len()
    ));
    g.sample_size(10);
    g.bench_function("Silhouette::from_mesh (render targets)", |b| {
        b.iter(|| {
            Silhouette::from_mesh(cameras.clone(), &target, &triangles, SoftOptions::default())
        })
    });
    g.bench_function("loss", |b| {
        b.iter(|| silhouette.loss(&predicted, &triangles))
    });
    g.bench_function("loss_and_gradient", |b| {
        b.iter(|| silhouette.loss_and_gradient(&predicted, &triangles))
    });
    g.bench_function("loss, 1 thread", |b| {
        b.iter(|| one_thread.install(|| silhouette.loss(&predicted, &triangles)))
    });
    g.bench_function("loss_and_gradient, 1 thread", |b| {
        b.iter(|| one_thread.install(|| silhouette.loss_and_gradient(&predicted, &triangles)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
