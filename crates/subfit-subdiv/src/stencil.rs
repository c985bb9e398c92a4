//! `StencilMatrix`: a sparse row-major (CSR) matrix of f64 weights over control points.
//!
//! Every subdivision operation of this crate — one level of refinement, limit positions, limit
//! tangents, their compositions — is such a matrix (OpenSubdiv `Far::StencilTable`). Rows are
//! results (refined or limit vertices), columns are inputs (parent or control vertices).
//! Products use row-by-row accumulation into a dense scratch row with a list of touched columns
//! (Gustavson's algorithm), parallel over row blocks with rayon.

use rayon::prelude::*;

/// Entries with `|w| <= DROP_TOLERANCE * max_row |w|` are dropped by [`StencilMatrix::compose`]
/// (round-off left by cancelling weights, e.g. in tangent rows). Relative, dimensionless.
pub const DROP_TOLERANCE: f64 = 1e-15;

/// A sparse matrix in compressed-row form with f64 weights.
///
/// Shape `nrows × ncols`. Invariants (upheld by every constructor): `offsets` has `nrows + 1`
/// non-decreasing entries starting at 0 and ending at `nnz`; column indices are `< ncols`, and
/// sorted and unique within each row.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StencilMatrix {
    ncols: usize,
    offsets: Vec<usize>,
    indices: Vec<u32>,
    weights: Vec<f64>,
}

impl StencilMatrix {
    /// An empty matrix with `ncols` columns and no rows.
    pub fn new(ncols: usize) -> Self {
        Self {
            ncols,
            offsets: vec![0],
            indices: Vec::new(),
            weights: Vec::new(),
        }
    }

    /// The `n × n` identity.
    pub fn identity(n: usize) -> Self {
        Self {
            ncols: n,
            offsets: (0..=n).collect(),
            indices: (0..n as u32).collect(),
            weights: vec![1.0; n],
        }
    }

    /// Builds a matrix from raw CSR arrays; `None` if the invariants above do not hold.
    pub fn from_raw(
        ncols: usize,
        offsets: Vec<usize>,
        indices: Vec<u32>,
        weights: Vec<f64>,
    ) -> Option<Self> {
        let ok = offsets.first() == Some(&0)
            && offsets.last() == Some(&indices.len())
            && indices.len() == weights.len()
            && offsets.windows(2).all(|w| {
                w[0] <= w[1]
                    && indices[w[0]..w[1]].windows(2).all(|p| p[0] < p[1])
                    && indices[w[0]..w[1]].iter().all(|&c| (c as usize) < ncols)
            });
        ok.then_some(Self {
            ncols,
            offsets,
            indices,
            weights,
        })
    }

    /// Appends a row given as `(column, weight)` pairs in any order; repeated columns are summed
    /// and exact zeros dropped. Cost O(k log k) for `k` pairs.
    ///
    /// # Panics
    /// If a column is `>= ncols` (a broken invariant).
    #[track_caller]
    pub fn push_row(&mut self, entries: &mut [(u32, f64)]) {
        entries.sort_unstable_by_key(|e| e.0);
        let mut last = u32::MAX;
        for &(c, w) in entries.iter() {
            assert!((c as usize) < self.ncols, "column {c} >= {}", self.ncols);
            if c == last {
                *self.weights.last_mut().expect("a previous entry") += w;
            } else {
                self.indices.push(c);
                self.weights.push(w);
                last = c;
            }
        }
        // Drop exact zeros of this row.
        let start = *self.offsets.last().expect("offsets start at 0");
        let mut k = start;
        for i in start..self.indices.len() {
            if self.weights[i] != 0.0 {
                self.indices[k] = self.indices[i];
                self.weights[k] = self.weights[i];
                k += 1;
            }
        }
        self.indices.truncate(k);
        self.weights.truncate(k);
        self.offsets.push(k);
    }

