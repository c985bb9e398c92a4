//! `subfit.Surface` and the sampling operator for `subfit.torch.LimitSurface`: a control mesh
//! with a scheme, and what `subfit::subdiv` computes on it — limit samples through the sparse
//! operator `C = L_l · M_l ⋯ M_1` (DESIGN.md decision 1), exact evaluation at `(face, u, v)` with
//! derivatives (module `eval`), and closest points on the limit surface (`closest`).

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use numpy::ndarray::Array1;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use rayon::prelude::*;
use subfit::mesh::{Polygons, Tags};
use subfit::subdiv::{
    sampling_operator as build_operator, ClosestOptions, ClosestPointFinder, Evaluator, Options,
    SamplingOperator, Scheme, StencilMatrix, SurfaceParam,
};

use crate::arrays::{polygons, polygons_to_py, scheme, scheme_name, tags, vec3s, vec3s_to_py};
use crate::errors::{eval_error, value_error};

/// The finest sampling level accepted (a level multiplies the samples by about 4).
const MAX_LEVEL: i64 = 8;

/// A CSR matrix for Python: `(indptr (r + 1,), indices (nnz,), data (nnz,), (r, c))`, int64
/// indices.
type Csr<'py> = (
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<f64>>,
    (usize, usize),
);

fn csr_to_py<'py>(py: Python<'py>, m: &StencilMatrix) -> Csr<'py> {
    let ptr: Vec<i64> = m.offsets().iter().map(|&o| o as i64).collect();
    let idx: Vec<i64> = m.indices().iter().map(|&i| i64::from(i)).collect();
    (
        Array1::from(ptr).into_pyarray(py),
        Array1::from(idx).into_pyarray(py),
        Array1::from(m.weights().to_vec()).into_pyarray(py),
        (m.nrows(), m.ncols()),
    )
}

fn level(l: i64) -> PyResult<usize> {
    if !(0..=MAX_LEVEL).contains(&l) {
        return Err(value_error(format!(
            "level must be in [0, {MAX_LEVEL}], got {l}"
        )));
    }
    Ok(l as usize)
}

/// Tags from the four optional arrays (all or none).
type TagArrays<'py> = (
    PyReadonlyArray2<'py, i64>,
    PyReadonlyArray1<'py, f64>,
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, f64>,
);

fn tags_of(t: Option<&TagArrays<'_>>, n: usize) -> PyResult<Tags> {
    match t {
        None => Ok(Tags::new()),
        Some((e, es, c, cs)) => tags(e, es, c, cs, n),
    }
}

/// The operator of `faces` at `level`, with the topology errors as `ValueError`.
fn operator_of(
    faces: &Polygons,
    n: usize,
    tags: &Tags,
    scheme: Scheme,
    level: usize,
) -> PyResult<SamplingOperator> {
    build_operator(faces, n, tags, &Options::new(scheme), level)
        .map_err(|e| value_error(e.to_string()))
}

/// The sampling operator of a control mesh given by its faces alone (`LimitSurface`): the CSR
/// position matrix `(s, num_vertices)` and the level-`l` faces `(offsets, indices)` over its rows.
#[pyfunction]
#[pyo3(signature = (counts, indices, num_vertices, scheme_name, level_, tag_arrays=None))]
#[allow(clippy::type_complexity)]
pub fn sampling_operator<'py>(
    py: Python<'py>,
    counts: PyReadonlyArray1<'py, i64>,
    indices: PyReadonlyArray1<'py, i64>,
    num_vertices: i64,
    scheme_name: &str,
    level_: i64,
    tag_arrays: Option<TagArrays<'py>>,
) -> PyResult<(
    Csr<'py>,
    (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<i64>>),
)> {
    if !(3..=u32::MAX as i64 - 1).contains(&num_vertices) {
        return Err(value_error(format!(
            "num_vertices must be at least 3, got {num_vertices}"
        )));
    }
    let n = num_vertices as usize;
    let faces = polygons(&counts, &indices, n)?;
    let t = tags_of(tag_arrays.as_ref(), n)?;
    let s = scheme(scheme_name, false)?.unwrap_or(Scheme::Loop);
    let l = level(level_)?;
    let op = py.detach(|| operator_of(&faces, n, &t, s, l))?;
    Ok((csr_to_py(py, &op.position), polygons_to_py(py, &op.faces)))
}

/// A control mesh with its scheme and tags: limit samples, operators, exact evaluation and
/// closest points. Immutable; operators are built once per level and kept.
#[pyclass(frozen, module = "subfit._subfit")]
pub struct NativeSurface {
    positions: Vec<[f64; 3]>,
    faces: Polygons,
    tags: Tags,
    scheme: Scheme,
    evaluator: Evaluator,
    operators: Mutex<HashMap<usize, Arc<SamplingOperator>>>,
}

