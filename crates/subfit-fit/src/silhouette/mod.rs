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
//! Triangles are binned into 32 × 32-pixel tiles by their projected bounding boxes grown by the
//! cutoff; each tile visits, triangle by triangle, the rows of the grown box cut by a disc
//! around the triangle, 4 pixels at a time in branch-free code the compiler vectorizes; all
//! tiles of all views run in parallel (rayon), and results are summed in a fixed order, so they
//! do not depend on the number of threads.
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
//! about `4√σ` pixels (`D` from 0.98 to 0.02 over `d ∈ [−2√σ, 2√σ]`), and an edge is felt
//! `√(13.8σ)` pixels away. The default `σ = 1` px² (PyTorch3D's `σ = 1e-4` in NDC units, as used
//! by Xie et al., is `σ·R²/4 = 1.6` px² at their `R = 256`) ties the blur to the pixel: an
//! edge's sub-pixel motion changes several pixels smoothly. Measured on a 29.7k-triangle sphere
//! of radius 1 against itself, 8 views of 128², translated by `d` pixels: the loss is smooth
//! (finite differences over 0.05-pixel steps agree with the analytic derivative within 0.3% for
//! σ from 0.25 to 2) and quadratic for `d ≲ √σ`, then grows more slowly (`L·N/d²` = 838, 817,
//! 772, 708 at `d` = 0.25, 0.5, 0.75, 1 px for σ = 1; 1442 → 947 for σ = 0.25; 663 → 582 for
//! σ = 2). A larger σ widens the basin and flattens the minimum; a smaller one sharpens it. The
//! resolution sets what can be resolved: 128² per view for 8 views of a shape filling the image
//! (features down to about 1/60 of its size) is a good default, 64² for a coarse first stage,
//! 256² when thin parts matter.
//!
//! **Tessellation bias.** The rule is not independent of the tessellation. With triangles of a
//! few pixels the soft silhouette of a sphere has its true area (+0.3% for 6.4k triangles at
//! 256², σ = 1); with triangles near or below a pixel it is wider, because each rim edge is
//! shared by a front and a back triangle and many foreshortened triangles lie within a pixel of
//! the rim, whose tails add up outside it: at 128² and σ = 1 (radius 55 px), +7% area (1.9 px of
//! radius) for 29.7k triangles, +5.7% for 7.4k, +2.4% (0.7 px) for 1.5k; for 29.7k, +4.6% at
//! σ = 0.5 and +3% at 0.25. Coarse meshes lose a little inside, along interior edges that no
//! other layer covers. The loss compares like with like, so a prediction and a mesh target of
//! similar triangle size in pixels share the bias; a target much finer or coarser than the
//! prediction, or given as points ([`render_points`]), moves the fitted outline by up to a pixel
//! or two.
//!
//! **In a fitter.** Near the minimum the loss is quadratic in the outline's displacement:
//! `L ≈ κ · Σ_views ∫_outline δ² ds / N`, `δ` the normal displacement of the outline and `s` its
//! arc length, both in pixels, valid for `|δ| ≲ √σ`; `κ` ≈ 1.6, 1.4, 0.95, 0.75 for σ = 0.25,
//! 0.5, 1, 2 px² (measured as above). The gradient is first-order information only: a vertex
//! on the outline of a view, owning `ℓ` pixels of it, gets `∂L/∂δ ≈ 2κ δ ℓ / (N h)` per world
//! unit (`h` the pixel size) along the outline's normal in the image plane, and a curvature of
//! about `2κ ℓ / (N h²)` there, a usable diagonal for Gauss–Newton or Levenberg–Marquardt; the
//! vertices away from every outline get (almost) nothing. For the 29.7k-triangle sphere above,
//! shifted by ¼ pixel, the gradient's norm is 3.5e-3 and its largest component 2.7e-4.
//!
//! **Cost.** Per view: projecting O(#V), binning O(#F), then about `#F · π (√(13.8σ) + ρ)²`
//! pixel visits (`ρ` the triangles' circumradius in pixels; visits are made 4 at a time, about
//! 3 in 4 of them within the cutoff), each a point–triangle distance and an `exp`; the gradient
//! revisits the same pixels once more (reusing the exponentials) and is scattered to the
//! vertices in O(#F). Memory O(#F) per view. The time is proportional to the number of
//! triangles when they are below a few pixels (`benches/silhouette.rs`: a 29.7k-triangle
//! sphere, 8 views of 128², takes on the order of 0.1–0.2 s of one core for the loss and twice
//! that with the gradient), so the first lever is a coarser tessellation of the predicted
//! surface for this term (triangles of 2–4 pixels: 7.4k triangles cost about a third of 29.7k),
//! then σ (`σ = 0.5` visits about 40% fewer pixels) and ε (1e-4: about 25% fewer).
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
mod image;
mod raster;

use rayon::prelude::*;

pub use camera::{cameras_around, Camera};
pub use image::{Image, SoftOptions};

use raster::Soft;

/// The soft silhouette of a triangle mesh seen by `camera`.
///
/// `positions` is `#V by 3` (world units), `triangles` `#F by 3` indices into it (any
/// orientation). A triangle with a non-finite corner is left out. Cost: see the module
/// documentation; the tiles run in parallel. Panics if a triangle indexes past `positions`, or
/// on invalid `opts`.
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
/// The balls widen the outline: the rim points' discs reach about `radius` beyond the true
/// outline, so choose `radius` as small as keeps the inside free of holes — the point spacing
/// `√(area / #points)` when it is at most about a pixel. Measured on 40k points uniformly
/// random on a sphere (spacing 0.98 px at 128², σ = 1): with `radius` = spacing no pixel inside
/// drops below 0.9 and the area is 3.4% above the 29.7k-triangle mesh's (itself +7% above
/// `π r²`, see the module documentation), with half the spacing +1.5%; at 256² (spacing 2 px)
/// half the spacing leaves hundreds of holes and 0.7 × spacing still a few dozen. A mesh fitted
/// to a point target under this loss therefore ends up wider along its outlines by about
/// `radius` (0.94 px for the 29.7k-triangle sphere and `radius` = 0.98 px). Panics on invalid `opts` or a negative `radius`.
/// Cost: about `#points · π (radius/h + √(13.8σ))²` pixel visits (`h` the pixel size).
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
    /// triangles, as for [`render_mesh`]). Deterministic (independent of the thread count).
    /// Cost: one forward pass over all views (module documentation).
    #[track_caller]
    pub fn loss(&self, positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> f64 {
        let soft = Soft::new(&self.options);
        let views = self.views(positions, triangles, &soft);
        let tiles = raster::loss_tiles(&views, &self.targets, &soft, None);
        tiles.iter().map(|t| t.sum_sq).sum::<f64>() / self.pixel_count() as f64
    }

    /// The loss and its exact gradient w.r.t. every position (`#V by 3`, loss per world unit;
    /// zero for vertices no triangle uses, whose triangles reach no pixel, or that are not
    /// finite). Deterministic. Cost: about twice [`Self::loss`], plus memory for the
    /// exponentials of the tiles in flight (8 bytes per pixel visit of a tile).
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
