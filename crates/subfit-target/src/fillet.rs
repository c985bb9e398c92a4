//! Fillet widths of sharp feature curves: how wide the band is over which a mesh target's
//! surface turns from one side of a feature curve to the other — zero for a designed crease, a
//! few triangles for a rounded (filleted or worn) edge. The input of semi-sharp crease tags
//! (`subfit fit --semi-sharp`): OpenSubdiv's sharpness `s` keeps a crease sharp for
//! `s` levels and then lets the smooth rules round it (DeRose, Kass and Truong 1998,
//! *Subdivision Surfaces in Character Animation*, §3), so a wider fillet needs a smaller `s`.
//!
//! Per curve, at up to [`SAMPLES_PER_CURVE`] of its interior vertices `v` (tangent `t` from its
//! curve neighbours): the faces whose centroid lies within a radius `R` of `v` (6 mean curve
//! edge lengths) and within `R/2` of the cross-section plane through `v` are split into the
//! two sides of the curve by their offset across it (`b = t × n̄`, `n̄` the mean normal); the
//! faces of the outer half on each side give the side's plateau normal `n_a`, `n_b` and the
//! turn `Θ = ∠(n_a, n_b)`. A face is part of the fillet when its normal lies between the two
//! (within 10° of the arc from `n_a` to `n_b`) and at least `Θ/10` from both; the width at `v`
//! is the extent across the curve (along `b`) of those faces' vertices, 0 when there are none
//! (a sharp edge: the faces next to it are already on their plateaus). The curve's width is
//! the median over its sampled vertices. A curve vertex whose neighbourhood has no plateau on
//! one side (the curve runs along a boundary, or the side is all fillet) is skipped; a curve
//! with no usable vertex gets `None`.
//!
//! Cost: O(samples · faces within `R`), after an O(#corners) vertex → face table.

use subfit_mesh::vec3::{cross, dot, normalize, sub};
use subfit_mesh::Polygons;

use crate::features::Features;

/// The most vertices sampled per curve.
pub const SAMPLES_PER_CURVE: usize = 24;

/// Per feature curve of `features` (same order as `features.curves`): its fillet width in the
/// units of `positions`, `Some(0.0)` for a sharp crease, `None` when it could not be measured
/// (see the module docs).
pub fn fillet_widths(
    positions: &[[f64; 3]],
    faces: &Polygons,
    features: &Features,
) -> Vec<Option<f64>> {
    let mut vertex_faces: Vec<Vec<u32>> = vec![Vec::new(); positions.len()];
    let mut face_normal = Vec::with_capacity(faces.len());
    let mut centroid = Vec::with_capacity(faces.len());
    for (f, face) in faces.iter().enumerate() {
        for &v in face {
            if let Some(l) = vertex_faces.get_mut(v as usize) {
                l.push(f as u32);
            }
        }
        face_normal.push(newell(positions, face));
        let mut c = [0.0; 3];
        for &v in face {
            for k in 0..3 {
                c[k] += positions[v as usize][k] / face.len() as f64;
            }
        }
        centroid.push(c);
    }
    let ctx = Context {
        positions,
        faces,
        vertex_faces: &vertex_faces,
        face_normal: &face_normal,
        centroid: &centroid,
    };
    features
        .curves
        .iter()
        .map(|curve| {
            let vs = &curve.vertices;
            let n = vs.len();
            let interior: Vec<usize> = if curve.closed {
                (0..n).collect()
            } else {
                (1..n.saturating_sub(1)).collect()
            };
            if interior.is_empty() {
                return None;
            }
            let step = interior.len().div_ceil(SAMPLES_PER_CURVE).max(1);
            let mut widths: Vec<f64> = interior
                .iter()
                .step_by(step)
                .filter_map(|&i| {
                    let prev = vs[(i + n - 1) % n];
                    let next = vs[(i + 1) % n];
                    ctx.width_at(vs[i], prev, next)
                })
                .collect();
            if widths.is_empty() {
                return None;
            }
            widths.sort_by(f64::total_cmp);
            Some(widths[widths.len() / 2])
        })
        .collect()
}

/// The mesh with its per-face tables.
struct Context<'a> {
    positions: &'a [[f64; 3]],
    faces: &'a Polygons,
    vertex_faces: &'a [Vec<u32>],
    face_normal: &'a [[f64; 3]],
    centroid: &'a [[f64; 3]],
}

