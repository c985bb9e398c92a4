//! MNI BIC surface files: the `.obj` of the Montreal Neurological Institute's Brain Imaging
//! Centre tools (bicpl, minc-tools, CIVET, brain-view), which shares its extension with
//! Wavefront OBJ but not its syntax.
//!
//! The ascii polygon object (bicpl's `input_polygons`, described in the MNI "obj file format"
//! note of the BIC) is one stream of blank-separated tokens:
//!
//! ```text
//! P ambient diffuse specular shininess opacity n_points
//! n_points × (x y z)
//! n_points × (nx ny nz)
//! n_items
//! colour_flag colours     0: one RGBA; 1: one RGBA per item; 2: one RGBA per point
//! n_items end indices     cumulative: item i uses indices[end[i-1]..end[i]]
//! end[n_items-1] indices  0-based point indices
//! ```
//!
//! Read: points, normals (kept when finite; a zero normal is kept as written), polygons (at
//! least 3 corners each) and per-point colours (flag 2; RGBA in 0..1, alpha dropped). Every
//! count is checked against the tokens present, and nothing may follow the indices. Other MNI
//! objects (`L` lines, `M` models, `Q` quad meshes, `T` text, `V` markers, `X` pixels) and the
//! binary form are [`ErrorKind::Unsupported`] with a message saying the file is an MNI object,
//! not Wavefront.

use std::path::Path;

use subfit_mesh::{PolyMesh, Polygons};

use crate::error::{Error, ErrorKind, Result};
use crate::text::{finite_f64, parse_f64, parse_int, syntax, tokens, unit_to_u8, NumberedLines};

/// The single-letter object types of MNI files, with what they hold.
const OBJECT_TYPES: [(&[u8], &str); 7] = [
    (b"P", "polygons"),
    (b"L", "lines"),
    (b"M", "a model of several objects"),
    (b"Q", "a quadrilateral mesh"),
    (b"T", "text"),
    (b"V", "markers"),
    (b"X", "pixels"),
];

/// The first two tokens of a file (within its first 256 bytes).
fn head(bytes: &[u8]) -> (Option<&[u8]>, Option<&[u8]>) {
    let mut t = tokens(&bytes[..bytes.len().min(256)]);
    (t.next(), t.next())
}

/// Whether `bytes` starts like an MNI object: an upper-case MNI object letter followed by a
/// number. Wavefront OBJ has no upper-case statement, so this never claims a Wavefront file.
pub(crate) fn is_mni(bytes: &[u8]) -> bool {
    match head(bytes) {
        (Some(kw), Some(next)) => {
            OBJECT_TYPES.iter().any(|(k, _)| *k == kw) && parse_f64(next).is_some()
        }
        _ => false,
    }
}

/// Blank-separated tokens with their 1-based line.
struct Tokens<'a> {
    lines: NumberedLines<'a>,
    line: u64,
    current: std::vec::IntoIter<&'a [u8]>,
}

impl<'a> Tokens<'a> {
    fn next(&mut self) -> Option<(u64, &'a [u8])> {
        loop {
            if let Some(t) = self.current.next() {
                return Some((self.line, t));
            }
            let (no, l) = self.lines.next()?;
            self.line = no;
            self.current = tokens(l).collect::<Vec<_>>().into_iter();
        }
    }
}

/// Reading state: the path for errors and the token stream.
struct Reader<'a, 'p> {
    path: &'p Path,
    toks: Tokens<'a>,
}

impl<'a> Reader<'a, '_> {
    /// The next token, or [`ErrorKind::Truncated`] naming what is missing.
    fn token(&mut self, what: &str) -> Result<(u64, &'a [u8])> {
        self.toks.next().ok_or_else(|| {
            Error::at_line(
                self.path,
                self.toks.line.max(1),
                ErrorKind::Truncated(format!("the MNI surface ends before {what}")),
            )
        })
    }

    fn float(&mut self, what: &str) -> Result<f64> {
        let (no, t) = self.token(what)?;
        finite_f64(t, self.path, no, what)
    }

    /// A count in `0..=limit` (`limit`: what the remaining bytes could hold at most).
    fn count(&mut self, what: &str, limit: u64) -> Result<u64> {
        let (no, t) = self.token(what)?;
        match parse_int(t) {
            Some(n) if n >= 0 && (n as u64) <= limit => Ok(n as u64),
            Some(n) => Err(Error::at_line(
                self.path,
                no,
                ErrorKind::BadCount(format!("{what} {n} (at most {limit} fit in the file)")),
            )),
            None => Err(syntax(self.path, no, &format!("expected {what}"), t)),
        }
    }

    fn triples(&mut self, n: u64, what: &str) -> Result<Vec<[f64; 3]>> {
        let mut out = Vec::with_capacity(n as usize);
        for _ in 0..n {
            out.push([self.float(what)?, self.float(what)?, self.float(what)?]);
        }
        Ok(out)
    }
}

