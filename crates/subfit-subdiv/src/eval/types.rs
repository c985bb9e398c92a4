//! Parameters and results of an evaluation: [`SurfaceParam`] in, [`EvalWeights`] (weights over
//! control points) or [`SurfacePoint`] (values) out, and why an evaluation is refused.

use crate::error::SubdivError;
use subfit_mesh::vec3::{cross, unit};

/// A point of the parameter domain: `(face, sub, u, v)`, see the module docs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceParam {
    /// Control-mesh face.
    pub face: u32,
    /// Sub-patch: the corner of a Catmull-Clark `n`-gon (`n ≠ 4`), else 0.
    pub sub: u32,
    /// First parameter.
    pub u: f64,
    /// Second parameter.
    pub v: f64,
}

impl SurfaceParam {
    /// A parameter on face `face` (sub-patch 0).
    pub fn new(face: u32, u: f64, v: f64) -> Self {
        Self { face, sub: 0, u, v }
    }
}

/// Why an evaluation was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EvalError {
    /// The control mesh is not a valid subdivision control mesh.
    #[error(transparent)]
    Topology(#[from] SubdivError),
    /// The face index is out of range.
    #[error("face {face} out of range: the mesh has {num_faces} faces")]
    FaceOutOfRange {
        /// The face asked for.
        face: u32,
        /// Number of faces.
        num_faces: usize,
    },
    /// The sub-patch index is out of range for the face.
    #[error("sub-patch {sub} out of range for face {face} ({count} sub-patches)")]
    SubOutOfRange {
        /// The face.
        face: u32,
        /// The sub-patch asked for.
        sub: u32,
        /// Number of sub-patches of the face.
        count: usize,
    },
    /// `(u, v)` is not finite or lies outside the face's domain by more than 1e-9.
    #[error("parameter ({u}, {v}) outside the domain of face {face}")]
    OutOfDomain {
        /// The face.
        face: u32,
        /// First parameter.
        u: f64,
        /// Second parameter.
        v: f64,
    },
    /// The positions array does not have one row per control point.
    #[error("expected {expected} control points, got {got}")]
    PositionCount {
        /// Number of control points of the mesh.
        expected: usize,
        /// Rows given.
        got: usize,
    },
    /// Local refinement lost part of the neighbourhood it needed (a broken invariant, reported
    /// rather than panicking so one bad sample does not abort a batch).
    #[error("internal: incomplete neighbourhood evaluating face {face} at depth {depth}")]
    Incomplete {
        /// The face.
        face: u32,
        /// The refinement depth.
        depth: u32,
    },
}

/// What the derivative fields of an evaluation mean.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EvalKind {
    /// Inside a regular patch (possibly after local refinement): `du`, `dv` are the parametric
    /// first derivatives and the second derivatives are present.
    Patch,
    /// Exactly at an irregular vertex (extraordinary, crease end, corner, …): the position is the
    /// limit mask's; `du`, `dv` are the two limit tangents of [`Scheme::limit_masks`](crate::Scheme::limit_masks) (directions
    /// spanning the tangent plane, OpenSubdiv's scale, not parametric derivatives, which do not
    /// exist there); no second derivatives.
    Vertex,
}

/// The weights of one evaluation over control points: the position and its derivatives are
/// `Σ_i w[i] · P[indices[i]]`.
#[derive(Clone, Debug, PartialEq)]
pub struct EvalWeights {
    /// Control-point ids, ascending, unique.
    pub indices: Vec<u32>,
    /// Position weights (sum 1).
    pub position: Vec<f64>,
    /// ∂/∂u weights (sum 0); limit tangent 1 for [`EvalKind::Vertex`].
    pub du: Vec<f64>,
    /// ∂/∂v weights (sum 0); limit tangent 2 for [`EvalKind::Vertex`].
    pub dv: Vec<f64>,
    /// `[∂²/∂u², ∂²/∂u∂v, ∂²/∂v²]` weights, `None` for [`EvalKind::Vertex`].
    pub second: Option<[Vec<f64>; 3]>,
    /// What the derivative weights mean.
    pub kind: EvalKind,
    /// Number of local refinement levels used (0 for a regular control-mesh face).
    pub depth: u32,
}

/// The limit surface at one parameter: position, derivatives and unit normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// Position, in the units of the control points.
    pub position: [f64; 3],
    /// ∂S/∂u (see [`EvalKind`]).
    pub du: [f64; 3],
    /// ∂S/∂v (see [`EvalKind`]).
    pub dv: [f64; 3],
    /// `[S_uu, S_uv, S_vv]`, `None` at an irregular vertex.
    pub second: Option<[[f64; 3]; 3]>,
    /// Unit normal `normalize(du × dv)`, on the side the face winding makes the front; zero if
    /// the tangents are parallel (a degenerate control mesh).
    pub normal: [f64; 3],
    /// What the derivative fields mean.
    pub kind: EvalKind,
    /// Local refinement levels used.
    pub depth: u32,
}

impl EvalWeights {
    /// Applies the weights to control points (`#V by 3`): position, derivatives and normal.
    /// Cost O(#weights).
    ///
    /// # Panics
    /// If an index is out of range of `positions`.
    #[track_caller]
    pub fn apply(&self, positions: &[[f64; 3]]) -> SurfacePoint {
        let dot = |w: &[f64]| {
            let mut s = [0.0; 3];
            for (&i, &wi) in self.indices.iter().zip(w) {
                let p = positions[i as usize];
                s[0] += wi * p[0];
                s[1] += wi * p[1];
                s[2] += wi * p[2];
            }
            s
        };
        let (du, dv) = (dot(&self.du), dot(&self.dv));
        SurfacePoint {
            position: dot(&self.position),
            du,
            dv,
            second: self
                .second
                .as_ref()
                .map(|[a, b, c]| [dot(a), dot(b), dot(c)]),
            normal: unit(cross(du, dv)).unwrap_or([0.0; 3]),
            kind: self.kind,
            depth: self.depth,
        }
    }
}
