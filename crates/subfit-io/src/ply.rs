//! Stanford PLY (Turk 1994; the format as written by Stanford's `ply` tools, VCG/MeshLab and
//! Cyberware): reader and writer.
//!
//! **Reading** accepts `format ascii 1.0`, `binary_little_endian 1.0` and
//! `binary_big_endian 1.0`; header lines may end in `\n` or `\r\n`; `comment` and `obj_info`
//! lines are ignored. Properties may come in any order and have any scalar type (`char`,
//! `uchar`, `short`, `ushort`, `int`, `uint`, `float`, `double` and the aliases `int8` …
//! `float64`). What is taken:
//! - `element vertex`: `x`, `y`, `z` (required, any scalar type); `nx`, `ny`, `nz` when all three
//!   are present; `red`, `green`, `blue` (or `diffuse_red` …) when all three are present —
//!   integer colours are clamped to 0..=255, float colours in 0..1 are scaled by 255.
//! - `element face`: a list property `vertex_indices` (or `vertex_index`) with any integer count
//!   and index types; faces of every size are kept as they are.
//! - `element tristrips`: a list `vertex_indices`; `-1` ends a strip, every odd triangle of a
//!   strip is flipped to keep the orientation, and triangles with two equal corners (the
//!   "swap" triangles strip encoders insert) are dropped.
//! - every other element is skipped, including its list properties.
//!
//! Ascii values keep the precision of their text whatever type the header declares.
//!
//! Every problem is an [`Error`]: ascii files report the 1-based line ([`crate::Location::Line`], the
//! message names the element), binary files the element ([`crate::Location::Element`], the message
//! gives the byte offset). The reader never panics, and never allocates more than the
//! remaining bytes could hold, whatever the counts in the header say. Non-finite positions and
//! normals and out-of-range indices are errors.
//!
//! **Writing** produces `vertex` with `double` coordinates (`float` when `single_precision`),
//! normals and `uchar` colours when present, and `face` as `list uchar int vertex_indices`
//! (`ushort`/`uint` counts for faces of more than 255/65535 corners, `uint` indices past
//! `i32::MAX` vertices). Ascii output prints the shortest decimal that reads back exactly.
//!
//! This is a parser of our own rather than the `ply-rs-bw` crate: we need element- and
//! line-level error locations, a no-panic guarantee under fuzzing with allocation capped by the
//! data, `tristrips`, and I/O-bound speed on fixed-layout binary records.

use std::io::Write as _;
use std::path::Path;

use subfit_mesh::{PolyMesh, Polygons};

use crate::error::{Error, ErrorKind, Result};
use crate::text::{parse_f64, parse_i64, push_f64, tokens, NumberedLines};
use crate::Encoding;

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn from_name(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }
}

/// `N` bytes from the front of `b` in little-endian order. The caller guarantees `b.len() >= N`.
fn bytes<const N: usize>(b: &[u8], big: bool) -> [u8; N] {
    let mut a = [0u8; N];
    a.copy_from_slice(&b[..N]);
    if big {
        a.reverse();
    }
    a
}

/// Decodes a binary scalar from the front of `b` (at least `s.size()` bytes) as f64.
#[inline]
fn bin_f64(s: Scalar, b: &[u8], big: bool) -> f64 {
    match s {
        Scalar::F32 => f32::from_le_bytes(bytes(b, big)) as f64,
        Scalar::F64 => f64::from_le_bytes(bytes(b, big)),
        _ => bin_i64(s, b, big) as f64,
    }
}

