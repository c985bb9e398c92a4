//! The typed report of [`crate::fit_scan`]; `report.json` is its serialization (serde).
//!
//! Errors are in the target's normalized units (the unit cube its longest side is scaled to,
//! as in the papers) unless a field says otherwise; `*_fraction_of_diagonal` divides by the
//! target's bounding-box diagonal in the same units; `*_original_units` multiplies by
//! [`Report::normalized_unit_in_original_units`].

use serde::{Deserialize, Serialize};
use subfit_fit::{ErrorStats, IterationRow, StageReport};
use subfit_measure::{DistanceStats, TwoSided};

/// Errors of one cage, surface → data, as the fitter measures them (Cheng 2007 §II-B step 7).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Errors {
    /// `E_max`.
    pub e_max: f64,
    /// `E_rms`.
    pub e_rms: f64,
    /// `E_max` / diagonal.
    pub e_max_fraction_of_diagonal: f64,
    /// `E_rms` / diagonal.
    pub e_rms_fraction_of_diagonal: f64,
    /// The objective `E_rms² + λ/n Σ|W(P_i)|²`.
    pub objective: f64,
}

impl From<&ErrorStats> for Errors {
    fn from(s: &ErrorStats) -> Self {
        Self {
            e_max: s.e_max,
            e_rms: s.e_rms,
            e_max_fraction_of_diagonal: s.e_max_diag,
            e_rms_fraction_of_diagonal: s.e_rms_diag,
            objective: s.objective,
        }
    }
}

/// Distances both ways (DESIGN.md decision 11): `e_rms` and `e_max` are the worse of the two
/// directions; each direction is given too.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TwoSidedErrors {
    /// The worse RMS of the two directions.
    pub e_rms: f64,
    /// The worse maximum (the Hausdorff distance of the two sample sets).
    pub e_max: f64,
    /// `e_rms` / diagonal.
    pub e_rms_fraction_of_diagonal: f64,
    /// `e_max` / diagonal.
    pub e_max_fraction_of_diagonal: f64,
    /// `e_rms` in the input's units.
    pub e_rms_original_units: f64,
    /// `e_max` in the input's units.
    pub e_max_original_units: f64,
    /// Limit-surface samples to the data.
    pub surface_to_data: DistanceStats,
    /// Data samples to their exact closest points on the limit surface.
    pub data_to_surface: DistanceStats,
}

impl TwoSidedErrors {
    /// From both directions, with the diagonal (normalized units) and the size of one
    /// normalized unit in the input's units.
    pub fn new(t: &TwoSided, diagonal: f64, unit: f64) -> Self {
        let d = diagonal.max(f64::MIN_POSITIVE);
        Self {
            e_rms: t.rms(),
            e_max: t.max(),
            e_rms_fraction_of_diagonal: t.rms() / d,
            e_max_fraction_of_diagonal: t.max() / d,
            e_rms_original_units: t.rms() * unit,
            e_max_original_units: t.max() * unit,
            surface_to_data: t.surface_to_data,
            data_to_surface: t.data_to_surface,
        }
    }
}

/// Genus and boundary loops of a surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Topology {
    /// Genus.
    pub genus: u32,
    /// Boundary loops.
    pub boundary_loops: usize,
}

/// Faces of a mesh target turned to agree with their neighbours.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Reorientation {
    /// Faces flipped.
    pub faces_flipped: usize,
    /// Connected components in which faces were flipped.
    pub components_changed: usize,
}

