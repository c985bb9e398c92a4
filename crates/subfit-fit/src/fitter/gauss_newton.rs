//! The Gauss-Newton path of [`Fitter::run`] (Cheng et al. 2007, §II-B steps 4–7 and §III-C;
//! DESIGN.md §3.3–3.4): assemble the data term's quadratic model into `H` and `g`, solve the
//! damped normal equations with the reused sparse Cholesky, then accept the step as it is, by
//! the Levenberg–Marquardt gain ratio (Madsen, Nielsen & Tingleff 2004, §3.2) or by Armijo
//! backtracking — both judged on the true objective with fresh projections.

use std::time::Instant;

use rayon::prelude::*;

use super::{check_finite, Fitter, State};
use crate::arap::ArapState;
use crate::error::{FitError, FitPhase};
use crate::options::{FitOptions, StepControl};
use crate::report::{FitReport, IterationRow, PhaseTimings, StopReason};
use crate::solve::SolveFailure;
use crate::surface_term::control_gradient;
use crate::term::DataTerm;

/// LM damping beyond `μ > MU_MAX · max diag(H)` means no descent is possible.
const MU_MAX: f64 = 1e16;

/// What a step trial ends with: (accepted, the trial's state, step length, gain ratio).
type Trial<S> = (bool, State<S>, f64, f64);

/// A step solved by [`Fitter::damped_step`]: (`δ`, LM damping `μ` (0 without LM), the
/// diagonal shift `μ + ridge`, the largest diagonal entry of `H`).
type Damped = (Vec<[f64; 3]>, f64, f64, f64);

