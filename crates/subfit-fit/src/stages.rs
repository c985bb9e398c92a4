//! Multi-stage fitting (Cheng et al. 2007 §II-B step 8, §II-E, §II-F and Table IV; Cheng et
//! al. 2004 §4.4–4.6; DESIGN.md §3.5): a sequence of [`Fitter`] runs in which the smoothing
//! weight `λ` is lowered from stage to stage (default 1e-3 → 1e-5, ×0.1 per stage) and, when
//! a stage stalls above the tolerance, the control mesh is changed where the error is large:
//! edge flips that lower the error are kept, then the faces with large error are split 1-to-4
//! with red-green closure ([`crate::adapt`]). Stops at the tolerance (`E_rms`, and `E_max`
//! when asked), at the control-point budget, or when nothing more can be changed.
//!
//! Only triangle cages (Loop) are refined and flipped; a Catmull-Clark cage goes through the
//! `λ` schedule alone.

use std::time::{Duration, Instant};

use rayon::prelude::*;
use subfit_mesh::{PolyMesh, Polygons, Tags};
use subfit_subdiv::{sampling_operator, Options};
use subfit_target::Target;

use crate::adapt::{
    apply_flips, face_errors, independent_flips, refine_red_green_with_parents, FaceError,
    RefineStats,
};
use crate::error::FitError;
use crate::feet::FootPointSource;
use crate::fitter::Fitter;
use crate::options::FitOptions;
use crate::report::{ErrorStats, FitReport, IterationRow};

/// Options of the stage driver; the per-iteration options (method, step control, sample
/// level, scheme) come from a [`FitOptions`].
#[derive(Clone, Debug, PartialEq)]
pub struct StageOptions {
    /// `λ` of the first stage (the papers: 1e-3).
    pub lambda_start: f64,
    /// Smallest `λ` (the papers: 1e-4 to 1e-5).
    pub lambda_end: f64,
    /// Factor applied to `λ` after each stage, in (0, 1].
    pub lambda_factor: f64,
    /// Iterations of one stage at most.
    pub iterations_per_stage: usize,
    /// A stage ends when an accepted iteration lowers the objective by less than this
    /// fraction.
    pub stall: f64,
    /// Stop when `E_rms ≤` this (normalized units; 0 = not used).
    pub tolerance_rms: f64,
    /// Stop when `E_max ≤` this (normalized units; 0 = not used). With both tolerances set,
    /// both must hold.
    pub tolerance_max: f64,
    /// Never refine beyond this many control points.
    pub max_control_points: usize,
    /// Stages at most.
    pub max_stages: usize,
    /// Iterations over all stages at most.
    pub max_iterations: usize,
    /// Local 1-to-4 refinement of high-error faces between stages.
    pub refine: bool,
    /// At most this fraction of the current control points is added by one refinement.
    pub growth: f64,
    /// Edge flips in high-error regions, kept only where they lower the error.
    pub edge_flips: bool,
    /// A face that descends from this many splits of an initial face is not split again:
    /// where refinement does not lower the error (a foot point on the wrong side of a thin
    /// part, a sharp crease), it would otherwise only pile up control points.
    pub max_depth: u8,
    /// After a stage changed the mesh (refinement, flips), optimize only the control points
    /// near the change in the next stage — the new points, the points of every face touching
    /// one or changed by a flip, and `local_rings` rings of faces around them — holding the
    /// rest, which already fit, fixed (Cheng 2004 §4.6). Such a stage samples, projects and
    /// solves only that region ([`Fitter::set_active`]); its reported errors are still over
    /// the whole surface. A stage whose `λ` changed with nothing else, or whose region would
    /// hold more than half of the points, is global.
    pub local: bool,
    /// Rings of faces added around the changed region by [`Self::local`].
    pub local_rings: usize,
}

impl Default for StageOptions {
    fn default() -> Self {
        Self {
            lambda_start: 1e-3,
            lambda_end: 1e-5,
            lambda_factor: 0.1,
            iterations_per_stage: 6,
            stall: 0.02,
            tolerance_rms: 5e-4,
            tolerance_max: 0.0,
            max_control_points: 5_000,
            max_stages: 16,
            max_iterations: 100,
            refine: true,
            growth: 0.6,
            edge_flips: true,
            max_depth: 4,
            local: false,
            local_rings: 2,
        }
    }
}