    /// Number of rows.
    #[inline]
    pub fn nrows(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Number of columns.
    #[inline]
    pub fn ncols(&self) -> usize {
        self.ncols
    }

    /// Number of stored entries.
    #[inline]
    pub fn nnz(&self) -> usize {
        self.indices.len()
    }

    /// Row `i` as `(columns, weights)`, columns ascending.
    ///
    /// # Panics
    /// If `i >= nrows`.
    #[inline]
    #[track_caller]
    pub fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let (a, b) = (self.offsets[i], self.offsets[i + 1]);
        (&self.indices[a..b], &self.weights[a..b])
    }

    /// The row offsets (`nrows + 1` entries).
    pub fn offsets(&self) -> &[usize] {
        &self.offsets
    }

    /// All column indices, row after row.
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }

    /// All weights, row after row.
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// Sum of the weights of each row (`nrows` entries): 1 for position stencils, 0 for tangent
    /// stencils.
    pub fn row_sums(&self) -> Vec<f64> {
        (0..self.nrows())
            .map(|i| self.row(i).1.iter().sum())
            .collect()
    }

    /// Multiplies every weight by `s`.
    pub fn scale(&mut self, s: f64) {
        self.weights.iter_mut().for_each(|w| *w *= s);
    }

    /// Keeps only the first `n` rows.
    pub fn truncate_rows(&mut self, n: usize) {
        if n < self.nrows() {
            self.offsets.truncate(n + 1);
            let nnz = self.offsets[n];
            self.indices.truncate(nnz);
            self.weights.truncate(nnz);
        }
    }

    /// Appends the rows of `other` (same column count) below those of `self`.
    ///
    /// # Panics
    /// If the column counts differ.
    #[track_caller]
    pub(crate) fn append_rows(&mut self, other: &StencilMatrix) {
        assert_eq!(self.ncols, other.ncols, "matrices differ in columns");
        let base = self.nnz();
        self.offsets
            .extend(other.offsets[1..].iter().map(|&o| o + base));
        self.indices.extend_from_slice(&other.indices);
        self.weights.extend_from_slice(&other.weights);
    }

    /// `y = self · x` for 3-vectors: `x` is `ncols by 3`, the result `nrows by 3`.
    /// Cost O(nnz), parallel over rows.
    ///
    /// # Panics
    /// If `x.len() != ncols`.
    #[track_caller]
    pub fn apply(&self, x: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let mut y = vec![[0.0; 3]; self.nrows()];
        self.apply_into(x, &mut y);
        y
    }

    /// As [`Self::apply`], writing into `y` (`nrows by 3`).
    ///
    /// # Panics
    /// If `x.len() != ncols` or `y.len() != nrows`.
    #[track_caller]
    pub fn apply_into(&self, x: &[[f64; 3]], y: &mut [[f64; 3]]) {
        assert_eq!(x.len(), self.ncols, "input has the wrong number of rows");
        assert_eq!(y.len(), self.nrows(), "output has the wrong number of rows");
        y.par_iter_mut()
            .with_min_len(4096)
            .enumerate()
            .for_each(|(i, yi)| {
                let (cols, ws) = self.row(i);
                let mut acc = [0.0; 3];
                for (&c, &w) in cols.iter().zip(ws) {
                    let p = &x[c as usize];
                    acc[0] += w * p[0];
                    acc[1] += w * p[1];
                    acc[2] += w * p[2];
                }
                *yi = acc;
            });
    }

    /// The sparse product `self · rhs` (`nrows × rhs.ncols`). Entries below
    /// [`DROP_TOLERANCE`] relative to their row's largest are dropped.
    ///
    /// Cost O(Σ over entries (i, j) of `self` of nnz(row j of rhs)), parallel over blocks of rows;
    /// scratch O(rhs.ncols) per thread. Deterministic (columns sorted within each row).
    ///
    /// # Panics
    /// If `self.ncols != rhs.nrows`.
    #[track_caller]
    pub fn compose(&self, rhs: &StencilMatrix) -> StencilMatrix {
        assert_eq!(self.ncols, rhs.nrows(), "inner dimensions differ");
        let [out] = compose_rows(
            self.nrows(),
            Stacked::one(rhs),
            || (),
            |_, i, row| {
                let (c, w) = self.row(i);
                row.extend(c.iter().zip(w).map(|(&c, &w)| (c, [w])));
            },
        );
        out
    }
}

