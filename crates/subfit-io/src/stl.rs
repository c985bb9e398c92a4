//! Stereolithography (STL), ascii and binary little-endian.
//!
//! Detection: a file whose size is exactly `84 + 50·n` for the facet count `n` stored at byte
//! 80 is binary, even when its 80-byte header starts with `solid` (many exporters do that).
//! Otherwise a file starting with `solid` whose first 512 bytes are text is ascii; anything else
//! is read as binary, and its size mismatch is reported.
//!
//! Ascii: `solid [name]`, then facets `facet normal nx ny nz` / `outer loop` / `vertex x y z` …
//! / `endloop` / `endfacet`, then `endsolid [name]`; several solids may follow one another.
//! Keywords are matched case-insensitively and may be split over lines in any way. A loop with
//! more than three vertices is kept as a polygon. Coordinates are parsed as f64.
//!
//! Binary: 80-byte header (ignored), u32 facet count, then per facet a normal and three
//! vertices as f32 and a u16 attribute (ignored).
//!
//! Facet normals are dropped on reading (they are redundant with the winding, and often wrong);
//! they are parsed but may be NaN. Vertex coordinates must be finite. With `weld`, corners with
//! bit-identical coordinates (with `-0.0 == 0.0`) become one vertex, numbered in order of first
//! appearance; without it, every corner is its own vertex. A truncated file is
//! [`ErrorKind::Truncated`] at the facet that is cut (with its byte offset for binary files);
//! nothing is skipped. An STL with no facets gives an empty mesh.
//!
//! Writing: binary (f32, header `subfit binary STL`, which never starts with `solid`) or ascii
//! (coordinates as the shortest decimal of their f32 value); facet normals are computed from
//! the f64 positions; polygons are written as triangle fans; faces with fewer than three vertices
//! are left out.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::path::Path;

use subfit_mesh::{PolyMesh, Polygons};

use crate::error::{Error, ErrorKind, Location, Result};
use crate::text::{check_utf8, finite_f64, line_of, parse_f64, syntax};
use crate::Encoding;

/// Parses a whole STL file (ascii or binary), welding identical corners when `weld` is set.
///
/// Cost: O(file size) time, and memory proportional to the facets present (the stored facet
/// count is only trusted once the file size confirms it).
pub fn read(bytes: &[u8], path: &Path, weld: bool) -> Result<(PolyMesh, Encoding)> {
    if bytes.iter().all(|c| c.is_ascii_whitespace()) {
        return Err(Error::file(path, ErrorKind::Empty));
    }
    if !is_binary_stl(bytes) && looks_ascii(bytes) {
        return Ok((read_ascii(bytes, path, weld)?, Encoding::Ascii));
    }
    Ok((
        read_binary(bytes, path, weld)?,
        Encoding::BinaryLittleEndian,
    ))
}

/// Whether the bytes look like a binary STL (84-byte header + count matching the size).
pub fn is_binary_stl(bytes: &[u8]) -> bool {
    if bytes.len() < 84 {
        return false;
    }
    let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
    84 + 50 * n == bytes.len() as u64
}

/// Starts with `solid` (after blanks) and the first 512 bytes hold no control characters.
fn looks_ascii(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(512)];
    let start = head.iter().take_while(|c| c.is_ascii_whitespace()).count();
    head[start..].len() >= 5
        && head[start..start + 5].eq_ignore_ascii_case(b"solid")
        && head
            .iter()
            .all(|&c| c >= 0x20 || matches!(c, b'\t' | b'\n' | b'\r' | 0x0c))
}

/// Collects corners into vertices, welding them when asked.
struct Builder {
    weld: bool,
    map: HashMap<[u64; 3], u32, BuildHasherDefault<FxHasher>>,
    positions: Vec<[f64; 3]>,
    faces: Polygons,
}

impl Builder {
    fn new(weld: bool, facets: usize) -> Self {
        Self {
            weld,
            map: HashMap::with_capacity_and_hasher(
                if weld { facets / 2 } else { 0 },
                Default::default(),
            ),
            positions: Vec::with_capacity(if weld { facets / 2 } else { facets * 3 }),
            faces: Polygons::with_capacity(facets, facets * 3),
        }
    }

