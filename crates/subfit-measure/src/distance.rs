//! Distance statistics, one way and both ways (DESIGN.md decision 11).
//!
//! Surface → data is Cheng et al.'s measure (2007 §II-B step 7): samples of the limit surface
//! against their foot points on the data. Alone it reports success on shapes the surface
//! leaves uncovered — boundaries that shrink, holes capped, rounded sharp edges — so a fit is
//! also measured data → surface, from the data's points to their exact closest points on the
//! limit surface, and a tolerance holds only when it holds both ways.

use serde::{Deserialize, Serialize};

/// Statistics of a set of distances (normalized units unless stated).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DistanceStats {
    /// Number of distances.
    pub samples: usize,
    /// Root mean square.
    pub rms: f64,
    /// Mean.
    pub mean: f64,
    /// Largest.
    pub max: f64,
}

impl DistanceStats {
    /// Statistics of `d` (summed in order: deterministic for any thread count). Empty: all 0.
    pub fn of(d: &[f64]) -> Self {
        if d.is_empty() {
            return Self::default();
        }
        let (mut s, mut s2, mut max) = (0.0, 0.0, 0.0f64);
        for &x in d {
            s += x;
            s2 += x * x;
            max = max.max(x);
        }
        let n = d.len() as f64;
        Self {
            samples: d.len(),
            rms: (s2 / n).sqrt(),
            mean: s / n,
            max,
        }
    }

    /// Statistics of distances `d` of points that stand for the areas `w` of a surface (e.g.
    /// the area each point of a tessellation stands for): RMS and mean weighted
    /// by area, so a region sampled densely (refined deeper, compressed) counts by its area, as
    /// in a measurement that samples the surface uniformly by area; the maximum and the count
    /// are unweighted. Unweighted ([`Self::of`]) when the weights do not match or sum to zero.
    pub fn of_weighted(d: &[f64], w: &[f64]) -> Self {
        let total: f64 = w.iter().sum();
        if w.len() != d.len() || total.is_nan() || total <= 0.0 || !total.is_finite() {
            return Self::of(d);
        }
        let (mut s, mut s2, mut max) = (0.0, 0.0, 0.0f64);
        for (&x, &a) in d.iter().zip(w) {
            s += a * x;
            s2 += a * x * x;
            max = max.max(x);
        }
        Self {
            samples: d.len(),
            rms: (s2 / total).sqrt(),
            mean: s / total,
            max,
        }
    }

    /// Statistics of data → surface distances `d` whose last `extremes` values are measured
    /// for the maximum only (a mesh's boundary vertices, [`crate::DataSamples::boundary`]):
    /// RMS and mean over the others (uniform by area), the maximum and the count over all.
    /// All of them when `extremes` leaves none.
    pub fn of_samples(d: &[f64], extremes: usize) -> Self {
        let area = &d[..d.len() - extremes.min(d.len())];
        if area.is_empty() {
            return Self::of(d);
        }
        Self {
            samples: d.len(),
            max: d.iter().fold(0.0, |m, &x| m.max(x)),
            ..Self::of(area)
        }
    }

    /// Statistics from squared distances.
    pub fn of_squared(d2: &[f64]) -> Self {
        let d: Vec<f64> = d2.iter().map(|x| x.max(0.0).sqrt()).collect();
        Self::of(&d)
    }

    /// Whether the tolerances that are set (`> 0`) hold: RMS ≤ `tolerance_rms`, max ≤
    /// `tolerance_max`; false when none is set.
    pub fn within(&self, tolerance_rms: f64, tolerance_max: f64) -> bool {
        let any = tolerance_rms > 0.0 || tolerance_max > 0.0;
        any && (tolerance_rms <= 0.0 || self.rms <= tolerance_rms)
            && (tolerance_max <= 0.0 || self.max <= tolerance_max)
    }

    /// The same scaled by `s` (e.g. normalized → original units).
    pub fn scaled(self, s: f64) -> Self {
        Self {
            samples: self.samples,
            rms: self.rms * s,
            mean: self.mean * s,
            max: self.max * s,
        }
    }
}

/// The triangles of the polygon mesh `faces` over `positions` (polygons fanned from their
/// first corner) with their areas.
fn fanned_triangles<'a>(
    positions: &'a [[f64; 3]],
    faces: &'a subfit_mesh::Polygons,
) -> impl Iterator<Item = ([usize; 3], f64)> + 'a {
    use subfit_mesh::vec3::{cross, norm, sub};
    faces.iter().flat_map(move |f| {
        (1..f.len().saturating_sub(1)).map(move |i| {
            let t = [f[0] as usize, f[i] as usize, f[i + 1] as usize];
            let area = 0.5
                * norm(cross(
                    sub(positions[t[1]], positions[t[0]]),
                    sub(positions[t[2]], positions[t[0]]),
                ));
            (t, area)
        })
    })
}

