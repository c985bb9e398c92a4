//! Object File Format (Geomview OFF; the Geomview manual, "OFF Files"), text and binary.
//!
//! Supported on reading:
//! - The header keyword `[ST][C][N]OFF` (`OFF`, `COFF`, `NOFF`, `CNOFF`, `NCOFF`, `STOFF`…),
//!   alone on its line or followed by the counts, also glued to them (`OFF8 6 12`); the keyword
//!   may also be missing (the file starts with the counts). `4OFF` and `nOFF` (other
//!   dimensions) are [`ErrorKind::Unsupported`].
//! - `[ST][C][N]OFF BINARY`: binary OFF (32-bit counts, floats and indices after the header
//!   line), big- or little-endian, with or without a colour count after each face: the one
//!   combination that accounts for every byte is taken, with a warning when it is not the
//!   spec's (big-endian with colour counts). Its encoding is reported as binary.
//! - Counts `V F [E]` (the edge count is ignored), on the header line or the next one.
//! - One vertex per line: `x y z [nx ny nz] [r g b [a]] [s t]`, in that order, with the
//!   normal when the keyword has `N`, the colour when it has `C`, texture coordinates (ignored)
//!   when it has `ST`. Colours are 3 or 4 values: integers in 0..255, or floats in 0..1 when
//!   any of them is written with a `.` or an exponent; alpha is dropped and values are clamped.
//! - Faces `n i1 … in`, 0-based indices, `n >= 3`; a face starts on a new line and its indices
//!   may continue on the following lines until `n` are read; the rest of the line holding the
//!   last index may be up to four colour values, which are ignored.
//! - `#` comments anywhere (to the end of the line; they may hold any bytes) and blank lines.
//!
//! The data must match the counts: a file that ends early is [`ErrorKind::Truncated`] (at the
//! missing vertex or face); data after the last face is [`ErrorKind::BadCount`].
//! A file with counts `0 0` gives an empty mesh.
//!
//! Writing: `OFF`, `NOFF`, `COFF` or `CNOFF` depending on the attributes, counts `V F 0`,
//! vertices with the shortest decimal that reads back to the same f64, colours as four integers
//! (alpha 255), faces as `n i1 … in`.

use std::path::Path;

use subfit_mesh::{PolyMesh, Polygons};

use crate::error::{Error, ErrorKind, Result};
use crate::off_keyword::{keyword, Layout};
use crate::text::{
    finite_f64, parse_f64, parse_i64, parse_int, push_f64_exact, push_u64, strip_hash_comment,
    syntax, tokens, unit_to_u8, NumberedLines,
};
use crate::Encoding;

/// Parses a whole OFF file, text or binary; returns the mesh and the encoding read.
///
/// Cost: O(file size) time; memory proportional to the data present (the counts are never
/// trusted for allocation beyond what the file size allows).
pub fn read(bytes: &[u8], path: &Path, warnings: &mut Vec<String>) -> Result<(PolyMesh, Encoding)> {
    if let Some((layout, no, data_start)) = binary_header(bytes, path)? {
        return crate::off_binary::read(layout, bytes, data_start, no, path, warnings);
    }
    read_text(bytes, path).map(|m| (m, Encoding::Ascii))
}

/// When the first line that is not blank or a comment is `<keyword> BINARY`: the layout, that
/// line's number and the byte offset where the binary data starts (after its line end).
fn binary_header(bytes: &[u8], path: &Path) -> Result<Option<(Layout, u64, usize)>> {
    let mut lines = NumberedLines::new(bytes);
    while let Some((no, raw)) = lines.next() {
        let line = strip_hash_comment(raw);
        let mut toks = tokens(line);
        let Some(kw) = toks.next() else { continue };
        if !toks
            .next()
            .is_some_and(|t| t.eq_ignore_ascii_case(b"BINARY"))
        {
            return Ok(None);
        }
        if let Some(t) = toks.next() {
            return Err(syntax(path, no, "unexpected value after `BINARY`", t));
        }
        let layout = keyword(kw, path, no)?;
        return Ok(Some((layout, no, bytes.len() - lines.rest().len())));
    }
    Ok(None)
}

/// Splits a keyword glued to the vertex count (`OFF8` → `OFF`, rest of the line from `8`).
fn split_glued(kw: &[u8]) -> usize {
    match kw.windows(3).position(|w| w == b"OFF") {
        Some(i) if kw.get(i + 3).is_some_and(|c| c.is_ascii_digit()) => i + 3,
        _ => kw.len(),
    }
}

