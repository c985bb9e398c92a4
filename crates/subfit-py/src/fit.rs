//! `subfit.fit`: numpy arrays and keywords → [`subfit::FitScanOptions`] → [`subfit::fit_scan`]
//! (the pipeline of `subfit fit`, nothing re-implemented) → a [`NativeFit`] holding the result.
//!
//! Keywords mirror the CLI's flags (every `--method`, `imls` with `imls_radius` and `arap`
//! included) (`--max-control-points` → `max_control_points`, `--lambda`
//! → `lambda_start`, `--no-refine` → `refine=False`, …) with the same defaults and ranges. The
//! fit runs with the interpreter detached; once per iteration the progress hook re-attaches to
//! check for Ctrl-C (`KeyboardInterrupt`), pass warnings to Python's `warnings`, and call the
//! user's `progress` callable, any of which cancels the run through [`subfit::mesh::Cancel`].

use std::sync::Mutex;

use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyRuntimeWarning;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use subfit::fit::{FitOptions, StageOptions, StepControl};
use subfit::mesh::{Cancel, PolyMesh, Tags};
use subfit::{fit_scan, FitScanOptions, Fitted, InitialCage, Input, OutputOptions, Progress, Step};

use crate::arrays::{
    polygons, polygons_to_py, scheme, scheme_name, tags_to_py, vec3s, vec3s_to_py,
};
use crate::errors::{fit_error, value_error};

/// Faces as `(counts, indices)` int64 arrays.
type FaceArrays<'py> = (PyReadonlyArray1<'py, i64>, PyReadonlyArray1<'py, i64>);

/// A finished fit: the library's [`Fitted`] (cage, tags, scheme, report, and what writing the
/// outputs needs: the analysed target and the limit tessellation).
#[pyclass(frozen, module = "subfit._subfit")]
pub struct NativeFit {
    fitted: Mutex<Fitted>,
}

fn range(name: &str, v: i64, lo: i64, hi: i64) -> PyResult<usize> {
    if v < lo || v > hi {
        return Err(value_error(format!(
            "{name} must be in [{lo}, {hi}], got {v}"
        )));
    }
    Ok(v as usize)
}

/// The library's options for the keywords of `subfit.fit` (the CLI's `fit::options`).
#[allow(clippy::too_many_arguments)]
fn options(
    scheme_name: &str,
    method: &str,
    step: &str,
    tolerance: Option<f64>,
    max_error: Option<f64>,
    max_control_points: Option<i64>,
    control_points: Option<i64>,
    as_points: bool,
    lambda_start: f64,
    lambda_end: Option<f64>,
    sample_level: i64,
    max_iterations: i64,
    stage_iterations: i64,
    one_sided: bool,
    coverage: f64,
    refine: bool,
    edge_flips: bool,
    max_depth: i64,
    local: bool,
    local_rings: Option<i64>,
    local_field: (f64, f64),
    error_scale: Option<f64>,
    imls: (Option<f64>, f64),
) -> PyResult<FitScanOptions> {
    let (imls_radius, arap) = imls;
    let (local_field_peak, local_field_share) = local_field;
    if !(local_field_peak > 0.5 && local_field_peak <= 1.0) {
        return Err(value_error(format!(
            "local_field_peak must be in (0.5, 1], got {local_field_peak}"
        )));
    }
    if !(0.0..=1.0).contains(&local_field_share) {
        return Err(value_error(format!(
            "local_field_share must be in [0, 1], got {local_field_share}"
        )));
    }
    if !(coverage >= 0.0 && coverage.is_finite()) {
        return Err(value_error(format!(
            "coverage must be a finite number >= 0, got {coverage}"
        )));
    }
    let method = subfit::method_named(method).map_err(|e| value_error(e.to_string()))?;
    let step = match step.to_ascii_lowercase().as_str() {
        "none" => StepControl::None,
        "lm" => StepControl::LevenbergMarquardt,
        "armijo" => StepControl::Armijo,
        _ => {
            return Err(value_error(format!(
                "step must be \"none\", \"lm\" or \"armijo\", got {step:?}"
            )))
        }
    };
    if local_rings.is_some() && !local {
        return Err(value_error("local_rings needs local=True"));
    }
    let mut o = FitScanOptions {
        control_points: control_points
            .map(|n| range("control_points", n, 4, 1_000_000))
            .transpose()?,
        as_points,
        scheme: scheme(scheme_name, true)?,
        fit: FitOptions {
            sample_level: range("sample_level", sample_level, 0, 6)?,
            method,
            step,
            coverage,
            imls_radius,
            arap,
            ..FitScanOptions::default().fit
        },
        stages: StageOptions {
            iterations_per_stage: range("stage_iterations", stage_iterations, 1, 10_000)?,
            max_iterations: range("max_iterations", max_iterations, 1, 10_000)?,
            max_depth: range("max_depth", max_depth, 1, 12)? as u8,
            local,
            local_rings: range("local_rings", local_rings.unwrap_or(2), 0, 1_000)?,
            two_sided: !one_sided,
            local_field_peak,
            local_field_share,
            ..StageOptions::default()
        },
        error_scale,
        ..FitScanOptions::default()
    };
    o.set_limits(
        tolerance,
        max_error,
        max_control_points
            .map(|n| range("max_control_points", n, 4, 10_000_000))
            .transpose()?,
    );
    o.set_lambda(lambda_start, lambda_end);
    o.set_refinement(refine, edge_flips);
    Ok(o)
}

