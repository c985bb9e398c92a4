//! Point lists as text (`.xyz`, `.pts`, `.txt`, `.xyzn`): one point per line.
//!
//! Supported on reading:
//! - Values separated by blanks and/or commas. Comments from `#` or `//` to the end of the
//!   line (they may hold any bytes); blank lines.
//! - Point counts: a line holding a single non-negative integer before the first point (the
//!   Leica `.pts` header) or right after a block of exactly that many points (Leica files of
//!   several scans). Each count must match the points of its block ([`ErrorKind::BadCount`]).
//! - Statement files (the old VTK/ioa3d `.pts`): when the first data line starts with a word,
//!   points are the `p x y z` lines and every other statement (`d`, `s`, `g` material lines…)
//!   is skipped with a warning naming them.
//! - Columns, the same number on every point (a line that differs is an error naming it); what
//!   the columns after `x y z` hold is decided from their values by [`columns`], and said in a
//!   warning.
//!
//!   Every column must be a number; positions and normals must be finite; a NaN colour
//!   component reads as 0.
//! - A last line that ends without a line break and holds fewer values than the others is the
//!   mark of a file cut short (a copy stopped at a block boundary): [`ErrorKind::Truncated`]
//!   naming that line, never a silently dropped point.
//!
//! Faces are never read (there are none). A file without any point is [`ErrorKind::Empty`].
//!
//! Writing: `x y z` or `x y z nx ny nz` per line, shortest decimals that read back to the same
//! f64. Faces and colours are not written.

mod columns;
mod table;

use std::path::Path;

use subfit_mesh::{PolyMesh, Polygons};

use crate::error::{Error, ErrorKind, Result};
use crate::text::{finite_f64, parse_f64, parse_i64, push_f64_exact, syntax, NumberedLines};
use columns::{decide, Plan};
use table::Table;

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

/// A point count line and how many points followed it so far.
struct Block {
    count: u64,
    line: u64,
    seen: u64,
}

/// What the scan of the lines keeps besides the table.
#[derive(Default)]
struct Scan {
    /// `p` statement file: the skipped statements (keyword, first line, how many).
    statements: Option<Vec<(String, u64, u64)>>,
    block: Option<Block>,
    /// Line of the first point, and the shortest data line's length in bytes.
    first: u64,
    shortest: usize,
}

/// Parses a whole point list; what the columns were taken to be, and any statements
/// skipped, go to `warnings`.
///
/// Cost: O(file size) time; memory: the values of every point as f64 until the points are
/// built.
pub fn read(bytes: &[u8], path: &Path, warnings: &mut Vec<String>) -> Result<PolyMesh> {
    let (table, scan) = scan(bytes, path)?;
    if let Some(st) = &scan.statements {
        let listed: Vec<String> = st
            .iter()
            .map(|(k, l, n)| format!("`{k}` ×{n} (first on line {l})"))
            .collect();
        if table.rows() == 0 {
            return Err(Error::file(
                path,
                ErrorKind::Syntax(format!(
                    "no `p x y z` point statement; the file holds {}",
                    listed.join(", ")
                )),
            ));
        }
        if !listed.is_empty() {
            warnings.push(format!(
                "points read from the `p x y z` statements (VTK/ioa3d .pts); skipped: {}",
                listed.join(", ")
            ));
        }
    }
    if table.rows() == 0 {
        return Err(Error::file(path, ErrorKind::Empty));
    }
    if table.rows() >= u32::MAX as usize {
        return Err(Error::file(
            path,
            ErrorKind::BadCount("more than 2^32 - 1 points".into()),
        ));
    }
    let plan = decide(&table);
    if let Some(note) = plan.describe(table.cols) {
        warnings.push(note);
    }
    build(&table, &plan, path)
}

/// Reads every line into a [`Table`] (see the module documentation for the line forms).
fn scan(bytes: &[u8], path: &Path) -> Result<(Table, Scan)> {
    let mut t = Table {
        cols: 0,
        values: Vec::with_capacity(bytes.len() / 10),
        lines: Vec::with_capacity(bytes.len() / 30),
    };
    let mut s = Scan {
        shortest: usize::MAX,
        ..Scan::default()
    };
    let unterminated = !bytes.ends_with(b"\n") && !bytes.ends_with(b"\r");
    let mut lines = NumberedLines::new(bytes);
    let mut toks: Vec<&[u8]> = Vec::new();
    while let Some((no, raw)) = lines.next() {
        toks.clear();
        toks.extend(fields(strip_comment(raw)));
        if toks.is_empty() {
            continue;
        }
        let last = unterminated && lines.rest().is_empty();
        if t.rows() == 0 && s.block.is_none() && s.statements.is_none() {
            let kw = toks[0];
            if kw[0].is_ascii_alphabetic() && parse_f64(kw).is_none() {
                s.statements = Some(Vec::new());
            }
        }
        let row: &[&[u8]] = match &mut s.statements {
            Some(st) => match statement(&toks, no, path, st)? {
                Some(r) => r,
                None => continue,
            },
            None => {
                if count_line(&toks, no, &t, &mut s, path)? {
                    continue;
                }
                &toks
            }
        };
        push_row(&mut t, &mut s, row, no, raw, last, path)?;
    }
    if let Some(b) = &s.block {
        check_block(b, path, unterminated)?;
    }
    Ok((t, s))
}