/// Decodes a binary integer scalar from the front of `b` (floats are truncated; callers only
/// pass integer types).
#[inline]
fn bin_i64(s: Scalar, b: &[u8], big: bool) -> i64 {
    match s {
        Scalar::I8 => b[0] as i8 as i64,
        Scalar::U8 => b[0] as i64,
        Scalar::I16 => i16::from_le_bytes(bytes(b, big)) as i64,
        Scalar::U16 => u16::from_le_bytes(bytes(b, big)) as i64,
        Scalar::I32 => i32::from_le_bytes(bytes(b, big)) as i64,
        Scalar::U32 => u32::from_le_bytes(bytes(b, big)) as i64,
        Scalar::F32 | Scalar::F64 => bin_f64(s, b, big) as i64,
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ty {
    Scalar(Scalar),
    /// `list <count> <item>`.
    List(Scalar, Scalar),
}

#[derive(Clone, Debug)]
struct Property {
    name: String,
    ty: Ty,
}

/// What a property feeds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Slot {
    Skip,
    Coord(usize),
    Normal(usize),
    Color(usize),
    Indices,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Role {
    Vertex,
    Face,
    Strips,
    Other,
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Property>,
    /// 1-based header line of the `element` statement.
    line: u64,
    role: Role,
    slots: Vec<Slot>,
}

impl Element {
    /// Smallest number of bytes one binary record can take (lists counted as empty).
    fn min_binary_size(&self) -> usize {
        self.props
            .iter()
            .map(|p| match p.ty {
                Ty::Scalar(s) => s.size(),
                Ty::List(c, _) => c.size(),
            })
            .sum()
    }

    fn fixed_size(&self) -> bool {
        self.props.iter().all(|p| matches!(p.ty, Ty::Scalar(_)))
    }
}

struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Byte offset of the first data byte.
    data_start: usize,
    /// Number of header lines (the data starts on the next line for ascii).
    lines: u64,
    has_normals: bool,
    has_colors: bool,
    vertex_count: u64,
}

fn bad_header(path: &Path, line: u64, msg: impl Into<String>) -> Error {
    Error::at_line(path, line, ErrorKind::BadHeader(msg.into()))
}

/// Parses the header, up to and including `end_header`.
fn parse_header(bytes: &[u8], path: &Path) -> Result<Header> {
    let mut pos = 0usize;
    let mut line_no = 0u64;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        if pos >= bytes.len() {
            return Err(Error::at_line(
                path,
                line_no + 1,
                ErrorKind::Truncated("the header ends without `end_header`".into()),
            ));
        }
        let rest = &bytes[pos..];
        let (raw, next) = match rest.iter().position(|&c| c == b'\n') {
            Some(i) => (&rest[..i], pos + i + 1),
            None => (rest, bytes.len()),
        };
        pos = next;
        line_no += 1;
        let text = std::str::from_utf8(raw)
            .map_err(|_| bad_header(path, line_no, "the header is not UTF-8 text"))?;
        let text = text.trim();
        if line_no == 1 {
            if text != "ply" {
                return Err(bad_header(path, 1, "missing `ply` magic on the first line"));
            }
            continue;
        }
        let mut toks = text.split_ascii_whitespace();
        let Some(keyword) = toks.next() else { continue };
        let toks: Vec<&str> = toks.collect();
        match keyword {
            "comment" | "obj_info" => {}
            "format" => {
                if encoding.is_some() {
                    return Err(bad_header(path, line_no, "a second `format` line"));
                }
                encoding = Some(parse_format(&toks).ok_or_else(|| {
                    bad_header(
                        path,
                        line_no,
                        format!(
                            "bad format line `{text}` (expected `format ascii|binary_little_endian|binary_big_endian 1.0`)"
                        ),
                    )
                })?);
            }
            "element" => {
                let [name, count] = toks[..] else {
                    return Err(bad_header(
                        path,
                        line_no,
                        format!("bad element line `{text}` (expected `element <name> <count>`)"),
                    ));
                };
                let count = parse_count(count).map_err(|k| Error::at_line(path, line_no, k))?;
                if elements.iter().any(|e| e.name == name) {
                    return Err(bad_header(
                        path,
                        line_no,
                        format!("element `{name}` declared twice"),
                    ));
                }
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                    line: line_no,
                    role: Role::Other,
                    slots: Vec::new(),
                });
            }
            "property" => {
                let Some(el) = elements.last_mut() else {
                    return Err(bad_header(path, line_no, "`property` before any `element`"));
                };
                let prop = parse_property(&toks).map_err(|m| bad_header(path, line_no, m))?;
                if el.props.iter().any(|p| p.name == prop.name) {
                    return Err(bad_header(
                        path,
                        line_no,
                        format!("property `{}` declared twice in `{}`", prop.name, el.name),
                    ));
                }
                el.props.push(prop);
            }
            "end_header" => break,
            other => {
                let shown: String = other.chars().take(40).collect();
                return Err(bad_header(
                    path,
                    line_no,
                    format!("unknown header keyword `{shown}`"),
                ));
            }
        }
    }
    let encoding = encoding
        .ok_or_else(|| bad_header(path, line_no, "no `format` line before `end_header`"))?;
    let mut header = Header {
        encoding,
        elements,
        data_start: pos,
        lines: line_no,
        has_normals: false,
        has_colors: false,
        vertex_count: 0,
    };
    plan(&mut header, path)?;
    Ok(header)
}

fn parse_format(toks: &[&str]) -> Option<Encoding> {
    let [enc, version] = toks[..] else {
        return None;
    };
    if !matches!(version, "1.0" | "1" | "1.00") {
        return None;
    }
    match enc {
        "ascii" => Some(Encoding::Ascii),
        "binary_little_endian" => Some(Encoding::BinaryLittleEndian),
        "binary_big_endian" => Some(Encoding::BinaryBigEndian),
        _ => None,
    }
}

