//! Feature-aligned simplification: the sharp edges of a CAD-like box stay cage
//! edges, tagged as creases, its corners stay where they are, tagged as corners, and the flat
//! sides keep only the vertices their shape needs (`exact_error`).

use std::collections::HashSet;

use subfit_init::{
    initial_control_mesh, simplify_with_features, FeatureLock, InitOptions, SimplifyOptions,
};
use subfit_mesh::shapes::gridded_box;
use subfit_mesh::{HalfEdgeMesh, PolyMesh, SHARPNESS_INFINITE};
use subfit_target::{detect_features, FeatureOptions, Target, TargetOptions};

/// Whether `p` is on an edge of the unit cube (two coordinates at 0 or 1).
fn on_cube_edge(p: [f64; 3]) -> bool {
    p.iter()
        .filter(|&&x| x.abs() < 1e-12 || (x - 1.0).abs() < 1e-12)
        .count()
        >= 2
}

fn is_cube_corner(p: [f64; 3]) -> bool {
    p.iter()
        .all(|&x| x.abs() < 1e-12 || (x - 1.0).abs() < 1e-12)
}

fn edges_of(m: &PolyMesh) -> HashSet<(u32, u32)> {
    let mut e = HashSet::new();
    for f in m.faces.iter() {
        for i in 0..f.len() {
            let (a, b) = (f[i], f[(i + 1) % f.len()]);
            e.insert((a.min(b), a.max(b)));
        }
    }
    e
}

#[test]
fn a_box_keeps_its_sharp_edges_as_creases_and_its_corners() {
    let m = gridded_box(12, false);
    let f = detect_features(&m.positions, &m.faces, &FeatureOptions::default());
    assert_eq!((f.curves.len(), f.corners.len()), (12, 8));
    let lock = FeatureLock {
        edges: f.edges.clone(),
        corners: f.corners.clone(),
    };
    let options = SimplifyOptions {
        target_vertices: 60,
        ..SimplifyOptions::default()
    };
    let (out, tags, rep) = simplify_with_features(&m, &lock, &options).unwrap();
    assert_eq!(out.num_vertices(), 60, "{rep:?}");
    let h = HalfEdgeMesh::from_mesh(&out).unwrap();
    assert_eq!((h.genus(), h.boundary_loops().len()), (0, 0));
    // Every crease is a cage edge along a cube edge; the 12 cube edges are covered: each
    // corner has exactly three creases, every other crease vertex two.
    let edges = edges_of(&out);
    let creases = tags.creases();
    let mut degree = vec![0; out.num_vertices()];
    for ((a, b), s) in &creases {
        assert_eq!(*s, SHARPNESS_INFINITE);
        assert!(
            edges.contains(&(*a, *b)),
            "crease {a}-{b} is not a cage edge"
        );
        let (pa, pb) = (out.positions[*a as usize], out.positions[*b as usize]);
        assert!(on_cube_edge(pa) && on_cube_edge(pb), "{pa:?} {pb:?}");
        let mid: [f64; 3] = std::array::from_fn(|k| 0.5 * (pa[k] + pb[k]));
        assert!(on_cube_edge(mid), "crease {pa:?}-{pb:?} cuts across a side");
        degree[*a as usize] += 1;
        degree[*b as usize] += 1;
    }
    let corners = tags.corners();
    assert_eq!(corners.len(), 8);
    for (v, s) in &corners {
        assert_eq!(*s, SHARPNESS_INFINITE);
        assert!(is_cube_corner(out.positions[*v as usize]));
        assert_eq!(degree[*v as usize], 3);
    }
    for (v, &d) in degree.iter().enumerate() {
        if d > 0 && !is_cube_corner(out.positions[v]) {
            assert_eq!(d, 2, "crease vertex {v} at {:?}", out.positions[v]);
        }
    }
    // Without the features the same budget rounds the box off its edges.
    let (_, plain_tags, _) = simplify_with_features(&m, &FeatureLock::default(), &options).unwrap();
    assert!(plain_tags.is_empty());
}

#[test]
fn flat_sides_lose_the_vertices_they_do_not_need() {
    let m = gridded_box(16, true);
    let target = Target::from_mesh(&m, &TargetOptions::default()).unwrap();
    let options = InitOptions {
        features: Some(FeatureOptions::default()),
        simplify: SimplifyOptions {
            exact_error: 1e-6,
            ..SimplifyOptions::default()
        },
        ..InitOptions::default()
    };
    let (cage, report) = initial_control_mesh(&target, Some(&m), 200, &options).unwrap();
    // The open box's shape is its 8 corners (4 on the floor, 4 on the rim).
    assert_eq!(cage.num_vertices(), 8, "{:?}", report.simplify);
    assert_eq!(report.boundary_loops, (1, 1));
    let counts = report.features.unwrap();
    assert_eq!((counts.curves, counts.corners, counts.darts), (8, 4, 4));
    assert_eq!(report.tags.corners().len(), 4);
    assert_eq!(report.tags.creases().len(), 8);
    // Without exact_error the count asked for is the count given.
    let exact_off = InitOptions {
        simplify: SimplifyOptions::default(),
        ..options
    };
    let (cage, _) = initial_control_mesh(&target, Some(&m), 200, &exact_off).unwrap();
    assert_eq!(cage.num_vertices(), 200);
}
