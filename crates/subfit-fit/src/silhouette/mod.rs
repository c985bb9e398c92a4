//! A CPU soft silhouette rasterizer with an analytic gradient: the image loss of Xie et al.
//! 2023 §4.2 (eq. 6), rendered by the Soft Rasterizer's silhouette rule (Liu et al. 2019,
//! "Soft Rasterizer: A Differentiable Renderer for Image-based 3D Reasoning", §3.2–3.3; the
//! soft silhouette shader of PyTorch3D, `sigmoid_alpha_blend`).
//!
//! **What it computes.** Each triangle `f`, projected into the image, covers the pixel centre
//! `p` with the probability
//!
//! ```text
//! D_f(p) = sigmoid(δ · d²(p, f) / σ),   δ = +1 inside the projected triangle, −1 outside,
//! ```
//!
//! `d` the distance from `p` to the triangle's boundary, in pixels, and `σ` in pixel²
//! ([`SoftOptions::sigma`]). The pixel's value is the probability that some triangle covers it,
//!
//! ```text
//! I(p) = 1 − Π_f (1 − D_f(p)),
//! ```
//!
//! and the loss against target images `T` over the views `k` is eq. 6 of Xie et al.,
//! `L = Σ_k Σ_p (I_k(p) − T_k(p))² / N`, `N` the number of pixels of all views. There is no
//! depth test: a silhouette is a union, so back faces count like front faces and the triangles'
//! orientation is irrelevant. A target given as points ([`render_points`]) splats each point as
//! a ball of a given radius — a disc in the image, `d` the distance to its rim — under the same
//! rule.
//!
//! **Gradient.** With `z_f = δ d²/σ`, `∂I/∂z_f = D_f (1 − D_f) Π_{g≠f}(1 − D_g) = D_f · Q`,
//! `Q = Π_g (1 − D_g) = 1 − I`: no division, so a saturated factor (`D = 1` in floating point)
//! needs no special case — it makes `Q = 0` and the pixel's gradient vanishes, as it should.
//! `d²` is the squared distance to the nearest point `a + t(b − a)` of the nearest edge
//! `(a, b)`, whose derivative w.r.t. the edge's ends is `−2r(1 − t)`, `−2rt` with `r` the offset
//! from that point to `p`. `z` is C¹ across the triangle's edges (`d² = 0` there); it has kinks
//! only on the triangle's inner medial axis, where the nearest edge changes (a null set).
//!
//! **Cutoff.** A triangle is ignored at pixels farther than `√(σ·ln((1 − ε)/ε))` outside it,
//! where `D < ε` ([`SoftOptions::epsilon`], 1e-6: 3.7 pixels at `σ = 1`); the factor kept is
//! `min(1, (1 − D)/(1 − ε))`, so the image, the loss and the gradient stay continuous when a
//! triangle crosses the cutoff (a deviation of at most `ε` from the untruncated rule).
//! Triangles are binned into 16 × 16-pixel tiles by their projected bounding boxes grown by the
//! cutoff; each tile visits, triangle by triangle, only the pixels of the grown box, and all
//! tiles of all views run in parallel (rayon).
//!
//! **Orthographic cameras.** [`Camera`] is orthographic: projection is affine with a constant
//! Jacobian (`∂x/∂P = right / h`, `h` the pixel size), so the gradient of a projected corner is
//! carried back to the vertex by one 2 × 3 matrix shared by the whole view, and the projected
//! area of a shape is its true cross-section, independent of its distance to the camera (a
//! silhouette's area can be checked against `π r²`). A perspective camera would add a per-vertex
//! Jacobian and depth-dependent foreshortening for no benefit when the views only constrain the
//! outline of a shape seen from all around. [`cameras_around`] places `k` views evenly over the
//! directions (a Fibonacci spiral on the half sphere: orthographic silhouettes from `d` and
//! `−d` are mirror images).
//!
//! **Choosing σ and the resolution.** The soft edge is a ramp `D = sigmoid(±d²/σ)` of width
//! about `4√σ` pixels (`D` from 0.98 to 0.02 over `d ∈ [−2√σ, 2√σ]`). With `σ = 1` px² (the
//! default; PyTorch3D's `σ = 1e-4` in NDC units is `σ·R²/4 = 1.6` px² at `R = 256`) an edge's
//! motion by a fraction of a pixel changes several pixels smoothly, so the loss has no visible
//! aliasing steps; `σ < 0.3` px² makes the loss piecewise flat between pixel centres. A larger
//! `σ` widens the basin (an edge is felt `√(13.8σ)` pixels away) and blurs detail. The
//! resolution sets what can be resolved: 128² per view is a good default for 8 views of a shape
//! spanning the image (features down to ~1/60 of its size), 64² for a coarse first stage, 256²
//! when thin parts matter. Note that with triangles much smaller than a pixel the silhouette of
//! a closed mesh is slightly wider than the hard one (each rim edge is shared by a front and a
//! back triangle whose tails add outside the rim): the loss compares like with like, so this
//! cancels between prediction and a mesh target, but not against a point target.
//!
//! **Cost.** Per view: projecting O(#V), binning O(#F), then O(Σ_f area of the grown box) pixel
//! visits, each a point–triangle distance and, within the cutoff, one `exp` (twice with the
//! gradient); the gradient is scattered to the vertices in O(#F). Memory O(#F) per view.
//!
//! ```
//! use subfit_fit::silhouette::{cameras_around, Silhouette, SoftOptions};
//!
//! // A unit octahedron as target, a slightly larger one as prediction.
//! let positions = vec![
//!     [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0],
//!     [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0],
//! ];
//! let triangles = vec![
//!     [0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
//!     [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5],
//! ];
//! let cameras = cameras_around([0.0; 3], 1.5, 4, 64);
//! let silhouette =
//!     Silhouette::from_mesh(cameras, &positions, &triangles, SoftOptions::default());
//! assert!(silhouette.loss(&positions, &triangles) < 1e-12);
//! let grown: Vec<[f64; 3]> = positions.iter().map(|p| p.map(|c| 1.1 * c)).collect();
//! let (loss, gradient) = silhouette.loss_and_gradient(&grown, &triangles);
//! assert!(loss > 0.0);
//! // The gradient pulls the vertices back in.
//! assert!(gradient[0][0] > 0.0);
//! ```

