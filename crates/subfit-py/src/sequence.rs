//! `subfit.fit_sequence`: frames pulled one at a time from a Python iterator (each a
//! `(points, faces)` pair of arrays) → [`subfit::fit_sequence`] (the pipeline of
//! `subfit sequence`, nothing re-implemented) → a [`NativeSequence`].
//!
//! The fit runs with the interpreter detached; the frame iterator and the per-frame progress
//! callback re-attach. A bad frame, an exception from the iterator or the callback, or Ctrl-C
//! stops the run and is raised.

use std::sync::Mutex;

use numpy::{PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use subfit::fit::{FitOptions, Method};
use subfit::mesh::{Cancel, PolyMesh, Tags};
use subfit::{fit_sequence, FitScanOptions, InitialCage, Input, Sequence, SequenceOptions};

use crate::arrays::{polygons, polygons_to_py, scheme, scheme_name, tags_to_py, vec3s};
use crate::errors::{fit_error, value_error};

/// Faces as `(counts, indices)` int64 arrays.
type FaceArrays<'py> = (PyReadonlyArray1<'py, i64>, PyReadonlyArray1<'py, i64>);

/// A fitted sequence: the cage's connectivity, every frame's positions, the report.
#[pyclass(frozen, module = "subfit._subfit")]
pub struct NativeSequence {
    sequence: Sequence,
}

/// One frame from Python: `(points, faces or None, name)`.
fn frame(item: &Bound<'_, PyAny>, index: usize) -> PyResult<Input> {
    let (points, faces, name): (PyReadonlyArray2<'_, f64>, Option<FaceArrays<'_>>, String) =
        item.extract()?;
    let positions = vec3s(
        &format!("frame {index} points"),
        &points,
        subfit::target::MIN_POINTS,
    )?;
    let n = positions.len();
    let mesh = match &faces {
        Some((c, i)) => PolyMesh::new(positions, polygons(c, i, n)?),
        None => PolyMesh::point_cloud(positions, None),
    };
    Ok(Input::Mesh { mesh, name })
}

/// Markers from Python: a path to a marker file (`subfit::read_markers`) or rows
/// `(frame, name, (x, y, z))`.
fn marker_observations(m: &Bound<'_, PyAny>) -> PyResult<Vec<subfit::MarkerObservation>> {
    if let Ok(path) = m.extract::<std::path::PathBuf>() {
        return subfit::read_markers(&path).map_err(fit_error);
    }
    let rows: Vec<(usize, String, [f64; 3])> = m
        .extract()
        .map_err(|_| value_error("markers must be a path or rows (frame, name, (x, y, z))"))?;
    Ok(rows
        .into_iter()
        .map(|(frame, marker, position)| subfit::MarkerObservation {
            frame,
            marker,
            position,
        })
        .collect())
}

/// The template of `subfit.fit_sequence`: fitted to the first frame, or the cage given (then
/// `control_points` cannot be).
fn template_cage(
    template: Option<&(PyReadonlyArray2<'_, f64>, FaceArrays<'_>)>,
    control_points: Option<usize>,
) -> PyResult<InitialCage> {
    let Some((v, (c, i))) = template else {
        return Ok(InitialCage::Auto);
    };
    if control_points.is_some() {
        return Err(value_error(
            "control_points sets the size of the fitted template; it cannot be used with template",
        ));
    }
    let cage = vec3s("template vertices", v, 4)?;
    let faces = polygons(c, i, cage.len())?;
    Ok(InitialCage::Given {
        mesh: PolyMesh::new(cage, faces),
        tags: Tags::new(),
        name: "template".into(),
    })
}

/// The tracking step of `subfit.fit_sequence`: `nodes` deformation nodes (0: off) and the
/// markers, which need it.
fn tracking_options(
    nodes: usize,
    markers: Option<Bound<'_, PyAny>>,
) -> PyResult<Option<subfit::TrackingOptions>> {
    match (nodes, markers.map(|m| marker_observations(&m)).transpose()?) {
        (0, None) => Ok(None),
        (0, Some(_)) => Err(value_error(
            "markers need the tracking step (track_nodes > 0)",
        )),
        (nodes, markers) => Ok(Some(subfit::TrackingOptions {
            nodes,
            markers: markers.unwrap_or_default(),
            ..subfit::TrackingOptions::default()
        })),
    }
}

/// Fits one cage to every frame (see the Python `subfit.fit_sequence`).
#[pyfunction]
#[pyo3(name = "fit_sequence", signature = (
    frames, *, template=None, control_points=None, scheme_name="auto", method="sdm",
    arap=0.01, lambda_=1e-5, iterations=12, tolerance=5e-4, sample_level=2,
    silhouette_views=8, silhouette_resolution=128,
    silhouette_weight=subfit::DEFAULT_SILHOUETTE_WEIGHT, track_nodes=60, markers=None,
    progress=None
))]
#[allow(clippy::too_many_arguments)]
pub fn fit_sequence_py(
    py: Python<'_>,
    frames: Bound<'_, PyAny>,
    template: Option<(PyReadonlyArray2<'_, f64>, FaceArrays<'_>)>,
    control_points: Option<i64>,
    scheme_name: &str,
    method: &str,
    arap: f64,
    lambda_: f64,
    iterations: i64,
    tolerance: f64,
    sample_level: i64,
    silhouette_views: i64,
    silhouette_resolution: i64,
    silhouette_weight: f64,
    track_nodes: i64,
    markers: Option<Bound<'_, PyAny>>,
    progress: Option<Py<PyAny>>,
) -> PyResult<NativeSequence> {
    let method = match method.to_ascii_lowercase().as_str() {
        "sdm" => Method::Sdm,
        "imls" => Method::Imls,
        m => {
            return Err(value_error(format!(
                "method must be \"sdm\" or \"imls\", got {m:?}"
            )))
        }
    };
    let in_range = |name: &str, v: i64, lo: i64, hi: i64| {
        if (lo..=hi).contains(&v) {
            Ok(v as usize)
        } else {
            Err(value_error(format!(
                "{name} must be in [{lo}, {hi}], got {v}"
            )))
        }
    };
    let fit = FitOptions {
        sample_level: in_range("sample_level", sample_level, 0, 6)?,
        method,
        coverage: 1.0,
        ..FitOptions::default()
    };
    let control_points = control_points
        .map(|n| in_range("control_points", n, 4, 1_000_000))
        .transpose()?;
    let mut template_fit = FitScanOptions {
        control_points,
        scheme: scheme(scheme_name, true)?,
        fit: FitOptions {
            sample_level: 3,
            ..fit.clone()
        },
        ..FitScanOptions::default()
    };
    template_fit.stages.tolerance_rms = tolerance;
    if let Some(n) = control_points {
        template_fit.stages.max_control_points = n;
    }
    let template = template_cage(template.as_ref(), control_points)?;
    let cancel = Cancel::new();
    let options = SequenceOptions {
        template,
        template_fit,
        fit,
        lambda: lambda_,
        arap,
        iterations: in_range("iterations", iterations, 1, 1000)?,
        tolerance_rms: tolerance,
        silhouette: subfit::SilhouetteOptions {
            views: in_range("silhouette_views", silhouette_views, 0, 64)?,
            resolution: in_range("silhouette_resolution", silhouette_resolution, 16, 1024)?,
            weight: silhouette_weight,
            ..subfit::SilhouetteOptions::default()
        },
        tracking: tracking_options(in_range("track_nodes", track_nodes, 0, 2000)?, markers)?,
        cancel: cancel.clone(),
        ..SequenceOptions::default()
    };
    let iter = frames.try_iter()?.unbind();
    let failure: Mutex<Option<PyErr>> = Mutex::new(None);
    let fail = |e: PyErr| {
        let mut f = failure.lock().unwrap_or_else(|e| e.into_inner());
        if f.is_none() {
            *f = Some(e);
        }
        cancel.cancel();
    };
    let result = py.detach(|| {
        let mut index = 0;
        let inputs = std::iter::from_fn(|| {
            Python::attach(|py| {
                let r = (|| -> PyResult<Option<Input>> {
                    py.check_signals()?;
                    match iter.bind(py).clone().next() {
                        None => Ok(None),
                        Some(item) => frame(&item?, index).map(Some),
                    }
                })();
                index += 1;
                r.unwrap_or_else(|e| {
                    fail(e);
                    None
                })
            })
        });
        let mut on_frame = |f: subfit::SequenceFrame<'_>| -> Result<(), subfit::Error> {
            Python::attach(|py| {
                let r = (|| -> PyResult<()> {
                    py.check_signals()?;
                    if let Some(cb) = &progress {
                        let d = PyDict::new(py);
                        d.set_item("frame", f.report.index)?;
                        d.set_item("name", &f.report.name)?;
                        d.set_item("e_rms", f.report.two_sided.e_rms_original_units)?;
                        d.set_item("e_max", f.report.two_sided.e_max_original_units)?;
                        d.set_item("seconds", f.report.timings_s.total)?;
                        cb.call1(py, (d,))?;
                    }
                    Ok(())
                })();
                r.map_err(|e| {
                    fail(e);
                    subfit::Error::Interrupted
                })
            })
        };
        let mut warn = |m: &str| {
            Python::attach(|py| {
                let cat = py.get_type::<pyo3::exceptions::PyRuntimeWarning>();
                let msg = std::ffi::CString::new(m).unwrap_or_default();
                if let Err(e) = PyErr::warn(py, &cat, &msg, 2) {
                    fail(e);
                }
            })
        };
        fit_sequence(inputs, &options, &mut on_frame, &mut warn)
    });
    if let Some(e) = failure.into_inner().unwrap_or_else(|e| e.into_inner()) {
        return Err(e);
    }
    Ok(NativeSequence {
        sequence: result.map_err(fit_error)?,
    })
}

