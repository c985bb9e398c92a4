//! What [`crate::fit_scan`] is asked (DESIGN.md §2 `subfit`, STYLE.md rule 4): the input, the
//! initial cage and every option of the pipeline in one struct, [`FitScanOptions`], which the
//! CLI, the Python package and the bench fill and the pipeline borrows to the solver, and its
//! validation ([`validate`]) before any work.

use std::path::PathBuf;

use subfit_fit::{FitOptions, StageOptions};
use subfit_init::{InitOptions, SimplifyOptions};
use subfit_mesh::{Cancel, PolyMesh, Tags};
use subfit_subdiv::Scheme;
use subfit_target::{FeatureOptions, TargetOptions};

use crate::error::Error;

/// The scan to fit.
#[derive(Clone, Debug)]
pub enum Input {
    /// A file of any supported format (read with [`subfit_io::read_file`]).
    File(PathBuf),
    /// A mesh or point cloud already in memory, with a name for messages and the report.
    Mesh {
        /// Positions (and optional normals) and faces (none for a point cloud).
        mesh: PolyMesh,
        /// The name used in messages (e.g. its file).
        name: String,
    },
}

/// The initial control mesh.
// Built once per run: the size of the `Given` variant does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, Default)]
pub enum InitialCage {
    /// Built with the target's topology: QEM simplification of a mesh target or IMLS contour
    /// of a point cloud, with [`FitScanOptions::control_points`] points; a small open mesh
    /// target of genus 0 is also fitted from the curvature-line cage and the better fit kept
    /// (see [`crate::starts`](mod@crate::starts)).
    #[default]
    Auto,
    /// QEM only: [`subfit_init::initial_control_mesh`] (the simplification of a mesh target,
    /// the trimmed IMLS contour of a point cloud), never the curvature-line cage.
    Qem,
    /// The curvature-line cage of Lavoué et al. 2007 §4 ([`subfit_init::curvature_lines`]):
    /// open mesh targets of genus 0 only; an error otherwise.
    CurvatureLines,
    /// Given, in the target's coordinates; its genus and boundary loops must match a mesh
    /// target's.
    Given {
        /// The cage.
        mesh: PolyMesh,
        /// Its crease and corner tags.
        tags: Tags,
        /// Its name (file) for messages.
        name: String,
    },
}

/// How an automatic quad cage is laid out ([`FitScanOptions::quads`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum QuadLayout {
    /// Edges along a smooth cross field of the surface, irregular vertices at its
    /// singularities ([`subfit_init::cross_field`]); the paired QEM cage when the field's cage
    /// cannot be taken or the target has sharp features to keep.
    #[default]
    Field,
    /// The QEM cage's triangles paired into quads ([`subfit_init::pair_triangles`]).
    Paired,
    /// Along a cross field, every face a quad (each face of the field's cage split into
    /// quads, as one Catmull-Clark step does).
    Only,
}