impl<T: DataTerm> Fitter<'_, T> {
    /// The Gauss-Newton iterations of [`Fitter::run`] from `cur`, the state at `control`,
    /// until a stopping rule of `opts` (the fitter's options) fires; `report` holds the
    /// initial errors and gets a row per iteration.
    pub(super) fn run_gauss_newton(
        &mut self,
        control: &mut [[f64; 3]],
        mut cur: State<T::Sample>,
        mut report: FitReport,
        mut progress: Option<&mut dyn FnMut(&IterationRow)>,
        opts: &FitOptions,
    ) -> Result<FitReport, FitError> {
        let mut lm = Damping {
            mu: f64::NAN,
            nu: 2.0,
        };
        let mut grad: Vec<[f64; 3]> = Vec::new();
        let mut stale = true;
        let mut trial_p = control.to_vec();
        for it in 1..=opts.max_iterations {
            opts.cancel.check()?;
            let mut t = PhaseTimings::default();
            if stale {
                let t0 = Instant::now();
                grad = self.assemble(control, &cur);
                t.assemble += t0.elapsed();
                stale = false;
            }
            let Some((delta, damping, shift, max_diag)) =
                self.damped_step(&grad, &mut lm, &mut t, it, opts)?
            else {
                continue;
            };
            // g·δ: the directional derivative of the model is 2 g·δ.
            let gd: f64 = grad
                .iter()
                .zip(&delta)
                .map(|(g, d)| g[0] * d[0] + g[1] * d[1] + g[2] * d[2])
                .sum();
            let dd: f64 = delta.iter().flatten().map(|x| x * x).sum();
            let f0 = cur.stats.objective;
            let dir = Direction {
                delta: &delta,
                gd,
                dd,
                shift,
            };
            let (accepted, trial, step_length, gain_ratio) =
                self.try_step(control, &dir, f0, &mut lm, &mut trial_p, &mut t, it)?;
            let trial_objective = trial.stats.objective;
            if accepted {
                control.copy_from_slice(&trial_p);
                cur = trial;
                stale = true;
            }
            let row = IterationRow {
                iteration: it,
                accepted,
                errors: cur.stats,
                trial_objective,
                damping,
                step_length,
                gain_ratio,
                timings: t,
            };
            report.iterations.push(row);
            if let Some(cb) = progress.as_mut() {
                cb(&row);
            }
            if self.reached(&cur.stats) {
                report.stop = StopReason::Tolerance;
                break;
            }
            if accepted && (f0 - trial_objective).abs() < opts.min_relative_decrease * f0 {
                report.stop = StopReason::Stalled;
                break;
            }
            let no_descent = match opts.step {
                StepControl::LevenbergMarquardt => !accepted && lm.mu > MU_MAX * max_diag,
                StepControl::Armijo => !accepted,
                StepControl::None => false,
            };
            if no_descent {
                report.stop = StopReason::NoDescent;
                break;
            }
        }
        self.keep(control, cur);
        Ok(report)
    }

    /// Solves the normal equations assembled last, `(H + (ridge + μ)·I) δ = −g`, with the LM
    /// damping `lm` (started at `lm_tau · max diag(H)`) when the step control is LM. `None`:
    /// the factorization failed and LM raised `μ` — iteration `it` is to be tried again.
    /// Errors: a failed factorization without LM damping (or with `μ` beyond [`MU_MAX`]), a
    /// non-finite solution.
    fn damped_step(
        &mut self,
        grad: &[[f64; 3]],
        lm: &mut Damping,
        t: &mut PhaseTimings,
        it: usize,
        opts: &FitOptions,
    ) -> Result<Option<Damped>, FitError> {
        let max_diag = self.hdiag.iter().fold(0.0f64, |a, &b| a.max(b));
        let mean_diag = self.hdiag.iter().sum::<f64>() / self.hdiag.len().max(1) as f64;
        let ridge = opts.ridge * mean_diag;
        if opts.step == StepControl::LevenbergMarquardt && lm.mu.is_nan() {
            lm.mu = opts.lm_tau * max_diag;
        }
        let damping = if opts.step == StepControl::LevenbergMarquardt {
            lm.mu
        } else {
            0.0
        };
        let shift = ridge + damping;
        let t0 = Instant::now();
        let delta = match self.solve_step(grad, shift) {
            Ok(d) => d,
            Err(SolveFailure::NotPositiveDefinite { index }) => {
                if opts.step == StepControl::LevenbergMarquardt && lm.mu < MU_MAX * max_diag {
                    lm.reject();
                    return Ok(None);
                }
                return Err(FitError::NotPositiveDefinite {
                    iteration: it,
                    phase: FitPhase::Solve,
                    pivot: index,
                    damping,
                    mean_diagonal: mean_diag,
                });
            }
            Err(SolveFailure::Other(s)) => return Err(FitError::Solver(s)),
        };
        t.solve += t0.elapsed();
        if delta.iter().flatten().any(|x| !x.is_finite()) {
            return Err(FitError::NonFinite {
                iteration: it,
                phase: FitPhase::Solve,
                what: "solution of the normal equations",
            });
        }
        Ok(Some((delta, damping, shift, max_diag)))
    }

    /// Evaluates trial control points along `dir` with fresh projections and decides, per the
    /// step control, whether to accept (Cheng 2007 §III-C). Returns (accepted, trial state,
    /// step length, gain ratio); the trial control points are left in `trial_p`.
    #[allow(clippy::too_many_arguments)]
    fn try_step(
        &self,
        control: &[[f64; 3]],
        dir: &Direction<'_>,
        f0: f64,
        lm: &mut Damping,
        trial_p: &mut [[f64; 3]],
        t: &mut PhaseTimings,
        it: usize,
    ) -> Result<Trial<T::Sample>, FitError> {
        let opts = &self.options;
        let mut step_length = 1.0;
        let mut backtracks = 0;
        loop {
            opts.cancel.check()?;
            match &self.active {
                None => {
                    for ((p, c), d) in trial_p.iter_mut().zip(control).zip(dir.delta) {
                        *p = std::array::from_fn(|a| c[a] + step_length * d[a]);
                    }
                }
                Some(set) => {
                    trial_p.copy_from_slice(control);
                    for (&i, d) in set.points.iter().zip(dir.delta) {
                        let (p, c) = (&mut trial_p[i as usize], control[i as usize]);
                        *p = std::array::from_fn(|a| c[a] + step_length * d[a]);
                    }
                }
            }
            let trial = self.state(trial_p, t);
            check_finite(trial.stats.objective, it, FitPhase::Evaluate, "objective")?;
            let f1 = trial.stats.objective;
            match opts.step {
                StepControl::None => return Ok((true, trial, step_length, f64::NAN)),
                StepControl::LevenbergMarquardt => {
                    // Model decrease with (H + sI)δ = −g: −(2gᵀδ + δᵀHδ) = −gᵀδ + s‖δ‖².
                    let predicted = -dir.gd + dir.shift * dir.dd;
                    let rho = (f0 - f1) / predicted;
                    let ok = predicted > 0.0 && rho > 0.0;
                    if ok {
                        lm.accept(rho);
                    } else {
                        lm.reject();
                    }
                    return Ok((ok, trial, step_length, rho));
                }
                StepControl::Armijo => {
                    // The directional derivative of F along δ is 2gᵀδ.
                    if f1 <= f0 + opts.armijo_c1 * step_length * 2.0 * dir.gd {
                        return Ok((true, trial, step_length, f64::NAN));
                    }
                    if backtracks >= opts.armijo_max_backtracks {
                        return Ok((false, trial, step_length, f64::NAN));
                    }
                    backtracks += 1;
                    step_length *= opts.armijo_beta;
                }
            }
        }
    }

    /// Fills `H` (values and its diagonal copy) at the current state; returns `g` — over the
    /// active points (`H_aa`, `g_a`) when an active set is in use.
    fn assemble(&mut self, control: &[[f64; 3]], cur: &State<T::Sample>) -> Vec<[f64; 3]> {
        let m = self.num_samples().max(1) as f64;
        let n = control.len().max(1) as f64;
        let (w_e, w_s) = (1.0 / m, self.options.lambda / n);
        let term = &self.term;
        let coupled = self.pattern.block() == 3;
        // Q_k and the weighted residuals r_k = Q_k (S_k − V_k) (isotropic: S_k − V_k) in one
        // pass.
        let r: Vec<[f64; 3]> = if coupled {
            self.q.resize(cur.projected.len(), [[0.0; 3]; 3]);
            self.q
                .par_iter_mut()
                .zip(cur.projected.par_iter())
                .zip(cur.samples.par_iter())
                .map(|((q, f), &s)| {
                    let (qk, rk) = term.model(f, s);
                    *q = qk;
                    rk
                })
                .collect()
        } else {
            cur.samples
                .par_iter()
                .zip(cur.projected.par_iter())
                .map(|(&s, f)| term.model(f, s).1)
                .collect()
        };
        let (mut g, pattern, values, points) = match &mut self.active {
            None => {
                let g = self.pattern.fill_with_gradient(
                    &self.op.position,
                    &self.q,
                    &r,
                    control,
                    w_e,
                    w_s,
                    &mut self.values,
                    &mut self.scratch,
                );
                (g, &self.pattern, &mut self.values, None)
            }
            Some(a) => {
                // The smoothing gradient needs the fixed points too: the fill's own is taken
                // at P_a = 0 (where it vanishes) and the true one added.
                let zero = vec![[0.0; 3]; a.points.len()];
                let mut g = a.pattern.fill_with_gradient(
                    &a.op,
                    &self.q,
                    &r,
                    &zero,
                    w_e,
                    w_s,
                    &mut a.values,
                    &mut self.scratch,
                );
                a.add_smoothing_gradient(&self.lap, control, w_s, &mut g);
                (g, &a.pattern, &mut a.values, Some(&a.points[..]))
            }
        };
        if let (Some(st), Some((sop, tris))) = (&self.options.surface_term, &self.surface) {
            // Half the gradient of w·value: ½ w Cₛᵀ ∇value, over the active points.
            let gp = control_gradient(st.term.as_ref(), sop, tris, control);
            let c = 0.5 * st.weight;
            match points {
                None => g.iter_mut().zip(&gp).for_each(|(g, p)| {
                    (0..3).for_each(|a| g[a] += c * p[a]);
                }),
                Some(pts) => g.iter_mut().zip(pts).for_each(|(g, &i)| {
                    (0..3).for_each(|a| g[a] += c * gp[i as usize][a]);
                }),
            }
        }
        if let Some(arap) = self.arap.as_ref().and_then(ArapState::ready) {
            let w = 2.0 * self.options.arap / n;
            if let Err((i, j)) = arap.add_to_system(control, w, pattern, values, &mut g, points) {
                panic!("ARAP pair ({i}, {j}) is missing from the pattern of H");
            }
        }
        self.hdiag = pattern.diag_slots().iter().map(|&s| values[s]).collect();
        g
    }

    /// Solves `(H + shift·I) δ = −g`.
    fn solve_step(&mut self, g: &[[f64; 3]], shift: f64) -> Result<Vec<[f64; 3]>, SolveFailure> {
        let (pattern, solver, values) = match &mut self.active {
            Some(a) => (&a.pattern, &mut a.solver, &mut a.values),
            None => (&self.pattern, &mut self.solver, &mut self.values),
        };
        for (&s, &h) in pattern.diag_slots().iter().zip(&self.hdiag) {
            values[s] = h + shift;
        }
        let n = g.len();
        let mut rhs = vec![0.0; 3 * n];
        let coupled = pattern.block() == 3;
        for (i, gi) in g.iter().enumerate() {
            for (a, &ga) in gi.iter().enumerate() {
                let idx = if coupled { 3 * i + a } else { a * n + i };
                rhs[idx] = -ga;
            }
        }
        let nrhs = if coupled { 1 } else { 3 };
        solver.solve(pattern, values, &mut rhs, nrhs)?;
        Ok((0..n)
            .map(|i| {
                std::array::from_fn(|a| {
                    if coupled {
                        rhs[3 * i + a]
                    } else {
                        rhs[a * n + i]
                    }
                })
            })
            .collect())
    }
}

/// A solved step `δ` with the quantities the step control needs.
struct Direction<'a> {
    /// `δ`, `n by 3`.
    delta: &'a [[f64; 3]],
    /// `gᵀδ` (half the directional derivative of the objective).
    gd: f64,
    /// `‖δ‖²`.
    dd: f64,
    /// Diagonal shift `μ + ridge` the step was solved with.
    shift: f64,
}

/// Levenberg–Marquardt damping state (Madsen, Nielsen & Tingleff 2004, §3.2).
struct Damping {
    mu: f64,
    nu: f64,
}

impl Damping {
    /// After an accepted step with gain ratio `rho > 0`.
    fn accept(&mut self, rho: f64) {
        self.mu *= (1.0f64 / 3.0).max(1.0 - (2.0 * rho - 1.0).powi(3));
        self.nu = 2.0;
    }

    /// After a rejected step (or a failed factorization).
    fn reject(&mut self) {
        self.mu *= self.nu;
        self.nu *= 2.0;
    }
}
