//! Wavefront OBJ: polygon meshes and point clouds as text.
//!
//! Supported on reading:
//! - `v x y z`, `v x y z w` (the weight `w` is validated and ignored) and the common colour
//!   extension `v x y z r g b` (floats in 0..1, clamped, rounded to 8 bits). Colours are kept only
//!   when *every* vertex has them; otherwise they are dropped.
//! - `vn x y z`; `vt u [v [w]]` (validated, then ignored: subfit has no texture coordinates).
//! - `f` with corners `v`, `v/vt`, `v//vn`, `v/vt/vn`; negative indices count back from the
//!   last element defined so far; positive ones may refer forward (they are checked once the
//!   whole file is read). Faces need at least three corners; polygons of any size are kept.
//! - Comments from `#` to the end of the line, and line continuation with a trailing `\`.
//!   Every line, comments included, must be UTF-8 (an error names the line and column).
//! - `l`, `p`, `o`, `g`, `s`, `usemtl`, `mtllib` and the free-form geometry statements
//!   (`vp`, `curv`, `surf`, `cstype`…) are ignored. Any other statement is a syntax error.
//!
//! Normals: OBJ normals belong to face corners, subfit's to vertices. When every vertex is
//! used with exactly one normal (the same `vn` index, or `vn` entries with bit-identical
//! values, at all of its corners, and every vertex has one), the result has per-vertex normals.
//! Otherwise (split normals at creases, corners without a normal, vertices used by no face)
//! normals are dropped. When no corner refers to a normal and there are exactly as many `vn` as
//! `v` (a point cloud with normals), they are paired in order.
//!
//! Tags: OpenSubdiv's OBJ tag statements (the `t` lines of its `shape_utils` reader and of
//! Hbr's test shapes), `t crease 2/1/0 a b sharpness` and `t corner 1/1/0 v sharpness` with
//! 0-based vertex indices, are read by [`read_tags`] and written by [`write_with_tags`]; the
//! mesh reader skips `t` lines. Blender's OBJ importer ignores them (it reads control.usda's
//! creases).
//!
//! Dropped: texture coordinates, groups, materials, smoothing groups, lines, points, free-form
//! geometry. A file without any `v` is [`ErrorKind::Empty`].
//!
//! Writing: `v` with the shortest decimal that reads back to the same f64, `vn` when the mesh has
//! normals, `f` with 1-based indices (`a//a` when there are normals). Colours are not written.

use std::path::Path;

use subfit_mesh::{PolyMesh, Polygons, Tags};

use crate::error::{Error, ErrorKind, Result};
use crate::text::{parse_int, push_f64_exact, push_u64, syntax, unit_to_u8, NumberedLines};

/// Marks a corner without a normal, or a vertex without one.
const NONE: u32 = u32::MAX;

/// Statements that are read and ignored.
const IGNORED: &[&str] = &[
    "t",
    "l",
    "p",
    "o",
    "g",
    "s",
    "usemtl",
    "mtllib",
    "vp",
    "cstype",
    "deg",
    "bmat",
    "step",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "mg",
    "lod",
    "usemap",
    "maplib",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
    "bevel",
    "c_interp",
    "d_interp",
    "call",
    "csh",
];

/// Parses a whole OBJ file.
///
/// Cost: O(file size) time; memory proportional to the data actually present.
/// Errors: non-UTF-8 text, syntax errors (quoting the token), NaN/infinite values, zero or
/// out-of-range indices (with their line), faces with fewer than three corners, no vertices.
pub fn read(bytes: &[u8], path: &Path) -> Result<PolyMesh> {
    let mut p = Parser::new(path, bytes.len());
    let mut lines = NumberedLines::new(bytes).map(|(no, raw)| (no, utf8_line(raw, no, path)));
    let mut joined = String::new();
    while let Some((no, text)) = lines.next() {
        let line = strip_comment(text?);
        match continued(line) {
            None => p.statement(no, line)?,
            Some(head) => {
                joined.clear();
                joined.push_str(head);
                joined.push(' ');
                for (_, next) in lines.by_ref() {
                    let next = strip_comment(next?);
                    match continued(next) {
                        Some(h) => {
                            joined.push_str(h);
                            joined.push(' ');
                        }
                        None => {
                            joined.push_str(next);
                            break;
                        }
                    }
                }
                p.statement(no, &joined)?;
            }
        }
    }
    p.finish()
}

