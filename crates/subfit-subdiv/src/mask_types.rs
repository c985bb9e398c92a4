//! The mask types: [`Mask`] (weights over a vertex neighbourhood), [`EdgeMask`] (the weights
//! of an edge point) and [`FaceWeights`] (what face weights refer to). They are plain buffers,
//! filled by the scheme rules in module `mask` (re-exported there) and by the quad/triangle
//! limit analysis in module `mixed`, which both build on them.

/// What the face weights of a [`Mask`] refer to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FaceWeights {
    /// The centroid of each incident face (its Catmull-Clark face point).
    #[default]
    Centers,
    /// The vertex two corners away from the centre vertex in each incident face (the diagonal
    /// vertex of a quad). Used by Catmull-Clark limit masks, which require quads.
    Opposite,
}

/// Weights over a vertex neighbourhood: the vertex itself, its ring vertices (one per incident
/// edge, in [`Neighborhood`](crate::scheme::Neighborhood) order) and its incident faces.
///
/// Buffers are reused between calls (`fill` methods clear and resize them), so one `Mask` per
/// thread serves a whole mesh without allocating.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mask {
    /// Weight of the centre vertex.
    pub vertex: f64,
    /// Weight of the far end of each incident edge (`num_edges` entries).
    pub edges: Vec<f64>,
    /// Weight of each incident face (`num_faces` entries, or none), interpreted as `face_weights`.
    pub faces: Vec<f64>,
    /// What `faces` refers to.
    pub face_weights: FaceWeights,
}

impl Mask {
    pub(crate) fn reset(&mut self, num_edges: usize, num_faces: usize, face_weights: FaceWeights) {
        self.vertex = 0.0;
        self.edges.clear();
        self.edges.resize(num_edges, 0.0);
        self.faces.clear();
        self.faces.resize(num_faces, 0.0);
        self.face_weights = face_weights;
    }

    /// Sum of all weights (1 for position masks, 0 for tangent masks).
    pub fn sum(&self) -> f64 {
        self.vertex + self.edges.iter().sum::<f64>() + self.faces.iter().sum::<f64>()
    }
}

/// The weights of an edge point: both ends get `end`, incident face `i` (in the order of
/// [`EdgeNeighborhood::triangles`](crate::scheme::EdgeNeighborhood::triangles)) gets `face[i]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeMask {
    /// Weight of each end vertex.
    pub end: f64,
    /// Weight of each incident face, interpreted as `face_weights`: for a triangle the vertex
    /// opposite the edge, for other faces the face point.
    pub face: [f64; 2],
    /// What each `face` weight refers to: [`FaceWeights::Opposite`] (the triangle's third
    /// vertex) or [`FaceWeights::Centers`] (the face's centroid).
    pub face_weights: [FaceWeights; 2],
}
