//! Object File Format (Geomview OFF) as text.
//!
//! Supported on reading:
//! - The header keyword `[ST][C][N]OFF` (`OFF`, `COFF`, `NOFF`, `CNOFF`, `NCOFF`, `STOFF`…),
//!   alone on its line or followed by the counts; the keyword may also be missing (the file
//!   starts with the counts). `4OFF`, `nOFF` (other dimensions) and `OFF BINARY` are
//!   [`ErrorKind::Unsupported`].
//! - Counts `V F [E]` (the edge count is ignored), on the header line or the next one.
//! - One vertex per line: `x y z [nx ny nz] [r g b [a]] [s t]`, in that order, with the
//!   normal when the keyword has `N`, the colour when it has `C`, texture coordinates (ignored)
//!   when it has `ST`. Colours are 3 or 4 values: integers in 0..255, or floats in 0..1 when
//!   any of them is written with a `.` or an exponent; alpha is dropped and values are clamped.
//! - One face per line: `n i1 … in`, 0-based indices, `n >= 3`, optionally followed by up to
//!   four colour values, which are ignored.
//! - `#` comments anywhere (to the end of the line) and blank lines.
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
use crate::text::{
    check_utf8, finite_f64, parse_f64, parse_i64, parse_int, push_f64_exact, push_u64,
    strip_hash_comment, syntax, tokens, unit_to_u8, NumberedLines,
};

/// What the header keyword announces per vertex.
#[derive(Clone, Copy, Debug, Default)]
struct Layout {
    normals: bool,
    colors: bool,
    texcoords: bool,
}

/// Parses a whole OFF file.
///
/// Cost: O(file size) time; memory proportional to the data present (the counts are never
/// trusted for allocation beyond what the file size allows).
pub fn read(bytes: &[u8], path: &Path) -> Result<PolyMesh> {
    check_utf8(bytes, path)?;
    // Non-blank lines with comments removed.
    let mut lines = NumberedLines::new(bytes)
        .map(|(no, l)| (no, strip_hash_comment(l)))
        .filter(|(_, l)| l.iter().any(|c| !c.is_ascii_whitespace()));
    let Some((first_no, first)) = lines.next() else {
        return Err(Error::file(path, ErrorKind::Empty));
    };
    let mut toks = tokens(first);
    let kw = toks.next().unwrap_or_default();
    let (layout, count_line) = if parse_i64(kw).is_some() {
        (Layout::default(), (first_no, first))
    } else {
        let layout = keyword(kw, path, first_no)?;
        let rest: Vec<&[u8]> = toks.collect();
        if let Some(&t) = rest.first() {
            if t.eq_ignore_ascii_case(b"BINARY") {
                return Err(Error::at_line(
                    path,
                    first_no,
                    ErrorKind::Unsupported("binary OFF".into()),
                ));
            }
        }
        if rest.is_empty() {
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
            let at = kw.len() + first.windows(kw.len()).position(|w| w == kw).unwrap_or(0);
            (layout, (first_no, &first[at..]))
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
        face_line(line, no, path, nv, &mut face)?;
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

/// Decodes `[ST][C][N][4][n]OFF`.
fn keyword(kw: &[u8], path: &Path, no: u64) -> Result<Layout> {
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

/// Parses one face line `n i1 … in [colour]` into `face`.
fn face_line(line: &[u8], no: u64, path: &Path, nv: u64, face: &mut Vec<u32>) -> Result<()> {
    face.clear();
    let mut toks = tokens(line);
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
        let Some(t) = toks.next() else {
            return Err(Error::at_line(
                path,
                no,
                ErrorKind::Syntax(format!("face announces {n} vertices but lists {k}")),
            ));
        };
        let Some(i) = parse_int(t) else {
            return Err(syntax(path, no, "bad vertex index", t));
        };
        if i < 0 || i as u64 >= nv {
            return Err(Error::at_line(
                path,
                no,
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
                no,
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