    /// The vertex id of a corner. Fails only past 2^32 - 1 vertices.
    fn corner(&mut self, p: [f64; 3]) -> Option<u32> {
        let next = u32::try_from(self.positions.len()).ok()?;
        if !self.weld {
            self.positions.push(p);
            return Some(next);
        }
        // `+ 0.0` turns -0.0 into 0.0; NaN never reaches here.
        let key = p.map(|c| (c + 0.0).to_bits());
        let id = *self.map.entry(key).or_insert(next);
        if id == next {
            self.positions.push(p);
        }
        Some(id)
    }

    fn finish(self) -> PolyMesh {
        PolyMesh::new(self.positions, self.faces)
    }
}

fn too_many(path: &Path, location: Location) -> Error {
    Error::new(
        path,
        location,
        ErrorKind::BadCount("more than 2^32 - 1 vertices".into()),
    )
}

fn read_binary(bytes: &[u8], path: &Path, weld: bool) -> Result<PolyMesh> {
    if bytes.len() < 84 {
        return Err(Error::new(
            path,
            Location::Byte(bytes.len() as u64),
            ErrorKind::Truncated(format!(
                "a binary STL starts with 84 bytes (header and facet count); the file has {} \
                 (and it is not ascii STL: no `solid` at the start, or binary bytes in it)",
                bytes.len()
            )),
        ));
    }
    let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
    let expected = 84 + 50 * n;
    let len = bytes.len() as u64;
    if len < expected {
        let index = (len - 84) / 50;
        return Err(Error::at_element(
            path,
            "facet",
            index,
            ErrorKind::Truncated(format!(
                "the header announces {n} facets ({expected} bytes); facet {index} starts at \
                 byte {} but the file ends at byte {len}",
                84 + 50 * index
            )),
        ));
    }
    if len > expected {
        return Err(Error::new(
            path,
            Location::Byte(expected),
            ErrorKind::BadCount(format!(
                "the header announces {n} facets ({expected} bytes) but the file has {len} bytes"
            )),
        ));
    }
    let mut b = Builder::new(weld, n as usize);
    for (i, rec) in bytes[84..].chunks_exact(50).enumerate() {
        let mut tri = [0u32; 3];
        for (k, slot) in tri.iter_mut().enumerate() {
            let at = 12 + 12 * k;
            let c = |j: usize| {
                let o = at + 4 * j;
                f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]]) as f64
            };
            let p = [c(0), c(1), c(2)];
            if !p.iter().all(|v| v.is_finite()) {
                return Err(Error::at_element(
                    path,
                    "facet",
                    i as u64,
                    ErrorKind::NonFinite(format!(
                        "vertex {k} is ({}, {}, {}) at byte {}",
                        p[0],
                        p[1],
                        p[2],
                        84 + 50 * i + at
                    )),
                ));
            }
            *slot = b
                .corner(p)
                .ok_or_else(|| too_many(path, Location::Byte(84 + 50 * i as u64)))?;
        }
        b.faces.push(&tri);
    }
    Ok(b.finish())
}

/// A cursor over whitespace-separated tokens that knows its line.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    fn next(&mut self) -> Option<(usize, &'a [u8])> {
        let b = self.bytes;
        while self.pos < b.len() && b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        if self.pos == b.len() {
            return None;
        }
        let start = self.pos;
        while self.pos < b.len() && !b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        Some((start, &b[start..self.pos]))
    }

    /// Skips to the end of the current line (a solid's name).
    fn skip_line(&mut self) {
        let b = self.bytes;
        while self.pos < b.len() && b[self.pos] != b'\n' && b[self.pos] != b'\r' {
            self.pos += 1;
        }
    }
}

/// The ascii reader's state: where it is, for messages.
struct Ascii<'a, 'p> {
    cur: Cursor<'a>,
    path: &'p Path,
    facet: u64,
}

