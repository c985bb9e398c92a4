//! The curved interpolant of a tessellation (PN triangles, Vlachos et al. 2001) on a capped
//! cylinder exported coarsely: its points are far closer to the true cylinder than the
//! facets', its caps stay exactly flat, its rims stay where the facets put them, and it has no
//! cracks (closed in, closed out).

use std::collections::HashMap;

use subfit_mesh::shapes;
use subfit_target::tessellation::{curved_interpolant, Facets};

/// The capped cylinder of radius 1 and height `h`, `m` segments (as an exporter cuts it).
fn capped_cylinder(m: usize, h: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let c = shapes::capped_cylinder(1.0, h, m);
    (c.positions, c.faces.triangulate_fan())
}

/// Distance of `x` to the capped cylinder's surface.
fn cylinder_distance(x: [f64; 3], h: f64) -> f64 {
    let r = (x[0] * x[0] + x[1] * x[1]).sqrt();
    let (dr, dz) = (r - 1.0, (-x[2]).max(x[2] - h));
    if dr > 0.0 || dz > 0.0 {
        (dr.max(0.0).powi(2) + dz.max(0.0).powi(2)).sqrt()
    } else {
        (-dr).min(-dz)
    }
}

/// The same grid on flat facets: barycentric midpoints of every edge, recursively.
fn flat_deviation(p: &[[f64; 3]], t: &[[u32; 3]], n: usize, h: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for tri in t {
        let [a, b, c] = tri.map(|v| p[v as usize]);
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let x = [0, 1, 2].map(|k| (1.0 - u - v) * a[k] + u * b[k] + v * c[k]);
                worst = worst.max(cylinder_distance(x, h));
            }
        }
    }
    worst
}

#[test]
fn the_curved_interpolant_of_a_coarse_cylinder_is_near_the_cylinder() {
    let h = 2.0;
    let (p, t) = capped_cylinder(16, h);
    let facets = Facets::new(&p, &t, 1e-12);
    let curved_mesh = curved_interpolant(&p, &facets, 4);
    let (q, f) = (&curved_mesh.positions, &curved_mesh.triangles);
    assert_eq!(f.len(), t.len() * 16);
    // The input's vertices first, unchanged.
    assert_eq!(&q[..p.len()], &p[..]);

    let flat = flat_deviation(&p, &t, 4, h);
    let curved = q
        .iter()
        .map(|&x| cylinder_distance(x, h))
        .fold(0.0, f64::max);
    // The sag of a 16-gon is 1 − cos(π/16) = 0.019; the cubic patches through the corners
    // with the cylinder's normals follow it within 5.5e-4.
    let sag = 1.0 - (std::f64::consts::PI / 16.0).cos();
    assert!(
        (flat - sag).abs() < 1e-3 * sag,
        "flat {flat:.4e}, sag {sag:.4e}"
    );
    assert!(
        curved < 0.03 * sag,
        "curved {curved:.3e} against the facets' {flat:.3e}"
    );
    // Twice as many segments: the interpolant's error falls at least 8-fold (measured: 16-fold,
    // 5.5e-4 → 3.5e-5, fourth order), the facets' 4-fold.
    let (p2, t2) = capped_cylinder(32, h);
    let q2 = curved_interpolant(&p2, &Facets::new(&p2, &t2, 1e-12), 4).positions;
    let curved2 = q2
        .iter()
        .map(|&x| cylinder_distance(x, h))
        .fold(0.0, f64::max);
    assert!(curved2 < curved / 8.0, "{curved2:.3e} against {curved:.3e}");

    // The caps stay flat, the rims where the facets put them (a crease stays straight).
    for x in q {
        let on_cap = x[2].abs() < 1e-12 || (x[2] - h).abs() < 1e-12;
        let inside = x[0] * x[0] + x[1] * x[1] <= 1.0 + 1e-12;
        assert!(!on_cap || inside, "a cap point {x:?} off the cap");
        assert!(
            (-1e-12..=h + 1e-12).contains(&x[2]),
            "{x:?} bulges off the caps"
        );
    }

    // No cracks: every edge of the refined mesh has two faces.
    let mut count: HashMap<(u32, u32), usize> = HashMap::new();
    for tri in f {
        for i in 0..3 {
            let (a, b) = (tri[i], tri[(i + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    assert!(
        count.values().all(|&c| c == 2),
        "open edges in the interpolant"
    );

    // What the facets cut off: the sag, seen from the interpolant.
    let dev = curved_mesh.facet_deviation;
    assert!(
        (dev - sag).abs() < 0.05 * sag,
        "deviation {dev:.4e}, sag {sag:.4e}"
    );
}

#[test]
fn one_level_gives_the_facets_back() {
    let (p, t) = capped_cylinder(8, 1.0);
    let facets = Facets::new(&p, &t, 1e-12);
    let c = curved_interpolant(&p, &facets, 1);
    assert_eq!(c.positions, p);
    assert_eq!(c.triangles, t);
    assert_eq!(c.facet_deviation, 0.0);
}
