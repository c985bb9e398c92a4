//! The elements the facets of a tessellation are read into: interior edges with their dihedral
//! angles ([`FacetEdge`]) and planar regions ([`PlanarRegion`]); filled by [`Facets::new`]
//! (facets.rs) and the region growth (planes.rs).
//!
//! [`Facets::new`]: super::Facets::new

/// An interior manifold edge of the tessellation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FacetEdge {
    /// Its two vertices, `ends[0] < ends[1]`.
    pub ends: [u32; 2],
    /// Its two faces (the face with `ends[0] → ends[1]` in its winding first).
    pub faces: [u32; 2],
    /// Dihedral angle between the two faces' planes (radians, `[0, π]`): 0 where the surface
    /// goes on flat. Measured with the planar regions' normals, which are exact where a single
    /// sliver's normal is not.
    pub angle: f64,
    /// Whether the edge is convex (the faces turn away from their normals: the outside of a
    /// box edge) rather than concave.
    pub convex: bool,
    /// Whether the two faces lie in one plane within the flat tolerance.
    pub flat: bool,
}

/// One planar region: faces grown across flat edges that all lie on one plane.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanarRegion {
    /// Unit normal (area-weighted mean of its faces', oriented like them).
    pub normal: [f64; 3],
    /// Number of faces.
    pub faces: usize,
    /// Total area.
    pub area: f64,
}