#[pymethods]
impl NativeSequence {
    /// Every frame's control points, `(frames, n, 3)` float64, in the input's coordinates.
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let p = &self.sequence.positions;
        let n = p.first().map_or(0, Vec::len);
        let flat: Vec<f64> = p.iter().flatten().flatten().copied().collect();
        PyArray1::from_vec(py, flat).reshape([p.len(), n, 3])
    }

    /// Cage faces as `(offsets (m + 1,), indices)` int64.
    #[allow(clippy::type_complexity)]
    fn faces<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<i64>>) {
        polygons_to_py(py, &self.sequence.faces)
    }

    /// Crease and corner tags (see `arrays::tags_to_py`).
    #[allow(clippy::type_complexity)]
    fn tags<'py>(
        &self,
        py: Python<'py>,
    ) -> (
        Bound<'py, PyArray2<i64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<i64>>,
        Bound<'py, PyArray1<f64>>,
    ) {
        tags_to_py(py, &self.sequence.tags)
    }

    /// `"loop"`, `"catmull-clark"` or `"quad-tri"`.
    fn scheme(&self) -> &'static str {
        scheme_name(self.sequence.scheme)
    }

    /// The report as JSON text (report.json).
    fn report_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.sequence.report)
            .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))
    }

    /// Writes frame_0000.obj …, sequence.usda and report.json into the existing directory
    /// `dir`.
    fn write_into(&self, py: Python<'_>, dir: std::path::PathBuf, fps: f64) -> PyResult<()> {
        if !(fps.is_finite() && fps > 0.0) {
            return Err(value_error(format!(
                "fps must be a positive number, got {fps}"
            )));
        }
        py.detach(|| self.sequence.write_into(&dir, fps))
            .map_err(fit_error)
    }
}
