//! Assembly of the normal equations of the quadratic model (Cheng et al. 2007, §II-B step 5–6,
//! §III-B; DESIGN.md §3.3, §6).
//!
//! With samples `S_k = Σ_i c_ki P_i` (rows of the sampling operator), frozen foot points `V_k`
//! and error matrices `Q_k` (a data term's model, [`crate::DataTerm`]), the model of eq. 2 is
//!
//! ```text
//! F_L(P) = 1/m Σ_k (S_k − V_k)ᵀ Q_k (S_k − V_k) + λ/n ‖L P‖²
//! ```
//!
//! whose Hessian is `2H` with `H = 1/m Σ_k (c_k c_kᵀ) ⊗ Q_k + λ/n · LᵀL ⊗ I3` and whose gradient
//! is `2g` with `g = 1/m Σ_k c_k ⊗ Q_k (S_k − V_k) + λ/n · (LᵀL ⊗ I3) P`. `H` is stored as the
//! upper triangle of a scalar CSC matrix (`3n × 3n`, or `n × n` for PD where `Q = I` and the
//! system separates into one scalar system with three right-hand sides).
//!
//! The [`Pattern`] (union of the `c_k c_kᵀ` and `LᵀL` patterns) is built once per control-mesh
//! topology; each iteration [`Pattern::fill`] writes values in place, so there is no triplet
//! re-assembly and nothing dense of size `n²`. With 3×3 blocks the samples are grouped by
//! shared support (`grouped_fill`: all samples of a control face share one), each group's dense
//! block is one small matrix product added once into per-chunk partial sums, and every block
//! entry then sums its parts in a fixed order — parallel, lock-free and bitwise identical for
//! any thread count. PD (and any operator whose supports are too wide to group) uses the
//! column-wise fill: each rayon task owns one block column's slice of the value array and
//! scatters through a per-thread index map.

use rayon::prelude::*;
use subfit_subdiv::StencilMatrix;

use crate::grouped_fill::Groups;
use crate::smooth::Laplacian;
use crate::term::{mul, Mat3};

/// Sparsity pattern of the normal matrix `H` (upper triangle, CSC) with the index structures
/// that let values be filled in place.
///
/// Storage: block column `j` lists its block rows `i ≤ j` in increasing order (the diagonal
/// block last). Scalar column `b·j + c` (`b` = block size, 3 or 1) stores, for each
/// off-diagonal block row `i`, the `b` rows `b·i .. b·i + b`, then the diagonal rows
/// `b·j ..= b·j + c`.
#[derive(Clone, Debug)]
pub struct Pattern {
    n: usize,
    block: usize,
    bcol_ptr: Vec<usize>,
    brow: Vec<u32>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    diag_slots: Vec<usize>,
    /// Transposed sampling operator: samples touching control point `j` with weight `c_kj`.
    samp_ptr: Vec<usize>,
    samp: Vec<SampleRef>,
    lap: Laplacian,
    lap_t: Laplacian,
    /// Samples grouped by shared support (block size 3; `None`: column-wise fill).
    groups: Option<Groups>,
    /// `(LᵀL)_ij` per block entry (block rows of every column), for the grouped fill.
    ltl: Vec<f64>,
}

impl Pattern {
    /// Builds the pattern for the sampling operator `position` (`m × n` limit stencils) and the
    /// smoothing operator `lap` (`n × n`), with block size `block` (3 for TD/SD, 1 for PD).
    ///
    /// Cost: O(Σ_k s_k² + nnz(LᵀL)) with `s_k` the row lengths, parallel over columns; memory
    /// O(nnz(C) + nnz(H)).
    ///
    /// # Panics
    /// If `block` is not 1 or 3, or the operator and Laplacian sizes differ.
    #[track_caller]
    pub fn new(position: &StencilMatrix, lap: &Laplacian, block: usize) -> Self {
        assert_eq!(
            lap.len(),
            position.ncols(),
            "Laplacian size differs from the control-point count"
        );
        Self::with_smoothing_rows(position, lap, block)
    }

