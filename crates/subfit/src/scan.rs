//! The whole pipeline behind every front end (DESIGN.md §1, §2 `subfit`): read or take the
//! target, analyse it (Cheng 2007 §II-C), build an initial control mesh with its topology
//! (§II-A; QEM simplification or IMLS contouring), fit it in stages (Cheng 2004 §4.4–4.6,
//! Cheng 2007 §II-F) while measuring both ways (DESIGN.md decision 11), and return the best
//! cage measured (decision 12) in the input's coordinates with a typed [`Report`].
//!
//! The CLI's `fit`, `demo` and `bench fit`, the tests and (later) the Python package call
//! [`fit_scan`]; none re-implements a step. Nothing here prints: progress and warnings go to the
//! callback.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use subfit_fit::{
    fit_stages, judged_with_boundary, DataTerm, FitOptions, FootPointTerm, IterationRow,
    StageEvent, StageOptions, StageReport, StagesResult,
};
use subfit_init::{default_control_points, initial_control_mesh, InitOptions, SimplifyOptions};
use subfit_io::usda::UsdScheme;
use subfit_mesh::{Cancel, HalfEdgeMesh, PolyMesh, Polygons, Tags};
use subfit_subdiv::Scheme;
use subfit_target::{FeatureOptions, Target, TargetOptions};

use crate::error::Error;
use crate::outputs::usd_scheme;
use crate::tolerance::{
    edge_count, noise_floored, target_tolerances, with_sampling_margin, ToleranceKind,
    NOISE_FLOOR_FACTOR, SCAN_RMS,
};
use subfit_report::{
    data_samples, limit_tessellation, vertex_areas, DistanceStats, MeshDistance, TwoSided,
};

use crate::pipeline_report::{
    face_counts, Errors, FinalErrors, InitSummary, IterationSummary, OptionsSummary, Report,
    RmsMax, StageSummary, TagCounts, TessellationSummary, Timings, Topology, TwoSidedErrors,
    UsdDifference,
};

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
    /// (see [`crate::initial_cage`](mod@crate::initial_cage)).
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

/// Options of [`fit_scan`]. Lengths are in the target's normalized units (the unit cube).
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
    /// ([`ToleranceKind::CadPart`]) has its sharp features detected again from this dihedral
    /// angle (degrees) when the features' angle is larger, and its cage built again
    /// ([`crate::tolerance::CAD_FEATURE_ANGLE`] by default; `None`: never). `subfit fit` sets
    /// `None` when `--feature-angle` is given.
    pub cad_feature_angle: Option<f64>,
    /// Target analysis options.
    pub target: TargetOptions,
    /// Initial-mesh options (`expected_genus` and `expected_boundary_loops` are set from the faces
    /// with `as_points`).
    pub init_options: InitOptions,
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
            fit: FitOptions {
                coverage: 1.0,
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
            error_scale: None,
            cancel: Cancel::default(),
        }
    }
}

/// The automatic cage's simplification goes on past the default control-point count while its
/// collapses move the surface by at most this (unit cube): the flat sides and straight rulings
/// of a CAD part keep only the vertices their shape needs (an open box: its corners).
pub const EXACT_ERROR: f64 = 1e-6;

/// A step of [`fit_scan`], for progress display.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Reading the input file.
    Read,
    /// Target analysis: normals, orientation, curvature, indices.
    Analyse,
    /// Building the initial control mesh.
    Init,
    /// The fitting stages.
    Fit,
}