/// A line as text: validated once here, so that number tokens need no further check.
fn utf8_line<'a>(raw: &'a [u8], no: u64, path: &Path) -> Result<&'a str> {
    std::str::from_utf8(raw).map_err(|e| {
        let at = e.valid_up_to();
        let bad = &raw[at..raw.len().min(at + 4)];
        Error::at_line(
            path,
            no,
            ErrorKind::Syntax(format!(
                "not UTF-8 text (column {}: {bad:02x?}); is this a binary file?",
                at + 1
            )),
        )
    })
}

/// Cuts a line at `#`.
fn strip_comment(line: &str) -> &str {
    line.split('#').next().unwrap_or_default()
}

/// If `line` ends with a continuation backslash (before trailing blanks), the part before it.
fn continued(line: &str) -> Option<&str> {
    line.trim_end_matches(|c: char| c.is_ascii_whitespace())
        .strip_suffix('\\')
}

/// Parses a number token that must be finite (errors as [`crate::text`]'s `finite_f64`).
fn float(tok: &str, path: &Path, no: u64, what: &str) -> Result<f64> {
    match tok.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(Error::at_line(
            path,
            no,
            ErrorKind::NonFinite(format!("{what} `{tok}`")),
        )),
        Err(_) => Err(syntax(
            path,
            no,
            &format!("expected a number ({what})"),
            tok.as_bytes(),
        )),
    }
}

/// Reading state: everything seen so far.
struct Parser<'p> {
    path: &'p Path,
    positions: Vec<[f64; 3]>,
    /// A colour for every vertex (black when the vertex had none).
    colors: Vec<[u8; 3]>,
    /// How many vertices carried a colour.
    colored: usize,
    normals: Vec<[f64; 3]>,
    texcoords: u64,
    faces: Polygons,
    /// The normal index of every face corner (parallel to the face indices), or [`NONE`].
    corner_normals: Vec<u32>,
    /// Largest positive (1-based) index seen for `v`, `vt`, `vn`, with its line, checked at the end.
    max_ref: [(i64, u64); 3],
    face_buf: Vec<u32>,
    normal_buf: Vec<u32>,
}

/// Which array an index refers to.
#[derive(Clone, Copy)]
enum Target {
    Vertex = 0,
    Texcoord = 1,
    Normal = 2,
}

impl Target {
    fn name(self) -> &'static str {
        match self {
            Target::Vertex => "vertex",
            Target::Texcoord => "texture coordinate",
            Target::Normal => "normal",
        }
    }
}

impl<'p> Parser<'p> {
    fn new(path: &'p Path, size: usize) -> Self {
        // A guess that never exceeds what the file could hold (a `v` line takes >= 8 bytes).
        let guess = size / 64;
        Self {
            path,
            positions: Vec::with_capacity(guess),
            colors: Vec::with_capacity(guess),
            colored: 0,
            normals: Vec::new(),
            texcoords: 0,
            faces: Polygons::with_capacity(guess * 2, guess * 6),
            corner_normals: Vec::with_capacity(guess * 6),
            max_ref: [(0, 0); 3],
            face_buf: Vec::new(),
            normal_buf: Vec::new(),
        }
    }

    fn statement(&mut self, no: u64, line: &str) -> Result<()> {
        let mut toks = line.split_ascii_whitespace();
        let Some(kw) = toks.next() else {
            return Ok(());
        };
        match kw {
            "v" => self.vertex(no, toks),
            "vn" => {
                let n = self.triple(no, &mut toks, "normal component")?;
                self.no_more(no, toks, "`vn` takes 3 numbers")?;
                self.normals.push(n);
                Ok(())
            }
            "vt" => self.texcoord(no, toks),
            "f" | "fo" => self.face(no, toks),
            _ if IGNORED.contains(&kw) => Ok(()),
            _ => Err(syntax(
                self.path,
                no,
                "unknown OBJ statement",
                kw.as_bytes(),
            )),
        }
    }

