//! The fitting loop (Cheng et al. 2007, §II-B steps 4–7 and §III-C; DESIGN.md §1, §3.3–3.4):
//! sample `S = C·P`, project the samples through the data term ([`DataTerm`]), assemble its
//! quadratic model, solve with the reused sparse Cholesky, then accept the step as it is, by
//! the LM gain ratio, or by Armijo backtracking — both judged on the true objective with fresh
//! projections.

use std::marker::PhantomData;
use std::time::{Duration, Instant};

use rayon::prelude::*;
use subfit_mesh::{PolyMesh, Polygons};
use subfit_subdiv::{sampling_operator, SamplingOperator};
use subfit_target::Target;

use crate::active::{sample_rows, ActiveSet, FixedErrors};
use crate::any_term::AnyTerm;
use crate::arap::ArapState;
use crate::assemble::{FillScratch, Pattern};
use crate::error::{FitError, FitPhase};
use crate::foot_point_term::FootPointTerm;
use crate::options::{FitOptions, Optimizer};
use crate::report::{ErrorStats, FitReport, IterationRow, PhaseTimings, StopReason};
use crate::smooth::Laplacian;
use crate::solve::{CholeskySolver, NormalSolver};
use crate::surface_term::fan_triangles;
use crate::term::{DataTerm, Mat3};

mod first_order;
mod gauss_newton;

/// Samples and their projections of one set of control points (all samples, or with an
/// active set only the samples touching an active point; `stats` are always over all samples).
struct State<S> {
    samples: Vec<[f64; 3]>,
    projected: Vec<S>,
    stats: ErrorStats,
}

/// A state over all samples with the control points it was evaluated at.
type KeptState<S> = (Vec<[f64; 3]>, State<S>);

/// A reusable fitter for one data term and one control-mesh topology. Keeps the sampling
/// operator, the pattern of the normal matrix, the symbolic Cholesky factorization and all
/// buffers between iterations and between calls to [`Fitter::run`] (STYLE.md rule 3).
///
/// The data term `T` ([`DataTerm`]) is by default Cheng's foot-point term on a [`Target`]
/// ([`FootPointTerm`], built by [`Fitter::new`]); any other comes in through
/// [`Fitter::with_term`].
pub struct Fitter<'t, T: DataTerm = FootPointTerm<'t>> {
    term: T,
    options: FitOptions,
    op: SamplingOperator,
    pattern: Pattern,
    solver: CholeskySolver,
    values: Vec<f64>,
    hdiag: Vec<f64>,
    q: Vec<Mat3>,
    bbox_diagonal: f64,
    setup: Duration,
    /// The umbrella Laplacian over all control points.
    lap: Laplacian,
    /// The active set and its sub-problem ([`Self::set_active`]); `None`: all points active.
    active: Option<ActiveSet>,
    /// Partial sums of the fill, reused.
    scratch: FillScratch,
    /// The ARAP regularizer when [`FitOptions::arap`] `> 0` (rest shape: the first run's cage).
    arap: Option<ArapState>,
    /// The tessellation a [`FitOptions::surface_term`] sees (its own sampling operator at its
    /// level and the triangles of its faces).
    surface: Option<(SamplingOperator, Vec<[u32; 3]>)>,
    /// The state over all samples at the control points [`Self::run`] returned, with those
    /// points: a measurement or the next run at the same points reuses its projections
    /// instead of projecting the same samples again (Cheng 2007 §II-B: one projection per
    /// iteration).
    last: Option<KeptState<T::Sample>>,
    /// The target (or whatever the term borrows) outlives the fitter.
    _data: PhantomData<&'t ()>,
}

/// The solver the options call for with `n` unknown points of block size `block`.
fn make_solver(options: &FitOptions, n: usize, block: usize) -> NormalSolver {
    use crate::options::LinearSolver;
    let pcg = match options.linear_solver {
        LinearSolver::Auto => n >= options.pcg_min_points && block == 3,
        LinearSolver::Cholesky => false,
        LinearSolver::Pcg => true,
    };
    if pcg {
        NormalSolver::with_pcg(options.pcg_tolerance, options.pcg_max_iterations)
    } else {
        NormalSolver::with_ordering(options.fill_ordering)
    }
}

