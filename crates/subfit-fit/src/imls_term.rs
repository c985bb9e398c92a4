//! The IMLS fit energy of Xie et al. 2023 (§4.1, eq. 2–4) as a [`DataTerm`]: each limit sample
//! `x = S_k` is measured by the implicit moving-least-squares function of the target's oriented
//! points (Öztireli et al.; [`subfit_target::imls_value`]),
//!
//! ```text
//! f(x) = Σ_i n_iᵀ(x − p_i) φ_i(x) / Σ_i φ_i(x),    φ(r) = (1 − r²/h²)⁴ for r < h, 0 beyond,
//! ```
//!
//! and the true squared error is `e² = f(x)²` (eq. 4 summed over the samples; the fitter takes
//! the mean). Where Xie et al. minimize eq. 1 with a generic solver (Ceres, gradient descent,
//! §4.1 "Optimization"), the fitter here keeps its sparse Gauss-Newton/LM machinery: with the
//! exact gradient `∇f` the Gauss-Newton model of `f²` around `x` is
//!
//! ```text
//! f(x + Δ)² ≈ (f + ∇fᵀΔ)² = f² + 2 f ∇fᵀΔ + Δᵀ (∇f ∇fᵀ) Δ,
//! ```
//!
//! i.e. `Q = ∇f ∇fᵀ` and `r = f ∇f` (the model's gradient `2r = 2 f ∇f` is the true one). In the
//! trait's form `r = Q (x − V)` this is the foot point `V = x − f ∇f / ‖∇f‖²` — the Newton step
//! onto the zero set, so `(x − V)ᵀ Q (x − V) = f²`: the model is exact in value and gradient at
//! `x`, like TD's (`Q = N Nᵀ`) with the IMLS gradient for the normal. Like TD, `Q` is rank one:
//! a sample may slide along the surface at no cost, and only the smoothing, ARAP and the LM
//! damping hold the tangential motion.
//!
//! **Tangential term.** [`FitOptions::imls_tangential`] `= β` adds `β (‖∇f‖² I − ∇f ∇fᵀ)` to
//! `Q`, leaving `r` (so the gradient) alone: a constant stand-in for SD's `[α]₊ T Tᵀ` curvature
//! terms, which damps tangential drift. Measured on the 14-vertex ellipsoid cage of Cheng 2007
//! Example 10 (12k points, λ = 0, level 3, LM; `tests/imls.rs`), IMLS `E_rms` per iteration:
//! β = 0 reaches 0.0059 at iteration 2 and 0.00144 at 3 (the floor, 0.00140, is the IMLS zero
//! set's own deviation); β = 0.01 descends faster at first (0.0154, 0.0024, 0.0017 at 3) but
//! crawls to the floor (0.00141 at 10); β = 0.1 is still above 0.003 after 10. The term adds
//! stiffness, not information, so the default is 0.
//!
//! **Support radius.** `h` comes from [`FitOptions::imls_radius`], else
//! [`ImlsTerm::auto_radius`]: half the target's point spacing (the median distance to the 16th
//! nearest neighbour, so about 4 points inside the kernel, 2 nearest-neighbour spacings) and at
//! least 4 × its noise level (on a noisy scan the kernel must average the noise out). Xie et al.
//! set `h₀` by hand (0.0005 for the bunny and Lucy, 0.05 for the noisy koala, §5.1). Measured on
//! the bunny's points (spacing 0.0188, `subfit fit --as-points --method imls`, fixed control
//! points), two-sided E_rms by `h`: at 4,667 points 0.005 → 1.31e-3, 0.008 → 9.3e-4, 0.012 →
//! 1.12e-3, 0.02 → 1.48e-3, 0.043 → 2.31e-3 (a wide kernel rounds the ears and the surface fits
//! the rounded shape); at 314 points 0.008 → 3.14e-3, 0.02 → 3.69e-3, 0.043 → 3.49e-3 (too few
//! control points for `h` to matter much).
//!
//! **Samples.** Xie et al. evaluate eq. 4 at the control mesh's vertices pushed to the limit
//! (§4.1; Fig. 9 shows one more level as slightly better and three times slower); here the
//! samples are the fitter's, the limit points of the level-`l` vertices
//! ([`FitOptions::sample_level`], default 3), as for the foot-point terms. Measured with
//! `subfit fit stanford-bunny.obj --as-points --control-points N --max-control-points N`
//! (2 shared cores, wall clock, whole pipeline; two-sided E_rms by the same foot-point
//! measure): N = 314, `--method imls` 6.2 s, 3.17e-3; SDM 6.5 s, 3.36e-3. N = 4,667: IMLS
//! 33.7 s, 1.02e-3; SDM 52.3 s, 9.5e-4 (Xie et al. Fig. 13: 4.06 s and 42.74 s on a GPU, no
//! error given).
//!
//! **Empty neighbourhoods.** A sample farther than `h` from every data point (a cage far from
//! the data) grows the radius: `2h`, then `4h`; beyond that `f` is the signed distance to the
//! tangent plane of the nearest point (value `n_jᵀ(x − p_j)`, gradient `n_j`), the fallback of
//! [`subfit_target::imls_value`]. Either way the sample keeps a defined value and gradient.

use rayon::prelude::*;
use subfit_target::{imls_value, Target};

use crate::options::FitOptions;
use crate::term::{DataTerm, Mat3};

/// Radius doublings tried before the nearest-plane fallback.
const GROWTH_STEPS: usize = 2;