fn parse_count(tok: &str) -> std::result::Result<u64, ErrorKind> {
    let digits = tok.strip_prefix('-').unwrap_or(tok);
    if digits.is_empty() || !digits.bytes().all(|c| c.is_ascii_digit()) {
        let shown: String = tok.chars().take(40).collect();
        return Err(ErrorKind::BadHeader(format!(
            "element count `{shown}` is not an integer"
        )));
    }
    if tok.starts_with('-') && digits.bytes().any(|c| c != b'0') {
        return Err(ErrorKind::BadCount(format!("negative element count {tok}")));
    }
    digits
        .parse::<u64>()
        .map_err(|_| ErrorKind::BadCount(format!("element count {tok} is too large")))
}

fn scalar(name: &str) -> std::result::Result<Scalar, String> {
    Scalar::from_name(name).ok_or_else(|| {
        let shown: String = name.chars().take(40).collect();
        format!("unknown type `{shown}`")
    })
}

fn parse_property(toks: &[&str]) -> std::result::Result<Property, String> {
    match toks {
        ["list", count, item, name] => {
            let count = scalar(count)?;
            let item = scalar(item)?;
            if count.is_float() {
                return Err(format!(
                    "list `{name}` has a floating-point count type"
                ));
            }
            Ok(Property {
                name: name.to_string(),
                ty: Ty::List(count, item),
            })
        }
        [ty, name] if *ty != "list" => Ok(Property {
            name: name.to_string(),
            ty: Ty::Scalar(scalar(ty)?),
        }),
        _ => Err(format!(
            "bad property line `property {}` (expected `property <type> <name>` or `property list <count type> <item type> <name>`)",
            toks.join(" ")
        )),
    }
}

/// Decides what each element and property feeds, and checks that the vertex element is usable.
fn plan(h: &mut Header, path: &Path) -> Result<()> {
    let mut seen_vertex = false;
    for el in &mut h.elements {
        el.slots = vec![Slot::Skip; el.props.len()];
        let find = |names: &[&str]| {
            el.props
                .iter()
                .position(|p| names.contains(&p.name.as_str()))
        };
        match el.name.as_str() {
            "vertex" => {
                seen_vertex = true;
                el.role = Role::Vertex;
                h.vertex_count = el.count;
                let scalar_of = |i: usize| matches!(el.props[i].ty, Ty::Scalar(_));
                let mut coords = [0usize; 3];
                for (k, name) in ["x", "y", "z"].into_iter().enumerate() {
                    match find(&[name]) {
                        Some(i) if scalar_of(i) => coords[k] = i,
                        Some(_) => {
                            return Err(bad_header(
                                path,
                                el.line,
                                format!("vertex property `{name}` is a list"),
                            ))
                        }
                        None => {
                            return Err(bad_header(
                                path,
                                el.line,
                                format!("the vertex element has no `{name}` property"),
                            ))
                        }
                    }
                }
                let group = |names: [&[&str]; 3]| -> Option<[usize; 3]> {
                    let a = find(names[0]).filter(|&i| scalar_of(i))?;
                    let b = find(names[1]).filter(|&i| scalar_of(i))?;
                    let c = find(names[2]).filter(|&i| scalar_of(i))?;
                    Some([a, b, c])
                };
                let normals = group([&["nx"], &["ny"], &["nz"]]);
                let colors = group([
                    &["red", "diffuse_red"],
                    &["green", "diffuse_green"],
                    &["blue", "diffuse_blue"],
                ]);
                for k in 0..3 {
                    el.slots[coords[k]] = Slot::Coord(k);
                    if let Some(n) = normals {
                        el.slots[n[k]] = Slot::Normal(k);
                    }
                    if let Some(c) = colors {
                        el.slots[c[k]] = Slot::Color(k);
                    }
                }
                h.has_normals = normals.is_some();
                h.has_colors = colors.is_some();
            }
            "face" | "tristrips" => {
                el.role = if el.name == "face" {
                    Role::Face
                } else {
                    Role::Strips
                };
                let Some(i) = find(&["vertex_indices", "vertex_index"]) else {
                    return Err(bad_header(
                        path,
                        el.line,
                        format!("the {} element has no `vertex_indices` list", el.name),
                    ));
                };
                match el.props[i].ty {
                    Ty::List(_, item) if !item.is_float() => el.slots[i] = Slot::Indices,
                    _ => {
                        return Err(bad_header(
                            path,
                            el.line,
                            format!(
                                "{}: `{}` must be a list of integers",
                                el.name, el.props[i].name
                            ),
                        ))
                    }
                }
            }
            _ => {}
        }
    }
    if !seen_vertex {
        return Err(bad_header(path, h.lines, "no `vertex` element"));
    }
    Ok(())
}