    fn number(&self, no: u64, tok: Option<&str>, what: &str) -> Result<f64> {
        match tok {
            Some(t) => float(t, self.path, no, what),
            None => Err(Error::at_line(
                self.path,
                no,
                ErrorKind::Syntax(format!("missing {what}")),
            )),
        }
    }

    fn triple<'a>(
        &self,
        no: u64,
        toks: &mut impl Iterator<Item = &'a str>,
        what: &str,
    ) -> Result<[f64; 3]> {
        Ok([
            self.number(no, toks.next(), what)?,
            self.number(no, toks.next(), what)?,
            self.number(no, toks.next(), what)?,
        ])
    }

    fn no_more<'a>(
        &self,
        no: u64,
        mut toks: impl Iterator<Item = &'a str>,
        what: &str,
    ) -> Result<()> {
        match toks.next() {
            Some(t) => Err(syntax(
                self.path,
                no,
                &format!("extra value ({what})"),
                t.as_bytes(),
            )),
            None => Ok(()),
        }
    }

    fn vertex<'a>(&mut self, no: u64, mut toks: impl Iterator<Item = &'a str>) -> Result<()> {
        if self.positions.len() >= NONE as usize {
            return Err(Error::at_line(
                self.path,
                no,
                ErrorKind::BadCount("more than 2^32 - 1 vertices".into()),
            ));
        }
        let p = self.triple(no, &mut toks, "vertex coordinate")?;
        let mut extra = [0.0; 3];
        let mut n = 0;
        for t in toks {
            if n == 3 {
                return Err(syntax(
                    self.path,
                    no,
                    "extra value (`v` takes x y z, x y z w or x y z r g b)",
                    t.as_bytes(),
                ));
            }
            extra[n] = float(t, self.path, no, "vertex weight or colour")?;
            n += 1;
        }
        let color = match n {
            0 | 1 => [0; 3],
            3 => {
                self.colored += 1;
                extra.map(unit_to_u8)
            }
            _ => {
                return Err(Error::at_line(
                    self.path,
                    no,
                    ErrorKind::Syntax(
                        "`v` with 5 numbers (expected x y z, x y z w or x y z r g b)".into(),
                    ),
                ))
            }
        };
        self.positions.push(p);
        self.colors.push(color);
        Ok(())
    }

    fn texcoord<'a>(&mut self, no: u64, toks: impl Iterator<Item = &'a str>) -> Result<()> {
        let mut n = 0;
        for t in toks {
            if n == 3 {
                return Err(syntax(
                    self.path,
                    no,
                    "extra value (`vt` takes 1 to 3 numbers)",
                    t.as_bytes(),
                ));
            }
            float(t, self.path, no, "texture coordinate")?;
            n += 1;
        }
        if n == 0 {
            return Err(Error::at_line(
                self.path,
                no,
                ErrorKind::Syntax("`vt` without numbers".into()),
            ));
        }
        self.texcoords += 1;
        Ok(())
    }

    fn face<'a>(&mut self, no: u64, toks: impl Iterator<Item = &'a str>) -> Result<()> {
        self.face_buf.clear();
        self.normal_buf.clear();
        for corner in toks {
            let mut parts = corner.split('/');
            let v = parts.next().unwrap_or_default();
            let vt = parts.next().unwrap_or_default();
            let vn = parts.next().unwrap_or_default();
            if parts.next().is_some() || v.is_empty() || (vt.is_empty() && corner.ends_with('/')) {
                return Err(syntax(
                    self.path,
                    no,
                    "bad face corner (expected v, v/vt, v//vn or v/vt/vn)",
                    corner.as_bytes(),
                ));
            }
            let vi = self.resolve(no, v, Target::Vertex)?;
            if !vt.is_empty() {
                self.resolve(no, vt, Target::Texcoord)?;
            }
            let ni = if vn.is_empty() {
                NONE
            } else {
                self.resolve(no, vn, Target::Normal)?
            };
            self.face_buf.push(vi);
            self.normal_buf.push(ni);
        }
        if self.face_buf.len() < 3 {
            return Err(Error::at_line(
                self.path,
                no,
                ErrorKind::Syntax(format!(
                    "face with {} corner(s); at least 3 are needed",
                    self.face_buf.len()
                )),
            ));
        }
        if self.faces.indices().len() + self.face_buf.len() > NONE as usize {
            return Err(Error::at_line(
                self.path,
                no,
                ErrorKind::BadCount("more than 2^32 - 1 face corners".into()),
            ));
        }
        self.faces.push(&self.face_buf);
        self.corner_normals.extend_from_slice(&self.normal_buf);
        Ok(())
    }

    /// Turns a 1-based or negative index token into a 0-based index. Positive indices past the
    /// current count are allowed here (forward references) and checked in [`Parser::finish`].
    fn resolve(&mut self, no: u64, tok: &str, target: Target) -> Result<u32> {
        let what = target.name();
        let Some(i) = parse_int(tok.as_bytes()) else {
            return Err(syntax(
                self.path,
                no,
                &format!("bad {what} index"),
                tok.as_bytes(),
            ));
        };
        let count = match target {
            Target::Vertex => self.positions.len() as u64,
            Target::Texcoord => self.texcoords,
            Target::Normal => self.normals.len() as u64,
        };
        let out_of_range = || match target {
            Target::Vertex => Error::at_line(
                self.path,
                no,
                ErrorKind::IndexOutOfRange { index: i, count },
            ),
            _ => Error::at_line(
                self.path,
                no,
                ErrorKind::Syntax(format!(
                    "{what} index {i} out of range (the file has {count} so far)"
                )),
            ),
        };
        if i == 0 {
            return Err(syntax(
                self.path,
                no,
                &format!("{what} index 0 (OBJ indices start at 1; negative ones count back)"),
                tok.as_bytes(),
            ));
        }
        if i < 0 {
            let r = count as i64 + i;
            return if r < 0 {
                Err(out_of_range())
            } else {
                Ok(r as u32)
            };
        }
        if i > NONE as i64 {
            return Err(out_of_range());
        }
        let slot = &mut self.max_ref[target as usize];
        if i > slot.0 {
            *slot = (i, no);
        }
        Ok((i - 1) as u32)
    }

    fn finish(self) -> Result<PolyMesh> {
        let counts = [
            self.positions.len() as u64,
            self.texcoords,
            self.normals.len() as u64,
        ];
        for (t, target) in [Target::Vertex, Target::Texcoord, Target::Normal]
            .into_iter()
            .enumerate()
        {
            let (max, no) = self.max_ref[t];
            if max as u64 > counts[t] {
                return Err(match target {
                    Target::Vertex => Error::at_line(
                        self.path,
                        no,
                        ErrorKind::IndexOutOfRange {
                            index: max,
                            count: counts[t],
                        },
                    ),
                    _ => Error::at_line(
                        self.path,
                        no,
                        ErrorKind::Syntax(format!(
                            "{} index {max} out of range (the file has {})",
                            target.name(),
                            counts[t]
                        )),
                    ),
                });
            }
        }
        if self.positions.is_empty() {
            return Err(Error::file(self.path, ErrorKind::Empty));
        }
        let normals = vertex_normals(
            self.positions.len(),
            &self.normals,
            self.faces.indices(),
            &self.corner_normals,
        );
        let colors = (self.colored == self.positions.len()).then_some(self.colors);
        Ok(PolyMesh {
            positions: self.positions,
            normals,
            colors,
            faces: self.faces,
        })
    }
}

