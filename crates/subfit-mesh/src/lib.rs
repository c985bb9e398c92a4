//! Polygon mesh topology for subfit.
//!
//! Topology is flat `u32` arrays behind typed ids ([`VertexId`], [`FaceId`], …); positions live
//! beside it. [`Polygons`] is the compressed-row face list passed between crates and [`PolyMesh`]
//! bundles it with positions and optional attributes.

pub mod ids;
pub mod polygons;
pub mod shapes;
pub mod tags;

pub use ids::{EdgeId, FaceId, HalfEdgeId, VertexId};
pub use polygons::{bounding_box, PolyMesh, Polygons};
pub use tags::{Tags, SHARPNESS_INFINITE};