/// A line of a statement file: `Some(values)` for a `p` line, `None` for a skipped statement.
fn statement<'a, 'b>(
    toks: &'b [&'a [u8]],
    no: u64,
    path: &Path,
    skipped: &mut Vec<(String, u64, u64)>,
) -> Result<Option<&'b [&'a [u8]]>> {
    let kw = toks[0];
    if kw == b"p" {
        return Ok(Some(&toks[1..]));
    }
    if !kw[0].is_ascii_alphabetic() {
        return Err(syntax(
            path,
            no,
            "expected a statement (`p x y z`, or a word) in a file of `p` statements",
            kw,
        ));
    }
    let name = String::from_utf8_lossy(&kw[..kw.len().min(20)]).into_owned();
    match skipped.iter_mut().find(|(k, _, _)| *k == name) {
        Some(e) => e.2 += 1,
        None => skipped.push((name, no, 1)),
    }
    Ok(None)
}

/// Whether `toks` is a point count line (see the module documentation); checks the block it
/// closes.
fn count_line(toks: &[&[u8]], no: u64, t: &Table, s: &mut Scan, path: &Path) -> Result<bool> {
    if toks.len() != 1 {
        return Ok(false);
    }
    let Some(count) = parse_i64(toks[0]).filter(|&c| c >= 0) else {
        return Ok(false);
    };
    let at_start = t.rows() == 0 && s.block.is_none();
    match &s.block {
        _ if at_start => {}
        Some(b) if b.seen == b.count => {}
        Some(b) => {
            return Err(Error::at_line(
                path,
                b.line,
                ErrorKind::BadCount(format!(
                    "this line announces {} points, but {} follow before the next count \
                     (line {no})",
                    b.count, b.seen
                )),
            ))
        }
        None => return Ok(false),
    }
    s.block = Some(Block {
        count: count as u64,
        line: no,
        seen: 0,
    });
    Ok(true)
}

fn check_block(b: &Block, path: &Path, unterminated: bool) -> Result<()> {
    if b.seen == b.count {
        return Ok(());
    }
    let cut = if unterminated && b.seen < b.count {
        "; the file ends without a line break: it seems truncated"
    } else {
        ""
    };
    Err(Error::at_line(
        path,
        b.line,
        ErrorKind::BadCount(format!(
            "this line announces {} points, {} follow{cut}",
            b.count, b.seen
        )),
    ))
}

/// Appends one point's values; `last`: the line is the file's last and has no line break.
fn push_row(
    t: &mut Table,
    s: &mut Scan,
    row: &[&[u8]],
    no: u64,
    raw: &[u8],
    last: bool,
    path: &Path,
) -> Result<()> {
    let n = row.len();
    let cut = |have: &str| {
        let shown = String::from_utf8_lossy(&raw[..raw.len().min(60)]).into_owned();
        Error::at_line(
            path,
            no,
            ErrorKind::Truncated(format!(
                "the file seems truncated: its last line `{shown}` ({} bytes, the shortest \
                 other line has {}) ends without a line break and {have}",
                raw.len(),
                s.shortest
            )),
        )
    };
    if t.rows() == 0 {
        if n < 3 {
            return Err(Error::at_line(
                path,
                no,
                ErrorKind::Syntax(format!("{n} column(s); a point needs at least x y z")),
            ));
        }
        t.cols = n;
        s.first = no;
    } else if n != t.cols {
        if last && n < t.cols {
            return Err(cut(&format!(
                "holds {n} of the {} values of a point",
                t.cols
            )));
        }
        return Err(Error::at_line(
            path,
            no,
            ErrorKind::Syntax(format!(
                "{n} columns, but the first point (line {}) has {}",
                s.first, t.cols
            )),
        ));
    }
    for (k, tok) in row.iter().enumerate() {
        let v = if k < 3 {
            finite_f64(tok, path, no, "coordinate")
        } else {
            parse_f64(tok).ok_or_else(|| syntax(path, no, "expected a number", tok))
        };
        match v {
            Ok(v) => t.values.push(v),
            Err(_) if last && t.rows() > 0 => {
                return Err(cut(&format!(
                    "its value `{}` is not a number",
                    String::from_utf8_lossy(tok)
                )))
            }
            Err(e) => return Err(e),
        }
    }
    t.lines.push(no);
    s.shortest = s.shortest.min(raw.len());
    if let Some(b) = &mut s.block {
        b.seen += 1;
    }
    Ok(())
}

/// Builds the point cloud from the table and the column plan.
fn build(t: &Table, plan: &Plan, path: &Path) -> Result<PolyMesh> {
    let n = t.rows();
    let mut positions = Vec::with_capacity(n);
    let mut normals = Vec::with_capacity(if plan.normals.is_some() { n } else { 0 });
    let mut colors = Vec::with_capacity(if plan.colours.is_some() { n } else { 0 });
    for i in 0..n {
        let r = t.row(i);
        positions.push([r[0], r[1], r[2]]);
        if let Some(a) = plan.normals {
            let v = [r[a], r[a + 1], r[a + 2]];
            if let Some(c) = v.iter().find(|c| !c.is_finite()) {
                return Err(Error::at_line(
                    path,
                    t.lines[i],
                    ErrorKind::NonFinite(format!("normal component `{c}`")),
                ));
            }
            normals.push(v);
        }
        if let Some((a, scale)) = plan.colours {
            colors.push([r[a], r[a + 1], r[a + 2]].map(|v| scale.to_u8(v)));
        }
    }
    Ok(PolyMesh {
        positions,
        normals: plan.normals.is_some().then_some(normals),
        colors: plan.colours.is_some().then_some(colors),
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