impl<'t> Fitter<'t> {
    /// Prepares fitting `faces` (over `num_vertices` control points, with the crease/corner
    /// tags and subdivision rules of `options`) to `target` with the foot-point term of
    /// `options` ([`FootPointTerm::from_options`]: [`FitOptions::method`],
    /// [`FitOptions::foot_points`]). See [`Self::with_term`].
    ///
    /// Errors: invalid options, invalid control topology (see [`subfit_subdiv::SubdivError`]).
    pub fn new(
        target: &'t Target,
        faces: &Polygons,
        num_vertices: usize,
        options: &FitOptions,
    ) -> Result<Self, FitError> {
        Self::with_term(
            FootPointTerm::from_options(target, options),
            faces,
            num_vertices,
            options,
        )
    }
}

impl<'t, T: DataTerm> Fitter<'t, T> {
    /// Prepares fitting `faces` (over `num_vertices` control points, with the crease/corner
    /// tags and subdivision rules of `options`) to the data term `term` (which is then the
    /// fitter's: a term with warm-start state keyed by sample row serves one fitter).
    /// Builds the sampling operator at `options.sample_level`, the umbrella Laplacian, the
    /// pattern of `H` (block size 1 when the term is isotropic, else 3) and its symbolic
    /// Cholesky analysis. The control points themselves are given to [`Self::run`], in the
    /// target's normalized coordinates. Options that configure a particular term
    /// ([`FitOptions::method`], [`FitOptions::foot_points`]) are not read here.
    ///
    /// Errors: invalid options, invalid control topology (see [`subfit_subdiv::SubdivError`]).
    /// Cost: dominated by the sampling operator and the pattern, O(m·s²) with `m` samples and
    /// `s` ≈ 12–15 control points per sample.
    pub fn with_term(
        mut term: T,
        faces: &Polygons,
        num_vertices: usize,
        options: &FitOptions,
    ) -> Result<Self, FitError> {
        let t0 = Instant::now();
        options
            .validate()
            .map_err(|(name, value)| FitError::BadOption { name, value })?;
        if num_vertices == 0 || faces.is_empty() {
            return Err(FitError::BadInput("no control points or no faces".into()));
        }
        let op = sampling_operator(
            faces,
            num_vertices,
            &options.tags,
            &options.subdivision(),
            options.sample_level,
        )?;
        term.prepare(&op);
        let surface = match &options.surface_term {
            None => None,
            Some(st) => {
                let sop = sampling_operator(
                    faces,
                    num_vertices,
                    &options.tags,
                    &options.subdivision(),
                    st.level,
                )?;
                let tris = fan_triangles(&sop.faces);
                Some((sop, tris))
            }
        };
        let lap = Laplacian::umbrella_tagged(faces, num_vertices, &options.tags);
        let block = if term.isotropic() { 1 } else { 3 };
        let pattern = Pattern::new(&op.position, &lap, block);
        let values = vec![0.0; pattern.nnz()];
        let bbox_diagonal = term.bbox_diagonal();
        let mut solver: CholeskySolver = make_solver(options, num_vertices, block);
        solver
            .analyse(&pattern)
            .map_err(|e| FitError::Solver(format!("symbolic analysis: {e:?}")))?;
        Ok(Self {
            term,
            options: options.clone(),
            pattern,
            solver,
            values,
            hdiag: Vec::new(),
            q: Vec::new(),
            bbox_diagonal,
            setup: t0.elapsed(),
            lap,
            active: None,
            scratch: FillScratch::default(),
            arap: (options.arap > 0.0).then(|| ArapState::Pending(faces.clone())),
            surface,
            op,
            last: None,
            _data: PhantomData,
        })
    }

