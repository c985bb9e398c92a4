//! Open CAD-like patches through the whole pipeline with defaults (issue 14): the rim of the
//! limit surface reaches the data's edge (the data → surface part of the objective) and its
//! corners (corner tags at the boundary's sharp turns), genus and boundary loops are kept, and
//! the two-sided tolerance holds.

use subfit::mesh::{HalfEdgeMesh, PolyMesh, Polygons};
use subfit::report::MeshDistance;
use subfit::subdiv::{sampling_operator, Options};
use subfit::{fit_scan, FitScanOptions, Input};

/// `z = f(x, y)` over `[-1, 1]²` as an `n × n`-cell triangle grid.
fn height_field(n: usize, f: impl Fn(f64, f64) -> f64) -> PolyMesh {
    let mut p = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (
                -1.0 + 2.0 * i as f64 / n as f64,
                -1.0 + 2.0 * j as f64 / n as f64,
            );
            p.push([x, y, f(x, y)]);
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut tris = Vec::new();
    for j in 0..n {
        for i in 0..n {
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    PolyMesh::new(p, Polygons::from_triangles(&tris))
}

/// The half-cylinder `y² + z² = 1, z ≥ 0` over `x ∈ [-1.5, 1.5]` as a grid.
fn half_cylinder(nu: usize, nv: usize) -> PolyMesh {
    let mut m = height_field(nu.max(nv), |_, _| 0.0);
    let n = nu.max(nv);
    for (k, p) in m.positions.iter_mut().enumerate() {
        let (i, j) = (k % (n + 1), k / (n + 1));
        let t = std::f64::consts::PI * j as f64 / n as f64;
        *p = [-1.5 + 3.0 * i as f64 / n as f64, t.cos(), t.sin()];
    }
    m
}

/// Largest distance (fraction of the diagonal) of the data's boundary vertices to the fitted
/// limit surface (level 4 tessellation), and the fit's report figures.
fn check(name: &str, data: PolyMesh) {
    let fitted = fit_scan(
        Input::Mesh {
            mesh: data.clone(),
            name: name.into(),
        },
        &FitScanOptions::default(),
        None,
    )
    .unwrap();
    let r = &fitted.report;
    let two = &r.r#final.two_sided;
    let cage = fitted.normalized_cage();
    let target = fitted.target();
    let op = sampling_operator(
        &cage.faces,
        cage.num_vertices(),
        &fitted.tags,
        &Options::new(fitted.scheme),
        4,
    )
    .unwrap();
    let samples = op.position.apply(&cage.positions);
    let h = HalfEdgeMesh::new(&data.faces, data.num_vertices()).unwrap();
    let rim: Vec<[f64; 3]> = h
        .boundary_loops()
        .into_iter()
        .flatten()
        .map(|v| target.to_normalized(data.positions[v.0 as usize]))
        .collect();
    let gap = MeshDistance::new(&samples, &op.faces)
        .distances(&rim)
        .iter()
        .fold(0.0f64, |m, d| m.max(d.distance))
        / r.bbox_diagonal_unit_cube;
    eprintln!(
        "{name}: {} control points, {} corner tags, two-sided RMS {:.2e} / Hausdorff {:.2e} of the diagonal, rim gap {gap:.2e}",
        r.control_points,
        r.tags.corners,
        two.e_rms_fraction_of_diagonal,
        two.e_max_fraction_of_diagonal
    );
    assert_eq!(r.init.boundary_loops.cage, 1, "{name}");
    assert_eq!(r.init.genus, 0, "{name}");
    assert!(
        r.tolerance_reached,
        "{name}: tolerance not reached both ways"
    );
    assert!(two.e_max_fraction_of_diagonal < 0.01, "{name}");
    assert!(
        gap < 0.005,
        "{name}: the rim misses the data's edge by {gap:.2e}"
    );
    assert_eq!(r.tags.corners, 4, "{name}: corner tags");
}

#[test]
fn a_square_saddle_patch_keeps_its_rim_and_corners() {
    check("saddle", height_field(48, |x, y| 0.3 * (x * x - y * y)));
}

#[test]
fn a_half_cylinder_keeps_its_rim_and_corners() {
    check("half-cylinder", half_cylinder(48, 48));
}
