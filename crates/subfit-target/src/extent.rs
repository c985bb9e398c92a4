//! The distance from a point to a point cloud's surface as a user measures it (DESIGN.md
//! decision 11: the error we report is the error a user would measure), for the surface → data
//! direction of the measurer. The fitter's foot points are projections onto local quadrics
//! ([`crate::project`]) fitted over neighbourhoods of many points; two things they miss:
//! - **Past the data's edge.** A quadric goes on past the last data point: a limit surface
//!   that overhangs the edge of a scan, or spans a hole of a single view (a veil over an
//!   occlusion), is as near the nearest quadric as the data around it, however far it is from
//!   any data — and a quadric of a ragged edge that curls away says far where the data is near.
//! - **Detail finer than the neighbourhood.** Where the quadric smooths what the data shows
//!   (the scales of a scanned statue), a surface that follows the data is measured to the
//!   smoothed quadric.
//!
//! So the data's local surface is also taken as one disc per data point, on its tangent plane
//! (its normal), of one radius for the whole cloud — the median distance of a point to its
//! [`EXTENT_NEIGHBOURS`]-th nearest neighbour ([`Target::data_reach`]) — and a point is as far
//! from the data as the nearer of its quadric foot point and the nearest disc; farther than the
//! radius from every data point, the quadric is an extrapolation and only the discs count.
//! The discs are the point surfaces of Hoppe et al., "Surface reconstruction from unorganized
//! points", SIGGRAPH 1992, §3.2 (tangent planes of `k` neighbours, a sampling density `δ` past
//! which there is no surface).
//!
//! Why that radius: `k` neighbours of a sampling of density `ρ` fill a disc of area `k / ρ`,
//! so the `k`-th-neighbour distance is about twice the mean spacing for `k = 12`, and the
//! largest empty circle among `N` random points (area about `ln N / ρ`) stays inside it: the
//! discs leave no false gaps inside the data, and the distance grows continuously past their
//! rim. A mesh target needs none of this: its foot points are on its triangles.
//!
//! Measured against the scoreboard's judge (`subfit bench corpus $SUBFIT_CORPUS --category
//! range`, the report's two-sided figures against the judge's, % of the diagonal): with
//! quadric foot points alone the report said 0.69 % Hausdorff where the judge measured 0.81 %
//! (range-dragon-stand-264) and 1.15 % against 1.34 %; with the discs past the edge only, the
//! maxima agreed but the surface → data RMS stayed 12–16 % above the judge's on three of four
//! views (finer detail than the quadrics); with both, every row agrees within 7 %.
//!
//! Cost: [`Target::data_reach`] once (one `k`-nearest query per point of an even subsample of
//! at most [`REACH_SAMPLES`] points); [`Target::to_local_surface`] one [`DISCS_NEAR`]-nearest
//! query per point measured, a [`DISCS_TRIED`]-nearest one for a point past the radius.

use rayon::prelude::*;
use subfit_mesh::vec3::{dot, norm, sub};

use crate::Target;

/// Neighbours whose farthest sets the discs' radius ([`Target::data_reach`]).
pub const EXTENT_NEIGHBOURS: usize = 12;
/// Points whose neighbours set the radius, at most (an even subsample): the median of the
/// `k`-th-neighbour distance is a property of the sampling, well estimated from this many.
pub const REACH_SAMPLES: usize = 50_000;
/// Nearest data points whose discs a query within the radius of the data is measured to.
const DISCS_NEAR: usize = 4;
/// Nearest data points whose discs a query past the radius is measured to.
const DISCS_TRIED: usize = 8;

impl Target {
    /// The radius of a point cloud's local surface (normalized units): the median over the
    /// points (an even subsample of at most [`REACH_SAMPLES`]) of the distance to their
    /// [`EXTENT_NEIGHBOURS`]-th nearest neighbour; see the module docs. 0 when the cloud has
    /// too few points. Computed on the first call and kept.
    pub fn data_reach(&self) -> f64 {
        *self.reach.get_or_init(|| {
            let points = self.points();
            if points.len() <= EXTENT_NEIGHBOURS {
                return 0.0;
            }
            let stride = points.len().div_ceil(REACH_SAMPLES);
            let mut far: Vec<f64> = points
                .par_iter()
                .step_by(stride)
                .map(|p| {
                    self.index()
                        .k_nearest(p, EXTENT_NEIGHBOURS + 1)
                        .last()
                        .map_or(0.0, |n| n.distance)
                })
                .collect();
            let mid = far.len() / 2;
            far.select_nth_unstable_by(mid, f64::total_cmp);
            far[mid]
        })
    }

