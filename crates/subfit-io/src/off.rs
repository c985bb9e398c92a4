//! off reader and writer (placeholder until implemented).

use std::path::Path;

use subfit_mesh::PolyMesh;

use crate::error::{Error, ErrorKind, Result};

/// Parses a whole off file.
pub fn read(_bytes: &[u8], path: &Path) -> Result<PolyMesh> {
    Err(Error::file(path, ErrorKind::Unsupported("off reader not implemented yet".into())))
}

/// Writes a mesh as off.
pub fn write(_mesh: &PolyMesh, _out: &mut Vec<u8>) -> std::io::Result<()> {
    Err(std::io::Error::other("off writer not implemented yet"))
}