    /// Restricts the optimization to the control points with `active[i] == true`; the others
    /// are held fixed by [`Self::run`] (their rows and columns are eliminated: the step solves
    /// `H_aa δ_a = −g_a`). `None` makes every point active again (the full problem, whose
    /// pattern and factorization were kept).
    ///
    /// Only the samples whose stencil touches an active point are sampled, projected and
    /// assembled during [`Self::run`], so an iteration costs in proportion to the active
    /// region. The other samples cannot move; their squared errors are measured once per
    /// run start at which the fixed points changed (the first run after this call, or after the
    /// caller moved a fixed point), and cached. So every [`ErrorStats`] reported by
    /// [`Self::run`] (initial, per iteration) is still over the whole surface, exact: fresh
    /// projections of the active samples plus the cached errors of the fixed ones, and
    /// the smoothing energy of all points. [`Self::evaluate`] always samples everything.
    ///
    /// Building an active set costs a pass over the sampling operator, the pattern of `H_aa`
    /// and its symbolic analysis (a new active set is a new pattern); setting the same mask
    /// again keeps all of it. The solver (Cholesky or PCG) is chosen by the options' rule for
    /// the number of active points.
    ///
    /// Errors: a mask whose length is not the control-point count, or with no active point;
    /// a failed symbolic analysis. On error the previous active set is kept.
    pub fn set_active(&mut self, active: Option<Vec<bool>>) -> Result<(), FitError> {
        let Some(mask) = active else {
            self.active = None;
            return Ok(());
        };
        let n = self.pattern.num_points();
        if mask.len() != n {
            return Err(FitError::BadInput(format!(
                "active mask has {} entries, the mesh has {n} control points",
                mask.len()
            )));
        }
        if !mask.contains(&true) {
            return Err(FitError::BadInput("no active control point".into()));
        }
        if self.active.as_ref().is_some_and(|a| a.mask == mask) {
            return Ok(());
        }
        let n_a = mask.iter().filter(|&&b| b).count();
        let block = self.pattern.block();
        let solver = make_solver(&self.options, n_a, block);
        let set = ActiveSet::new(mask, &self.op.position, &self.lap, block, solver)
            .map_err(FitError::Solver)?;
        self.active = Some(set);
        Ok(())
    }

    /// The active mask set by [`Self::set_active`] (`None`: all points active).
    pub fn active(&self) -> Option<&[bool]> {
        self.active.as_ref().map(|a| &a.mask[..])
    }

    /// Number of samples a [`Self::run`] iteration samples, projects and assembles: those
    /// touching an active point, or all `m` without an active set.
    pub fn num_active_samples(&self) -> usize {
        self.active
            .as_ref()
            .map_or(self.num_samples(), |a| a.samples.len())
    }

    /// The options in use.
    pub fn options(&self) -> &FitOptions {
        &self.options
    }

    /// Changes `λ` (e.g. between stages); the pattern and factorization are kept.
    pub fn set_lambda(&mut self, lambda: f64) {
        self.options.lambda = lambda;
    }

    /// Changes the ARAP weight `α` (e.g. annealed from stiff to loose, as non-rigid ICP does);
    /// the regularizer exists only when the fitter was built with `α > 0`
    /// ([`FitOptions::arap`]), so a fitter built without it ignores this.
    pub fn set_arap(&mut self, alpha: f64) {
        if self.arap.is_some() {
            self.options.arap = alpha.max(0.0);
        }
    }

    /// Both-way distances of `control` (normalized units): the squared errors of every sample
    /// from fresh projections of the data term (RMS and mean weighted by the area each sample
    /// stands for in the sample tessellation) and the distance of every point of `data` to
    /// that tessellation (the level-`l` limit points; within its chordal error of the limit
    /// surface; the RMS over the area samples, the maximum over the rim as well:
    /// [`subfit_measure::DistanceStats::of_samples`]). Also returns the per-sample squared
    /// errors and the data points' closest points, for per-face statistics. Cost: one projection of the samples, one BVH over the sample
    /// tessellation and one query per data point.
    pub fn measure_two_sided(
        &self,
        control: &[[f64; 3]],
        data: &subfit_measure::DataSamples,
    ) -> (
        subfit_measure::TwoSided,
        Vec<f64>,
        Vec<subfit_measure::PointToLimit>,
    ) {
        use subfit_measure::{DistanceStats, MeshDistance, TwoSided};
        let (samples, mut err2) = match self.last_at(control) {
            Some(st) => (st.samples.clone(), self.state_errors(st)),
            None => {
                let samples = self.op.position.apply(control);
                let err2 = self.squared_errors(&samples);
                (samples, err2)
            }
        };
        self.term.measured_errors(&samples, &mut err2);
        let to_surface = MeshDistance::new(&samples, &self.op.faces).distances(&data.points);
        let d: Vec<f64> = to_surface.iter().map(|p| p.distance).collect();
        let two = TwoSided {
            surface_to_data: DistanceStats::over_surface(
                &err2.iter().map(|x| x.max(0.0).sqrt()).collect::<Vec<_>>(),
                &samples,
                &self.op.faces,
            ),
            data_to_surface: DistanceStats::of_samples(&d, data.extremes()),
        };
        (two, err2, to_surface)
    }