mod camera;
mod raster;

use rayon::prelude::*;

pub use camera::{cameras_around, Camera};

use raster::Soft;

/// Parameters of the soft coverage `D = sigmoid(±d²/σ)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftOptions {
    /// The blur `σ`, pixel² (SoftRas's σ with distances measured in pixels; PyTorch3D's NDC
    /// `σ_ndc` is `σ_ndc · R²/4` here for an `R`-pixel image). Default 1.0: the edge ramp spans
    /// about 4 pixels. Must be positive.
    pub sigma: f64,
    /// Coverage below which a primitive is ignored (dimensionless). Default 1e-6: a primitive
    /// reaches `√(13.8 σ)` pixels beyond its edges. Must lie in (0, 0.5).
    pub epsilon: f64,
}

impl Default for SoftOptions {
    fn default() -> Self {
        Self {
            sigma: 1.0,
            epsilon: 1e-6,
        }
    }
}

impl SoftOptions {
    /// These options with `sigma` (pixel²).
    pub fn with_sigma(mut self, sigma: f64) -> Self {
        self.sigma = sigma;
        self
    }

    /// These options with `epsilon`.
    pub fn with_epsilon(mut self, epsilon: f64) -> Self {
        self.epsilon = epsilon;
        self
    }
}

/// A square grey-level image, row-major: pixel `(i, j)` (column `i`, row `j`) is
/// `pixels[j·resolution + i]`, values in `[0, 1]` (see [`Camera`] for the pixel geometry).
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Pixels along each side.
    pub resolution: usize,
    /// `resolution²` values.
    pub pixels: Vec<f64>,
}

impl Image {
    /// The sum of the pixel values: the soft silhouette's area in pixels (multiply by
    /// [`Camera::pixel_area`] for world units²).
    pub fn coverage(&self) -> f64 {
        self.pixels.iter().sum()
    }
}

/// The soft silhouette of a triangle mesh seen by `camera`.
///
/// `positions` is `#V by 3` (world units), `triangles` `#F by 3` indices into it (any
/// orientation). Cost: see the module documentation; the tiles run in parallel. Panics if a
/// triangle indexes past `positions`, or on invalid `opts`.
#[track_caller]
pub fn render_mesh(
    camera: &Camera,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    opts: &SoftOptions,
) -> Image {
    let soft = Soft::new(opts);
    let view = raster::mesh_view(camera, positions, triangles, &soft);
    raster::render(std::slice::from_ref(&view), &soft)
        .pop()
        .expect("one view")
}

/// The soft silhouette of a point set seen by `camera`: each point a ball of `radius` world
/// units (a disc in the image), combined by the same `1 − Π(1 − D)` rule.
///
/// The balls round the outline outwards: the rim points' discs reach about `radius` beyond the
/// true outline, so choose `radius` as small as keeps the inside free of holes — about the
/// point spacing (the mean distance between neighbours) when `σ` is about a pixel and the
/// spacing at most a couple of pixels. Panics on invalid `opts` or a negative `radius`.
/// Cost: O(#points · (2·radius/h + 7.4√σ)²) pixel visits (`h` the pixel size).
#[track_caller]
pub fn render_points(
    camera: &Camera,
    points: &[[f64; 3]],
    radius: f64,
    opts: &SoftOptions,
) -> Image {
    render_points_views(std::slice::from_ref(camera), points, radius, opts)
        .pop()
        .expect("one view")
}

#[track_caller]
fn render_points_views(
    cameras: &[Camera],
    points: &[[f64; 3]],
    radius: f64,
    opts: &SoftOptions,
) -> Vec<Image> {
    assert!(
        radius >= 0.0 && radius.is_finite(),
        "point radius must be non-negative, got {radius}"
    );
    let soft = Soft::new(opts);
    let views: Vec<_> = cameras
        .par_iter()
        .map(|camera| raster::points_view(camera, points, radius, &soft))
        .collect();
    raster::render(&views, &soft)
}

