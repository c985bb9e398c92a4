//! Typed errors for bad control-mesh topology.

/// Why a control mesh cannot be subdivided.
///
/// Every variant names the offending element (face index, vertex ids) of the mesh that was passed
/// in, so callers can report it against their input.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SubdivError {
    /// A face has fewer than three vertices.
    #[error("face {face} has {len} vertices; at least 3 are needed")]
    DegenerateFace {
        /// Index of the face.
        face: usize,
        /// Number of vertices it has.
        len: usize,
    },
    /// A face references a vertex id `>= num_vertices`.
    #[error("face {face} references vertex {vertex}, but there are only {num_vertices} vertices")]
    VertexOutOfRange {
        /// Index of the face.
        face: usize,
        /// The offending vertex id.
        vertex: u32,
        /// The vertex count that was given.
        num_vertices: usize,
    },
    /// A face lists the same vertex twice.
    #[error("face {face} lists vertex {vertex} more than once")]
    RepeatedVertex {
        /// Index of the face.
        face: usize,
        /// The repeated vertex id.
        vertex: u32,
    },
    /// The directed edge `a → b` occurs in two faces: the edge has more than two faces or its
    /// faces are inconsistently oriented.
    #[error("edge {a}-{b} is non-manifold or its faces are inconsistently oriented")]
    NonManifoldEdge {
        /// First vertex of the directed edge.
        a: u32,
        /// Second vertex of the directed edge.
        b: u32,
    },
    /// The faces around a vertex form more than one fan (a "bow-tie" vertex).
    #[error("vertex {vertex} is non-manifold: its faces form more than one fan")]
    NonManifoldVertex {
        /// The vertex id.
        vertex: u32,
    },
    /// Loop subdivision was asked for a mesh with a non-triangular face.
    #[error("Loop subdivision needs triangles, but face {face} has {len} vertices")]
    NotTriangles {
        /// Index of the first non-triangular face.
        face: usize,
        /// Its number of vertices.
        len: usize,
    },
    /// The quad/triangle scheme was asked for a vertex with both triangles and other faces
    /// around it on more than 64 faces (its rules record the face kinds in a 64-bit mask).
    #[error("vertex {vertex} has {num_faces} faces of mixed kinds; the quad/triangle scheme supports at most 64 there")]
    MixedValence {
        /// The vertex id.
        vertex: u32,
        /// Its number of incident faces.
        num_faces: usize,
    },
    /// The refined mesh would need more than `u32::MAX - 1` elements of one kind.
    #[error("the refined mesh is too large for 32-bit ids ({count} {what})")]
    TooLarge {
        /// What overflowed (vertices, indices).
        what: &'static str,
        /// How many were needed.
        count: usize,
    },
}