/// Parses a text OFF file.
fn read_text(bytes: &[u8], path: &Path) -> Result<PolyMesh> {
    // Non-blank lines with comments removed.
    let mut lines = NumberedLines::new(bytes)
        .map(|(no, l)| (no, strip_hash_comment(l)))
        .filter(|(_, l)| l.iter().any(|c| !c.is_ascii_whitespace()));
    let Some((first_no, first)) = lines.next() else {
        return Err(Error::file(path, ErrorKind::Empty));
    };
    let tok = tokens(first).next().unwrap_or_default();
    let (layout, count_line) = if parse_i64(tok).is_some() {
        (Layout::default(), (first_no, first))
    } else {
        let kw_len = split_glued(tok);
        let layout = keyword(&tok[..kw_len], path, first_no)?;
        // The counts may follow the keyword on the same line (`tok` is the first token).
        let start = first.iter().position(|c| !c.is_ascii_whitespace());
        let rest = &first[start.unwrap_or(0) + kw_len..];
        if tokens(rest).next().is_none() {
            match lines.next() {
                Some(l) => (layout, l),
                None => {
                    return Err(Error::at_line(
                        path,
                        first_no,
                        ErrorKind::Truncated("the counts `V F E` are missing".into()),
                    ))
                }
            }
        } else {
            (layout, (first_no, rest))
        }
    };
    let (nv, nf) = counts(count_line.1, path, count_line.0)?;

    // Never reserve more than the file could hold: a vertex line takes at least 6 bytes, a face
    // line at least 8.
    let nv_cap = (nv as usize).min(bytes.len() / 6);
    let nf_cap = (nf as usize).min(bytes.len() / 8);
    let mut positions = Vec::with_capacity(nv_cap);
    let mut normals = Vec::with_capacity(if layout.normals { nv_cap } else { 0 });
    let mut colors = Vec::with_capacity(if layout.colors { nv_cap } else { 0 });
    for i in 0..nv {
        let Some((no, line)) = lines.next() else {
            return Err(Error::at_element(
                path,
                "vertex",
                i,
                ErrorKind::Truncated(format!(
                    "the header announces {nv} vertices, the file ends after {i}"
                )),
            ));
        };
        vertex(
            line,
            no,
            path,
            layout,
            &mut positions,
            &mut normals,
            &mut colors,
        )?;
    }
    let mut faces = Polygons::with_capacity(nf_cap, nf_cap * 3);
    let mut face = Vec::new();
    for i in 0..nf {
        let Some((no, line)) = lines.next() else {
            return Err(Error::at_element(
                path,
                "face",
                i,
                ErrorKind::Truncated(format!(
                    "the header announces {nf} faces, the file ends after {i}"
                )),
            ));
        };
        face_lines(line, no, &mut lines, path, nv, &mut face)?;
        if faces.indices().len() + face.len() > u32::MAX as usize {
            return Err(Error::at_line(
                path,
                no,
                ErrorKind::BadCount("more than 2^32 - 1 face corners".into()),
            ));
        }
        faces.push(&face);
    }
    if let Some((no, _)) = lines.next() {
        return Err(Error::at_line(
            path,
            no,
            ErrorKind::BadCount(format!(
                "data after the {nv} vertices and {nf} faces the header announces"
            )),
        ));
    }
    Ok(PolyMesh {
        positions,
        normals: layout.normals.then_some(normals),
        colors: layout.colors.then_some(colors),
        faces,
    })
}

/// Parses `V F [E]`.
fn counts(line: &[u8], path: &Path, no: u64) -> Result<(u64, u64)> {
    let mut out = [0u64; 3];
    let mut n = 0;
    for t in tokens(line) {
        if n == 3 {
            return Err(syntax(path, no, "extra value after the counts `V F E`", t));
        }
        let Some(v) = parse_int(t) else {
            return Err(syntax(path, no, "expected the counts `V F E`", t));
        };
        if !(0..=u32::MAX as i64).contains(&v) {
            return Err(Error::at_line(
                path,
                no,
                ErrorKind::BadCount(format!("count {v} is negative or larger than 2^32 - 1")),
            ));
        }
        out[n] = v as u64;
        n += 1;
    }
    if n < 2 {
        return Err(Error::at_line(
            path,
            no,
            ErrorKind::Syntax("expected the counts `V F E`".into()),
        ));
    }
    Ok((out[0], out[1]))
}