impl<'a> Ascii<'a, '_> {
    fn line(&self, at: usize) -> u64 {
        // Only called on errors: O(file) is fine there.
        line_of(self.cur.bytes, at)
    }

    /// The next token; the end of the file inside a facet is a truncation.
    fn token(&mut self, wanted: &str) -> Result<(usize, &'a [u8])> {
        self.cur.next().ok_or_else(|| {
            Error::at_element(
                self.path,
                "facet",
                self.facet,
                ErrorKind::Truncated(format!(
                    "the file ends inside facet {} (line {}) where {wanted} was expected",
                    self.facet,
                    self.line(self.cur.bytes.len())
                )),
            )
        })
    }

    fn expect(&mut self, kw: &str) -> Result<()> {
        let (at, t) = self.token(&format!("`{kw}`"))?;
        if t.eq_ignore_ascii_case(kw.as_bytes()) {
            Ok(())
        } else {
            Err(syntax(
                self.path,
                self.line(at),
                &format!("expected `{kw}`"),
                t,
            ))
        }
    }

    fn number(&mut self, what: &str) -> Result<f64> {
        let (at, t) = self.token(what)?;
        // The line is counted only for an error (O(file) each: counted for every number it
        // made reading a 3.7 MB ascii STL take minutes).
        match parse_f64(t) {
            Some(v) if v.is_finite() => Ok(v),
            _ => finite_f64(t, self.path, self.line(at), what),
        }
    }
}

fn read_ascii(bytes: &[u8], path: &Path, weld: bool) -> Result<PolyMesh> {
    check_utf8(bytes, path)?;
    // An ascii facet takes well over 100 bytes.
    let mut b = Builder::new(weld, bytes.len() / 128);
    let mut a = Ascii {
        cur: Cursor { bytes, pos: 0 },
        path,
        facet: 0,
    };
    let mut corners = Vec::with_capacity(3);
    while let Some((at, t)) = a.cur.next() {
        if !t.eq_ignore_ascii_case(b"solid") {
            return Err(syntax(path, a.line(at), "expected `solid`", t));
        }
        a.cur.skip_line();
        loop {
            let Some((at, t)) = a.cur.next() else {
                return Err(Error::at_line(
                    path,
                    a.line(bytes.len()),
                    ErrorKind::Truncated(format!("`endsolid` is missing after facet {}", a.facet)),
                ));
            };
            if t.eq_ignore_ascii_case(b"endsolid") {
                a.cur.skip_line();
                break;
            }
            if !t.eq_ignore_ascii_case(b"facet") {
                return Err(syntax(
                    path,
                    a.line(at),
                    "expected `facet` or `endsolid`",
                    t,
                ));
            }
            a.expect("normal")?;
            for _ in 0..3 {
                // Parsed, not kept; NaN normals from degenerate facets are common.
                let (at, t) = a.token("a normal component")?;
                if parse_f64(t).is_none() {
                    return Err(syntax(
                        path,
                        a.line(at),
                        "expected a number (facet normal)",
                        t,
                    ));
                }
            }
            a.expect("outer")?;
            a.expect("loop")?;
            corners.clear();
            loop {
                let (at, t) = a.token("`vertex` or `endloop`")?;
                if t.eq_ignore_ascii_case(b"endloop") {
                    break;
                }
                if !t.eq_ignore_ascii_case(b"vertex") {
                    return Err(syntax(
                        path,
                        a.line(at),
                        "expected `vertex` or `endloop`",
                        t,
                    ));
                }
                let p = [
                    a.number("vertex coordinate")?,
                    a.number("vertex coordinate")?,
                    a.number("vertex coordinate")?,
                ];
                let id = b
                    .corner(p)
                    .ok_or_else(|| too_many(path, Location::Line(a.line(at))))?;
                corners.push(id);
            }
            if corners.len() < 3 {
                return Err(Error::at_element(
                    path,
                    "facet",
                    a.facet,
                    ErrorKind::Syntax(format!(
                        "facet with {} vertices (line {})",
                        corners.len(),
                        a.line(a.cur.pos)
                    )),
                ));
            }
            a.expect("endfacet")?;
            if b.faces.indices().len() + corners.len() > u32::MAX as usize {
                return Err(too_many(path, Location::Line(a.line(a.cur.pos))));
            }
            b.faces.push(&corners);
            a.facet += 1;
        }
    }
    Ok(b.finish())
}