/// The silhouette loss of Xie et al. 2023 eq. 6 against fixed target images: cameras, soft
/// options and one target image per camera, ready to evaluate a predicted mesh.
#[derive(Clone, Debug)]
pub struct Silhouette {
    cameras: Vec<Camera>,
    options: SoftOptions,
    targets: Vec<Image>,
}

impl Silhouette {
    /// Targets rendered from a triangle mesh (`#V by 3` positions, `#F by 3` triangles).
    #[track_caller]
    pub fn from_mesh(
        cameras: Vec<Camera>,
        positions: &[[f64; 3]],
        triangles: &[[u32; 3]],
        options: SoftOptions,
    ) -> Self {
        let soft = Soft::new(&options);
        let views: Vec<_> = cameras
            .par_iter()
            .map(|camera| raster::mesh_view(camera, positions, triangles, &soft))
            .collect();
        let targets = raster::render(&views, &soft);
        Self {
            cameras,
            options,
            targets,
        }
    }

    /// Targets rendered from points, each a ball of `radius` world units (see
    /// [`render_points`] for the choice of `radius`).
    #[track_caller]
    pub fn from_points(
        cameras: Vec<Camera>,
        points: &[[f64; 3]],
        radius: f64,
        options: SoftOptions,
    ) -> Self {
        let targets = render_points_views(&cameras, points, radius, &options);
        Self {
            cameras,
            options,
            targets,
        }
    }

    /// Targets given as images, one per camera with the camera's resolution. Panics otherwise.
    #[track_caller]
    pub fn from_images(cameras: Vec<Camera>, targets: Vec<Image>, options: SoftOptions) -> Self {
        assert_eq!(cameras.len(), targets.len(), "one target image per camera");
        for (k, (c, t)) in cameras.iter().zip(&targets).enumerate() {
            assert!(
                t.resolution == c.resolution && t.pixels.len() == c.resolution * c.resolution,
                "target {k} is not a {0}×{0} image",
                c.resolution
            );
        }
        Soft::new(&options);
        Self {
            cameras,
            options,
            targets,
        }
    }

    /// The cameras, one per view.
    pub fn cameras(&self) -> &[Camera] {
        &self.cameras
    }

    /// The soft options.
    pub fn options(&self) -> &SoftOptions {
        &self.options
    }

    /// The target images, one per camera.
    pub fn targets(&self) -> &[Image] {
        &self.targets
    }

    /// `N`, the number of pixels over all views.
    pub fn pixel_count(&self) -> usize {
        self.cameras
            .iter()
            .map(|c| c.resolution * c.resolution)
            .sum()
    }

    /// The predicted images of a mesh, one per camera.
    #[track_caller]
    pub fn images(&self, positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<Image> {
        let soft = Soft::new(&self.options);
        raster::render(&self.views(positions, triangles, &soft), &soft)
    }

    /// `L = Σ_views Σ_pixels (I − T)² / N` for the mesh (`#V by 3` positions, `#F by 3`
    /// triangles). Deterministic (independent of the thread count).
    #[track_caller]
    pub fn loss(&self, positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> f64 {
        let soft = Soft::new(&self.options);
        let views = self.views(positions, triangles, &soft);
        let tiles = raster::loss_tiles(&views, &self.targets, &soft, None);
        tiles.iter().map(|t| t.sum_sq).sum::<f64>() / self.pixel_count() as f64
    }

    /// The loss and its exact gradient w.r.t. every position (`#V by 3`; zero for vertices no
    /// triangle uses or whose triangles reach no pixel). Deterministic.
    #[track_caller]
    pub fn loss_and_gradient(
        &self,
        positions: &[[f64; 3]],
        triangles: &[[u32; 3]],
    ) -> (f64, Vec<[f64; 3]>) {
        let soft = Soft::new(&self.options);
        let views = self.views(positions, triangles, &soft);
        let n = self.pixel_count() as f64;
        let tiles = raster::loss_tiles(&views, &self.targets, &soft, Some(2.0 / n));
        let mut gradient = vec![[0.0; 3]; positions.len()];
        let mut sum_sq = 0.0;
        for tile in &tiles {
            sum_sq += tile.sum_sq;
            // Pixel coordinates move by right/h, up/h per world unit.
            let camera = &self.cameras[tile.view];
            let inv_h = 1.0 / camera.pixel_size();
            for (f, g) in &tile.grads {
                for (corner, &v) in triangles[*f as usize].iter().enumerate() {
                    let (gx, gy) = (g[2 * corner] * inv_h, g[2 * corner + 1] * inv_h);
                    let out = &mut gradient[v as usize];
                    for ((o, r), u) in out.iter_mut().zip(camera.right).zip(camera.up) {
                        *o += gx * r + gy * u;
                    }
                }
            }
        }
        (sum_sq / n, gradient)
    }

    fn views(
        &self,
        positions: &[[f64; 3]],
        triangles: &[[u32; 3]],
        soft: &Soft,
    ) -> Vec<raster::View<raster::TriPx>> {
        self.cameras
            .par_iter()
            .map(|camera| raster::mesh_view(camera, positions, triangles, soft))
            .collect()
    }
}
