//! The OFF header keyword `[ST][C][N][4][n]OFF` (the Geomview manual, "OFF Files") and the
//! per-vertex layout it announces, shared by the text reader ([`crate::off`]) and the binary
//! reader (`off_binary`).

use std::path::Path;

use crate::error::{Error, ErrorKind, Result};
use crate::text::syntax;

/// What the header keyword announces per vertex.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Layout {
    pub(crate) normals: bool,
    pub(crate) colors: bool,
    pub(crate) texcoords: bool,
}

/// Decodes `[ST][C][N][4][n]OFF`.
pub(crate) fn keyword(kw: &[u8], path: &Path, no: u64) -> Result<Layout> {
    let Some(mut pre) = kw.strip_suffix(b"OFF") else {
        return Err(syntax(path, no, "expected the OFF header keyword", kw));
    };
    let mut layout = Layout::default();
    if let Some(p) = pre.strip_prefix(b"ST") {
        layout.texcoords = true;
        pre = p;
    }
    loop {
        match pre.first() {
            Some(b'C') if !layout.colors => layout.colors = true,
            Some(b'N') if !layout.normals => layout.normals = true,
            _ => break,
        }
        pre = &pre[1..];
    }
    match pre {
        b"" => Ok(layout),
        b"4" | b"n" | b"4n" => Err(Error::at_line(
            path,
            no,
            ErrorKind::Unsupported(format!(
                "`{}`: OFF in other than three dimensions",
                String::from_utf8_lossy(kw)
            )),
        )),
        _ => Err(syntax(path, no, "unknown OFF header keyword", kw)),
    }
}
