//! Wavefront OBJ: polygon meshes and point clouds as text (the format of Wavefront's Advanced
//! Visualizer manual, Appendix B1, "Object Files").
//!
//! Supported on reading:
//! - `v x y z`, `v x y z w` (the weight `w` is validated and ignored) and the common colour
//!   extension `v x y z r g b` (floats in 0..1, clamped, rounded to 8 bits). Colours are kept only
//!   when *every* vertex has them; otherwise they are dropped.
//! - `vn x y z`; `vt u [v [w]]` (validated, then ignored: subfit has no texture coordinates).
//! - `f` with corners `v`, `v/vt`, `v//vn`, `v/vt/vn`, and the same with empty trailing slots
//!   (`v/`, `v//`, `v/vt/`, as some exporters write them); faces with and without `vt` may be
//!   mixed. Negative indices count back from the last element defined so far; positive ones
//!   may refer forward (they are checked once the whole file is read). Faces need at least
//!   three corners; polygons of any size are kept.
//! - Comments from `#` to the end of the line, and line continuation with a trailing `\`.
//! - Lines are bytes: comments, names (`o`, `g`, `usemtl`, `mtllib`) and every other statement
//!   that carries no geometry may hold any bytes (old exporters wrote names in Latin-1 or
//!   code pages); the statements that are read (`v`, `vn`, `vt`, `f`) must be ASCII numbers.
//! - `l`, `p`, `o`, `g`, `s`, `usemtl`, `mtllib` and the free-form geometry statements
//!   (`vp`, `curv`, `surf`, `cstype`…) are ignored. Any other statement is a syntax error.
//!
//! Normals: OBJ normals belong to face corners, subfit's to vertices. Each vertex takes the
//! normals of its corners: the `vn` itself when all of them name the same normal (the same
//! index, or bit-identical values), otherwise the normalized mean of its corners' normals
//! (each normalized first; the first corner's normal where they cancel) — a vertex on a crease
//! exported with split normals gets the direction between its faces — with a warning counting
//! such vertices. Corners without a normal are passed over (warned). When some vertex has no
//! normal at all (used by no face, or only by corners without one) normals are dropped, with
//! a warning. When no corner refers to a normal and there are exactly as many `vn` as `v` (a
//! point cloud with normals), they are paired in order.
//!
//! Tags: OpenSubdiv's OBJ tag statements (the `t` lines of its `shape_utils` reader and of
//! Hbr's test shapes), `t crease 2/1/0 a b sharpness` and `t corner 1/1/0 v sharpness` with
//! 0-based vertex indices, are read by [`read_tags`] and written by [`write_with_tags`]; the
//! mesh reader skips `t` lines. Blender's OBJ importer ignores them (it reads control.usda's
//! creases).
//!
//! Dropped: texture coordinates, groups, materials, smoothing groups, lines, points, free-form
//! geometry. A file without any `v` is [`ErrorKind::Empty`]. An MNI surface file with an
//! `.obj` extension is read by the registry's MNI reader, not this one.
//!
//! Writing: `v` with the shortest decimal that reads back to the same f64, `vn` when the mesh has
//! normals, `f` with 1-based indices (`a//a` when there are normals). Colours are not written.

use std::path::Path;

use subfit_mesh::{PolyMesh, Polygons, Tags};

use crate::error::{Error, ErrorKind, Result};
use crate::text::{
    finite_f64, parse_int, push_f64_exact, push_u64, strip_hash_comment, syntax, tokens,
    unit_to_u8, NumberedLines,
};

/// Marks a corner without a normal, or a vertex without one.
const NONE: u32 = u32::MAX;

/// Statements that are read and ignored.
const IGNORED: &[&[u8]] = &[
    b"t",
    b"l",
    b"p",
    b"o",
    b"g",
    b"s",
    b"usemtl",
    b"mtllib",
    b"vp",
    b"cstype",
    b"deg",
    b"bmat",
    b"step",
    b"curv",
    b"curv2",
    b"surf",
    b"parm",
    b"trim",
    b"hole",
    b"scrv",
    b"sp",
    b"end",
    b"con",
    b"mg",
    b"lod",
    b"usemap",
    b"maplib",
    b"shadow_obj",
    b"trace_obj",
    b"ctech",
    b"stech",
    b"bevel",
    b"c_interp",
    b"d_interp",
    b"call",
    b"csh",
];

