use super::*;
use crate::diagnose_mesh;
use crate::vec3::{cross, dot};

/// Every part of the tests, with its genus.
fn parts() -> Vec<(&'static str, Part, u32)> {
    vec![
        ("block", Part::block(2.0, 1.0, 0.5), 0),
        ("l-bracket", Part::l_bracket(1.0, 0.6), 0),
        ("cylinder", Part::cylinder(0.5, 2.0), 0),
        ("tube", Part::tube(1.0, 0.6, 3.0), 1),
        ("filleted", Part::filleted_block(2.0, 1.5, 1.0, 0.3), 0),
        ("plate", Part::drilled_plate([3, 2], 1.0, 0.25, 0.2), 6),
    ]
}

#[test]
fn tessellations_are_closed_oriented_manifolds_of_the_right_genus() {
    for (name, part, genus) in parts() {
        for (chord, max_edge) in [(1e-2, None), (1e-3, Some(0.2))] {
            let m = part.tessellate(chord, max_edge);
            let r = diagnose_mesh(&m);
            assert!(
                r.is_manifold && r.is_closed && r.is_consistently_oriented,
                "{name} {chord}: {r:?}"
            );
            assert_eq!(r.genus, Some(genus), "{name} {chord}");
            assert_eq!(r.num_components, 1, "{name}");
            assert_eq!(r.degenerate_faces + r.repeated_vertex_faces, 0, "{name}");
            // Outward: the signed volume is the part's, positive.
            let volume: f64 = m
                .faces
                .iter()
                .map(|f| {
                    let [a, b, c] = [0, 1, 2].map(|k| m.positions[f[k] as usize]);
                    dot(a, cross(b, c)) / 6.0
                })
                .sum();
            assert!(volume > 0.0, "{name}: volume {volume}");
        }
    }
}

#[test]
fn vertices_lie_on_the_part_and_facets_within_the_chord_height() {
    for (name, part, _) in parts() {
        for chord in [1e-2, 1e-3] {
            let m = part.tessellate(chord, None);
            let scale = part.diagonal();
            for p in &m.positions {
                let d = part.distance(*p);
                assert!(d <= 1e-12 * scale, "{name}: vertex {p:?} {d}");
            }
            for f in m.faces.iter() {
                let [a, b, c] = [0, 1, 2].map(|k| m.positions[f[k] as usize]);
                // Centroid and edge midpoints sag by at most the chord height.
                for p in [
                    [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0),
                    [0, 1, 2].map(|k| 0.5 * (a[k] + b[k])),
                ] {
                    let d = part.distance(p);
                    assert!(d <= chord * (1.0 + 1e-9), "{name} {chord}: {d}");
                }
            }
        }
    }
}

#[test]
fn a_finer_chord_gives_more_segments_and_a_closer_surface() {
    let part = Part::cylinder(1.0, 1.0);
    let coarse = part.tessellate(1e-2, None);
    let fine = part.tessellate(1e-4, None);
    assert!(fine.positions.len() > 5 * coarse.positions.len());
    // The sagitta of the coarse facets: at least half the chord height is used.
    let worst = coarse
        .faces
        .iter()
        .map(|f| {
            let [a, b] = [0, 1].map(|k| coarse.positions[f[k] as usize]);
            part.distance([0, 1, 2].map(|k| 0.5 * (a[k] + b[k])))
        })
        .fold(0.0, f64::max);
    assert!(worst > 0.5e-2 && worst <= 1e-2, "{worst}");
}

#[test]
fn the_distance_is_exact_on_simple_cases() {
    let block = Part::block(2.0, 1.0, 0.5);
    assert!((block.distance([1.0, 0.5, 0.25]) - 0.25).abs() < 1e-15);
    assert!((block.distance([3.0, 0.5, 0.25]) - 1.0).abs() < 1e-15);
    assert!((block.distance([3.0, 2.0, 0.25]) - 2f64.sqrt()).abs() < 1e-15);
    let tube = Part::tube(1.0, 0.6, 3.0);
    assert!((tube.distance([0.0, 0.0, 1.5]) - 0.6).abs() < 1e-15);
    assert!((tube.distance([0.8, 0.0, 1.5]) - 0.2).abs() < 1e-12);
    let plate = Part::drilled_plate([2, 1], 1.0, 0.25, 0.2);
    assert!(
        (plate.distance([1.5, 0.5, 0.1]) - 0.25).abs() < 1e-12,
        "hole axis"
    );
    assert!((plate.distance([1.5, 0.85, 0.1]) - 0.1).abs() < 1e-12);
}
