//! The `[f64; 3]` helpers of [`subfit_mesh::vec3`], for the modules that still import them from
//! here (they move to `subfit_mesh::vec3` with the next change to their imports).

pub(crate) use subfit_mesh::vec3::{add, cross, dot, normalize, scale, sub};