/// Per-vertex normals from per-corner normal indices, when they are consistent (see the module
/// documentation); `None` otherwise. All indices are already validated.
fn vertex_normals(
    nv: usize,
    normals: &[[f64; 3]],
    corners: &[u32],
    corner_normals: &[u32],
) -> Option<Vec<[f64; 3]>> {
    if normals.is_empty() {
        return None;
    }
    if corner_normals.iter().all(|&n| n == NONE) {
        return (normals.len() == nv).then(|| normals.to_vec());
    }
    let mut of_vertex = vec![NONE; nv];
    let same = |a: u32, b: u32| {
        a == b || normals[a as usize].map(f64::to_bits) == normals[b as usize].map(f64::to_bits)
    };
    for (&v, &n) in corners.iter().zip(corner_normals) {
        if n == NONE {
            return None;
        }
        let slot = &mut of_vertex[v as usize];
        if *slot == NONE {
            *slot = n;
        } else if !same(*slot, n) {
            return None;
        }
    }
    of_vertex
        .iter()
        .map(|&n| (n != NONE).then(|| normals[n as usize]))
        .collect()
}

/// Writes a mesh as OBJ (see the module documentation for what is written).
///
/// Indices are not checked here; [`crate::write_bytes`] checks them first.
pub fn write(mesh: &PolyMesh, out: &mut Vec<u8>) -> std::io::Result<()> {
    out.reserve(mesh.positions.len() * 40 + mesh.faces.indices().len() * 8);
    out.extend_from_slice(b"# written by subfit\n");
    for p in &mesh.positions {
        push_line(out, b"v", p);
    }
    let normals = mesh.normals.as_ref();
    for n in normals.into_iter().flatten() {
        push_line(out, b"vn", n);
    }
    for f in mesh.faces.iter() {
        out.push(b'f');
        for &v in f {
            out.push(b' ');
            push_u64(out, v as u64 + 1);
            if normals.is_some() {
                out.extend_from_slice(b"//");
                push_u64(out, v as u64 + 1);
            }
        }
        out.push(b'\n');
    }
    Ok(())
}

