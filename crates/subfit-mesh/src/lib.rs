//! Polygon mesh topology for subfit.
//!
//! Topology is flat `u32` arrays behind typed ids ([`VertexId`], [`FaceId`], …); positions live
//! beside it. [`Polygons`] is the compressed-row face list passed between crates and [`PolyMesh`]
//! bundles it with positions and optional attributes. [`HalfEdgeMesh`] is a derived view for
//! navigating manifold meshes; [`diagnose()`] reports on any polygon soup (boundary loops,
//! manifoldness, orientation, components, Euler characteristic, genus); [`reorient_faces`] repairs
//! inconsistently oriented faces; [`split_concave_corners`] keeps a tagged cage from folding at
//! its concave corners. [`Cancel`] is the cancellation token that the long phases of
//! the other crates poll. [`vec3`] holds the small `[f64; 3]` helpers every crate uses; [`bvh`]
//! the exact closest point on triangles; [`deforming`] generates deforming test sequences with
//! known correspondence.

pub mod bowtie;
pub mod bvh;
pub mod cancel;
pub mod components;
pub mod concave;
pub mod deforming;
pub mod diagnose;
pub mod edge_pairs;
mod edges;
pub mod halfedge;
pub mod ids;
pub mod nonmanifold;
pub mod parts;
pub mod polygons;
pub mod range_scan;
pub mod reorient;
pub mod shapes;
pub mod tags;
pub mod thin_shapes;
pub mod twins;
pub mod vec3;
pub mod weld;

pub use bowtie::{split_bowties, BowtieReport};
pub use cancel::{Cancel, Cancelled};
pub use components::{euler_characteristic, face_components, genus, Components};
pub use concave::{
    split_concave_corners, split_concave_corners_with, ConcaveSplits, CONCAVE_ANGLE,
};
pub use diagnose::{diagnose, diagnose_mesh, ComponentReport, IssueExamples, MeshReport};
pub use edges::UnionFind;
pub use halfedge::{HalfEdgeMesh, Outgoing, TopologyError};
pub use ids::{EdgeId, FaceId, HalfEdgeId, VertexId};
pub use nonmanifold::{clean_faces, cut_nonmanifold_edges, EdgeCutReport, FaceCleanReport};
pub use polygons::{bounding_box, PolyMesh, Polygons};
pub use reorient::{reorient_faces, ReorientError, ReorientReport};
pub use tags::{Tags, SHARPNESS_INFINITE};
pub use twins::{drop_twin_sides, TwinReport};
pub use weld::{coincident_vertices, weld_coincident, WeldReport};
