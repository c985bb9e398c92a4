//! One cage fitted to every frame of a deforming scan (Xie et al. 2023 §4.2, §5.2, Fig. 2 and
//! 10–13): the template is fitted to the first frame (or given), each next frame starts from
//! the template carried onto it by the tracking step below (warm-started from the previous
//! frames' motions; without tracking, from the previous frame's cage) and is fitted with the
//! data term of [`FitOptions::method`], the umbrella smoothing, the as-rigid-as-possible
//! regularizer whose rest shape is the **template** (so the cage keeps its local shape and
//! does not swim over the surface), and optionally the soft silhouette term of
//! [`subfit_fit::silhouette`] (K orthographic views around the frame, Xie et al.'s remedy for
//! tangential drift; on complete 3D frames it changes the drift by less than 0.01 % of the
//! diagonal either way — a silhouette is a function of the shape alone and cannot see a
//! slide over it, [`subfit_fit::SurfaceTerm`]). Every
//! frame's cage has the template's connectivity and vertex order — the point of a sequence —
//! and is measured both ways like a single fit.
//!
//! **Tracking.** Before each frame's fit, the template is carried onto the frame by an
//! embedded deformation ([`subfit_fit::track`], [`TrackingOptions`]: 60 nodes inside the body,
//! halfway to its medial points, laid out over the surface — neighbours and skinning by
//! distance over it; at most 20 Gauss-Newton steps annealed from stiff to supple, pulling the
//! model's samples to the frame and the frame's points to the model, started from the two
//! previous frames' motions extrapolated). Closest points only move the cage along the
//! surface's normal; the step follows large motion between frames (a limb that moved farther
//! than its width) and the part of the motion along the surface that the frame's shape
//! reveals (limbs, joints, a head turning), and the field's smoothness decides the rest.
//! Mapping from the template rather than from the previous frame (re-anchoring every frame to
//! the first) keeps one frame's error from being carried into the next. A step stops as soon
//! as the frame's residual is within [`TrackingOptions::discrepancy`] of what the previous cage
//! left on its own frame (Morozov's discrepancy principle): a body that holds still is then not
//! tracked into a slide. The fit's ARAP term then keeps the template's local shape *as the
//! tracking carried it*: the template itself would pull the cage back from the frame's true
//! strains, and so along the surface.
//!
//! Measured with `subfit bench sequence --motion dance --stride 5 --points 40000` (an
//! articulated figure dancing, seen at a fifth of a smooth capture's frame rate, 30 frames of
//! 40k fresh random points without normals, 1,000 control points; fractions of the diagonal,
//! worst frame): two-sided RMS 0.038 %, tracked points' drift RMS 0.73 % and 95th percentile
//! 1.56 % (largest 3.1 %), with the silhouette term or without; 1.98 CPU seconds per frame with
//! the 8-view silhouette, 1.44 without (all threads; the wall clock on a machine loaded twenty
//! times over its two cores was 6.3 and 4.7 s). A body
//! whose bulges travel over its material (`--motion moderate|large`, the generated tube) leaves
//! the slide along its surface free: its drift stays a few per cent, the priors' choice (see
//! [`subfit_fit::track`]); markers pin it ([`TrackingOptions::markers`]).
//!
//! On the corpus (`subfit bench corpus --entry seq-cat-run`): the 36-frame run cycle of a
//! low-poly cat (398 vertices, 4,723 control points by [`fit_scan`]'s rule) is tracked within
//! 0.16 % of the diagonal both ways at its worst frame, its drift 2.4 % RMS and 5.7 % at the
//! 95th percentile — growing with the pose's distance from the template's and back to 0.16 %
//! as the cycle closes, so what is left is the tracking's reach, not an accumulation. Smaller
//! templates drift less over the first frames and fit worse (first 12 frames, no silhouette,
//! before the tracking's robust weights: 500 / 1,500 / 4,723 control points, RMS 0.21 / 0.16 /
//! 0.14 %, drift 1.9 / 2.5 / 3.6 %), but not over the whole cycle (1,000: RMS 0.39 %, drift
//! 3.9 %; 1,500: 0.24 %, 3.3 %; 4,723: 0.19 %, 3.2 %, with the silhouette). Poses that are not a
//! capture's steps (seq-lion: consecutive frames 8–124° apart) were lost from the second frame
//! (worst frame 2.05 % / 9.73 %); started from rigid alignments judged with normals
//! ([`subfit_fit::track::warm_starts`]) 1.12 % / 6.79 % of the diagonal, 7 of 9 frames turned
//! within 14° of their true rotation — the rest of the error is the tracking's reach on limbs
//! that moved as far as the body's width, and the fit after it (0.46–1.12 % per frame, the
//! template itself 0.146 %).
//!
//! All frames share one normalization, the first frame's (the unit cube of frame 0), so that
//! the cage moves in one set of units; every figure is reported in the frame's own units and
//! as a fraction of the frame's own bounding-box diagonal.
//!
//! Frames come from an iterator and leave through a callback ([`fit_sequence`]): a long
//! sequence streams, only the per-frame reports and the cages' positions are kept.
//!
//! **Drift diagnostics** (no ground truth is needed): the limit points of the control vertices
//! are tracked; per frame the report gives the RMS of their motion since the previous frame
//! split into its part along the limit normal and its tangential part (the sliding a geometric
//! fit cannot see), and the RMS relative change of the cage's edge lengths against the
//! template (how far the cage is from the template's local shape).