impl Context<'_> {
    /// The fillet width at curve vertex `v` between its curve neighbours `prev` and `next`.
    fn width_at(&self, v: u32, prev: u32, next: u32) -> Option<f64> {
        let p = |i: u32| self.positions[i as usize];
        let pv = p(v);
        let t = normalize(sub(p(next), p(prev)))?;
        let h = 0.5
            * (dot(sub(p(next), pv), sub(p(next), pv)).sqrt()
                + dot(sub(p(prev), pv), sub(p(prev), pv)).sqrt());
        let radius = 6.0 * h;
        let near = self.faces_near(v, radius, t);
        if near.is_empty() {
            return None;
        }
        let mut mean = [0.0; 3];
        for &f in &near {
            let n = self.face_normal[f as usize];
            for k in 0..3 {
                mean[k] += n[k];
            }
        }
        let b = normalize(cross(t, normalize(mean)?))?;
        let offset = |f: u32| dot(sub(self.centroid[f as usize], pv), b);
        // Plateau normals: the faces of the outer half on either side.
        let (mut na, mut nb) = ([0.0; 3], [0.0; 3]);
        for &f in &near {
            let s = offset(f);
            if s.abs() < 0.5 * radius {
                continue;
            }
            let n = self.face_normal[f as usize];
            let side = if s < 0.0 { &mut na } else { &mut nb };
            for k in 0..3 {
                side[k] += n[k];
            }
        }
        let (na, nb) = (normalize(na)?, normalize(nb)?);
        let turn = angle(na, nb);
        if turn < 1e-3 {
            return None;
        }
        let slack = 10f64.to_radians();
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for &f in &near {
            let n = self.face_normal[f as usize];
            let (a, c) = (angle(n, na), angle(n, nb));
            if a < 0.1 * turn || c < 0.1 * turn || a + c > turn + slack {
                continue;
            }
            for &w in self.faces.face(subfit_mesh::FaceId(f)) {
                let s = dot(sub(p(w), pv), b);
                lo = lo.min(s);
                hi = hi.max(s);
            }
        }
        Some(if hi >= lo { hi - lo } else { 0.0 })
    }

    /// Faces reachable from `v` through shared vertices whose centroid is within `radius` of
    /// `v` and within `radius / 2` of the plane through `v` normal to `t`.
    fn faces_near(&self, v: u32, radius: f64, t: [f64; 3]) -> Vec<u32> {
        let pv = self.positions[v as usize];
        let inside = |f: u32| {
            let d = sub(self.centroid[f as usize], pv);
            dot(d, d) <= radius * radius && dot(d, t).abs() <= 0.5 * radius
        };
        let mut seen: Vec<u32> = Vec::new();
        let mut queue: Vec<u32> = self.vertex_faces[v as usize].clone();
        queue.retain(|&f| inside(f));
        seen.extend(&queue);
        while let Some(f) = queue.pop() {
            for &w in self.faces.face(subfit_mesh::FaceId(f)) {
                for &g in &self.vertex_faces[w as usize] {
                    if !seen.contains(&g) && inside(g) {
                        seen.push(g);
                        queue.push(g);
                    }
                }
            }
        }
        seen
    }
}

/// The unit Newell normal of a polygon (zero for a degenerate one).
fn newell(positions: &[[f64; 3]], face: &[u32]) -> [f64; 3] {
    normalize(subfit_mesh::vec3::polygon_normal(positions, face)).unwrap_or([0.0; 3])
}

/// The angle between unit vectors (radians).
fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    dot(a, b).clamp(-1.0, 1.0).acos()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::{detect_features, FeatureOptions};
    use subfit_mesh::shapes::gridded_box;
    use subfit_mesh::PolyMesh;

    /// A square tube of side 1 along z (height 1, open ends), its four long edges rounded with
    /// radius `r` by quarter arcs of two segments each, gridded in triangles.
    fn rounded_tube(r: f64, nz: usize) -> PolyMesh {
        // The profile: per corner, the arc start, middle and end (counter-clockwise).
        let mut profile: Vec<[f64; 2]> = Vec::new();
        let centres = [[1.0 - r, 1.0 - r], [r, 1.0 - r], [r, r], [1.0 - r, r]];
        for (c, centre) in centres.iter().enumerate() {
            let a0 = c as f64 * std::f64::consts::FRAC_PI_2;
            for k in 0..3 {
                let a = a0 + k as f64 * std::f64::consts::FRAC_PI_4;
                profile.push([centre[0] + r * a.cos(), centre[1] + r * a.sin()]);
            }
            // Straight sides, gridded.
            let end = [
                centre[0] + r * (a0 + std::f64::consts::FRAC_PI_2).cos(),
                centre[1] + r * (a0 + std::f64::consts::FRAC_PI_2).sin(),
            ];
            let next = centres[(c + 1) % 4];
            let a1 = a0 + std::f64::consts::FRAC_PI_2;
            let start = [next[0] + r * a1.cos(), next[1] + r * a1.sin()];
            for k in 1..8 {
                let s = k as f64 / 8.0;
                profile.push([
                    end[0] + s * (start[0] - end[0]),
                    end[1] + s * (start[1] - end[1]),
                ]);
            }
        }
        let m = profile.len();
        let mut pos = Vec::new();
        for j in 0..=nz {
            let z = j as f64 / nz as f64;
            for q in &profile {
                pos.push([q[0], q[1], z]);
            }
        }
        let mut tris = Vec::new();
        for j in 0..nz {
            for i in 0..m {
                let a = (j * m + i) as u32;
                let b = (j * m + (i + 1) % m) as u32;
                let c = ((j + 1) * m + (i + 1) % m) as u32;
                let d = ((j + 1) * m + i) as u32;
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            }
        }
        PolyMesh::new(pos, Polygons::from_triangles(&tris))
    }

    #[test]
    fn a_sharp_box_has_zero_fillet_widths() {
        let m = gridded_box(12, false);
        let f = detect_features(&m.positions, &m.faces, &FeatureOptions::default());
        assert_eq!(f.curves.len(), 12);
        let w = fillet_widths(&m.positions, &m.faces, &f);
        for (i, w) in w.iter().enumerate() {
            assert_eq!(*w, Some(0.0), "curve {i}");
        }
    }

    #[test]
    fn a_rounded_tube_has_its_fillet_width() {
        for r in [0.05, 0.1] {
            let m = rounded_tube(r, 20);
            let f = detect_features(&m.positions, &m.faces, &FeatureOptions::default());
            assert_eq!(f.curves.len(), 4, "r = {r}");
            let w = fillet_widths(&m.positions, &m.faces, &f);
            // The two arc segments span the chord between the arc's ends, measured across
            // the curve (along the bisector's normal): r·√2.
            let expected = r * std::f64::consts::SQRT_2;
            for w in w {
                let w = w.unwrap();
                assert!(
                    (w - expected).abs() < 0.05 * expected,
                    "r = {r}: width {w}, expected {expected}"
                );
            }
        }
    }
}