/// Parses an MNI ascii polygon object (see the module documentation); a warning says the file
/// was read as MNI. Cost: O(file size).
pub(crate) fn read(bytes: &[u8], path: &Path, warnings: &mut Vec<String>) -> Result<PolyMesh> {
    if let (Some(kw), _) = head(bytes) {
        if kw != b"P" {
            let what = OBJECT_TYPES
                .iter()
                .find(|(k, _)| *k == kw)
                .map_or("an object", |(_, w)| w);
            return Err(Error::at_line(
                path,
                1,
                ErrorKind::Unsupported(format!(
                    "this looks like an MNI BIC .obj file holding {what} (`{}`), not a \
                     Wavefront OBJ; only MNI polygon surfaces (`P`) are read",
                    String::from_utf8_lossy(kw)
                )),
            ));
        }
    }
    let mut r = Reader {
        path,
        toks: Tokens {
            lines: NumberedLines::new(bytes),
            line: 0,
            current: Vec::new().into_iter(),
        },
    };
    r.token("`P`")?;
    for what in ["ambient", "diffuse", "specular", "shininess", "opacity"] {
        r.float(&format!("the surface property `{what}`"))?;
    }
    // Every number takes at least two bytes (a digit and a separator).
    let room = bytes.len() as u64 / 2;
    let np = r.count("the point count", (room / 6).min(u32::MAX as u64))?;
    let positions = r.triples(np, "point coordinate")?;
    let normals = r.triples(np, "normal component")?;
    // A polygon takes an end index and three indices: at least 8 bytes.
    let n_items = r.count("the polygon count", room / 4)?;
    let colors = colours(&mut r, n_items, np)?;
    let faces = polygons(&mut r, n_items, np, room)?;
    if let Some((no, t)) = r.toks.next() {
        return Err(syntax(
            path,
            no,
            "data after the last polygon index of the MNI surface",
            t,
        ));
    }
    warnings.push(
        "read as an MNI BIC polygon surface (an `.obj` of the MNI tools, not Wavefront)".into(),
    );
    Ok(PolyMesh {
        positions,
        normals: Some(normals),
        colors,
        faces,
    })
}

/// The end indices and indices of `n_items` polygons over `np` points (`room`: the most
/// tokens the file can hold).
fn polygons(r: &mut Reader<'_, '_>, n_items: u64, np: u64, room: u64) -> Result<Polygons> {
    let path = r.path;
    let mut ends = Vec::with_capacity(n_items as usize);
    let mut prev = 0u64;
    for i in 0..n_items {
        let (no, t) = r.token("the polygon end indices")?;
        let end = parse_int(t)
            .filter(|&e| e >= 0)
            .ok_or_else(|| syntax(path, no, "expected a polygon end index", t))?
            as u64;
        if end < prev + 3 || end > room {
            return Err(Error::at_line(
                path,
                no,
                ErrorKind::BadCount(format!(
                    "polygon {i} ends at index {end} after starting at {prev}: a polygon needs \
                     at least 3 corners, and ends must increase"
                )),
            ));
        }
        ends.push(end);
        prev = end;
    }
    let mut faces = Polygons::with_capacity(n_items as usize, prev as usize);
    let mut face = Vec::new();
    let mut start = 0u64;
    for end in ends {
        face.clear();
        for _ in start..end {
            let (no, t) = r.token("the polygon indices")?;
            match parse_int(t) {
                Some(i) if i >= 0 && (i as u64) < np => face.push(i as u32),
                Some(i) => {
                    return Err(Error::at_line(
                        path,
                        no,
                        ErrorKind::IndexOutOfRange {
                            index: i,
                            count: np,
                        },
                    ))
                }
                None => return Err(syntax(path, no, "expected a point index", t)),
            }
        }
        faces.push(&face);
        start = end;
    }
    Ok(faces)
}

/// The colour flag and its colours; per-point colours are returned, the others skipped.
fn colours(r: &mut Reader<'_, '_>, n_items: u64, np: u64) -> Result<Option<Vec<[u8; 3]>>> {
    let (no, t) = r.token("the colour flag")?;
    let (n, per_point) = match parse_int(t) {
        Some(0) => (1, false),
        Some(1) => (n_items, false),
        Some(2) => (np, true),
        _ => return Err(syntax(r.path, no, "expected the colour flag 0, 1 or 2", t)),
    };
    let mut out = Vec::with_capacity(if per_point { np as usize } else { 0 });
    for _ in 0..n {
        let mut rgba = [0.0; 4];
        for c in &mut rgba {
            // Not checked for finiteness: a NaN colour reads as 0 (colours do not shape the fit).
            let (no, tok) = r.token("colour component")?;
            *c = parse_f64(tok)
                .ok_or_else(|| syntax(r.path, no, "expected a number (colour component)", tok))?;
        }
        if per_point {
            out.push([rgba[0], rgba[1], rgba[2]].map(unit_to_u8));
        }
    }
    Ok(per_point.then_some(out))
}
