//! Mesh and point-cloud files for subfit.
//!
//! One registry ([`Format`]) maps extensions and file contents to a reader and a writer, so no
//! other crate matches on extensions. Readers work on the whole file in memory (`&[u8]`) and
//! never panic: every malformed input gives an [`Error`] naming the file, the line or element,
//! and what is wrong. Writers keep f64 precision where the format allows (ascii PLY/OBJ/OFF/XYZ
//! print the shortest round-tripping decimal; binary PLY can store `double`) and
//! [`write_file`] writes to a temporary name in the target directory, then renames, so no
//! partial file is ever left behind.

pub mod error;
mod mni;
pub mod obj;
pub mod off;
mod off_binary;
mod off_keyword;
pub mod ply;
pub mod stl;
pub mod tags_json;
mod text;
pub mod usda;
pub mod xyz;

use std::io::Write;
use std::path::{Path, PathBuf};

pub use error::{Error, ErrorKind, Location, Result};
use subfit_mesh::PolyMesh;

/// A supported file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// Stanford PLY (ascii, binary little- or big-endian; `face` lists and `tristrips`).
    Ply,
    /// Wavefront OBJ (`v`, `vn`, `f`).
    Obj,
    /// Object File Format (OFF, COFF, NOFF, CNOFF…; text or binary).
    Off,
    /// Stereolithography (ascii or binary; triangles, vertices welded on reading).
    Stl,
    /// Point list: `x y z` per line with optional normal, colour or intensity columns, or
    /// `p x y z` statements (`.xyz`, `.pts`, `.txt`; see [`xyz`]).
    Xyz,
}

/// How a format's data is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Encoding {
    /// Text.
    #[default]
    Ascii,
    /// Binary, little-endian.
    BinaryLittleEndian,
    /// Binary, big-endian (PLY; binary OFF on reading).
    BinaryBigEndian,
}

impl Format {
    /// Every format, in the order `info` lists them.
    pub const ALL: [Format; 5] = [
        Format::Ply,
        Format::Obj,
        Format::Off,
        Format::Stl,
        Format::Xyz,
    ];

    /// Short lowercase name (`ply`, `obj`, `off`, `stl`, `xyz`).
    pub fn name(self) -> &'static str {
        match self {
            Format::Ply => "ply",
            Format::Obj => "obj",
            Format::Off => "off",
            Format::Stl => "stl",
            Format::Xyz => "xyz",
        }
    }

    /// The format a file extension denotes (case-insensitive), if any.
    pub fn from_extension(ext: &str) -> Option<Format> {
        match ext.to_ascii_lowercase().as_str() {
            "ply" => Some(Format::Ply),
            "obj" => Some(Format::Obj),
            "off" | "coff" | "noff" | "cnoff" => Some(Format::Off),
            "stl" => Some(Format::Stl),
            "xyz" | "pts" | "txt" | "xyzn" => Some(Format::Xyz),
            _ => None,
        }
    }

    /// The format a path's extension denotes, if any.
    pub fn from_path(path: &Path) -> Option<Format> {
        path.extension()
            .and_then(|e| e.to_str())
            .and_then(Format::from_extension)
    }

    /// Guesses the format from the first bytes of a file (magic words), if they are telling.
    pub fn sniff(bytes: &[u8]) -> Option<Format> {
        let head = &bytes[..bytes.len().min(512)];
        let trimmed = trim_start(head);
        if trimmed.starts_with(b"ply") {
            return Some(Format::Ply);
        }
        if trimmed.starts_with(b"OFF")
            || trimmed.starts_with(b"COFF")
            || trimmed.starts_with(b"NOFF")
            || trimmed.starts_with(b"CNOFF")
        {
            return Some(Format::Off);
        }
        if trimmed.starts_with(b"solid") {
            return Some(Format::Stl);
        }
        if stl::is_binary_stl(bytes) {
            return Some(Format::Stl);
        }
        None
    }

    /// Whether a mesh can be written in this format without losing data, and if not, what
    /// would be lost (one short phrase per loss).
    pub fn losses(self, mesh: &PolyMesh) -> Vec<&'static str> {
        let mut lost = Vec::new();
        let has_faces = !mesh.faces.is_empty();
        match self {
            // PLY and OFF (CNOFF) carry positions, normals, colours and polygons.
            Format::Ply | Format::Off => {}
            Format::Obj => {
                if mesh.colors.is_some() {
                    lost.push("vertex colours");
                }
            }
            Format::Stl => {
                if mesh.normals.is_some() {
                    lost.push("vertex normals");
                }
                if mesh.colors.is_some() {
                    lost.push("vertex colours");
                }
                if !mesh.faces.is_triangles() {
                    lost.push("polygon structure (faces are triangulated)");
                }
                if !has_faces {
                    lost.push("points (STL holds only triangles)");
                }
                lost.push("vertex sharing and f64 precision (STL stores f32 per triangle corner)");
            }
            Format::Xyz => {
                if has_faces {
                    lost.push("faces");
                }
                if mesh.colors.is_some() {
                    lost.push("vertex colours");
                }
            }
        }
        lost
    }
}

