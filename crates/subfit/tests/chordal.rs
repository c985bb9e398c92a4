//! The chordal tolerance on generated CAD parts whose true shape is known: a coarse export of
//! a capped cylinder fitted with `chordal` comes out closer to the true cylinder than the
//! export itself (two-sided RMS), within the export's vertex count; a box stays exact.

#![allow(clippy::print_stderr)] // the figures are printed

use subfit::measure::MeshDistance;
use subfit::mesh::shapes::{capped_cylinder, gridded_box};
use subfit::mesh::{PolyMesh, Polygons};
use subfit::subdiv::sampling_operator;
use subfit::{fit_scan, FitScanOptions, Fitted, Input};

const R: f64 = 10.0;
const H: f64 = 20.0;

/// The capped cylinder of radius `R` and height `H` exported with `m` segments.
fn export(m: usize) -> PolyMesh {
    capped_cylinder(R, H, m)
}

/// Distance of `x` to the true cylinder's surface.
fn to_cylinder(x: [f64; 3]) -> f64 {
    let r = (x[0] * x[0] + x[1] * x[1]).sqrt();
    let (dr, dz) = (r - R, (-x[2]).max(x[2] - H));
    if dr > 0.0 || dz > 0.0 {
        (dr.max(0.0).powi(2) + dz.max(0.0).powi(2)).sqrt()
    } else {
        (-dr).min(-dz)
    }
}

/// Points of the true cylinder, about uniform by area (a grid on the side, rings on the caps).
fn cylinder_points() -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    let (na, nz) = (360, 120);
    for k in 0..=nz {
        for i in 0..na {
            let a = std::f64::consts::TAU * (i as f64 + 0.5) / na as f64;
            out.push([R * a.cos(), R * a.sin(), H * k as f64 / nz as f64]);
        }
    }
    for z in [0.0, H] {
        for ring in 1..30 {
            let r = R * ring as f64 / 30.0;
            let n = 12 * ring;
            for i in 0..n {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                out.push([r * a.cos(), r * a.sin(), z]);
            }
        }
    }
    out
}

/// Two-sided RMS between `surface` (a triangle mesh, its vertices a fine sampling of it) and
/// the true cylinder: the worse of the two directions.
fn rms_to_cylinder(surface: &PolyMesh) -> f64 {
    let rms = |d: Vec<f64>| (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt();
    let out = rms(surface.positions.iter().map(|&x| to_cylinder(x)).collect());
    let back = rms(MeshDistance::new(&surface.positions, &surface.faces)
        .distances(&cylinder_points())
        .iter()
        .map(|p| p.distance)
        .collect());
    out.max(back)
}

/// The export cut into `n²` flat pieces per facet (so its vertices sample its facets).
fn flat_pieces(m: &PolyMesh, n: usize) -> PolyMesh {
    let mut p = Vec::new();
    let mut t = Vec::new();
    for tri in m.faces.triangulate_fan() {
        let [a, b, c] = tri.map(|v| m.positions[v as usize]);
        let base = p.len() as u32;
        let id = |i: usize, j: usize| base + (i * (n + 1) + j) as u32;
        for i in 0..=n {
            for j in 0..=n {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let (u, v) = if u + v > 1.0 {
                    (1.0 - v, 1.0 - u)
                } else {
                    (u, v)
                };
                p.push([0, 1, 2].map(|k| (1.0 - u - v) * a[k] + u * b[k] + v * c[k]));
            }
        }
        for i in 0..n {
            for j in 0..n - i {
                t.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
            }
        }
    }
    PolyMesh::new(p, Polygons::from_triangles(&t))
}

fn fit(mesh: PolyMesh, chordal: bool) -> Fitted {
    let mut options = FitScanOptions {
        target_tolerances: true,
        chordal,
        ..FitScanOptions::default()
    };
    options.stages.max_control_points = mesh.positions.len();
    fit_scan(
        Input::Mesh {
            mesh,
            name: "part".into(),
        },
        &options,
        None,
    )
    .expect("the part fits")
}

/// The limit surface of a fit, tessellated finely (input coordinates).
fn limit(f: &Fitted) -> PolyMesh {
    let op = sampling_operator(
        &f.cage.faces,
        f.cage.num_vertices(),
        &f.tags,
        &f.subdivision(),
        4,
    )
    .expect("the cage subdivides");
    PolyMesh::new(op.position.apply(&f.cage.positions), op.faces)
}

#[test]
fn a_coarse_cylinder_export_fitted_chordally_is_closer_to_the_cylinder_than_the_export() {
    let stl = export(24);
    let vertices = stl.positions.len();
    let export_rms = rms_to_cylinder(&flat_pieces(&stl, 8));
    let fitted = fit(stl, true);
    let ours = rms_to_cylinder(&limit(&fitted));
    eprintln!(
        "export: RMS {export_rms:.3e}; chordal fit: RMS {ours:.3e}, {} control points",
        fitted.cage.num_vertices()
    );
    assert_eq!(fitted.report.options.chordal_levels, Some(4));
    assert!(fitted.cage.num_vertices() <= vertices);
    // Measured: 1.3e-2 against the export's 6.8e-2.
    assert!(
        ours < 0.5 * export_rms,
        "chordal fit RMS {ours:.3e}, the export's {export_rms:.3e}"
    );
}

#[test]
fn a_box_stays_exact_under_the_chordal_tolerance() {
    let mut b = gridded_box(3, false);
    for p in &mut b.positions {
        *p = [40.0 * p[0], 20.0 * p[1], 10.0 * p[2]];
    }
    let fitted = fit(b, true);
    let two = &fitted.report.r#final.two_sided;
    assert!(fitted.report.options.chordal_levels.is_some());
    assert!(fitted.report.tolerance_reached);
    assert!(
        two.e_max_fraction_of_diagonal < 1e-6,
        "box: Hausdorff {:.3e} of the diagonal",
        two.e_max_fraction_of_diagonal
    );
    assert!(
        fitted.cage.num_vertices() <= 8 + 12,
        "{} control points",
        fitted.cage.num_vertices()
    );
}