/// The initial control mesh.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct InitSummary {
    /// `"Mesh"` (QEM simplification of the target's mesh), `"Contour"` (IMLS contour, then
    /// simplification) or `"File"` (given).
    pub source: String,
    /// The file, when given.
    pub file: Option<String>,
    /// Control points asked of the automatic initial mesh.
    pub requested_control_points: Option<usize>,
    /// A point cloud found open (a single-view scan): the default start was scaled by
    /// `subfit_init::OPEN_CLOUD_SCALE` to this many control points. `None` otherwise.
    #[serde(default)]
    pub open_cloud_control_points: Option<usize>,
    /// Specks: small discs of seven control points added to an open clean cloud's cage for
    /// clusters of lone returns that no piece of its trimmed surface reaches
    /// (`subfit_init::specks`).
    #[serde(default)]
    pub specks: usize,
    /// A one-sided cloud (a single view) contoured again one level finer
    /// (`subfit_init::InitOptions::one_sided_refine`).
    #[serde(default)]
    pub one_sided_refined: bool,
    /// The fraction of `--max-control-points` the automatic start took: a quad scheme whose
    /// default start exceeds the budget starts below it ([`crate::BUDGET_STARTS`]). `None`
    /// otherwise.
    #[serde(default)]
    pub budget_start: Option<f64>,
    /// Control points.
    pub control_points: usize,
    /// Faces.
    pub faces: usize,
    /// Quads among the faces.
    #[serde(default)]
    pub quads: usize,
    /// Triangles among the faces.
    #[serde(default)]
    pub triangles: usize,
    /// Quads over all faces, in `[0, 1]`.
    #[serde(default)]
    pub quad_fraction: f64,
    /// Whether the triangle cage was paired into a quad-dominant one (`quad_dominant`).
    #[serde(default)]
    pub paired: bool,
    /// The target's genus (as the initial mesh saw it).
    pub genus_target: u32,
    /// The cage's genus.
    pub genus: u32,
    /// Whether they match.
    pub genus_matches: bool,
    /// Boundary loops of the target and of the cage. For a point cloud the target's are those of
    /// its trimmed contour (`subfit_init::trim`: the loops found in the cloud).
    pub boundary_loops: BoundaryLoops,
    /// Point clouds: whether the cloud was found open (contour faces without data nearby were
    /// trimmed, `subfit_init::trim`). `false` for meshes and given cages.
    #[serde(default)]
    pub cloud_open: bool,
    /// Point clouds: contour faces trimmed as unsupported by data (0 for a closed cloud, a mesh
    /// or a given cage).
    #[serde(default)]
    pub contour_faces_trimmed: usize,
    /// Mesh targets: whether the mesh was too noisy to simplify (the simplification stuck well
    /// above the requested count) and the cage was simplified from a Taubin-smoothed copy
    /// (`subfit_init::SimplifyReport::smoothed`).
    #[serde(default)]
    pub smoothed: bool,
    /// Mesh targets with feature detection on: the target's sharp features, which the cage
    /// keeps as crease and corner tags (`subfit_target::detect_features`). `None` otherwise.
    #[serde(default)]
    pub features: Option<FeatureSummary>,
    /// The CAD tessellation start ([`crate::start_cad`]), when it built the cage.
    #[serde(default)]
    pub cad: Option<CadSummary>,
    /// Seconds per step (contour, simplify, total).
    pub timings_s: InitTimings,
    /// The curvature-line cage (`subfit_init::curvature_lines`) when it was built or tried:
    /// whether it is this cage, and why not. `None` when it was not tried.
    #[serde(default)]
    pub curvature_lines: Option<CurvatureLineSummary>,
    /// A quad cage laid along a cross field (`subfit_init::cross_field`) when it was asked
    /// of this start: the cage's face sizes and valences, or why the paired simplification was
    /// used instead. `None` for other starts.
    #[serde(default)]
    pub cross_field: Option<CrossFieldSummary>,
}

/// The cross-field cage of a start ([`InitSummary::cross_field`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CrossFieldSummary {
    /// Whether the cage is the field's (otherwise the paired simplification, see `failure`).
    pub used: bool,
    /// Why the field's cage was not taken.
    pub failure: Option<String>,
    /// Whether the lattice was taken at about a quarter of the count, each face then split
    /// into quads.
    pub split: bool,
    /// Irregular vertices (interior of valence other than 4, boundary other than 2 or 3).
    pub irregular: usize,
    /// Interior vertices by valence: `[valence, count]`, ascending.
    pub valences: Vec<(usize, usize)>,
    /// Working-mesh vertices the fields were computed on.
    pub working_vertices: usize,
    /// Seconds spent.
    pub seconds: f64,
}

