//! Reading: [`read`] parses the header, runs the ascii or binary decoder into a [`Sink`] and
//! returns the mesh.

use std::path::Path;

use subfit_mesh::{PolyMesh, Polygons};

use super::ascii::read_ascii;
use super::binary::read_binary;
use super::header::parse_header;
use super::sink::Sink;
use crate::error::{Error, ErrorKind, Result};
use crate::Encoding;

/// Parses a whole PLY file (see the module doc for what is supported).
///
/// Returns the mesh (positions, optional normals and colours, faces from `face` and/or
/// `tristrips`) and the file's encoding; header lines with an unknown keyword (skipped) and
/// NaN colours (read as 0) are reported in `warnings`. Cost: O(file size); memory O(mesh size).
///
/// Errors: [`ErrorKind::Empty`], [`ErrorKind::BadHeader`] (missing magic, bad `format`, unknown
/// type, missing `x`/`y`/`z`, non-UTF-8 header…), [`ErrorKind::BadCount`] (negative counts, an
/// element count the remaining bytes cannot hold, negative list counts),
/// [`ErrorKind::Truncated`], [`ErrorKind::Syntax`] (ascii), [`ErrorKind::IndexOutOfRange`],
/// [`ErrorKind::NonFinite`]. Never panics.
pub fn read(bytes: &[u8], path: &Path, warnings: &mut Vec<String>) -> Result<(PolyMesh, Encoding)> {
    if bytes.iter().all(|c| c.is_ascii_whitespace()) {
        return Err(Error::file(path, ErrorKind::Empty));
    }
    let header = parse_header(bytes, path)?;
    let data = &bytes[header.data_start..];
    let mut sink = Sink {
        positions: Vec::new(),
        normals: header.has_normals.then(Vec::new),
        colors: header.has_colors.then(Vec::new),
        faces: Polygons::new(),
        vertex_count: header.vertex_count,
        face: Vec::new(),
        nan_colors: 0,
    };
    if !header.skipped.is_empty() {
        let listed: Vec<String> = header
            .skipped
            .iter()
            .take(5)
            .map(|(l, k)| format!("line {l} `{k}`"))
            .collect();
        warnings.push(format!(
            "{} header line(s) with an unknown keyword skipped: {}{}",
            header.skipped.len(),
            listed.join(", "),
            if header.skipped.len() > 5 {
                ", …"
            } else {
                ""
            }
        ));
    }
    match header.encoding {
        Encoding::Ascii => read_ascii(&header, data, path, &mut sink)?,
        Encoding::BinaryLittleEndian => read_binary(&header, data, false, path, &mut sink)?,
        Encoding::BinaryBigEndian => read_binary(&header, data, true, path, &mut sink)?,
    }
    if sink.nan_colors > 0 {
        warnings.push(format!(
            "{} vertices have a NaN colour component, read as 0",
            sink.nan_colors
        ));
    }
    let mesh = PolyMesh {
        positions: sink.positions,
        normals: sink.normals,
        colors: sink.colors,
        faces: sink.faces,
    };
    Ok((mesh, header.encoding))
}
