//! `subfit.read` / `subfit.write`: the formats of `subfit::io` (PLY, OBJ, OFF, STL, XYZ; USDA
//! cages on writing) from and to numpy arrays, through its single format registry.

use std::path::PathBuf;

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use subfit::io::usda::{UsdBoundary, UsdScheme};
use subfit::io::{Encoding, Format, ReadOptions, WriteOptions};
use subfit::mesh::{PolyMesh, Polygons, Tags};

use crate::arrays::{polygons, polygons_to_py, tags, vec3s, vec3s_to_py};
use crate::errors::{io_error, value_error};

/// What `read` returns: positions, normals, colours, faces `(offsets, indices)`, format name.
type ReadResult<'py> = (
    Bound<'py, PyArray2<f64>>,
    Option<Bound<'py, PyArray2<f64>>>,
    Option<Bound<'py, PyArray2<u8>>>,
    (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<i64>>),
    &'static str,
);

/// Reads a mesh or point cloud (format from the extension, else the content).
#[pyfunction]
pub fn read(py: Python<'_>, path: PathBuf) -> PyResult<ReadResult<'_>> {
    let (mesh, info) = py
        .detach(|| subfit::io::read_file(&path, &ReadOptions::default()))
        .map_err(io_error)?;
    let colors = mesh.colors.as_ref().map(|c| {
        Array2::from_shape_vec((c.len(), 3), c.iter().flatten().copied().collect())
            .expect("n × 3 colours")
            .into_pyarray(py)
    });
    Ok((
        vec3s_to_py(py, &mesh.positions),
        mesh.normals.as_ref().map(|n| vec3s_to_py(py, n)),
        colors,
        polygons_to_py(py, &mesh.faces),
        info.format.name(),
    ))
}

/// The extensions `write` understands.
#[pyfunction]
pub fn formats() -> Vec<&'static str> {
    vec![
        "ply", "obj", "off", "stl", "xyz", "pts", "txt", "xyzn", "usda",
    ]
}

/// Faces as `(counts, indices)` int64 arrays.
type FaceArrays<'py> = (PyReadonlyArray1<'py, i64>, PyReadonlyArray1<'py, i64>);
/// Tags as four arrays.
type TagArrays<'py> = (
    PyReadonlyArray2<'py, i64>,
    PyReadonlyArray1<'py, f64>,
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, f64>,
);

/// Writes a mesh or point cloud atomically; the format comes from the extension. `.usda`
/// writes a subdivision cage (faces required) with `scheme` and tags.
#[pyfunction]
#[pyo3(signature = (path, vertices, faces=None, normals=None, colors=None, binary=false, scheme="catmull-clark", tag_arrays=None, boundary="edge-only"))]
#[allow(clippy::too_many_arguments)]
pub fn write(
    py: Python<'_>,
    path: PathBuf,
    vertices: PyReadonlyArray2<'_, f64>,
    faces: Option<FaceArrays<'_>>,
    normals: Option<PyReadonlyArray2<'_, f64>>,
    colors: Option<PyReadonlyArray2<'_, u8>>,
    binary: bool,
    scheme: &str,
    tag_arrays: Option<TagArrays<'_>>,
    boundary: &str,
) -> PyResult<()> {
    let positions = vec3s("vertices", &vertices, 1)?;
    let n = positions.len();
    let faces = match &faces {
        Some((c, i)) => polygons(c, i, n)?,
        None => Polygons::new(),
    };
    let mut mesh = PolyMesh::new(positions, faces);
    if let Some(nr) = &normals {
        let nr = vec3s("normals", nr, 0)?;
        if nr.len() != n {
            return Err(value_error(format!(
                "normals must have one row per vertex: {} rows for {n} vertices",
                nr.len()
            )));
        }
        mesh.normals = Some(nr);
    }
    if let Some(c) = &colors {
        let c = c.as_array();
        if c.dim() != (n, 3) {
            return Err(value_error(format!(
                "colors must have shape ({n}, 3) uint8, got {:?}",
                c.dim()
            )));
        }
        mesh.colors = Some(c.outer_iter().map(|r| [r[0], r[1], r[2]]).collect());
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext == "usda" {
        let scheme = match scheme.to_ascii_lowercase().as_str() {
            "loop" => UsdScheme::Loop,
            "catmull-clark" | "catmull_clark" | "catmullclark" | "cc" => UsdScheme::CatmullClark,
            // As the CLI writes it: Loop when the cage has no quads (the same surface).
            "quad-tri" | "quad_tri" | "quadtriangle" | "quad-triangle" => {
                subfit::usd_scheme(subfit::subdiv::Scheme::QuadTriangle, &mesh.faces)
            }
            "none" => UsdScheme::None,
            _ => {
                return Err(value_error(format!(
                    "scheme must be \"loop\", \"catmull-clark\", \"quad-tri\" or \"none\", got {scheme:?}"
                )))
            }
        };
        let boundary = match boundary {
            "edge-only" => UsdBoundary::EdgeOnly,
            "edge-and-corner" => UsdBoundary::EdgeAndCorner,
            _ => {
                return Err(value_error(format!(
                    "boundary must be \"edge-only\" or \"edge-and-corner\", got {boundary:?}"
                )))
            }
        };
        let t = match &tag_arrays {
            Some((e, es, c, cs)) => tags(e, es, c, cs, n)?,
            None => Tags::new(),
        };
        return py
            .detach(|| subfit::io::write_usda_file(&path, &mesh, &t, scheme, boundary))
            .map_err(io_error);
    }
    if Format::from_extension(&ext).is_none() {
        return Err(value_error(format!(
            "{}: cannot tell the format from the extension (one of {})",
            path.display(),
            formats().join(", ")
        )));
    }
    let opts = WriteOptions {
        format: None,
        encoding: if binary {
            Encoding::BinaryLittleEndian
        } else {
            Encoding::Ascii
        },
        single_precision: false,
    };
    py.detach(|| subfit::io::write_file(&path, &mesh, &opts))
        .map_err(io_error)
}