impl NativeSurface {
    fn op(&self, py: Python<'_>, l: i64) -> PyResult<Arc<SamplingOperator>> {
        let l = level(l)?;
        if let Some(op) = self
            .operators
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .get(&l)
        {
            return Ok(op.clone());
        }
        let op = Arc::new(py.detach(|| {
            operator_of(
                &self.faces,
                self.positions.len(),
                &self.tags,
                self.scheme,
                l,
            )
        })?);
        self.operators
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .insert(l, op.clone());
        Ok(op)
    }
}

/// Parameters from equal-length arrays, checked for shape (the evaluator checks ranges).
fn params(
    face: &PyReadonlyArray1<'_, i64>,
    u: &PyReadonlyArray1<'_, f64>,
    v: &PyReadonlyArray1<'_, f64>,
    sub: &PyReadonlyArray1<'_, i64>,
) -> PyResult<Vec<SurfaceParam>> {
    let (f, u, v, s) = (face.as_array(), u.as_array(), v.as_array(), sub.as_array());
    if u.len() != f.len() || v.len() != f.len() || s.len() != f.len() {
        return Err(value_error(format!(
            "face, u, v and sub must have the same length, got {}, {}, {}, {}",
            f.len(),
            u.len(),
            v.len(),
            s.len()
        )));
    }
    (0..f.len())
        .map(|i| {
            if f[i] < 0 || f[i] > u32::MAX as i64 || s[i] < 0 || s[i] > u32::MAX as i64 {
                return Err(value_error(format!(
                    "face[{i}] = {} or sub[{i}] = {} is out of range",
                    f[i], s[i]
                )));
            }
            Ok(SurfaceParam {
                face: f[i] as u32,
                sub: s[i] as u32,
                u: u[i],
                v: v[i],
            })
        })
        .collect()
}

#[pymethods]
impl NativeSurface {
    /// Validates and builds: `vertices (n, 3)`, faces `(counts, indices)`, scheme name, tags.
    #[new]
    #[pyo3(signature = (vertices, counts, indices, scheme_name, tag_arrays=None))]
    fn new(
        py: Python<'_>,
        vertices: PyReadonlyArray2<'_, f64>,
        counts: PyReadonlyArray1<'_, i64>,
        indices: PyReadonlyArray1<'_, i64>,
        scheme_name: &str,
        tag_arrays: Option<TagArrays<'_>>,
    ) -> PyResult<Self> {
        let positions = vec3s("vertices", &vertices, 3)?;
        let n = positions.len();
        let faces = polygons(&counts, &indices, n)?;
        let tags = tags_of(tag_arrays.as_ref(), n)?;
        let scheme = scheme(scheme_name, false)?.unwrap_or(Scheme::Loop);
        let evaluator = py
            .detach(|| Evaluator::new(&faces, n, &tags, &Options::new(scheme)))
            .map_err(eval_error)?;
        Ok(Self {
            positions,
            faces,
            tags,
            scheme,
            evaluator,
            operators: Mutex::new(HashMap::new()),
        })
    }

