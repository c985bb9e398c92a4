//! numpy arrays in and out, validated: every array that crosses into the library is checked
//! here (shape, finiteness, index ranges) so that a bad one is a `ValueError` naming the
//! argument, the row and the reason, never a panic in the library.

use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use subfit::mesh::{Polygons, Tags};

use crate::errors::value_error;

/// Rows of an `(n, 3)` float64 array, checked: three columns, at least `min_rows` rows, every
/// value finite. `name` is the argument's name in the messages.
pub fn vec3s(
    name: &str,
    a: &PyReadonlyArray2<'_, f64>,
    min_rows: usize,
) -> PyResult<Vec<[f64; 3]>> {
    let v = a.as_array();
    let (n, c) = v.dim();
    if c != 3 {
        return Err(value_error(format!(
            "{name} must have shape (n, 3), got ({n}, {c})"
        )));
    }
    if n < min_rows {
        return Err(value_error(format!(
            "{name} needs at least {min_rows} rows (points), got {n}"
        )));
    }
    let mut out = Vec::with_capacity(n);
    for (i, row) in v.outer_iter().enumerate() {
        let p = [row[0], row[1], row[2]];
        if !p.iter().all(|x| x.is_finite()) {
            return Err(value_error(format!(
                "{name}[{i}] is not finite: ({}, {}, {})",
                p[0], p[1], p[2]
            )));
        }
        out.push(p);
    }
    Ok(out)
}

/// A face list from `counts` (`(m,)`, vertices per face) and `indices` (`(Σ counts,)`), checked
/// against `num_vertices`: every face has at least 3 vertices, indices are in range, the counts
/// add up. A face repeating a vertex is left to the library's topology checks.
pub fn polygons(
    counts: &PyReadonlyArray1<'_, i64>,
    indices: &PyReadonlyArray1<'_, i64>,
    num_vertices: usize,
) -> PyResult<Polygons> {
    let counts = counts.as_array();
    let indices = indices.as_array();
    if counts.is_empty() {
        return Err(value_error("faces is empty: at least one face is needed"));
    }
    let mut offsets = Vec::with_capacity(counts.len() + 1);
    offsets.push(0u32);
    let mut total: u64 = 0;
    for (f, &c) in counts.iter().enumerate() {
        if c < 3 {
            return Err(value_error(format!(
                "faces[{f}] has {c} vertices; a face needs at least 3"
            )));
        }
        total += c as u64;
        if total > u32::MAX as u64 {
            return Err(value_error("faces has more than 2^32 corners"));
        }
        offsets.push(total as u32);
    }
    if total != indices.len() as u64 {
        return Err(value_error(format!(
            "faces: the counts add up to {total} corners but {} indices were given",
            indices.len()
        )));
    }
    let mut idx = Vec::with_capacity(indices.len());
    let mut face = 0usize;
    for (k, &i) in indices.iter().enumerate() {
        while offsets[face + 1] as usize <= k {
            face += 1;
        }
        if i < 0 || i as u64 >= num_vertices as u64 {
            return Err(value_error(format!(
                "faces[{face}] refers to vertex {i}, out of range for {num_vertices} vertices"
            )));
        }
        idx.push(i as u32);
    }
    Polygons::from_raw(offsets, idx).ok_or_else(|| value_error("faces: inconsistent face list"))
}

