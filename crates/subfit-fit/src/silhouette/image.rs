//! The soft silhouette's plain data (Liu et al. 2019, "Soft Rasterizer", §3.2–3.3; see
//! [`super`]): the parameters of the soft coverage `D = sigmoid(±d²/σ)` and the grey-level
//! image it renders. Both the loss in [`super`] and the tile rasterizer in `raster` name them,
//! so they live here, below both.

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
/// `pixels[j·resolution + i]`, values in `[0, 1]` (see [`super::Camera`] for the pixel geometry).
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Pixels along each side.
    pub resolution: usize,
    /// `resolution²` values.
    pub pixels: Vec<f64>,
}

impl Image {
    /// The sum of the pixel values: the soft silhouette's area in pixels (multiply by
    /// [`super::Camera::pixel_area`] for world units²).
    pub fn coverage(&self) -> f64 {
        self.pixels.iter().sum()
    }
}