/// A progress event as a Python dict.
fn event<'py>(py: Python<'py>, p: &Progress<'_>) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    match p {
        Progress::Step(s) => {
            d.set_item("event", "step")?;
            d.set_item(
                "step",
                match s {
                    Step::Read => "read",
                    Step::Analyse => "analyse",
                    Step::Init => "init",
                    Step::Fit => "fit",
                },
            )?;
        }
        Progress::Iteration { stage, row } => {
            d.set_item("event", "iteration")?;
            d.set_item("stage", *stage)?;
            d.set_item("iteration", row.iteration)?;
            d.set_item("accepted", row.accepted)?;
            d.set_item("e_rms", row.errors.e_rms)?;
            d.set_item("e_max", row.errors.e_max)?;
            d.set_item("objective", row.errors.objective)?;
        }
        Progress::Stage(r) => {
            d.set_item("event", "stage")?;
            d.set_item("stage", r.stage)?;
            d.set_item("lambda", r.lambda)?;
            d.set_item("control_points", r.num_control_points)?;
            d.set_item("iterations", r.fit.iterations.len())?;
        }
        Progress::Warning(w) => {
            d.set_item("event", "warning")?;
            d.set_item("message", *w)?;
        }
    }
    Ok(d)
}

/// The `quads` argument of [`fit`] as a [`subfit::QuadLayout`].
fn quad_layout(quads: &str) -> PyResult<subfit::QuadLayout> {
    Ok(match quads.to_ascii_lowercase().as_str() {
        "field" => subfit::QuadLayout::Field,
        "paired" => subfit::QuadLayout::Paired,
        "only" => subfit::QuadLayout::Only,
        _ => {
            return Err(value_error(format!(
                "quads must be \"field\", \"paired\" or \"only\", got {quads:?}"
            )))
        }
    })
}

/// The target of [`fit`]: `points` (`#V by 3`) with `faces` (a mesh) or without (a point
/// cloud), and the unit `normals` (`#V by 3`, none zero) when given.
fn target_mesh(
    points: &PyReadonlyArray2<'_, f64>,
    faces: Option<&FaceArrays<'_>>,
    normals: Option<&PyReadonlyArray2<'_, f64>>,
) -> PyResult<PolyMesh> {
    let positions = vec3s("points", points, subfit::target::MIN_POINTS)?;
    let n = positions.len();
    let mut mesh = match faces {
        Some((c, i)) => PolyMesh::new(positions, polygons(c, i, n)?),
        None => PolyMesh::point_cloud(positions, None),
    };
    if let Some(nr) = normals {
        let nr = vec3s("normals", nr, 0)?;
        if nr.len() != n {
            return Err(value_error(format!(
                "normals must have one row per point: {} rows for {n} points",
                nr.len()
            )));
        }
        if let Some(i) = nr.iter().position(|v| v.iter().all(|&x| x == 0.0)) {
            return Err(value_error(format!("normals[{i}] is zero")));
        }
        mesh.normals = Some(nr);
    }
    Ok(mesh)
}