    /// Sets what the next [`Self::run`] does, keeping everything built for the topology:
    /// `λ`, the iteration cap, the stopping tolerances (`E_rms`, `E_max`; 0 = off) and the
    /// stall threshold ([`FitOptions::min_relative_decrease`]).
    pub fn set_stage(
        &mut self,
        lambda: f64,
        max_iterations: usize,
        tolerance_rms: f64,
        tolerance_max: f64,
        stall: f64,
    ) {
        self.options.lambda = lambda;
        self.options.max_iterations = max_iterations;
        self.options.tolerance_rms = tolerance_rms;
        self.options.tolerance_max = tolerance_max;
        self.options.min_relative_decrease = stall;
    }

    /// The kept state over all samples ([`Self::last`]) when it was evaluated at `control`.
    fn last_at(&self, control: &[[f64; 3]]) -> Option<&State<T::Sample>> {
        self.last
            .as_ref()
            .filter(|(c, _)| c[..] == control[..])
            .map(|(_, st)| st)
    }

    /// The squared error of every sample of `st` ([`DataTerm::squared_error`]), in order.
    fn state_errors(&self, st: &State<T::Sample>) -> Vec<f64> {
        st.samples
            .par_iter()
            .zip(st.projected.par_iter())
            .map(|(&x, s)| self.term.squared_error(s, x))
            .collect()
    }

    /// Squared errors of `samples` (e.g. `C·P`, or any points) from fresh projections
    /// ([`DataTerm::squared_errors`]); the term's warm start is left alone.
    pub fn squared_errors(&self, samples: &[[f64; 3]]) -> Vec<f64> {
        self.term.squared_errors(samples)
    }

    /// The data term.
    pub fn term(&self) -> &T {
        &self.term
    }

    /// The sampling operator (`m × n` limit stencils at the sample level).
    pub fn sampling_operator(&self) -> &SamplingOperator {
        &self.op
    }

    /// Stored values of the normal matrix `H` (its pattern's nonzeros; with [`Self::factor_len`]
    /// a measure of fill-in).
    pub fn normal_matrix_nnz(&self) -> usize {
        self.pattern.nnz()
    }

    /// Stored values of the Cholesky factor (fill-in measure; `None` before the first solve).
    pub fn factor_len(&self) -> Option<usize> {
        self.solver.factor_len()
    }

    /// Iterations and residual of the last PCG solve (`None` with the Cholesky solver or before
    /// the first solve). With an active set, those of the active set's solver.
    pub fn last_pcg(&self) -> Option<crate::pcg::PcgStats> {
        match &self.active {
            Some(a) => a.solver.last_pcg(),
            None => self.solver.last_pcg(),
        }
    }

    /// Number of samples `m`.
    pub fn num_samples(&self) -> usize {
        self.op.position.nrows()
    }

    /// Errors of `control` (`n by 3`, normalized units) with fresh samples and projections.
    /// Cost: one `C·P` and one projection of the `m` samples.
    pub fn evaluate(&self, control: &[[f64; 3]]) -> ErrorStats {
        if let Some(st) = self.last_at(control) {
            return self.restat(control, st);
        }
        let mut t = PhaseTimings::default();
        self.full_state(control, &mut t).stats
    }

    /// The state at `control`: all samples, or with an active set the active samples (the
    /// stats adding the cached fixed ones, which must be valid for `control`).
    fn state(&self, control: &[[f64; 3]], t: &mut PhaseTimings) -> State<T::Sample> {
        let Some(a) = &self.active else {
            return self.full_state(control, t);
        };
        let t0 = Instant::now();
        let samples = sample_rows(&self.op.position, &a.samples, control);
        let t1 = Instant::now();
        let projected = self.term.project(Some(&a.samples), &samples);
        let t2 = Instant::now();
        // Active samples get no coverage (see `DataTerm::project`): objective = errors.
        let (_, sum, max) = sums_d2(&self.term, &samples, &projected);
        let (fs, fm) = a.fixed.as_ref().map_or((0.0, 0.0), |f| (f.sum, f.max));
        let surface = self.surface_value(control);
        let stats = self.stats(control, sum + fs + surface, sum + fs, max.max(fm));
        t.sample += t1 - t0;
        t.project += t2 - t1;
        t.evaluate += t2.elapsed();
        State {
            samples,
            projected,
            stats,
        }
    }

    /// Measures the fixed samples of the active set at `control` unless the cache holds.
    fn ensure_fixed(&mut self, control: &[[f64; 3]]) {
        let Some(a) = &self.active else { return };
        if a.fixed_valid(control) {
            return;
        }
        let xs = sample_rows(&self.op.position, &a.fixed_samples, control);
        let projected = self.term.project(Some(&a.fixed_samples), &xs);
        let (_, sum, max) = sums_d2(&self.term, &xs, &projected);
        if let Some(a) = &mut self.active {
            a.fixed = Some(FixedErrors {
                control: control.to_vec(),
                sum,
                max,
            });
        }
    }

