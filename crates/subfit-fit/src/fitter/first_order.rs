//! The first-order path: the fitter's objective `F(P)` with its gradient
//! `∇_P F = Cᵀ ∂F/∂S` (+ the smoothing, surface-term and ARAP parts), and the Adam and L-BFGS
//! drivers of [`Optimizer`]. Xie et al. 2023 (§3.1, §5.1) minimize their IMLS + ARAP energy
//! with Adam through a dense Jacobian on a GPU; here the gradient is one sparse product with
//! the sampling operator's transpose, on the CPU, for every data term (SDM, TDM, PDM, IMLS).
//!
//! The gradient is that of the objective the Gauss-Newton path decreases: per sample the
//! data term's model residual `r_k` at its current projection is half the gradient of the
//! sample's share (foot points and the coverage assignment are re-found at every
//! evaluation, so by the envelope argument their motion adds nothing to first order). ARAP
//! contributes `α/n · 4 (L P − b(R))` at the rotations `R` of `P` (Sorkine & Alexa 2007: the
//! local step's rotations minimize the energy, so the same argument holds). It is checked
//! against central differences of the objective in `tests/first_order.rs`.
//!
//! The first-order path is always over all samples (a stage's active set is ignored).

use argmin::core::{CostFunction, Executor, Gradient, State as _};
use argmin::solver::linesearch::MoreThuenteLineSearch;
use argmin::solver::quasinewton::LBFGS;
use rayon::prelude::*;
use std::sync::Mutex;
use std::time::Instant;

use super::{check_finite, Fitter, State};
use crate::error::{FitError, FitPhase};
use crate::options::{Optimizer, FIRST_ORDER_STEPS};
use crate::report::{FitReport, IterationRow, PhaseTimings, StopReason};
use crate::term::DataTerm;

/// Adam's decay rates and its ε (the moments are of gradients of order 1e-3..1 in normalized
/// units; ε only guards a zero second moment).
const BETA1: f64 = 0.9;
const BETA2: f64 = 0.999;
const EPSILON: f64 = 1e-12;

