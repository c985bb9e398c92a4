//! Feature-aligned cages of point clouds: a box sampled as points gives a cage whose
//! creases follow the box's edges and whose corners sit at the box's corners; the contour is
//! only moved, so genus and manifoldness are kept.
#![allow(clippy::print_stdout)]

use subfit_init::{initial_control_mesh, InitOptions};
use subfit_mesh::shapes::gridded_box;
use subfit_mesh::HalfEdgeMesh;
use subfit_target::{FeatureOptions, NormalSource, Target, TargetOptions};

/// `n` points uniform by area on the unit cube's surface, from `seed`.
fn cube_points(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let m = gridded_box(1, false);
    let tris = m.faces.triangulate_fan();
    // xorshift64*: seeded, no dependency.
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut random = move || {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            let k = ((random() * tris.len() as f64) as usize).min(tris.len() - 1);
            let [a, b, c] = tris[k].map(|v| m.positions[v as usize]);
            let (mut u, mut v) = (random(), random());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            [0, 1, 2].map(|k| a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]))
        })
        .collect()
}

/// Distance of `p` from the nearest edge of the unit cube.
fn off_edges(p: [f64; 3]) -> f64 {
    let mut d: Vec<f64> = p.iter().map(|&x| x.min(1.0 - x).abs()).collect();
    d.sort_by(f64::total_cmp);
    (d[0] * d[0] + d[1] * d[1]).sqrt()
}

#[test]
fn a_box_cloud_gives_a_cage_with_creases_along_its_edges() {
    let pts = cube_points(20_000, 11);
    let opts = TargetOptions {
        normals: NormalSource::Estimate,
        ..TargetOptions::default()
    };
    let t = Target::from_points(&pts, None, &opts).unwrap();
    let options = InitOptions {
        features: Some(FeatureOptions::default()),
        cloud_features: true,
        ..InitOptions::default()
    };
    let (cage, rep) = initial_control_mesh(&t, None, 200, &options).unwrap();
    let f = rep.features.expect("features were detected");
    assert_eq!((f.curves, f.corners), (12, 8), "{f:?}");
    let h = HalfEdgeMesh::from_mesh(&cage).unwrap();
    assert_eq!((h.genus(), h.boundary_loops().len()), (0, 0));
    let creases = rep.tags.creases();
    let corners = rep.tags.corners();
    assert!(creases.len() >= 12, "{} creases", creases.len());
    assert_eq!(corners.len(), 8, "{f:?}");
    // The contour's crease vertices were moved onto the traced curves, except where that
    // would fold a triangle (those go part of the way), and the simplification keeps the
    // crease vertices where they are: 90 % within 1 % of the side of the edges, all within 6 %
    // (measured 0.63 % and 4.1 %).
    let mut off: Vec<f64> = creases
        .iter()
        .flat_map(|((a, b), _)| [*a, *b])
        .map(|v| off_edges(t.to_original(cage.positions[v as usize])))
        .collect();
    off.sort_by(f64::total_cmp);
    let (p90, worst) = (off[off.len() * 9 / 10], off[off.len() - 1]);
    println!(
        "{} creases; crease vertices off the edges: 90 % {p90:.4}, max {worst:.4}",
        creases.len()
    );
    assert!(p90 < 0.01 && worst < 0.06, "90 % {p90}, max {worst}");
    let tol = 0.06;
    for (v, _) in &corners {
        let p = t.to_original(cage.positions[*v as usize]);
        let d = p.iter().map(|&x| x.min(1.0 - x).abs()).fold(0.0, f64::max);
        assert!(d < tol, "corner {p:?}");
    }
    // Without features: no tags, same topology.
    let (plain, prep) = initial_control_mesh(&t, None, 200, &InitOptions::default()).unwrap();
    assert!(prep.tags.is_empty() && prep.features.is_none());
    assert_eq!(HalfEdgeMesh::from_mesh(&plain).unwrap().genus(), 0);
}