use std::sync::Arc;
use std::time::Instant;

use subfit_fit::{AnyTerm, FitOptions, Fitter, Method, WeightedSurfaceTerm};
use subfit_measure::data_samples;
use subfit_mesh::vec3::{cross, dist2, dot, sub};
use subfit_mesh::{Cancel, PolyMesh, Polygons, Tags};
use subfit_subdiv::{sampling_operator, Scheme};
use subfit_target::{Normalization, Target, TargetOptions};

use crate::error::Error;
use crate::limit_stencils::LimitStencils;
use crate::pipeline_report::{Reorientation, TwoSidedErrors};
use crate::repair::read_input;
pub use crate::sequence_output::{
    frame_file_name, DriftDiagnostics, FrameReport, FrameTimings, Sequence, SequenceFrame,
    SequenceOptionsSummary, SequenceReport,
};
use crate::sequence_tracking::Tracking;
pub use crate::sequence_tracking::{MarkerObservation, TrackingOptions, TrackingReport};
use crate::{fit_scan, FitScanOptions, InitialCage, Input};

/// The silhouette term of a sequence (Xie et al. 2023 §4.2; [`subfit_fit::silhouette`]).
#[derive(Clone, Debug, PartialEq)]
pub struct SilhouetteOptions {
    /// Number of views around the frame's bounding sphere; 0 turns the term off. Default 8.
    pub views: usize,
    /// Image resolution (pixels per side). Default 128.
    pub resolution: usize,
    /// Refinement level of the limit tessellation that is rendered (its triangles are what the
    /// rasterizer pays for, per view). Default 0, the control vertices' limit points: on 1,000
    /// control points about 2,000 triangles of a few pixels each at 128², whose chords stray
    /// from the limit surface by less than a pixel even on the thin limbs of the dancing
    /// figure (level 1 rendered four times the triangles, a fifth of a frame's time).
    pub level: usize,
    /// Weight of the loss (mean squared pixel difference) in the objective, against the data
    /// term's mean squared distance (normalized units²). Default [`DEFAULT_SILHOUETTE_WEIGHT`].
    pub weight: f64,
}

/// The default weight of the silhouette loss (see [`SilhouetteOptions::weight`]).
pub const DEFAULT_SILHOUETTE_WEIGHT: f64 = 1e-4;

impl Default for SilhouetteOptions {
    fn default() -> Self {
        Self {
            views: 8,
            resolution: 128,
            level: 0,
            weight: DEFAULT_SILHOUETTE_WEIGHT,
        }
    }
}

