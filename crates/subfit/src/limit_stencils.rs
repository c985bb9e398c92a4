//! The limit samples of a sequence's cage as rows of weights over its control points
//! (STYLE.md rule 2): positions and both tangents, built once per cage topology and shared by
//! the frame fits ([`crate::sequence`]) and the tracking step ([`crate::sequence_tracking`]).

use subfit_subdiv::StencilMatrix;

/// Limit positions and tangents of the sample points, one row per sample.
pub(crate) struct LimitStencils {
    /// Positions.
    pub(crate) position: StencilMatrix,
    /// First tangents.
    pub(crate) tangent1: StencilMatrix,
    /// Second tangents.
    pub(crate) tangent2: StencilMatrix,
}
