//! The soft silhouette (`subfit_fit::silhouette`): its gradient against finite differences,
//! the area of a rendered sphere against `π r²`, the loss at and near the target, a points
//! target against a mesh target, and invariants (orientation, translation by a pixel, scale,
//! thread count).

#[path = "common/sphere.rs"]
mod sphere;

use std::f64::consts::PI;

use sphere::uv_sphere;
use subfit_fit::silhouette::{
    cameras_around, render_mesh, render_points, Camera, Silhouette, SoftOptions,
};
use subfit_mesh::shapes::Shape;

/// A deterministic pseudo-random number in [-1, 1) (SplitMix64).
fn uniform(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// A coarse sphere of radius 0.5 moved off a finer target sphere (shifted, jittered), with
/// 4 views of 48² around the target: the fixture of the gradient tests.
fn offset_fixture() -> (Silhouette, Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let (target, target_tris) = uv_sphere(0.5, [0.0; 3], 24, 12);
    let cameras = cameras_around([0.0; 3], 0.6, 4, 48);
    let silhouette = Silhouette::from_mesh(cameras, &target, &target_tris, SoftOptions::default());
    let (mut positions, triangles) = uv_sphere(0.5, [0.02, -0.015, 0.01], 10, 6);
    let mut rng = 7;
    for p in &mut positions {
        for c in p.iter_mut() {
            *c += 0.01 * uniform(&mut rng);
        }
    }
    (silhouette, positions, triangles)
}

fn moved(positions: &[[f64; 3]], direction: &[[f64; 3]], step: f64) -> Vec<[f64; 3]> {
    positions
        .iter()
        .zip(direction)
        .map(|(p, d)| [p[0] + step * d[0], p[1] + step * d[1], p[2] + step * d[2]])
        .collect()
}

#[test]
fn gradient_matches_central_differences() {
    let (silhouette, positions, triangles) = offset_fixture();
    // Enough pixels in the soft transition zones for the check to mean something.
    let images = silhouette.images(&positions, &triangles);
    let transition = images
        .iter()
        .flat_map(|im| &im.pixels)
        .filter(|&&v| v > 0.01 && v < 0.99)
        .count();
    assert!(transition > 300, "only {transition} pixels in transition");

    let (loss, gradient) = silhouette.loss_and_gradient(&positions, &triangles);
    assert!((loss - silhouette.loss(&positions, &triangles)).abs() <= 1e-15 * loss);
    let h = 1e-6;
    let fd = |direction: &[[f64; 3]]| {
        let plus = silhouette.loss(&moved(&positions, direction, h), &triangles);
        let minus = silhouette.loss(&moved(&positions, direction, -h), &triangles);
        (plus - minus) / (2.0 * h)
    };
    let unit = |v: usize, c: usize| {
        let mut d = vec![[0.0; 3]; positions.len()];
        d[v][c] = 1.0;
        d
    };
    let max_g = gradient
        .iter()
        .flatten()
        .fold(0.0f64, |m, &g| m.max(g.abs()));
    assert!(max_g > 0.0);
    // Measured: errors about 3e-10 of the largest component, of each of the ten largest and of
    // the directional derivative. Every component, against the largest:
    let mut worst = 0.0f64;
    let mut components: Vec<(f64, usize, usize)> = Vec::new();
    for (v, g) in gradient.iter().enumerate() {
        for (c, &gc) in g.iter().enumerate() {
            let numeric = fd(&unit(v, c));
            worst = worst.max((numeric - gc).abs());
            components.push((gc.abs(), v, c));
        }
    }
    assert!(
        worst <= 1e-7 * max_g,
        "worst error {worst:e}, largest component {max_g:e}"
    );
    // The ten largest components, each relative to itself.
    components.sort_by(|a, b| b.0.total_cmp(&a.0));
    for &(g, v, c) in &components[..10] {
        let numeric = fd(&unit(v, c));
        let rel = (numeric - gradient[v][c]).abs() / g;
        assert!(
            rel <= 1e-7,
            "vertex {v} coordinate {c}: {numeric:e} vs {:e}",
            gradient[v][c]
        );
    }
    // A random direction.
    let mut rng = 11;
    let direction: Vec<[f64; 3]> = (0..positions.len())
        .map(|_| [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)])
        .collect();
    let analytic: f64 = gradient
        .iter()
        .zip(&direction)
        .map(|(g, d)| g[0] * d[0] + g[1] * d[1] + g[2] * d[2])
        .sum();
    let numeric = fd(&direction);
    assert!(
        (numeric - analytic).abs() <= 1e-7 * analytic.abs(),
        "directional derivative {numeric:e} vs {analytic:e}"
    );
}

