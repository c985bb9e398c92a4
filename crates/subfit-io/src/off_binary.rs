//! Binary OFF (the Geomview manual, "OFF Files", binary format): after the text line
//! `[ST][C][N]OFF BINARY`, 32-bit integers and floats:
//!
//! ```text
//! V F E                                     int32 counts (E ignored)
//! V × (x y z [nx ny nz] [r g b a] [s t])    float32, the fields the keyword announces
//! F × (n i1 … in  nc c1 … c_nc)             int32 n and indices, int32 colour count (0..=4)
//!                                           and nc float32 colour components (ignored)
//! ```
//!
//! The spec says big-endian with a colour count after every face. Files in the wild also come
//! little-endian (written by the native order of x86 tools) and without the colour count (pmp's
//! writer). The reader tries the four combinations, the spec's first, and takes the first one
//! that accounts for every byte: counts that fit the file, indices in range, finite positions
//! and normals, every face with at least 3 corners, and nothing but blanks after the last face.
//! A wrong byte order gives counts the file cannot hold and a wrong face layout lands the faces
//! off their records, so at most one combination reads a real file; a choice other than the
//! spec's is reported as a warning. When none reads, the error is the one of the combination
//! that got furthest into the file.
//!
//! Colours (RGBA floats in 0..1) are kept per vertex (alpha dropped, a NaN component reads as
//! 0); texture coordinates are skipped.

use std::path::Path;

use subfit_mesh::{PolyMesh, Polygons};

use crate::error::{Error, ErrorKind, Location, Result};
use crate::off_keyword::Layout;
use crate::text::unit_to_u8;
use crate::Encoding;

/// Why one combination failed, and at which byte of the data (after the header line).
struct Failure {
    at: usize,
    kind: ErrorKind,
}

/// A reading position over the binary data in one byte order.
struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
    big: bool,
}

impl Cursor<'_> {
    fn word(&mut self, what: &str) -> std::result::Result<[u8; 4], Failure> {
        let Some(b) = self.data.get(self.pos..self.pos + 4) else {
            return Err(Failure {
                at: self.pos,
                kind: ErrorKind::Truncated(format!(
                    "{what} needs 4 bytes at byte {}, the data ends at {}",
                    self.pos,
                    self.data.len()
                )),
            });
        };
        self.pos += 4;
        let mut w = [b[0], b[1], b[2], b[3]];
        if self.big {
            w.reverse();
        }
        Ok(w)
    }

    fn int(&mut self, what: &str) -> std::result::Result<i32, Failure> {
        self.word(what).map(i32::from_le_bytes)
    }

    fn float(&mut self, what: &str) -> std::result::Result<f64, Failure> {
        self.word(what).map(|w| f32::from_le_bytes(w) as f64)
    }

    /// A count in `0..=i32::MAX`.
    fn count(&mut self, what: &str) -> std::result::Result<u64, Failure> {
        let at = self.pos;
        let n = self.int(what)?;
        u64::try_from(n).map_err(|_| Failure {
            at,
            kind: ErrorKind::BadCount(format!("negative {what} {n}")),
        })
    }

    fn left(&self) -> u64 {
        (self.data.len() - self.pos) as u64
    }
}

/// Reads binary OFF data (`bytes[data_start..]`, after the header line `header_line`).
pub(crate) fn read(
    layout: Layout,
    bytes: &[u8],
    data_start: usize,
    header_line: u64,
    path: &Path,
    warnings: &mut Vec<String>,
) -> Result<(PolyMesh, Encoding)> {
    let data = &bytes[data_start..];
    let mut furthest: Option<(Failure, bool, bool)> = None;
    for (k, (big, colour_counts)) in [(true, true), (false, true), (true, false), (false, false)]
        .into_iter()
        .enumerate()
    {
        match decode(layout, data, big, colour_counts) {
            Ok(mesh) => {
                if k > 0 {
                    warnings.push(format!(
                        "binary OFF read as {}: the only byte order and face layout that \
                         account for every byte (Geomview's spec says big-endian with a colour \
                         count after each face)",
                        describe(big, colour_counts)
                    ));
                }
                let enc = if big {
                    Encoding::BinaryBigEndian
                } else {
                    Encoding::BinaryLittleEndian
                };
                return Ok((mesh, enc));
            }
            Err(f) => {
                if furthest.as_ref().is_none_or(|(g, _, _)| f.at > g.at) {
                    furthest = Some((f, big, colour_counts));
                }
            }
        }
    }
    let Some((f, big, colour_counts)) = furthest else {
        return Err(Error::at_line(
            path,
            header_line,
            ErrorKind::Syntax("binary OFF could not be read".into()),
        ));
    };
    let context = format!(
        " (binary OFF after line {header_line}; no byte order or face layout reads the file, \
         and reading it as {} gets furthest)",
        describe(big, colour_counts)
    );
    let kind = match f.kind {
        ErrorKind::Truncated(m) => ErrorKind::Truncated(m + &context),
        ErrorKind::BadCount(m) => ErrorKind::BadCount(m + &context),
        ErrorKind::NonFinite(m) => ErrorKind::NonFinite(m + &context),
        other => other,
    };
    Err(Error::new(
        path,
        Location::Byte((data_start + f.at) as u64),
        kind,
    ))
}

