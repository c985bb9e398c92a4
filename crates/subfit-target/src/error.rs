//! Typed errors of target construction (bad input or unusable options).

/// Why a [`crate::Target`] could not be built.
///
/// Every variant names the offending element by its index in the input (before duplicates are
/// merged), so a caller can point at it in the source file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TargetError {
    /// A point has a NaN or infinite coordinate.
    #[error("point {index} has a non-finite coordinate {coordinates:?}")]
    NonFinitePoint {
        /// Index of the point in the input.
        index: usize,
        /// Its coordinates as given.
        coordinates: [f64; 3],
    },
    /// An input normal has a NaN or infinite component.
    #[error("normal {index} has a non-finite component {components:?}")]
    NonFiniteNormal {
        /// Index of the normal (= its point) in the input.
        index: usize,
        /// Its components as given.
        components: [f64; 3],
    },
    /// The normals array does not have one row per point.
    #[error("{normals} normals given for {points} points")]
    NormalCountMismatch {
        /// Number of points.
        points: usize,
        /// Number of normals.
        normals: usize,
    },
    /// Fewer input points than the estimators need.
    #[error("{found} points given, at least {required} are needed")]
    TooFewPoints {
        /// Number of points given.
        found: usize,
        /// Minimum number of points ([`crate::MIN_POINTS`]).
        required: usize,
    },
    /// Fewer distinct points than the estimators need once exact duplicates are merged
    /// (this includes input made of one point repeated).
    #[error("{distinct} distinct points among {input} ({merged} exact duplicates merged), at least {required} are needed")]
    TooFewDistinctPoints {
        /// Distinct points left after merging.
        distinct: usize,
        /// Points given.
        input: usize,
        /// Points merged into an earlier identical point.
        merged: usize,
        /// Minimum number of points ([`crate::MIN_POINTS`]).
        required: usize,
    },
    /// All points lie (up to rounding) on one straight line: there is no surface to fit.
    #[error(
        "all {points} points lie on one line (spread across the line {spread:e} of its length)"
    )]
    Collinear {
        /// Number of distinct points.
        points: usize,
        /// Root of the ratio of the two largest covariance eigenvalues (0 for an exact line).
        spread: f64,
    },
    /// A face refers to a vertex that does not exist.
    #[error("face {face} refers to vertex {vertex}, but there are only {vertices} vertices")]
    FaceIndexOutOfRange {
        /// Index of the face in the input.
        face: usize,
        /// The vertex id it refers to.
        vertex: u32,
        /// Number of vertices.
        vertices: usize,
    },
    /// [`crate::TargetOptions::cancel`] was cancelled: construction stopped early.
    #[error("interrupted")]
    Interrupted,
    /// An option is out of its valid range.
    #[error("invalid option {name}: {reason}")]
    InvalidOption {
        /// The option's field name.
        name: &'static str,
        /// What is wrong with it.
        reason: String,
    },
}

impl From<subfit_mesh::Cancelled> for TargetError {
    fn from(_: subfit_mesh::Cancelled) -> Self {
        TargetError::Interrupted
    }
}
