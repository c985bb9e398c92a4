//! The deforming test sequence: every frame a closed, consistently oriented genus-0 manifold
//! of its own resolution without slivers; `Φ_0` the identity; the material lookup exact on
//! frame vertices; drift zero for points that follow their material and growing for points
//! that stay put; everything reproducible from the seed.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use subfit_mesh::deforming::{
    DeformingParams, DeformingSequence, Frame, InvalidParams, MaterialLookup,
};
use subfit_mesh::vec3::{cross, dist2, dot, norm, sub};
use subfit_mesh::{diagnose_mesh, HalfEdgeMesh};

/// Smallest interior angle of the frame's triangles, degrees.
fn min_angle(frame: &Frame) -> f64 {
    let p = &frame.mesh.positions;
    let mut least = 180.0f64;
    for t in frame.mesh.faces.iter() {
        for k in 0..3 {
            let a = sub(p[t[(k + 1) % 3] as usize], p[t[k] as usize]);
            let b = sub(p[t[(k + 2) % 3] as usize], p[t[k] as usize]);
            let c = (dot(a, b) / (norm(a) * norm(b))).clamp(-1.0, 1.0);
            least = least.min(c.acos().to_degrees());
        }
    }
    least
}

/// Volume enclosed by the frame's triangles (positive when they are wound outward).
fn signed_volume(frame: &Frame) -> f64 {
    let p = &frame.mesh.positions;
    frame
        .mesh
        .faces
        .iter()
        .map(|t| dot(p[t[0] as usize], cross(p[t[1] as usize], p[t[2] as usize])) / 6.0)
        .sum()
}

/// A point at random barycentric coordinates in a random triangle of `frame`, in both the
/// frame and material spaces.
fn random_surface_points(frame: &Frame, count: usize, seed: u64) -> Vec<([f64; 3], [f64; 3])> {
    let mut rng = StdRng::seed_from_u64(seed);
    let faces = &frame.mesh.faces;
    (0..count)
        .map(|_| {
            let t = faces.iter().nth(rng.random_range(0..faces.len())).unwrap();
            let (mut u, mut v): (f64, f64) = (rng.random(), rng.random());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let w = [1.0 - u - v, u, v];
            let mix = |x: &[[f64; 3]]| -> [f64; 3] {
                std::array::from_fn(|k| (0..3).map(|c| w[c] * x[t[c] as usize][k]).sum())
            };
            (mix(&frame.mesh.positions), mix(&frame.material))
        })
        .collect()
}

#[test]
fn frames_are_closed_manifolds_of_varying_resolution_without_slivers() {
    for params in [
        DeformingParams::default(),
        DeformingParams::large_tangential_motion(),
    ] {
        let seq = DeformingSequence::new(params).unwrap();
        let approx = 3000;
        let mut counts = Vec::new();
        for t in 0..seq.len() {
            let frame = seq.frame(t, approx, 11);
            let nv = frame.mesh.num_vertices();
            assert!(
                (0.7 * approx as f64..=1.3 * approx as f64).contains(&(nv as f64)),
                "frame {t}: {nv} vertices"
            );
            assert_eq!(frame.material.len(), nv);
            assert!(frame.mesh.faces.is_triangles());
            let r = diagnose_mesh(&frame.mesh);
            assert!(
                r.is_closed && r.is_manifold && r.is_consistently_oriented,
                "{r:?}"
            );
            assert_eq!(r.genus, Some(0));
            assert_eq!(r.num_components, 1);
            assert_eq!(r.unreferenced_vertices, 0);
            assert_eq!(r.zero_area_faces, Some(0));
            assert_eq!(r.duplicate_faces + r.degenerate_faces, 0);
            let he = HalfEdgeMesh::from_mesh(&frame.mesh).unwrap();
            assert_eq!(he.num_boundary_edges(), 0);
            assert!(signed_volume(&frame) > 0.0, "frame {t} is wound inward");
            // The tessellation itself (frame 0 is the rest shape) has no sliver; the
            // deformation shears triangles only moderately.
            let least = min_angle(&frame);
            assert!(
                least > if t == 0 { 25.0 } else { 10.0 },
                "frame {t}: {least}°"
            );
            counts.push(nv);
        }
        counts.sort_unstable();
        counts.dedup();
        assert!(counts.len() >= 4, "vertex counts {counts:?}");
    }
    // Coarse and fine requests are honoured too.
    let seq = DeformingSequence::default();
    for approx in [200, 25_000] {
        for t in [0, 7] {
            let nv = seq.frame(t, approx, 3).mesh.num_vertices() as f64;
            assert!(
                (0.7..=1.3).contains(&(nv / approx as f64)),
                "{approx}: {nv}"
            );
        }
    }
}

