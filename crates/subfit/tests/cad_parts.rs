//! Generated CAD parts (`subfit_mesh::parts`), tessellated as an exporter does, fitted with the
//! defaults: the CAD tessellation start (`subfit::start_cad`) must give a cage with no more
//! control points than the tessellation has vertices, crease tags, and a limit surface within
//! the CAD tolerances of the facets; a part made only of planes is reproduced exactly.
//!
//! The judge here is independent of the fit's own measurer: the limit surface is sampled by
//! subdividing the fitted cage with its tags (`subfit_subdiv`) and each sample's distance to the
//! facets is taken by brute force over the triangles, and each facet vertex's distance to the
//! limit mesh likewise.

use subfit::mesh::parts::Part;
use subfit::mesh::PolyMesh;
use subfit::{fit_scan, FitScanOptions, Fitted, Input};

/// Fits `mesh` with the defaults a user gets (`subfit fit FILE`).
fn fit(mesh: &PolyMesh, name: &str) -> Fitted {
    let mut options = FitScanOptions::default();
    options.set_limits(None, None, None);
    fit_scan(
        Input::Mesh {
            mesh: mesh.clone(),
            name: name.into(),
        },
        &options,
        None,
    )
    .unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Distance from `p` to the triangle `abc` (Ericson, Real-Time Collision Detection §5.1.5).
fn point_triangle(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    let lerp =
        |u: [f64; 3], v: f64, w: [f64; 3]| [u[0] + v * w[0], u[1] + v * w[1], u[2] + v * w[2]];
    let q = if d1 <= 0.0 && d2 <= 0.0 {
        a
    } else {
        let bp = sub(p, b);
        let (d3, d4) = (dot(ab, bp), dot(ac, bp));
        let cp = sub(p, c);
        let (d5, d6) = (dot(ab, cp), dot(ac, cp));
        let vc = d1 * d4 - d3 * d2;
        let vb = d5 * d2 - d1 * d6;
        let va = d3 * d6 - d5 * d4;
        if d3 >= 0.0 && d4 <= d3 {
            b
        } else if d6 >= 0.0 && d5 <= d6 {
            c
        } else if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            lerp(a, d1 / (d1 - d3), ab)
        } else if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            lerp(a, d2 / (d2 - d6), ac)
        } else if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
            lerp(b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), sub(c, b))
        } else {
            let denom = 1.0 / (va + vb + vc);
            let (v, w) = (vb * denom, vc * denom);
            let x = lerp(a, v, ab);
            lerp(x, w, ac)
        }
    };
    dot(sub(p, q), sub(p, q)).sqrt()
}

fn mesh_distance(p: [f64; 3], m: &PolyMesh) -> f64 {
    m.faces
        .triangulate_fan()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| m.positions[v as usize]);
            point_triangle(p, a, b, c)
        })
        .fold(f64::INFINITY, f64::min)
}

/// The fitted cage's limit surface at refinement `level`, with its tags (input units).
fn limit_mesh(f: &Fitted, level: usize) -> PolyMesh {
    let op = subfit::subdiv::sampling_operator(
        &f.cage.faces,
        f.cage.num_vertices(),
        &f.tags,
        &f.subdivision(),
        level,
    )
    .unwrap_or_else(|e| panic!("limit: {e}"));
    PolyMesh::new(op.position.apply(&f.cage.positions), op.faces)
}

/// Two-sided Hausdorff distance between the limit mesh and the facets, fraction of the
/// diagonal (brute force, both ways over vertices).
fn hausdorff(limit: &PolyMesh, facets: &PolyMesh, diagonal: f64) -> f64 {
    let a = limit
        .positions
        .iter()
        .map(|&p| mesh_distance(p, facets))
        .fold(0.0, f64::max);
    // The facets' vertices (those their faces use) to the limit.
    let b = facets
        .faces
        .iter()
        .flatten()
        .map(|&v| mesh_distance(facets.positions[v as usize], limit))
        .fold(0.0, f64::max);
    a.max(b) / diagonal
}

fn diagonal(m: &PolyMesh) -> f64 {
    let (lo, hi) = subfit::mesh::bounding_box(&m.positions).expect("non-empty");
    dot(sub(hi, lo), sub(hi, lo)).sqrt()
}

