//! Local enrichment (Lavoué et al. 2005 §5.2): a narrow bump on a sphere, fitted from a coarse
//! cage, is a local error field once the RMS is met, and gets one control point instead of
//! the splits of every face around it; the fit reaches its tolerances either way.

#![allow(clippy::print_stdout)]

use std::collections::HashMap;

use subfit::mesh::{PolyMesh, Polygons};
use subfit::{fit_scan, FitScanOptions, Input};

/// A sphere of radius 0.5 (icosahedron, `levels` geodesic subdivisions) with a Gaussian bump of
/// height 6 % and angular width 0.08 rad.
fn bumpy_sphere(levels: usize) -> PolyMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let unit = |p: [f64; 3]| {
        let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        [p[0] / l, p[1] / l, p[2] / l]
    };
    let mut v: Vec<[f64; 3]> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .into_iter()
    .map(unit)
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid = HashMap::new();
        let mut next = Vec::with_capacity(4 * f.len());
        let mut m = |a: u32, b: u32, v: &mut Vec<[f64; 3]>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (p, q) = (v[a as usize], v[b as usize]);
                v.push(unit([p[0] + q[0], p[1] + q[1], p[2] + q[2]]));
                v.len() as u32 - 1
            })
        };
        for [a, b, c] in f {
            let (ab, bc, ca) = (m(a, b, &mut v), m(b, c, &mut v), m(c, a, &mut v));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = next;
    }
    let d = unit([0.3, 0.5, 0.8]);
    let positions = v
        .into_iter()
        .map(|p| {
            let angle = (p[0] * d[0] + p[1] * d[1] + p[2] * d[2])
                .clamp(-1.0, 1.0)
                .acos();
            let r = 0.5 * (1.0 + 0.06 * (-(angle / 0.08).powi(2)).exp());
            [r * p[0], r * p[1], r * p[2]]
        })
        .collect();
    PolyMesh::new(positions, Polygons::from_triangles(&f))
}

#[test]
fn a_bump_gets_one_control_point() {
    let data = bumpy_sphere(5);
    let fit = |share: f64| {
        let mut options = FitScanOptions {
            control_points: Some(40),
            target_tolerances: true,
            ..FitScanOptions::default()
        };
        options.stages.local_field_share = share;
        let f = fit_scan(
            Input::Mesh {
                mesh: data.clone(),
                name: "bump".into(),
            },
            &options,
            None,
        )
        .unwrap();
        let local: usize = f.report.stages.iter().map(|s| s.local_points).sum();
        println!(
            "share {share}: {} control points, {local} added locally, reached {}",
            f.report.control_points, f.report.tolerance_reached
        );
        (f.report.control_points, local, f.report.tolerance_reached)
    };
    let (with, local, reached) = fit(subfit::fit::LOCAL_FIELD_SHARE);
    let (without, none, reached_without) = fit(0.0);
    assert!(reached && reached_without);
    assert!(local >= 1, "no field was enriched locally");
    assert_eq!(none, 0);
    // Counts from a coarse start swing with the path (the same bump as an OBJ through the CLI:
    // 66 with, 93 without); the point is not to cost more.
    assert!(
        with as f64 <= 1.1 * without as f64,
        "{with} control points with local enrichment, {without} without"
    );
}
