//! Subdivision surfaces for subfit: Loop, Catmull-Clark and the Stam–Loop quad/triangle schemes
//! with OpenSubdiv's boundary, crease and corner rules, expressed as sparse linear operators.
//!
//! * [`scheme`] — [`Scheme`], [`BoundaryRule`], [`Options`], the vertex rules and the
//!   storage-free [`Neighborhood`] a scheme reads (OpenSubdiv `Sdc` vocabulary).
//! * [`mask`] — refinement and limit masks (Loop 1987; Catmull & Clark 1978; Hoppe et al. 1994;
//!   Halstead et al. 1993; OpenSubdiv 3.5 tangent masks).
//! * [`crease`] — semi-sharp creases and corners: decay, fractional weights and blended masks
//!   (DeRose, Kass & Truong 1998; OpenSubdiv 3.5 `Sdc::Crease`).
//! * [`stencil`] — [`StencilMatrix`], CSR rows of weights over control points.
//! * [`topology`] — the edge and vertex-ring adjacency the rules need.
//! * [`mod@refine`] — one level of uniform refinement as a matrix, with a documented child order.
//! * `child` (internal) — the adjacency of a refined mesh read off its parent's.
//! * `mixed` (internal) — quad/triangle limit masks from the local subdivision matrix's
//!   eigenvectors.
//! * `regular` (internal) — tabulated limit rows of regular Catmull-Clark neighbourhoods.
//! * [`limit`] — limit position and tangent stencils at every vertex.
//! * `semi_limit` (internal) — limit rows where semi-sharpness is left, by local refinement.
//! * [`sample`] — the sampling operator `C = L_l · M_l ⋯ M_1` (DESIGN §3.1).
//!
//! Topology never owns positions: functions take a [`subfit_mesh::Polygons`] face list, a vertex
//! count and [`subfit_mesh::Tags`], and return matrices to apply to `#V by 3` positions.
//! Everything is checked against OpenSubdiv's limit values (`tests/golden.rs`).

pub mod crease;
pub mod error;
pub mod limit;
pub mod mask;
pub mod refine;
pub mod sample;
pub mod scheme;
pub mod stencil;
pub mod topology;

mod child;
mod face_points;
mod limit_row;
mod mask_types;
mod mixed;
mod regular;
mod semi_limit;

pub use error::SubdivError;
pub use limit::{limit_stencils, LimitStencils};
pub use mask::{EdgeMask, FaceWeights, Mask};
pub use refine::{refine, Refinement};
pub use sample::{normals_from_tangents, sampling_operator, LimitSamples, SamplingOperator};
pub use scheme::{
    BoundaryRule, EdgeNeighborhood, FaceKinds, Neighborhood, Options, Scheme, TriangleRule,
    VertexRule,
};
pub use stencil::StencilMatrix;
pub use topology::Topology;

pub mod eval;
mod local;
pub mod patch;

pub use eval::{
    area_weights, random_samples, EvalError, EvalKind, EvalWeights, Evaluator, SurfaceParam,
    SurfacePoint, DEFAULT_CACHE_BYTES,
};
pub mod closest;
pub use closest::{ClosestOptions, ClosestPoint, ClosestPointFinder};