    /// Sets the squared surface → data distance `err2[i]` of each point `xs[i]` (normalized
    /// units; from the quadric foot points) of a point cloud target to the squared distance to
    /// the data's local surface as the module docs define it: the smaller of `err2[i]` and the
    /// nearest data disc's, or the disc's alone where `xs[i]` is farther than
    /// [`Self::data_reach`] from every data point (past the edge of the data, or over a hole in
    /// it). A mesh target is left alone.
    pub fn to_local_surface(&self, xs: &[[f64; 3]], err2: &mut [f64]) {
        if self.mesh().is_some() || self.facets().is_some() {
            return;
        }
        let reach = self.data_reach();
        if reach <= 0.0 {
            return;
        }
        xs.par_iter().zip(err2.par_iter_mut()).for_each(|(x, e)| {
            let near = self.index().k_nearest(x, DISCS_NEAR);
            let within = near.first().is_some_and(|n| n.distance <= reach);
            let disc = if within {
                near.iter()
                    .map(|n| {
                        let i = n.index as usize;
                        disc_distance(*x, self.points()[i], self.normals()[i], reach)
                    })
                    .fold(f64::INFINITY, f64::min)
            } else {
                self.index()
                    .k_nearest(x, DISCS_TRIED)
                    .iter()
                    .map(|n| {
                        let i = n.index as usize;
                        disc_distance(*x, self.points()[i], self.sampling_normal(i), reach)
                    })
                    .fold(f64::INFINITY, f64::min)
            };
            if disc.is_finite() {
                *e = if within {
                    e.min(disc * disc)
                } else {
                    disc * disc
                };
            }
        });
    }
}

impl Target {
    /// The normal of point `i`'s tangent plane at the sampling's own scale: the axis of least
    /// variance of its [`EXTENT_NEIGHBOURS`] nearest points and itself (Hoppe et al. 1992
    /// §3.2). Past the data's edge the disc's tilt decides how far a point overhangs, and the
    /// target's normals, estimated over the fitting neighbourhood, lean over a ragged edge or
    /// a depth jump of a range scan where the nearest points do not.
    fn sampling_normal(&self, i: usize) -> [f64; 3] {
        let p = self.points()[i];
        let rel: Vec<[f64; 3]> = self
            .index()
            .k_nearest(&p, EXTENT_NEIGHBOURS + 1)
            .iter()
            .map(|n| sub(self.points()[n.index as usize], p))
            .collect();
        let (_, _, axes) = crate::estimate::pca(&rel);
        axes[0]
    }
}

/// Distance from `x` to the disc of radius `radius` centred on `centre` with unit normal
/// `normal` (to the point itself when the normal is not a unit vector).
fn disc_distance(x: [f64; 3], centre: [f64; 3], normal: [f64; 3], radius: f64) -> f64 {
    let d = sub(x, centre);
    if (norm(normal) - 1.0).abs() > 1e-6 {
        return norm(d);
    }
    let h = dot(d, normal);
    let t = (norm(d).powi(2) - h * h).max(0.0).sqrt();
    if t <= radius {
        h.abs()
    } else {
        (h * h + (t - radius).powi(2)).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TargetOptions;

    /// A square grid of points in z = 0 with spacing `h`, `n × n`.
    fn grid(n: usize, h: f64) -> Vec<[f64; 3]> {
        (0..n * n)
            .map(|i| [(i % n) as f64 * h, (i / n) as f64 * h, 0.0])
            .collect()
    }

    #[test]
    fn a_disc_is_measured_to_its_rim() {
        let n = [0.0, 0.0, 1.0];
        assert!((disc_distance([0.5, 0.0, 0.3], [0.0; 3], n, 1.0) - 0.3).abs() < 1e-12);
        assert!(
            (disc_distance([4.0, 0.0, 3.0], [0.0; 3], n, 1.0) - (9.0f64 + 9.0).sqrt()).abs()
                < 1e-12
        );
        assert!((disc_distance([0.0, 2.0, 0.0], [0.0; 3], [0.0; 3], 1.0) - 2.0).abs() < 1e-12);
    }

    /// Points over the data are as far as the nearer of their foot point and the discs; points
    /// past its edge are as far as they are from the last discs.
    #[test]
    fn over_and_past_the_edge_of_a_flat_patch() {
        let points = grid(40, 0.025);
        let normals = vec![[0.0, 0.0, 1.0]; points.len()];
        let target = Target::from_points(&points, Some(&normals), &TargetOptions::default())
            .expect("target");
        let norm = target.normalization();
        let reach = target.data_reach();
        // The 12th neighbour of a grid point is at √5 spacings (√4 = 2 for the 12th counting
        // ties: 4 at 1, 4 at √2, 4 at 2).
        let spacing = norm.length_to_normalized(0.025);
        assert!(
            reach > 1.9 * spacing && reach < 2.3 * spacing,
            "{reach} vs {spacing}"
        );
        let inside = norm.to_normalized([0.5, 0.5, 0.01]);
        let past = norm.to_normalized([0.975 + 0.2, 0.5, 0.0]);
        let off = norm.length_to_normalized(0.01);
        // A foot point as far as the disc through the data keeps its distance; one that says
        // farther (a quadric that curls away) gets the disc's; past the edge, only the discs
        // count, however near a quadric said the point was.
        let mut err2 = vec![off * off, (5.0 * off).powi(2), 0.0];
        target.to_local_surface(&[inside, inside, past], &mut err2);
        assert!((err2[0].sqrt() - off).abs() < 1e-12);
        assert!((err2[1].sqrt() - off).abs() < 1e-12);
        let expected = norm.length_to_normalized(0.2) - reach;
        assert!(
            (err2[2].sqrt() - expected).abs() < 1e-9,
            "{} vs {expected}",
            err2[2].sqrt()
        );
    }
}