impl StageOptions {
    fn validate(&self) -> Result<(), FitError> {
        let bad = |name: &'static str, value: f64| Err(FitError::BadOption { name, value });
        if !(self.lambda_start >= 0.0 && self.lambda_start.is_finite()) {
            return bad("lambda_start", self.lambda_start);
        }
        if !(self.lambda_end >= 0.0 && self.lambda_end <= self.lambda_start) {
            return bad("lambda_end", self.lambda_end);
        }
        if !(self.lambda_factor > 0.0 && self.lambda_factor <= 1.0) {
            return bad("lambda_factor", self.lambda_factor);
        }
        if !(self.stall >= 0.0 && self.stall < 1.0) {
            return bad("stall", self.stall);
        }
        if !(self.tolerance_rms >= 0.0 && self.tolerance_rms.is_finite()) {
            return bad("tolerance_rms", self.tolerance_rms);
        }
        if !(self.tolerance_max >= 0.0 && self.tolerance_max.is_finite()) {
            return bad("tolerance_max", self.tolerance_max);
        }
        if !(self.growth > 0.0 && self.growth.is_finite()) {
            return bad("growth", self.growth);
        }
        for (name, v) in [
            ("iterations_per_stage", self.iterations_per_stage),
            ("max_stages", self.max_stages),
            ("max_iterations", self.max_iterations),
        ] {
            if v == 0 {
                return bad(name, 0.0);
            }
        }
        Ok(())
    }

    /// Whether `e` meets every tolerance that is set (false when none is set).
    pub fn reached(&self, e: &ErrorStats) -> bool {
        let any = self.tolerance_rms > 0.0 || self.tolerance_max > 0.0;
        any && (self.tolerance_rms <= 0.0 || e.e_rms <= self.tolerance_rms)
            && (self.tolerance_max <= 0.0 || e.e_max <= self.tolerance_max)
    }
}

/// One stage: a fit at one `λ` and one control mesh, then the mesh changes made after it.
#[derive(Clone, Debug, PartialEq)]
pub struct StageReport {
    /// 0-based stage number.
    pub stage: usize,
    /// `λ` of this stage.
    pub lambda: f64,
    /// Control points during this stage's fit.
    pub num_control_points: usize,
    /// Control faces during this stage's fit.
    pub num_faces: usize,
    /// The iterations of this stage.
    pub fit: FitReport,
    /// Edge flips evaluated after the fit.
    pub flips_tried: usize,
    /// Edge flips kept (they lowered the error on their faces).
    pub flips_kept: usize,
    /// Local refinement after the fit, if any.
    pub refine: Option<RefineStats>,
    /// Control points optimized in this stage when it was local ([`StageOptions::local`]);
    /// `None`: all of them.
    pub active_points: Option<usize>,
    /// Wall time of the stage (fit, flips and refinement).
    pub time: Duration,
}

/// Marks the vertices of the faces a flip pass changed (flips keep face ids).
fn mark_flipped(seed: &mut [bool], before: &Polygons, after: &Polygons) {
    for (old, new) in before.iter().zip(after.iter()) {
        if old != new {
            for &v in new {
                seed[v as usize] = true;
            }
        }
    }
}

/// Extends `seed` (over the `old_n` points before a refinement) to the `new_n` points after it
/// and marks the vertices of every face touching a new point (index `≥ old_n`): the split
/// faces' corners, which a full split also moves to Loop vertex points.
fn mark_refined(seed: &mut Vec<bool>, old_n: usize, faces: &Polygons, new_n: usize) {
    seed.resize(new_n, false);
    for face in faces.iter() {
        if face.iter().any(|&v| v as usize >= old_n) {
            for &v in face {
                seed[v as usize] = true;
            }
        }
    }
}

/// `seed` grown by `rings` rings of faces; `None` when it holds more than half of the points
/// (then a global stage costs about the same and fits better).
fn local_region(faces: &Polygons, mut seed: Vec<bool>, rings: usize) -> Option<Vec<bool>> {
    for _ in 0..rings {
        let mut next = seed.clone();
        for face in faces.iter() {
            if face.iter().any(|&v| seed[v as usize]) {
                for &v in face {
                    next[v as usize] = true;
                }
            }
        }
        seed = next;
    }
    let count = seed.iter().filter(|&&x| x).count();
    (count > 0 && 2 * count <= seed.len()).then_some(seed)
}

/// Why the stage driver stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StageStop {
    /// Every tolerance set is met.
    Tolerance,
    /// The control-point budget is spent and `λ` is at its end value.
    Budget,
    /// Nothing left to change: `λ` at its end, no refinement possible or useful.
    Stalled,
    /// `max_stages` or `max_iterations` reached.
    Limit,
}