/// The curvature-line initial cage of Lavoué et al. 2007 §4 ([`InitSummary::curvature_lines`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CurvatureLineSummary {
    /// Whether it is the initial cage.
    pub used: bool,
    /// Why it is not (it cannot be built, or the QEM start gave the better fit, see
    /// `crate::starts`). `None` when used.
    pub reason: Option<String>,
    /// Its control points (0 when it could not be built).
    pub control_points: usize,
    /// Its faces.
    pub faces: usize,
    /// Control points tagged as corners (sharp turns of the boundary).
    pub corners: usize,
    /// Control points per boundary curve.
    pub curve_control_points: Vec<usize>,
    /// Largest distance of a target boundary vertex from its boundary curve, as a fraction of
    /// the bounding-box diagonal.
    pub curve_max_error: f64,
    /// Edges linking the boundary loops into one contour.
    pub links: usize,
    /// Cuts along lines of curvature.
    pub cuts: usize,
    /// Contours closed by a fan where no cut was legal
    /// ([`subfit_init::curvature_lines::CurvatureLineReport::fans`]).
    pub fans: usize,
    /// Under `--init auto`, what the other start gave (QEM when this one was kept, this one
    /// when QEM was). `None` when only one start was fitted.
    pub alternative: Option<InitAlternative>,
}

/// A start fitted and not kept ([`CurvatureLineSummary::alternative`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct InitAlternative {
    /// Control points of its initial cage.
    pub initial_control_points: usize,
    /// Control points of its fitted cage.
    pub control_points: usize,
    /// Its two-sided RMS, as a fraction of the diagonal.
    pub rms_fraction_of_diagonal: f64,
    /// Its two-sided maximum (Hausdorff distance), as a fraction of the diagonal.
    pub max_fraction_of_diagonal: f64,
    /// Whether it met the tolerances.
    pub tolerance_reached: bool,
}

/// A mesh target's sharp features ([`InitSummary::features`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FeatureSummary {
    /// The feature angle used (degrees).
    pub angle_deg: f64,
    /// Sharp edges of the target.
    pub edges: usize,
    /// Feature curves.
    pub curves: usize,
    /// Corners.
    pub corners: usize,
    /// Darts (curve ends in smooth regions).
    pub darts: usize,
    /// Concave sectors of the cage's corners split by a crease so the limit surface does not
    /// fold there (`subfit_mesh::concave`).
    #[serde(default)]
    pub concave_sectors: usize,
    /// Control points inserted for those creases (in [`InitSummary::control_points`], beyond
    /// [`InitSummary::requested_control_points`]).
    #[serde(default)]
    pub concave_points: usize,
}

/// Quads and triangles of `faces`, and the fraction of quads (0 without faces). Cost `O(F)`.
pub fn face_counts(faces: &subfit_mesh::Polygons) -> (usize, usize, f64) {
    let quads = faces.iter().filter(|f| f.len() == 4).count();
    let triangles = faces.iter().filter(|f| f.len() == 3).count();
    let fraction = if faces.is_empty() {
        0.0
    } else {
        quads as f64 / faces.len() as f64
    };
    (quads, triangles, fraction)
}

/// Boundary loops of the target and the cage.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct BoundaryLoops {
    /// The target's.
    pub target: usize,
    /// The cage's.
    pub cage: usize,
}

/// Seconds spent building the initial mesh.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct InitTimings {
    /// Contouring (point clouds).
    pub contour: f64,
    /// Simplification.
    pub simplify: f64,
    /// Pairing triangles into quads.
    #[serde(default)]
    pub pair: f64,
    /// All of it.
    pub total: f64,
}