    /// The statistics of the state `st` over all samples at `control`, at the current options
    /// (`λ`): the projections are kept, the sums are taken anew (O(m)).
    fn restat(&self, control: &[[f64; 3]], st: &State<T::Sample>) -> ErrorStats {
        let (objective, sum, max) = sums_d2(&self.term, &st.samples, &st.projected);
        let surface = self.surface_value(control);
        self.stats(control, objective + surface, sum, max)
    }

    /// The state at `control` over all samples.
    fn full_state(&self, control: &[[f64; 3]], t: &mut PhaseTimings) -> State<T::Sample> {
        let t0 = Instant::now();
        let samples = self.op.position.apply(control);
        let t1 = Instant::now();
        // Samples move little between calls: the term may warm-start from its last answers.
        let projected = self.term.project(None, &samples);
        let t2 = Instant::now();
        let (objective, sum, max) = sums_d2(&self.term, &samples, &projected);
        let surface = self.surface_value(control);
        let stats = self.stats(control, objective + surface, sum, max);
        t.sample += t1 - t0;
        t.project += t2 - t1;
        t.evaluate += t2.elapsed();
        State {
            samples,
            projected,
            stats,
        }
    }

    /// `m · w · value` of the [`FitOptions::surface_term`] at `control` (on its own
    /// tessellation), so that [`Self::stats`]' division by `m` leaves `w · value`; 0 without one.
    fn surface_value(&self, control: &[[f64; 3]]) -> f64 {
        let (Some(st), Some((sop, tris))) = (&self.options.surface_term, &self.surface) else {
            return 0.0;
        };
        let m = self.num_samples().max(1) as f64;
        m * st.weight * st.term.value(&sop.position.apply(control), tris)
    }

    /// Error statistics over all `m` samples from the sum of their objective shares, the sum
    /// and maximum of their squared distances, and the smoothing energy of `control`.
    fn stats(&self, control: &[[f64; 3]], objective: f64, sum: f64, max: f64) -> ErrorStats {
        let m = self.num_samples().max(1) as f64;
        let n = control.len().max(1) as f64;
        let e_rms = (sum / m).sqrt();
        let e_max = max.sqrt();
        let smooth = if self.options.lambda > 0.0 {
            self.options.lambda / n * self.lap.energy(control)
        } else {
            0.0
        };
        ErrorStats {
            e_max,
            e_rms,
            e_max_diag: e_max / self.bbox_diagonal,
            e_rms_diag: e_rms / self.bbox_diagonal,
            objective: objective / m + smooth + self.arap_objective(control),
        }
    }

    /// Fits: iterates on `control` (`n by 3`, normalized units; updated in place to the best
    /// accepted control points) until a stopping rule of the options fires. `progress`, when
    /// given, is called after each iteration.
    ///
    /// Errors: non-finite input or results, an indefinite system without LM damping.
    /// Cost per iteration: one fill of `H` (O(m·s²)), one numeric Cholesky, one projection of
    /// the `m` samples per trial.
    pub fn run(
        &mut self,
        control: &mut [[f64; 3]],
        progress: Option<&mut dyn FnMut(&IterationRow)>,
    ) -> Result<FitReport, FitError> {
        let n = self.pattern.num_points();
        if control.len() != n {
            return Err(FitError::BadInput(format!(
                "{} control points given, the mesh has {n}",
                control.len()
            )));
        }
        if control.iter().flatten().any(|x| !x.is_finite()) {
            return Err(FitError::NonFinite {
                iteration: 0,
                phase: FitPhase::Setup,
                what: "initial control points",
            });
        }
        let opts = self.options.clone();
        self.ensure_arap(control)?;
        self.ensure_fixed(control);
        // The last run's final state at these control points (a `λ` change keeps the cage
        // and the topology) is reused: its samples need no second projection.
        let kept = self.last.take().filter(|(c, _)| c[..] == control[..]);
        let cur = match kept {
            Some((_, mut st)) if self.active.is_none() => {
                st.stats = self.restat(control, &st);
                st
            }
            _ => self.state(control, &mut PhaseTimings::default()),
        };
        check_finite(cur.stats.objective, 0, FitPhase::Evaluate, "objective")?;
        let mut report = FitReport {
            method: opts.method,
            step: opts.step,
            num_control_points: n,
            num_samples: self.num_samples(),
            initial: cur.stats,
            iterations: Vec::new(),
            stop: StopReason::MaxIterations,
            setup: self.setup,
        };
        if self.reached(&cur.stats) {
            report.stop = StopReason::Tolerance;
            self.keep(control, cur);
            return Ok(report);
        }
        if opts.optimizer != Optimizer::GaussNewton {
            return self.run_first_order(control, report, progress);
        }
        self.run_gauss_newton(control, cur, report, progress, &opts)
    }