/// Writes the triangles (fans of polygons) of a mesh as STL, binary little-endian or ascii.
///
/// Indices are not checked here; [`crate::write_bytes`] checks them first.
/// Errors: a coordinate outside the f32 range, more than 2^32 - 1 triangles in binary, or a
/// big-endian encoding.
pub fn write(mesh: &PolyMesh, encoding: Encoding, out: &mut Vec<u8>) -> std::io::Result<()> {
    if mesh
        .positions
        .iter()
        .flatten()
        .any(|c| c.is_nan() || c.abs() > f32::MAX as f64)
    {
        return Err(std::io::Error::other(
            "a coordinate is NaN or beyond the f32 range STL stores",
        ));
    }
    let tris = mesh.faces.triangulate_fan();
    let corner = |v: u32| mesh.positions[v as usize];
    match encoding {
        Encoding::BinaryLittleEndian => {
            let n = u32::try_from(tris.len())
                .map_err(|_| std::io::Error::other("more than 2^32 - 1 triangles"))?;
            out.reserve(84 + 50 * tris.len());
            let mut header = [b' '; 80];
            header[..17].copy_from_slice(b"subfit binary STL");
            out.extend_from_slice(&header);
            out.extend_from_slice(&n.to_le_bytes());
            for t in &tris {
                let p = t.map(corner);
                for v in std::iter::once(normal(&p)).chain(p) {
                    for c in v {
                        out.extend_from_slice(&(c as f32).to_le_bytes());
                    }
                }
                out.extend_from_slice(&[0, 0]);
            }
            Ok(())
        }
        Encoding::Ascii => {
            out.reserve(260 * tris.len() + 40);
            out.extend_from_slice(b"solid subfit\n");
            for t in &tris {
                let p = t.map(corner);
                out.extend_from_slice(b"  facet normal");
                push_f32s(out, &normal(&p));
                out.extend_from_slice(b"\n    outer loop\n");
                for v in &p {
                    out.extend_from_slice(b"      vertex");
                    push_f32s(out, v);
                    out.push(b'\n');
                }
                out.extend_from_slice(b"    endloop\n  endfacet\n");
            }
            out.extend_from_slice(b"endsolid subfit\n");
            Ok(())
        }
        Encoding::BinaryBigEndian => Err(std::io::Error::other("STL has no big-endian encoding")),
    }
}

/// Unit normal of a triangle (zero when degenerate).
fn normal(p: &[[f64; 3]; 3]) -> [f64; 3] {
    let u = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
    let v = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len > 0.0 && len.is_finite() {
        n.map(|c| c / len)
    } else {
        [0.0; 3]
    }
}

/// Appends ` x y z` with the shortest decimals of the f32 values.
fn push_f32s(out: &mut Vec<u8>, v: &[f64; 3]) {
    let mut buf = ryu::Buffer::new();
    for &c in v {
        out.push(b' ');
        let c = c as f32;
        if c == 0.0 {
            out.push(b'0');
        } else {
            // Finite: `write` rejects coordinates beyond the f32 range first.
            let s = buf.format(c);
            out.extend_from_slice(s.strip_suffix(".0").unwrap_or(s).as_bytes());
        }
    }
}

/// FxHash (as in rustc): fast, and good enough for coordinate bit patterns.
#[derive(Default)]
struct FxHasher(u64);

impl Hasher for FxHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut b = [0u8; 8];
            b[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(b));
        }
    }

    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }

    fn finish(&self) -> u64 {
        // Coordinates widened from f32 have 29 zero low bits: mix (murmur3 fmix64) so that the
        // table index, taken from the low bits, sees all of them.
        let mut h = self.0;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        h ^ (h >> 33)
    }
}
