//! The embedded-deformation tracking step (`subfit_fit::track`): a rigid motion of a body that
//! is not symmetric is recovered, points and all — including its component along the surface,
//! which closest points alone do not see.
#![allow(clippy::print_stderr)]

use subfit_fit::track::{track, DeformationGraph, Samples, TrackOptions};
use subfit_mesh::deforming::{DeformingParams, DeformingSequence};
use subfit_mesh::vec3::{cross, dist2, norm, sub};
use subfit_target::{Normalization, Target, TargetOptions};

fn vertex_normals(p: &[[f64; 3]], tris: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let mut n = vec![[0.0; 3]; p.len()];
    for t in tris {
        let [a, b, c] = t.map(|i| p[i as usize]);
        let f = cross(sub(b, a), sub(c, a));
        for &i in t {
            for k in 0..3 {
                n[i as usize][k] += f[k];
            }
        }
    }
    n.iter()
        .map(|v| {
            let l = norm(*v);
            v.map(|x| x / l)
        })
        .collect()
}

/// RMS of the distances between corresponding points.
fn rms_distance(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    (a.iter().zip(b).map(|(p, q)| dist2(*p, *q)).sum::<f64>() / a.len() as f64).sqrt()
}

fn turn_z(p: [f64; 3], angle: f64, shift: [f64; 3]) -> [f64; 3] {
    let (s, c) = angle.sin_cos();
    [
        c * p[0] - s * p[1] + shift[0],
        s * p[0] + c * p[1] + shift[1],
        p[2] + shift[2],
    ]
}

#[test]
fn a_turn_along_the_surface_is_followed() {
    let seq = DeformingSequence::new(DeformingParams::default()).expect("default motion");
    let rest = seq.frame(0, 3000, 7).mesh;
    let tris = rest.faces.triangulate_fan();
    // The frame moved: turned about the body's long axis (mostly along its surface) and shifted.
    let (angle, shift) = (0.15, [0.02, -0.03, 0.05]);
    let moved: Vec<[f64; 3]> = rest
        .positions
        .iter()
        .map(|&p| turn_z(p, angle, shift))
        .collect();
    let frame = subfit_mesh::PolyMesh::new(moved.clone(), rest.faces.clone());
    let (lo, hi) = frame.bounding_box().expect("points");
    let norm_ = Normalization::from_bounds(lo, hi).expect("extent");
    let target = Target::from_mesh(
        &frame,
        &TargetOptions {
            normalization: Some(norm_),
            ..TargetOptions::default()
        },
    )
    .expect("target");
    let to =
        |p: &[[f64; 3]]| -> Vec<[f64; 3]> { p.iter().map(|&x| norm_.to_normalized(x)).collect() };
    let samples = to(&rest.positions);
    let normals = vertex_normals(&samples, &tris);
    let expected = to(&moved);
    let graph = DeformationGraph::new(&samples, 30, 8);
    let (out, _, stats) = track(
        &graph,
        &samples,
        Samples {
            positions: &samples,
            normals: &normals,
        },
        &target,
        &[],
        None,
        &TrackOptions::default(),
    );
    let (before, after) = (
        rms_distance(&samples, &expected),
        rms_distance(&out, &expected),
    );
    eprintln!("{stats:?}; distance to the true motion: RMS {before:.4} -> {after:.6}");
    assert!(after < 0.02 * before, "RMS {before} -> {after}");
}

/// Samples of a sphere of radius 0.4 centred at `c` and an elongated capsule-like body: the
/// shrinking balls of a sphere end at its centre, and interior nodes at depth ½ lie halfway
/// in.
#[test]
fn medial_points_and_interior_nodes_lie_inside() {
    let sphere = subfit_mesh::shapes::geodesic_sphere(4);
    let (c, r) = ([0.3, -0.2, 0.5], 0.4);
    let samples: Vec<[f64; 3]> = sphere
        .positions
        .iter()
        .map(|p| std::array::from_fn(|a| c[a] + r * p[a]))
        .collect();
    let normals = sphere.positions.clone();
    let medial = subfit_fit::track::medial_points(&samples, &normals);
    let worst = medial
        .iter()
        .map(|&m| dist2(m, c).sqrt())
        .fold(0.0, f64::max);
    assert!(worst < 0.02 * r, "medial point {worst} from the centre");
    let graph = DeformationGraph::interior(&samples, &normals, 0.5, 30, 8);
    assert_eq!(graph.len(), 30);
    for &g in graph.positions() {
        let d = dist2(g, c).sqrt();
        assert!(
            (d - 0.5 * r).abs() < 0.02 * r,
            "node at {d} from the centre"
        );
    }
    // An open side: a flat square's balls touch nothing below it; its samples stay put.
    let flat: Vec<[f64; 3]> = (0..400)
        .map(|i| [f64::from(i % 20) / 19.0, f64::from(i / 20) / 19.0, 0.0])
        .collect();
    let up = vec![[0.0, 0.0, 1.0]; flat.len()];
    let m = subfit_fit::track::medial_points(&flat, &up);
    assert_eq!(m, flat);
}