/// Options of [`fit_sequence`]. Lengths in the first frame's normalized units (its unit cube).
#[derive(Clone, Debug)]
pub struct SequenceOptions {
    /// The template: [`InitialCage::Auto`] (default) fits the first frame with
    /// [`Self::template_fit`] ([`fit_scan`]); [`InitialCage::Given`] is a cage in the first
    /// frame's coordinates, fitted to it like every other frame.
    pub template: InitialCage,
    /// Options of the template's fit ([`fit_scan`]; its `init` is replaced by
    /// [`Self::template`], its `cancel` by [`Self::cancel`]). Default: `fit_scan`'s.
    pub template_fit: FitScanOptions,
    /// Per-frame fit options: method (SDM or IMLS), sample level, coverage, step control. The
    /// scheme and tags are the template's, `λ`, `α` and the iteration cap those below.
    /// Default: [`FitOptions::default`] with coverage 1 (as [`fit_scan`]).
    pub fit: FitOptions,
    /// Umbrella smoothing `λ` per frame. Default `1e-5` (the end of the template's schedule).
    pub lambda: f64,
    /// ARAP weight `α` towards the template ([`FitOptions::arap`]) at the end of each frame's
    /// fit: its rest shape is the template as the tracking carried it onto the frame (the
    /// template itself without tracking). Default 0.01 (Xie et al.).
    pub arap: f64,
    /// ARAP weight at the start of each frame's fit: `α` is annealed from this down to
    /// [`Self::arap`] by factors of 10, the iterations shared among the levels, so the cage
    /// first follows the frame nearly rigidly piece by piece (closest points pull, ARAP keeps
    /// the template's local shape: the cage's points go where their material went) and then
    /// fits the details (the stiffness annealing of non-rigid ICP, Amberg et al. 2007).
    /// Default 0.01, equal to [`Self::arap`]: no annealing (on the generated sequences of
    /// `subfit bench sequence` annealing from 10 or 1000 did not lower the drift).
    pub arap_start: f64,

    /// LM iterations per frame at most. Default 12.
    pub iterations: usize,
    /// A frame stops early when both directions' RMS are within this (normalized units), or
    /// within 1.25 times the template's own two-sided RMS on its frame when that is larger
    /// (the cage fits no frame better than its own). Default `5e-4`.
    pub tolerance_rms: f64,
    /// The silhouette term. Default on (8 views, 128²).
    pub silhouette: SilhouetteOptions,
    /// Data → surface samples of a mesh frame (0: as many as it has points). Default 0.
    pub data_samples: usize,
    /// Frame-to-frame tracking before each frame's fit ([`subfit_fit::track`]); `None` starts
    /// each frame's fit from the previous frame's cage as it is. Default on.
    pub tracking: Option<TrackingOptions>,
    /// Cancels the run; polled by every long step.
    pub cancel: Cancel,
}

impl Default for SequenceOptions {
    fn default() -> Self {
        Self {
            template: InitialCage::Auto,
            template_fit: FitScanOptions::default(),
            fit: FitOptions {
                coverage: 1.0,
                ..FitOptions::default()
            },
            lambda: 1e-5,
            arap: 0.01,
            arap_start: 0.01,

            iterations: 12,
            tolerance_rms: 5e-4,
            silhouette: SilhouetteOptions::default(),
            data_samples: 0,
            tracking: Some(TrackingOptions::default()),
            cancel: Cancel::default(),
        }
    }
}

/// What carries over from frame to frame.
struct Carry {
    normalization: Normalization,
    faces: Polygons,
    tags: Tags,
    scheme: Scheme,
    template: Arc<Vec<[f64; 3]>>,
    previous: Vec<[f64; 3]>,
    /// Limit points of the control vertices (`#V × #V` stencils) and their tangents.
    limit: LimitStencils,
    previous_limit: Option<Vec<[f64; 3]>>,
    template_edges: Vec<(u32, u32, f64)>,
    /// The template's own two-sided RMS on its frame (normalized units; 0 for a given cage).
    template_rms: f64,
    /// The tracking step's graph, the limit samples it tracks and its last motion.
    tracking: Option<Tracking>,
}

