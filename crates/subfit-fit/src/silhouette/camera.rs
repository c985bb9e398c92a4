//! Orthographic cameras for the soft silhouette: a view direction, an orthonormal image basis
//! and a square image, plus a deterministic set of views around a bounding sphere.

use subfit_mesh::vec3::{cross, dot, scale, sub};

/// Room kept around the bounding sphere by [`cameras_around`], as a fraction of its radius.
const MARGIN_FRACTION: f64 = 0.05;

/// Room kept around the bounding sphere by [`cameras_around`], in pixels: the soft edge reaches
/// `√(σ·ln(1/ε))` pixels beyond the silhouette (3.7 px at the default σ = 1 px², ε = 1e-6).
const MARGIN_PIXELS: f64 = 6.0;

/// An orthographic camera: it looks along `−direction` at `center`, and its square image of
/// `resolution × resolution` pixels covers `[−half_size, half_size]²` world units of the plane
/// through `center` spanned by `right` (image x, columns) and `up` (image y, rows).
///
/// A world point `p` lands at the pixel coordinates
/// `x = (p − center)·right / h + resolution/2`, `y = (p − center)·up / h + resolution/2`, with
/// `h = 2·half_size / resolution` the pixel size; pixel `(i, j)` (column `i`, row `j`) has its
/// centre at `(i + ½, j + ½)` and is stored at index `j·resolution + i` of an [`super::Image`].
/// The map is affine with the constant Jacobian `[right; up] / h`, which is what keeps the
/// silhouette's gradient simple (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// The point the camera looks at; it projects to the image centre.
    pub center: [f64; 3],
    /// Unit vector from `center` towards the viewer (the camera looks along its negative).
    pub direction: [f64; 3],
    /// Unit image x axis (columns), orthogonal to `direction`.
    pub right: [f64; 3],
    /// Unit image y axis (rows), `direction × right`.
    pub up: [f64; 3],
    /// Half the side of the square the image covers, world units.
    pub half_size: f64,
    /// Pixels along each side of the image.
    pub resolution: usize,
}

impl Camera {
    /// A camera looking from `direction` (any non-zero length; normalized here) at `center`,
    /// covering `2·half_size` world units with `resolution²` pixels. The image basis is fixed by
    /// `direction` alone (`right` is orthogonal to the world axis least aligned with it), so the
    /// same arguments always give the same camera.
    ///
    /// Panics if `direction` is zero or not finite, `half_size` is not positive or `resolution`
    /// is zero.
    #[track_caller]
    pub fn new(center: [f64; 3], direction: [f64; 3], half_size: f64, resolution: usize) -> Self {
        let norm = dot(direction, direction).sqrt();
        assert!(
            norm > 0.0 && norm.is_finite(),
            "camera direction must be non-zero and finite, got {direction:?}"
        );
        assert!(
            half_size > 0.0 && half_size.is_finite(),
            "camera half_size must be positive, got {half_size}"
        );
        assert!(resolution > 0, "camera resolution must be positive");
        let d = scale(direction, 1.0 / norm);
        // The world axis least aligned with d keeps the cross product well conditioned.
        let axis = (0..3)
            .min_by(|&a, &b| d[a].abs().total_cmp(&d[b].abs()))
            .expect("three axes");
        let mut hint = [0.0; 3];
        hint[axis] = 1.0;
        let r = cross(hint, d);
        let right = scale(r, 1.0 / dot(r, r).sqrt());
        let up = cross(d, right);
        Self {
            center,
            direction: d,
            right,
            up,
            half_size,
            resolution,
        }
    }

    /// Side of one pixel, world units: `2·half_size / resolution`.
    pub fn pixel_size(&self) -> f64 {
        2.0 * self.half_size / self.resolution as f64
    }

    /// Area of one pixel, world units².
    pub fn pixel_area(&self) -> f64 {
        self.pixel_size().powi(2)
    }

    /// Pixel coordinates `[x, y]` of the world point `p` (see the type documentation). Points
    /// outside the image get coordinates outside `[0, resolution)`; nothing is clipped.
    pub fn project(&self, p: [f64; 3]) -> [f64; 2] {
        let q = sub(p, self.center);
        let inv_h = 1.0 / self.pixel_size();
        let half = 0.5 * self.resolution as f64;
        [
            dot(q, self.right) * inv_h + half,
            dot(q, self.up) * inv_h + half,
        ]
    }
}

/// `k` orthographic cameras looking at the sphere `(center, radius)` from directions spread
/// evenly and deterministically over a hemisphere, each with a `resolution²` image covering
/// the sphere's disc with a margin (5% of the radius plus 6 pixels, room for the soft edge).
///
/// The directions are a Fibonacci (golden-angle) spiral on the half sphere `z > 0`: under an
/// orthographic projection the silhouettes seen from `d` and `−d` are mirror images of each
/// other, so a spiral over the whole sphere would spend half its views repeating the other
/// half; over the half sphere the `k` directions are `k` distinct lines of sight spread evenly
/// (the first looks nearly down the z axis, the last lies close to the equator).
///
/// Panics if `k` is zero, `radius` is not positive, or `resolution ≤ 2·6` (no room left for
/// the margin). Cost: O(k).
#[track_caller]
pub fn cameras_around(center: [f64; 3], radius: f64, k: usize, resolution: usize) -> Vec<Camera> {
    assert!(k > 0, "cameras_around needs at least one view");
    assert!(
        radius > 0.0 && radius.is_finite(),
        "cameras_around needs a positive radius, got {radius}"
    );
    assert!(
        resolution as f64 > 2.0 * MARGIN_PIXELS,
        "cameras_around needs a resolution above {}, got {resolution}",
        2.0 * MARGIN_PIXELS
    );
    // half_size = (1 + m)·radius + MARGIN_PIXELS·h with h = 2·half_size/resolution.
    let half_size =
        (1.0 + MARGIN_FRACTION) * radius / (1.0 - 2.0 * MARGIN_PIXELS / resolution as f64);
    let golden_angle = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..k)
        .map(|i| {
            let z = 1.0 - (i as f64 + 0.5) / k as f64;
            let rho = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden_angle * i as f64;
            let direction = [rho * phi.cos(), rho * phi.sin(), z];
            Camera::new(center, direction, half_size, resolution)
        })
        .collect()
}
