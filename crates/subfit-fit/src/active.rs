//! Active sets: fitting only some control points while the others stay fixed — the local
//! optimization of Cheng et al. 2004 §4.5: after a local subdivision, "if the fitting error in
//! most other regions are already acceptable, only the newly added points and their
//! neighboring vertices are treated as variables and optimized".
//!
//! With the control points split into active `a` and fixed `f`, the model's minimizer over
//! `δ_a` with `δ_f = 0` solves `H_aa δ_a = −g_a` (the fixed variables eliminated:
//! `A_aa x_a = b_a − A_af x_f` written for the step). A sample `k` whose stencil `c_k` has no
//! active column neither moves nor contributes to `H_aa` or `g_a`, so only the samples that
//! touch an active point are sampled, projected and assembled; the others' squared distances
//! are measured once and cached (they cannot change while their control points are fixed).
//! The smoothing block is `(LᵀL)_aa = Σ_r L_raᵀ L_ra` over the rows `r` of `L` that touch an
//! active point, restricted to the active columns.

use rayon::prelude::*;
use subfit_subdiv::StencilMatrix;

use crate::assemble::{transpose_rows, Pattern};
use crate::smooth::Laplacian;
use crate::solve::NormalSolver;

/// The sub-problem over the active control points, built once per active set.
#[derive(Debug)]
pub(crate) struct ActiveSet {
    /// Per control point, whether it is active (`n`).
    pub mask: Vec<bool>,
    /// Active control points, increasing (`n_a`); local index = position here.
    pub points: Vec<u32>,
    /// Samples whose stencil touches an active point, increasing (`m_a`).
    pub samples: Vec<u32>,
    /// The other samples (fixed while the active set is).
    pub fixed_samples: Vec<u32>,
    /// Rows `samples` of the sampling operator restricted to the active columns, with local
    /// column indices (`m_a × n_a`).
    pub op: StencilMatrix,
    /// Rows of `L` that touch an active point (`r_a`), as indices into `L`.
    pub lap_rows: Vec<u32>,
    /// `(L restricted)ᵀ`: per active point, `(local row, L_rj)` (`n_a` rows over `r_a`).
    pub lap_t: Laplacian,
    /// Pattern of `H_aa`.
    pub pattern: Pattern,
    /// Solver of `H_aa` (its own symbolic analysis).
    pub solver: NormalSolver,
    /// Values of `H_aa`.
    pub values: Vec<f64>,
    /// Cached errors of the fixed samples.
    pub fixed: Option<FixedErrors>,
}

/// Squared distances of the fixed samples, valid while the fixed control points keep the
/// values they had when it was measured.
#[derive(Clone, Debug)]
pub(crate) struct FixedErrors {
    /// The control points it was measured at (`n`; only the inactive ones matter).
    pub control: Vec<[f64; 3]>,
    /// `Σ_k d_k²` over the fixed samples (in increasing sample order).
    pub sum: f64,
    /// `max_k d_k²` over the fixed samples.
    pub max: f64,
}