    /// Like [`Self::new`] with a rectangular smoothing operator: `lap` holds any number of
    /// rows over the `n = position.ncols()` unknowns, and the smoothing block is
    /// `w_s · lapᵀ lap ⊗ I`. This is how a sub-problem over some of the control points is built
    /// (the rows of `L` that touch them, restricted to their columns; see
    /// [`crate::Fitter::set_active`]); [`Self::gradient`]'s smoothing part then needs `p`'s
    /// full context and is better added by the caller (pass `w_s = 0`).
    ///
    /// # Panics
    /// If `block` is not 1 or 3, or a column of `lap` is `≥ n`.
    #[track_caller]
    pub fn with_smoothing_rows(position: &StencilMatrix, lap: &Laplacian, block: usize) -> Self {
        assert!(block == 1 || block == 3, "block size must be 1 or 3");
        let n = position.ncols();
        assert!(
            lap.indices.iter().all(|&j| (j as usize) < n),
            "smoothing column out of range"
        );
        let (samp_ptr, samp) = transpose_operator(position);
        let lap_t = transpose_rows(lap, n);

        // Block rows of each block column (i ≤ j), in parallel with a per-thread marker.
        let cols: Vec<Vec<u32>> = (0..n)
            .into_par_iter()
            .map_init(
                || vec![u32::MAX; n],
                |mark, j| {
                    let mut rows = Vec::new();
                    let mut visit = |i: u32| {
                        if i as usize <= j && mark[i as usize] != j as u32 {
                            mark[i as usize] = j as u32;
                            rows.push(i);
                        }
                    };
                    for e in &samp[samp_ptr[j]..samp_ptr[j + 1]] {
                        position.row(e.k as usize).0.iter().for_each(|&i| visit(i));
                    }
                    let (rs, _) = lap_t.row(j);
                    for &r in rs {
                        lap.row(r as usize).0.iter().for_each(|&i| visit(i));
                    }
                    visit(j as u32);
                    rows.sort_unstable();
                    rows
                },
            )
            .collect();

        let mut bcol_ptr = Vec::with_capacity(n + 1);
        bcol_ptr.push(0);
        let mut brow = Vec::new();
        for c in &cols {
            brow.extend_from_slice(c);
            bcol_ptr.push(brow.len());
        }
        drop(cols);

        let b = block;
        let mut col_ptr = Vec::with_capacity(b * n + 1);
        let mut row_idx = Vec::new();
        let mut diag_slots = Vec::with_capacity(b * n);
        col_ptr.push(0);
        for j in 0..n {
            let rows = &brow[bcol_ptr[j]..bcol_ptr[j + 1]];
            let (off, _) = rows.split_at(rows.len() - 1);
            for c in 0..b {
                for &i in off {
                    for a in 0..b {
                        row_idx.push(b * i as usize + a);
                    }
                }
                for a in 0..=c {
                    row_idx.push(b * j + a);
                }
                diag_slots.push(row_idx.len() - 1);
                col_ptr.push(row_idx.len());
            }
        }
        let (groups, ltl) = if block == 3 {
            let groups = Groups::new(position, &bcol_ptr, &brow);
            let ltl = smoothing_blocks(lap, &lap_t, &bcol_ptr, &brow);
            (groups, ltl)
        } else {
            (None, Vec::new())
        };
        Self {
            n,
            block,
            bcol_ptr,
            brow,
            col_ptr,
            row_idx,
            diag_slots,
            samp_ptr,
            samp,
            lap: lap.clone(),
            lap_t,
            groups,
            ltl,
        }
    }

    /// Number of control points `n`.
    pub fn num_points(&self) -> usize {
        self.n
    }

    /// Block size (3: coupled coordinates; 1: PD, coordinates separate).
    pub fn block(&self) -> usize {
        self.block
    }

