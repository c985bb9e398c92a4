//! Solve of the (damped) normal equations (DESIGN.md §3.3, §6): a sparse Cholesky with `faer`
//! — the symbolic analysis (fill-reducing ordering on the block graph, see [`crate::ordering`];
//! supernodal structure) done once per [`Pattern`] and reused by every numeric factorization,
//! the factor's value buffer and the workspace reused too — or, for large systems,
//! preconditioned conjugate gradients ([`crate::pcg`]).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltError as DenseLltError;
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{get_global_parallelism, Conj, MatMut, Side};

use crate::assemble::Pattern;
use crate::ordering::{block_amd, expand, inverse, nested_dissection, BlockGraph, FillOrdering};
use crate::pcg::{PcgFailure, PcgSolver, PcgStats};

/// Nested dissection stops splitting parts of at most this many control points.
const ND_LEAF: usize = 64;

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

/// The name the fitter uses for `NormalSolver` (a sparse Cholesky unless built with
/// `NormalSolver::with_pcg`).
pub type CholeskySolver = NormalSolver;

/// A solver of the normal equations for one [`Pattern`]: a sparse `LLᵀ` factorization that keeps
/// the symbolic analysis, the factor's values and the workspace between calls, or (built with
/// [`Self::with_pcg`]) block-Jacobi PCG that keeps its block-CSR index.
#[derive(Debug, Default)]
pub struct NormalSolver {
    symbolic: Option<SymbolicCholesky<usize>>,
    factor: Vec<f64>,
    ordering: FillOrdering,
    pcg: Option<PcgMode>,
}

/// Settings and state of the PCG path.
#[derive(Debug)]
struct PcgMode {
    tol: f64,
    max_iter: usize,
    solver: Option<PcgSolver>,
    last: Option<PcgStats>,
}

impl NormalSolver {
    /// A Cholesky solver without analysis yet (done at the first [`Self::solve`]), with the
    /// default [`FillOrdering`].
    pub fn new() -> Self {
        Self::default()
    }

    /// A PCG solver stopping each solve at relative residual `tol` or after `max_iter`
    /// iterations (see [`PcgSolver::solve`]).
    pub fn with_pcg(tol: f64, max_iter: usize) -> Self {
        Self {
            pcg: Some(PcgMode {
                tol,
                max_iter,
                solver: None,
                last: None,
            }),
            ..Self::default()
        }
    }

    /// True for the PCG path.
    pub fn is_pcg(&self) -> bool {
        self.pcg.is_some()
    }

    /// Iterations and residual of the last PCG solve (`None` for Cholesky or before a solve).
    pub fn last_pcg(&self) -> Option<PcgStats> {
        self.pcg.as_ref().and_then(|p| p.last)
    }

    /// A solver that will analyse with `ordering`.
    pub fn with_ordering(ordering: FillOrdering) -> Self {
        Self {
            ordering,
            ..Self::default()
        }
    }

    /// Whether the analysis chose `faer`'s supernodal (blocked) factorization rather than the
    /// simplicial one (`None` before the analysis).
    pub fn is_supernodal(&self) -> Option<bool> {
        self.symbolic
            .as_ref()
            .map(|s| matches!(s.raw(), SymbolicCholeskyRaw::Supernodal(_)))
    }

    /// Forgets the symbolic analysis / PCG index (call when the pattern changes).
    pub fn reset(&mut self) {
        self.symbolic = None;
        self.factor = Vec::new();
        if let Some(p) = &mut self.pcg {
            p.solver = None;
            p.last = None;
        }
    }

    /// Number of stored values of the Cholesky factor (after the first solve), a measure of
    /// fill-in and of the factorization's memory (8 bytes each).
    pub fn factor_len(&self) -> Option<usize> {
        self.symbolic.as_ref().map(SymbolicCholesky::len_val)
    }

    /// The symbolic analysis (fill-reducing ordering, elimination tree, supernodes) of
    /// `pattern`, unless already done; for PCG, its block-CSR index. Cost: roughly one numeric
    /// factorization or less (PCG: O(nnz)).
    pub fn analyse(&mut self, pattern: &Pattern) -> Result<(), SolveFailure> {
        if let Some(p) = &mut self.pcg {
            if p.solver.is_none() {
                p.solver = Some(PcgSolver::new(pattern));
            }
            return Ok(());
        }
        if self.symbolic.is_none() {
            let order = match self.ordering {
                FillOrdering::ScalarAmd => None,
                FillOrdering::BlockAmd => Some(block_amd(pattern).map_err(SolveFailure::Other)?),
                FillOrdering::NestedDissection => Some(nested_dissection(
                    &BlockGraph::from_pattern(pattern),
                    ND_LEAF,
                )),
            };
            let fwd = order.map(|o| expand(&o, pattern.block()));
            let inv = fwd.as_deref().map(inverse);
            let ord = match (&fwd, &inv) {
                (Some(f), Some(i)) => {
                    SymmetricOrdering::Custom(PermRef::new_checked(f, i, pattern.dim()))
                }
                _ => SymmetricOrdering::Amd,
            };
            let s = factorize_symbolic_cholesky(
                symbolic_ref(pattern),
                Side::Upper,
                ord,
                Default::default(),
            )
            .map_err(|e| SolveFailure::Other(format!("{e:?}")))?;
            self.factor = vec![0.0; s.len_val()];
            self.symbolic = Some(s);
        }
        Ok(())
    }

    /// Factors `A` (upper triangle in `values`, pattern `pattern`) and solves `A X = B` in
    /// place (PCG: solves approximately, see [`PcgSolver::solve`]). `rhs` is column-major
    /// `dim × nrhs`.
    ///
    /// Cost: one numeric supernodal Cholesky (the first call also the symbolic analysis) plus
    /// `nrhs` triangular solve pairs; parallel per `faer`'s global parallelism (rayon). PCG:
    /// O(nnz) per iteration.
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
        if let Some(p) = &mut self.pcg {
            let solver = p.solver.as_mut().expect("analysed above");
            let stats = solver
                .solve(pattern, values, rhs, nrhs, p.tol, p.max_iter)
                .map_err(|PcgFailure::NotPositiveDefinite { index }| {
                    SolveFailure::NotPositiveDefinite { index }
                })?;
            p.last = Some(stats);
            return Ok(());
        }
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
