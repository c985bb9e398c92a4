//! Sparse Cholesky solve of the (damped) normal equations with `faer` (DESIGN.md §3.3, §6):
//! the symbolic analysis (fill-reducing ordering, supernodal structure) is done once per
//! [`Pattern`] and reused by every numeric factorization.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::linalg::LltError;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{MatMut, Side};

use crate::assemble::Pattern;

/// Why a factorization failed.
#[derive(Clone, Debug, PartialEq)]
pub enum SolveFailure {
    /// The matrix is not numerically positive definite: pivot `index` (scalar unknown, in
    /// the permuted order of the factorization) was `≤ 0`.
    NotPositiveDefinite {
        /// Index of the failing pivot.
        index: usize,
    },
    /// Out of memory or another non-numerical failure in `faer`.
    Other(String),
}

/// A sparse `LLᵀ` solver that keeps the symbolic factorization of one [`Pattern`].
#[derive(Debug, Default)]
pub struct CholeskySolver {
    symbolic: Option<SymbolicLlt<usize>>,
}

impl CholeskySolver {
    /// A solver without analysis yet (done at the first [`Self::solve`]).
    pub fn new() -> Self {
        Self { symbolic: None }
    }

    /// Forgets the symbolic analysis (call when the pattern changes).
    pub fn reset(&mut self) {
        self.symbolic = None;
    }

    /// Factors `A` (upper triangle in `values`, pattern `pattern`) and solves `A X = B` in
    /// place. `rhs` is column-major `dim × nrhs`.
    ///
    /// Cost: one numeric supernodal Cholesky (the first call also the symbolic analysis) plus
    /// `nrhs` triangular solve pairs.
    ///
    /// # Panics
    /// If `values.len() != pattern.nnz()` or `rhs.len() != dim · nrhs`.
    #[track_caller]
    pub fn solve(
        &mut self,
        pattern: &Pattern,
        values: &[f64],
        rhs: &mut [f64],
        nrhs: usize,
    ) -> Result<(), SolveFailure> {
        let dim = pattern.dim();
        assert_eq!(rhs.len(), dim * nrhs, "rhs length");
        let sym = SymbolicSparseColMatRef::new_checked(
            dim,
            dim,
            pattern.col_ptr(),
            None,
            pattern.row_idx(),
        );
        let symbolic = match &self.symbolic {
            Some(s) => s.clone(),
            None => {
                let s = SymbolicLlt::try_new(sym, Side::Upper)
                    .map_err(|e| SolveFailure::Other(format!("{e:?}")))?;
                self.symbolic = Some(s.clone());
                s
            }
        };
        let mat = SparseColMatRef::new(sym, values);
        let llt = Llt::try_new_with_symbolic(symbolic, mat, Side::Upper).map_err(|e| match e {
            LltError::Numeric(
                faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index },
            ) => SolveFailure::NotPositiveDefinite { index },
            other => SolveFailure::Other(format!("{other:?}")),
        })?;
        let x = MatMut::from_column_major_slice_mut(rhs, dim, nrhs);
        llt.solve_in_place(x);
        Ok(())
    }
}