    /// Scalar dimension `b·n` of the system.
    pub fn dim(&self) -> usize {
        self.block * self.n
    }

    /// Number of stored scalar entries (upper triangle).
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// CSC column pointers (`dim + 1`).
    pub fn col_ptr(&self) -> &[usize] {
        &self.col_ptr
    }

    /// CSC row indices (`nnz`), sorted within each column, all `≤` the column.
    pub fn row_idx(&self) -> &[usize] {
        &self.row_idx
    }

    /// The value slot of each scalar diagonal entry (`dim`).
    pub fn diag_slots(&self) -> &[usize] {
        &self.diag_slots
    }

    /// Block rows `i ≤ j` of block column `j`, increasing, the diagonal `j` last.
    pub fn block_col(&self, j: usize) -> &[u32] {
        &self.brow[self.bcol_ptr[j]..self.bcol_ptr[j + 1]]
    }

    /// The smoothing operator the pattern was built with (`rows × n`; square for
    /// [`Self::new`]).
    pub fn laplacian(&self) -> &Laplacian {
        &self.lap
    }

    /// Writes `H = w_e Σ_k (c_k c_kᵀ) ⊗ Q_k + w_s LᵀL ⊗ I` into `values` (`nnz`), overwriting.
    /// For block size 1 the `Q_k` are ignored (taken as `I`; PD). Typically `w_e = 1/m`,
    /// `w_s = λ/n`. The `Q_k` must be symmetric: only their upper triangles are read.
    ///
    /// `position` must be the operator the pattern was built with (for block size 3 a
    /// different operator of another shape or nonzero count falls back to the column-wise
    /// fill; one of the same shape and count but other columns is not detected).
    ///
    /// Cost: O(Σ_groups 6·s²·K) for block size 3 (`K` samples sharing a support of `s` points)
    /// or O(Σ_k s_k² · b²) column-wise, parallel; allocates partial sums of about the size of
    /// the blocks of `H` (see [`Self::fill_with`] to reuse them).
    ///
    /// # Panics
    /// If `values.len() != nnz`, or (block 3) `q.len()` is not the sample count.
    #[track_caller]
    pub fn fill(
        &self,
        position: &StencilMatrix,
        q: &[Mat3],
        w_e: f64,
        w_s: f64,
        values: &mut [f64],
    ) {
        self.fill_with(position, q, w_e, w_s, values, &mut FillScratch::default());
    }

    /// [`Self::fill`] reusing `scratch` between calls (the fitter keeps one: with block size 3
    /// it holds partial sums of about the size of `H`'s blocks, which are not reallocated).
    ///
    /// # Panics
    /// As [`Self::fill`].
    #[track_caller]
    pub fn fill_with(
        &self,
        position: &StencilMatrix,
        q: &[Mat3],
        w_e: f64,
        w_s: f64,
        values: &mut [f64],
        scratch: &mut FillScratch,
    ) {
        self.fill_impl(position, q, w_e, w_s, values, scratch, None);
    }

