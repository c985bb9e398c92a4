//! Point lists as text (`.xyz`, `.pts`, `.txt`, `.xyzn`): one point per line.
//!
//! Supported on reading:
//! - Values separated by blanks and/or commas. Comments from `#` or `//` to the end of the
//!   line; blank lines.
//! - An optional first line holding a single non-negative integer: the point count of a
//!   `.pts` file. It must match the number of points that follow ([`ErrorKind::BadCount`]
//!   otherwise). Files of several such blocks are not supported.
//! - Columns, the same number on every line (a line that differs is a syntax error naming it):
//!   - 3: `x y z`;
//!   - 4 or 5: `x y z` and ignored values (intensity…);
//!   - 6: `x y z nx ny nz`;
//!   - 7: `x y z intensity r g b` (the Leica PTS layout): colours as integers 0..255 (clamped),
//!     intensity ignored;
//!   - 8 or more: `x y z nx ny nz` and ignored values.
//!
//!   Every column must be a number; positions, normals and colours must be finite.
//!
//! Faces are never read (there are none). A file without any point is [`ErrorKind::Empty`].
//!
//! Writing: `x y z` or `x y z nx ny nz` per line, shortest decimals that read back to the same
//! f64. Faces and colours are not written.

use std::path::Path;

use subfit_mesh::{PolyMesh, Polygons};

use crate::error::{Error, ErrorKind, Result};
use crate::text::{
    check_utf8, finite_f64, parse_f64, parse_i64, push_f64_exact, syntax, NumberedLines,
};

/// Cuts a line at `#` or `//`.
fn strip_comment(line: &[u8]) -> &[u8] {
    let mut i = 0;
    while i < line.len() {
        match line[i] {
            b'#' => return &line[..i],
            b'/' if line.get(i + 1) == Some(&b'/') => return &line[..i],
            _ => i += 1,
        }
    }
    line
}

/// Splits on blanks and commas.
fn fields(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|&c| c.is_ascii_whitespace() || c == b',')
        .filter(|t| !t.is_empty())
}

/// Parses a whole point list.
///
/// Cost: O(file size) time; memory proportional to the points present.
pub fn read(bytes: &[u8], path: &Path) -> Result<PolyMesh> {
    check_utf8(bytes, path)?;
    let mut positions: Vec<[f64; 3]> = Vec::with_capacity(bytes.len() / 32);
    let mut normals: Vec<[f64; 3]> = Vec::new();
    let mut colors: Vec<[u8; 3]> = Vec::new();
    // (columns, line of the first point)
    let mut layout: Option<(usize, u64)> = None;
    let mut announced: Option<(u64, u64)> = None;
    let mut first_data = true;
    for (no, raw) in NumberedLines::new(bytes) {
        let line = strip_comment(raw);
        let mut vals = [0f64; 7];
        let mut toks: [&[u8]; 7] = [b""; 7];
        let mut n = 0usize;
        for t in fields(line) {
            if n < 7 {
                toks[n] = t;
            } else if parse_f64(t).is_none() {
                return Err(syntax(path, no, "expected a number", t));
            }
            n += 1;
        }
        if n == 0 {
            continue;
        }
        if std::mem::take(&mut first_data) && n == 1 {
            if let Some(c) = parse_i64(toks[0]).filter(|&c| c >= 0) {
                announced = Some((c as u64, no));
                continue;
            }
        }
        let cols = match layout {
            Some((cols, first)) => {
                if n != cols {
                    return Err(Error::at_line(
                        path,
                        no,
                        ErrorKind::Syntax(format!(
                            "{n} columns, but the first point (line {first}) has {cols}"
                        )),
                    ));
                }
                cols
            }
            None => {
                if n < 3 {
                    return Err(Error::at_line(
                        path,
                        no,
                        ErrorKind::Syntax(format!("{n} column(s); a point needs at least x y z")),
                    ));
                }
                layout = Some((n, no));
                n
            }
        };
        for (k, v) in vals.iter_mut().enumerate().take(n) {
            let role = match (k, cols) {
                (0..=2, _) => Some("coordinate"),
                (3..=5, c) if c == 6 || c >= 8 => Some("normal component"),
                (4..=6, 7) => Some("colour component"),
                _ => None,
            };
            *v = match role {
                Some(what) => finite_f64(toks[k], path, no, what)?,
                None => parse_f64(toks[k])
                    .ok_or_else(|| syntax(path, no, "expected a number", toks[k]))?,
            };
        }
        positions.push([vals[0], vals[1], vals[2]]);
        if cols == 6 || cols >= 8 {
            normals.push([vals[3], vals[4], vals[5]]);
        } else if cols == 7 {
            colors.push([4, 5, 6].map(|k| vals[k].clamp(0.0, 255.0).round() as u8));
        }
    }
    if let Some((count, no)) = announced {
        if count != positions.len() as u64 {
            return Err(Error::at_line(
                path,
                no,
                ErrorKind::BadCount(format!(
                    "the first line announces {count} points, the file has {}",
                    positions.len()
                )),
            ));
        }
    }
    if positions.is_empty() {
        return Err(Error::file(path, ErrorKind::Empty));
    }
    let has_normals = !normals.is_empty();
    let has_colors = !colors.is_empty();
    Ok(PolyMesh {
        positions,
        normals: has_normals.then_some(normals),
        colors: has_colors.then_some(colors),
        faces: Polygons::new(),
    })
}

/// Writes a mesh as a point list (`x y z [nx ny nz]` per line).
pub fn write(mesh: &PolyMesh, out: &mut Vec<u8>) -> std::io::Result<()> {
    let normals = mesh.normals.as_deref();
    out.reserve(mesh.positions.len() * if normals.is_some() { 80 } else { 40 });
    for (i, p) in mesh.positions.iter().enumerate() {
        push_floats(out, p);
        if let Some(n) = normals.and_then(|n| n.get(i)) {
            out.push(b' ');
            push_floats(out, n);
        }
        out.push(b'\n');
    }
    Ok(())
}

fn push_floats(out: &mut Vec<u8>, v: &[f64; 3]) {
    push_f64_exact(out, v[0]);
    out.push(b' ');
    push_f64_exact(out, v[1]);
    out.push(b' ');
    push_f64_exact(out, v[2]);
}
