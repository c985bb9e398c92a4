//! Writing: [`write`] and [`write_with_properties`].

use std::io::Write as _;

use subfit_mesh::PolyMesh;

use super::header::{Scalar, AXES, NORMAL_AXES};
use crate::text::push_f64;
use crate::Encoding;

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
