//! The shape being fitted (DESIGN.md §2 `subfit-target`, §3.2).
//!
//! A [`Target`] is a point cloud or mesh scaled uniformly into the unit cube (Cheng 2004 §3
//! step 1), with exact duplicates merged, outliers of point clouds dropped and the noise level
//! estimated ([`TargetOptions::remove_outliers`]), a kd-tree ([`neighbors`]), a unit normal and a local
//! quadric per point ([`estimate`], [`quadric`]; Cheng 2004 §4.1, Cheng 2007 §II-C), normals
//! oriented by minimum-spanning-tree propagation ([`orient`]; Hoppe et al. 1992), foot-point
//! queries with the signed distance, frame and curvature radii of the SD term ([`project`];
//! Cheng 2007 §II-D3), the IMLS distance ([`imls`]; Xie et al. 2023 eq. 2–3) and, for meshes,
//! exact closest points on the triangles ([`closest`]) and foot points on them
//! ([`Target::mesh_foot_point`]).
//!
//! Everything inside is in normalized units; [`Normalization`] maps back. The library prints
//! nothing: progress goes through [`ProgressFn`], figures through [`TargetStats`].
//!
//! ```
//! use subfit_target::{Target, TargetOptions};
//! // A 20×20 grid on a paraboloid.
//! let pts: Vec<[f64; 3]> = (0..400)
//!     .map(|i| {
//!         let (x, y) = ((i % 20) as f64 / 19.0 - 0.5, (i / 20) as f64 / 19.0 - 0.5);
//!         [x, y, 0.5 * (x * x + y * y)]
//!     })
//!     .collect();
//! let t = Target::from_points(&pts, None, &TargetOptions::default()).unwrap();
//! let f = t.foot_point(t.to_normalized([0.0, 0.0, 0.1]));
//! assert!(f.distance > 0.0 && f.normal[2] > 0.99);
//! ```

// `!(x > 0.0)` is used deliberately: it is true for NaN, which must take the fallback branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod angular_gap;
mod blend;
pub mod boundary_corners;
mod build_steps;
pub mod closest;
pub mod cloud_features;
pub mod cloud_rim;
pub mod consistency;
mod error;
pub mod estimate;
mod extent;
pub mod features;
pub mod fillet;
mod foot;
pub mod imls;
mod layout;
mod mesh_parts;
pub mod neighbors;
mod normalize;
mod options;
pub mod orient;
mod outliers;
pub mod project;
pub mod quadric;
mod regularize;
mod target;
pub mod tessellation;
mod winding;

pub use boundary_corners::{boundary_corners, boundary_vertices, BoundaryCorners};
pub use closest::{MeshClosestPoint, TriangleBvh};
pub use cloud_features::{
    detect_cloud_features, detect_cloud_features_in, CloudFeatures, FeaturePolyline,
};
pub use cloud_rim::{cloud_boundary_points, RIM_GAP, RIM_NEIGHBORS};
pub use error::TargetError;
pub use estimate::Neighborhood;
pub use extent::{EXTENT_NEIGHBOURS, REACH_SAMPLES};
pub use features::{detect_features, FeatureCurve, FeatureOptions, Features};
pub use fillet::fillet_widths;
pub use imls::{imls_value, ImlsValue};
pub use mesh_parts::CLOSED_BOUNDARY_SHARE;
pub use neighbors::{Neighbor, PointIndex};
pub use normalize::Normalization;
pub use options::{
    NormalOrigin, NormalSource, Phase, Progress, ProgressFn, TargetOptions, TargetStats,
    TargetTimings,
};
pub use project::{alpha_plus, FootPoint};
pub use quadric::{FitQuality, LocalQuadric, SurfaceFrame};
pub use target::{PointAttributes, Target, MIN_POINTS};