    /// [`Self::fill_with`] and [`Self::gradient`]`(r, p, w_e, w_s)` in one pass over the
    /// samples where the fill groups them (block size 3), else one after the other. Returns
    /// the half-gradient `g` (`n by 3`).
    ///
    /// # Panics
    /// As [`Self::fill`] and [`Self::gradient`].
    #[allow(clippy::too_many_arguments)]
    #[track_caller]
    pub fn fill_with_gradient(
        &self,
        position: &StencilMatrix,
        q: &[Mat3],
        r: &[[f64; 3]],
        p: &[[f64; 3]],
        w_e: f64,
        w_s: f64,
        values: &mut [f64],
        scratch: &mut FillScratch,
    ) -> Vec<[f64; 3]> {
        assert_eq!(p.len(), self.n, "one control point per column");
        assert_eq!(r.len(), position.nrows(), "one residual per sample");
        if !self.fill_impl(position, q, w_e, w_s, values, scratch, Some(r)) {
            return self.gradient(r, p, w_e, w_s);
        }
        let Some(groups) = self.groups.as_ref() else {
            return self.gradient(r, p, w_e, w_s);
        };
        let vparts = &scratch.vparts[..];
        let lp = if w_s != 0.0 {
            self.lap.apply(p)
        } else {
            Vec::new()
        };
        (0..self.n)
            .into_par_iter()
            .map(|j| {
                let mut g = [0.0; 3];
                for &x in groups.vcontribs(j) {
                    for (g, v) in g.iter_mut().zip(&vparts[x as usize]) {
                        *g += v;
                    }
                }
                if w_s != 0.0 {
                    let (rs, lrj) = self.lap_t.row(j);
                    for (&row, &l) in rs.iter().zip(lrj) {
                        for a in 0..3 {
                            g[a] += w_s * l * lp[row as usize][a];
                        }
                    }
                }
                g
            })
            .collect()
    }

    /// The fill; with `r`, also the gradient's parts when the grouped fill runs (returns
    /// whether it did).
    #[allow(clippy::too_many_arguments)]
    #[track_caller]
    fn fill_impl(
        &self,
        position: &StencilMatrix,
        q: &[Mat3],
        w_e: f64,
        w_s: f64,
        values: &mut [f64],
        scratch: &mut FillScratch,
        r: Option<&[[f64; 3]]>,
    ) -> bool {
        assert_eq!(values.len(), self.nnz(), "values length differs from nnz");
        if self.block == 3 {
            assert_eq!(q.len(), position.nrows(), "one Q per sample");
        }
        let b = self.block;
        // Split the value array into one slice per block column. (Visiting the columns in a
        // breadth-first order of the block graph was measured no faster on Igea: the control
        // meshes' vertex order is already local.)
        let mut chunks: Vec<&mut [f64]> = Vec::with_capacity(self.n);
        let mut rest = values;
        for j in 0..self.n {
            let len = self.col_ptr[b * j + b] - self.col_ptr[b * j];
            let (head, tail) = rest.split_at_mut(len);
            chunks.push(head);
            rest = tail;
        }
        if b == 1 {
            chunks.into_par_iter().enumerate().for_each_init(
                || vec![u32::MAX; self.n],
                |pos, (j, chunk)| self.fill_scalar_column(position, w_e, w_s, j, pos, chunk),
            );
        } else if let Some(groups) = self.groups.as_ref().filter(|g| g.fits(position)) {
            // Per host the dense block once, summed per chunk of hosts; then every block entry
            // sums its parts (fixed order) and the smoothing term, column by column.
            let parts = &mut scratch.parts;
            parts.resize(groups.num_parts(), [0.0; 6]);
            let grad = match r {
                Some(r) => {
                    scratch.vparts.resize(groups.num_vparts(), [0.0; 3]);
                    Some((r, &mut scratch.vparts[..]))
                }
                None => None,
            };
            groups.fill_parts(q, w_e, parts, grad);
            let parts = &parts[..];
            chunks
                .into_par_iter()
                .enumerate()
                .for_each_init(Vec::new, |acc, (j, chunk)| {
                    acc.clear();
                    let first = self.bcol_ptr[j];
                    let rows = self.block_col(j);
                    acc.extend(rows.iter().enumerate().map(|(p, _)| {
                        let e = first + p;
                        let mut a = [0.0; 6];
                        for &x in groups.contribs(e) {
                            for (a, v) in a.iter_mut().zip(&parts[x as usize]) {
                                *a += v;
                            }
                        }
                        let v = w_s * self.ltl[e];
                        a[0] += v;
                        a[3] += v;
                        a[5] += v;
                        a
                    }));
                    self.scatter_block_column(j, acc, chunk);
                });
            return r.is_some();
        } else {
            chunks.into_par_iter().enumerate().for_each_init(
                || (vec![u32::MAX; self.n], Vec::new()),
                |(pos, acc), (j, chunk)| {
                    self.fill_block_column(position, q, w_e, w_s, j, pos, acc, chunk)
                },
            );
        }
        false
    }

