//! Generated hard cases for coverage (thin parts, a thin handle, genus 8, partial clouds), each
//! with its known surface, written to a folder that `subfit bench corpus` fits with defaults and
//! judges two-sided (RMS and Hausdorff as fractions of the diagonal, genus kept):
//!
//! ```text
//! cargo run --release -p subfit --example coverage_cases -- OUT_DIR
//! subfit bench corpus OUT_DIR --out OUT_DIR/scoreboard.json
//! ```
//!
//! The shapes are those of [`subfit::mesh::thin_shapes`]; thicknesses are fractions of each
//! shape's length (capsule), diameter (coin) or tube circle (handle), so the names say how thin
//! a part is against the whole. The partial clouds are single-view range scans
//! ([`subfit::mesh::range_scan::range_scan`], 300 × 300 pixels, noise 2e-4 of the diagonal) of
//! the handle and the lattice: an open sheet with holes where the view is occluded.
#![allow(clippy::print_stdout)]

use std::path::Path;

use subfit::mesh::range_scan::range_scan;
use subfit::mesh::thin_shapes::{capsule, coin, handle_torus, lattice, LatticeOptions};
use subfit::mesh::PolyMesh;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .ok_or("usage: coverage_cases OUT_DIR")?;
    let dir = Path::new(&dir);
    std::fs::create_dir_all(dir)?;
    let mut cases: Vec<(String, PolyMesh)> = Vec::new();
    for t in [0.005, 0.01, 0.02, 0.05] {
        cases.push((format!("capsule-t{t}.obj"), capsule(0.5 * t, 1.0, 24)));
    }
    for t in [0.01, 0.02, 0.05] {
        cases.push((format!("coin-t{t}.obj"), coin(0.5, t, 192, 4)));
    }
    for thin in [0.02, 0.05] {
        cases.push((
            format!("handle-thin{thin}.obj"),
            handle_torus(1.0, 0.6, thin, 256, 32),
        ));
    }
    let grid = LatticeOptions {
        thickness: 0.5,
        ..Default::default()
    };
    let genus8 = lattice(&grid);
    let handle = handle_torus(1.0, 0.6, 0.1, 256, 32);
    for (name, m, view) in [
        ("range-handle.xyz", &handle, [0.3, 0.2, -1.0]),
        ("range-lattice.xyz", &genus8, [0.2, 0.3, -1.0]),
    ] {
        let points = range_scan(m, 300, 2e-4, Some(view), 1);
        cases.push((name.to_string(), PolyMesh::point_cloud(points, None)));
    }
    cases.push(("lattice-genus8.obj".to_string(), genus8));
    for (name, m) in &cases {
        subfit::io::write_file(&dir.join(name), m, &Default::default())?;
        println!(
            "{name}: {} vertices, {} faces",
            m.num_vertices(),
            m.num_faces()
        );
    }
    Ok(())
}
