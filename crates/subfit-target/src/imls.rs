//! The IMLS distance of Xie et al. 2023, eq. 2–3 (after Öztireli et al.):
//! `f(x) = Σ_i n_iᵀ(x − p_i) φ_i(x) / Σ_i φ_i(x)`, `φ(r) = (1 − r²/h²)⁴` for `r < h`, 0 beyond,
//! over the points within the support radius `h` (kd-tree radius search), with its exact
//! gradient.
//!
//! When no point lies within `h` (or all weights vanish), `f` falls back to the signed distance to
//! the tangent plane of the nearest point, `f(x) = n_jᵀ(x − p_j)`, gradient `n_j`, so it is
//! defined (and continuous in value up to the kernel's decay) everywhere.

use rayon::prelude::*;

use crate::neighbors::PointIndex;
use crate::target::Target;
use subfit_mesh::vec3::{dot, sub};

/// Value and gradient of the IMLS function at one point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ImlsValue {
    /// `f(x)` (normalized units; positive on the side the normals point to).
    pub value: f64,
    /// `∇f(x)`.
    pub gradient: [f64; 3],
    /// Number of points inside the support radius.
    pub neighbors: usize,
    /// Whether the nearest-point fallback was used.
    pub fallback: bool,
}

impl Target {
    /// IMLS value and gradient at `x` (normalized coordinates) with the target's support radius
    /// [`Target::imls_radius`]. Cost: a radius query plus O(#neighbours).
    pub fn imls(&self, x: [f64; 3]) -> ImlsValue {
        self.imls_with_radius(x, self.imls_radius())
    }

    /// IMLS value and gradient with an explicit support radius `h > 0` (normalized units).
    pub fn imls_with_radius(&self, x: [f64; 3], h: f64) -> ImlsValue {
        imls_value(self.index(), self.points(), self.normals(), x, h)
    }

    /// The IMLS value at `x` whose kernel reaches the data: [`Self::imls`] where some point lies
    /// within the support radius `h`, else the kernel grown to `d + h`, `d` the distance to the
    /// nearest point, so the points of a patch around the nearest one vote on the side. The
    /// nearest point's tangent plane alone (the fallback of [`Self::imls`]) takes the side of a
    /// single point's normal: one wrong normal, or a point of a thin part seen edge-on, puts a
    /// far point inside (the contour of a point cloud then grows pockets, bridges and stray
    /// components in its band).
    ///
    /// Where the nearest point is flagged in `rim` (`#P` flags, or empty for none: the cloud's
    /// boundary points, [`crate::cloud_boundary_points`]) the tangent-plane fallback is kept:
    /// beyond the data's edge the grown kernel would interpolate across a hole of the scan and
    /// cap it. Cost: one nearest query and one more radius query where the fallback is used.
    pub fn imls_reaching(&self, x: [f64; 3], rim: &[bool]) -> f64 {
        let v = self.imls(x);
        if !v.fallback {
            return v.value;
        }
        let nearest = self.index().nearest(&x);
        if rim.get(nearest.index as usize).copied().unwrap_or(false) {
            return v.value;
        }
        self.imls_with_radius(x, nearest.distance + self.imls_radius())
            .value
    }

    /// [`Self::imls_reaching`] for many points, in parallel; `#Q` values in order.
    pub fn imls_reaching_batch(&self, xs: &[[f64; 3]], rim: &[bool]) -> Vec<f64> {
        xs.par_iter().map(|&x| self.imls_reaching(x, rim)).collect()
    }

    /// [`Self::imls`] for many points, in parallel; `#Q` results in order.
    pub fn imls_batch(&self, xs: &[[f64; 3]]) -> Vec<ImlsValue> {
        xs.par_iter().map(|&x| self.imls(x)).collect()
    }
}

/// The IMLS value and gradient at `x` over `points` (`#P by 3`) with unit `normals` (`#P by 3`)
/// indexed by `index` (built over `points`), support radius `h > 0` (units of the points): the
/// kernel of [`Target::imls_with_radius`], for callers with their own points and normals (the
/// Python package's autograd layer). Cost: a radius query plus O(#neighbours), no allocation
/// (the sums are taken while the tree is visited).
///
/// Not checked: that `index` was built over `points` and that the slices have equal lengths
/// (an index past their end panics).
pub fn imls_value(
    index: &PointIndex,
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    x: [f64; 3],
    h: f64,
) -> ImlsValue {
    let inv_h2 = 1.0 / (h * h);
    // s0 = Σφ, s1 = Σ n·(x−p) φ; g0 = Σ∇φ, g1 = Σ (n φ + n·(x−p) ∇φ).
    let (mut s0, mut s1) = (0.0, 0.0);
    let (mut g0, mut g1) = ([0.0; 3], [0.0; 3]);
    let mut neighbors = 0;
    index.for_each_within(&x, h, |i| {
        neighbors += 1;
        let i = i as usize;
        let d = sub(x, points[i]);
        let t = 1.0 - dot(d, d) * inv_h2;
        if t <= 0.0 {
            return;
        }
        let t3 = t * t * t;
        let phi = t3 * t;
        let dphi = -8.0 * inv_h2 * t3; // ∇φ = dphi · d
        let s = dot(normals[i], d);
        s0 += phi;
        s1 += s * phi;
        for k in 0..3 {
            g0[k] += dphi * d[k];
            g1[k] += normals[i][k] * phi + s * dphi * d[k];
        }
    });
    if s0 > 0.0 && s0.is_finite() {
        let value = s1 / s0;
        let gradient = [0, 1, 2].map(|k| (g1[k] - value * g0[k]) / s0);
        return ImlsValue {
            value,
            gradient,
            neighbors,
            fallback: false,
        };
    }
    let j = index.nearest(&x).index as usize;
    ImlsValue {
        value: dot(normals[j], sub(x, points[j])),
        gradient: normals[j],
        neighbors: 0,
        fallback: true,
    }
}
