//! Initial control meshes with the target's topology (DESIGN.md §2 `subfit-init`, §3.6;
//! Cheng et al. 2004 §4.3, Cheng et al. 2007 §II-C).
//!
//! * [`simplify`](mod@simplify): topology-preserving quadric-error edge collapse (Garland & Heckbert 1997) with
//!   the link condition of Dey et al. 1999, for mesh targets and for contoured point clouds.
//! * [`contour`](mod@contour): a point cloud's IMLS function (Xie et al. 2023 eq. 2–3) sampled on an
//!   adaptive, 2:1-balanced octree (fine only in a band around the data, as Cheng et al. 2004
//!   §4.3 and 2007 §II-C contour an octree) and contoured by marching tetrahedra (the
//!   ambiguity-free variant of Lorensen & Cline 1987) on a conforming tetrahedralization of its
//!   leaves, which always yields a closed, manifold, consistently oriented, crack-free surface.
//! * [`carve`](mod@carve): a normal-free wrap of a point cloud (space carving with a ball), the
//!   fallback when the IMLS contour misses an expected genus (e.g. badly oriented normals).
//! * [`islands`](mod@islands): the rule that keeps a small component when it alone covers data.
//! * [`trim`](mod@trim): the faces of a contour that no data supports are cut away, so an open
//!   cloud (a single-view scan) gives an open surface with its boundary loops.
//! * [`init`](mod@init): the entry point [`initial_control_mesh`]: mesh targets are simplified, point clouds
//!   contoured then simplified; the genus is checked against the target's and reported.
//! * [`cad_cage`](mod@cad_cage): the cage of a CAD tessellation from its own features (creases
//!   and corners tagged, planes emptied, smooth faces coarsened within a bound).
//! * [`snap`](mod@snap): a point cloud's crease curves traced on its contour, for
//!   feature-aligned cages.
//! * [`quads`](mod@quads): [`pair_triangles`] turns a triangle cage into a quad-dominant one,
//!   pairing triangles along the principal curvature directions (Lavoué et al. 2007 §4.3).
//!
//! Everything works in the target's normalized units (the unit cube). The library prints nothing.

// `!(x > t)` is used deliberately: it is true for NaN, which must take the fallback branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod cad_cage;
pub mod carve;
pub mod contour;
pub mod cross_field;
pub mod curvature_lines;
mod denoise;
mod heap;
pub mod hexagons;
pub mod init;
mod init_options;
pub mod islands;
mod march;
mod octree;
mod quad_shape;
pub mod quads;
pub mod semi_sharp;
pub mod simplify;
pub mod snap;
pub mod specks;
pub mod trim;

pub use cad_cage::{cad_cage, CadOptions, CadReport};
pub use carve::carve;
pub use contour::{contour, ContourError, ContourOptions, ContourReport, MAX_RESOLUTION};
pub use init::{
    default_control_points, initial_control_mesh, min_vertices_for_topology, FeatureCounts,
    InitError, InitOptions, InitReport, InitSource, InitTimings, ONE_SIDED_REFINE, ONE_SIDED_TRIM,
    OPEN_CLOUD_SCALE,
};
pub use quads::{coherency_score, pair_triangles, PairOptions, PairReport};
pub use simplify::{
    simplify, simplify_with_features, FeatureLock, SimplifyError, SimplifyOptions, SimplifyReport,
};
pub use snap::{snap_to_features, SnapReport};
pub use trim::{boundary_polylines, trim_unsupported, TrimError, TrimOptions, TrimReport};