/// [`write`] followed by the crease and corner tags as OpenSubdiv `t` statements (see the
/// module documentation).
pub fn write_with_tags(mesh: &PolyMesh, tags: &Tags, out: &mut Vec<u8>) -> std::io::Result<()> {
    write(mesh, out)?;
    for ((a, b), s) in tags.creases() {
        out.extend_from_slice(format!("t crease 2/1/0 {a} {b} {s}\n").as_bytes());
    }
    for (v, s) in tags.corners() {
        out.extend_from_slice(format!("t corner 1/1/0 {v} {s}\n").as_bytes());
    }
    Ok(())
}

/// The `t crease` and `t corner` tags of an OBJ file (other `t` tags and every other
/// statement are skipped; see the module documentation). Errors name the line: a malformed
/// count triple, missing or non-numeric arguments, a negative or non-finite sharpness, a
/// vertex index beyond `num_vertices`.
pub fn read_tags(bytes: &[u8], path: &Path, num_vertices: usize) -> Result<Tags> {
    let mut tags = Tags::new();
    for (no, raw) in NumberedLines::new(bytes) {
        let line = strip_comment(utf8_line(raw, no, path)?);
        let mut tok = line.split_ascii_whitespace();
        if tok.next() != Some("t") {
            continue;
        }
        let name = tok.next().unwrap_or_default();
        let wanted = match name {
            "crease" => 2,
            "corner" => 1,
            _ => continue,
        };
        let bad = |what: &str, t: &str| syntax(path, no, what, t.as_bytes());
        let counts = tok.next().unwrap_or_default();
        let n: Vec<usize> = counts
            .split('/')
            .map(|c| c.parse::<usize>())
            .collect::<std::result::Result<_, _>>()
            .map_err(|_| bad("expected int/float/string counts", counts))?;
        if n.len() != 3 || n[0] != wanted || n[1] != 1 {
            return Err(bad(
                &format!("expected {wanted}/1/0 for a {name} tag"),
                counts,
            ));
        }
        let mut ids = [0u32; 2];
        for id in ids.iter_mut().take(wanted) {
            let t = tok.next().unwrap_or_default();
            *id = t
                .parse::<u32>()
                .ok()
                .filter(|&v| (v as usize) < num_vertices)
                .ok_or_else(|| bad(&format!("expected a vertex index below {num_vertices}"), t))?;
        }
        let t = tok.next().unwrap_or_default();
        let sharpness = t
            .parse::<f64>()
            .ok()
            .filter(|s| s.is_finite() && *s >= 0.0)
            .ok_or_else(|| bad("expected a sharpness ≥ 0", t))?;
        if wanted == 2 {
            tags.set_crease(ids[0], ids[1], sharpness);
        } else {
            tags.set_corner(ids[0], sharpness);
        }
    }
    Ok(tags)
}

fn push_line(out: &mut Vec<u8>, kw: &[u8], v: &[f64; 3]) {
    out.extend_from_slice(kw);
    for &c in v {
        out.push(b' ');
        push_f64_exact(out, c);
    }
    out.push(b'\n');
}
