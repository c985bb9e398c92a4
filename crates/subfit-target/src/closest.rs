//! Exact closest point on a mesh target's triangles: the BVH of [`subfit_mesh::bvh`]
//! (axis-aligned boxes, median split; point–triangle test of Ericson 2005, §5.1.5), re-exported
//! here because the target owns one ([`crate::Target::mesh`]) and its callers name it from this
//! crate. Inside a [`crate::Target`] the points are in normalized units and the triangles are a
//! fan triangulation of the input faces over the distinct points.

pub use subfit_mesh::bvh::{MeshClosestPoint, TriangleBvh};
