//! Unit tests of the stage driver's private helpers and of [`crate::stage_refine`] (tag carrying,
//! refinement order).

use super::*;
use crate::remesh::refine_red_green;
use crate::report::ErrorStats;
use crate::stage_measure::judged_with_boundary;
use crate::stage_refine::{carry_tags, FEATURE_PRIORITY};
use subfit_measure::TwoSided;
use subfit_mesh::shapes::octahedron_mesh;
use subfit_mesh::{Tags, SHARPNESS_INFINITE};

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

/// Near the RMS tolerance a refinement grows the cage by what the error's order predicts,
/// not by the full growth; far from it, or for a missed maximum only, by the full growth.
#[test]
fn refinement_near_the_tolerance_grows_by_what_is_needed() {
    let stages = StageOptions {
        tolerance_rms: 1.0,
        ..StageOptions::default()
    };
    let g = |rms: f64, unmet| needed_growth(&stages, rms, unmet);
    // 5 % above: 1.05^(4/3) · 1.05 − 1 ≈ 12 %.
    let near = g(1.05, (true, false));
    assert!((near - (1.05f64.powf(1.0 / RMS_ORDER) * 1.05 - 1.0)).abs() < 1e-12);
    assert!(near > 0.1 && near < 0.15, "{near}");
    assert_eq!(g(2.0, (true, false)), stages.growth);
    assert_eq!(g(1.05, (false, true)), stages.growth);
    // At the tolerance (rounding): the margin.
    assert!((g(1.0, (true, false)) - GROWTH_MARGIN).abs() < 1e-12);
}

/// A boundary vertex is judged by the boundary tolerance through the maximum: its distance is
/// scaled by `tolerance_max / tolerance_boundary`, the reported figures are not.
#[test]
fn boundary_vertices_are_judged_by_their_own_tolerance() {
    let stages = StageOptions {
        tolerance_rms: 1.0,
        tolerance_max: 7.0,
        tolerance_boundary: 3.5,
        ..StageOptions::default()
    };
    let two = TwoSided {
        surface_to_data: subfit_measure::DistanceStats::of(&[1.0, 2.0]),
        data_to_surface: subfit_measure::DistanceStats::of(&[1.0, 5.0, 4.0]),
    };
    // The last distance (4.0) is a boundary vertex: judged as 8 against 7.
    let judged = judged_with_boundary(&two, &[4.0], &stages);
    assert_eq!(judged.data_to_surface.max, 8.0);
    assert_eq!(two.data_to_surface.max, 5.0);
    assert!(!judged.within(1e9, stages.tolerance_max));
    assert!(judged_with_boundary(&two, &[3.0], &stages).within(1e9, 7.0));
    // Without a boundary tolerance nothing changes.
    let plain = StageOptions {
        tolerance_boundary: 0.0,
        ..stages.clone()
    };
    assert_eq!(
        judged_with_boundary(&two, &[4.0], &plain)
            .data_to_surface
            .max,
        5.0
    );
}

/// On a noisy scan the noise is taken out of the ratio: an RMS at 1.02 × a noise-floored
/// tolerance can still be far from the tolerance's noise-free part.
#[test]
fn the_noise_is_taken_out_of_the_growth() {
    let stages = StageOptions {
        tolerance_rms: 1.0f64.hypot(3.0),
        noise_rms: 3.0,
        ..StageOptions::default()
    };
    // rms² − 9 = 1.02² · 10 − 9 ≈ 1.40: 1.18 × the noise-free tolerance.
    let g = needed_growth(&stages, 1.02 * 10f64.sqrt(), (true, false));
    let plain = needed_growth(
        &StageOptions {
            noise_rms: 0.0,
            ..stages.clone()
        },
        1.02 * 10f64.sqrt(),
        (true, false),
    );
    assert!(g > 0.2 && plain < 0.1, "{g} vs {plain}");
}

/// The badness ranks a cage meeting both tolerances above any that misses one, and counts
/// progress on either miss when both are missed: a stage at 1.3× the RMS tolerance and 2.2×
/// the maximum beats one at 1.7× and 2.1× (the larger ratio alone ranked them the other way).
#[test]
fn badness_counts_progress_on_either_missed_tolerance() {
    let stages = StageOptions {
        tolerance_rms: 1.0,
        tolerance_max: 10.0,
        two_sided: false,
        ..StageOptions::default()
    };
    let two = TwoSided {
        surface_to_data: subfit_measure::DistanceStats::of(&[0.0]),
        data_to_surface: subfit_measure::DistanceStats::of(&[0.0]),
    };
    let bad = |rms: f64, max: f64| {
        let e = ErrorStats {
            e_rms: rms,
            e_max: max,
            ..ErrorStats::default()
        };
        stages.badness(&e, &two)
    };
    assert!(bad(1.3, 22.0) < bad(1.7, 21.0));
    assert!((bad(1.3, 22.0) - (1.3f64 * 2.2).sqrt()).abs() < 1e-12);
    // Both met: the larger ratio, below 1 and so below any miss.
    assert_eq!(bad(0.9, 5.0), 0.9);
    assert!(bad(0.99, 9.9) < bad(0.1, 10.01));
    // One missed: its ratio's square root, in the same order as the ratio.
    assert!(bad(0.5, 12.0) < bad(0.9, 13.0));
    // One tolerance set: its ratio.
    let rms_only = StageOptions {
        tolerance_max: 0.0,
        ..stages.clone()
    };
    let e = ErrorStats {
        e_rms: 1.5,
        e_max: 99.0,
        ..ErrorStats::default()
    };
    assert_eq!(rms_only.badness(&e, &two), 1.5);
}