/// Options of [`crate::fit_scan`]. Lengths are in the target's normalized units (the unit cube).
#[derive(Clone, Debug)]
pub struct FitScanOptions {
    /// The initial control mesh. Default [`InitialCage::Auto`].
    pub init: InitialCage,
    /// Control points of the automatic initial mesh. Default `None`: `clamp(round(1.5·√points),
    /// 200, 2000)`, capped by the budget [`StageOptions::max_control_points`].
    pub control_points: Option<usize>,
    /// Ignore the target's faces and fit its points (and normals), as for a scan; the faces'
    /// genus still tells the initial mesh what to aim for. Default false.
    pub as_points: bool,
    /// Subdivision scheme; `None` (default): for an all-triangle cage the quad/triangle scheme
    /// when the target is an open mesh and the cage is not given (Lavoué et al.; on triangles
    /// it is Loop), Loop otherwise; Catmull-Clark for other cages, and quad/triangle for the
    /// curvature-line start.
    pub scheme: Option<Scheme>,
    /// Pair the triangles of the initial cage into quads before the fit
    /// ([`subfit_init::pair_triangles`]: a quad-dominant cage along the target's principal
    /// directions, same control points). `None` (default): on for an automatic cage when
    /// [`Self::scheme`] is given and is not Loop (Catmull-Clark, quad/triangle), off otherwise
    /// (an automatic cage stays all triangles: the inferred scheme is Loop, or for an open mesh
    /// the quad/triangle scheme, which is Loop on triangles). `Some(true)` also
    /// pairs the triangles of a given cage (keeping its tagged creases) and, with no scheme
    /// given, makes the inferred scheme Catmull-Clark; it cannot be combined with Loop.
    /// It replaces [`InitOptions::quad_dominant`] in [`Self::init_options`].
    pub quad_dominant: Option<bool>,
    /// How an automatic quad cage is laid out when there is one ([`Self::quad_dominant`], or a
    /// quad scheme): along a cross field (default), the QEM cage's triangles paired, or along
    /// a cross field with every face a quad ([`QuadLayout::Only`] also makes the cage quads
    /// when neither is given).
    pub quads: QuadLayout,
    /// Per-iteration options (method, step control, sample level, solver; by default with the
    /// data → surface part on, [`FitOptions::coverage`] = 1, so the fit aims at the two-sided
    /// tolerance it is judged by). Its scheme, tags,
    /// `λ`, tolerances and iteration caps are set by the pipeline.
    pub fit: FitOptions,
    /// The stages: `λ` schedule, tolerances (two-sided by default), budgets, refinement.
    pub stages: StageOptions,
    /// Replace the tolerances of [`Self::stages`] by the defaults for the target
    /// ([`crate::tolerance`]: fractions of its bounding-box diagonal, by whether it is a scan,
    /// a CAD part with sharp creases or a noisy scan), as `subfit fit` does when no tolerance is
    /// given. Default false: the tolerances of `stages` (unit cube).
    pub target_tolerances: bool,
    /// With [`Self::target_tolerances`], a mesh target whose initial cage makes it a CAD part
    /// ([`crate::tolerance::ToleranceKind::CadPart`]) has its sharp features detected again from this dihedral
    /// angle (degrees) when the features' angle is larger, and its cage built again
    /// ([`crate::tolerance::CAD_FEATURE_ANGLE`] by default; `None`: never). `subfit fit` sets
    /// `None` when `--feature-angle` is given.
    pub cad_feature_angle: Option<f64>,
    /// Target analysis options.
    pub target: TargetOptions,
    /// Initial-mesh options (`expected_genus` and `expected_boundary_loops` are set from the faces
    /// with `as_points`).
    pub init_options: InitOptions,
    /// The chordal tolerance: fit the part a tessellation stands for rather than its facets.
    /// When the target is recognised as a tessellation (a CAD export), the fit and the
    /// measurements aim at its curved interpolant
    /// ([`subfit_target::tessellation::curved_interpolant`], PN triangles through its vertices
    /// with the surface's normals), which the facets cut by up to their chord height; its
    /// curved faces may then come out smooth whatever their sag. Default false: the facets.
    pub chordal: bool,
    /// The error mapped to red in `error.ply` (normalized units). Default `None`: the final
    /// surface → data `E_max`.
    pub error_scale: Option<f64>,
    /// Cancels the run from another thread (e.g. a signal handler): every long step polls it
    /// and the run returns [`Error::Interrupted`]. It replaces the tokens of `target`,
    /// `init_options` and `fit`. Default: a token nobody cancels.
    pub cancel: Cancel,
}

impl Default for FitScanOptions {
    fn default() -> Self {
        Self {
            init: InitialCage::Auto,
            control_points: None,
            as_points: false,
            scheme: None,
            quad_dominant: None,
            quads: QuadLayout::default(),
            fit: FitOptions {
                coverage: 1.0,
                facing: true,
                ..FitOptions::default()
            },
            stages: StageOptions::default(),
            target_tolerances: false,
            cad_feature_angle: Some(crate::tolerance::CAD_FEATURE_ANGLE),
            target: TargetOptions::default(),
            init_options: InitOptions {
                features: Some(FeatureOptions::default()),
                simplify: SimplifyOptions {
                    exact_error: EXACT_ERROR,
                    ..SimplifyOptions::default()
                },
                one_sided_refine: subfit_init::ONE_SIDED_REFINE,
                ..InitOptions::default()
            },
            chordal: false,
            error_scale: None,
            cancel: Cancel::default(),
        }
    }
}

/// The automatic cage's simplification goes on past the default control-point count while its
/// collapses move the surface by at most this (unit cube): the flat sides and straight rulings
/// of a CAD part keep only the vertices their shape needs (an open box: its corners).
pub const EXACT_ERROR: f64 = 1e-6;

impl FitScanOptions {
    /// Sets the tolerances and the budget a user gives (`--tolerance`, `--max-error`,
    /// `--max-control-points` of the CLI; the keywords of the same names in Python), in
    /// unit-cube units, with the rules every front end shares: the RMS tolerance is 5e-4
    /// (Cheng et al. 2007's Table IV) unless given, no maximum unless given, the budget 5,000
    /// unless given; with none of the three given the tolerances are the target's
    /// ([`Self::target_tolerances`], [`crate::tolerance`]). Validated by [`crate::fit_scan`].
    pub fn set_limits(
        &mut self,
        tolerance: Option<f64>,
        max_error: Option<f64>,
        max_control_points: Option<usize>,
    ) {
        let defaults = StageOptions::default();
        self.stages.tolerance_rms = tolerance.unwrap_or(defaults.tolerance_rms);
        self.stages.tolerance_max = max_error.unwrap_or(0.0);
        self.stages.max_control_points = max_control_points.unwrap_or(defaults.max_control_points);
        self.target_tolerances =
            tolerance.is_none() && max_error.is_none() && max_control_points.is_none();
    }

    /// Sets the smoothing schedule: `λ` from `start` down to `end` (dimensionless; default
    /// `min(1e-5, start)`), as `--lambda` / `--lambda-end` and Python's `lambda_start` /
    /// `lambda_end`.
    pub fn set_lambda(&mut self, start: f64, end: Option<f64>) {
        self.stages.lambda_start = start;
        self.stages.lambda_end = end.unwrap_or(start.min(1e-5));
    }