/// Parses one vertex line into the attribute arrays.
fn vertex(
    line: &[u8],
    no: u64,
    path: &Path,
    layout: Layout,
    positions: &mut Vec<[f64; 3]>,
    normals: &mut Vec<[f64; 3]>,
    colors: &mut Vec<[u8; 3]>,
) -> Result<()> {
    // x y z, normal, up to 4 colour values, 2 texture coordinates: at most 12 tokens.
    let mut t: [&[u8]; 12] = [b""; 12];
    let mut n = 0;
    for tok in tokens(line) {
        if n == t.len() {
            return Err(syntax(path, no, "too many values on a vertex line", tok));
        }
        t[n] = tok;
        n += 1;
    }
    let base = 3 + if layout.normals { 3 } else { 0 } + if layout.texcoords { 2 } else { 0 };
    let ncolor = n.saturating_sub(base);
    let ok = if layout.colors {
        n >= base && (ncolor == 3 || ncolor == 4)
    } else {
        n == base
    };
    if !ok {
        return Err(Error::at_line(
            path,
            no,
            ErrorKind::Syntax(format!(
                "vertex line with {n} values; the header announces {}",
                describe(layout)
            )),
        ));
    }
    let num = |i: usize, what: &str| finite_f64(t[i], path, no, what);
    positions.push([
        num(0, "vertex coordinate")?,
        num(1, "vertex coordinate")?,
        num(2, "vertex coordinate")?,
    ]);
    let mut at = 3;
    if layout.normals {
        normals.push([
            num(3, "normal component")?,
            num(4, "normal component")?,
            num(5, "normal component")?,
        ]);
        at = 6;
    }
    if layout.colors {
        let c = &t[at..at + ncolor];
        let floats = c
            .iter()
            .any(|t| t.iter().any(|&b| matches!(b, b'.' | b'e' | b'E')));
        let mut rgb = [0u8; 3];
        for (k, slot) in rgb.iter_mut().enumerate() {
            let v = num(at + k, "colour component")?;
            *slot = if floats {
                unit_to_u8(v)
            } else {
                v.clamp(0.0, 255.0).round() as u8
            };
        }
        if ncolor == 4 {
            num(at + 3, "colour component")?;
        }
        colors.push(rgb);
        at += ncolor;
    }
    if layout.texcoords {
        num(at, "texture coordinate")?;
        num(at + 1, "texture coordinate")?;
    }
    Ok(())
}

fn describe(layout: Layout) -> String {
    let mut s = String::from("x y z");
    if layout.normals {
        s.push_str(" nx ny nz");
    }
    if layout.colors {
        s.push_str(" r g b [a]");
    }
    if layout.texcoords {
        s.push_str(" s t");
    }
    s
}

/// Parses one face `n i1 … in [colour]` into `face`: it starts on `line` (number `no`) and
/// takes further lines from `more` until its `n` indices are read.
fn face_lines<'a>(
    line: &'a [u8],
    no: u64,
    more: &mut impl Iterator<Item = (u64, &'a [u8])>,
    path: &Path,
    nv: u64,
    face: &mut Vec<u32>,
) -> Result<()> {
    face.clear();
    let mut toks = tokens(line);
    let mut at = no;
    let first = toks.next().unwrap_or_default();
    let n = match parse_int(first) {
        Some(n) if n >= 3 => n as u64,
        Some(n) => {
            return Err(Error::at_line(
                path,
                no,
                ErrorKind::Syntax(format!("face with {n} vertices; at least 3 are needed")),
            ))
        }
        None => return Err(syntax(path, no, "expected a face vertex count", first)),
    };
    for k in 0..n {
        let t = loop {
            if let Some(t) = toks.next() {
                break t;
            }
            match more.next() {
                Some((next_no, next)) => {
                    at = next_no;
                    toks = tokens(next);
                }
                None => {
                    return Err(Error::at_line(
                        path,
                        no,
                        ErrorKind::Syntax(format!("face announces {n} vertices but lists {k}")),
                    ))
                }
            }
        };
        let Some(i) = parse_int(t) else {
            return Err(syntax(path, at, "bad vertex index", t));
        };
        if i < 0 || i as u64 >= nv {
            return Err(Error::at_line(
                path,
                at,
                ErrorKind::IndexOutOfRange {
                    index: i,
                    count: nv,
                },
            ));
        }
        face.push(i as u32);
    }
    for (k, t) in toks.enumerate() {
        if k == 4 || parse_f64(t).is_none() {
            return Err(syntax(
                path,
                at,
                "unexpected value after the face (at most a colour may follow)",
                t,
            ));
        }
    }
    Ok(())
}

/// Writes a mesh as OFF (see the module documentation for the variant chosen).
///
/// Indices are not checked here; [`crate::write_bytes`] checks them first.
pub fn write(mesh: &PolyMesh, out: &mut Vec<u8>) -> std::io::Result<()> {
    let normals = mesh.normals.as_deref();
    let colors = mesh.colors.as_deref();
    out.reserve(mesh.positions.len() * 40 + mesh.faces.indices().len() * 8);
    if colors.is_some() {
        out.push(b'C');
    }
    if normals.is_some() {
        out.push(b'N');
    }
    out.extend_from_slice(b"OFF\n");
    push_u64(out, mesh.positions.len() as u64);
    out.push(b' ');
    push_u64(out, mesh.faces.len() as u64);
    out.extend_from_slice(b" 0\n");
    for (i, p) in mesh.positions.iter().enumerate() {
        push_floats(out, p);
        if let Some(n) = normals.and_then(|n| n.get(i)) {
            out.push(b' ');
            push_floats(out, n);
        }
        if let Some(c) = colors.and_then(|c| c.get(i)) {
            for &v in c {
                out.push(b' ');
                push_u64(out, v as u64);
            }
            out.extend_from_slice(b" 255");
        }
        out.push(b'\n');
    }
    for f in mesh.faces.iter() {
        push_u64(out, f.len() as u64);
        for &v in f {
            out.push(b' ');
            push_u64(out, v as u64);
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