    /// Block column `j` of `H` for block size 1 (PD) into `chunk` (its value slice).
    fn fill_scalar_column(
        &self,
        position: &StencilMatrix,
        w_e: f64,
        w_s: f64,
        j: usize,
        pos: &mut [u32],
        chunk: &mut [f64],
    ) {
        chunk.fill(0.0);
        let rows = self.block_col(j);
        for (p, &i) in rows.iter().enumerate() {
            pos[i as usize] = p as u32;
        }
        for e in &self.samp[self.samp_ptr[j]..self.samp_ptr[j + 1]] {
            let (idx, wts) = position.row(e.k as usize);
            let w = w_e * e.w;
            for (&i, &cki) in idx[..e.upto as usize].iter().zip(wts) {
                chunk[pos[i as usize] as usize] += w * cki;
            }
        }
        if w_s != 0.0 {
            let (rs, lrj) = self.lap_t.row(j);
            for (&r, &lrj) in rs.iter().zip(lrj) {
                let (idx, wts) = self.lap.row(r as usize);
                for (&i, &lri) in idx.iter().zip(wts) {
                    if i as usize <= j {
                        chunk[pos[i as usize] as usize] += w_s * lri * lrj;
                    }
                }
            }
        }
        for &i in rows {
            pos[i as usize] = u32::MAX;
        }
    }

    /// Block column `j` of `H` for block size 3 into `chunk` (its value slice). Every block
    /// `Σ_k c_ki c_kj Q_k + w_s (LᵀL)_ij I` is symmetric (the `Q_k` are), so only its 6
    /// upper entries are accumulated — in `acc`, one contiguous `[f64; 6]` per block row, which
    /// vectorizes — and mirrored into the CSC layout at the end.
    #[allow(clippy::too_many_arguments)]
    fn fill_block_column(
        &self,
        position: &StencilMatrix,
        q: &[Mat3],
        w_e: f64,
        w_s: f64,
        j: usize,
        pos: &mut [u32],
        acc: &mut Vec<[f64; 6]>,
        chunk: &mut [f64],
    ) {
        let rows = self.block_col(j);
        let nb = rows.len();
        for (p, &i) in rows.iter().enumerate() {
            pos[i as usize] = p as u32;
        }
        acc.clear();
        acc.resize(nb, [0.0; 6]);
        for e in &self.samp[self.samp_ptr[j]..self.samp_ptr[j + 1]] {
            let (idx, wts) = position.row(e.k as usize);
            let qk = &q[e.k as usize];
            let w = w_e * e.w;
            let wq = [
                w * qk[0][0],
                w * qk[0][1],
                w * qk[0][2],
                w * qk[1][1],
                w * qk[1][2],
                w * qk[2][2],
            ];
            for (&i, &cki) in idx[..e.upto as usize].iter().zip(wts) {
                let a = &mut acc[pos[i as usize] as usize];
                for (a, &v) in a.iter_mut().zip(&wq) {
                    *a += cki * v;
                }
            }
        }
        if w_s != 0.0 {
            let (rs, lrj) = self.lap_t.row(j);
            for (&r, &lrj) in rs.iter().zip(lrj) {
                let (idx, wts) = self.lap.row(r as usize);
                for (&i, &lri) in idx.iter().zip(wts) {
                    if i as usize <= j {
                        let a = &mut acc[pos[i as usize] as usize];
                        let v = w_s * lri * lrj;
                        a[0] += v;
                        a[3] += v;
                        a[5] += v;
                    }
                }
            }
        }
        for &i in rows {
            pos[i as usize] = u32::MAX;
        }
        self.scatter_block_column(j, acc, chunk);
    }