/// Rows whose entries carry `K` weights each (e.g. a limit position and two tangents sharing
/// one support), over `ncols` columns. Columns may repeat within a row (they are summed).
#[derive(Clone, Debug, Default)]
pub(crate) struct MultiRows<const K: usize> {
    pub(crate) ncols: usize,
    pub(crate) offsets: Vec<usize>,
    pub(crate) cols: Vec<u32>,
    pub(crate) weights: Vec<[f64; K]>,
}

impl<const K: usize> MultiRows<K> {
    pub(crate) fn nrows(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Splits into `K` matrices (repeated columns summed, exact zeros dropped).
    pub(crate) fn split(&self) -> [StencilMatrix; K] {
        let mut out: [StencilMatrix; K] = std::array::from_fn(|_| StencilMatrix::new(self.ncols));
        let mut row = Vec::new();
        for i in 0..self.nrows() {
            let (a, b) = (self.offsets[i], self.offsets[i + 1]);
            for (k, m) in out.iter_mut().enumerate() {
                row.clear();
                row.extend((a..b).map(|e| (self.cols[e], self.weights[e][k])));
                m.push_row(&mut row);
            }
        }
        out
    }

    /// The `K` products `W_k · rhs` in one pass over `rhs` (each row of `rhs` is read once per
    /// use for all `K` weights). Same pruning and determinism as [`StencilMatrix::compose`].
    pub(crate) fn compose(&self, rhs: &StencilMatrix) -> [StencilMatrix; K] {
        assert_eq!(self.ncols, rhs.nrows(), "inner dimensions differ");
        compose_rows(
            self.nrows(),
            Stacked::one(rhs),
            || (),
            |_, i, row| {
                let (a, b) = (self.offsets[i], self.offsets[i + 1]);
                row.extend((a..b).map(|e| (self.cols[e], self.weights[e])));
            },
        )
    }
}

/// The right-hand side of [`compose_rows`]: the rows of `top` followed by the rows of `bottom`
/// (if any), over the same columns. Stacking lets a left row refer to rows computed by an
/// earlier product (e.g. Catmull-Clark face points, computed first and then used by the edge
/// and vertex points) instead of re-expanding them.
#[derive(Clone, Copy)]
pub(crate) struct Stacked<'a> {
    top: &'a StencilMatrix,
    bottom: Option<&'a StencilMatrix>,
}

impl<'a> Stacked<'a> {
    /// Just `m`.
    pub(crate) fn one(m: &'a StencilMatrix) -> Self {
        Self {
            top: m,
            bottom: None,
        }
    }

    /// The rows of `top`, then those of `bottom`.
    ///
    /// # Panics
    /// If the column counts differ.
    #[track_caller]
    pub(crate) fn two(top: &'a StencilMatrix, bottom: &'a StencilMatrix) -> Self {
        assert_eq!(
            top.ncols, bottom.ncols,
            "stacked matrices differ in columns"
        );
        Self {
            top,
            bottom: Some(bottom),
        }
    }

    fn ncols(&self) -> usize {
        self.top.ncols
    }

    #[inline]
    fn row(&self, j: usize) -> (&'a [u32], &'a [f64]) {
        let n = self.top.nrows();
        match self.bottom {
            Some(b) if j >= n => b.row(j - n),
            _ => self.top.row(j),
        }
    }
}