#[test]
fn frames_are_deterministic_and_differ_between_indices_and_seeds() {
    let seq = DeformingSequence::default();
    assert_eq!(seq.frame(5, 2000, 42), seq.frame(5, 2000, 42));
    assert_ne!(seq.frame(5, 2000, 42), seq.frame(5, 2000, 43));
    // Same index, different seeds: different tessellations.
    let (a, b) = (seq.frame(4, 2000, 1), seq.frame(4, 2000, 2));
    assert_ne!(a.material, b.material);
    // Different indices never share vertex positions on the rest shape.
    let (c, d) = (seq.frame(0, 2000, 1), seq.frame(1, 2000, 1));
    assert!(c.material.iter().all(|m| !d.material.contains(m)));
}

#[test]
fn phi_0_is_the_identity_and_frames_are_deformed_material() {
    for params in [
        DeformingParams::default(),
        DeformingParams::large_tangential_motion(),
    ] {
        let seq = DeformingSequence::new(params).unwrap();
        let rest = seq.frame(0, 2000, 5);
        assert_eq!(rest.mesh.positions, rest.material);
        for &m in &rest.material {
            assert_eq!(seq.deform(0, m), m);
        }
        let later = seq.frame(9, 2000, 5);
        assert_eq!(later.mesh.positions, seq.deform_all(9, &later.material));
        // Frame 9 really moved.
        let moved = later
            .material
            .iter()
            .map(|&m| dist2(seq.deform(9, m), m).sqrt())
            .fold(0.0, f64::max);
        assert!(moved > 0.2, "{moved}");
    }
}

#[test]
fn the_motion_is_smooth_in_time_and_the_body_keeps_its_size() {
    let seq = DeformingSequence::default();
    let rest = seq.frame(0, 4000, 8);
    let mut prev = rest.material.clone();
    for t in 1..seq.len() {
        let now = seq.deform_all(t, &rest.material);
        let step = prev
            .iter()
            .zip(&now)
            .map(|(a, b)| dist2(*a, *b).sqrt())
            .fold(0.0, f64::max);
        // Moderate: about 4% of the body's diagonal (2.3) per frame at most.
        assert!(step > 1e-3 && step < 0.12, "frame {t}: step {step}");
        let (lo, hi) = subfit_mesh::bounding_box(&now).unwrap();
        let diag = norm(sub(hi, lo));
        assert!((2.0..2.6).contains(&diag), "frame {t}: diagonal {diag}");
        prev = now;
    }
}

#[test]
fn the_rest_shape_has_no_rotational_or_mirror_symmetry() {
    let seq = DeformingSequence::default();
    let rest = seq.frame(0, 6000, 2);
    let lookup = MaterialLookup::new(&rest);
    let coarse = seq.frame(0, 1500, 3);
    let off_surface = |map: &dyn Fn([f64; 3]) -> [f64; 3]| {
        coarse
            .material
            .iter()
            .map(|&m| lookup.locate(map(m)).1)
            .fold(0.0, f64::max)
    };
    // The shape itself is found again (to the chord error of the two tessellations).
    assert!(off_surface(&|m| m) < 5e-3);
    // Off the surface by 0.17 × the angle for small turns, by 0.058 at least beyond (a half
    // turn, which maps the ellipse onto itself but not the bumps).
    for step in 1..72 {
        let angle = step as f64 * 5f64.to_radians();
        let (s, c) = angle.sin_cos();
        let spun = off_surface(&|m| [c * m[0] - s * m[1], s * m[0] + c * m[1], m[2]]);
        let turn = angle.min(std::f64::consts::TAU - angle);
        assert!(
            spun > (0.1 * turn).min(0.04),
            "turned by {}°: {spun}",
            5 * step
        );
    }
    for mirror in [[-1.0, 1.0, 1.0], [1.0, -1.0, 1.0], [1.0, 1.0, -1.0]] {
        let flipped = off_surface(&|m| std::array::from_fn(|k| mirror[k] * m[k]));
        assert!(flipped > 0.04, "mirror {mirror:?}: {flipped}");
    }
}

