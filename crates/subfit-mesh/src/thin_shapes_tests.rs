//! Checks of the generated hard cases against their construction: closed, manifold, outward,
//! the genus asked for, and enclosed volumes against the analytic solids (within the chordal
//! error of the tessellation).

use super::*;
use crate::diagnose_mesh;
use crate::vec3::{cross, dot, norm};

/// Signed volume enclosed by a closed triangle mesh (positive for outward winding).
fn volume(m: &PolyMesh) -> f64 {
    m.faces
        .triangulate_fan()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| m.positions[v as usize]);
            dot(a, cross(b, c)) / 6.0
        })
        .sum()
}

/// Closed, manifold, consistently oriented, of genus `g`.
#[track_caller]
fn assert_closed_genus(m: &PolyMesh, g: u32) {
    let r = diagnose_mesh(m);
    assert!(r.is_closed, "boundary edges: {}", r.boundary_edges);
    assert!(r.is_manifold && r.is_consistently_oriented, "{r:?}");
    assert_eq!(r.num_components, 1);
    assert_eq!(r.genus, Some(g));
}

#[test]
fn capsule_is_the_solid_it_says() {
    for (r, l) in [(0.01, 1.0), (0.05, 1.0), (0.2, 0.5)] {
        let m = capsule(r, l, 48);
        assert_closed_genus(&m, 0);
        let exact = PI * r * r * l + 4.0 / 3.0 * PI * r * r * r;
        let v = volume(&m);
        // Inscribed 48-gons: the cross-section's area is short by about (2π/48)²/6 = 0.3 %.
        assert!((v - exact).abs() < 0.01 * exact, "r {r}: {v} vs {exact}");
        // Every vertex of the straight part is at the radius from the axis.
        for p in &m.positions {
            if p[2].abs() < 0.5 * l {
                assert!((p[0].hypot(p[1]) - r).abs() < 1e-12 * (1.0 + l));
            }
        }
    }
}

#[test]
fn coin_is_the_solid_it_says() {
    for t in [0.01, 0.05] {
        let (radius, h) = (0.5, 0.5 * t);
        let m = coin(radius, t, 128, 8);
        assert_closed_genus(&m, 0);
        // Pappus: the rim is a half disc of radius h, its centroid 4h/3π outside radius.
        let rim = 0.5 * PI * h * h * TAU * (radius + 4.0 * h / (3.0 * PI));
        let exact = PI * radius * radius * t + rim;
        let v = volume(&m);
        assert!((v - exact).abs() < 0.01 * exact, "t {t}: {v} vs {exact}");
        let zmax = m.positions.iter().map(|p| p[2].abs()).fold(0.0, f64::max);
        assert!((zmax - h).abs() < 1e-12);
    }
}

#[test]
fn handle_torus_is_thin_on_one_side() {
    let (major, thick, thin) = (1.0, 0.6, 0.03);
    let m = handle_torus(major, thick, thin, 96, 24);
    assert_closed_genus(&m, 1);
    assert!(volume(&m) > 0.0);
    // Tube radius at each vertex: its distance from the tube's centre circle.
    let radius = |p: &[f64; 3]| {
        let rho = p[0].hypot(p[1]);
        (rho - major).hypot(p[2])
    };
    // Every vertex on its tube: thick at the body (angle 0), thin at the handle (angle π).
    let mut thinnest = f64::INFINITY;
    for p in &m.positions {
        let w = 0.5 * (1.0 + p[1].atan2(p[0]).cos());
        let r = thin + (thick - thin) * w * w;
        assert!((radius(p) - r).abs() < 1e-12, "{p:?}");
        thinnest = thinnest.min(r);
    }
    assert!((thinnest - thin).abs() < 1e-12);
}

#[test]
fn lattice_has_the_genus_of_its_holes() {
    let m = lattice(&LatticeOptions::default());
    assert_closed_genus(&m, 8);
    assert!(volume(&m) > 0.0);
    let all = LatticeOptions {
        skip_middle: false,
        holes: 2,
        smoothing: 0,
        ..Default::default()
    };
    let m = lattice(&all);
    assert_closed_genus(&m, 4);
    // Unsmoothed: exactly the voxels, 5×5 minus 4 holes, one voxel thick.
    assert!((volume(&m) - 21.0).abs() < 1e-9, "{}", volume(&m));
    let diag = {
        let (lo, hi) = m.bounding_box().unwrap();
        norm(sub(hi, lo))
    };
    assert!((diag - (50.0f64 + 1.0).sqrt()).abs() < 1e-12);
}
