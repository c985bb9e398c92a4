//! Three open CAD-like patches in the spirit of Lavoué et al. 2007, Table 1 and Fig. 12 (that
//! kind of result on patches of our own making), written as triangle meshes
//! scaled to the unit cube (longest side 1, the paper's units for its `E_L1`):
//!
//! ```text
//! cargo run --release -p subfit --example open_patches -- OUT_DIR
//! ```
//!
//! * `plate_hole.obj`: the square `[-1, 1]²` bent to `z = 0.25 x² − 0.1 y² + 0.1 x y` with a
//!   round hole of radius 0.35 in the middle: 40 rays of 25 vertices from the hole to the
//!   square's edge (1,000 vertices; the paper's Fig. 12a has 950), rays every 9° so that the
//!   square's corners are vertices (with 38 rays the corners were cut off by a chord between
//!   two 45° turns, too gentle to be taken for corners); two boundary loops.
//! * `half_cylinder.obj`: half of a cylinder of radius 0.5 and length 1, 18 × 18 vertices (324,
//!   as Fig. 12b); one boundary loop with four corners.
//! * `saddle.obj`: `z = 0.3 (x² − y²)` over `[-1, 1]²`, 13 × 13 vertices (169, as Fig. 12c's
//!   168); one boundary loop with four corners.
//!
//! Fit each with `subfit fit FILE --scheme quad-tri` (or a budget, `--max-control-points N`),
//! and measure with `subfit compare OUT/control.obj FILE --scheme quad-tri`: the mean distances
//! both ways are the paper's `E_L1` (its threshold ε = 5e-3 in the same units).
#![allow(clippy::print_stdout)]

use std::path::Path;

use subfit::mesh::{PolyMesh, Polygons};

/// A `nu × nv` grid of points `at(u, v)` (`u`, `v` in `[0, 1]`), triangulated along alternating
/// diagonals; `wrap_u` joins the last column to the first.
fn grid(nu: usize, nv: usize, wrap_u: bool, at: impl Fn(f64, f64) -> [f64; 3]) -> PolyMesh {
    let du = if wrap_u { nu } else { nu - 1 };
    let mut positions = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            positions.push(at(i as f64 / du as f64, j as f64 / (nv - 1) as f64));
        }
    }
    let id = |i: usize, j: usize| (j * nu + i % nu) as u32;
    let mut tris = Vec::new();
    for j in 0..nv - 1 {
        for i in 0..du {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i + j) % 2 == 0 {
                tris.extend([[a, b, c], [a, c, d]]);
            } else {
                tris.extend([[a, b, d], [b, c, d]]);
            }
        }
    }
    PolyMesh::new(positions, Polygons::from_triangles(&tris))
}

/// Scales and moves `m` so that its bounding box starts at the origin with longest side 1.
fn unit_cube(mut m: PolyMesh) -> PolyMesh {
    let (lo, hi) = m.bounding_box().expect("a patch has vertices");
    let side = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    for p in &mut m.positions {
        for k in 0..3 {
            p[k] = (p[k] - lo[k]) / side;
        }
    }
    m
}

/// The bent square plate with a round hole (see the module docs).
fn plate_with_hole() -> PolyMesh {
    grid(40, 25, true, |u, v| {
        let t = std::f64::consts::TAU * u;
        let (c, s) = (t.cos(), t.sin());
        // Where the ray from the centre at angle t leaves the square [-1, 1]².
        let edge = 1.0 / c.abs().max(s.abs());
        let r = 0.35 + (edge - 0.35) * v;
        let (x, y) = (r * c, r * s);
        [x, y, 0.25 * x * x - 0.1 * y * y + 0.1 * x * y]
    })
}

/// Half of a cylinder of radius 0.5 and length 1.
fn half_cylinder() -> PolyMesh {
    grid(18, 18, false, |u, v| {
        let t = std::f64::consts::PI * u;
        [0.5 * t.cos(), v, 0.5 * t.sin()]
    })
}

/// The saddle `z = 0.3 (x² − y²)` over `[-1, 1]²`.
fn saddle() -> PolyMesh {
    grid(13, 13, false, |u, v| {
        let (x, y) = (2.0 * u - 1.0, 2.0 * v - 1.0);
        [x, y, 0.3 * (x * x - y * y)]
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args().nth(1).ok_or("open_patches OUT_DIR")?;
    let dir = Path::new(&dir);
    std::fs::create_dir_all(dir)?;
    for (name, mesh) in [
        ("plate_hole", plate_with_hole()),
        ("half_cylinder", half_cylinder()),
        ("saddle", saddle()),
    ] {
        let mesh = unit_cube(mesh);
        let path = dir.join(format!("{name}.obj"));
        subfit::io::write_file(&path, &mesh, &Default::default())?;
        println!(
            "{}: {} vertices, {} faces",
            path.display(),
            mesh.positions.len(),
            mesh.faces.len()
        );
    }
    Ok(())
}