/// The values of one record that matter, filled by the ascii or binary decoder.
#[derive(Default)]
struct Record {
    p: [f64; 3],
    n: [f64; 3],
    c: [u8; 3],
    /// The index list (face corners or strip indices, `-1` included).
    list: Vec<i64>,
}

/// Converts a colour value of type `s` to 8 bits.
#[inline]
fn color8(v: f64, s: Scalar) -> u8 {
    let v = if s.is_float() { (v * 255.0).round() } else { v };
    // `as` saturates (NaN → 0).
    v.clamp(0.0, 255.0) as u8
}

/// The mesh being built.
struct Sink {
    positions: Vec<[f64; 3]>,
    normals: Option<Vec<[f64; 3]>>,
    colors: Option<Vec<[u8; 3]>>,
    faces: Polygons,
    vertex_count: u64,
    face: Vec<u32>,
}

const AXES: [&str; 3] = ["x", "y", "z"];
const NORMAL_AXES: [&str; 3] = ["nx", "ny", "nz"];

/// `NonFinite` naming the first non-finite component of vertex `index`.
fn check_finite(v: &[f64; 3], names: [&str; 3], index: u64) -> std::result::Result<(), ErrorKind> {
    match v.iter().zip(names).find(|(c, _)| !c.is_finite()) {
        Some((c, name)) => Err(ErrorKind::NonFinite(format!(
            "{name} = {c} in vertex {index}"
        ))),
        None => Ok(()),
    }
}

impl Sink {
    fn reserve(&mut self, role: Role, n: usize) {
        match role {
            Role::Vertex => {
                self.positions.reserve(n);
                if let Some(v) = &mut self.normals {
                    v.reserve(n);
                }
                if let Some(v) = &mut self.colors {
                    v.reserve(n);
                }
            }
            // Only before the first face: a `tristrips` element may already have filled it.
            Role::Face if self.faces.is_empty() => {
                self.faces = Polygons::with_capacity(n, n.saturating_mul(3))
            }
            Role::Face | Role::Strips | Role::Other => {}
        }
    }

    /// Stores a finished record of an element with the given role (`index`: its 0-based index,
    /// for messages).
    fn finish(
        &mut self,
        role: Role,
        rec: &Record,
        index: u64,
    ) -> std::result::Result<(), ErrorKind> {
        match role {
            Role::Vertex => {
                check_finite(&rec.p, AXES, index)?;
                self.positions.push(rec.p);
                if let Some(v) = &mut self.normals {
                    check_finite(&rec.n, NORMAL_AXES, index)?;
                    v.push(rec.n);
                }
                if let Some(v) = &mut self.colors {
                    v.push(rec.c);
                }
            }
            Role::Face => {
                self.face.clear();
                for &i in &rec.list {
                    self.face.push(self.check_index(i)?);
                }
                self.room_for(self.face.len())?;
                self.faces.push(&self.face);
            }
            Role::Strips => self.strips(&rec.list)?,
            Role::Other => {}
        }
        Ok(())
    }

    /// Whether `n` more corners still fit the `u32` offsets of [`Polygons`].
    #[inline]
    fn room_for(&self, n: usize) -> std::result::Result<(), ErrorKind> {
        if self.faces.indices().len() + n > u32::MAX as usize {
            return Err(ErrorKind::BadCount(
                "more than 2^32 - 1 face corners in total".into(),
            ));
        }
        Ok(())
    }

    #[inline]
    fn check_index(&self, i: i64) -> std::result::Result<u32, ErrorKind> {
        if i < 0 || i as u64 >= self.vertex_count || i > u32::MAX as i64 {
            return Err(ErrorKind::IndexOutOfRange {
                index: i,
                count: self.vertex_count,
            });
        }
        Ok(i as u32)
    }

    /// Turns one `tristrips` list into triangles: `-1` restarts, odd triangles are flipped,
    /// triangles with a repeated corner are dropped.
    fn strips(&mut self, list: &[i64]) -> std::result::Result<(), ErrorKind> {
        for &i in list {
            if i != -1 {
                self.check_index(i)?;
            }
        }
        if self.faces.is_empty() {
            // At most one triangle per index; `list` is bounded by the data already read.
            self.faces = Polygons::with_capacity(list.len(), list.len().saturating_mul(3));
        }
        for strip in list.split(|&i| i == -1) {
            for j in 2..strip.len() {
                // Checked above: every entry is in 0..vertex_count <= u32::MAX.
                let (a, b, c) = (strip[j - 2] as u32, strip[j - 1] as u32, strip[j] as u32);
                if a == b || b == c || a == c {
                    continue;
                }
                self.room_for(3)?;
                if j % 2 == 0 {
                    self.faces.push(&[a, b, c]);
                } else {
                    self.faces.push(&[b, a, c]);
                }
            }
        }
        Ok(())
    }
}