    /// Writes the upper blocks of block column `j` (`acc`: 6 upper entries per block row)
    /// into its CSC value slice `chunk`.
    fn scatter_block_column(&self, j: usize, acc: &[[f64; 6]], chunk: &mut [f64]) {
        let nb = acc.len();
        // Column 3j + c holds rows 3p + a of each off-diagonal block row p, then the diagonal
        // rows a ≤ c.
        const SYM: [[usize; 3]; 3] = [[0, 1, 2], [1, 3, 4], [2, 4, 5]];
        let base = self.col_ptr[3 * j];
        for c in 0..3 {
            let col =
                &mut chunk[self.col_ptr[3 * j + c] - base..self.col_ptr[3 * j + c + 1] - base];
            for (p, a6) in acc[..nb - 1].iter().enumerate() {
                for a in 0..3 {
                    col[3 * p + a] = a6[SYM[a][c]];
                }
            }
            let d = &acc[nb - 1];
            for a in 0..=c {
                col[3 * (nb - 1) + a] = d[SYM[a][c]];
            }
        }
    }

    /// The half-gradient `g = w_e Σ_k c_k ⊗ r_k + w_s (LᵀL ⊗ I) P` (`n by 3`), where
    /// `r_k = Q_k (S_k − V_k)` are the per-sample weighted residuals (`m by 3`).
    /// Cost: O(nnz(C) + nnz(L)), parallel over control points.
    ///
    /// # Panics
    /// If the lengths do not match the pattern.
    #[track_caller]
    pub fn gradient(&self, r: &[[f64; 3]], p: &[[f64; 3]], w_e: f64, w_s: f64) -> Vec<[f64; 3]> {
        assert_eq!(p.len(), self.n, "one control point per column");
        let lp = if w_s != 0.0 {
            self.lap.apply(p)
        } else {
            Vec::new()
        };
        (0..self.n)
            .into_par_iter()
            .map(|j| {
                let mut g = [0.0; 3];
                for e in &self.samp[self.samp_ptr[j]..self.samp_ptr[j + 1]] {
                    let (rk, c) = (r[e.k as usize], e.w);
                    for a in 0..3 {
                        g[a] += w_e * c * rk[a];
                    }
                }
                if w_s != 0.0 {
                    let (rs, lrj) = self.lap_t.row(j);
                    for (&row, &l) in rs.iter().zip(lrj) {
                        for a in 0..3 {
                            g[a] += w_s * l * lp[row as usize][a];
                        }
                    }
                }
                g
            })
            .collect()
    }

    /// The stored entries as `(row, col, value)` with `row ≤ col` (tests, diagnostics).
    /// Cost: O(nnz).
    pub fn triplets(&self, values: &[f64]) -> Vec<(usize, usize, f64)> {
        let mut out = Vec::with_capacity(self.nnz());
        for c in 0..self.dim() {
            let r = self.col_ptr[c]..self.col_ptr[c + 1];
            for (&row, &v) in self.row_idx[r.clone()].iter().zip(&values[r]) {
                out.push((row, c, v));
            }
        }
        out
    }
}

/// Scratch of [`Pattern::fill_with`], reused between fills.
#[derive(Clone, Debug, Default)]
pub struct FillScratch {
    parts: Vec<[f64; 6]>,
    vparts: Vec<[f64; 3]>,
}