impl DistanceStats {
    /// Statistics of a distance field given at the vertices `d` of the polygon mesh `faces`
    /// over `positions` (a tessellation of the surface), uniform by area: the mean and RMS of
    /// the field interpolated linearly over each triangle (polygons fanned from their first
    /// corner), integrated exactly — `∫f = A (f₁ + f₂ + f₃) / 3` and
    /// `∫f² = A (f₁² + f₂² + f₃² + f₁f₂ + f₂f₃ + f₃f₁) / 6` — the maximum over the vertices.
    /// Lumping a third of each triangle's area on its corners instead (the mean is the same)
    /// overstates the RMS wherever the field changes across a triangle: up to twice the
    /// squared integral where it rises from 0 to its value across one triangle, as it does
    /// along a surface's boundary strip past the edge of a cloud's data. Falls back to
    /// [`Self::of`] when `d` does not match `positions` or the mesh has no area.
    /// Cost O(#corners).
    pub fn over_surface(d: &[f64], positions: &[[f64; 3]], faces: &subfit_mesh::Polygons) -> Self {
        if d.len() != positions.len() {
            return Self::of(d);
        }
        let (mut total, mut s, mut s2) = (0.0, 0.0, 0.0);
        for ([a, b, c], area) in fanned_triangles(positions, faces) {
            let (x, y, z) = (d[a], d[b], d[c]);
            total += area;
            s += area * (x + y + z) / 3.0;
            s2 += area * (x * x + y * y + z * z + x * y + y * z + z * x) / 6.0;
        }
        if total.is_nan() || total <= 0.0 || !total.is_finite() {
            return Self::of(d);
        }
        Self {
            samples: d.len(),
            rms: (s2 / total).max(0.0).sqrt(),
            mean: s / total,
            max: d.iter().fold(0.0, |m, &x| m.max(x)),
        }
    }
}

/// Distances both ways between a limit surface and its data.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TwoSided {
    /// Limit-surface samples to the data (Cheng's measure).
    pub surface_to_data: DistanceStats,
    /// Data points to their exact closest points on the limit surface.
    pub data_to_surface: DistanceStats,
}

impl TwoSided {
    /// The worse RMS of the two directions.
    pub fn rms(&self) -> f64 {
        self.surface_to_data.rms.max(self.data_to_surface.rms)
    }

    /// The worse maximum of the two directions (the Hausdorff distance of the two sample sets).
    pub fn max(&self) -> f64 {
        self.surface_to_data.max.max(self.data_to_surface.max)
    }

    /// Whether both directions meet the tolerances that are set (`> 0`); false when none is.
    pub fn within(&self, tolerance_rms: f64, tolerance_max: f64) -> bool {
        self.surface_to_data.within(tolerance_rms, tolerance_max)
            && self.data_to_surface.within(tolerance_rms, tolerance_max)
    }

    /// The same scaled by `s`.
    pub fn scaled(self, s: f64) -> Self {
        Self {
            surface_to_data: self.surface_to_data.scaled(s),
            data_to_surface: self.data_to_surface.scaled(s),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A field rising linearly from 0 to 1 across a unit square (two triangles): RMS 1/√3
    /// exactly, where lumping a third of each triangle's area on its corners says more.
    #[test]
    fn a_linear_field_over_a_square_integrates_exactly() {
        let positions = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let faces = subfit_mesh::Polygons::from_triangles(&[[0, 1, 2], [0, 2, 3]]);
        let d = [0.0, 1.0, 1.0, 0.0];
        let s = DistanceStats::over_surface(&d, &positions, &faces);
        assert!((s.rms - (1.0f64 / 3.0).sqrt()).abs() < 1e-12, "{}", s.rms);
        assert!((s.mean - 0.5).abs() < 1e-12);
        assert_eq!(s.max, 1.0);
        assert_eq!(s.samples, 4);
        let lumped = DistanceStats::of_weighted(&d, &[1.0 / 3.0, 1.0 / 6.0, 1.0 / 3.0, 1.0 / 6.0]);
        assert!(lumped.rms > s.rms + 0.05);
        // A mismatched field falls back to the plain statistics.
        assert_eq!(
            DistanceStats::over_surface(&d[..3], &positions, &faces),
            DistanceStats::of(&d[..3])
        );
    }

    #[test]
    fn stats_and_the_worse_direction() {
        let a = DistanceStats::of(&[3.0, 4.0]);
        assert_eq!(a.samples, 2);
        assert!((a.rms - 12.5f64.sqrt()).abs() < 1e-15);
        assert_eq!((a.mean, a.max), (3.5, 4.0));
        assert_eq!(DistanceStats::of_squared(&[9.0, 16.0]), a);
        assert_eq!(DistanceStats::of(&[]), DistanceStats::default());
        // Area weights: a point standing for three times the area counts three times.
        let w = DistanceStats::of_weighted(&[1.0, 3.0], &[3.0, 1.0]);
        assert!((w.mean - 1.5).abs() < 1e-15 && (w.rms - 3.0f64.sqrt()).abs() < 1e-15);
        assert_eq!(w.max, 3.0);
        assert_eq!(DistanceStats::of_weighted(&[3.0, 4.0], &[1.0]), a);
        let b = DistanceStats::of(&[1.0, 5.0, 0.0]);
        let t = TwoSided {
            surface_to_data: a,
            data_to_surface: b,
        };
        assert_eq!(t.max(), 5.0);
        assert_eq!(t.rms(), a.rms.max(b.rms));
        assert!(t.within(4.0, 0.0));
        assert!(!t.within(4.0, 4.5));
        assert!(t.within(0.0, 5.0));
        assert!(!t.within(0.0, 0.0), "no tolerance set is never reached");
        assert_eq!(t.scaled(2.0).data_to_surface.max, 10.0);
        // Rim points count for the maximum only.
        let r = DistanceStats::of_samples(&[3.0, 4.0, 9.0], 1);
        assert_eq!((r.samples, r.max), (3, 9.0));
        assert_eq!((r.rms, r.mean), (a.rms, a.mean));
        assert_eq!(DistanceStats::of_samples(&[3.0, 4.0], 2), a);
        assert_eq!(DistanceStats::of_samples(&[3.0, 4.0], 0), a);
    }
}
