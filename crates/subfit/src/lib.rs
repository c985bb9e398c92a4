//! subfit: fit compact subdivision surfaces to dense 3D scans.
//!
//! This facade re-exports the workspace crates:
//! - [`mesh`]: polygon topology, half-edge view, diagnostics, generated shapes;
//! - [`io`]: PLY, OBJ, OFF, STL and XYZ readers and writers;
//! - [`subdiv`]: subdivision schemes, stencils and limit evaluation;
//! - [`target`]: the shape being fitted (normals, curvature, foot points);
//! - [`fit`]: the fitting engine (PDM/TDM/SDM, smoothing, LM and Armijo step control);
//! - [`init`]: initial control meshes with the target's topology (QEM simplification, contouring).

pub use subfit_fit as fit;
pub use subfit_init as init;
pub use subfit_io as io;
pub use subfit_mesh as mesh;
pub use subfit_subdiv as subdiv;
pub use subfit_target as target;
