//! Unit tests of the stage driver's private helpers (tag carrying, refinement order).

use super::*;
use crate::remesh::refine_red_green;
use subfit_mesh::shapes::octahedron_mesh;

/// A crease on a split edge passes to both halves; one on an unsplit edge stays.
#[test]
fn tags_survive_refinement() {
    let mesh = octahedron_mesh(1.0, 1.0, 1.0);
    let f0 = mesh.faces.iter().next().unwrap().to_vec();
    let mut tags = Tags::new();
    tags.set_crease(f0[0], f0[1], 2.0);
    tags.set_corner(f0[2], 1.0);
    let n = mesh.num_vertices();
    let mut marked = vec![false; mesh.faces.len()];
    marked[0] = true;
    let (refined, _) = refine_red_green(&mesh, &marked).unwrap();
    let out = carry_tags(&tags, n, &refined.faces);
    let creases = out.creases();
    assert_eq!(creases.len(), 2, "{creases:?}");
    for ((a, b), s) in creases {
        assert_eq!(s, 1.0, "a finite sharpness drops by one per split");
        let (old, new) = if (a as usize) < n { (a, b) } else { (b, a) };
        assert!([f0[0], f0[1]].contains(&old) && new as usize >= n);
    }
    assert_eq!(out.corner(f0[2]), 1.0);
    // Nothing split: the tags as they were.
    let same = carry_tags(&tags, n, &mesh.faces);
    assert_eq!(same.creases(), tags.creases());
}

/// With room for one split, a face along a crease goes before a smooth face that scores
/// higher, but less than [`FEATURE_PRIORITY`] times higher; without the crease the worse
/// face goes first.
#[test]
fn refinement_prefers_crease_faces() {
    let mesh = octahedron_mesh(1.0, 1.0, 1.0);
    let faces: Vec<Vec<u32>> = mesh.faces.iter().map(<[u32]>::to_vec).collect();
    // Face 1 shares no edge with face 0's crease edge (f0[0], f0[1]) unless it must.
    let f0 = &faces[0];
    let other = (1..faces.len())
        .find(|&g| {
            let e = &faces[g];
            !(e.contains(&f0[0]) && e.contains(&f0[1]))
        })
        .unwrap();
    let mut score = vec![0.0; faces.len()];
    score[0] = 1.2;
    score[other] = 1.2 * FEATURE_PRIORITY * 0.9;
    let depth = vec![0u8; faces.len()];
    let stages = StageOptions {
        growth: 1e-6,
        max_control_points: 1000,
        ..StageOptions::default()
    };
    // Which face was split shows in the crease edge: split (two halves) only when face 0,
    // the face along it, was.
    let creases_after = |sharpness: f64| {
        let mut tags = Tags::new();
        tags.set_crease(f0[0], f0[1], sharpness);
        let r = refine_step(&mesh, &tags, &score, &depth, &stages, &Splitter::RedGreen)
            .unwrap()
            .unwrap();
        // One red split (4 children) and its green closure (3 neighbours, 2 each).
        assert_eq!(r.per_face.iter().filter(|&&d| d == 1).count(), 10);
        r.tags.creases().len()
    };
    assert_eq!(
        creases_after(SHARPNESS_INFINITE),
        2,
        "the crease face first"
    );
    // A semi-sharp tag is no sharp feature: the worse face first, the tagged edge kept.
    assert_eq!(creases_after(2.0), 1);
}