#[test]
fn material_lookup_recovers_material_coordinates() {
    let seq = DeformingSequence::new(DeformingParams::large_tangential_motion()).unwrap();
    for t in [0, 6] {
        let frame = seq.frame(t, 3000, 21);
        let lookup = MaterialLookup::new(&frame);
        assert_eq!(lookup.vertex_material(), &frame.material[..]);
        for (&p, &m) in frame.mesh.positions.iter().zip(&frame.material) {
            let (found, distance) = lookup.locate(p);
            assert!(distance < 1e-12);
            assert!(dist2(found, m).sqrt() < 1e-9, "{found:?} vs {m:?}");
        }
        for (p, m) in random_surface_points(&frame, 500, 4) {
            assert!(dist2(lookup.material(p), m).sqrt() < 1e-9);
        }
    }
}

#[test]
fn drift_is_zero_along_the_material_and_grows_for_frozen_points() {
    let seq = DeformingSequence::new(DeformingParams::large_tangential_motion()).unwrap();
    let first = seq.frame(0, 3000, 13);
    let lookup = MaterialLookup::new(&first);
    let points = random_surface_points(&first, 400, 9);
    let material: Vec<[f64; 3]> = points.iter().map(|&(_, m)| m).collect();
    let exact: Vec<Vec<[f64; 3]>> = (0..seq.len())
        .map(|t| seq.deform_all(t, &material))
        .collect();
    let stats = seq.drift(&exact, &lookup);
    assert_eq!(stats.frames.len(), seq.len());
    assert!(stats.max_relative() < 1e-12, "{}", stats.max_relative());

    let frozen = vec![exact[0].clone(); seq.len()];
    let stats = seq.drift(&frozen, &lookup);
    let max: Vec<f64> = stats.frames.iter().map(|f| f.max).collect();
    assert!(max[0] < 1e-12);
    for t in 1..6 {
        assert!(max[t] > max[t - 1], "drift {max:?}");
    }
    for f in &stats.frames {
        assert!(f.rms <= f.max && f.diagonal > 2.0);
        assert!((f.max_relative - f.max / f.diagonal).abs() < 1e-15);
        assert!((f.rms_relative - f.rms / f.diagonal).abs() < 1e-15);
    }
    assert!(stats.max_relative() > 0.1);

    // Points that follow the surface but lag one frame behind the material drift by about a
    // frame's motion.
    let lagging: Vec<Vec<[f64; 3]>> = (0..seq.len())
        .map(|t| exact[t.saturating_sub(1)].clone())
        .collect();
    let lag = seq.drift(&lagging, &lookup);
    assert!(lag.frames[0].max < 1e-12 && lag.frames[1].max > 0.05);
    assert!(seq.drift(&[], &lookup).frames.is_empty());
}

#[test]
fn invalid_parameters_are_named() {
    let check = |p: DeformingParams, field: &str| {
        let err: InvalidParams = DeformingSequence::new(p).unwrap_err();
        assert_eq!(err.field, field);
        assert!(err.to_string().contains(field));
    };
    let d = DeformingParams::default;
    check(DeformingParams { frames: 0, ..d() }, "frames");
    check(
        DeformingParams {
            thickness: 1.0,
            ..d()
        },
        "thickness",
    );
    check(DeformingParams { bend: 2.0, ..d() }, "bend");
    check(
        DeformingParams {
            twist: f64::NAN,
            ..d()
        },
        "twist",
    );
    check(
        DeformingParams {
            thickness_wavelength: 0.0,
            ..d()
        },
        "thickness_wavelength",
    );
    assert!(DeformingSequence::new(DeformingParams { frames: 1, ..d() }).is_ok());
}