/// Parses a whole PLY file (see the module doc for what is supported).
///
/// Returns the mesh (positions, optional normals and colours, faces from `face` and/or
/// `tristrips`) and the file's encoding. Cost: O(file size); memory O(mesh size).
///
/// Errors: [`ErrorKind::Empty`], [`ErrorKind::BadHeader`] (missing magic, bad `format`, unknown
/// type, missing `x`/`y`/`z`, non-UTF-8 header…), [`ErrorKind::BadCount`] (negative counts, an
/// element count the remaining bytes cannot hold, negative list counts),
/// [`ErrorKind::Truncated`], [`ErrorKind::Syntax`] (ascii), [`ErrorKind::IndexOutOfRange`],
/// [`ErrorKind::NonFinite`]. Never panics.
pub fn read(bytes: &[u8], path: &Path) -> Result<(PolyMesh, Encoding)> {
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
    };
    match header.encoding {
        Encoding::Ascii => read_ascii(&header, data, path, &mut sink)?,
        Encoding::BinaryLittleEndian => read_binary(&header, data, false, path, &mut sink)?,
        Encoding::BinaryBigEndian => read_binary(&header, data, true, path, &mut sink)?,
    }
    let mesh = PolyMesh {
        positions: sink.positions,
        normals: sink.normals,
        colors: sink.colors,
        faces: sink.faces,
    };
    Ok((mesh, header.encoding))
}

// ---------------------------------------------------------------------------------------------
// ascii

fn read_ascii(h: &Header, data: &[u8], path: &Path, sink: &mut Sink) -> Result<()> {
    let mut lines = NumberedLines::new(data);
    let mut rec = Record::default();
    let mut last_line = h.lines;
    for el in &h.elements {
        if el.props.is_empty() {
            continue;
        }
        // Every ascii value takes at least two bytes (digit and separator).
        let room = data.len() / (2 * el.props.len());
        sink.reserve(el.role, (el.count.min(room as u64)) as usize);
        for index in 0..el.count {
            let (line, text) = loop {
                match lines.next() {
                    None => {
                        return Err(Error::at_line(
                            path,
                            last_line + 1,
                            ErrorKind::Truncated(format!(
                                "{} {index} is missing (the header declares {})",
                                el.name, el.count
                            )),
                        ))
                    }
                    Some((n, t)) if t.iter().all(|c| c.is_ascii_whitespace()) => {
                        last_line = h.lines + n;
                    }
                    Some((n, t)) => break (h.lines + n, t),
                }
            };
            last_line = line;
            ascii_record(el, index, line, text, path, &mut rec)?;
            sink.finish(el.role, &rec, index)
                .map_err(|k| Error::at_line(path, line, k))?;
        }
    }
    Ok(())
}

/// Decodes one ascii element line into `rec`.
fn ascii_record(
    el: &Element,
    index: u64,
    line: u64,
    text: &[u8],
    path: &Path,
    rec: &mut Record,
) -> Result<()> {
    let mut toks = tokens(text);
    let name = &el.name;
    let missing = |p: &Property| {
        Error::at_line(
            path,
            line,
            ErrorKind::Syntax(format!(
                "{name} {index}: no value for property `{}` (the line ends early)",
                p.name
            )),
        )
    };
    for (p, &slot) in el.props.iter().zip(&el.slots) {
        match p.ty {
            Ty::Scalar(s) => {
                let tok = toks.next().ok_or_else(|| missing(p))?;
                if slot == Slot::Skip {
                    continue;
                }
                let v = parse_f64(tok).ok_or_else(|| {
                    crate::text::syntax(
                        path,
                        line,
                        &format!("{name} {index}: `{}` is not a number", p.name),
                        tok,
                    )
                })?;
                match slot {
                    Slot::Coord(k) => rec.p[k] = v,
                    Slot::Normal(k) => rec.n[k] = v,
                    Slot::Color(k) => rec.c[k] = color8(v, s),
                    Slot::Skip | Slot::Indices => {}
                }
            }
            Ty::List(_, _) => {
                let tok = toks.next().ok_or_else(|| missing(p))?;
                let n = ascii_int(tok).ok_or_else(|| {
                    crate::text::syntax(
                        path,
                        line,
                        &format!(
                            "{name} {index}: list count of `{}` is not an integer",
                            p.name
                        ),
                        tok,
                    )
                })?;
                if n < 0 {
                    return Err(Error::at_line(
                        path,
                        line,
                        ErrorKind::BadCount(format!(
                            "{name} {index}: negative list count {n} for `{}`",
                            p.name
                        )),
                    ));
                }
                let short = |got: i64| {
                    Error::at_line(
                        path,
                        line,
                        ErrorKind::BadCount(format!(
                            "{name} {index}: list `{}` announces {n} values but the line holds {got}",
                            p.name
                        )),
                    )
                };
                if slot == Slot::Indices {
                    rec.list.clear();
                    for got in 0..n {
                        let tok = toks.next().ok_or_else(|| short(got))?;
                        let v = ascii_int(tok).ok_or_else(|| {
                            crate::text::syntax(
                                path,
                                line,
                                &format!("{name} {index}: vertex index is not an integer"),
                                tok,
                            )
                        })?;
                        rec.list.push(v);
                    }
                } else {
                    for got in 0..n {
                        toks.next().ok_or_else(|| short(got))?;
                    }
                }
            }
        }
    }
    if toks.next().is_some() {
        return Err(Error::at_line(
            path,
            line,
            ErrorKind::Syntax(format!(
                "{name} {index}: more values than the header declares"
            )),
        ));
    }
    Ok(())
}