    /// `"loop"` or `"catmull-clark"`.
    #[getter]
    fn scheme(&self) -> &'static str {
        scheme_name(self.scheme)
    }

    /// Limit positions of the level-`level` vertices, `(s, 3)`, and their unit normals when
    /// `normals`.
    #[pyo3(signature = (level_, normals=false))]
    #[allow(clippy::type_complexity)]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        level_: i64,
        normals: bool,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Option<Bound<'py, PyArray2<f64>>>)> {
        let op = self.op(py, level_)?;
        if normals {
            let s = py.detach(|| op.evaluate(&self.positions));
            Ok((
                vec3s_to_py(py, &s.positions),
                Some(vec3s_to_py(py, &s.normals)),
            ))
        } else {
            let p = py.detach(|| op.position.apply(&self.positions));
            Ok((vec3s_to_py(py, &p), None))
        }
    }

    /// The operator at `level`: `which` is `position`, `tangent1` or `tangent2`.
    #[pyo3(signature = (level_, which="position"))]
    fn operator<'py>(&self, py: Python<'py>, level_: i64, which: &str) -> PyResult<Csr<'py>> {
        let op = self.op(py, level_)?;
        let m = match which {
            "position" => &op.position,
            "tangent1" => &op.tangent1,
            "tangent2" => &op.tangent2,
            _ => {
                return Err(value_error(format!(
                    "which must be \"position\", \"tangent1\" or \"tangent2\", got {which:?}"
                )))
            }
        };
        Ok(csr_to_py(py, m))
    }

    /// Faces of the level-`level` mesh over the sample rows, `(offsets, indices)`.
    #[allow(clippy::type_complexity)]
    fn level_faces<'py>(
        &self,
        py: Python<'py>,
        level_: i64,
    ) -> PyResult<(Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<i64>>)> {
        let op = self.op(py, level_)?;
        Ok(polygons_to_py(py, &op.faces))
    }

    /// Exact evaluation: `(position, du, dv, normal, second)`, each `(k, 3)`; `second` is
    /// `(k, 3, 3)` (`S_uu`, `S_uv`, `S_vv`), NaN where not available.
    #[allow(clippy::type_complexity)]
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        face: PyReadonlyArray1<'py, i64>,
        u: PyReadonlyArray1<'py, f64>,
        v: PyReadonlyArray1<'py, f64>,
        sub: PyReadonlyArray1<'py, i64>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, numpy::PyArray3<f64>>,
    )> {
        let ps = params(&face, &u, &v, &sub)?;
        let pts = py
            .detach(|| self.evaluator.evaluate_batch(&self.positions, &ps))
            .map_err(eval_error)?;
        let col = |f: &dyn Fn(&subfit::subdiv::SurfacePoint) -> [f64; 3]| {
            vec3s_to_py(py, &pts.iter().map(f).collect::<Vec<_>>())
        };
        let second: Vec<f64> = pts
            .iter()
            .flat_map(|p| p.second.unwrap_or([[f64::NAN; 3]; 3]))
            .flatten()
            .collect();
        let second = numpy::ndarray::Array3::from_shape_vec((pts.len(), 3, 3), second)
            .expect("k × 3 × 3 values")
            .into_pyarray(py);
        Ok((
            col(&|p| p.position),
            col(&|p| p.du),
            col(&|p| p.dv),
            col(&|p| p.normal),
            second,
        ))
    }

    /// Weights of the limit positions at the parameters over the control points, CSR `(k, n)`.
    fn evaluation_operator<'py>(
        &self,
        py: Python<'py>,
        face: PyReadonlyArray1<'py, i64>,
        u: PyReadonlyArray1<'py, f64>,
        v: PyReadonlyArray1<'py, f64>,
        sub: PyReadonlyArray1<'py, i64>,
    ) -> PyResult<Csr<'py>> {
        let ps = params(&face, &u, &v, &sub)?;
        let m = py.detach(|| -> PyResult<StencilMatrix> {
            let rows: Vec<_> = ps
                .par_iter()
                .map(|&p| self.evaluator.weights(p))
                .collect::<Result<_, _>>()
                .map_err(eval_error)?;
            let mut m = StencilMatrix::new(self.positions.len());
            for w in rows {
                let mut e: Vec<(u32, f64)> = w.indices.iter().copied().zip(w.position).collect();
                m.push_row(&mut e);
            }
            Ok(m)
        })?;
        Ok(csr_to_py(py, &m))
    }

    /// Closest points on the limit surface: `(position (k, 3), face, sub, u, v, distance,
    /// signed_distance, normal (k, 3), converged)`.
    #[allow(clippy::type_complexity)]
    fn closest_point<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<i64>>,
        Bound<'py, PyArray1<i64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<bool>>,
    )> {
        let q = vec3s("points", &points, 0)?;
        let cps = py
            .detach(|| {
                ClosestPointFinder::new(
                    &self.evaluator,
                    &self.positions,
                    ClosestOptions::default(),
                )?
                .closest_batch(&q)
            })
            .map_err(eval_error)?;
        let a1 = |f: &dyn Fn(&subfit::subdiv::ClosestPoint) -> f64| {
            Array1::from_iter(cps.iter().map(f)).into_pyarray(py)
        };
        let i1 = |f: &dyn Fn(&subfit::subdiv::ClosestPoint) -> i64| {
            Array1::from_iter(cps.iter().map(f)).into_pyarray(py)
        };
        Ok((
            vec3s_to_py(py, &cps.iter().map(|c| c.position).collect::<Vec<_>>()),
            i1(&|c| i64::from(c.param.face)),
            i1(&|c| i64::from(c.param.sub)),
            a1(&|c| c.param.u),
            a1(&|c| c.param.v),
            a1(&|c| c.distance),
            a1(&|c| c.signed_distance),
            vec3s_to_py(py, &cps.iter().map(|c| c.normal).collect::<Vec<_>>()),
            Array1::from_iter(cps.iter().map(|c| c.converged)).into_pyarray(py),
        ))
    }
}
