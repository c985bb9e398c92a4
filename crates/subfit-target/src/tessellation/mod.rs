//! Recognising a CAD tessellation and reading its features from the facets themselves.
//!
//! A CAD system exports a part as the triangles of a chordal tessellation: every planar face is
//! a fan or strip of exactly coplanar triangles, a cylinder or fillet is a row of long thin
//! strips (each a planar quad cut in two), and every vertex lies on the true part while the
//! facets between them sag inside it by at most the exporter's chord height (Hoppe et al.
//! 1994, *Piecewise smooth surface reconstruction*, §2 on the piecewise-smooth model; Lavoué
//! et al. 2005 §6 on CAD meshes whose patch boundaries are sharp). Such a mesh is not a
//! scan: its vertex spacing says nothing about noise, a point-count neighbourhood spans
//! whole faces, and its features are exact — a dihedral angle between two facets, a plane
//! that many facets share.
//!
//! * [`Facets::new`] measures what the facets say: face normals and areas, the interior edges
//!   with their dihedral angles, which of them are **flat** (the four corners of the two faces
//!   coplanar within a tolerance set by the file's number precision), and the **planar
//!   regions** grown across flat edges from the largest faces (planes.rs; facets.rs measures,
//!   elements.rs holds the edge and region types both use).
//! * [`TessellationStats`] ([`Facets::stats`]) says whether the mesh is a tessellation:
//!   at least [`FLAT_EDGE_SHARE`] of its interior edges are flat. A scan has almost none
//!   (noise breaks exact coplanarity); a CAD export has about one in three even on its curved
//!   faces (the diagonal of each strip).
//! * [`classify_edges`] (edges.rs) sorts the edges between different planar regions into
//!   smooth ones (a curved face's facets turning a little, whose smooth limit lies within a
//!   budget of them) and creases, and estimates the exporter's chord height.
//!
//! Units are those of the positions given (the target's unit cube in the pipeline).

mod curved;
mod edges;
mod elements;
mod facets;
mod planes;

pub use curved::{curved_interpolant, CurvedInterpolant, MIN_PLANE_FACES};
pub use edges::{
    chord_height, classify_edges, classify_edges_chordal, EdgeClass, FacetFeatures, SmoothBudget,
    CHORDAL_SAGS, CHORDAL_STRIP_RATIO, MAX_SMOOTH_ANGLE_DEG,
};
pub use elements::{FacetEdge, PlanarRegion};
pub use facets::{Facets, TessellationStats, FLAT_EDGE_SHARE, PLANAR_AREA_SHARE, SLIVER_ASPECT};

#[cfg(test)]
mod tests;
