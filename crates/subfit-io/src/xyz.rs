//! xyz reader and writer (placeholder until implemented).

use std::path::Path;

use subfit_mesh::PolyMesh;

use crate::error::{Error, ErrorKind, Result};

/// Parses a whole xyz file.
pub fn read(_bytes: &[u8], path: &Path) -> Result<PolyMesh> {
    Err(Error::file(path, ErrorKind::Unsupported("xyz reader not implemented yet".into())))
}

/// Writes a mesh as xyz.
pub fn write(_mesh: &PolyMesh, _out: &mut Vec<u8>) -> std::io::Result<()> {
    Err(std::io::Error::other("xyz writer not implemented yet"))
}
