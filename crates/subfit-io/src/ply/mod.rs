//! Stanford PLY (Turk 1994; the format as written by Stanford's `ply` tools, VCG/MeshLab and
//! Cyberware): reader and writer.
//!
//! **Reading** accepts `format ascii 1.0`, `binary_little_endian 1.0` and
//! `binary_big_endian 1.0`; header lines may end in `\n` or `\r\n`; `comment` and `obj_info`
//! lines are ignored (they may hold any bytes), and so are lines with an unknown keyword (old
//! Cyberware range scans carry stray `bye` lines), with a warning naming them. Properties may
//! come in any order and have any scalar type (`char`, `uchar`, `short`, `ushort`, `int`,
//! `uint`, `float`, `double` and the aliases `int8` … `float64`). What is taken:
//! - `element vertex`: `x`, `y`, `z` (required, any scalar type); `nx`, `ny`, `nz` when all three
//!   are present; `red`, `green`, `blue` (or `diffuse_red` …) when all three are present —
//!   integer colours are clamped to 0..=255, float colours in 0..1 are scaled by 255; a NaN
//!   colour component reads as 0 (with a warning counting such vertices). Other vertex
//!   properties are skipped.
//! - `element face`: a list property `vertex_indices` (or `vertex_index`) with any integer count
//!   and index types; faces of every size are kept as they are; other face properties (colours,
//!   flags, texture coordinate lists) are skipped.
//! - `element tristrips`: a list `vertex_indices`; `-1` ends a strip, every odd triangle of a
//!   strip is flipped to keep the orientation, and triangles with two equal corners (the
//!   "swap" triangles strip encoders insert) are dropped.
//! - every other element is skipped, including its list properties.
//!
//! Ascii values keep the precision of their text whatever type the header declares.
//!
//! Every problem is an [`Error`](crate::Error): ascii files report the 1-based line
//! ([`crate::Location::Line`], the message names the element), binary files the element
//! ([`crate::Location::Element`], the message gives the byte offset). The reader never panics,
//! and never allocates more than the remaining bytes could hold, whatever the counts in the
//! header say. Non-finite positions and normals and out-of-range indices are errors.
//!
//! **Writing** produces `vertex` with `double` coordinates (`float` when `single_precision`),
//! normals and `uchar` colours when present, and `face` as `list uchar int vertex_indices`
//! (`ushort`/`uint` counts for faces of more than 255/65535 corners, `uint` indices past
//! `i32::MAX` vertices). Ascii output prints the shortest decimal that reads back exactly.
//!
//! This is a parser of our own rather than the `ply-rs-bw` crate: we need element- and
//! line-level error locations, a no-panic guarantee under fuzzing with allocation capped by the
//! data, `tristrips`, and I/O-bound speed on fixed-layout binary records.
//!
//! Modules: `header` (the header and the record layout it declares), `sink` (the mesh being
//! built from decoded records), `ascii` and `binary` (the two record decoders), `read`
//! ([`read()`]), `write` ([`write()`], [`write_with_properties`]).

mod ascii;
mod binary;
mod header;
mod read;
mod sink;
mod write;

pub use read::read;
pub use write::{write, write_with_properties, VertexProperty};
