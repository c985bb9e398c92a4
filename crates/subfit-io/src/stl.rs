//! STL reader and writer (placeholder until implemented).

use std::path::Path;

use subfit_mesh::PolyMesh;

use crate::error::{Error, ErrorKind, Result};
use crate::Encoding;

/// Parses a whole STL file (ascii or binary), welding identical corners when `weld` is set.
pub fn read(_bytes: &[u8], path: &Path, _weld: bool) -> Result<(PolyMesh, Encoding)> {
    Err(Error::file(path, ErrorKind::Unsupported("stl reader not implemented yet".into())))
}

/// Writes the triangles (fans of polygons) of a mesh as STL.
pub fn write(_mesh: &PolyMesh, _encoding: Encoding, _out: &mut Vec<u8>) -> std::io::Result<()> {
    Err(std::io::Error::other("stl writer not implemented yet"))
}

/// Whether the bytes look like a binary STL (84-byte header + count matching the size).
pub fn is_binary_stl(bytes: &[u8]) -> bool {
    if bytes.len() < 84 {
        return false;
    }
    let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
    84 + 50 * n == bytes.len() as u64
}
