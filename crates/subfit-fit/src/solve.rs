//! Sparse Cholesky solve of the (damped) normal equations with `faer` (DESIGN.md §3.3, §6):
//! the symbolic analysis (AMD fill-reducing ordering, supernodal structure) is done once per
//! [`Pattern`] and reused by every numeric factorization; the factor's value buffer and the
//! workspace are reused too.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltError as DenseLltError;
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, SymbolicCholesky};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{get_global_parallelism, Conj, MatMut, Side};

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

/// A sparse `LLᵀ` solver that keeps the symbolic factorization of one [`Pattern`], the factor's
/// values and the workspace between calls.
#[derive(Debug, Default)]
pub struct CholeskySolver {
    symbolic: Option<SymbolicCholesky<usize>>,
    factor: Vec<f64>,
}

impl CholeskySolver {
    /// A solver without analysis yet (done at the first [`Self::solve`]).
    pub fn new() -> Self {
        Self::default()
    }

    /// Forgets the symbolic analysis (call when the pattern changes).
    pub fn reset(&mut self) {
        self.symbolic = None;
        self.factor = Vec::new();
    }

    /// Number of stored values of the Cholesky factor (after the first solve), a measure of
    /// fill-in and of the factorization's memory (8 bytes each).
    pub fn factor_len(&self) -> Option<usize> {
        self.symbolic.as_ref().map(SymbolicCholesky::len_val)
    }

    /// The symbolic analysis (fill-reducing ordering, elimination tree, supernodes) of
    /// `pattern`, unless already done. Cost: roughly one numeric factorization or less.
    pub fn analyse(&mut self, pattern: &Pattern) -> Result<(), SolveFailure> {
        if self.symbolic.is_none() {
            let s = factorize_symbolic_cholesky(
                symbolic_ref(pattern),
                Side::Upper,
                Default::default(),
                Default::default(),
            )
            .map_err(|e| SolveFailure::Other(format!("{e:?}")))?;
            self.factor = vec![0.0; s.len_val()];
            self.symbolic = Some(s);
        }
        Ok(())
    }

    /// Factors `A` (upper triangle in `values`, pattern `pattern`) and solves `A X = B` in
    /// place. `rhs` is column-major `dim × nrhs`.
    ///
    /// Cost: one numeric supernodal Cholesky (the first call also the symbolic analysis) plus
    /// `nrhs` triangular solve pairs; parallel per `faer`'s global parallelism (rayon).
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
        self.analyse(pattern)?;
        let sym = symbolic_ref(pattern);
        let symbolic = self.symbolic.as_ref().expect("analysed above");
        let par = get_global_parallelism();
        let mat = SparseColMatRef::new(sym, values);
        let req = symbolic
            .factorize_numeric_llt_scratch::<f64>(par, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(nrhs, par));
        let mut buf = MemBuffer::try_new(req).map_err(|e| SolveFailure::Other(format!("{e:?}")))?;
        let stack = MemStack::new(&mut buf);
        let llt = symbolic
            .factorize_numeric_llt::<f64>(
                &mut self.factor,
                mat,
                Side::Upper,
                Default::default(),
                par,
                stack,
                Default::default(),
            )
            .map_err(|e| match e {
                DenseLltError::NonPositivePivot { index } => {
                    SolveFailure::NotPositiveDefinite { index }
                }
            })?;
        let x = MatMut::from_column_major_slice_mut(rhs, dim, nrhs);
        llt.solve_in_place_with_conj(Conj::No, x, par, MemStack::new(&mut buf));
        Ok(())
    }
}

/// The CSC pattern of `pattern` as a `faer` symbolic matrix.
fn symbolic_ref(pattern: &Pattern) -> SymbolicSparseColMatRef<'_, usize> {
    let dim = pattern.dim();
    SymbolicSparseColMatRef::new_checked(dim, dim, pattern.col_ptr(), None, pattern.row_idx())
}