/// Parts made only of planes: the cage reproduces the facets exactly (within 1e-6 of the
/// diagonal), with crease tags and at most the tessellation's vertices.
#[test]
fn planar_parts_are_exact() {
    let parts = [
        ("block", Part::block(3.0, 2.0, 1.0)),
        ("l-bracket", Part::l_bracket(1.0, 0.5)),
        (
            "prism",
            Part::prism(
                vec![[0.0, 0.0], [2.0, 0.0], [2.5, 1.0], [1.0, 2.0], [-0.5, 1.0]],
                0.7,
            ),
        ),
    ];
    for (name, part) in parts {
        for max_edge in [None, Some(0.4)] {
            let mesh = part.tessellate(1e-3, max_edge);
            if mesh.num_vertices() < subfit::target::MIN_POINTS {
                // The coarse block's 8 vertices: the target needs MIN_POINTS.
                continue;
            }
            let f = fit(&mesh, name);
            let d = diagonal(&mesh);
            let h = hausdorff(&limit_mesh(&f, 3), &mesh, d);
            assert!(
                f.cage.num_vertices() <= mesh.num_vertices(),
                "{name} {max_edge:?}: {} control points for {} vertices",
                f.cage.num_vertices(),
                mesh.num_vertices()
            );
            assert!(!f.tags.creases().is_empty(), "{name}: no crease tags");
            assert!(
                h <= 1e-6,
                "{name} {max_edge:?}: Hausdorff {h:.2e} of the diagonal"
            );
        }
    }
}

/// An open box (a block without its top), coarse: at most 40 control points, Hausdorff
/// ≤ 1e-3 of the diagonal.
#[test]
fn coarse_open_box() {
    let mesh = Part::block(1.0, 1.0, 1.0).tessellate(1e-3, Some(0.5));
    // The top's triangles dropped; its rim's vertices stay (the walls use them all).
    let mut faces = subfit::mesh::Polygons::new();
    for f in mesh.faces.iter() {
        if !f
            .iter()
            .all(|&v| mesh.positions[v as usize][2] > 1.0 - 1e-9)
        {
            faces.push(f);
        }
    }
    let open = PolyMesh::new(mesh.positions.clone(), faces);
    let f = fit(&open, "open box");
    let h = hausdorff(&limit_mesh(&f, 3), &open, diagonal(&open));
    assert!(
        f.cage.num_vertices() <= 40,
        "{} control points",
        f.cage.num_vertices()
    );
    assert!(
        h <= 1e-3,
        "Hausdorff {h:.2e} of the diagonal, {} control points from {}",
        f.cage.num_vertices(),
        f.report.init.source
    );
}

/// Curved parts (cylinder, tube, filleted block, drilled plate), coarse and fine: at most the
/// tessellation's vertices, crease tags, within the CAD Hausdorff tolerance (0.2 %) of the
/// facets.
#[test]
fn curved_parts_within_cad_tolerance() {
    let parts = [
        ("cylinder", Part::cylinder(1.0, 1.5)),
        ("tube", Part::tube(1.0, 0.6, 0.8)),
        ("filleted block", Part::filleted_block(3.0, 2.0, 1.0, 0.3)),
        ("drilled plate", Part::drilled_plate([2, 1], 1.0, 0.25, 0.2)),
    ];
    for (name, part) in parts {
        for chord in [5e-3, 5e-4] {
            let chord = chord * part.diagonal();
            let mesh = part.tessellate(chord, None);
            let f = fit(&mesh, name);
            let h = hausdorff(&limit_mesh(&f, 2), &mesh, diagonal(&mesh));
            assert!(
                f.cage.num_vertices() <= mesh.num_vertices(),
                "{name} chord {chord:.1e}: {} control points for {} vertices",
                f.cage.num_vertices(),
                mesh.num_vertices()
            );
            assert!(!f.tags.creases().is_empty(), "{name}: no crease tags");
            assert!(h <= 2.5e-3, "{name} chord {chord:.1e}: Hausdorff {h:.2e}");
        }
    }
}