/// `K` products `L_k · rhs` where the rows of the `L_k` (sharing one support, `K` weights per
/// entry, columns < the row count of `rhs`, repeats allowed) are generated on the fly by
/// `lhs_row(state, i, row)`, so the left factors are never stored. Entries below
/// [`DROP_TOLERANCE`] relative to their row's largest are dropped; columns are sorted within
/// each row.
///
/// Rows are produced in waves of [`WAVE`] blocks of [`BLOCK`] rows: the blocks of a wave are
/// computed in parallel (one `init()` state and one dense scratch row of `rhs.ncols` entries per
/// worker) into buffers reused from wave to wave, then appended to the output, whose capacity is
/// extrapolated from the first wave. The append of one wave runs beside the computation of the
/// next (two sets of buffers, `rayon::join`), so the writes into the output — and the page
/// faults of its fresh memory, a good part of the cost for large outputs — overlap with
/// arithmetic instead of stalling the other workers. So the output is written once and no large
/// temporary is allocated per call beyond two waves' buffers. (A parallel copy into a
/// zero-filled output was tried: the allocator zero-fills allocations below its mmap
/// threshold, which cost more than the serial append it saved.)
pub(crate) fn compose_rows<const K: usize, S>(
    nrows: usize,
    rhs: Stacked<'_>,
    init: impl Fn() -> S,
    lhs_row: impl Fn(&mut S, usize, &mut Vec<(u32, [f64; K])>) + Sync + Send,
) -> [StencilMatrix; K]
where
    S: Send,
{
    let ncols = rhs.ncols();
    let mut out: [StencilMatrix; K] = std::array::from_fn(|_| StencilMatrix::new(ncols));
    for m in &mut out {
        m.offsets.reserve_exact(nrows);
    }
    // One scratch per block of a wave and two sets of output buffers (the wave being computed
    // and the wave being appended), all reused from wave to wave (small enough to stay in
    // cache; no allocation per wave).
    let nslots = nrows.div_ceil(BLOCK).min(WAVE);
    let mut scratch: Vec<Scratch<K, S>> =
        (0..nslots).map(|_| Scratch::new(ncols, init())).collect();
    let new_bufs = || -> Vec<[RowBlock; K]> {
        (0..nslots)
            .map(|_| std::array::from_fn(|_| RowBlock::default()))
            .collect()
    };
    let (mut ready, mut next) = (new_bufs(), new_bufs());
    let compute = |first: usize, bufs: &mut [[RowBlock; K]], scratch: &mut [Scratch<K, S>]| {
        let nblocks = (nrows - first).div_ceil(BLOCK).min(WAVE);
        bufs[..nblocks]
            .par_iter_mut()
            .zip(&mut scratch[..nblocks])
            .enumerate()
            .for_each(|(b, (blk, scratch))| {
                let rows = first + b * BLOCK..(first + (b + 1) * BLOCK).min(nrows);
                blk.iter_mut().for_each(RowBlock::clear);
                for i in rows {
                    scratch.lrow.clear();
                    lhs_row(&mut scratch.state, i, &mut scratch.lrow);
                    scratch.accumulate(&rhs);
                    scratch.emit(blk);
                }
            });
        (first + nblocks * BLOCK).min(nrows)
    };
    let mut done = if nrows > 0 {
        compute(0, &mut ready, &mut scratch)
    } else {
        0
    };
    let mut appended = 0;
    while appended < nrows {
        let (first_wave, wave_end) = (appended == 0, done);
        let nblocks = (wave_end - appended).div_ceil(BLOCK);
        let append = |out: &mut [StencilMatrix; K]| {
            append_wave(out, &ready[..nblocks], first_wave, wave_end, nrows)
        };
        if done < nrows {
            let ((), end) = rayon::join(
                || append(&mut out),
                || compute(done, &mut next, &mut scratch),
            );
            done = end;
        } else {
            append(&mut out);
        }
        appended = wave_end;
        std::mem::swap(&mut ready, &mut next);
    }
    for m in &mut out {
        m.indices.shrink_to_fit();
        m.weights.shrink_to_fit();
    }
    out
}