/// Fits one cage to every frame of `frames` in order (see the module docs), calling
/// `on_frame` with each fitted frame as soon as it is done (to write it; an error there stops
/// the run). `warn` receives what the user should know.
///
/// Errors: an unreadable or unusable frame (named), a failed fit, a cage whose topology does
/// not suit the first frame, an interruption, the callback's error. Cost per frame: one target
/// analysis (near-linear in its points), the silhouette's target images, one fitter set-up and
/// at most [`SequenceOptions::iterations`] LM iterations, one two-sided measurement.
///
/// ```
/// use subfit::mesh::shapes::Shape;
/// use subfit::{fit_sequence, FitScanOptions, Input, SequenceOptions, SilhouetteOptions};
///
/// // Three frames of the papers' ellipsoid (1,500 points each) moving along x.
/// let frames = (0..3).map(|t| {
///     let mut mesh = Shape::PAPER_ELLIPSOID.sample(1_500, 0.0, 1 + t);
///     mesh.positions.iter_mut().for_each(|p| p[0] += 0.05 * t as f64);
///     Input::Mesh { mesh, name: format!("frame {t}") }
/// });
/// let mut template_fit = FitScanOptions { control_points: Some(60), ..Default::default() };
/// template_fit.stages.max_iterations = 5;
/// let options = SequenceOptions {
///     template_fit,
///     silhouette: SilhouetteOptions { views: 0, ..Default::default() },
///     ..Default::default()
/// };
/// let mut written = 0;
/// let seq = fit_sequence(frames, &options, &mut |_frame| { written += 1; Ok(()) }, &mut |_| {})?;
/// assert_eq!((written, seq.positions.len()), (3, 3));
/// // One connectivity, every frame: the cage follows the motion.
/// let n = seq.positions[0].len();
/// assert!(seq.positions.iter().all(|p| p.len() == n));
/// let mean_x = |p: &[[f64; 3]]| p.iter().map(|q| q[0]).sum::<f64>() / p.len() as f64;
/// let moved = mean_x(&seq.positions[2]) - mean_x(&seq.positions[0]);
/// assert!((moved - 0.1).abs() < 0.02, "moved {moved}");
/// # Ok::<(), subfit::Error>(())
/// ```
pub fn fit_sequence<I>(
    frames: I,
    options: &SequenceOptions,
    on_frame: &mut dyn FnMut(SequenceFrame<'_>) -> Result<(), Error>,
    warn: &mut dyn FnMut(&str),
) -> Result<Sequence, Error>
where
    I: IntoIterator<Item = Input>,
{
    validate(options)?;
    let mut warnings: Vec<String> = Vec::new();
    let mut warn_all = |m: String| {
        warn(&m);
        warnings.push(m);
    };
    let mut carry: Option<Carry> = None;
    let mut reports: Vec<FrameReport> = Vec::new();
    let mut positions: Vec<Vec<[f64; 3]>> = Vec::new();
    let mut template_report = None;
    let mut template_name = "fit".to_string();
    for (index, input) in frames.into_iter().enumerate() {
        options.cancel.check().map_err(|_| Error::Interrupted)?;
        let t0 = Instant::now();
        let (report, cage) = match carry.as_mut() {
            None if !matches!(options.template, InitialCage::Given { .. }) => {
                let (c, report, fitted_report) = template_frame(input, options, &mut warn_all)?;
                template_report = Some(Box::new(fitted_report));
                let cage = original_cage(&c);
                carry = Some(c);
                (report, cage)
            }
            None => {
                let InitialCage::Given { mesh, tags, name } = &options.template else {
                    unreachable!("matched above")
                };
                template_name.clone_from(name);
                let (mesh_in, fname, reoriented, read) = read_frame(input, &mut warn_all)?;
                let (lo, hi) = mesh_in.bounding_box().unwrap_or(([0.0; 3], [0.0; 3]));
                let normalization = Normalization::from_bounds(lo, hi)
                    .ok_or_else(|| Error::input(&fname, "all points coincide: nothing to fit"))?;
                let cage: Vec<[f64; 3]> = mesh
                    .positions
                    .iter()
                    .map(|&p| normalization.to_normalized(p))
                    .collect();
                let scheme = options
                    .template_fit
                    .scheme
                    .unwrap_or(if mesh.faces.is_triangles() {
                        Scheme::Loop
                    } else {
                        Scheme::CatmullClark
                    });
                let mut c = Carry::new(
                    normalization,
                    mesh.faces.clone(),
                    tags.clone(),
                    scheme,
                    cage,
                    &options.fit,
                    options.tracking.as_ref(),
                )
                .map_err(|e| Error::input(name, e))?;
                let report = fit_frame(
                    &mut c,
                    (mesh_in, fname, reoriented, read),
                    index,
                    options,
                    t0,
                )?;
                let cage = original_cage(&c);
                carry = Some(c);
                (report, cage)
            }
            Some(c) => {
                let frame = read_frame(input, &mut warn_all)?;
                let report = fit_frame(c, frame, index, options, t0)?;
                (report, original_cage(c))
            }
        };
        let c = carry.as_ref().expect("set above");
        on_frame(SequenceFrame {
            cage: &cage,
            tags: &c.tags,
            scheme: c.scheme,
            report: &report,
        })?;
        positions.push(cage.positions);
        reports.push(report);
    }
    let Some(c) = carry else {
        return Err(Error::Options("a sequence needs at least one frame".into()));
    };
    let later: Vec<f64> = reports.iter().skip(1).map(|r| r.timings_s.total).collect();
    let report = SequenceReport {
        frames_fitted: reports.len(),
        control_points: c.template.len(),
        control_faces: c.faces.len(),
        scheme: format!("{:?}", c.scheme),
        template: template_name,
        template_report,
        options: SequenceOptionsSummary {
            method: format!("{:?}", options.fit.method).to_uppercase(),
            lambda: options.lambda,
            arap: options.arap,
            iterations: options.iterations,
            tolerance_rms: options.tolerance_rms,
            silhouette_views: options.silhouette.views,
            silhouette_resolution: options.silhouette.resolution,
            silhouette_weight: options.silhouette.weight,
            sample_level: options.fit.sample_level,
        },
        worst_rms_fraction_of_diagonal: reports
            .iter()
            .map(|r| r.two_sided.e_rms_fraction_of_diagonal)
            .fold(0.0, f64::max),
        worst_max_fraction_of_diagonal: reports
            .iter()
            .map(|r| r.two_sided.e_max_fraction_of_diagonal)
            .fold(0.0, f64::max),
        mean_seconds_per_frame: if later.is_empty() {
            0.0
        } else {
            later.iter().sum::<f64>() / later.len() as f64
        },
        frames: reports,
        warnings,
    };
    Ok(Sequence {
        faces: c.faces,
        tags: c.tags,
        scheme: c.scheme,
        boundary: options.fit.boundary,
        positions,
        report,
    })
}

impl Carry {
    fn new(
        normalization: Normalization,
        faces: Polygons,
        tags: Tags,
        scheme: Scheme,
        template: Vec<[f64; 3]>,
        fit: &FitOptions,
        tracking: Option<&TrackingOptions>,
    ) -> Result<Self, String> {
        let opts = fit.clone().with_scheme(scheme).subdivision();
        let op = sampling_operator(&faces, template.len(), &tags, &opts, 0)
            .map_err(|e| e.to_string())?;
        let previous = template.clone();
        let template = Arc::new(template);
        let tracking = match tracking {
            None => None,
            Some(t) => {
                let op = sampling_operator(&faces, template.len(), &tags, &opts, t.level)
                    .map_err(|e| e.to_string())?;
                Some(Tracking::new(Arc::clone(&template), op, t, &normalization))
            }
        };
        let template_edges = edges(&faces)
            .into_iter()
            .map(|(a, b)| {
                (
                    a,
                    b,
                    dist2(template[a as usize], template[b as usize]).sqrt(),
                )
            })
            .collect();
        Ok(Self {
            normalization,
            faces,
            tags,
            scheme,
            previous,
            template,
            limit: LimitStencils {
                position: op.position,
                tangent1: op.tangent1,
                tangent2: op.tangent2,
            },
            previous_limit: None,
            template_edges,
            template_rms: 0.0,
            tracking,
        })
    }

    /// Drift diagnostics of `cage` (normalized units) against the previous frame's limit
    /// points and the template's edges, as fractions of `diagonal` (normalized units).
    fn drift(&mut self, cage: &[[f64; 3]], diagonal: f64) -> DriftDiagnostics {
        let limit = self.limit.position.apply(cage);
        let t1 = self.limit.tangent1.apply(cage);
        let t2 = self.limit.tangent2.apply(cage);
        let strain = {
            let s: f64 = self
                .template_edges
                .iter()
                .map(|&(a, b, l0)| {
                    let l = dist2(cage[a as usize], cage[b as usize]).sqrt();
                    ((l - l0) / l0.max(1e-300)).powi(2)
                })
                .sum();
            (s / self.template_edges.len().max(1) as f64).sqrt()
        };
        let mut d = DriftDiagnostics {
            edge_strain_rms: strain,
            ..DriftDiagnostics::default()
        };
        if let Some(prev) = &self.previous_limit {
            let (mut all, mut normal) = (0.0, 0.0);
            for i in 0..limit.len() {
                let m = sub(limit[i], prev[i]);
                let n = cross(t1[i], t2[i]);
                let nn = dot(n, n).sqrt();
                let along = if nn > 0.0 { dot(m, n) / nn } else { 0.0 };
                all += dot(m, m);
                normal += along * along;
            }
            let k = limit.len().max(1) as f64;
            d.motion_rms = (all / k).sqrt() / diagonal;
            d.normal_motion_rms = (normal / k).sqrt() / diagonal;
            d.tangential_motion_rms = ((all - normal).max(0.0) / k).sqrt() / diagonal;
        }
        self.previous_limit = Some(limit);
        d
    }
}

/// The template: the first frame fitted with [`fit_scan`].
fn template_frame(
    input: Input,
    options: &SequenceOptions,
    warn: &mut dyn FnMut(String),
) -> Result<(Carry, FrameReport, crate::Report), Error> {
    let t0 = Instant::now();
    let mut o = options.template_fit.clone();
    o.init = options.template.clone();
    o.fit.boundary = options.fit.boundary;
    o.cancel = options.cancel.clone();
    let mut forward = |p: crate::Progress<'_>| {
        if let crate::Progress::Warning(m) = p {
            warn(m.to_string());
        }
    };
    let fitted = fit_scan(input, &o, Some(&mut forward))?;
    let target = fitted.target();
    let mut carry = Carry::new(
        *target.normalization(),
        fitted.normalized_cage().faces.clone(),
        fitted.tags.clone(),
        fitted.scheme,
        fitted.normalized_cage().positions.clone(),
        &options.fit,
        options.tracking.as_ref(),
    )
    .map_err(|e| Error::input(&fitted.report.target, e))?;
    let r = &fitted.report;
    carry.template_rms = r.r#final.two_sided.e_rms;
    let diagonal = r.bbox_diagonal_unit_cube;
    if let (Some(tr), Some(o)) = (carry.tracking.as_mut(), options.tracking.as_ref()) {
        tr.settle(&fitted.normalized_cage().positions, target, o);
    }
    let drift = carry.drift(&fitted.normalized_cage().positions, diagonal);
    let report = FrameReport {
        index: 0,
        name: r.target.clone(),
        points: r.target_points,
        mesh: target.mesh().is_some(),
        reoriented: r.reoriented.clone(),
        bbox_diagonal: diagonal * r.normalized_unit_in_original_units,
        two_sided: r.r#final.two_sided,
        tolerance_reached: r.tolerance_reached_two_sided,
        iterations: r.iterations.len(),
        silhouette_loss: None,
        drift,
        tracking: None,
        timings_s: FrameTimings {
            read: r.timings_s.read,
            analyse: r.timings_s.preprocess,
            silhouette: 0.0,
            track: 0.0,
            fit: r.timings_s.fit + r.timings_s.init,
            total: t0.elapsed().as_secs_f64(),
        },
    };
    Ok((carry, report, fitted.report))
}

