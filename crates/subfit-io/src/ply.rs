//! PLY reader and writer (placeholder until implemented).

use std::path::Path;

use subfit_mesh::PolyMesh;

use crate::error::{Error, ErrorKind, Result};
use crate::Encoding;

/// Parses a whole PLY file.
pub fn read(_bytes: &[u8], path: &Path) -> Result<(PolyMesh, Encoding)> {
    Err(Error::file(path, ErrorKind::Unsupported("ply reader not implemented yet".into())))
}

/// Writes a mesh as PLY in the given encoding, with `double` coordinates unless
/// `single_precision`.
pub fn write(
    _mesh: &PolyMesh,
    _encoding: Encoding,
    _single_precision: bool,
    _out: &mut Vec<u8>,
) -> std::io::Result<()> {
    Err(std::io::Error::other("ply writer not implemented yet"))
}