/// Appends the rows of one wave of [`compose_rows`] (`blocks`, ending at row `wave_end` of
/// `nrows`) to the outputs; after the first wave, reserves the extrapolated total.
fn append_wave<const K: usize>(
    out: &mut [StencilMatrix; K],
    blocks: &[[RowBlock; K]],
    first_wave: bool,
    wave_end: usize,
    nrows: usize,
) {
    for (k, m) in out.iter_mut().enumerate() {
        if first_wave {
            // Extrapolate the total from the first wave, generously: unused capacity is
            // never touched (so costs no memory) and is given back at the end.
            let wave_nnz: usize = blocks.iter().map(|b| b[k].indices.len()).sum();
            let guess = (wave_nnz as f64 * nrows as f64 / wave_end as f64 * 1.25) as usize;
            m.indices.reserve_exact(guess);
            m.weights.reserve_exact(guess);
        }
        for blk in blocks {
            let RowBlock {
                lens,
                indices,
                weights,
            } = &blk[k];
            let mut end = m.indices.len();
            for &l in lens {
                end += l as usize;
                m.offsets.push(end);
            }
            m.indices.extend_from_slice(indices);
            m.weights.extend_from_slice(weights);
        }
    }
}

/// Rows per parallel task in [`compose_rows`].
const BLOCK: usize = 256;
/// Tasks per wave in [`compose_rows`].
const WAVE: usize = 8;

/// Rows of one output matrix computed by one task: row lengths, then the entries.
#[derive(Default)]
struct RowBlock {
    lens: Vec<u32>,
    indices: Vec<u32>,
    weights: Vec<f64>,
}

impl RowBlock {
    fn clear(&mut self) {
        self.lens.clear();
        self.indices.clear();
        self.weights.clear();
    }
}

/// Per-worker state of [`compose_rows`]: a dense accumulator over the columns of `rhs` with a
/// marker array and the list of touched columns (Gustavson), the current left row, and the
/// caller's state.
struct Scratch<const K: usize, S> {
    /// Per column: the accumulated weights and whether the column is in `touched` (one array,
    /// so one bounds check and one cache line per update).
    acc: Vec<([f64; K], bool)>,
    touched: Vec<u32>,
    ntouched: usize,
    lrow: Vec<(u32, [f64; K])>,
    state: S,
}

impl<const K: usize, S> Scratch<K, S> {
    fn new(ncols: usize, state: S) -> Self {
        Self {
            acc: vec![([0.0; K], false); ncols],
            // One slot more than columns: the branch-free append writes before it counts.
            touched: vec![0; ncols + 1],
            ntouched: 0,
            lrow: Vec::with_capacity(64),
            state,
        }
    }

    /// Accumulates `Σ_j lrow_j · rhs_j` into `acc`, recording touched columns in
    /// `touched[..ntouched]` (branch-free: most columns repeat, unpredictably).
    #[inline]
    fn accumulate(&mut self, rhs: &Stacked<'_>) {
        let (acc, touched) = (&mut self.acc, &mut self.touched);
        let mut n = self.ntouched;
        for &(j, w) in &self.lrow {
            let (c2, w2) = rhs.row(j as usize);
            for (&c, &u) in c2.iter().zip(w2) {
                let cu = c as usize;
                touched[n] = c;
                let (a, mark) = &mut acc[cu];
                n += usize::from(!*mark);
                *mark = true;
                for k in 0..K {
                    a[k] += w[k] * u;
                }
            }
        }
        self.ntouched = n;
    }

    /// Appends the accumulated row (sorted, pruned) to `blk` and resets the accumulator.
    #[inline]
    fn emit(&mut self, blk: &mut [RowBlock; K]) {
        let acc = &mut self.acc;
        let touched = &mut self.touched[..self.ntouched];
        self.ntouched = 0;
        touched.sort_unstable();
        let mut big = [0.0f64; K];
        for &c in touched.iter() {
            let a = &acc[c as usize].0;
            for k in 0..K {
                big[k] = big[k].max(a[k].abs());
            }
        }
        // One pass writing all `K` rows; the tolerance test almost always keeps the entry, so
        // its branch is well predicted.
        let t = touched.len();
        let tol: [f64; K] = std::array::from_fn(|k| DROP_TOLERANCE * big[k]);
        let mut base = [0usize; K];
        for (k, b) in blk.iter_mut().enumerate() {
            base[k] = b.indices.len();
            b.indices.reserve(t);
            b.weights.reserve(t);
        }
        for &c in touched.iter() {
            let (a, _) = std::mem::replace(&mut acc[c as usize], ([0.0; K], false));
            for (k, b) in blk.iter_mut().enumerate() {
                if a[k].abs() > tol[k] {
                    b.indices.push(c);
                    b.weights.push(a[k]);
                }
            }
        }
        for (k, b) in blk.iter_mut().enumerate() {
            let len = b.indices.len() - base[k];
            b.lens.push(len as u32);
        }
    }
}