/// Sets the initial cage of `opts` from [`fit`]'s `init_method` (`"auto"`, `"qem"` or
/// `"curvature-lines"`) and `init` (a given cage: vertices `#C by 3`, faces), which excludes
/// `control_points`.
fn initial_cage(
    opts: &mut FitScanOptions,
    init_method: Option<&str>,
    init: Option<&(PyReadonlyArray2<'_, f64>, FaceArrays<'_>)>,
    control_points: Option<i64>,
) -> PyResult<()> {
    match init_method {
        None | Some("auto") => {}
        Some("qem") => opts.init = InitialCage::Qem,
        Some("curvature-lines") => opts.init = InitialCage::CurvatureLines,
        Some(other) => {
            return Err(value_error(format!(
                "init must be a cage, \"auto\", \"qem\" or \"curvature-lines\", got {other:?}"
            )))
        }
    }
    if let Some((v, (c, i))) = init {
        if control_points.is_some() {
            return Err(value_error(
                "control_points sets the size of the automatic initial cage; it cannot be used with init",
            ));
        }
        let cage = vec3s("init vertices", v, 4)?;
        let faces = polygons(c, i, cage.len())?;
        opts.init = InitialCage::Given {
            mesh: PolyMesh::new(cage, faces),
            tags: Tags::new(),
            name: "init".into(),
        };
    }
    Ok(())
}

/// Runs the pipeline on arrays (see the Python `subfit.fit` for the documented API).
#[pyfunction]
#[pyo3(signature = (
    points, faces=None, normals=None, *, scheme="auto", method="sdm", step="lm",
    tolerance=None, max_error=None, max_control_points=None, control_points=None,
    as_points=false, init=None, init_method=None, lambda_start=1e-3, lambda_end=None, sample_level=3,
    max_iterations=100, stage_iterations=6, one_sided=false, coverage=1.0, facing=true, chordal=false,
    refine=true, edge_flips=true,
    max_depth=5, local=false, local_rings=None, local_field_peak=0.8, local_field_share=0.5,
    error_scale=None, imls_radius=None, arap=0.0, quads="field", name=None, progress=None
))]
#[allow(clippy::too_many_arguments)]
pub fn fit(
    py: Python<'_>,
    points: PyReadonlyArray2<'_, f64>,
    faces: Option<FaceArrays<'_>>,
    normals: Option<PyReadonlyArray2<'_, f64>>,
    scheme: &str,
    method: &str,
    step: &str,
    tolerance: Option<f64>,
    max_error: Option<f64>,
    max_control_points: Option<i64>,
    control_points: Option<i64>,
    as_points: bool,
    init: Option<(PyReadonlyArray2<'_, f64>, FaceArrays<'_>)>,
    init_method: Option<&str>,
    lambda_start: f64,
    lambda_end: Option<f64>,
    sample_level: i64,
    max_iterations: i64,
    stage_iterations: i64,
    one_sided: bool,
    coverage: f64,
    facing: bool,
    chordal: bool,
    refine: bool,
    edge_flips: bool,
    max_depth: i64,
    local: bool,
    local_rings: Option<i64>,
    local_field_peak: f64,
    local_field_share: f64,
    error_scale: Option<f64>,
    imls_radius: Option<f64>,
    arap: f64,
    quads: &str,
    name: Option<String>,
    progress: Option<Py<PyAny>>,
) -> PyResult<NativeFit> {
    let mut opts = options(
        scheme,
        method,
        step,
        tolerance,
        max_error,
        max_control_points,
        control_points,
        as_points,
        lambda_start,
        lambda_end,
        sample_level,
        max_iterations,
        stage_iterations,
        one_sided,
        coverage,
        refine,
        edge_flips,
        max_depth,
        local,
        local_rings,
        (local_field_peak, local_field_share),
        error_scale,
        (imls_radius, arap),
    )?;
    opts.fit.facing = facing;
    opts.chordal = chordal;
    opts.quads = quad_layout(quads)?;
    let mesh = target_mesh(&points, faces.as_ref(), normals.as_ref())?;
    initial_cage(&mut opts, init_method, init.as_ref(), control_points)?;
    let cancel = Cancel::new();
    opts.cancel = cancel.clone();
    let name = name.unwrap_or_else(|| "<array>".into());
    let failure: Mutex<Option<PyErr>> = Mutex::new(None);
    let result = py.detach(|| {
        let mut hook = |p: Progress<'_>| {
            Python::attach(|py| {
                let r = (|| -> PyResult<()> {
                    py.check_signals()?;
                    if let Progress::Warning(w) = p {
                        let cat = py.get_type::<PyRuntimeWarning>();
                        PyErr::warn(py, &cat, &std::ffi::CString::new(w).unwrap_or_default(), 2)?;
                    }
                    if let Some(cb) = &progress {
                        cb.call1(py, (event(py, &p)?,))?;
                    }
                    Ok(())
                })();
                if let Err(e) = r {
                    let mut f = failure.lock().unwrap_or_else(|e| e.into_inner());
                    if f.is_none() {
                        *f = Some(e);
                    }
                    cancel.cancel();
                }
            });
        };
        fit_scan(Input::Mesh { mesh, name }, &opts, Some(&mut hook))
    });
    if let Some(e) = failure.into_inner().unwrap_or_else(|e| e.into_inner()) {
        return Err(e);
    }
    Ok(NativeFit {
        fitted: Mutex::new(result.map_err(fit_error)?),
    })
}