impl<T: DataTerm> Fitter<'_, T> {
    /// The objective `F` at `control` (as reported in [`crate::ErrorStats::objective`]) and its
    /// gradient with respect to the control points (`n by 3`), over all samples. The ARAP
    /// regularizer, if on and not yet built, is built as by [`Fitter::run`].
    ///
    /// Errors: a wrong number of control points or rest points, non-finite values.
    /// Cost: one projection of the samples, one product with `Cᵀ`, O(nnz(L)) for the
    /// smoothing, one 3×3 SVD per control point for ARAP.
    pub fn objective_and_gradient(
        &mut self,
        control: &[[f64; 3]],
    ) -> Result<(f64, Vec<[f64; 3]>), FitError> {
        if control.len() != self.pattern.num_points() {
            return Err(FitError::BadInput(format!(
                "{} control points given, the mesh has {}",
                control.len(),
                self.pattern.num_points()
            )));
        }
        self.ensure_arap(control)?;
        let state = self.full_state(control, &mut PhaseTimings::default());
        let g = self.gradient_at(control, &state);
        check_finite(state.stats.objective, 0, FitPhase::Evaluate, "objective")?;
        if g.iter().flatten().any(|x| !x.is_finite()) {
            return Err(FitError::NonFinite {
                iteration: 0,
                phase: FitPhase::Assemble,
                what: "gradient",
            });
        }
        Ok((state.stats.objective, g))
    }

    /// `∇F` at `control` from its full state.
    fn gradient_at(&self, control: &[[f64; 3]], state: &State<T::Sample>) -> Vec<[f64; 3]> {
        let m = self.num_samples().max(1) as f64;
        let n = control.len().max(1) as f64;
        let (w_e, w_s) = (1.0 / m, self.options.lambda / n);
        let term = &self.term;
        let r: Vec<[f64; 3]> = state
            .samples
            .par_iter()
            .zip(state.projected.par_iter())
            .map(|(&s, f)| term.model(f, s).1)
            .collect();
        // Half-gradients, doubled at the end.
        let mut g = self.pattern.gradient(&r, control, w_e, w_s);
        if let (Some(st), Some((sop, tris))) = (&self.options.surface_term, &self.surface) {
            let c = 0.5 * st.weight;
            let gp = crate::surface_term::control_gradient(st.term.as_ref(), sop, tris, control);
            for (g, p) in g.iter_mut().zip(&gp) {
                (0..3).for_each(|a| g[a] += c * p[a]);
            }
        }
        if let Some(arap) = self.arap.as_ref().and_then(|a| a.ready()) {
            let c = 0.5 * self.options.arap / n;
            let ga = arap.gradient(control, &arap.rotations(control));
            for (g, a) in g.iter_mut().zip(&ga) {
                for k in 0..3 {
                    g[k] += c * a[k];
                }
            }
        }
        for g in &mut g {
            for x in g.iter_mut() {
                *x *= 2.0;
            }
        }
        g
    }

    /// [`Fitter::run`] with a first-order optimizer, from the state `cur` of `control`:
    /// `max_iterations` rows of [`FIRST_ORDER_STEPS`] steps each; `control` ends at the best
    /// control points seen at a row's end.
    pub(super) fn run_first_order(
        &mut self,
        control: &mut [[f64; 3]],
        mut report: FitReport,
        mut progress: Option<&mut dyn FnMut(&IterationRow)>,
    ) -> Result<FitReport, FitError> {
        let opts = self.options.clone();
        let mut best = (report.initial.objective, control.to_vec());
        let mut last = report.initial.objective;
        let n = control.len();
        let (mut m1, mut m2) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
        let mut adam_t = 0i32;
        for it in 1..=opts.max_iterations {
            opts.cancel.check()?;
            let t0 = Instant::now();
            match opts.optimizer {
                Optimizer::Adam { learning_rate } => {
                    for _ in 0..FIRST_ORDER_STEPS {
                        let (_, g) = self.objective_and_gradient(control)?;
                        adam_t += 1;
                        let (c1, c2) = (1.0 - BETA1.powi(adam_t), 1.0 - BETA2.powi(adam_t));
                        for i in 0..n {
                            for a in 0..3 {
                                let gi = g[i][a];
                                m1[i][a] = BETA1 * m1[i][a] + (1.0 - BETA1) * gi;
                                m2[i][a] = BETA2 * m2[i][a] + (1.0 - BETA2) * gi * gi;
                                let step = (m1[i][a] / c1) / ((m2[i][a] / c2).sqrt() + EPSILON);
                                control[i][a] -= learning_rate * step;
                            }
                        }
                    }
                }
                Optimizer::Lbfgs { memory } => self.lbfgs_steps(control, memory)?,
                Optimizer::GaussNewton => unreachable!("the Gauss-Newton path is Fitter::run"),
            }
            let elapsed = t0.elapsed();
            let cur = self.full_state(control, &mut PhaseTimings::default());
            check_finite(cur.stats.objective, it, FitPhase::Evaluate, "objective")?;
            let f = cur.stats.objective;
            let row = IterationRow {
                iteration: it,
                accepted: f < last,
                errors: cur.stats,
                trial_objective: f,
                damping: 0.0,
                step_length: 1.0,
                gain_ratio: f64::NAN,
                timings: PhaseTimings {
                    solve: elapsed,
                    ..PhaseTimings::default()
                },
            };
            report.iterations.push(row);
            if let Some(cb) = progress.as_mut() {
                cb(&row);
            }
            if f < best.0 {
                best = (f, control.to_vec());
            }
            if self.reached(&cur.stats) {
                report.stop = StopReason::Tolerance;
                break;
            }
            if (last - f).abs() < opts.min_relative_decrease * last {
                report.stop = StopReason::Stalled;
                break;
            }
            last = f;
        }
        control.copy_from_slice(&best.1);
        Ok(report)
    }

    /// [`FIRST_ORDER_STEPS`] iterations of argmin's L-BFGS from `control`, which ends at
    /// argmin's best point.
    fn lbfgs_steps(&mut self, control: &mut [[f64; 3]], memory: usize) -> Result<(), FitError> {
        let problem = Problem {
            fitter: Mutex::new(self),
            cache: Mutex::new(None),
        };
        let solver: LBFGS<_, Vec<f64>, Vec<f64>, f64> =
            LBFGS::new(MoreThuenteLineSearch::new(), memory);
        let start: Vec<f64> = control.iter().flatten().copied().collect();
        let result = Executor::new(problem, solver)
            .configure(|s| s.param(start).max_iters(FIRST_ORDER_STEPS as u64))
            .run()
            .map_err(|e| FitError::Solver(format!("L-BFGS: {e}")))?;
        if let Some(p) = result.state().get_best_param() {
            for (c, x) in control.iter_mut().zip(p.chunks_exact(3)) {
                *c = [x[0], x[1], x[2]];
            }
        }
        Ok(())
    }
}

/// The fitter as argmin's problem; the last objective and gradient are cached, since argmin
/// asks for the cost and the gradient at the same point separately.
struct Problem<'a, 't, T: DataTerm> {
    fitter: Mutex<&'a mut Fitter<'t, T>>,
    cache: Mutex<Option<Evaluated>>,
}

/// A point (flattened control points), its objective and its gradient.
type Evaluated = (Vec<f64>, f64, Vec<f64>);

impl<T: DataTerm> Problem<'_, '_, T> {
    fn evaluate(&self, p: &[f64]) -> Result<(f64, Vec<f64>), argmin::core::Error> {
        let mut cache = self
            .cache
            .lock()
            .map_err(|_| FitError::Solver("poisoned".into()))?;
        if let Some((q, f, g)) = cache.as_ref() {
            if q.as_slice() == p {
                return Ok((*f, g.clone()));
            }
        }
        let control: Vec<[f64; 3]> = p.chunks_exact(3).map(|x| [x[0], x[1], x[2]]).collect();
        let mut fitter = self
            .fitter
            .lock()
            .map_err(|_| FitError::Solver("poisoned".into()))?;
        let (f, g) = fitter.objective_and_gradient(&control)?;
        let g: Vec<f64> = g.into_iter().flatten().collect();
        *cache = Some((p.to_vec(), f, g.clone()));
        Ok((f, g))
    }
}

impl<T: DataTerm> CostFunction for Problem<'_, '_, T> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, p: &Vec<f64>) -> Result<f64, argmin::core::Error> {
        Ok(self.evaluate(p)?.0)
    }
}

impl<T: DataTerm> Gradient for Problem<'_, '_, T> {
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;

    fn gradient(&self, p: &Vec<f64>) -> Result<Vec<f64>, argmin::core::Error> {
        Ok(self.evaluate(p)?.1)
    }
}