/// The log of [`fit_stages`].
#[derive(Clone, Debug, PartialEq)]
pub struct StagesReport {
    /// Errors of the initial control mesh (at the first stage's `λ`).
    pub initial: ErrorStats,
    /// Errors of the final control mesh.
    pub last: ErrorStats,
    /// One entry per stage.
    pub stages: Vec<StageReport>,
    /// Why it stopped.
    pub stop: StageStop,
    /// Total wall time.
    pub time: Duration,
}

impl StagesReport {
    /// Iterations over all stages.
    pub fn iterations(&self) -> usize {
        self.stages.iter().map(|s| s.fit.iterations.len()).sum()
    }
}

/// Result of [`fit_stages`].
#[derive(Clone, Debug)]
pub struct StagesResult {
    /// The fitted cage in the target's normalized units (new control points appended after
    /// the initial ones; the initial ids persist).
    pub mesh: PolyMesh,
    /// The log.
    pub report: StagesReport,
}

/// A progress event of [`fit_stages`].
#[derive(Clone, Copy, Debug)]
pub enum StageEvent<'a> {
    /// An iteration of stage `stage` ended.
    Iteration {
        /// 0-based stage.
        stage: usize,
        /// The iteration's row.
        row: &'a IterationRow,
    },
    /// A stage ended (after its mesh changes).
    Stage(&'a StageReport),
}