/// `(LᵀL)_ij` for every block entry `(i, j)` of the pattern (block rows `brow` of each column),
/// summed in the order of the column-wise fill. Cost: O(Σ_j Σ_{r ∋ j} |row r|).
fn smoothing_blocks(
    lap: &Laplacian,
    lap_t: &Laplacian,
    bcol_ptr: &[usize],
    brow: &[u32],
) -> Vec<f64> {
    let n = bcol_ptr.len() - 1;
    let mut out = vec![0.0; brow.len()];
    let mut pos = vec![u32::MAX; n];
    for j in 0..n {
        let rows = &brow[bcol_ptr[j]..bcol_ptr[j + 1]];
        for (p, &i) in rows.iter().enumerate() {
            pos[i as usize] = p as u32;
        }
        let col = &mut out[bcol_ptr[j]..bcol_ptr[j + 1]];
        let (rs, lrj) = lap_t.row(j);
        for (&r, &lrj) in rs.iter().zip(lrj) {
            let (idx, wts) = lap.row(r as usize);
            for (&i, &lri) in idx.iter().zip(wts) {
                if i as usize <= j {
                    col[pos[i as usize] as usize] += lri * lrj;
                }
            }
        }
        for &i in rows {
            pos[i as usize] = u32::MAX;
        }
    }
    out
}

/// The transpose of a CSR operator with `rows` rows over `ncols` columns: `ncols` rows, the
/// entries of column `j` in increasing row order. Equals [`Laplacian::transpose`] for a square
/// operator. Cost: O(nnz + ncols).
pub(crate) fn transpose_rows(l: &Laplacian, ncols: usize) -> Laplacian {
    let mut offsets = vec![0usize; ncols + 1];
    for &j in &l.indices {
        offsets[j as usize + 1] += 1;
    }
    for j in 0..ncols {
        offsets[j + 1] += offsets[j];
    }
    let mut next = offsets.clone();
    let mut indices = vec![0u32; l.indices.len()];
    let mut weights = vec![0.0; l.indices.len()];
    for r in 0..l.len() {
        let (idx, w) = l.row(r);
        for (&j, &w) in idx.iter().zip(w) {
            let s = &mut next[j as usize];
            indices[*s] = r as u32;
            weights[*s] = w;
            *s += 1;
        }
    }
    Laplacian {
        offsets,
        indices,
        weights,
    }
}

/// Per-sample weighted residuals `r_k = Q_k (S_k − V_k)` (block 3) or `S_k − V_k` (PD).
pub fn weighted_residuals(s: &[[f64; 3]], v: &[[f64; 3]], q: Option<&[Mat3]>) -> Vec<[f64; 3]> {
    s.par_iter()
        .zip(v.par_iter())
        .enumerate()
        .map(|(k, (s, v))| {
            let e = [s[0] - v[0], s[1] - v[1], s[2] - v[2]];
            match q {
                Some(q) => mul(&q[k], e),
                None => e,
            }
        })
        .collect()
}

/// One nonzero `c_kj` of the sampling operator, seen from its column `j`.
#[derive(Clone, Copy, Debug, Default)]
struct SampleRef {
    /// The sample (row) `k`.
    k: u32,
    /// Length of the prefix of row `k` with columns `≤ j` (rows are sorted and unique, so
    /// `j`'s position + 1): the entries that fall in the upper triangle of column `j`.
    upto: u32,
    /// The weight `c_kj`.
    w: f64,
}

/// Columns of a CSR operator: for each column `j`, its nonzeros as [`SampleRef`]s.
fn transpose_operator(c: &StencilMatrix) -> (Vec<usize>, Vec<SampleRef>) {
    let n = c.ncols();
    let mut ptr = vec![0usize; n + 1];
    for &j in c.indices() {
        ptr[j as usize + 1] += 1;
    }
    for j in 0..n {
        ptr[j + 1] += ptr[j];
    }
    let mut next = ptr.clone();
    let mut out = vec![SampleRef::default(); c.nnz()];
    for k in 0..c.nrows() {
        let (idx, w) = c.row(k);
        debug_assert!(
            idx.windows(2).all(|p| p[0] < p[1]),
            "rows sorted and unique"
        );
        for (p, (&j, &w)) in idx.iter().zip(w).enumerate() {
            let s = &mut next[j as usize];
            out[*s] = SampleRef {
                k: k as u32,
                upto: p as u32 + 1,
                w,
            };
            *s += 1;
        }
    }
    (ptr, out)
}
