//! What a fit is judged and shown by (DESIGN.md §2 `subfit-report`, decision 11).
//!
//! * [`distance`]: distance statistics one way ([`DistanceStats`]) and both ways
//!   ([`TwoSided`]): surface → data and data → surface, in normalized (unit-cube) units and as a
//!   fraction of the bounding-box diagonal; a fit has reached a tolerance only when both
//!   directions are within it.
//! * [`limit_distance`]: exact distances from points to a limit surface (closest points on the
//!   limit surface, [`subfit_subdiv::ClosestPointFinder`]), with the control face they land on.
//! * [`mesh_distance`]: distances from points to a tessellation of it (point–triangle, BVH),
//!   within the tessellation's chordal error of the exact ones and ~50× faster.
//! * [`data_samples`]: the points the data → surface direction is measured from: a point
//!   cloud's points, or a mesh's surface sampled uniformly by area.
//! * [`color`]: the papers' error colours (Cheng 2007 §IV-D).
//! * [`tessellate`]: the limit tessellation written with a fit, at the coarsest level whose
//!   chordal error is a tenth of the fitting error.
//! * [`plot`]: deterministic SVG line charts.
//! * [`html`]: self-contained report pages (report.html) around a three.js viewer.
//! * [`preview`]: a CPU rasterizer for `preview.png` (error colours, cage wireframe, colour bar).
//!
//! Nothing here prints or touches files.

pub mod color;
pub mod data_samples;
pub mod distance;
pub mod html;
pub mod limit_distance;
pub mod mesh_distance;
pub mod plot;
pub mod preview;
pub mod tessellate;

pub use color::error_color;
pub use data_samples::{data_samples, DataSamples};
pub use distance::{vertex_areas, DistanceStats, TwoSided};
pub use limit_distance::{LimitDistance, LimitDistanceError, PointToLimit};
pub use mesh_distance::MeshDistance;
pub use preview::{
    preview_png, render as render_preview, render_polymesh as render_preview_polymesh, ColorBar,
    Image, PreviewError, PreviewOptions, Projection, UpAxis, View, Wireframe,
};
pub use tessellate::{limit_tessellation, Chordal, LimitTessellation};