/// The options the fit ran with.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct OptionsSummary {
    /// Subdivision scheme.
    pub scheme: String,
    /// Error term.
    pub method: String,
    /// Step control.
    pub step: String,
    /// `λ` of the first stage.
    pub lambda_start: f64,
    /// Smallest `λ`.
    pub lambda_end: f64,
    /// Factor per stage.
    pub lambda_factor: f64,
    /// Sample level.
    pub sample_level: usize,
    /// Iterations over all stages at most.
    pub max_iterations: usize,
    /// Iterations per stage at most.
    pub stage_iterations: usize,
    /// `E_rms` tolerance.
    pub tolerance_rms: f64,
    /// `E_max` tolerance, if any.
    pub tolerance_max: Option<f64>,
    /// Whether the tolerances are judged both ways.
    pub two_sided: bool,
    /// The control-point budget.
    pub max_control_points: usize,
    /// Local refinement.
    pub refine: bool,
    /// Edge flips.
    pub edge_flips: bool,
    /// Refinement depth at most.
    pub max_depth: u8,
    /// Local stages.
    pub local: bool,
    /// Rings around a local change.
    pub local_rings: usize,
    /// Local enrichment: the fraction of an error field's maximum that counts as close to it
    /// (Lavoué et al.'s 0.8).
    #[serde(default)]
    pub local_field_peak: f64,
    /// Local enrichment: the share of close error points below which a field is local (one
    /// control point); 0: off.
    #[serde(default)]
    pub local_field_share: f64,
    /// The error power of the last stage's max-error polish (2 or less: none).
    #[serde(default)]
    pub polish_power: f64,
    /// `--method imls`: the IMLS kernel support radius `h` in use (normalized units); absent
    /// for the foot-point methods.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub imls_radius: Option<f64>,
    /// Weight `α` of the ARAP regularizer (0: off).
    #[serde(default)]
    pub arap: f64,
    /// Whether foot points face the sample's side inside thin parts (`--facing`).
    #[serde(default)]
    pub facing: bool,
    /// The optimizer (`GaussNewton`, `Adam`, `Lbfgs`; `--optimizer`).
    #[serde(default)]
    pub optimizer: String,
    /// Under the chordal tolerance (`--chordal`), each facet of the tessellation was cut into
    /// this many squared triangles of its curved interpolant, which the fit aimed at and the
    /// errors are measured against; `None`: the input as given.
    #[serde(default)]
    pub chordal_levels: Option<usize>,
}

/// One stage.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StageSummary {
    /// 0-based stage.
    pub stage: usize,
    /// `λ`.
    pub lambda: f64,
    /// Control points during its fit.
    pub control_points: usize,
    /// Faces during its fit.
    pub faces: usize,
    /// Iterations.
    pub iterations: usize,
    /// Why its fit stopped.
    pub stop: String,
    /// Errors before its fit.
    pub initial: Errors,
    /// Errors after its fit.
    pub r#final: Errors,
    /// Both ways after its fit.
    pub two_sided: TwoSided,
    /// Samples.
    pub samples: usize,
    /// Setup seconds (sampling operator, pattern, symbolic analysis; 0 when reused).
    pub setup_s: f64,
    /// Edge flips tried.
    pub flips_tried: usize,
    /// Edge flips kept.
    pub flips_kept: usize,
    /// Control points optimized in a local stage.
    pub active_points: Option<usize>,
    /// Refinement after the fit: faces marked, red and green splits, new points.
    pub refine: Option<RefineSummary>,
    /// Control points added after the fit by local enrichment (one per local error field,
    /// Lavoué et al. 2005 §5.2).
    #[serde(default)]
    pub local_points: usize,
    /// The last step only, the polish of the best cage towards a lower maximum error
    /// (`subfit_fit::polish`): whether the polished cage was kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polish_kept: Option<bool>,
    /// Seconds.
    pub time_s: f64,
}

/// A local refinement.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RefineSummary {
    /// Faces marked.
    pub marked: usize,
    /// Red (1-to-4) splits.
    pub red: usize,
    /// Green (closure) splits.
    pub green: usize,
    /// New control points.
    pub new_points: usize,
}