fn trim_start(b: &[u8]) -> &[u8] {
    let n = b.iter().take_while(|c| c.is_ascii_whitespace()).count();
    &b[n..]
}

/// What was read, besides the mesh.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FileInfo {
    /// The format the data was parsed as.
    pub format: Format,
    /// Its encoding.
    pub encoding: Encoding,
    /// Size of the file in bytes.
    pub bytes: u64,
    /// What the reader decided or skipped in a file it still read, one sentence each, for the
    /// caller to show (columns taken as colours rather than normals, unknown header lines
    /// skipped, normals averaged, a file read as another variant of its format…). Each names
    /// the line or element it concerns where there is one; the file path is not repeated.
    pub warnings: Vec<String>,
}

/// Options for reading.
#[derive(Clone, Debug)]
pub struct ReadOptions {
    /// Force a format instead of detecting it. Default: `None` (extension, then content).
    pub format: Option<Format>,
    /// Merge STL corners with bit-identical positions into shared vertices. Default: `true`.
    pub weld_stl: bool,
}

impl Default for ReadOptions {
    fn default() -> Self {
        Self {
            format: None,
            weld_stl: true,
        }
    }
}

/// Options for writing.
#[derive(Clone, Debug, Default)]
pub struct WriteOptions {
    /// Format to write. Default: `None` (from the output path's extension).
    pub format: Option<Format>,
    /// Encoding (PLY: all three; STL: ascii or binary little-endian; others: ascii only).
    /// Default: ascii.
    pub encoding: Encoding,
    /// Store f32 instead of f64 in binary PLY (smaller files). Default: `false`.
    pub single_precision: bool,
}

/// Parses a file already in memory. `path` is used for error messages and format detection.
///
/// Cost: O(file size). Never panics.
pub fn read_bytes(bytes: &[u8], path: &Path, opts: &ReadOptions) -> Result<(PolyMesh, FileInfo)> {
    let format = match opts.format.or_else(|| Format::from_path(path)) {
        Some(f) => f,
        None => Format::sniff(bytes).ok_or_else(|| {
            let ext = path
                .extension()
                .map(|e| format!(" (extension .{})", e.to_string_lossy()))
                .unwrap_or_else(|| " (no extension, and the content is not recognised)".into());
            Error::file(path, ErrorKind::UnknownFormat(ext))
        })?,
    };
    if trim_start(bytes).is_empty() && format != Format::Stl {
        return Err(Error::file(path, ErrorKind::Empty));
    }
    if bytes.is_empty() {
        return Err(Error::file(path, ErrorKind::Empty));
    }
    let mut warnings = Vec::new();
    let w = &mut warnings;
    let (mesh, encoding) = match format {
        Format::Ply => ply::read(bytes, path, w)?,
        // An MNI surface is the one other `.obj` found in the wild; its first statement (`P`)
        // is not Wavefront's, so the content decides unambiguously.
        Format::Obj if mni::is_mni(bytes) => (mni::read(bytes, path, w)?, Encoding::Ascii),
        Format::Obj => (obj::read(bytes, path, w)?, Encoding::Ascii),
        Format::Off => off::read(bytes, path, w)?,
        Format::Stl => stl::read(bytes, path, opts.weld_stl)?,
        Format::Xyz => (xyz::read(bytes, path, w)?, Encoding::Ascii),
    };
    Ok((
        mesh,
        FileInfo {
            format,
            encoding,
            bytes: bytes.len() as u64,
            warnings,
        },
    ))
}

/// Reads a file from disk, detecting its format from the extension, then the content.
///
/// Errors: [`ErrorKind::IsDirectory`], [`ErrorKind::Io`], and every parse error of the readers.
pub fn read_file(path: &Path, opts: &ReadOptions) -> Result<(PolyMesh, FileInfo)> {
    let bytes = read_all(path)?;
    read_bytes(&bytes, path, opts)
}

/// Reads a whole file into memory with a clear error for directories and missing files.
pub fn read_all(path: &Path) -> Result<Vec<u8>> {
    if path.is_dir() {
        return Err(Error::file(path, ErrorKind::IsDirectory));
    }
    std::fs::read(path).map_err(|e| Error::file(path, ErrorKind::Io(e)))
}