type ReadFrame = (PolyMesh, String, Option<Reorientation>, f64);

fn read_frame(input: Input, warn: &mut dyn FnMut(String)) -> Result<ReadFrame, Error> {
    let t = Instant::now();
    let crate::repair::ReadInput {
        mesh,
        name,
        reoriented,
        ..
    } = read_input(input, false, warn)?;
    Ok((mesh, name, reoriented, t.elapsed().as_secs_f64()))
}

/// Fits the carried cage to one frame, updating the carry.
fn fit_frame(
    carry: &mut Carry,
    (mesh, name, reoriented, read): ReadFrame,
    index: usize,
    options: &SequenceOptions,
    t0: Instant,
) -> Result<FrameReport, Error> {
    let t = Instant::now();
    let target_options = TargetOptions {
        normalization: Some(carry.normalization),
        cancel: options.cancel.clone(),
        ..TargetOptions::default()
    };
    let target =
        Target::build(&mesh, &target_options, None).map_err(|e| Error::target(&name, e))?;
    let analyse = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let silhouette = silhouette_term(&target, &options.silhouette);
    let silhouette_time = t.elapsed().as_secs_f64();
    let mut positions = carry.previous.clone();
    let t_track = Instant::now();
    let mut tracking = None;
    if let (Some(tr), Some(o)) = (carry.tracking.as_mut(), options.tracking.as_ref()) {
        let (moved, report) = tr.step(&target, index, o);
        positions = moved;
        tracking = Some(report);
    }
    let track_time = t_track.elapsed().as_secs_f64();
    // ARAP keeps the template's local shape as the tracking carried it onto this frame: the
    // template itself would pull the cage back from the frame's true strains (a bend stretches
    // one side by a quarter) and so along the surface (measured when it did: drift 3.4 % after
    // the tracking step, 6.0 % after the fit, `subfit bench sequence --vertices 8000
    // --control-points 500`).
    let rest = (options.arap > 0.0).then(|| {
        if tracking.is_some() {
            Arc::new(positions.clone())
        } else {
            Arc::clone(&carry.template)
        }
    });
    let fit = FitOptions {
        scheme: carry.scheme,
        tags: carry.tags.clone(),
        arap: options.arap,
        arap_rest: rest,

        surface_term: silhouette.clone(),
        cancel: options.cancel.clone(),
        ..options.fit.clone()
    };
    let t = Instant::now();
    let fit_err = |e: subfit_fit::FitError| match e {
        subfit_fit::FitError::Interrupted => Error::Interrupted,
        e => Error::Fit {
            name: name.clone(),
            source: e,
        },
    };
    let term = AnyTerm::from_options(&target, &fit);
    let mut fitter =
        Fitter::with_term(term, &carry.faces, carry.previous.len(), &fit).map_err(fit_err)?;
    let schedule = arap_schedule(options);
    let mut iterations = 0;
    for (k, &(alpha, iters)) in schedule.iter().enumerate() {
        let last = k + 1 == schedule.len();
        fitter.set_arap(alpha);
        let tolerance = if last {
            frame_tolerance(options, carry)
        } else {
            0.0
        };
        fitter.set_stage(options.lambda, iters, tolerance, 0.0, 1e-4);
        let r = fitter.run(&mut positions, None).map_err(fit_err)?;
        iterations += r.iterations.len();
    }
    let data = data_samples(&target, options.data_samples);
    let (two, _, _) = fitter.measure_two_sided(&positions, &data);
    let fit_time = t.elapsed().as_secs_f64();
    let unit = carry.normalization.length_to_original(1.0);
    let diagonal = subfit_fit::DataTerm::bbox_diagonal(&subfit_fit::FootPointTerm::from_options(
        &target, &fit,
    ));
    let two = &two;
    let silhouette_loss = silhouette.as_ref().map(|s| {
        let op = sampling_operator(
            &carry.faces,
            positions.len(),
            &carry.tags,
            &fit.subdivision(),
            s.level,
        );
        op.map_or(f64::NAN, |op| {
            s.term.value(
                &op.position.apply(&positions),
                &subfit_fit::fan_triangles(&op.faces),
            )
        })
    });
    if let (Some(tr), Some(o)) = (carry.tracking.as_mut(), options.tracking.as_ref()) {
        tr.settle(&positions, &target, o);
    }
    let drift = carry.drift(&positions, diagonal);
    carry.previous = positions;
    Ok(FrameReport {
        index,
        name,
        points: target.len(),
        mesh: target.mesh().is_some(),
        reoriented,
        bbox_diagonal: diagonal * unit,
        two_sided: TwoSidedErrors::new(two, diagonal, unit),
        tolerance_reached: two.within(options.tolerance_rms, 0.0),
        iterations,
        silhouette_loss,
        drift,
        tracking,
        timings_s: FrameTimings {
            read,
            analyse,
            silhouette: silhouette_time,
            track: track_time,
            fit: fit_time,
            total: t0.elapsed().as_secs_f64(),
        },
    })
}