impl From<&StageReport> for StageSummary {
    fn from(s: &StageReport) -> Self {
        Self {
            stage: s.stage,
            lambda: s.lambda,
            control_points: s.num_control_points,
            faces: s.num_faces,
            iterations: s.fit.iterations.len(),
            stop: format!("{:?}", s.fit.stop),
            initial: (&s.fit.initial).into(),
            r#final: (&s.fit.last()).into(),
            two_sided: s.two_sided,
            samples: s.fit.num_samples,
            setup_s: s.fit.setup.as_secs_f64(),
            flips_tried: s.flips_tried,
            flips_kept: s.flips_kept,
            active_points: s.active_points,
            refine: s.refine.map(|r| RefineSummary {
                marked: r.marked,
                red: r.red,
                green: r.green,
                new_points: r.new_points,
            }),
            local_points: s.local_points,
            polish_kept: s.polish,
            time_s: s.time.as_secs_f64(),
        }
    }
}

/// One iteration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct IterationSummary {
    /// Stage.
    pub stage: usize,
    /// Iteration within the stage (1-based).
    pub iteration: usize,
    /// Whether the step was taken.
    pub accepted: bool,
    /// Errors after it.
    pub errors: Errors,
    /// Objective at the trial point.
    pub trial_objective: f64,
    /// LM damping.
    pub damping: f64,
    /// Step length.
    pub step_length: f64,
    /// LM gain ratio.
    pub gain_ratio: f64,
    /// Seconds per phase.
    pub timings_s: IterationTimings,
}

/// Seconds per phase of an iteration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct IterationTimings {
    /// `S = C·P`.
    pub sample: f64,
    /// Foot points.
    pub project: f64,
    /// Filling `H`.
    pub assemble: f64,
    /// Solving.
    pub solve: f64,
    /// Error statistics.
    pub evaluate: f64,
}

impl IterationSummary {
    /// From a row of `stage`.
    pub fn new(stage: usize, r: &IterationRow) -> Self {
        let t = &r.timings;
        Self {
            stage,
            iteration: r.iteration,
            accepted: r.accepted,
            errors: (&r.errors).into(),
            trial_objective: r.trial_objective,
            damping: r.damping,
            step_length: r.step_length,
            gain_ratio: r.gain_ratio,
            timings_s: IterationTimings {
                sample: t.sample.as_secs_f64(),
                project: t.project.as_secs_f64(),
                assemble: t.assemble.as_secs_f64(),
                solve: t.solve.as_secs_f64(),
                evaluate: t.evaluate.as_secs_f64(),
            },
        }
    }
}

/// The limit tessellation written to `limit.ply` / `error.ply`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TessellationSummary {
    /// Refinement level.
    pub level: usize,
    /// Vertices.
    pub vertices: usize,
    /// Predicted chordal error (max, RMS).
    pub predicted_chordal_error: RmsMax,
    /// A tenth of the fitting error (max, RMS).
    pub goal: RmsMax,
    /// Whether the chordal error is within the goal.
    pub goal_met: bool,
}

/// An RMS and a maximum.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RmsMax {
    /// Maximum.
    pub max: f64,
    /// Root mean square.
    pub rms: f64,
}

/// Seconds per phase of the whole run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Timings {
    /// Reading the input.
    pub read: f64,
    /// Target analysis (normals, orientation, curvature, indices).
    pub preprocess: f64,
    /// The initial control mesh.
    pub init: f64,
    /// The stages.
    pub fit: f64,
    /// Measuring the cage written both ways (its tessellation, foot points, data distances).
    pub measure: f64,
    /// Building the outputs (tessellation, error colours).
    pub output: f64,
    /// Everything.
    pub total: f64,
}