#[test]
fn loss_vanishes_at_the_target_and_decreases_along_the_negative_gradient() {
    let (silhouette, positions, triangles) = offset_fixture();
    let (target, target_tris) = uv_sphere(0.5, [0.0; 3], 24, 12);
    assert!(silhouette.loss(&target, &target_tris) <= 1e-12);
    let (zero_loss, zero_gradient) = silhouette.loss_and_gradient(&target, &target_tris);
    assert!(zero_loss <= 1e-12);
    assert!(zero_gradient.iter().flatten().all(|g| g.abs() <= 1e-12));

    let (loss, gradient) = silhouette.loss_and_gradient(&positions, &triangles);
    assert!(loss > 1e-4, "the fixture is off its target (loss {loss:e})");
    let norm = gradient.iter().flatten().map(|g| g * g).sum::<f64>().sqrt();
    // Largest vertex motion a tenth of a pixel.
    let step = 0.1 * silhouette.cameras()[0].pixel_size() / norm;
    let descent: Vec<[f64; 3]> = gradient.iter().map(|g| g.map(|c| -c)).collect();
    let after = silhouette.loss(&moved(&positions, &descent, step), &triangles);
    assert!(after < loss, "{after:e} ≥ {loss:e}");
    // First order: the decrease is close to step·|g|².
    let predicted = step * norm * norm;
    assert!(((loss - after) / predicted - 1.0).abs() < 0.05);
}

#[test]
fn sphere_silhouette_area_is_pi_r_squared() {
    // Triangles of a few pixels: the regime where the soft silhouette's area is the hard one's
    // (finer meshes bleed outwards at the rim, see the next test).
    let r = 0.8;
    let (positions, triangles) = uv_sphere(r, [0.1, -0.2, 0.3], 80, 40);
    for camera in cameras_around([0.1, -0.2, 0.3], r, 5, 256) {
        let image = render_mesh(&camera, &positions, &triangles, &SoftOptions::default());
        let area = image.coverage() * camera.pixel_area();
        let rel = area / (PI * r * r) - 1.0;
        assert!(rel.abs() < 0.01, "{camera:?}: relative area error {rel:e}");
    }
}

#[test]
fn a_large_triangle_has_its_area() {
    let positions = [[-0.8, -0.7, 0.1], [0.9, -0.5, 0.0], [0.1, 0.85, -0.3]];
    let exact = 0.5 * (1.7 * 1.55 - 0.2 * 0.9);
    let camera = Camera::new([0.0; 3], [0.0, 0.0, 1.0], 1.0, 128);
    for sigma in [0.01, 1.0, 4.0] {
        let options = SoftOptions::default().with_sigma(sigma);
        let image = render_mesh(&camera, &positions, &[[0, 1, 2]], &options);
        let rel = image.coverage() * camera.pixel_area() / exact - 1.0;
        // Only the corners lose a little of the soft edge, O(σ) px² each.
        assert!(rel.abs() < 2e-3 * sigma.max(1.0), "σ = {sigma}: {rel:e}");
    }
}

#[test]
fn fine_meshes_bleed_outwards_at_the_rim() {
    // Each rim edge is shared by a front and a back triangle, and near the rim many
    // foreshortened triangles lie within a pixel of it: their tails add up outside. The
    // excess grows with the number of triangles per pixel at the rim, not with σ alone.
    let r = 1.0;
    let cameras = cameras_around([0.0; 3], r, 3, 128);
    let excess = |n_lon, n_lat| {
        let (positions, triangles) = uv_sphere(r, [0.0; 3], n_lon, n_lat);
        let image = render_mesh(&cameras[0], &positions, &triangles, &SoftOptions::default());
        image.coverage() * cameras[0].pixel_area() / (PI * r * r) - 1.0
    };
    let (coarse, fine) = (excess(40, 20), excess(150, 100));
    assert!(coarse.abs() < 0.03, "{coarse}");
    assert!(fine > coarse && fine < 0.1, "{fine} vs {coarse}");
}

#[test]
fn points_target_matches_the_mesh_target() {
    let r = 0.5;
    let n = 40_000;
    let cloud = Shape::Ellipsoid { a: r, b: r, c: r }.sample(n, 0.0, 5);
    let spacing = (4.0 * PI * r * r / n as f64).sqrt();
    let (positions, triangles) = uv_sphere(r, [0.0; 3], 150, 100);
    let options = SoftOptions::default();
    let cameras = cameras_around([0.0; 3], r, 3, 128);
    let silhouette = Silhouette::from_points(cameras.clone(), &cloud.positions, spacing, options);
    for (camera, target) in cameras.iter().zip(silhouette.targets()) {
        let mesh = render_mesh(camera, &positions, &triangles, &options);
        let points = render_points(camera, &cloud.positions, spacing, &options);
        assert_eq!(&points, target);
        let rel = points.coverage() / mesh.coverage() - 1.0;
        assert!(rel.abs() < 0.05, "relative area difference {rel:e}");
        // No holes inside.
        let holes = mesh
            .pixels
            .iter()
            .zip(&points.pixels)
            .filter(|&(&m, &p)| m > 0.99 && p < 0.9)
            .count();
        assert_eq!(holes, 0);
    }
}