/// The IMLS state of one sample: value and gradient of `f` at it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ImlsSample {
    /// `f(x)` (normalized units; positive on the side the normals point to).
    pub value: f64,
    /// `∇f(x)` (dimensionless; unit length on a plane of consistent normals).
    pub gradient: [f64; 3],
    /// The support radius that gave a non-empty neighbourhood (normalized units; the last one
    /// tried when [`Self::fallback`]).
    pub radius: f64,
    /// Whether no data point lay within the grown radius, so `f` is the nearest point's plane.
    pub fallback: bool,
}

/// Xie et al.'s IMLS distance to the target's oriented points as the fitter's data term (see
/// the module docs). Stateless between calls: every projection is fresh.
#[derive(Clone, Debug)]
pub struct ImlsTerm<'t> {
    target: &'t Target,
    radius: f64,
    tangential: f64,
    diagonal: f64,
}

impl<'t> ImlsTerm<'t> {
    /// The term on `target` with support radius `radius` (normalized units; `None`:
    /// [`Self::auto_radius`]) and no tangential term.
    ///
    /// # Panics
    /// If `radius` is given and is not finite and `> 0`.
    #[track_caller]
    pub fn new(target: &'t Target, radius: Option<f64>) -> Self {
        let radius = radius.unwrap_or_else(|| Self::auto_radius(target));
        assert!(
            radius.is_finite() && radius > 0.0,
            "IMLS radius must be finite and > 0"
        );
        let diagonal = subfit_mesh::bounding_box(target.points())
            .map(|(lo, hi)| (0..3).map(|a| (hi[a] - lo[a]).powi(2)).sum::<f64>().sqrt())
            .filter(|d| d.is_finite() && *d > 0.0)
            .unwrap_or(1.0);
        Self {
            target,
            radius,
            tangential: 0.0,
            diagonal,
        }
    }

    /// The term `options` configure ([`FitOptions::imls_radius`],
    /// [`FitOptions::imls_tangential`]; validated by the fitter, a bad value panics here).
    pub fn from_options(target: &'t Target, options: &FitOptions) -> Self {
        Self::new(target, options.imls_radius).with_tangential(options.imls_tangential)
    }

    /// Sets the tangential weight `β ≥ 0` (see the module docs; negative or NaN is taken as 0).
    pub fn with_tangential(mut self, beta: f64) -> Self {
        self.tangential = if beta.is_finite() && beta > 0.0 {
            beta
        } else {
            0.0
        };
        self
    }

    /// The automatic support radius of `target` (normalized units): half the point spacing
    /// ([`subfit_target::TargetStats::point_spacing`]), at least four noise levels
    /// ([`subfit_target::TargetStats::noise_level`]); [`Target::imls_radius`] when both are
    /// unknown (0). Cost: O(1).
    pub fn auto_radius(target: &Target) -> f64 {
        let s = target.stats();
        let h = (0.5 * s.point_spacing).max(4.0 * s.noise_level);
        if h.is_finite() && h > 0.0 {
            h
        } else {
            target.imls_radius().max(f64::MIN_POSITIVE)
        }
    }

    /// The support radius `h` in use (normalized units).
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The tangential weight `β`.
    pub fn tangential(&self) -> f64 {
        self.tangential
    }

    /// The target.
    pub fn target(&self) -> &'t Target {
        self.target
    }

    /// `f` and `∇f` at `x` (normalized coordinates), growing the radius over empty
    /// neighbourhoods (module docs). Cost: one radius query per radius tried, plus one nearest
    /// query on fallback.
    pub fn evaluate(&self, x: [f64; 3]) -> ImlsSample {
        let t = self.target;
        let mut h = self.radius;
        for step in 0..=GROWTH_STEPS {
            let v = imls_value(t.index(), t.points(), t.normals(), x, h);
            if !v.fallback || step == GROWTH_STEPS {
                return ImlsSample {
                    value: v.value,
                    gradient: v.gradient,
                    radius: h,
                    fallback: v.fallback,
                };
            }
            h *= 2.0;
        }
        unreachable!("the last growth step returns")
    }
}

impl DataTerm for ImlsTerm<'_> {
    type Sample = ImlsSample;

    fn isotropic(&self) -> bool {
        false
    }

    fn project(&self, _rows: Option<&[u32]>, xs: &[[f64; 3]]) -> Vec<ImlsSample> {
        self.project_fresh(xs)
    }

    fn project_fresh(&self, xs: &[[f64; 3]]) -> Vec<ImlsSample> {
        xs.par_iter().map(|&x| self.evaluate(x)).collect()
    }

    /// `f(x)²`.
    #[inline]
    fn squared_error(&self, s: &ImlsSample, _x: [f64; 3]) -> f64 {
        s.value * s.value
    }

    /// `Q = ∇f ∇fᵀ + β (‖∇f‖² I − ∇f ∇fᵀ)`, `r = f ∇f`.
    #[inline]
    fn model(&self, s: &ImlsSample, _x: [f64; 3]) -> (Mat3, [f64; 3]) {
        let g = s.gradient;
        let g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        let b = self.tangential;
        let q = std::array::from_fn(|r| {
            std::array::from_fn(|c| {
                let ggt = g[r] * g[c];
                let eye = if r == c { g2 } else { 0.0 };
                ggt + b * (eye - ggt)
            })
        });
        (q, g.map(|gi| s.value * gi))
    }

    fn measured_errors(&self, xs: &[[f64; 3]], err2: &mut [f64]) {
        self.target.to_local_surface(xs, err2);
    }

    fn bbox_diagonal(&self) -> f64 {
        self.diagonal
    }
}