/// What [`fit_scan`] tells its caller while it works.
#[derive(Clone, Copy, Debug)]
pub enum Progress<'a> {
    /// A step starts.
    Step(Step),
    /// An iteration ended.
    Iteration {
        /// Stage.
        stage: usize,
        /// The row.
        row: &'a IterationRow,
    },
    /// A stage ended.
    Stage(&'a StageReport),
    /// Something the user should know (also kept in the report).
    Warning(&'a str),
}

/// The result of [`fit_scan`]: the cage in the input's coordinates, what is needed to write
/// the outputs, and the report.
pub struct Fitted {
    /// The cage: positions in the input's coordinates, faces.
    pub cage: PolyMesh,
    /// Its crease and corner tags.
    pub tags: Tags,
    /// Its subdivision scheme.
    pub scheme: Scheme,
    /// The report (`report.json`).
    pub report: Report,
    pub(crate) target: Target,
    pub(crate) normalized: PolyMesh,
    pub(crate) stages: StagesResult,
    pub(crate) fit: FitOptions,
    /// The limit tessellation (normalized units) and the distance of each of its vertices to
    /// the target.
    pub(crate) limit: PolyMesh,
    pub(crate) local_error: Vec<f64>,
    /// The distance of each data sample to that tessellation (data → surface).
    pub(crate) data_error: Vec<f64>,
    pub(crate) cancel: Cancel,
}

impl Fitted {
    /// Whether the cage meets the tolerances (both ways unless one-sided was asked).
    pub fn reached(&self) -> bool {
        self.report.tolerance_reached
    }

    /// The cage in the target's normalized units.
    pub fn normalized_cage(&self) -> &PolyMesh {
        &self.normalized
    }

    /// The analysed target.
    pub fn target(&self) -> &Target {
        &self.target
    }
}

/// Fits a subdivision surface to `input`: the whole pipeline (see the module docs).
///
/// Errors: invalid options ([`Error::Options`]), an unreadable or unusable input
/// ([`Error::Io`], [`Error::Input`] naming the element), a budget that cannot be honoured
/// ([`Error::Budget`]), a failed initial mesh or fit. On error nothing is returned; nothing
/// is written in any case (see [`Fitted::write_into`]).
///
/// A quad scheme whose default start exceeds the budget (`--max-control-points` below the
/// target's default size) is fitted from each of [`BUDGET_STARTS`] and the better cage kept
/// ([`crate::budget_starts`]).
pub fn fit_scan(
    input: Input,
    options: &FitScanOptions,
    progress: Option<&mut dyn FnMut(Progress<'_>)>,
) -> Result<Fitted, Error> {
    validate(options)?;
    crate::initial_cage::fit_best_init(input, options, progress)
}

/// [`fit_scan`] once: a quad scheme capped by the budget starts at `start` of it.
pub(crate) fn fit_scan_from(
    input: Input,
    options: &FitScanOptions,
    mut progress: Option<&mut dyn FnMut(Progress<'_>)>,
    start: f64,
) -> Result<Fitted, Error> {
    let mut warnings: Vec<String> = Vec::new();
    let mut warn = |msg: String, progress: &mut Option<&mut dyn FnMut(Progress<'_>)>| {
        if let Some(p) = progress.as_mut() {
            p(Progress::Warning(&msg));
        }
        warnings.push(msg);
    };
    let step = |s: Step, progress: &mut Option<&mut dyn FnMut(Progress<'_>)>| {
        if let Some(p) = progress.as_mut() {
            p(Progress::Step(s));
        }
    };
    let t0 = Instant::now();
    step(Step::Read, &mut progress);
    let (mut mesh, name, reoriented) =
        crate::repair::read_input(input, options.as_points, &mut |m| warn(m, &mut progress))?;
    let read = t0.elapsed().as_secs_f64();
    options.cancel.check().map_err(|_| Error::Interrupted)?;

    // With `as_points` the faces are dropped, but their genus still tells the initial mesh
    // what topology to aim for.
    let mut init_options = options.init_options.clone();
    init_options.cancel = options.cancel.clone();
    if options.control_points.is_some() {
        // The count asked for is the count given.
        init_options.simplify.exact_error = 0.0;
    }
    // Catmull-Clark and quad/triangle cages start quad-dominant; Loop needs triangles.
    init_options.quad_dominant = options
        .quad_dominant
        .unwrap_or(options.scheme.is_some_and(|s| s != Scheme::Loop));
    if options.as_points && !mesh.faces.is_empty() {
        if let Ok(t) = topology(&mesh) {
            init_options.expected_genus = Some(t.genus);
            init_options.expected_boundary_loops = Some(t.boundary_loops);
        }
        mesh.faces = Polygons::new();
    }
    let target_topology = if mesh.faces.is_empty() {
        None
    } else {
        Some(topology(&mesh).map_err(|e| Error::input(&name, e))?)
    };

    step(Step::Analyse, &mut progress);
    let target_options = TargetOptions {
        cancel: options.cancel.clone(),
        ..options.target.clone()
    };
    let target = Target::build(&mesh, &target_options, None).map_err(|e| match e {
        subfit_target::TargetError::Interrupted => Error::Interrupted,
        e => Error::input(&name, e),
    })?;
    let preprocess = target.stats().timings.total.as_secs_f64();
    let outliers = target.stats().outliers_removed;
    if outliers > 0 {
        warn(
            format!(
                "dropped {outliers} of {} points of {name} as outliers (not fitted, not measured)",
                target.stats().input_points
            ),
            &mut progress,
        );
    }

    step(Step::Init, &mut progress);
    let t_init = Instant::now();
    let budget = options.stages.max_control_points;
    // A CAD tessellation starts from its own features (crate::cad_start), or `None`.
    let cad = crate::cad_start::cad_start(&target, &mesh, &name, options)?;
    let mut feature_segments = cad.as_ref().map(|c| Arc::new(c.feature_segments.clone()));
    let (control, tags, init) = match (&options.init, &cad) {
        (_, Some(c)) => (c.cage.clone(), c.tags.clone(), c.init.clone()),
        (
            InitialCage::Given {
                mesh: c,
                tags,
                name: cname,
            },
            None,
        ) => crate::initial_cage::given_cage(
            &target,
            target_topology,
            &name,
            c,
            tags,
            cname,
            budget,
            options,
            &init_options,
        )?,
        (InitialCage::CurvatureLines, None) => {
            crate::initial_cage::curvature_line_start(&target, &mesh, &name, options)?
        }
        (InitialCage::Auto | InitialCage::Qem, None) => {
            let mut budget_start = None;
            let n = match options.control_points {
                Some(n) if n > budget => {
                    return Err(Error::Budget(format!(
                        "{n} initial control points asked for, more than the budget of {budget} (--max-control-points)"
                    )))
                }
                Some(n) => n,
                None => {
                    let (n, f) = crate::budget_starts::start_control_points(default_control_points(target.len()), budget, options.scheme, start);
                    budget_start = f;
                    n
                }
            };
            let dense = (!mesh.faces.is_empty()).then_some(&mesh);
            // The default start of a cloud found open is larger (subfit_init::OPEN_CLOUD_SCALE)
            // unless its noise is half a scan's RMS tolerance or more: the extra points would
            // fit noise (a view of the bunny with range noise 2e-3: 642 → 1,303 control points
            // for a surface 5 % closer to the true mesh). A count asked for, or a start the
            // budget set, is kept.
            let diagonal = subfit_mesh::bounding_box(target.points()).map_or(0.0, |(lo, hi)| {
                subfit_mesh::vec3::norm(subfit_mesh::vec3::sub(hi, lo))
            });
            let quiet = target.stats().noise_level < 0.5 * SCAN_RMS * diagonal;
            if options.control_points.is_none() && budget_start.is_none() && quiet {
                init_options.open_cloud_scale = subfit_init::OPEN_CLOUD_SCALE;
            }
            // Concave corners may add points within the budget, not to a count asked for.
            init_options.max_control_points = if options.control_points.is_some() {
                n
            } else {
                budget
            };
            let build = |init_options: &InitOptions| {
                initial_control_mesh(&target, dense, n, init_options).map_err(|e| match e {
                    subfit_init::InitError::TooFewForTopology { .. } if options.control_points.is_none() => {
                        Error::Budget(format!("{name}: the budget of {budget} control points is too small for this target: {e}"))
                    }
                    subfit_init::InitError::Interrupted => Error::Interrupted,
                    e => Error::Init { name: name.clone(), source: e },
                })
            };
            let (mut m, mut r) = build(&init_options)?;
            // A CAD part: its features again from a smaller angle (the facets of a coarsely
            // tessellated fillet meet at kinks the default angle leaves to the smooth surface).
            let cad_angle = options
                .cad_feature_angle
                .filter(|_| options.target_tolerances)
                .filter(|&a| {
                    init_options
                        .features
                        .as_ref()
                        .is_some_and(|f| f.angle_deg > a)
                });
            if let Some(angle) = cad_angle {
                let kind = ToleranceKind::of(target.stats(), &r.tags, edge_count(&m.faces));
                if kind == ToleranceKind::CadPart {
                    let mut again = init_options.clone();
                    if let Some(f) = again.features.as_mut() {
                        f.angle_deg = angle;
                    }
                    // A cage the smaller angle cannot give within the budget (too many
                    // feature curves for it) leaves the first one.
                    match build(&again) {
                        Ok(second) if second.0.num_vertices() <= budget => {
                            (m, r) = second;
                            init_options = again;
                        }
                        Err(Error::Interrupted) => return Err(Error::Interrupted),
                        _ => {}
                    }
                }
            }
            if m.num_vertices() > budget {
                return Err(Error::Budget(format!(
                    "{name}: the initial control mesh keeps {} control points (no legal simplification below it for this topology), more than the budget of {budget}",
                    m.num_vertices()
                )));
            }
            if r.simplify.smoothed {
                let msg = "the mesh is too noisy to simplify as it is (crumpled triangles): the initial cage comes from a smoothed copy";
                warn(msg.into(), &mut progress);
            }
            if !r.genus_matches {
                warn(
                    format!(
                        "the initial control mesh has genus {}, the target {}",
                        r.genus_after, r.genus_target
                    ),
                    &mut progress,
                );
            }
            let summary = InitSummary {
                budget_start,
                ..crate::initial_cage::init_summary(&r, n, &m, init_options.features.as_ref())
            };
            if !r.feature_segments.is_empty() {
                feature_segments = Some(Arc::new(r.feature_segments));
            }
            (m, r.tags, summary)
        }
    };
    let init_time = t_init.elapsed().as_secs_f64();

    let scheme = options
        .scheme
        .unwrap_or(if init.source == "CurvatureLines" {
            // Lavoué's cages are quad/triangle.
            Scheme::QuadTriangle
        } else if control.faces.is_triangles() {
            // Open mesh targets take the quad/triangle scheme (Lavoué et al.), whose quads come
            // from the start (the curvature-line cage); on the triangles of an automatic cage
            // it is Loop, refined as Loop ([`subfit_fit::TriangleSplit::for_cage`]).
            let open_mesh = target_topology.is_some_and(|t| t.boundary_loops > 0);
            if open_mesh && !matches!(options.init, InitialCage::Given { .. }) {
                Scheme::QuadTriangle
            } else {
                Scheme::Loop
            }
        } else {
            Scheme::CatmullClark
        });
    let fit = FitOptions {
        scheme,
        tags,
        feature_segments: feature_segments.or_else(|| options.fit.feature_segments.clone()),
        cancel: options.cancel.clone(),
        sample_level: if init.source == "CurvatureLines" {
            crate::initial_cage::coarse_sample_level(control.faces.len(), options.fit.sample_level)
        } else {
            options.fit.sample_level
        },
        ..options.fit.clone()
    };

    let tolerance_kind = options.target_tolerances.then(|| match &cad {
        Some(c) => c.kind,
        None => ToleranceKind::of(target.stats(), &fit.tags, edge_count(&control.faces)),
    });
    let mut judged = match tolerance_kind {
        Some(kind) => {
            let diagonal = FootPointTerm::from_options(&target, &fit).bbox_diagonal();
            target_tolerances(&options.stages, kind, diagonal)
        }
        None => options.stages.clone(),
    };
    if let Some(c) = &cad {
        // No more control points than the tessellation has vertices.
        judged.max_control_points = judged.max_control_points.min(c.max_control_points);
    }
    let (stages, noise_floor) = noise_floored(&judged, target.stats());
    if let Some(t) = noise_floor {
        warn(
            format!(
                "{name}: a noisy scan (noise level {:.2e}, {:.2} × the point spacing): the RMS tolerance is judged as √(tol² + ({NOISE_FLOOR_FACTOR} σ)²) = {t:.2e} unit cube, since the data's own noise keeps data → surface near σ",
                target.stats().noise_level,
                target.stats().noise_level / target.stats().point_spacing,
            ),
            &mut progress,
        );
    }

    step(Step::Fit, &mut progress);
    let t_fit = Instant::now();
    let result = {
        let mut on_event = |e: StageEvent<'_>| {
            if let Some(p) = progress.as_mut() {
                match e {
                    StageEvent::Iteration { stage, row } => p(Progress::Iteration { stage, row }),
                    StageEvent::Stage(s) => p(Progress::Stage(s)),
                }
            }
        };
        // The target's maxima are met by the stages with a margin: the final tessellation is
        // finer than the stages' samples and finds higher peaks.
        let working = match tolerance_kind {
            Some(_) => with_sampling_margin(&stages),
            None => stages.clone(),
        };
        fit_stages(&target, &control, &fit, &working, Some(&mut on_event)).map_err(|e| match e {
            subfit_fit::FitError::Interrupted => Error::Interrupted,
            e => Error::Fit {
                name: name.clone(),
                source: e,
            },
        })?
    };
    let fit_time = t_fit.elapsed().as_secs_f64();

    let unit = target.normalization().length_to_original(1.0);
    let last = result.report.last;
    // Foot points as the fitter takes them; its diagonal is the one ErrorStats divide by.
    let term = FootPointTerm::from_options(&target, &fit);
    let diagonal = term.bbox_diagonal();
    options.cancel.check().map_err(|_| Error::Interrupted)?;
    // The cage written, measured both ways on the tessellation written with it (chordal error
    // a tenth of the fitting error, reported): what a user measures on limit.ply.
    let t_measure = Instant::now();
    let tessellation = limit_tessellation(
        &result.mesh.faces,
        &result.mesh.positions,
        &result.tags,
        &fit.subdivision(),
        last.e_rms,
        last.e_max,
    )
    .map_err(|e| Error::Output(e.to_string()))?;
    let local: Vec<f64> = term
        .squared_errors(&tessellation.mesh.positions)
        .into_iter()
        .map(f64::sqrt)
        .collect();
    let data = data_samples(&target, options.stages.data_samples);
    let to_surface: Vec<f64> =
        MeshDistance::new(&tessellation.mesh.positions, &tessellation.mesh.faces)
            .distances(&data.points)
            .iter()
            .map(|p| p.distance)
            .collect();
    let final_two = TwoSided {
        surface_to_data: DistanceStats::of_weighted(
            &local,
            &vertex_areas(&tessellation.mesh.positions, &tessellation.mesh.faces),
        ),
        data_to_surface: DistanceStats::of(&to_surface),
    };
    let usd_difference = if usd_scheme(scheme, &result.mesh.faces) == UsdScheme::QuadTriangle {
        let d = usd_difference(
            &result.mesh,
            &result.tags,
            &fit.subdivision(),
            tessellation.level,
            diagonal,
            unit,
        )?;
        warn(
            format!(
                "USD has no quad/triangle scheme: control.usda declares Catmull-Clark with the smooth triangle rule (subfit:scheme = \"quadTriangle\" records the real one); that surface lies within {:.3}% of the diagonal of the fitted one (RMS {:.3}%, max {:.3e} input units)",
                100.0 * d.max_fraction_of_diagonal,
                100.0 * d.rms_fraction_of_diagonal,
                d.max_original_units
            ),
            &mut progress,
        );
        Some(d)
    } else {
        None
    };
    let measure_time = t_measure.elapsed().as_secs_f64();
    let two = TwoSidedErrors::new(&final_two, diagonal, unit);
    let rim = &to_surface[to_surface.len() - data.boundary.min(to_surface.len())..];
    let judged_two = judged_with_boundary(&final_two, rim, &stages);
    let reached = stages.met(&last, &judged_two);
    let reached_one_sided = stages.reached(&last);
    let reached_two_sided = judged_two.within(stages.tolerance_rms, stages.tolerance_max);
    let cage = PolyMesh::new(
        result
            .mesh
            .positions
            .iter()
            .map(|&p| target.to_original(p))
            .collect(),
        result.mesh.faces.clone(),
    );
    let st = &judged;
    let report = Report {
        target: name,
        target_points: target.len(),
        target_outliers_removed: target.stats().outliers_removed,
        target_noise_level: target.stats().noise_level,
        target_point_spacing: target.stats().point_spacing,
        noise_floored_tolerance: noise_floor,
        tolerance_kind,
        target_topology,
        reoriented,
        normalized_unit_in_original_units: unit,
        bbox_diagonal_unit_cube: diagonal,
        data_samples: match result.report.data_samples {
            subfit_report::data_samples::SampleKind::Points => "points".into(),
            subfit_report::data_samples::SampleKind::MeshArea => "mesh_area".into(),
        },
        init,
        options: OptionsSummary {
            scheme: format!("{scheme:?}"),
            method: format!("{:?}", fit.method).to_uppercase(),
            step: format!("{:?}", fit.step),
            lambda_start: st.lambda_start,
            lambda_end: st.lambda_end,
            lambda_factor: st.lambda_factor,
            sample_level: fit.sample_level,
            max_iterations: st.max_iterations,
            stage_iterations: st.iterations_per_stage,
            tolerance_rms: st.tolerance_rms,
            tolerance_max: (st.tolerance_max > 0.0).then_some(st.tolerance_max),
            two_sided: st.two_sided,
            max_control_points: st.max_control_points,
            refine: st.refine,
            edge_flips: st.edge_flips,
            max_depth: st.max_depth,
            local: st.local,
            local_rings: st.local_rings,
            local_field_peak: st.local_field_peak,
            local_field_share: st.local_field_share,
            polish_power: st.polish_power,
            imls_radius: (fit.method == subfit_fit::Method::Imls)
                .then(|| subfit_fit::ImlsTerm::from_options(&target, &fit).radius()),
            arap: fit.arap,
            optimizer: match fit.optimizer {
                subfit_fit::Optimizer::GaussNewton => "GaussNewton",
                subfit_fit::Optimizer::Adam { .. } => "Adam",
                subfit_fit::Optimizer::Lbfgs { .. } => "Lbfgs",
            }
            .into(),
        },
        control_points: result.mesh.num_vertices(),
        control_faces: result.mesh.faces.len(),
        control_quad_fraction: face_counts(&result.mesh.faces).2,
        tags: TagCounts {
            creases: result.tags.creases().len(),
            corners: result.tags.corners().len(),
        },
        initial: (&result.report.initial).into(),
        initial_two_sided: TwoSidedErrors::new(&result.report.initial_two_sided, diagonal, unit),
        r#final: {
            let e = Errors::from(&last);
            FinalErrors {
                e_max: e.e_max,
                e_rms: e.e_rms,
                e_max_fraction_of_diagonal: e.e_max_fraction_of_diagonal,
                e_rms_fraction_of_diagonal: e.e_rms_fraction_of_diagonal,
                objective: e.objective,
                two_sided: two,
            }
        },
        best_stage: result.report.best_stage,
        stop: format!("{:?}", result.report.stop),
        tolerance_reached: reached,
        tolerance_reached_surface_to_data: reached_one_sided,
        tolerance_reached_two_sided: reached_two_sided,
        warnings,
        usd_difference,
        stages: result
            .report
            .stages
            .iter()
            .map(StageSummary::from)
            .collect(),
        iterations: result
            .report
            .stages
            .iter()
            .flat_map(|s| {
                s.fit
                    .iterations
                    .iter()
                    .map(move |r| IterationSummary::new(s.stage, r))
            })
            .collect(),
        limit_tessellation: {
            let c = tessellation.chordal;
            TessellationSummary {
                level: tessellation.level,
                vertices: tessellation.mesh.positions.len(),
                predicted_chordal_error: RmsMax {
                    max: c.max,
                    rms: c.rms,
                },
                goal: RmsMax {
                    max: 0.1 * last.e_max,
                    rms: 0.1 * last.e_rms,
                },
                goal_met: c.max <= 0.1 * last.e_max && c.rms <= 0.1 * last.e_rms,
            }
        },
        error_color_scale_unit_cube: options.error_scale.unwrap_or(0.0),
        budget_starts: Vec::new(),
        timings_s: Timings {
            read,
            preprocess,
            init: init_time,
            fit: fit_time,
            measure: measure_time,
            output: 0.0,
            total: t0.elapsed().as_secs_f64(),
        },
    };
    Ok(Fitted {
        cage,
        tags: result.tags.clone(),
        scheme,
        report,
        target,
        normalized: result.mesh.clone(),
        stages: result,
        fit,
        limit: tessellation.mesh,
        local_error: local,
        data_error: to_surface,
        cancel: options.cancel.clone(),
    })
}

/// Both-way distances between the quad/triangle limit of `cage` and the Catmull-Clark limit
/// (smooth triangle rule, what control.usda declares) at refinement `level`.
fn usd_difference(
    cage: &PolyMesh,
    tags: &Tags,
    options: &subfit_subdiv::Options,
    level: usize,
    diagonal: f64,
    unit: f64,
) -> Result<UsdDifference, Error> {
    use subfit_subdiv::{sampling_operator, TriangleRule};
    let cc = options
        .with_triangles(TriangleRule::Smooth)
        .with_scheme(Scheme::CatmullClark);
    let surface = |o: &subfit_subdiv::Options| {
        sampling_operator(&cage.faces, cage.num_vertices(), tags, o, level)
            .map(|op| (op.position.apply(&cage.positions), op.faces))
            .map_err(|e| Error::Output(e.to_string()))
    };
    let (pa, fa) = surface(options)?;
    let (pb, fb) = surface(&cc)?;
    let ab = MeshDistance::new(&pb, &fb).distances(&pa);
    let ba = MeshDistance::new(&pa, &fa).distances(&pb);
    let d: Vec<f64> = ab.iter().chain(&ba).map(|p| p.distance).collect();
    let stats = DistanceStats::of(&d);
    Ok(UsdDifference {
        written_as: "catmullClark, triangleSubdivisionRule = smooth".into(),
        rms_fraction_of_diagonal: stats.rms / diagonal,
        max_fraction_of_diagonal: stats.max / diagonal,
        max_original_units: stats.max * unit,
    })
}

fn validate(o: &FitScanOptions) -> Result<(), Error> {
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

/// Genus and boundary loops of a mesh with faces; the error names the element that makes it
/// unusable.
pub(crate) fn topology(m: &PolyMesh) -> Result<Topology, subfit_mesh::TopologyError> {
    let h = HalfEdgeMesh::from_mesh(m)?;
    Ok(Topology {
        genus: h.genus(),
        boundary_loops: h.boundary_loops().len(),
    })
}

/// Reads `path` as a cage for [`InitialCage::Given`].
pub fn read_cage(path: &Path) -> Result<InitialCage, Error> {
    let (mesh, _) = subfit_io::read_file(path, &subfit_io::ReadOptions::default())?;
    if mesh.faces.is_empty() {
        return Err(Error::input(
            &path.display().to_string(),
            "has no faces; an initial control mesh is needed",
        ));
    }
    Ok(InitialCage::Given {
        mesh,
        tags: Tags::new(),
        name: path.display().to_string(),
    })
}
