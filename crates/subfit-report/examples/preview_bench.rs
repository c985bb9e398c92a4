//! Times `preview::render` on a torus of about 1M triangles with error colours, a 16×8 quad cage
//! as wireframe and a colour bar, and writes the PNG.
//!
//! `cargo run --release -p subfit-report --example preview_bench [-- OUT.png [NU NV]]`
//! (default `/tmp/preview_sample.png`, `NU × NV = 1000 × 500` → 1M triangles).

// A benchmark program reports its figures on stdout.
#![allow(clippy::print_stdout)]

use std::time::Instant;
use subfit_mesh::shapes::torus_mesh;
use subfit_report::error_color;
use subfit_report::preview::{render, ColorBar, PreviewOptions, Wireframe};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = args
        .first()
        .cloned()
        .unwrap_or("/tmp/preview_sample.png".into());
    let nu: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1000);
    let nv: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(500);

    let surface = torus_mesh(1.0, 0.4, nu, nv, true);
    let triangles = surface.faces.triangulate_fan();
    // A made-up error field: smooth bands around the torus, in the scale's range [0, 1.1].
    let colors: Vec<[u8; 3]> = surface
        .positions
        .iter()
        .map(|p| {
            let u = p[1].atan2(p[0]);
            error_color(0.55 + 0.55 * (3.0 * u).sin() * (4.0 * p[2]).cos())
        })
        .collect();
    let cage = torus_mesh(1.0, 0.46, 16, 8, false);
    let mut edges: Vec<[u32; 2]> = cage
        .faces
        .iter()
        .flat_map(|f| (0..f.len()).map(move |i| [f[i], f[(i + 1) % f.len()]]))
        .map(|[a, b]| [a.min(b), a.max(b)])
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let wire = Wireframe {
        positions: &cage.positions,
        edges: &edges,
    };
    let options = PreviewOptions {
        view: subfit_report::preview::View {
            up: subfit_report::preview::UpAxis::Z,
            ..Default::default()
        },
        color_bar: Some(ColorBar {
            max: 0.002,
            suffix: String::new(),
        }),
        ..Default::default()
    };

    let mut times = Vec::new();
    let mut image = None;
    for _ in 0..5 {
        let t = Instant::now();
        image = Some(
            render(
                &surface.positions,
                &triangles,
                &colors,
                Some(wire),
                &options,
            )
            .unwrap(),
        );
        times.push(t.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    let image = image.unwrap();
    let t = Instant::now();
    let png = image.to_png().unwrap();
    let t_png = t.elapsed().as_secs_f64();
    std::fs::write(&out, &png).unwrap();
    println!(
        "{} triangles, {} vertices, {} wire edges, {}x{} at 2x2 supersampling, {} threads: \
         render median {:.3} s (min {:.3} s), PNG encode {:.3} s ({} KiB) -> {out}",
        triangles.len(),
        surface.positions.len(),
        edges.len(),
        options.width,
        options.height,
        rayon::current_num_threads(),
        times[2],
        times[0],
        t_png,
        png.len() / 1024
    );
}