impl NativeFit {
    fn with<R>(&self, f: impl FnOnce(&Fitted) -> R) -> R {
        f(&self.fitted.lock().unwrap_or_else(|e| e.into_inner()))
    }
}

#[pymethods]
impl NativeFit {
    /// Cage control points, `(n, 3)` float64, in the input's coordinates.
    fn vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.with(|f| vec3s_to_py(py, &f.cage.positions))
    }

    /// Cage faces as `(offsets (m + 1,), indices)` int64.
    #[allow(clippy::type_complexity)]
    fn faces<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<i64>>) {
        self.with(|f| polygons_to_py(py, &f.cage.faces))
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
        self.with(|f| tags_to_py(py, &f.tags))
    }

    /// `"loop"` or `"catmull-clark"`.
    fn scheme(&self) -> &'static str {
        self.with(|f| scheme_name(f.scheme))
    }

    /// The report as JSON text (report.json).
    fn report_json(&self) -> PyResult<String> {
        self.with(|f| serde_json::to_string(&f.report))
            .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))
    }

    /// Whether the tolerances were met.
    fn reached(&self) -> bool {
        self.with(|f| f.reached())
    }

    /// One line: control points, stages, iterations, errors both ways.
    fn summary(&self) -> String {
        self.with(|f| f.summary())
    }

    /// Writes every output into the existing directory `dir` (`subfit::OUTPUTS`: control.obj,
    /// control.usda, control.tags.json, limit.ply, error.ply, log.csv, preview.png, report.html,
    /// report.json), interpreter detached. `limit_quads` keeps the limit tessellation's quads
    /// in limit.ply and error.ply ([`OutputOptions::limit_quads`], `subfit fit --limit-quads`).
    #[pyo3(signature = (dir, limit_quads=false))]
    fn write_into(
        &self,
        py: Python<'_>,
        dir: std::path::PathBuf,
        limit_quads: bool,
    ) -> PyResult<()> {
        let options = OutputOptions { limit_quads };
        py.detach(|| {
            self.fitted
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .write_into_with(&dir, &options)
        })
        .map_err(fit_error)
    }
}