/// The RMS at which a frame's fit stops (normalized units): [`SequenceOptions::tolerance_rms`],
/// or the template's own two-sided RMS on its frame times [`TEMPLATE_SLACK`] when that is
/// larger. The cage cannot fit a later frame better than it fitted the frame it was built
/// for; iterating on towards a tolerance the template itself missed spends every frame's
/// whole iteration cap for nothing. Measured on the low-poly cat (`subfit bench sequence
/// --meshes` over the first 12 frames of seq-cat-run, 1,500 control points, no silhouette):
/// 0.92 s a frame instead of 2.2 s, worst two-sided RMS 0.162 % against 0.166 % of the
/// diagonal, drift RMS 2.50 % against 2.36 %, p95 5.18 % against 5.35 % (slack 1.0: 0.160 %,
/// 2.38 %, 4.87 %, 1.5 s; 1.5: 0.174 %, 2.09 %, 4.15 %, 0.7 s). A template that met the
/// tolerance (the generated dance: 0.009 %) changes nothing.
fn frame_tolerance(options: &SequenceOptions, carry: &Carry) -> f64 {
    options
        .tolerance_rms
        .max(TEMPLATE_SLACK * carry.template_rms)
}

/// How much worse than the template's own fit (its two-sided RMS, a ratio) a frame's may be
/// before its fit stops (see [`frame_tolerance`]): room for what the tracking leaves.
const TEMPLATE_SLACK: f64 = 1.25;