/// Parses a whole OBJ file; what was decided about normals goes to `warnings`.
///
/// Cost: O(file size) time; memory proportional to the data actually present.
/// Errors: syntax errors (quoting the token), NaN/infinite values, zero or out-of-range
/// indices (with their line), faces with fewer than three corners, no vertices.
pub fn read(bytes: &[u8], path: &Path, warnings: &mut Vec<String>) -> Result<PolyMesh> {
    let mut p = Parser::new(path, bytes.len());
    let mut lines = NumberedLines::new(bytes);
    let mut joined = Vec::new();
    while let Some((no, raw)) = lines.next() {
        let line = strip_hash_comment(raw);
        match continued(line) {
            None => p.statement(no, line)?,
            Some(head) => {
                joined.clear();
                joined.extend_from_slice(head);
                joined.push(b' ');
                for (_, next) in lines.by_ref() {
                    let next = strip_hash_comment(next);
                    match continued(next) {
                        Some(h) => {
                            joined.extend_from_slice(h);
                            joined.push(b' ');
                        }
                        None => {
                            joined.extend_from_slice(next);
                            break;
                        }
                    }
                }
                p.statement(no, &joined)?;
            }
        }
    }
    p.finish(warnings)
}

/// If `line` ends with a continuation backslash (before trailing blanks), the part before it.
fn continued(line: &[u8]) -> Option<&[u8]> {
    let end = line
        .iter()
        .rposition(|c| !c.is_ascii_whitespace())
        .map_or(0, |i| i + 1);
    line[..end].strip_suffix(b"\\")
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

    fn statement(&mut self, no: u64, line: &[u8]) -> Result<()> {
        let mut toks = tokens(line);
        let Some(kw) = toks.next() else {
            return Ok(());
        };
        match kw {
            b"v" => self.vertex(no, toks),
            b"vn" => {
                let n = self.triple(no, &mut toks, "normal component")?;
                self.no_more(no, toks, "`vn` takes 3 numbers")?;
                self.normals.push(n);
                Ok(())
            }
            b"vt" => self.texcoord(no, toks),
            b"f" | b"fo" => self.face(no, toks),
            _ if IGNORED.contains(&kw) => Ok(()),
            _ => Err(syntax(self.path, no, "unknown OBJ statement", kw)),
        }
    }

    fn number(&self, no: u64, tok: Option<&[u8]>, what: &str) -> Result<f64> {
        match tok {
            Some(t) => finite_f64(t, self.path, no, what),
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
        toks: &mut impl Iterator<Item = &'a [u8]>,
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
        mut toks: impl Iterator<Item = &'a [u8]>,
        what: &str,
    ) -> Result<()> {
        match toks.next() {
            Some(t) => Err(syntax(self.path, no, &format!("extra value ({what})"), t)),
            None => Ok(()),
        }
    }

    fn vertex<'a>(&mut self, no: u64, mut toks: impl Iterator<Item = &'a [u8]>) -> Result<()> {
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
                    t,
                ));
            }
            extra[n] = finite_f64(t, self.path, no, "vertex weight or colour")?;
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

    fn texcoord<'a>(&mut self, no: u64, toks: impl Iterator<Item = &'a [u8]>) -> Result<()> {
        let mut n = 0;
        for t in toks {
            if n == 3 {
                return Err(syntax(
                    self.path,
                    no,
                    "extra value (`vt` takes 1 to 3 numbers)",
                    t,
                ));
            }
            finite_f64(t, self.path, no, "texture coordinate")?;
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

    fn face<'a>(&mut self, no: u64, toks: impl Iterator<Item = &'a [u8]>) -> Result<()> {
        self.face_buf.clear();
        self.normal_buf.clear();
        for corner in toks {
            let mut parts = corner.split(|&c| c == b'/');
            let v = parts.next().unwrap_or_default();
            let vt = parts.next().unwrap_or_default();
            let vn = parts.next().unwrap_or_default();
            // Empty trailing slots (`1/`, `1//`, `1/2/`) are accepted: they say "none".
            if parts.next().is_some() || v.is_empty() {
                return Err(syntax(
                    self.path,
                    no,
                    "bad face corner (expected v, v/vt, v//vn or v/vt/vn)",
                    corner,
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
    fn resolve(&mut self, no: u64, tok: &[u8], target: Target) -> Result<u32> {
        let what = target.name();
        let Some(i) = parse_int(tok) else {
            return Err(syntax(self.path, no, &format!("bad {what} index"), tok));
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
                tok,
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

    fn finish(self, warnings: &mut Vec<String>) -> Result<PolyMesh> {
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
            warnings,
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

/// Per-vertex normals from per-corner normal indices (see the module documentation for the
/// rule); `None`, with a warning, when some vertex has none. All indices are already validated.
/// Cost: O(#corners + #V).
fn vertex_normals(
    nv: usize,
    normals: &[[f64; 3]],
    corners: &[u32],
    corner_normals: &[u32],
    warnings: &mut Vec<String>,
) -> Option<Vec<[f64; 3]>> {
    if normals.is_empty() {
        return None;
    }
    if corner_normals.iter().all(|&n| n == NONE) {
        if normals.len() == nv {
            return Some(normals.to_vec());
        }
        warnings.push(format!(
            "{} `vn` normals, none used by a face corner and not one per vertex ({nv}): \
             normals dropped",
            normals.len()
        ));
        return None;
    }
    let same = |a: u32, b: u32| {
        a == b || normals[a as usize].map(f64::to_bits) == normals[b as usize].map(f64::to_bits)
    };
    // The first normal of each vertex, whether another differs, and the sum of unit normals.
    let mut first = vec![NONE; nv];
    let mut mixed = vec![false; nv];
    let mut sum = vec![[0.0f64; 3]; nv];
    let mut bare_corners = 0usize;
    for (&v, &n) in corners.iter().zip(corner_normals) {
        if n == NONE {
            bare_corners += 1;
            continue;
        }
        let v = v as usize;
        if first[v] == NONE {
            first[v] = n;
        } else if !same(first[v], n) {
            mixed[v] = true;
        }
        let u = unit(normals[n as usize]).unwrap_or([0.0; 3]);
        for k in 0..3 {
            sum[v][k] += u[k];
        }
    }
    let without = first.iter().filter(|&&n| n == NONE).count();
    if without > 0 {
        warnings.push(format!(
            "{without} of {nv} vertices have no normal (used by no face, or only by corners \
             without `vn`): normals dropped"
        ));
        return None;
    }
    if bare_corners > 0 {
        warnings.push(format!(
            "{bare_corners} face corners have no `vn`; their vertices take the normals of \
             their other corners"
        ));
    }
    let averaged = mixed.iter().filter(|&&m| m).count();
    if averaged > 0 {
        warnings.push(format!(
            "{averaged} vertices have corners with different normals (per-face or split \
             normals): each takes the normalized mean of its corners' normals"
        ));
    }
    Some(
        (0..nv)
            .map(|v| {
                let own = normals[first[v] as usize];
                if mixed[v] {
                    unit(sum[v]).unwrap_or(own)
                } else {
                    own
                }
            })
            .collect(),
    )
}

/// `v / |v|`, or `None` when `v` is zero or not finite.
fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (len > 0.0 && len.is_finite()).then(|| v.map(|c| c / len))
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
        let line = strip_hash_comment(raw);
        if tokens(line).next() != Some(&b"t"[..]) {
            continue;
        }
        // A tag line is read as text; other lines may hold any bytes (see the module doc).
        let line = std::str::from_utf8(line)
            .map_err(|_| syntax(path, no, "a `t` tag line that is not UTF-8 text", line))?;
        let mut tok = line.split_ascii_whitespace();
        tok.next();
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
