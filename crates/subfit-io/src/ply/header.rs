//! The PLY header: scalar types, elements and properties, and the plan of which property feeds
//! which field of the mesh.

use std::path::Path;

use crate::error::{Error, ErrorKind, Result};
use crate::Encoding;

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Scalar {
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
    pub(super) fn from_name(s: &str) -> Option<Scalar> {
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

    pub(super) fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    pub(super) fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Ty {
    Scalar(Scalar),
    /// `list <count> <item>`.
    List(Scalar, Scalar),
}

#[derive(Clone, Debug)]
pub(super) struct Property {
    pub(super) name: String,
    pub(super) ty: Ty,
}

/// What a property feeds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Slot {
    Skip,
    Coord(usize),
    Normal(usize),
    Color(usize),
    Indices,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Role {
    Vertex,
    Face,
    Strips,
    Other,
}

#[derive(Clone, Debug)]
pub(super) struct Element {
    pub(super) name: String,
    pub(super) count: u64,
    pub(super) props: Vec<Property>,
    /// 1-based header line of the `element` statement.
    pub(super) line: u64,
    pub(super) role: Role,
    pub(super) slots: Vec<Slot>,
}

impl Element {
    /// Smallest number of bytes one binary record can take (lists counted as empty).
    pub(super) fn min_binary_size(&self) -> usize {
        self.props
            .iter()
            .map(|p| match p.ty {
                Ty::Scalar(s) => s.size(),
                Ty::List(c, _) => c.size(),
            })
            .sum()
    }

    pub(super) fn fixed_size(&self) -> bool {
        self.props.iter().all(|p| matches!(p.ty, Ty::Scalar(_)))
    }
}

pub(super) struct Header {
    pub(super) encoding: Encoding,
    pub(super) elements: Vec<Element>,
    /// Byte offset of the first data byte.
    pub(super) data_start: usize,
    /// Number of header lines (the data starts on the next line for ascii).
    pub(super) lines: u64,
    pub(super) has_normals: bool,
    pub(super) has_colors: bool,
    pub(super) vertex_count: u64,
    /// Header lines with an unknown keyword, skipped: (1-based line, keyword).
    pub(super) skipped: Vec<(u64, String)>,
}

pub(super) fn bad_header(path: &Path, line: u64, msg: impl Into<String>) -> Error {
    Error::at_line(path, line, ErrorKind::BadHeader(msg.into()))
}

/// Parses the header, up to and including `end_header`.
pub(super) fn parse_header(bytes: &[u8], path: &Path) -> Result<Header> {
    let mut pos = 0usize;
    let mut line_no = 0u64;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut skipped = Vec::new();
    loop {
        if pos >= bytes.len() {
            let unknown: Vec<String> = skipped
                .iter()
                .take(3)
                .map(|(l, k)| format!("line {l} `{k}`"))
                .collect();
            let note = if unknown.is_empty() {
                String::new()
            } else {
                format!(" (not understood: {})", unknown.join(", "))
            };
            return Err(Error::at_line(
                path,
                line_no + 1,
                ErrorKind::Truncated(format!("the header ends without `end_header`{note}")),
            ));
        }
        let rest = &bytes[pos..];
        let (raw, next) = match rest.iter().position(|&c| c == b'\n') {
            Some(i) => (&rest[..i], pos + i + 1),
            None => (rest, bytes.len()),
        };
        pos = next;
        line_no += 1;
        // Comments may hold any bytes (names in Latin-1 or a code page); every other header
        // line is read as text.
        if line_no > 1 && (raw.starts_with(b"comment") || raw.starts_with(b"obj_info")) {
            continue;
        }
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
            // Lines no PLY reader understands (stray `bye` lines of old Cyberware range scans):
            // skipped and reported, since the elements and properties around them still say
            // exactly how to read the data.
            other => skipped.push((line_no, other.chars().take(40).collect())),
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
        skipped,
    };
    plan(&mut header, path)?;
    Ok(header)
}

pub(super) fn parse_format(toks: &[&str]) -> Option<Encoding> {
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

pub(super) fn parse_count(tok: &str) -> std::result::Result<u64, ErrorKind> {
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

pub(super) fn scalar(name: &str) -> std::result::Result<Scalar, String> {
    Scalar::from_name(name).ok_or_else(|| {
        let shown: String = name.chars().take(40).collect();
        format!("unknown type `{shown}`")
    })
}

pub(super) fn parse_property(toks: &[&str]) -> std::result::Result<Property, String> {
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
pub(super) fn plan(h: &mut Header, path: &Path) -> Result<()> {
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

pub(super) const AXES: [&str; 3] = ["x", "y", "z"];
pub(super) const NORMAL_AXES: [&str; 3] = ["nx", "ny", "nz"];
