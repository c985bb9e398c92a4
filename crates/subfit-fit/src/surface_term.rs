//! Terms on the whole sampled surface rather than per sample: a value of all the samples at
//! once and its gradient with respect to each (e.g. the soft silhouette loss of
//! [`crate::silhouette`], Xie et al. 2023 §4.2), on a limit tessellation of its own level. The
//! fitter adds `weight · value(S)` to its objective and the gradient, pulled back through that
//! tessellation's sampling operator (`Cₛᵀ ∇_S`), to the
//! gradient of its model — a first-order term: it contributes no curvature to the normal
//! matrix, the LM damping and the data term's Gauss-Newton matrix bound the step, and the gain
//! ratio judges it on the true objective like every other term.
//!
//! **Only the normal part.** The gradient is projected on the limit normal at each sample
//! before it is pulled back ([`control_gradient`]): a functional of the shape alone changes, to
//! first order, only with the normal component of a motion (Hadamard's structure theorem;
//! Delfour & Zolésio, *Shapes and Geometries*, 2nd ed., ch. 9, §3.4), so what the tessellation
//! reports along the surface is an artefact of its triangles, and a push along the surface
//! is a slide of the cage, which the data term cannot see either. (On `subfit bench
//! sequence` the difference is below 0.005 % of the diagonal in drift: the tracking and the
//! ARAP term hold the cage; the projection is for where nothing else does.)

use std::fmt;
use std::sync::Arc;

/// A differentiable function of all the samples of the limit surface and the triangles of
/// their tessellation (the level-`l` faces of the sampling operator, fanned into triangles).
/// Positions in the target's normalized units. The fitter uses only the gradient's part along
/// the limit normals (a functional of the shape alone changes only with the normal part of a
/// motion; what the triangles report along the surface would slide the cage).
pub trait SurfaceTerm: Send + Sync {
    /// The value at `samples`.
    fn value(&self, samples: &[[f64; 3]], triangles: &[[u32; 3]]) -> f64;

    /// The value and its gradient with respect to every sample (zero for samples no triangle
    /// uses).
    fn value_and_gradient(
        &self,
        samples: &[[f64; 3]],
        triangles: &[[u32; 3]],
    ) -> (f64, Vec<[f64; 3]>);
}

/// A [`SurfaceTerm`] with its weight in the objective, as [`crate::FitOptions::surface_term`]
/// holds it. Two are equal when they share the term (the same `Arc`) and the weight.
#[derive(Clone)]
pub struct WeightedSurfaceTerm {
    /// The term.
    pub term: Arc<dyn SurfaceTerm>,
    /// Its weight `w ≥ 0`: the objective gains `w · value`.
    pub weight: f64,
    /// The refinement level of the limit tessellation the term sees (its own sampling
    /// operator, independent of [`crate::FitOptions::sample_level`]): a silhouette needs far
    /// fewer triangles than the data term needs samples.
    pub level: usize,
}

impl fmt::Debug for WeightedSurfaceTerm {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("WeightedSurfaceTerm")
            .field("weight", &self.weight)
            .field("level", &self.level)
            .finish_non_exhaustive()
    }
}

impl PartialEq for WeightedSurfaceTerm {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.term, &other.term)
            && self.weight == other.weight
            && self.level == other.level
    }
}

/// `Cₛᵀ (N ∇_S value)`: the term's gradient with respect to the samples of `op` at `control`,
/// each projected on the sample's limit normal (see the module docs), pulled back to the
/// control points (`#control points` rows).
pub(crate) fn control_gradient(
    term: &dyn SurfaceTerm,
    op: &subfit_subdiv::SamplingOperator,
    triangles: &[[u32; 3]],
    control: &[[f64; 3]],
) -> Vec<[f64; 3]> {
    let (_, grad) = term.value_and_gradient(&op.position.apply(control), triangles);
    let normals = subfit_subdiv::normals_from_tangents(
        &op.tangent1.apply(control),
        &op.tangent2.apply(control),
    );
    let mut out = vec![[0.0; 3]; control.len()];
    for (k, (gk, n)) in grad.iter().zip(&normals).enumerate() {
        let along = gk[0] * n[0] + gk[1] * n[1] + gk[2] * n[2];
        let (cols, ws) = op.position.row(k);
        for (&j, &w) in cols.iter().zip(ws) {
            for a in 0..3 {
                out[j as usize][a] += w * along * n[a];
            }
        }
    }
    out
}

/// The triangles of a polygon tessellation, each polygon fanned from its first corner.
pub fn fan_triangles(faces: &subfit_mesh::Polygons) -> Vec<[u32; 3]> {
    let mut t = Vec::with_capacity(2 * faces.len());
    for f in faces.iter() {
        for k in 1..f.len().saturating_sub(1) {
            t.push([f[0], f[k], f[k + 1]]);
        }
    }
    t
}

impl SurfaceTerm for crate::silhouette::Silhouette {
    /// The silhouette loss (mean squared pixel difference over all views).
    fn value(&self, samples: &[[f64; 3]], triangles: &[[u32; 3]]) -> f64 {
        self.loss(samples, triangles)
    }

    fn value_and_gradient(
        &self,
        samples: &[[f64; 3]],
        triangles: &[[u32; 3]],
    ) -> (f64, Vec<[f64; 3]>) {
        self.loss_and_gradient(samples, triangles)
    }
}
