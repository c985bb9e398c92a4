//! The options, report, feature lock and errors of [`simplify`](super::simplify) and
//! [`simplify_with_features`](super::simplify_with_features) (Garland & Heckbert 1997 edge
//! collapse with the link condition of Dey et al. 1999); re-exported from the parent module.

use subfit_mesh::{Cancel, Cancelled, TopologyError};

/// Options of [`simplify`](super::simplify). Lengths are in the mesh's units; the checks are scale-invariant.
#[derive(Clone, Debug, PartialEq)]
pub struct SimplifyOptions {
    /// Stop when at most this many (referenced) vertices remain. Default 1000.
    pub target_vertices: usize,
    /// Largest allowed rotation of a face normal by one collapse, in degrees. Default 75
    /// (valid `(0, 180)`; the task's "no flipped faces" is `< 90`).
    pub max_normal_rotation_deg: f64,
    /// Smallest allowed triangle quality `4√3·A / (l₁² + l₂² + l₃²)` (1 for equilateral, 0 for
    /// degenerate) of a face changed by a collapse, unless the face was already worse. Default 0.02.
    pub min_triangle_quality: f64,
    /// Weight of the boundary constraint planes relative to face planes (both are multiplied by
    /// an area: face area, or boundary edge length²). Default 100.
    pub boundary_weight: f64,
    /// Past `target_vertices`, collapses go on while their error (the RMS distance to the
    /// accumulated planes, mesh units) stays at or below this: regions the surface spans exactly
    /// with fewer vertices (the flat sides and straight rulings of a CAD part) lose them.
    /// Default 0 (stop at the target).
    pub exact_error: f64,
    /// Cancellation token, polled every 1024 candidate collapses; once cancelled,
    /// [`simplify`](super::simplify) returns [`SimplifyError::Interrupted`]. Default: a fresh token, never
    /// cancelled. ([`crate::initial_control_mesh`] uses [`crate::InitOptions::cancel`] instead.)
    pub cancel: Cancel,
}

impl Default for SimplifyOptions {
    fn default() -> Self {
        Self {
            target_vertices: 1000,
            max_normal_rotation_deg: 75.0,
            min_triangle_quality: 0.02,
            boundary_weight: 100.0,
            exact_error: 0.0,
            cancel: Cancel::default(),
        }
    }
}

/// Sharp features [`simplify_with_features`](super::simplify_with_features) keeps: vertex ids of the input mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FeatureLock {
    /// Sharp edges `[a, b]` (either order); they stay edges of the output, as creases.
    pub edges: Vec<[u32; 2]>,
    /// Corner vertices: never removed, tagged as corners.
    pub corners: Vec<u32>,
}

/// What [`simplify`](super::simplify) did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SimplifyReport {
    /// Referenced vertices of the input.
    pub vertices_before: usize,
    /// Vertices of the output.
    pub vertices_after: usize,
    /// Triangles of the input (after fan triangulation).
    pub faces_before: usize,
    /// Triangles of the output.
    pub faces_after: usize,
    /// Edge collapses performed.
    pub collapses: usize,
    /// Candidate collapses rejected by the link condition (would change the topology).
    pub rejected_link: usize,
    /// Candidates rejected because they join two boundary vertices through the interior, or
    /// would close a boundary loop.
    pub rejected_boundary: usize,
    /// Candidates rejected because a face normal would rotate too far (fold-over).
    pub rejected_flip: usize,
    /// Candidates rejected because a face would become degenerate.
    pub rejected_degenerate: usize,
    /// Largest quadric error of a performed collapse, as an RMS distance to the accumulated
    /// planes: `sqrt(pᵀQp / Σ weights)` (mesh units).
    pub max_error: f64,
    /// Whether `target_vertices` was reached; `false` means no legal collapse remained.
    pub reached_target: bool,
    /// How many times the geometric checks were relaxed because no legal collapse remained
    /// (0–2: first to 85° and 1/4 of the quality bound, then to 89° and 1/50 of it).
    pub relaxations: usize,
    /// Candidates rejected because they would remove a corner, cut a feature curve or leave it
    /// ([`simplify_with_features`](super::simplify_with_features)).
    pub rejected_feature: usize,
    /// Whether the input stopped the simplification more than a tenth above its target and the
    /// result is that of a Taubin-smoothed copy ([`crate::denoise`]): the counts above are the
    /// copy's, the output's positions are smoothed (a noisy mesh).
    pub smoothed: bool,
}

/// Why [`simplify`](super::simplify) cannot run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SimplifyError {
    /// The input has no faces (a point cloud): contour it first.
    #[error("the mesh has no faces")]
    NoFaces,
    /// A coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFinite {
        /// The vertex.
        vertex: usize,
    },
    /// The input is not a manifold, consistently oriented surface.
    #[error("the mesh is not an oriented manifold: {0}")]
    Topology(#[from] TopologyError),
    /// The cancellation token ([`SimplifyOptions::cancel`]) was cancelled.
    #[error("interrupted")]
    Interrupted,
}

impl From<Cancelled> for SimplifyError {
    fn from(_: Cancelled) -> Self {
        SimplifyError::Interrupted
    }
}