/// How far the surface a USD reader subdivides lies from the fitted one (quad/triangle cages,
/// written as Catmull-Clark with the smooth triangle rule): both ways between the two limit
/// tessellations at the same level.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct UsdDifference {
    /// The scheme written to control.usda.
    pub written_as: String,
    /// Root mean square distance, fraction of the target's bounding-box diagonal.
    pub rms_fraction_of_diagonal: f64,
    /// Largest distance, fraction of the diagonal.
    pub max_fraction_of_diagonal: f64,
    /// Largest distance in the input's units.
    pub max_original_units: f64,
}

/// `report.json`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// The target's name (its file).
    pub target: String,
    /// Distinct target points (after outliers are dropped).
    pub target_points: usize,
    /// Points of a point-cloud target dropped as outliers (see `subfit_target::outliers`).
    #[serde(default)]
    pub target_outliers_removed: usize,
    /// The target's estimated noise level (1.4826 × the median distance of a point to the
    /// plane of its 16 nearest neighbours, normalized units: about the noise's standard
    /// deviation on a noisy scan, the curvature sag of a neighbourhood on a clean one).
    #[serde(default)]
    pub target_noise_level: f64,
    /// The target's median distance of a point to its 16th nearest neighbour (normalized
    /// units).
    #[serde(default)]
    pub target_point_spacing: f64,
    /// The RMS tolerance the fit was judged by when the target is a noisy scan: the requested
    /// one raised to the noise floor `√(tol² + (1.25 σ)²)` (unit cube); `None` otherwise.
    #[serde(default)]
    pub noise_floored_tolerance: Option<f64>,
    /// Which defaults set the tolerances, relative to the target's diagonal
    /// ([`crate::tolerance`]); `None` when they were given.
    #[serde(default)]
    pub tolerance_kind: Option<crate::tolerance::ToleranceKind>,
    /// The target mesh's topology (`None` for a point cloud).
    pub target_topology: Option<Topology>,
    /// Faces of the target re-oriented to agree with their neighbours, if any.
    pub reoriented: Option<Reorientation>,
    /// One normalized unit in the input's units.
    pub normalized_unit_in_original_units: f64,
    /// The target's bounding-box diagonal in normalized units.
    pub bbox_diagonal_unit_cube: f64,
    /// Where the data → surface distances are measured from: `points` or `mesh_area`.
    pub data_samples: String,
    /// The initial control mesh.
    pub init: InitSummary,
    /// Options.
    pub options: OptionsSummary,
    /// Control points of the cage written.
    pub control_points: usize,
    /// Faces of the cage written.
    pub control_faces: usize,
    /// Quads over all faces of the cage written, in `[0, 1]`.
    #[serde(default)]
    pub control_quad_fraction: f64,
    /// Crease edges and corners of the cage written.
    pub tags: TagCounts,
    /// Surface → data errors of the initial cage.
    pub initial: Errors,
    /// Both ways, the initial cage.
    pub initial_two_sided: TwoSidedErrors,
    /// Surface → data errors of the cage written.
    pub r#final: FinalErrors,
    /// The stage whose cage is written (the best measured).
    pub best_stage: usize,
    /// Why the stages stopped: `Tolerance`, `Budget`, `Stalled`, `Diminishing` or `Limit`.
    pub stop: String,
    /// Whether the tolerances hold for the cage written (both ways unless `options.two_sided`
    /// is false).
    pub tolerance_reached: bool,
    /// Whether the tolerances hold surface → data (Cheng's measure, the papers' tables).
    pub tolerance_reached_surface_to_data: bool,
    /// Whether they hold both ways.
    pub tolerance_reached_two_sided: bool,
    /// Warnings (also given to the progress callback).
    pub warnings: Vec<String>,
    /// For a quad/triangle cage: the distance between its limit surface and that of the
    /// standard scheme control.usda declares (Catmull-Clark, smooth triangle rule); `None` for
    /// Loop and Catmull-Clark cages, which USD describes exactly.
    #[serde(default)]
    pub usd_difference: Option<UsdDifference>,
    /// Stages.
    pub stages: Vec<StageSummary>,
    /// Iterations, all stages.
    pub iterations: Vec<IterationSummary>,
    /// The limit tessellation written (`limit.ply`), on which the final errors both ways are
    /// measured: they differ from the distances to the exact limit surface by at most its
    /// chordal error.
    pub limit_tessellation: TessellationSummary,
    /// The error that maps to red in `error.ply` (normalized units).
    pub error_color_scale_unit_cube: f64,
    /// Fits from several starts under a budget ([`crate::BUDGET_STARTS`]), the one written
    /// among them; empty when there was one fit.
    #[serde(default)]
    pub budget_starts: Vec<BudgetStart>,
    /// Seconds per phase of the fit written; `total` also counts the other starts' fits.
    pub timings_s: Timings,
}