/// Serializes a mesh into bytes in the given format and encoding.
pub fn write_bytes(mesh: &PolyMesh, format: Format, opts: &WriteOptions) -> Result<Vec<u8>> {
    let label = PathBuf::from(format!("<{} output>", format.name()));
    check_writable(mesh, format, opts, &label)?;
    let mut out = Vec::new();
    let res = match format {
        Format::Ply => ply::write(mesh, opts.encoding, opts.single_precision, &mut out),
        Format::Obj => obj::write(mesh, &mut out),
        Format::Off => off::write(mesh, &mut out),
        Format::Stl => stl::write(mesh, opts.encoding, &mut out),
        Format::Xyz => xyz::write(mesh, &mut out),
    };
    res.map_err(|e| Error::file(label, ErrorKind::Io(e)))?;
    Ok(out)
}

fn check_writable(mesh: &PolyMesh, format: Format, opts: &WriteOptions, path: &Path) -> Result<()> {
    let bad = |m: String| Err(Error::file(path, ErrorKind::CannotWrite(m)));
    match (format, opts.encoding) {
        (Format::Ply, _) | (_, Encoding::Ascii) => {}
        (Format::Stl, Encoding::BinaryLittleEndian) => {}
        (f, e) => return bad(format!("{} has no {e:?} encoding", f.name())),
    }
    if format == Format::Stl && mesh.faces.is_empty() {
        return bad("STL holds triangles only, and this data has no faces".into());
    }
    let n = mesh.positions.len();
    if mesh.normals.as_ref().is_some_and(|v| v.len() != n)
        || mesh.colors.as_ref().is_some_and(|v| v.len() != n)
    {
        return bad("attribute arrays do not match the vertex count".into());
    }
    if let Some(&m) = mesh.faces.indices().iter().max() {
        if m as usize >= n {
            return Err(Error::file(
                path,
                ErrorKind::IndexOutOfRange {
                    index: m as i64,
                    count: n as u64,
                },
            ));
        }
    }
    Ok(())
}

/// Writes a mesh to `path` atomically: the data goes to a temporary file in the same
/// directory, which is flushed, synced and renamed over `path`. On any error no file is left.
///
/// The format comes from `opts.format` or the extension of `path`.
pub fn write_file(path: &Path, mesh: &PolyMesh, opts: &WriteOptions) -> Result<()> {
    let format = opts
        .format
        .or_else(|| Format::from_path(path))
        .ok_or_else(|| {
            Error::file(
                path,
                ErrorKind::UnknownFormat(
                    " (cannot tell the output format from the extension)".into(),
                ),
            )
        })?;
    let bytes = write_bytes(mesh, format, opts).map_err(|mut e| {
        e.path = path.to_path_buf();
        e
    })?;
    write_atomic(path, &bytes)
}