/// Fits `mesh` (control points in the target's normalized units; no creases) to `target` in
/// stages. `base` gives the scheme, method, step control and sample level; its `λ`,
/// tolerances and iteration limits are replaced by those of `stages`.
///
/// Errors: those of [`Fitter::new`] and [`Fitter::run`]; invalid stage options.
/// Cost: per stage, one [`Fitter`] setup (sampling operator, symbolic analysis) and its
/// iterations; flips cost one more sampling operator and projection.
pub fn fit_stages(
    target: &Target,
    mesh: &PolyMesh,
    base: &FitOptions,
    stages: &StageOptions,
    mut progress: Option<&mut dyn FnMut(StageEvent<'_>)>,
) -> Result<StagesResult, FitError> {
    stages.validate()?;
    let t0 = Instant::now();
    let mut mesh = PolyMesh::new(mesh.positions.clone(), mesh.faces.clone());
    let tags = Tags::new();
    let mut lambda = stages.lambda_start;
    // Refinement depth of every face (0 for the initial faces).
    let mut depth = vec![0u8; mesh.faces.len()];
    let mut reports: Vec<StageReport> = Vec::new();
    let mut initial = None;
    let mut stop = StageStop::Limit;
    let mut used = 0;
    // Vertices the last change touched, for a local stage.
    let mut touched: Option<Vec<bool>> = None;
    for stage in 0..stages.max_stages {
        if used >= stages.max_iterations {
            break;
        }
        let ts = Instant::now();
        let opts = FitOptions {
            lambda,
            max_iterations: stages
                .iterations_per_stage
                .min(stages.max_iterations - used),
            tolerance_rms: stages.tolerance_rms,
            tolerance_max: stages.tolerance_max,
            min_relative_decrease: stages.stall,
            ..base.clone()
        };
        let n = mesh.num_vertices();
        let mut fitter = Fitter::new(target, &mesh.faces, n, &tags, &opts)?;
        let active = touched
            .take()
            .and_then(|seed| local_region(&mesh.faces, seed, stages.local_rings));
        let active_points = active.as_ref().map(|a| a.iter().filter(|&&x| x).count());
        if active.is_some() {
            fitter.set_active(active)?;
        }
        let fit = {
            let mut cb = |row: &IterationRow| {
                if let Some(p) = progress.as_mut() {
                    p(StageEvent::Iteration { stage, row });
                }
            };
            fitter.run(&mut mesh.positions, Some(&mut cb))?
        };
        initial.get_or_insert(fit.initial);
        used += fit.iterations.len().max(1);
        let last = fit.last();
        let mut report = StageReport {
            stage,
            lambda,
            num_control_points: n,
            num_faces: mesh.faces.len(),
            fit,
            flips_tried: 0,
            flips_kept: 0,
            refine: None,
            active_points,
            time: Duration::ZERO,
        };
        let next_lambda = (lambda * stages.lambda_factor).max(stages.lambda_end);
        let mut changed = next_lambda < lambda;
        if stages.reached(&last) {
            stop = StageStop::Tolerance;
        } else if mesh.faces.is_triangles() && (stages.refine || stages.edge_flips) {
            let errors = sample_face_errors(target, &mesh, &fitter);
            drop(fitter);
            let mut seed = stages.local.then(|| vec![false; n]);
            let errors = if stages.edge_flips {
                let before = seed.is_some().then(|| mesh.faces.clone());
                let (tried, kept, errs) =
                    flip_pass(target, &mut mesh, errors, stages, base, &last)?;
                report.flips_tried = tried;
                report.flips_kept = kept;
                changed |= kept > 0;
                if let (Some(seed), Some(before)) = (seed.as_mut(), before) {
                    mark_flipped(seed, &before, &mesh.faces);
                }
                errs
            } else {
                errors
            };
            if stages.refine && n < stages.max_control_points {
                if let Some((refined, rs, d)) = refine_step(&mesh, &errors, &depth, stages, &last) {
                    changed |= rs.new_points > 0;
                    mesh = refined;
                    depth = d;
                    report.refine = Some(rs);
                }
            }
            if let Some(mut seed) = seed {
                mark_refined(&mut seed, n, &mesh.faces, mesh.num_vertices());
                touched = seed.contains(&true).then_some(seed);
            }
        }
        report.time = ts.elapsed();
        if let Some(p) = progress.as_mut() {
            p(StageEvent::Stage(&report));
        }
        reports.push(report);
        if stop == StageStop::Tolerance {
            break;
        }
        if !changed {
            stop = if mesh.num_vertices() >= stages.max_control_points {
                StageStop::Budget
            } else {
                StageStop::Stalled
            };
            break;
        }
        lambda = next_lambda;
    }
    // The last stage may have changed the mesh after its fit: report the errors of what is
    // returned.
    let last = if reports
        .last()
        .is_some_and(|r| r.refine.is_some_and(|x| x.new_points > 0) || r.flips_kept > 0)
    {
        let opts = FitOptions {
            lambda,
            ..base.clone()
        };
        Fitter::new(target, &mesh.faces, mesh.num_vertices(), &tags, &opts)?
            .evaluate(&mesh.positions)
    } else {
        reports.last().map(|r| r.fit.last()).unwrap_or_default()
    };
    Ok(StagesResult {
        mesh,
        report: StagesReport {
            initial: initial.unwrap_or_default(),
            last,
            stages: reports,
            stop,
            time: t0.elapsed(),
        },
    })
}

/// Squared sample errors with fresh foot points, gathered per control face.
fn sample_face_errors(target: &Target, mesh: &PolyMesh, fitter: &Fitter<'_>) -> Vec<FaceError> {
    let op = fitter.sampling_operator();
    let samples = op.position.apply(&mesh.positions);
    let err2 = squared_errors(target, fitter.options().foot_points, &samples);
    face_errors(&mesh.faces, op, &err2)
}

fn squared_errors(target: &Target, source: FootPointSource, samples: &[[f64; 3]]) -> Vec<f64> {
    let feet = crate::feet::foot_points(target, source, samples);
    samples
        .par_iter()
        .zip(feet.par_iter())
        .map(|(s, f)| (0..3).map(|a| (s[a] - f.point[a]).powi(2)).sum())
        .collect()
}

/// How far above the tolerance a face is (`> 1`: too large), counting only the tolerances the
/// whole surface does not meet yet: once `E_rms` is within its tolerance, a face whose own RMS
/// is above it needs no refinement for it (the budget goes where `E_max` is still missed).
fn face_score(e: &FaceError, stages: &StageOptions, last: &ErrorStats) -> f64 {
    let rms_unmet = stages.tolerance_rms > 0.0 && last.e_rms > stages.tolerance_rms;
    let max_unmet = stages.tolerance_max > 0.0 && last.e_max > stages.tolerance_max;
    let mut s: f64 = 0.0;
    if rms_unmet {
        s = s.max(e.rms() / stages.tolerance_rms);
    }
    if max_unmet {
        s = s.max(e.max / stages.tolerance_max);
    }
    if stages.tolerance_rms <= 0.0 && stages.tolerance_max <= 0.0 {
        // No tolerance: refine where the error is above the current RMS.
        s = e.rms() / last.e_rms.max(f64::MIN_POSITIVE);
    }
    s
}

/// Tries independent edge flips on faces scoring above the tolerance with the current
/// control points (no re-fit): a flip is kept when the squared error summed over the faces
/// whose limit it changes goes down. Returns (tried, kept, per-face errors of the result).
fn flip_pass(
    target: &Target,
    mesh: &mut PolyMesh,
    errors: Vec<FaceError>,
    stages: &StageOptions,
    base: &FitOptions,
    last: &ErrorStats,
) -> Result<(usize, usize, Vec<FaceError>), FitError> {
    let score: Vec<f64> = errors.iter().map(|e| face_score(e, stages, last)).collect();
    let flips = independent_flips(&mesh.faces, mesh.num_vertices(), &score, 1.0);
    if flips.is_empty() {
        return Ok((0, 0, errors));
    }
    let flipped = apply_flips(&mesh.faces, &flips);
    let op = sampling_operator(
        &flipped,
        mesh.num_vertices(),
        &Tags::new(),
        &Options::new(base.scheme),
        base.sample_level,
    )?;
    let samples = op.position.apply(&mesh.positions);
    let new_errors = face_errors(
        &flipped,
        &op,
        &squared_errors(target, base.foot_points, &samples),
    );
    // Faces incident to each vertex of the old mesh (the same faces are incident to a, b, c,
    // d in both meshes).
    let mut vf: Vec<Vec<u32>> = vec![Vec::new(); mesh.num_vertices()];
    for (f, face) in mesh.faces.iter().enumerate() {
        for &v in face {
            vf[v as usize].push(f as u32);
        }
    }
    let mut kept = Vec::new();
    let mut result = errors.clone();
    for fl in &flips {
        let mut region: Vec<u32> = [fl.a, fl.b, fl.c, fl.d]
            .iter()
            .flat_map(|&v| vf[v as usize].iter().copied())
            .collect();
        region.sort_unstable();
        region.dedup();
        let before: f64 = region.iter().map(|&f| errors[f as usize].sum_sq).sum();
        let after: f64 = region.iter().map(|&f| new_errors[f as usize].sum_sq).sum();
        if after < before {
            kept.push(*fl);
            for &f in &region {
                result[f as usize] = new_errors[f as usize];
            }
        }
    }
    if !kept.is_empty() {
        mesh.faces = apply_flips(&mesh.faces, &kept);
    }
    Ok((flips.len(), kept.len(), result))
}

/// Marks the faces above the tolerance, worst first, within the growth and control-point
/// budget and the refinement depth, and refines them with red-green closure. Returns the new
/// mesh, what was done, and the depth of every new face.
fn refine_step(
    mesh: &PolyMesh,
    errors: &[FaceError],
    depth: &[u8],
    stages: &StageOptions,
    last: &ErrorStats,
) -> Option<(PolyMesh, RefineStats, Vec<u8>)> {
    let n = mesh.num_vertices();
    let room = stages.max_control_points.saturating_sub(n);
    let allowed = room.min(((n as f64) * stages.growth).ceil() as usize);
    if allowed == 0 {
        return None;
    }
    let mut order: Vec<(f64, usize)> = errors
        .iter()
        .enumerate()
        .filter(|&(f, _)| depth[f] < stages.max_depth)
        .map(|(f, e)| (face_score(e, stages, last), f))
        .filter(|(s, _)| *s > 1.0)
        .collect();
    order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    if order.is_empty() {
        return None;
    }
    // A split face adds about 1.5 points (3 edges, each shared by two faces), plus closure.
    let mut take = order
        .len()
        .min((allowed as f64 / 1.5).ceil() as usize)
        .max(1);
    loop {
        let mut marked = vec![false; mesh.faces.len()];
        for &(_, f) in &order[..take] {
            marked[f] = true;
        }
        let (refined, rs, parents) = refine_red_green_with_parents(mesh, &marked)?;
        if refined.num_vertices() <= n + allowed || take == 1 {
            if refined.num_vertices() > stages.max_control_points {
                return None;
            }
            // An unsplit face (its parent's only child) keeps its depth; children of a split
            // face (red or green) are one deeper.
            let mut children = vec![0u32; mesh.faces.len()];
            for &p in &parents {
                children[p as usize] += 1;
            }
            let d = parents
                .iter()
                .map(|&p| {
                    let dp = depth[p as usize];
                    if children[p as usize] > 1 {
                        dp.saturating_add(1)
                    } else {
                        dp
                    }
                })
                .collect();
            return Some((refined, rs, d));
        }
        take = (take * 3 / 4).max(1);
    }
}
