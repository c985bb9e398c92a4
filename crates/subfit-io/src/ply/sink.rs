//! The mesh being built ([`Sink`]) from the records the ascii and binary decoders fill
//! ([`Record`]): vertex checks, face indices and `tristrips` unrolling.

use subfit_mesh::Polygons;

use super::header::{Role, Scalar, AXES, NORMAL_AXES};
use crate::error::ErrorKind;

/// The values of one record that matter, filled by the ascii or binary decoder.
#[derive(Default)]
pub(super) struct Record {
    pub(super) p: [f64; 3],
    pub(super) n: [f64; 3],
    pub(super) c: [u8; 3],
    /// Whether a colour component of this record is NaN (it reads as 0).
    pub(super) nan_color: bool,
    /// The index list (face corners or strip indices, `-1` included).
    pub(super) list: Vec<i64>,
}

/// Stores colour component `k` of type `s` into `rec` (8 bits; NaN noted and read as 0).
#[inline]
pub(super) fn set_color(rec: &mut Record, k: usize, v: f64, s: Scalar) {
    rec.c[k] = color8(v, s);
    rec.nan_color |= v.is_nan();
}

/// Converts a colour value of type `s` to 8 bits.
#[inline]
fn color8(v: f64, s: Scalar) -> u8 {
    let v = if s.is_float() { (v * 255.0).round() } else { v };
    // `as` saturates (NaN → 0).
    v.clamp(0.0, 255.0) as u8
}

/// The mesh being built.
pub(super) struct Sink {
    pub(super) positions: Vec<[f64; 3]>,
    pub(super) normals: Option<Vec<[f64; 3]>>,
    pub(super) colors: Option<Vec<[u8; 3]>>,
    pub(super) faces: Polygons,
    pub(super) vertex_count: u64,
    pub(super) face: Vec<u32>,
    /// Vertices with a NaN colour component.
    pub(super) nan_colors: u64,
}

/// `NonFinite` naming the first non-finite component of vertex `index`.
pub(super) fn check_finite(
    v: &[f64; 3],
    names: [&str; 3],
    index: u64,
) -> std::result::Result<(), ErrorKind> {
    match v.iter().zip(names).find(|(c, _)| !c.is_finite()) {
        Some((c, name)) => Err(ErrorKind::NonFinite(format!(
            "{name} = {c} in vertex {index}"
        ))),
        None => Ok(()),
    }
}

impl Sink {
    pub(super) fn reserve(&mut self, role: Role, n: usize) {
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
    pub(super) fn finish(
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
                    self.nan_colors += rec.nan_color as u64;
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
    pub(super) fn room_for(&self, n: usize) -> std::result::Result<(), ErrorKind> {
        if self.faces.indices().len() + n > u32::MAX as usize {
            return Err(ErrorKind::BadCount(
                "more than 2^32 - 1 face corners in total".into(),
            ));
        }
        Ok(())
    }

    #[inline]
    pub(super) fn check_index(&self, i: i64) -> std::result::Result<u32, ErrorKind> {
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
    pub(super) fn strips(&mut self, list: &[i64]) -> std::result::Result<(), ErrorKind> {
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