impl ActiveSet {
    /// Builds the sub-problem of `mask` (`n`, at least one `true`) for the sampling operator
    /// `position` (`m × n`) and the Laplacian `lap` (`n × n`), with block size `block`.
    /// `solver` is analysed for the new pattern. Cost: O(nnz(C) + nnz(L)) plus the pattern and
    /// the symbolic analysis of `H_aa`.
    pub fn new(
        mask: Vec<bool>,
        position: &StencilMatrix,
        lap: &Laplacian,
        block: usize,
        mut solver: NormalSolver,
    ) -> Result<Self, String> {
        let n = mask.len();
        let mut local = vec![u32::MAX; n];
        let mut points = Vec::new();
        for (j, &act) in mask.iter().enumerate() {
            if act {
                local[j] = points.len() as u32;
                points.push(j as u32);
            }
        }
        let (mut samples, mut fixed_samples) = (Vec::new(), Vec::new());
        let mut offsets = vec![0usize];
        let (mut indices, mut weights) = (Vec::new(), Vec::new());
        for k in 0..position.nrows() {
            let (idx, w) = position.row(k);
            let before = indices.len();
            for (&j, &w) in idx.iter().zip(w) {
                if mask[j as usize] {
                    indices.push(local[j as usize]);
                    weights.push(w);
                }
            }
            if indices.len() > before {
                samples.push(k as u32);
                offsets.push(indices.len());
            } else {
                fixed_samples.push(k as u32);
            }
        }
        let op = StencilMatrix::from_raw(points.len(), offsets, indices, weights)
            .ok_or("active sampling operator: broken CSR invariants")?;

        let mut lap_rows = Vec::new();
        let mut sub = Laplacian {
            offsets: vec![0],
            indices: Vec::new(),
            weights: Vec::new(),
        };
        for r in 0..lap.len() {
            let (idx, w) = lap.row(r);
            let before = sub.indices.len();
            for (&j, &w) in idx.iter().zip(w) {
                if mask[j as usize] {
                    sub.indices.push(local[j as usize]);
                    sub.weights.push(w);
                }
            }
            if sub.indices.len() > before {
                lap_rows.push(r as u32);
                sub.offsets.push(sub.indices.len());
            }
        }
        let lap_t = transpose_rows(&sub, points.len());
        let pattern = Pattern::with_smoothing_rows(&op, &sub, block);
        solver
            .analyse(&pattern)
            .map_err(|e| format!("symbolic analysis of the active set: {e:?}"))?;
        let values = vec![0.0; pattern.nnz()];
        Ok(Self {
            mask,
            points,
            samples,
            fixed_samples,
            op,
            lap_rows,
            lap_t,
            pattern,
            solver,
            values,
            fixed: None,
        })
    }

    /// Whether the cached fixed errors hold for `control` (`n by 3`): every inactive point
    /// is bitwise the one they were measured at.
    pub fn fixed_valid(&self, control: &[[f64; 3]]) -> bool {
        self.fixed.as_ref().is_some_and(|f| {
            f.control.len() == control.len()
                && self
                    .mask
                    .iter()
                    .zip(f.control.iter().zip(control))
                    .all(|(&act, (c0, c))| act || c0.map(f64::to_bits) == c.map(f64::to_bits))
        })
    }

    /// The smoothing half-gradient over the active points, `w_s (Lᵀ L P)_a` (`n_a by 3`),
    /// added to `g`. `control` is the full `n by 3`. Cost: O(nnz of the rows of `L` touching
    /// the active points).
    pub fn add_smoothing_gradient(
        &self,
        lap: &Laplacian,
        control: &[[f64; 3]],
        w_s: f64,
        g: &mut [[f64; 3]],
    ) {
        if w_s == 0.0 {
            return;
        }
        let lp: Vec<[f64; 3]> = self
            .lap_rows
            .iter()
            .map(|&r| {
                let (idx, w) = lap.row(r as usize);
                let mut s = [0.0; 3];
                for (&j, &w) in idx.iter().zip(w) {
                    for a in 0..3 {
                        s[a] += w * control[j as usize][a];
                    }
                }
                s
            })
            .collect();
        g.par_iter_mut().enumerate().for_each(|(j, gj)| {
            let (rs, l) = self.lap_t.row(j);
            for (&r, &l) in rs.iter().zip(l) {
                for a in 0..3 {
                    gj[a] += w_s * l * lp[r as usize][a];
                }
            }
        });
    }
}

/// Positions `S_k = Σ_i c_ki P_i` of the samples `rows` of `position` (`rows.len() by 3`).
/// Cost: O(Σ row lengths), parallel.
pub(crate) fn sample_rows(
    position: &StencilMatrix,
    rows: &[u32],
    control: &[[f64; 3]],
) -> Vec<[f64; 3]> {
    rows.par_iter()
        .with_min_len(4096)
        .map(|&k| {
            let (idx, w) = position.row(k as usize);
            let mut s = [0.0; 3];
            for (&j, &w) in idx.iter().zip(w) {
                for a in 0..3 {
                    s[a] += w * control[j as usize][a];
                }
            }
            s
        })
        .collect()
}