/// An integer token; also accepts integral floats such as `3.0`, which some writers emit.
fn ascii_int(tok: &[u8]) -> Option<i64> {
    parse_i64(tok).or_else(|| {
        let v = parse_f64(tok)?;
        (v.fract() == 0.0 && v.abs() < 9.0e15).then_some(v as i64)
    })
}

// ---------------------------------------------------------------------------------------------
// binary

fn read_binary(h: &Header, data: &[u8], big: bool, path: &Path, sink: &mut Sink) -> Result<()> {
    let base = h.data_start as u64;
    let file_len = base + data.len() as u64;
    let mut pos = 0usize;
    let mut rec = Record::default();
    for el in &h.elements {
        let min = el.min_binary_size();
        if min == 0 || el.count == 0 {
            continue;
        }
        let remaining = data.len() - pos;
        let room = (remaining / min) as u64;
        if el.count > room {
            return Err(Error::at_element(
                path,
                &el.name,
                room,
                ErrorKind::BadCount(format!(
                    "the header declares {} `{}` elements of at least {min} bytes, but the {remaining} bytes left from byte {} hold at most {room} (truncated file or wrong count)",
                    el.count,
                    el.name,
                    base + pos as u64
                )),
            ));
        }
        // From here on `count <= room`, so counts fit in usize and reservations are bounded.
        let count = el.count as usize;
        if el.role == Role::Other && el.fixed_size() {
            pos += count * min;
            continue;
        }
        sink.reserve(el.role, count);
        if el.fixed_size() {
            pos = binary_fixed(el, &data[pos..pos + count * min], big, path, sink, &mut rec)
                .map(|()| pos + count * min)?;
            continue;
        }
        for index in 0..el.count {
            let at = |pos: usize| base + pos as u64;
            pos = binary_record(el, data, pos, big, &mut rec).map_err(|e| {
                let kind = match e {
                    BinError::Short(p, msg) => ErrorKind::Truncated(format!(
                        "{msg} at byte {}, but the file ends at byte {file_len}",
                        at(p)
                    )),
                    BinError::NegativeCount(p, msg) => {
                        ErrorKind::BadCount(format!("{msg} at byte {}", at(p)))
                    }
                };
                Error::at_element(path, &el.name, index, kind)
            })?;
            sink.finish(el.role, &rec, index)
                .map_err(|k| Error::at_element(path, &el.name, index, k))?;
        }
    }
    Ok(())
}

/// Decodes `count` fixed-size records laid out back to back in `block` (exactly
/// `count * record size` bytes).
fn binary_fixed(
    el: &Element,
    block: &[u8],
    big: bool,
    path: &Path,
    sink: &mut Sink,
    rec: &mut Record,
) -> Result<()> {
    // (offset, type, slot) of the properties that are used.
    let mut used = Vec::new();
    let mut off = 0;
    for (p, &slot) in el.props.iter().zip(&el.slots) {
        if let Ty::Scalar(s) = p.ty {
            if slot != Slot::Skip {
                used.push((off, s, slot));
            }
            off += s.size();
        }
    }
    if off == 0 {
        return Ok(());
    }
    for (index, r) in block.chunks_exact(off).enumerate() {
        for &(o, s, slot) in &used {
            let v = bin_f64(s, &r[o..], big);
            match slot {
                Slot::Coord(k) => rec.p[k] = v,
                Slot::Normal(k) => rec.n[k] = v,
                Slot::Color(k) => rec.c[k] = color8(v, s),
                Slot::Skip | Slot::Indices => {}
            }
        }
        sink.finish(el.role, rec, index as u64)
            .map_err(|k| Error::at_element(path, &el.name, index as u64, k))?;
    }
    Ok(())
}