/// Crease and corner tags from `(k, 2)` crease edges with `(k,)` sharpness and `(c,)` corner
/// vertices with `(c,)` sharpness, checked against `num_vertices` (sharpness finite and ≥ 0).
pub fn tags(
    crease_edges: &PyReadonlyArray2<'_, i64>,
    crease_sharpness: &PyReadonlyArray1<'_, f64>,
    corners: &PyReadonlyArray1<'_, i64>,
    corner_sharpness: &PyReadonlyArray1<'_, f64>,
    num_vertices: usize,
) -> PyResult<Tags> {
    let e = crease_edges.as_array();
    let es = crease_sharpness.as_array();
    let c = corners.as_array();
    let cs = corner_sharpness.as_array();
    if e.ncols() != 2 && e.nrows() > 0 {
        return Err(value_error(format!(
            "tags: crease edges must have shape (k, 2), got {:?}",
            e.dim()
        )));
    }
    if e.nrows() != es.len() || c.len() != cs.len() {
        return Err(value_error(
            "tags: one sharpness per crease edge and per corner is needed",
        ));
    }
    let vertex = |what: &str, v: i64| -> PyResult<u32> {
        if v < 0 || v as u64 >= num_vertices as u64 {
            Err(value_error(format!(
                "tags: {what} vertex {v} out of range for {num_vertices} vertices"
            )))
        } else {
            Ok(v as u32)
        }
    };
    let sharp = |what: &str, s: f64| -> PyResult<f64> {
        if s.is_finite() && s >= 0.0 {
            Ok(s)
        } else {
            Err(value_error(format!(
                "tags: {what} sharpness must be finite and ≥ 0, got {s}"
            )))
        }
    };
    let mut t = Tags::new();
    for (row, &s) in e.outer_iter().zip(es.iter()) {
        let (a, b) = (vertex("crease", row[0])?, vertex("crease", row[1])?);
        if a == b {
            return Err(value_error(format!(
                "tags: crease edge ({a}, {a}) is a loop"
            )));
        }
        t.set_crease(a, b, sharp("crease", s)?);
    }
    for (&v, &s) in c.iter().zip(cs.iter()) {
        t.set_corner(vertex("corner", v)?, sharp("corner", s)?);
    }
    Ok(t)
}

/// `(n, 3)` float64 array of `rows`.
pub fn vec3s_to_py<'py>(py: Python<'py>, rows: &[[f64; 3]]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    Array2::from_shape_vec((rows.len(), 3), flat)
        .expect("n × 3 values")
        .into_pyarray(py)
}

/// `(offsets, indices)` int64 arrays of a face list (`offsets` has `m + 1` entries).
pub fn polygons_to_py<'py>(
    py: Python<'py>,
    faces: &Polygons,
) -> (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<i64>>) {
    let off: Vec<i64> = faces.offsets().iter().map(|&o| i64::from(o)).collect();
    let idx: Vec<i64> = faces.indices().iter().map(|&i| i64::from(i)).collect();
    (
        Array1::from(off).into_pyarray(py),
        Array1::from(idx).into_pyarray(py),
    )
}

/// Tags as `(crease_edges (k, 2) int64, crease_sharpness (k,), corners (c,) int64,
/// corner_sharpness (c,))`, sorted by vertex ids.
#[allow(clippy::type_complexity)]
pub fn tags_to_py<'py>(
    py: Python<'py>,
    tags: &Tags,
) -> (
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<f64>>,
) {
    let mut creases = tags.creases();
    creases.sort_by_key(|a| a.0);
    let mut corners = tags.corners();
    corners.sort_by_key(|a| a.0);
    let e: Vec<i64> = creases
        .iter()
        .flat_map(|((a, b), _)| [i64::from(*a), i64::from(*b)])
        .collect();
    let es: Vec<f64> = creases.iter().map(|(_, s)| *s).collect();
    let c: Vec<i64> = corners.iter().map(|(v, _)| i64::from(*v)).collect();
    let cs: Vec<f64> = corners.iter().map(|(_, s)| *s).collect();
    (
        Array2::from_shape_vec((creases.len(), 2), e)
            .expect("k × 2 values")
            .into_pyarray(py),
        Array1::from(es).into_pyarray(py),
        Array1::from(c).into_pyarray(py),
        Array1::from(cs).into_pyarray(py),
    )
}

/// A scheme name: `loop`, `catmull-clark` (also `catmull_clark`, `catmullclark`, `cc`),
/// `quad-tri`, or
/// `auto` (`None`) when `allow_auto`.
pub fn scheme(name: &str, allow_auto: bool) -> PyResult<Option<subfit::subdiv::Scheme>> {
    use subfit::subdiv::Scheme;
    match name.to_ascii_lowercase().as_str() {
        "loop" => Ok(Some(Scheme::Loop)),
        "catmull-clark" | "catmull_clark" | "catmullclark" | "cc" => Ok(Some(Scheme::CatmullClark)),
        "quad-tri" | "quad_tri" | "quadtriangle" | "quad-triangle" => {
            Ok(Some(Scheme::QuadTriangle))
        }
        "auto" if allow_auto => Ok(None),
        _ => Err(value_error(format!(
            "scheme must be {}\"loop\", \"catmull-clark\" or \"quad-tri\", got {name:?}",
            if allow_auto { "\"auto\", " } else { "" }
        ))),
    }
}

/// The Python name of a scheme.
pub fn scheme_name(s: subfit::subdiv::Scheme) -> &'static str {
    s.name()
}
