//! The binary (little- and big-endian) record decoder.

use std::path::Path;

use super::header::{Element, Header, Role, Scalar, Slot, Ty};
use super::sink::{set_color, Record, Sink};
use crate::error::{Error, ErrorKind, Result};

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

pub(super) fn read_binary(
    h: &Header,
    data: &[u8],
    big: bool,
    path: &Path,
    sink: &mut Sink,
) -> Result<()> {
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
        rec.nan_color = false;
        for &(o, s, slot) in &used {
            let v = bin_f64(s, &r[o..], big);
            match slot {
                Slot::Coord(k) => rec.p[k] = v,
                Slot::Normal(k) => rec.n[k] = v,
                Slot::Color(k) => set_color(rec, k, v, s),
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
    rec.nan_color = false;
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
                    Slot::Color(k) => set_color(rec, k, v, s),
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