fn describe(big: bool, colour_counts: bool) -> String {
    format!(
        "{}-endian {} per-face colour counts",
        if big { "big" } else { "little" },
        if colour_counts { "with" } else { "without" }
    )
}

/// Decodes the data in one byte order and face layout, checking everything listed in the
/// module documentation.
fn decode(
    layout: Layout,
    data: &[u8],
    big: bool,
    colour_counts: bool,
) -> std::result::Result<PolyMesh, Failure> {
    let mut c = Cursor { data, pos: 0, big };
    let nv = c.count("the vertex count")?;
    let nf = c.count("the face count")?;
    c.count("the edge count")?;
    let floats =
        3 + 3 * layout.normals as u64 + 4 * layout.colors as u64 + 2 * layout.texcoords as u64;
    // The smallest face: a count and three indices, plus the colour count.
    let min_face = 16 + 4 * colour_counts as u64;
    if nv * floats * 4 + nf * min_face > c.left() {
        return Err(Failure {
            at: 0,
            kind: ErrorKind::BadCount(format!(
                "{nv} vertices of {} bytes and {nf} faces of at least {min_face} bytes do not \
                 fit in the {} bytes of data",
                floats * 4,
                c.left()
            )),
        });
    }
    // Bounded by the check above.
    let mut positions = Vec::with_capacity(nv as usize);
    let mut normals = Vec::with_capacity(if layout.normals { nv as usize } else { 0 });
    let mut colors = Vec::with_capacity(if layout.colors { nv as usize } else { 0 });
    for i in 0..nv {
        let at = c.pos;
        let p = [(); 3].map(|_| c.float("a coordinate").unwrap_or(f64::NAN));
        if p.iter().any(|v| !v.is_finite()) {
            return Err(Failure {
                at,
                kind: ErrorKind::NonFinite(format!("vertex {i} at {p:?}")),
            });
        }
        positions.push(p);
        if layout.normals {
            let n = [(); 3].map(|_| c.float("a normal").unwrap_or(f64::NAN));
            if n.iter().any(|v| !v.is_finite()) {
                return Err(Failure {
                    at,
                    kind: ErrorKind::NonFinite(format!("normal of vertex {i}: {n:?}")),
                });
            }
            normals.push(n);
        }
        if layout.colors {
            let rgba = [(); 4].map(|_| c.float("a colour").unwrap_or(0.0));
            colors.push([rgba[0], rgba[1], rgba[2]].map(unit_to_u8));
        }
        if layout.texcoords {
            c.pos += 8;
        }
    }
    let faces = decode_faces(&mut c, nv, nf, colour_counts)?;
    if let Some(k) = c.data[c.pos..]
        .iter()
        .position(|b| !b.is_ascii_whitespace())
    {
        return Err(Failure {
            at: c.pos + k,
            kind: ErrorKind::BadCount(format!(
                "{} bytes after the last face",
                c.data.len() - c.pos
            )),
        });
    }
    Ok(PolyMesh {
        positions,
        normals: layout.normals.then_some(normals),
        colors: layout.colors.then_some(colors),
        faces,
    })
}

/// Decodes `nf` faces (the vertex records are already checked to fit, so every read past
/// them is bounds-checked by the cursor).
fn decode_faces(
    c: &mut Cursor<'_>,
    nv: u64,
    nf: u64,
    colour_counts: bool,
) -> std::result::Result<Polygons, Failure> {
    let mut faces = Polygons::with_capacity(nf as usize, 3 * nf as usize);
    let mut face = Vec::new();
    for i in 0..nf {
        let at = c.pos;
        let n = c.count("a face size")?;
        if n < 3 || n * 4 > c.left() {
            return Err(Failure {
                at,
                kind: ErrorKind::BadCount(format!(
                    "face {i} has {n} corners ({} bytes of data left)",
                    c.left()
                )),
            });
        }
        face.clear();
        for _ in 0..n {
            let at = c.pos;
            let v = c.int("a vertex index")?;
            if v < 0 || v as u64 >= nv {
                return Err(Failure {
                    at,
                    kind: ErrorKind::IndexOutOfRange {
                        index: v as i64,
                        count: nv,
                    },
                });
            }
            face.push(v as u32);
        }
        faces.push(&face);
        if colour_counts {
            let at = c.pos;
            let nc = c.count("a face colour count")?;
            if nc > 4 || nc * 4 > c.left() {
                return Err(Failure {
                    at,
                    kind: ErrorKind::BadCount(format!(
                        "face {i} announces {nc} colour components (at most 4)"
                    )),
                });
            }
            c.pos += 4 * nc as usize;
        }
    }
    Ok(faces)
}