/// `(α, iterations)` per level of the annealing of [`SequenceOptions::arap_start`].
fn arap_schedule(o: &SequenceOptions) -> Vec<(f64, usize)> {
    let mut alphas = vec![o.arap_start.max(o.arap)];
    while alphas.len() < 8 && *alphas.last().expect("one") > 10.0 * o.arap.max(1e-12) * 1.0001 {
        let next = alphas.last().expect("one") / 10.0;
        alphas.push(next.max(o.arap));
    }
    if *alphas.last().expect("one") != o.arap {
        alphas.push(o.arap);
    }
    let k = alphas.len().min(o.iterations.max(1));
    let alphas = &alphas[alphas.len() - k..];
    let per = o.iterations / k;
    alphas
        .iter()
        .enumerate()
        .map(|(i, &a)| {
            (
                a,
                if i + 1 == k {
                    o.iterations - per * (k - 1)
                } else {
                    per
                },
            )
        })
        .collect()
}

/// The silhouette term of a frame: its target images from K views around its bounding sphere
/// (the frame's triangles, or its points splatted as balls of the point spacing).
fn silhouette_term(target: &Target, o: &SilhouetteOptions) -> Option<WeightedSurfaceTerm> {
    use subfit_fit::silhouette::{cameras_around, Silhouette, SoftOptions};
    if o.views == 0 || o.weight == 0.0 {
        return None;
    }
    let (lo, hi) = subfit_mesh::bounding_box(target.points())?;
    let center: [f64; 3] = std::array::from_fn(|a| 0.5 * (lo[a] + hi[a]));
    let radius = 0.5 * dist2(lo, hi).sqrt();
    let cameras = cameras_around(center, radius, o.views, o.resolution);
    let soft = SoftOptions::default();
    let silhouette = match target.mesh() {
        Some(bvh) => Silhouette::from_mesh(cameras, bvh.vertices(), bvh.triangles(), soft),
        None => Silhouette::from_points(
            cameras,
            target.points(),
            target.stats().point_spacing.max(1e-9),
            soft,
        ),
    };
    Some(WeightedSurfaceTerm {
        term: Arc::new(silhouette),
        weight: o.weight,
        level: o.level,
    })
}

