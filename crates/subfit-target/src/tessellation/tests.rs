use super::*;
use subfit_mesh::parts::Part;
use subfit_mesh::shapes::{geodesic_sphere, XorShift};
use subfit_mesh::PolyMesh;

fn facets(m: &PolyMesh) -> Facets {
    Facets::new(&m.positions, &m.faces.triangulate_fan(), 1e-9)
}

fn classes(m: &PolyMesh, budget: &SmoothBudget) -> (Facets, FacetFeatures) {
    let f = facets(m);
    let c = classify_edges(&m.positions, &f, budget);
    (f, c)
}

#[test]
fn cad_parts_are_tessellations_and_smooth_or_noisy_meshes_are_not() {
    for part in [
        Part::block(2.0, 1.0, 0.5),
        Part::cylinder(0.5, 2.0),
        Part::drilled_plate([2, 2], 1.0, 0.3, 0.2),
        Part::filleted_block(2.0, 1.0, 1.0, 0.2),
    ] {
        for (chord, edge) in [(1e-2, None), (1e-4, Some(0.1))] {
            let m = part.tessellate(chord, edge);
            let s = facets(&m).stats(&m.positions);
            assert!(s.is_tessellation, "{part:?} {chord}: {s:?}");
        }
    }
    let sphere = geodesic_sphere(3);
    let s = facets(&sphere).stats(&sphere.positions);
    assert!(!s.is_tessellation && s.flat_edge_share < 0.01, "{s:?}");
    // A finely gridded block with its vertices moved by 1e-4 of its size: a scanned box.
    let mut m = Part::block(1.0, 1.0, 1.0).tessellate(1e-3, Some(0.05));
    let mut rng = XorShift::new(7);
    for p in &mut m.positions {
        for c in p.iter_mut() {
            *c += 1e-4 * (rng.uniform() - 0.5);
        }
    }
    let s = facets(&m).stats(&m.positions);
    assert!(!s.is_tessellation, "{s:?}");
}

#[test]
fn a_block_has_six_planes_and_twelve_crease_lines_at_any_budget() {
    for edge in [None, Some(0.1)] {
        let m = Part::block(2.0, 1.0, 0.5).tessellate(1e-2, edge);
        let (f, c) = classes(
            &m,
            &SmoothBudget {
                max_sag: 1.0,
                max_rms: 1.0,
            },
        );
        assert_eq!(f.regions.len(), 6, "{edge:?}");
        assert_eq!(c.count(EdgeClass::Smooth), 0);
        for (e, class) in f.edges.iter().zip(&c.class) {
            let right = (e.angle - std::f64::consts::FRAC_PI_2).abs() < 1e-9;
            assert_eq!(*class == EdgeClass::Crease, right && e.convex, "{e:?}");
        }
        assert_eq!(c.chord_height, 0.0);
    }
}

#[test]
fn a_cylinders_side_is_smooth_within_its_chord_height_and_its_rims_are_creases() {
    let chord = 1e-3;
    let m = Part::cylinder(0.5, 1.0).tessellate(chord, None);
    let f = facets(&m);
    let c = classify_edges(&m.positions, &f, &SmoothBudget::FACETED);
    assert_eq!(c.count(EdgeClass::Smooth), 0, "faceted");
    // The exporter's chord height is read back from the strips.
    let c = classify_edges(
        &m.positions,
        &f,
        &SmoothBudget {
            max_sag: 2.0 * chord,
            max_rms: f64::INFINITY,
        },
    );
    assert!(
        (c.chord_height - chord).abs() < 0.2 * chord,
        "chord height {}",
        c.chord_height
    );
    for (e, class) in f.edges.iter().zip(&c.class) {
        let rim = (e.angle - std::f64::consts::FRAC_PI_2).abs() < 1e-6;
        let expected = if e.flat {
            EdgeClass::Flat
        } else if rim {
            EdgeClass::Crease
        } else {
            EdgeClass::Smooth
        };
        assert_eq!(*class, expected, "{e:?}");
    }
    // An RMS budget below what all the strips predict (0.3 × the chord height over the side,
    // 82 % of the area) smooths only some of them.
    let all = c.count(EdgeClass::Smooth);
    let c = classify_edges(
        &m.positions,
        &f,
        &SmoothBudget {
            max_sag: 2.0 * chord,
            max_rms: 0.1 * chord,
        },
    );
    assert!(c.predicted_rms <= 0.1 * chord && c.count(EdgeClass::Smooth) < all / 2);
}

#[test]
fn a_fillet_is_smooth_inside_and_creased_where_it_meets_its_planes() {
    let m = Part::filleted_block(2.0, 1.0, 1.0, 0.2).tessellate(1e-3, None);
    let f = facets(&m);
    let c = classify_edges(
        &m.positions,
        &f,
        &SmoothBudget {
            max_sag: 2e-3,
            max_rms: f64::INFINITY,
        },
    );
    assert!(c.count(EdgeClass::Smooth) > 0);
    for (i, e) in f.edges.iter().enumerate() {
        let wide = f.edges[i]
            .faces
            .iter()
            .any(|&g| f.regions[f.region[g as usize] as usize].area > 0.1);
        if !e.flat && wide {
            assert_eq!(c.class[i], EdgeClass::Crease, "{e:?}");
        }
    }
}

#[test]
fn the_float32_tolerance_follows_the_magnitude() {
    let t = Facets::float32_tolerance(250.0, 1.0 / 12.0);
    assert!(t > 1e-6 && t < 2e-5, "{t}");
    assert_eq!(Facets::float32_tolerance(0.0, 1.0), 1e-9);
}