/// Writes a mesh as PLY with extra per-vertex scalar properties (see
/// [`ply::write_with_properties`]), atomically like [`write_file`]. `opts.format` is ignored.
pub fn write_ply_with_properties(
    path: &Path,
    mesh: &PolyMesh,
    extra: &[ply::VertexProperty<'_>],
    opts: &WriteOptions,
) -> Result<()> {
    check_writable(mesh, Format::Ply, opts, path)?;
    let mut out = Vec::new();
    ply::write_with_properties(mesh, extra, opts.encoding, opts.single_precision, &mut out)
        .map_err(|e| Error::file(path, ErrorKind::CannotWrite(e.to_string())))?;
    write_atomic(path, &out)
}

/// Writes line segments as an ASCII PLY with `vertex` (x, y, z and a `uchar kind` per vertex)
/// and `edge` (`int vertex1, vertex2`) elements, the form MeshLab, CloudCompare and Blender's
/// PLY importer read as a wire mesh; atomically like [`write_file`]. `kinds` has one entry per
/// position (or is empty: all 0). Used for feature curves (kind 0 curve vertex, 1 corner,
/// 2 dart).
pub fn write_ply_edges(
    path: &Path,
    positions: &[[f64; 3]],
    kinds: &[u8],
    edges: &[[u32; 2]],
) -> Result<()> {
    use std::fmt::Write as _;
    let bad = |what: String| Err(Error::file(path, ErrorKind::CannotWrite(what)));
    if !kinds.is_empty() && kinds.len() != positions.len() {
        return bad(format!(
            "{} kinds for {} vertices",
            kinds.len(),
            positions.len()
        ));
    }
    if let Some(e) = edges
        .iter()
        .find(|e| e.iter().any(|&v| v as usize >= positions.len()))
    {
        return bad(format!(
            "edge {e:?} names a vertex beyond {}",
            positions.len()
        ));
    }
    let mut s = String::with_capacity(64 * (positions.len() + edges.len()) + 256);
    let _ = write!(
        s,
        "ply\nformat ascii 1.0\ncomment written by subfit {}\nelement vertex {}\n\
         property double x\nproperty double y\nproperty double z\nproperty uchar kind\n\
         element edge {}\nproperty int vertex1\nproperty int vertex2\nend_header\n",
        env!("CARGO_PKG_VERSION"),
        positions.len(),
        edges.len()
    );
    for (i, p) in positions.iter().enumerate() {
        let k = kinds.get(i).copied().unwrap_or(0);
        let _ = writeln!(s, "{} {} {} {k}", p[0], p[1], p[2]);
    }
    for e in edges {
        let _ = writeln!(s, "{} {}", e[0], e[1]);
    }
    write_atomic(path, s.as_bytes())
}

/// Writes a control cage as USDA (see [`usda`]) atomically. The cage must have faces.
pub fn write_usda_file(
    path: &Path,
    mesh: &PolyMesh,
    tags: &subfit_mesh::Tags,
    scheme: usda::UsdScheme,
    boundary: usda::UsdBoundary,
) -> Result<()> {
    if mesh.faces.is_empty() {
        return Err(Error::file(
            path,
            ErrorKind::CannotWrite("a USD mesh needs faces".into()),
        ));
    }
    check_writable(mesh, Format::Ply, &WriteOptions::default(), path)?;
    let mut out = Vec::new();
    usda::write(mesh, tags, scheme, boundary, &mut out);
    write_atomic(path, &out)
}

/// Writes a control cage as OBJ with its crease and corner tags as OpenSubdiv `t` statements
/// ([`obj::write_with_tags`]), atomically.
pub fn write_obj_with_tags_file(
    path: &Path,
    mesh: &PolyMesh,
    tags: &subfit_mesh::Tags,
) -> Result<()> {
    check_writable(mesh, Format::Obj, &WriteOptions::default(), path)?;
    let mut out = Vec::new();
    obj::write_with_tags(mesh, tags, &mut out).map_err(|e| Error::file(path, ErrorKind::Io(e)))?;
    write_atomic(path, &out)
}

/// Writes the crease and corner tags of a cage of `vertex_count` vertices as the JSON sidecar
/// of [`tags_json`] (`control.tags.json`), atomically.
pub fn write_tags_json_file(
    path: &Path,
    tags: &subfit_mesh::Tags,
    vertex_count: usize,
) -> Result<()> {
    write_atomic(path, tags_json::write(tags, vertex_count).as_bytes())
}

/// The crease and corner tags stored with a control mesh of `num_vertices` vertices: an OBJ
/// file's `t crease`/`t corner` statements ([`obj::read_tags`]); no tags for other formats.
pub fn read_tags_file(path: &Path, num_vertices: usize) -> Result<subfit_mesh::Tags> {
    if Format::from_path(path) != Some(Format::Obj) {
        return Ok(subfit_mesh::Tags::new());
    }
    obj::read_tags(&read_all(path)?, path, num_vertices)
}

/// Writes an animated control cage as USDA (see [`usda::write_animated`]) atomically:
/// `frames` holds the points of each frame (`N` frames of `#V by 3`), played at `fps` frames
/// per second.
///
/// Errors ([`ErrorKind::CannotWrite`], [`ErrorKind::IndexOutOfRange`]): no faces, no frames,
/// frames of different lengths, a face index beyond the points, or `fps` not positive and
/// finite.
pub fn write_usda_animated_file(
    path: &Path,
    faces: &subfit_mesh::Polygons,
    frames: &[Vec<[f64; 3]>],
    tags: &subfit_mesh::Tags,
    scheme: usda::UsdScheme,
    boundary: usda::UsdBoundary,
    fps: f64,
) -> Result<()> {
    let bad = |what: String| Err(Error::file(path, ErrorKind::CannotWrite(what)));
    let Some(first) = frames.first() else {
        return bad("an animation needs at least one frame".into());
    };
    if faces.is_empty() {
        return bad("a USD mesh needs faces".into());
    }
    if let Some((t, p)) = frames
        .iter()
        .enumerate()
        .find(|(_, p)| p.len() != first.len())
    {
        return bad(format!(
            "frame {t} has {} points, frame 0 has {}",
            p.len(),
            first.len()
        ));
    }
    if !(fps > 0.0 && fps.is_finite()) {
        return bad(format!("{fps} frames per second"));
    }
    if let Some(&m) = faces.indices().iter().max() {
        if m as usize >= first.len() {
            return Err(Error::file(
                path,
                ErrorKind::IndexOutOfRange {
                    index: m as i64,
                    count: first.len() as u64,
                },
            ));
        }
    }
    let mut out = Vec::new();
    usda::write_animated(faces, frames, tags, scheme, boundary, fps, &mut out);
    write_atomic(path, &out)
}

/// Writes `bytes` to `path` through a temporary file in the same directory and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let io_err = |e: std::io::Error| Error::file(path, ErrorKind::Io(e));
    if path.is_dir() {
        return Err(Error::file(path, ErrorKind::IsDirectory));
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(io_err(e));
    }
    Ok(())
}