/// Why a binary record could not be decoded: the position (relative to the data start) and
/// what was being read.
enum BinError {
    /// The data ends.
    Short(usize, String),
    /// A list count is negative.
    NegativeCount(usize, String),
}

/// Decodes one variable-size record starting at `data[pos]`; returns the position after it.
fn binary_record(
    el: &Element,
    data: &[u8],
    mut pos: usize,
    big: bool,
    rec: &mut Record,
) -> std::result::Result<usize, BinError> {
    let take = |pos: usize, n: usize| -> Option<&[u8]> { data.get(pos..pos.checked_add(n)?) };
    for (p, &slot) in el.props.iter().zip(&el.slots) {
        match p.ty {
            Ty::Scalar(s) => {
                let b = take(pos, s.size()).ok_or_else(|| {
                    BinError::Short(
                        pos,
                        format!("property `{}` needs {} bytes", p.name, s.size()),
                    )
                })?;
                pos += s.size();
                let v = bin_f64(s, b, big);
                match slot {
                    Slot::Coord(k) => rec.p[k] = v,
                    Slot::Normal(k) => rec.n[k] = v,
                    Slot::Color(k) => rec.c[k] = color8(v, s),
                    Slot::Skip | Slot::Indices => {}
                }
            }
            Ty::List(cs, is) => {
                let b = take(pos, cs.size()).ok_or_else(|| {
                    BinError::Short(
                        pos,
                        format!("the count of list `{}` needs {} bytes", p.name, cs.size()),
                    )
                })?;
                let n = bin_i64(cs, b, big);
                if n < 0 {
                    return Err(BinError::NegativeCount(
                        pos,
                        format!("negative list count {n} of `{}`", p.name),
                    ));
                }
                pos += cs.size();
                let len = (n as u64).saturating_mul(is.size() as u64);
                let items = usize::try_from(len)
                    .ok()
                    .and_then(|len| take(pos, len))
                    .ok_or_else(|| {
                        BinError::Short(
                            pos,
                            format!("list `{}` of {n} values needs {len} bytes", p.name),
                        )
                    })?;
                pos += items.len();
                if slot == Slot::Indices {
                    rec.list.clear();
                    rec.list
                        .extend(items.chunks_exact(is.size()).map(|c| bin_i64(is, c, big)));
                }
            }
        }
    }
    Ok(pos)
}

// ---------------------------------------------------------------------------------------------
// writing

/// Writes a mesh as PLY in the given encoding, with `double` coordinates and normals unless
/// `single_precision` (then `float`). Colours are `uchar`; faces are
/// `list uchar int vertex_indices` (wider count/index types when needed). A mesh without faces
/// gets no `face` element.
///
/// Errors: `InvalidInput` when the normal or colour array does not have one row per vertex.
/// Cost: O(mesh size).
pub fn write(
    mesh: &PolyMesh,
    encoding: Encoding,
    single_precision: bool,
    out: &mut Vec<u8>,
) -> std::io::Result<()> {
    write_with_properties(mesh, &[], encoding, single_precision, out)
}

/// A named per-vertex scalar property for [`write_with_properties`]: `values` has one entry per
/// vertex.
#[derive(Clone, Copy, Debug)]
pub struct VertexProperty<'a> {
    /// The property name in the header (e.g. `k1`, `error`); must be a single word.
    pub name: &'a str,
    /// One value per vertex.
    pub values: &'a [f64],
}