    /// Keeps `cur`, the state at `control`, for reuse ([`Self::last`]) when it is over all
    /// samples (not an active set's).
    fn keep(&mut self, control: &[[f64; 3]], cur: State<T::Sample>) {
        if self.active.is_none() {
            self.last = Some((control.to_vec(), cur));
        }
    }

    /// Builds the ARAP regularizer, if on and not built yet, with the rest shape of the options
    /// or else `control`. Errors: a rest shape of another size than the cage.
    fn ensure_arap(&mut self, control: &[[f64; 3]]) -> Result<(), FitError> {
        let n = control.len();
        if let Some(a) = &mut self.arap {
            match &self.options.arap_rest {
                Some(rest) if rest.len() == n => a.ensure(rest),
                Some(rest) => {
                    return Err(FitError::BadInput(format!(
                        "the ARAP rest shape has {} points, the mesh has {n} control points",
                        rest.len()
                    )))
                }
                None => a.ensure(control),
            };
        }
        Ok(())
    }

    /// Whether every tolerance that is set holds (false when none is set).
    fn reached(&self, s: &ErrorStats) -> bool {
        let (rms, max) = (self.options.tolerance_rms, self.options.tolerance_max);
        (rms > 0.0 || max > 0.0) && (rms <= 0.0 || s.e_rms <= rms) && (max <= 0.0 || s.e_max <= max)
    }

    /// `α/n · E_arap(control)` once the regularizer is built, else 0.
    fn arap_objective(&self, control: &[[f64; 3]]) -> f64 {
        match self.arap.as_ref().and_then(ArapState::ready) {
            Some(a) => self.options.arap / control.len().max(1) as f64 * a.energy(control),
            None => 0.0,
        }
    }
}

/// `(Σ_k objective share, Σ_k e_k², max_k e_k²)` of the samples `s` with their projections
/// `projected` ([`DataTerm::objective_error`], [`DataTerm::squared_error`]): in parallel,
/// summed serially in sample order (deterministic for any thread count).
fn sums_d2<T: DataTerm>(term: &T, s: &[[f64; 3]], projected: &[T::Sample]) -> (f64, f64, f64) {
    let d2: Vec<(f64, f64)> = s
        .par_iter()
        .zip(projected.par_iter())
        .map(|(&s, f)| (term.objective_error(f, s), term.squared_error(f, s)))
        .collect();
    let objective: f64 = d2.iter().map(|d| d.0).sum();
    let sum: f64 = d2.iter().map(|d| d.1).sum();
    let max = d2.iter().fold(0.0f64, |a, &b| a.max(b.1));
    (objective, sum, max)
}

fn check_finite(
    x: f64,
    iteration: usize,
    phase: FitPhase,
    what: &'static str,
) -> Result<(), FitError> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(FitError::NonFinite {
            iteration,
            phase,
            what,
        })
    }
}

/// Result of the one-shot [`fit`].
#[derive(Clone, Debug)]
pub struct FitResult {
    /// The fitted control points (`n by 3`, normalized units; map back with
    /// [`Target::to_original`]).
    pub control_points: Vec<[f64; 3]>,
    /// The iteration log.
    pub report: FitReport,
}

/// One-shot fit of `control_mesh` (positions in the target's normalized units; tags in `options`)
/// to `target` with `options`. See [`Fitter`] for reuse across calls and stages.
pub fn fit(
    target: &Target,
    control_mesh: &PolyMesh,
    options: &FitOptions,
) -> Result<FitResult, FitError> {
    let mut fitter = Fitter::with_term(
        AnyTerm::from_options(target, options),
        &control_mesh.faces,
        control_mesh.num_vertices(),
        options,
    )?;
    let mut control_points = control_mesh.positions.clone();
    let report = fitter.run(&mut control_points, None)?;
    Ok(FitResult {
        control_points,
        report,
    })
}
