//! Contouring oriented point clouds gives closed manifold meshes of the right genus near the
//! surface; the entry point simplifies them and reports the genus.

mod common;

use common::topology;
use subfit_init::{contour, initial_control_mesh, ContourOptions, InitOptions, InitSource};
use subfit_mesh::shapes::Shape;
use subfit_target::{Target, TargetOptions};

fn target_of(shape: &Shape, n: usize) -> Target {
    let cloud = shape.sample(n, 0.0, 7);
    Target::from_points(
        &cloud.positions,
        cloud.normals.as_deref(),
        &TargetOptions::default(),
    )
    .unwrap()
}

/// First-order distance `|f| / |∇f|` of a normalized point to the shape, in normalized units.
fn distance(shape: &Shape, t: &Target, p: [f64; 3]) -> f64 {
    let q = t.to_original(p);
    let g = shape.gradient(q);
    let d = shape.implicit(q).abs() / (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    t.normalization().length_to_normalized(d)
}

fn check_contour(shape: Shape, n: usize) {
    let t = target_of(&shape, n);
    let (m, rep) = contour(&t, &ContourOptions::default()).unwrap();
    assert_eq!(topology(&m), (shape.genus(), 0, 1), "{shape:?}: {rep:?}");
    assert_eq!(rep.genus, shape.genus());
    assert!(!rep.flipped);
    let worst = m
        .positions
        .iter()
        .map(|&p| distance(&shape, &t, p))
        .fold(0.0, f64::max);
    assert!(
        worst < 1.5 * rep.cell_size,
        "{shape:?}: {worst} vs cell {rep:?}"
    );
}

#[test]
fn ellipsoid_cloud_contours_to_a_sphere() {
    check_contour(Shape::PAPER_ELLIPSOID, 6000);
}

#[test]
fn torus_cloud_contours_to_genus_one() {
    check_contour(Shape::DEFAULT_TORUS, 8000);
}

#[test]
fn genus2_cloud_contours_to_genus_two() {
    check_contour(Shape::DEFAULT_GENUS2, 8000);
}

#[test]
fn point_cloud_initial_mesh_has_the_expected_genus() {
    let shape = Shape::DEFAULT_GENUS2;
    let t = target_of(&shape, 8000);
    let opts = InitOptions {
        expected_genus: Some(2),
        require_genus: true,
        ..InitOptions::default()
    };
    let (m, rep) = initial_control_mesh(&t, None, 150, &opts).unwrap();
    assert_eq!(rep.source, InitSource::Contour);
    assert_eq!((rep.genus_target, rep.genus_after), (2, 2));
    assert!(rep.genus_matches && rep.closed);
    // The thin handles may leave a few more vertices than asked when no legal collapse remains.
    assert!((150..=165).contains(&m.num_vertices()), "{rep:?}");
    assert_eq!(topology(&m), (2, 0, 1));
    let c = rep.contour.unwrap();
    let worst = m
        .positions
        .iter()
        .map(|&p| distance(&shape, &t, p))
        .fold(0.0, f64::max);
    assert!(worst < 3.0 * c.cell_size, "{worst} vs cell {}", c.cell_size);
}

#[test]
fn mesh_target_initial_mesh_keeps_the_genus() {
    let m0 = subfit_mesh::shapes::torus_mesh(1.0, 0.35, 40, 20, true);
    let t = Target::from_mesh(&m0, &TargetOptions::default()).unwrap();
    let (m, rep) = initial_control_mesh(&t, Some(&m0), 100, &InitOptions::default()).unwrap();
    assert_eq!(rep.source, InitSource::Mesh);
    assert_eq!((rep.genus_before, rep.genus_after), (1, 1));
    assert!(rep.genus_matches && rep.closed && rep.contour.is_none());
    assert_eq!(m.num_vertices(), 100);
    // Normalized units: inside the unit cube (up to rounding).
    for p in &m.positions {
        assert!(p.iter().all(|&c| (-0.01..=1.01).contains(&c)), "{p:?}");
    }
    assert!(matches!(
        initial_control_mesh(&t, Some(&m0), 3, &InitOptions::default()),
        Err(subfit_init::InitError::TooFewVertices(3))
    ));
}

#[test]
fn noisy_torus_cloud_still_has_genus_one() {
    let shape = Shape::DEFAULT_TORUS;
    let cloud = shape.sample(8000, 0.002, 11);
    let t = Target::from_points(
        &cloud.positions,
        cloud.normals.as_deref(),
        &TargetOptions::default(),
    )
    .unwrap();
    let (m, rep) = contour(&t, &ContourOptions::default()).unwrap();
    assert_eq!(topology(&m), (1, 0, 1), "{rep:?}");
}

#[test]
fn invalid_contour_options_are_errors() {
    let t = target_of(&Shape::PAPER_ELLIPSOID, 2000);
    let bad = ContourOptions {
        min_component_fraction: 2.0,
        ..ContourOptions::default()
    };
    assert!(matches!(
        contour(&t, &bad),
        Err(subfit_init::ContourError::InvalidOption(_))
    ));
    let bad = ContourOptions {
        refine_levels: 5,
        ..ContourOptions::default()
    };
    assert!(matches!(
        contour(&t, &bad),
        Err(subfit_init::ContourError::InvalidOption(_))
    ));
}

#[test]
fn inward_normals_are_detected_and_flipped() {
    let shape = Shape::DEFAULT_TORUS;
    let cloud = shape.sample(6000, 0.0, 3);
    let inward: Vec<[f64; 3]> = cloud
        .normals
        .as_ref()
        .unwrap()
        .iter()
        .map(|n| n.map(|c| -c))
        .collect();
    let t =
        Target::from_points(&cloud.positions, Some(&inward), &TargetOptions::default()).unwrap();
    let (m, rep) = contour(&t, &ContourOptions::default()).unwrap();
    assert!(rep.flipped, "{rep:?}");
    assert_eq!(topology(&m), (1, 0, 1), "{rep:?}");
    let worst = m
        .positions
        .iter()
        .map(|&p| distance(&shape, &t, p))
        .fold(0.0, f64::max);
    assert!(
        worst < 1.5 * rep.cell_size,
        "{worst} vs cell {}",
        rep.cell_size
    );
    // Also when the band is two octree levels above the finest cells.
    let fine = ContourOptions {
        resolution: Some(4 * rep.resolution),
        ..ContourOptions::default()
    };
    let (m, rep) = contour(&t, &fine).unwrap();
    assert!(rep.flipped && rep.band_level == 2, "{rep:?}");
    assert_eq!(topology(&m), (1, 0, 1), "{rep:?}");
}

#[test]
fn real_point_clouds_and_meshes_keep_their_genus() {
    let Some(dir) = common::data_dir() else {
        return;
    };
    for (file, genus) in [("rocker-arm.off", 1), ("fertility.off", 4)] {
        let (m, _) =
            subfit_io::read_file(&dir.join(file), &subfit_io::ReadOptions::default()).unwrap();
        // The vertices alone, normals estimated and oriented by the target.
        let t = Target::from_points(&m.positions, None, &TargetOptions::default()).unwrap();
        let opts = InitOptions {
            expected_genus: Some(genus),
            require_genus: true,
            ..InitOptions::default()
        };
        let (out, rep) = initial_control_mesh(&t, None, 1000, &opts).unwrap();
        assert_eq!(topology(&out), (genus, 0, 1), "{file}: {rep:?}");
        assert!(out.num_vertices() <= 1050, "{file}: {rep:?}");
        // The mesh itself.
        let t = Target::from_mesh(&m, &TargetOptions::default()).unwrap();
        let (out, rep) = initial_control_mesh(&t, Some(&m), 900, &opts).unwrap();
        assert_eq!(rep.source, InitSource::Mesh);
        assert_eq!(topology(&out), (genus, 0, 1), "{file}: {rep:?}");
        assert_eq!(out.num_vertices(), 900, "{file}: {rep:?}");
    }
}

/// Carving ignores the normals: a genus-2 cloud gives a closed genus-2 wrap about `r` outside.
#[test]
fn carving_wraps_a_genus2_cloud_without_normals() {
    let shape = Shape::DEFAULT_GENUS2;
    let t = target_of(&shape, 8000);
    let r = 0.02;
    let (m, rep) = subfit_init::carve(&t, 80, r, 0.05).unwrap();
    assert_eq!(topology(&m), (2, 0, 1), "{rep:?}");
    assert_eq!(rep.genus, 2);
    for &p in &m.positions {
        let d = distance(&shape, &t, p);
        assert!(d < r + 1.5 * rep.cell_size, "{d} vs r {r}: {rep:?}");
    }
    assert!(subfit_init::carve(&t, 80, 0.0, 0.05).is_err());
}

/// With a third of the normals flipped at random, their signs disagree between neighbours:
/// the target orients them again (`reoriented_input_normals`) and the IMLS contour has the
/// torus's genus without help.
#[test]
fn randomly_flipped_normals_are_oriented_again_and_the_contour_is_right() {
    let shape = Shape::DEFAULT_TORUS;
    let cloud = shape.sample(8000, 0.0, 5);
    let normals = flipped(&cloud, |i, _| i % 3 == 0);
    let t =
        Target::from_points(&cloud.positions, Some(&normals), &TargetOptions::default()).unwrap();
    assert!(t.stats().reoriented_input_normals);
    let (m, rep) = initial_control_mesh(&t, None, 200, &InitOptions::default()).unwrap();
    assert!(rep.carve_radius.is_none());
    assert_eq!(topology(&m), (1, 0, 1), "{rep:?}");
}

/// Normals flipped over a whole half of the torus agree with their neighbours within each
/// half, so the target keeps them, and the IMLS contour gets the genus wrong; given the
/// expected genus, `initial_control_mesh` falls back to carving and gets it right.
#[test]
fn wrong_normals_fall_back_to_carving_when_the_genus_is_known() {
    let shape = Shape::DEFAULT_TORUS;
    let cloud = shape.sample(8000, 0.0, 5);
    let normals = flipped(&cloud, |_, p| p[0] > 0.0);
    let t =
        Target::from_points(&cloud.positions, Some(&normals), &TargetOptions::default()).unwrap();
    assert!(!t.stats().reoriented_input_normals);
    let (_, plain) = initial_control_mesh(&t, None, 200, &InitOptions::default()).unwrap();
    assert!(plain.carve_radius.is_none());
    assert_ne!(
        plain.genus_after, 1,
        "the corrupted normals should mislead IMLS: {plain:?}"
    );
    let opts = InitOptions {
        expected_genus: Some(1),
        require_genus: true,
        ..InitOptions::default()
    };
    let (m, rep) = initial_control_mesh(&t, None, 200, &opts).unwrap();
    assert!(rep.carve_radius.is_some(), "{rep:?}");
    assert_eq!(topology(&m), (1, 0, 1), "{rep:?}");
    assert!(m.num_vertices() <= 200);
}

/// The normals of `cloud` with those of the points where `flip(index, position)` turned over.
fn flipped(cloud: &subfit_mesh::PolyMesh, flip: impl Fn(usize, [f64; 3]) -> bool) -> Vec<[f64; 3]> {
    let normals = cloud.normals.as_ref().unwrap();
    normals
        .iter()
        .zip(&cloud.positions)
        .enumerate()
        .map(|(i, (n, &p))| if flip(i, p) { n.map(|c| -c) } else { *n })
        .collect()
}

/// Every undirected edge of `m` is in exactly two triangles (no crack, no fin).
#[track_caller]
fn assert_crack_free(m: &subfit_mesh::PolyMesh) {
    let mut count = std::collections::HashMap::<(u32, u32), u32>::new();
    for t in m.faces.triangulate_fan() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let bad: Vec<_> = count.iter().filter(|(_, &n)| n != 2).take(5).collect();
    assert!(bad.is_empty(), "edges not in exactly two faces: {bad:?}");
}

/// First-order distance `|f| / |∇f|` of a point to the target's IMLS zero set.
fn imls_distance(t: &Target, p: [f64; 3]) -> f64 {
    let v = t.imls(p);
    let g = v.gradient;
    v.value.abs() / (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt()
}

/// The octree contour of a sphere and a torus cloud, at the automatic resolution (band level =
/// finest) and at 4× (band two levels up, finest cells only around the zero set): closed,
/// manifold, one component of the right genus, every edge in two faces, leaves on at least 3
/// levels; vertices within a fifth of a finest cell of the IMLS zero set, and within 0.15 (0.5 at 4×) of the
/// true surface at the automatic resolution (at 4× the cell is finer than the IMLS function's
/// own bias, about a quarter of the band cell here).
#[test]
fn octree_contours_are_closed_crack_free_and_on_the_surface() {
    let sphere = Shape::Ellipsoid {
        a: 1.0,
        b: 1.0,
        c: 1.0,
    };
    for (shape, n) in [(sphere, 6000), (Shape::DEFAULT_TORUS, 8000)] {
        let t = target_of(&shape, n);
        let (_, auto) = contour(&t, &ContourOptions::default()).unwrap();
        for res in [auto.resolution, 4 * auto.resolution] {
            let opts = ContourOptions {
                resolution: Some(res),
                ..ContourOptions::default()
            };
            let (m, rep) = contour(&t, &opts).unwrap();
            let what = format!("{shape:?} at {res}: {rep:?}");
            assert_eq!(topology(&m), (shape.genus(), 0, 1), "{what}");
            assert_crack_free(&m);
            let levels = rep.leaves_per_level.iter().filter(|&&n| n > 0).count();
            assert!(levels >= 3, "{what}");
            assert_eq!(rep.band_level, if res == auto.resolution { 0 } else { 2 });
            let cell = rep.cell_size;
            let worst =
                |d: &dyn Fn([f64; 3]) -> f64| m.positions.iter().map(|&p| d(p)).fold(0.0, f64::max);
            let on_imls = worst(&|p| imls_distance(&t, p));
            assert!(on_imls < 0.2 * cell, "{on_imls} vs cell {cell}: {what}");
            let on_shape = worst(&|p| distance(&shape, &t, p));
            let allowed = if rep.band_level == 0 { 0.15 } else { 0.5 } * cell;
            assert!(on_shape < allowed, "{on_shape} vs cell {cell}: {what}");
        }
    }
}

/// A resolution far above the old uniform grid's 160: 512 finest cells on a torus cloud. The
/// octree stays proportional to the surface (its points are a small fraction of the 512³ a
/// uniform grid would need; the figures are printed by `cargo bench --bench init`) and the
/// contour is still a closed, crack-free torus on the IMLS zero set.
#[test]
fn resolution_512_uses_a_small_octree() {
    let shape = Shape::DEFAULT_TORUS;
    let t = target_of(&shape, 8000);
    let opts = ContourOptions {
        resolution: Some(512),
        ..ContourOptions::default()
    };
    let (m, rep) = contour(&t, &opts).unwrap();
    let what = format!(
        "{} points, leaves {:?}, {} V",
        rep.octree_nodes, rep.leaves_per_level, rep.vertices
    );
    assert_eq!(rep.resolution, 512);
    assert!(rep.octree_nodes < 512 * 512 * 512 / 20, "{what}");
    assert_eq!(topology(&m), (1, 0, 1), "{what}");
    assert_crack_free(&m);
    let cell = rep.cell_size;
    for &p in m.positions.iter().step_by(97) {
        let d = imls_distance(&t, p);
        assert!(d < 0.1 * cell, "{d} vs cell {cell}: {what}");
    }
}

#[test]
fn resolutions_out_of_range_are_errors() {
    let t = target_of(&Shape::PAPER_ELLIPSOID, 2000);
    for bad in [
        ContourOptions {
            resolution: Some(1),
            ..ContourOptions::default()
        },
        ContourOptions {
            resolution: Some(subfit_init::MAX_RESOLUTION + 1),
            ..ContourOptions::default()
        },
        ContourOptions {
            refine_margin: -1.0,
            ..ContourOptions::default()
        },
    ] {
        assert!(matches!(
            contour(&t, &bad),
            Err(subfit_init::ContourError::InvalidOption(_))
        ));
    }
}

/// Thin parts keep their topology with a level of refinement below the band: a thin ring (tube
/// radius 0.02 on a ring of radius 1) and a thin genus-2 tube (half-thickness 0.03), 8,000
/// points each. On the band level alone (the default) their insides fall between the lattice
/// points and the contour breaks into pieces or loses its holes (the torus: 29 components;
/// the genus-2 tube: 6 components of genus 0); with [`ContourOptions::refine_levels`] 1 it
/// is one component of the right genus near the surface.
#[test]
fn thin_tubes_keep_their_topology() {
    for shape in [
        Shape::Torus {
            major: 1.0,
            minor: 0.02,
        },
        Shape::Genus2 { eps: 0.03 },
    ] {
        let t = target_of(&shape, 8000);
        let (m, rep) = contour(&t, &ContourOptions::default()).unwrap();
        assert_ne!(topology(&m), (shape.genus(), 0, 1), "{shape:?}: {rep:?}");
        let refined = ContourOptions {
            refine_levels: 1,
            ..ContourOptions::default()
        };
        let (m, rep) = contour(&t, &refined).unwrap();
        assert_eq!(topology(&m), (shape.genus(), 0, 1), "{shape:?}: {rep:?}");
        assert_crack_free(&m);
        let worst = m
            .positions
            .iter()
            .map(|&p| distance(&shape, &t, p))
            .fold(0.0, f64::max);
        assert!(worst < rep.cell_size, "{shape:?}: {worst} vs {rep:?}");
    }
}

/// A hollow ball: points on a sphere of radius 1 (normals outward) and on one of radius 0.6
/// (normals inward, towards the cavity). The cavity is off the band and out of the flood
/// fill's reach, and the band points around it are on its outside side: it is classified
/// outside, and the contour is the two spheres (a region enclosed by the band was taken as
/// inside before, which put a third, data-less sphere at the band's inner edge).
#[test]
fn an_enclosed_cavity_is_outside() {
    let unit = Shape::Ellipsoid {
        a: 1.0,
        b: 1.0,
        c: 1.0,
    };
    let outer = unit.sample(8000, 0.0, 5);
    let inner = unit.sample(3000, 0.0, 6);
    let mut points = outer.positions.clone();
    let mut normals = outer.normals.clone().unwrap();
    points.extend(inner.positions.iter().map(|p| p.map(|c| 0.6 * c)));
    normals.extend(inner.normals.unwrap().iter().map(|n| n.map(|c| -c)));
    let t = Target::from_points(&points, Some(&normals), &TargetOptions::default()).unwrap();
    let (m, rep) = contour(&t, &ContourOptions::default()).unwrap();
    assert!(rep.enclosed_nodes == 0 && !rep.flipped, "{rep:?}");
    assert_eq!(topology(&m), (0, 0, 2), "{rep:?}");
    for &p in &m.positions {
        let r = subfit_mesh::vec3::norm(t.to_original(p));
        assert!(
            (r - 1.0).abs() < 0.05 || (r - 0.6).abs() < 0.05,
            "{r}: {rep:?}"
        );
    }
}
