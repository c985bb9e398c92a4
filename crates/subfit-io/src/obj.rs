//! obj reader and writer (placeholder until implemented).

use std::path::Path;

use subfit_mesh::PolyMesh;

use crate::error::{Error, ErrorKind, Result};

/// Parses a whole obj file.
pub fn read(_bytes: &[u8], path: &Path) -> Result<PolyMesh> {
    Err(Error::file(path, ErrorKind::Unsupported("obj reader not implemented yet".into())))
}

/// Writes a mesh as obj.
pub fn write(_mesh: &PolyMesh, _out: &mut Vec<u8>) -> std::io::Result<()> {
    Err(std::io::Error::other("obj writer not implemented yet"))
}