/// The carried cage in the input's coordinates.
fn original_cage(c: &Carry) -> PolyMesh {
    PolyMesh::new(
        c.previous
            .iter()
            .map(|&p| c.normalization.to_original(p))
            .collect(),
        c.faces.clone(),
    )
}

fn validate(o: &SequenceOptions) -> Result<(), Error> {
    let bad = |m: String| Err(Error::Options(m));
    if !(o.lambda.is_finite() && o.lambda >= 0.0) {
        return bad(format!(
            "--lambda must be a finite number ≥ 0, got {}",
            o.lambda
        ));
    }
    if !(o.arap.is_finite() && o.arap >= 0.0) {
        return bad(format!(
            "--arap must be a finite number ≥ 0, got {}",
            o.arap
        ));
    }
    if o.iterations == 0 {
        return bad("--iterations must be at least 1".into());
    }
    if !(o.tolerance_rms.is_finite() && o.tolerance_rms >= 0.0 && o.tolerance_rms < 1.0) {
        return bad(format!(
            "--tolerance must be in [0, 1) (unit-cube units), got {}",
            o.tolerance_rms
        ));
    }
    let s = &o.silhouette;
    if s.views > 0 && !(16..=1024).contains(&s.resolution) {
        return bad(format!(
            "--silhouette-resolution must be within 16..=1024 pixels, got {}",
            s.resolution
        ));
    }
    if !(s.weight.is_finite() && s.weight >= 0.0) {
        return bad(format!(
            "--silhouette-weight must be a finite number ≥ 0, got {}",
            s.weight
        ));
    }
    if o.fit.method == Method::Imls && o.fit.imls_radius.is_some_and(|h| !(h > 0.0 && h < 1.0)) {
        return bad("--imls-radius must be in (0, 1) (unit-cube units)".into());
    }
    if let Some(t) = &o.tracking {
        t.check().map_err(Error::Options)?;
    }
    Ok(())
}

/// Unique undirected edges of `faces`.
fn edges(faces: &Polygons) -> Vec<(u32, u32)> {
    let mut e: Vec<(u32, u32)> = faces
        .iter()
        .flat_map(|f| (0..f.len()).map(move |k| (f[k], f[(k + 1) % f.len()])))
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    e.sort_unstable();
    e.dedup();
    e
}