    /// Whether the automatic cage is quads: `--quad-dominant`, `--quads only`, or a quad
    /// scheme asked (Catmull-Clark, quad/triangle), unless `--no-quad-dominant`.
    pub fn wants_quads(&self) -> bool {
        self.quad_dominant.unwrap_or(
            self.quads == QuadLayout::Only || self.scheme.is_some_and(|s| s != Scheme::Loop),
        )
    }

    /// Sets the refinement between stages: local refinement on or off (`--no-refine`), and
    /// edge flips (`--no-flips`), which need refinement.
    pub fn set_refinement(&mut self, refine: bool, edge_flips: bool) {
        self.stages.refine = refine;
        self.stages.edge_flips = refine && edge_flips;
    }
}

/// The error term named `name` (`pdm`, `tdm`, `sdm` or `imls`, any case), as `--method`
/// spells them; an options error naming the choices otherwise.
pub fn method_named(name: &str) -> Result<subfit_fit::Method, Error> {
    use subfit_fit::Method;
    match name.to_ascii_lowercase().as_str() {
        "pdm" => Ok(Method::Pdm),
        "tdm" => Ok(Method::Tdm),
        "sdm" => Ok(Method::Sdm),
        "imls" => Ok(Method::Imls),
        _ => Err(Error::Options(format!(
            "method must be \"pdm\", \"tdm\", \"sdm\" or \"imls\", got {name:?}"
        ))),
    }
}

/// Checks `o` before any work: each error names the flag and what is wrong.
pub(crate) fn validate(o: &FitScanOptions) -> Result<(), Error> {
    let bad = |m: String| Err(Error::Options(m));
    let st = &o.stages;
    if !(st.lambda_start.is_finite() && st.lambda_start >= 0.0) {
        return bad(format!(
            "--lambda must be a finite number ≥ 0, got {}",
            st.lambda_start
        ));
    }
    if !(st.lambda_end.is_finite() && st.lambda_end >= 0.0 && st.lambda_end <= st.lambda_start) {
        return bad(format!(
            "--lambda-end must be a finite number in [0, --lambda = {}], got {}",
            st.lambda_start, st.lambda_end
        ));
    }
    for (name, v) in [
        ("--tolerance", st.tolerance_rms),
        ("--max-error", st.tolerance_max),
    ] {
        if v != 0.0 && !(v.is_finite() && v > 0.0 && v < 1.0) {
            return bad(format!(
                "{name} must be in (0, 1) (unit-cube units), got {v}"
            ));
        }
    }
    if let Some(v) = o.fit.imls_radius {
        if !(v.is_finite() && v > 0.0 && v < 1.0) {
            return bad(format!(
                "--imls-radius must be in (0, 1) (unit-cube units), got {v}"
            ));
        }
        if o.fit.method != subfit_fit::Method::Imls {
            return bad(
                "--imls-radius is the IMLS kernel's radius: use it with --method imls".into(),
            );
        }
    }
    if !(o.fit.arap.is_finite() && o.fit.arap >= 0.0) {
        return bad(format!(
            "--arap must be a finite number ≥ 0, got {}",
            o.fit.arap
        ));
    }
    if let Some(v) = o.error_scale {
        if !(v.is_finite() && v > 0.0 && v < 1.0) {
            return bad(format!(
                "--error-scale must be in (0, 1) (unit-cube units), got {v}"
            ));
        }
    }
    if o.quads == QuadLayout::Only
        && (o.scheme == Some(Scheme::Loop) || o.quad_dominant == Some(false))
    {
        return bad("--quads only makes every face a quad: it needs a quad scheme (catmull-clark or quad-tri) and cannot be combined with --no-quad-dominant".into());
    }
    if o.quad_dominant == Some(true) && o.scheme == Some(Scheme::Loop) {
        return bad("--quad-dominant makes quads, and the Loop scheme needs triangles: use --scheme catmull-clark (or drop --quad-dominant)".into());
    }
    if matches!(o.init, InitialCage::CurvatureLines) && o.scheme == Some(Scheme::Loop) {
        return bad("--init curvature-lines makes a cage of quads and triangles, and the Loop scheme needs triangles: use --scheme quad-tri (its default) or catmull-clark".into());
    }
    if matches!(o.init, InitialCage::CurvatureLines) && o.control_points.is_some() {
        return bad("--control-points sets the size of the QEM initial mesh; a curvature-line cage takes the control points its boundary curves need".into());
    }
    if matches!(o.init, InitialCage::Given { .. }) && o.control_points.is_some() {
        return bad("--control-points sets the size of the automatic initial mesh; it cannot be used with --init FILE".into());
    }
    if let Some(n) = o.control_points {
        if n < 4 {
            return bad(format!("--control-points must be at least 4, got {n}"));
        }
    }
    if st.max_control_points < 4 {
        return bad(format!(
            "--max-control-points must be at least 4, got {}",
            st.max_control_points
        ));
    }
    Ok(())
}