/// A short sparse row of 3-weights being summed: `slot[c]` is the position of column `c` in
/// `entries` (`u32::MAX` if absent).
pub(crate) struct SparseSum {
    slot: Vec<u32>,
    entries: Vec<(u32, [f64; 3])>,
}

impl SparseSum {
    /// An empty sum over `ncols` columns.
    pub(crate) fn new(ncols: usize) -> Self {
        Self {
            slot: vec![u32::MAX; ncols],
            entries: Vec::with_capacity(64),
        }
    }

    /// The entries so far, in first-touch order.
    pub(crate) fn entries(&self) -> &[(u32, [f64; 3])] {
        &self.entries
    }

    /// Adds `w` to column `c`.
    #[inline]
    pub(crate) fn add(&mut self, c: u32, w: [f64; 3]) {
        let s = &mut self.slot[c as usize];
        if *s == u32::MAX {
            *s = self.entries.len() as u32;
            self.entries.push((c, w));
        } else {
            let e = &mut self.entries[*s as usize].1;
            e[0] += w[0];
            e[1] += w[1];
            e[2] += w[2];
        }
    }

    /// Replaces every entry of a column `c >= nv` (a face centre, face `c − nv`) by equal
    /// shares over the vertices of that face, given by `face`.
    #[inline]
    pub(crate) fn expand_faces<'f>(&mut self, nv: u32, face: impl Fn(u32) -> &'f [u32]) {
        let n = self.entries.len();
        let mut kept = 0;
        for i in 0..n {
            let (c, w) = self.entries[i];
            if c < nv {
                continue;
            }
            self.slot[c as usize] = u32::MAX;
            let verts = face(c - nv);
            let len = verts.len() as f64;
            for &u in verts {
                self.add(u, [w[0] / len, w[1] / len, w[2] / len]);
            }
            kept += 1;
        }
        if kept > 0 {
            // Drop the face columns; re-point the slots of the vertices that moved.
            self.entries.retain(|e| e.0 < nv);
            for (i, &(c, _)) in self.entries.iter().enumerate() {
                self.slot[c as usize] = i as u32;
            }
        }
    }

    /// Moves the entries (first-touch order) to `out` and clears the sum.
    #[inline]
    pub(crate) fn drain_into(&mut self, out: &mut Vec<(u32, [f64; 3])>) {
        for &(c, _) in &self.entries {
            self.slot[c as usize] = u32::MAX;
        }
        out.append(&mut self.entries);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compose_matches_dense_product() {
        let mut a = StencilMatrix::new(3);
        a.push_row(&mut [(2, 0.5), (0, 0.25), (2, 0.25)]);
        a.push_row(&mut [(1, 1.0), (0, 0.0)]);
        let mut b = StencilMatrix::new(2);
        b.push_row(&mut [(0, 1.0)]);
        b.push_row(&mut [(0, 0.5), (1, 0.5)]);
        b.push_row(&mut [(1, 2.0)]);
        assert_eq!(a.row(0), (&[0u32, 2][..], &[0.25, 0.75][..]));
        assert_eq!(a.nnz(), 3);
        let c = a.compose(&b);
        assert_eq!(c.row(0), (&[0u32, 1][..], &[0.25, 1.5][..]));
        assert_eq!(c.row(1), (&[0u32, 1][..], &[0.5, 0.5][..]));
        let y = c.apply(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        assert_eq!(y[0], [0.25, 1.5, 0.0]);
        let i = StencilMatrix::identity(2);
        assert_eq!(c.compose(&i), c);
        assert!(StencilMatrix::from_raw(2, vec![0, 2], vec![1, 0], vec![1.0, 1.0]).is_none());
    }
}
