//! The IMLS distance of Xie et al. 2023, eq. 2–4, for `subfit.torch.imls`: value and analytic
//! gradient at query points over the caller's own points and unit normals, with
//! [`subfit::target::imls_value`] (the kernel `Target::imls_with_radius` uses, not
//! re-implemented; a `Target` would re-orient and merge the user's normals, so it is not built).
//! The kernel is `φ(r) = (1 − r²/h²)⁴` for `r < h` (the paper's eq. 3; its published code
//! computes `(1 − r²)⁴`, a precedence slip, which is not reproduced).

use numpy::ndarray::Array1;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use rayon::prelude::*;
use subfit::target::{imls_value, PointIndex};

use crate::arrays::{vec3s, vec3s_to_py};
use crate::errors::value_error;

/// Points, unit normals and a support radius, with the kd-tree over the points (built once).
#[pyclass(frozen, module = "subfit._subfit")]
pub struct ImlsField {
    points: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
    index: PointIndex,
    h: f64,
}

#[pymethods]
impl ImlsField {
    /// `points (n, 3)`, `normals (n, 3)` (normalized here; zero rows refused), radius `h > 0`.
    #[new]
    fn new(
        py: Python<'_>,
        points: PyReadonlyArray2<'_, f64>,
        normals: PyReadonlyArray2<'_, f64>,
        h: f64,
    ) -> PyResult<Self> {
        let points = vec3s("points", &points, 1)?;
        let mut normals = vec3s("normals", &normals, 0)?;
        if normals.len() != points.len() {
            return Err(value_error(format!(
                "normals must have one row per point: {} rows for {} points",
                normals.len(),
                points.len()
            )));
        }
        if !(h.is_finite() && h > 0.0) {
            return Err(value_error(format!("h must be finite and > 0, got {h}")));
        }
        for (i, n) in normals.iter_mut().enumerate() {
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if l.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return Err(value_error(format!("normals[{i}] is zero")));
            }
            *n = n.map(|x| x / l);
        }
        let index = py
            .detach(|| PointIndex::new(&points))
            .ok_or_else(|| value_error("points: too many points for the index"))?;
        Ok(Self {
            points,
            normals,
            index,
            h,
        })
    }

    /// The support radius `h`.
    #[getter]
    fn h(&self) -> f64 {
        self.h
    }

    /// Number of points.
    fn __len__(&self) -> usize {
        self.points.len()
    }

    /// `(values (k,), gradients (k, 3))` at `x (k, 3)`, in parallel, interpreter detached.
    #[allow(clippy::type_complexity)]
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        x: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>)> {
        let x = vec3s("samples", &x, 0)?;
        let out: Vec<_> = py.detach(|| {
            x.par_iter()
                .map(|&q| imls_value(&self.index, &self.points, &self.normals, q, self.h))
                .collect()
        });
        let values = Array1::from_iter(out.iter().map(|v| v.value)).into_pyarray(py);
        let grads: Vec<[f64; 3]> = out.iter().map(|v| v.gradient).collect();
        Ok((values, vec3s_to_py(py, &grads)))
    }

    /// The support of each query, for a differentiable evaluation elsewhere (torch, when the
    /// scan itself needs gradients): `(offsets (k + 1,), indices (nnz,), nearest (k,))` — the
    /// points within `h` of query `q` are `indices[offsets[q]..offsets[q + 1]]`, and `nearest[q]`
    /// the nearest point (the fallback's). In parallel, interpreter detached.
    #[allow(clippy::type_complexity)]
    fn neighbors<'py>(
        &self,
        py: Python<'py>,
        x: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<(
        Bound<'py, PyArray1<i64>>,
        Bound<'py, PyArray1<i64>>,
        Bound<'py, PyArray1<i64>>,
    )> {
        let x = vec3s("samples", &x, 0)?;
        let lists: Vec<(Vec<i64>, i64)> = py.detach(|| {
            x.par_iter()
                .map(|q| {
                    let nb = self.index.within_unsorted(q, self.h);
                    let mut idx: Vec<i64> = nb.iter().map(|b| i64::from(b.index)).collect();
                    idx.sort_unstable();
                    (idx, i64::from(self.index.nearest(q).index))
                })
                .collect()
        });
        let mut offsets = Vec::with_capacity(lists.len() + 1);
        offsets.push(0i64);
        let mut indices = Vec::new();
        for (l, _) in &lists {
            indices.extend_from_slice(l);
            offsets.push(indices.len() as i64);
        }
        let nearest = Array1::from_iter(lists.iter().map(|(_, n)| *n)).into_pyarray(py);
        Ok((
            Array1::from(offsets).into_pyarray(py),
            Array1::from(indices).into_pyarray(py),
            nearest,
        ))
    }
}