#[test]
fn a_non_finite_vertex_leaves_its_triangles_out() {
    let (silhouette, mut positions, triangles) = offset_fixture();
    positions[3] = [f64::NAN, 0.0, f64::INFINITY];
    let (loss, gradient) = silhouette.loss_and_gradient(&positions, &triangles);
    assert!(loss.is_finite());
    assert_eq!(gradient[3], [0.0; 3]);
    assert!(gradient.iter().flatten().all(|g| g.is_finite()));
}

#[test]
fn orientation_does_not_matter() {
    let (positions, triangles) = uv_sphere(0.5, [0.0; 3], 12, 8);
    let flipped: Vec<[u32; 3]> = triangles.iter().map(|t| [t[0], t[2], t[1]]).collect();
    for camera in cameras_around([0.0; 3], 0.5, 3, 64) {
        let a = render_mesh(&camera, &positions, &triangles, &SoftOptions::default());
        let b = render_mesh(&camera, &positions, &flipped, &SoftOptions::default());
        for (x, y) in a.pixels.iter().zip(&b.pixels) {
            assert!((x - y).abs() <= 1e-14);
        }
    }
}

#[test]
fn translation_by_a_pixel_shifts_the_image() {
    let (positions, triangles) = uv_sphere(0.3, [0.0; 3], 16, 10);
    let camera = cameras_around([0.0; 3], 0.5, 2, 64)[1];
    let h = camera.pixel_size();
    let shifted: Vec<[f64; 3]> = positions
        .iter()
        .map(|p| [0, 1, 2].map(|c| p[c] + h * camera.right[c]))
        .collect();
    let a = render_mesh(&camera, &positions, &triangles, &SoftOptions::default());
    let b = render_mesh(&camera, &shifted, &triangles, &SoftOptions::default());
    let n = camera.resolution;
    for y in 0..n {
        for x in 0..n - 1 {
            let (before, after) = (a.pixels[y * n + x], b.pixels[y * n + x + 1]);
            assert!((before - after).abs() <= 1e-9, "pixel ({x}, {y})");
        }
    }
}

#[test]
fn images_are_invariant_to_scale() {
    let (positions, triangles) = uv_sphere(0.5, [0.1, 0.0, -0.1], 12, 8);
    let reference = {
        let cameras = cameras_around([0.0; 3], 0.7, 3, 48);
        Silhouette::from_mesh(cameras, &positions, &triangles, SoftOptions::default())
    };
    for s in [1e-6, 1e6] {
        let scaled: Vec<[f64; 3]> = positions.iter().map(|p| p.map(|c| c * s)).collect();
        let cameras = cameras_around([0.0; 3], 0.7 * s, 3, 48);
        let silhouette =
            Silhouette::from_mesh(cameras, &scaled, &triangles, SoftOptions::default());
        for (a, b) in reference.targets().iter().zip(silhouette.targets()) {
            for (x, y) in a.pixels.iter().zip(&b.pixels) {
                assert!((x - y).abs() <= 1e-9);
            }
        }
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let (silhouette, positions, triangles) = offset_fixture();
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool")
            .install(|| silhouette.loss_and_gradient(&positions, &triangles))
    };
    let (one, two) = (run(1), run(3));
    assert_eq!(one.0.to_bits(), two.0.to_bits());
    assert_eq!(one.1, two.1);
}

#[test]
fn cameras_around_spread_distinct_lines_of_sight() {
    let cameras = cameras_around([1.0, 2.0, 3.0], 2.0, 8, 128);
    assert_eq!(cameras.len(), 8);
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    for (i, c) in cameras.iter().enumerate() {
        // Orthonormal, right-handed basis; the bounding sphere inside the image.
        for (a, b, expect) in [
            (c.direction, c.direction, 1.0),
            (c.right, c.right, 1.0),
            (c.up, c.up, 1.0),
            (c.direction, c.right, 0.0),
            (c.direction, c.up, 0.0),
            (c.right, c.up, 0.0),
        ] {
            assert!((dot(a, b) - expect).abs() < 1e-12);
        }
        assert!(c.direction[2] > 0.0);
        assert!(c.half_size > 2.0 * 1.05);
        let centre = c.project([1.0, 2.0, 3.0]);
        assert!((centre[0] - 64.0).abs() < 1e-9 && (centre[1] - 64.0).abs() < 1e-9);
        // No two views along the same line (orthographic views from ±d are mirror images).
        for other in &cameras[..i] {
            assert!(dot(c.direction, other.direction).abs() < 0.95);
        }
    }
}