/// Writes a mesh as PLY like [`fn@write`], with extra per-vertex scalar properties after the
/// standard ones (stored as `double`, or `float` when `single_precision`).
///
/// Errors (`InvalidInput`) when an attribute or property length differs from the vertex count
/// or a property name is empty or contains whitespace.
pub fn write_with_properties(
    mesh: &PolyMesh,
    extra: &[VertexProperty<'_>],
    encoding: Encoding,
    single_precision: bool,
    out: &mut Vec<u8>,
) -> std::io::Result<()> {
    let n = mesh.positions.len();
    let invalid = |msg: &str| {
        Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            msg.to_string(),
        ))
    };
    if mesh.normals.as_ref().is_some_and(|v| v.len() != n)
        || mesh.colors.as_ref().is_some_and(|v| v.len() != n)
        || extra.iter().any(|p| p.values.len() != n)
    {
        return invalid("attribute arrays do not match the vertex count");
    }
    if extra
        .iter()
        .any(|p| p.name.is_empty() || p.name.chars().any(|c| c.is_whitespace()))
    {
        return invalid("a property name is empty or contains whitespace");
    }
    let max_face = mesh.faces.iter().map(|f| f.len()).max().unwrap_or(0);
    let count_ty = if max_face <= u8::MAX as usize {
        Scalar::U8
    } else if max_face <= u16::MAX as usize {
        Scalar::U16
    } else {
        Scalar::U32
    };
    let index_ty = if n <= i32::MAX as usize + 1 {
        Scalar::I32
    } else {
        Scalar::U32
    };
    let real = if single_precision { "float" } else { "double" };
    let fmt = match encoding {
        Encoding::Ascii => "ascii",
        Encoding::BinaryLittleEndian => "binary_little_endian",
        Encoding::BinaryBigEndian => "binary_big_endian",
    };
    let mut head =
        format!("ply\nformat {fmt} 1.0\ncomment written by subfit\nelement vertex {n}\n");
    for a in AXES {
        head += &format!("property {real} {a}\n");
    }
    if mesh.normals.is_some() {
        for a in NORMAL_AXES {
            head += &format!("property {real} {a}\n");
        }
    }
    if mesh.colors.is_some() {
        head += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    }
    for p in extra {
        head += &format!("property {real} {}\n", p.name);
    }
    if !mesh.faces.is_empty() {
        let name = |s: Scalar| match s {
            Scalar::U8 => "uchar",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            _ => "uint",
        };
        head += &format!(
            "element face {}\nproperty list {} {} vertex_indices\n",
            mesh.faces.len(),
            name(count_ty),
            name(index_ty)
        );
    }
    head += "end_header\n";
    out.extend_from_slice(head.as_bytes());
    let mut w = Writer {
        out,
        encoding,
        single_precision,
    };
    for (i, p) in mesh.positions.iter().enumerate() {
        for &v in p {
            w.real(v);
        }
        if let Some(ns) = &mesh.normals {
            for &v in &ns[i] {
                w.real(v);
            }
        }
        if let Some(cs) = &mesh.colors {
            for &c in &cs[i] {
                w.int(c as u32, Scalar::U8);
            }
        }
        for p in extra {
            w.real(p.values[i]);
        }
        w.end();
    }
    for f in mesh.faces.iter() {
        w.int(f.len() as u32, count_ty);
        for &v in f {
            w.int(v, index_ty);
        }
        w.end();
    }
    Ok(())
}

struct Writer<'a> {
    out: &'a mut Vec<u8>,
    encoding: Encoding,
    single_precision: bool,
}

impl Writer<'_> {
    fn real(&mut self, v: f64) {
        match (self.encoding, self.single_precision) {
            (Encoding::Ascii, false) => {
                if v == 0.0 && v.is_sign_negative() {
                    // `push_f64` prints both zeros as `0`; keep the sign bit.
                    self.out.extend_from_slice(b"-0");
                } else {
                    push_f64(self.out, v);
                }
                self.out.push(b' ');
            }
            (Encoding::Ascii, true) => {
                let v = v as f32;
                if v == 0.0 {
                    if v.is_sign_negative() {
                        self.out.push(b'-');
                    }
                    self.out.push(b'0');
                } else {
                    let mut buf = ryu::Buffer::new();
                    let s = buf.format(v);
                    self.out
                        .extend_from_slice(s.strip_suffix(".0").unwrap_or(s).as_bytes());
                }
                self.out.push(b' ');
            }
            (Encoding::BinaryLittleEndian, false) => self.out.extend_from_slice(&v.to_le_bytes()),
            (Encoding::BinaryBigEndian, false) => self.out.extend_from_slice(&v.to_be_bytes()),
            (Encoding::BinaryLittleEndian, true) => {
                self.out.extend_from_slice(&(v as f32).to_le_bytes())
            }
            (Encoding::BinaryBigEndian, true) => {
                self.out.extend_from_slice(&(v as f32).to_be_bytes())
            }
        }
    }

    /// Writes `v` as type `s` (U8, U16, I32 or U32; the caller picked a type that holds it).
    fn int(&mut self, v: u32, s: Scalar) {
        let big = match self.encoding {
            Encoding::Ascii => {
                // Writing to a Vec cannot fail.
                let _ = write!(self.out, "{v} ");
                return;
            }
            Encoding::BinaryLittleEndian => false,
            Encoding::BinaryBigEndian => true,
        };
        let le = v.to_le_bytes();
        let n = s.size();
        if big {
            self.out.extend(le[..n].iter().rev());
        } else {
            self.out.extend_from_slice(&le[..n]);
        }
    }

    fn end(&mut self) {
        if self.encoding == Encoding::Ascii {
            if let Some(last) = self.out.last_mut() {
                *last = b'\n';
            }
        }
    }
}