/// One of the fits from several starts under a budget ([`Report::budget_starts`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BudgetStart {
    /// The start's fraction of the budget.
    pub fraction: f64,
    /// Control points of its initial cage.
    pub initial_control_points: usize,
    /// Control points of its cage.
    pub control_points: usize,
    /// Two-sided RMS error, fraction of the diagonal.
    pub rms_fraction_of_diagonal: f64,
    /// Two-sided maximum error (Hausdorff distance), fraction of the diagonal.
    pub max_fraction_of_diagonal: f64,
    /// Whether its cage met the tolerances.
    pub tolerance_reached: bool,
    /// Seconds of its whole fit.
    pub seconds: f64,
    /// Whether its cage is the one written.
    pub kept: bool,
    /// Whether its initial cage was laid along a cross field ([`InitSummary::cross_field`]).
    #[serde(default)]
    pub cross_field: bool,
}

/// Tag counts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct TagCounts {
    /// Crease edges.
    pub creases: usize,
    /// Corners.
    pub corners: usize,
}

/// The errors of the cage written: surface → data (Cheng's measure, the fields of [`Errors`],
/// at the fitter's samples), and both ways on the tessellation written (`two_sided`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FinalErrors {
    /// `E_max` surface → data.
    pub e_max: f64,
    /// `E_rms` surface → data.
    pub e_rms: f64,
    /// `E_max` / diagonal.
    pub e_max_fraction_of_diagonal: f64,
    /// `E_rms` / diagonal.
    pub e_rms_fraction_of_diagonal: f64,
    /// The objective.
    pub objective: f64,
    /// Both ways.
    pub two_sided: TwoSidedErrors,
    /// Where each direction's largest distance lies, in the input's coordinates.
    #[serde(default)]
    pub largest_at: LargestErrorAt,
}

/// Where the largest distance of each direction lies: the place to look at first when a fit
/// misses its tolerance (report.json `final.largest_at`, printed by `subfit fit`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LargestErrorAt {
    /// The point of the limit surface (its tessellation written to limit.ply) farthest from
    /// the data.
    pub surface_to_data: [f64; 3],
    /// The data point (a sample of the input's faces, or a vertex) farthest from the limit
    /// surface.
    pub data_to_surface: [f64; 3],
}

/// What the CAD start found and built (report.json `init.cad`, [`crate::start_cad`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CadSummary {
    /// Share of the tessellation's interior edges that are flat (coplanar faces).
    pub flat_edge_share: f64,
    /// Planar regions of three faces or more.
    pub planar_regions: usize,
    /// Share of the triangles that are slivers.
    pub sliver_share: f64,
    /// The exporter's chord height read from the curved faces, fraction of the diagonal.
    pub chord_height: f64,
    /// Edges of the tessellation by class.
    pub flat_edges: usize,
    /// Edges a smooth limit may round.
    pub smooth_edges: usize,
    /// Edges tagged as creases.
    pub crease_edges: usize,
    /// Largest sag of a smooth edge, fraction of the diagonal.
    pub smooth_sag: f64,
    /// Predicted RMS deviation of the smooth faces from the facets, fraction of the diagonal.
    pub predicted_rms: f64,
    /// Vertices of the tessellation.
    pub vertices: usize,
    /// Corners locked before simplification.
    pub locked_corners: usize,
}
