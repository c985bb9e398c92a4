//! Preconditioned conjugate gradients for the damped normal equations `(H + sI) δ = −g`
//! (Hestenes & Stiefel 1952; Saad, *Iterative Methods for Sparse Linear Systems*, 2nd ed.,
//! Alg. 9.1) with a block-Jacobi preconditioner (the 3×3 diagonal blocks of `H`, inverted).
//!
//! Started from `x₀ = 0`, the PCG iterate `x_k` lies in the Krylov space to which the residual
//! `r_k = b − A x_k` is orthogonal, so `r_kᵀ x_k = 0` (up to rounding). For the LM gain ratio this
//! means the model decrease predicted from `−gᵀδ + s‖δ‖²` is exact for the inexact step too,
//! and `gᵀδ < 0`: every truncated PCG step is a descent direction of the model. (A warm start
//! would break both, so none is used.)
//!
//! The upper-triangle CSC storage of [`Pattern`] is mirrored once per pattern into a full block
//! CSR index (`b×b` blocks, `b` = 1 or 3); each solve gathers the values into it and runs
//! matrix–vector products in parallel over block rows. Reductions are summed per fixed-size
//! chunk and then serially, so results do not depend on the thread count.

use rayon::prelude::*;

use crate::assemble::Pattern;

/// Chunk length of the deterministic parallel reductions.
const CHUNK: usize = 4096;

/// Outcome of one PCG solve.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PcgStats {
    /// Iterations (matrix–vector products) used, summed over right-hand sides.
    pub iterations: usize,
    /// Largest final relative residual `‖b − A x‖ / ‖b‖` over the right-hand sides.
    pub relative_residual: f64,
}

/// Why PCG failed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PcgFailure {
    /// A diagonal block or a search direction has non-positive curvature (`pᵀAp ≤ 0`): the
    /// matrix is not positive definite. `index` is the block row (diagonal) or 0.
    NotPositiveDefinite {
        /// Block row of the failing diagonal block, or the iteration of the failing curvature.
        index: usize,
    },
}

/// A PCG solver that keeps, for one [`Pattern`], the full block-CSR index of `H` and buffers.
#[derive(Clone, Debug, Default)]
pub struct PcgSolver {
    b: usize,
    /// Block-row pointers (`n + 1`).
    row_ptr: Vec<usize>,
    /// Block column of each stored block.
    col: Vec<u32>,
    /// For each stored block, `b·b` slots into the upper CSC values (row-major in the block).
    gather: Vec<u32>,
    /// Gathered block values, `b·b` per block.
    vals: Vec<f64>,
    /// Inverted diagonal blocks, `b·b` per block row.
    dinv: Vec<f64>,
}

impl PcgSolver {
    /// Builds the block-CSR index of `pattern`. Cost: O(nnz), memory ≈ 2·nnz values + indices.
    ///
    /// # Panics
    /// If the pattern has more than `u32::MAX` stored values.
    #[track_caller]
    pub fn new(pattern: &Pattern) -> Self {
        let n = pattern.num_points();
        let b = pattern.block();
        assert!(pattern.nnz() <= u32::MAX as usize, "pattern too large");
        // Slot of scalar entry (b·i + a, b·j + c), i ≤ j, in the CSC values: column b·j + c
        // stores the b rows of each off-diagonal block row in order, then the diagonal rows.
        let col_ptr = pattern.col_ptr();
        let slot = |j: usize, p: usize, nb: usize, a: usize, c: usize| -> usize {
            let start = col_ptr[b * j + c];
            if p + 1 < nb {
                start + b * p + a
            } else {
                start + b * (nb - 1) + a
            }
        };
        // Count blocks per block row of the full matrix.
        let mut ptr = vec![0usize; n + 1];
        for j in 0..n {
            for &i in pattern.block_col(j) {
                ptr[i as usize + 1] += 1;
                if i as usize != j {
                    ptr[j + 1] += 1;
                }
            }
        }
        for i in 0..n {
            ptr[i + 1] += ptr[i];
        }
        let nblocks = ptr[n];
        let mut next = ptr.clone();
        let mut col = vec![0u32; nblocks];
        let mut gather = vec![0u32; nblocks * b * b];
        for j in 0..n {
            let rows = pattern.block_col(j);
            let nb = rows.len();
            for (p, &i) in rows.iter().enumerate() {
                let i = i as usize;
                // Block (i, j): entry (a, c) is stored at slot(j, p, a, c) for a ≤ c on the
                // diagonal block, always off it.
                let e = next[i];
                next[i] += 1;
                col[e] = j as u32;
                for a in 0..b {
                    for c in 0..b {
                        let s = if i == j && a > c {
                            slot(j, p, nb, c, a)
                        } else {
                            slot(j, p, nb, a, c)
                        };
                        gather[e * b * b + a * b + c] = s as u32;
                    }
                }
                if i != j {
                    // Block (j, i) = block (i, j)ᵀ.
                    let e = next[j];
                    next[j] += 1;
                    col[e] = i as u32;
                    for a in 0..b {
                        for c in 0..b {
                            gather[e * b * b + a * b + c] = slot(j, p, nb, c, a) as u32;
                        }
                    }
                }
            }
        }
        // Sort each block row by column (the mirrored blocks arrive out of order).
        for i in 0..n {
            let r = ptr[i]..ptr[i + 1];
            let mut idx: Vec<usize> = r.clone().collect();
            idx.sort_unstable_by_key(|&e| col[e]);
            let c: Vec<u32> = idx.iter().map(|&e| col[e]).collect();
            let g: Vec<u32> = idx
                .iter()
                .flat_map(|&e| gather[e * b * b..(e + 1) * b * b].to_vec())
                .collect();
            col[r.clone()].copy_from_slice(&c);
            gather[r.start * b * b..r.end * b * b].copy_from_slice(&g);
        }
        Self {
            b,
            row_ptr: ptr,
            col,
            gather,
            vals: vec![0.0; nblocks * b * b],
            dinv: vec![0.0; n * b * b],
        }
    }

    /// Solves `A X = B` approximately, in place: `rhs` (column-major `b·n × nrhs`) holds `B` on
    /// entry and `X` on exit. `A` is the upper triangle in `values` over `pattern` (the one
    /// given to [`Self::new`]). Each column stops at `‖r‖ ≤ tol·‖b‖` or after `max_iter`
    /// iterations (then returns the last iterate: still a descent direction).
    ///
    /// Cost per iteration: one matrix–vector product (O(nnz)) and O(n) vector work, parallel.
    ///
    /// # Panics
    /// If the sizes do not match the pattern.
    #[track_caller]
    pub fn solve(
        &mut self,
        pattern: &Pattern,
        values: &[f64],
        rhs: &mut [f64],
        nrhs: usize,
        tol: f64,
        max_iter: usize,
    ) -> Result<PcgStats, PcgFailure> {
        let dim = pattern.dim();
        assert_eq!(
            self.b,
            pattern.block(),
            "pattern differs from the one analysed"
        );
        assert_eq!(rhs.len(), dim * nrhs, "rhs length");
        assert_eq!(values.len(), pattern.nnz(), "values length");
        self.load(values)?;
        let mut stats = PcgStats::default();
        for col in rhs.chunks_mut(dim) {
            let (it, rel) = self.solve_one(col, tol, max_iter)?;
            stats.iterations += it;
            stats.relative_residual = stats.relative_residual.max(rel);
        }
        Ok(stats)
    }

    /// Gathers `values` into block CSR and inverts the diagonal blocks.
    fn load(&mut self, values: &[f64]) -> Result<(), PcgFailure> {
        let bb = self.b * self.b;
        self.vals
            .par_chunks_mut(CHUNK * bb)
            .zip(self.gather.par_chunks(CHUNK * bb))
            .for_each(|(v, g)| {
                for (v, &s) in v.iter_mut().zip(g) {
                    *v = values[s as usize];
                }
            });
        let (row_ptr, col, vals, b) = (&self.row_ptr, &self.col, &self.vals, self.b);
        let bad = self
            .dinv
            .par_chunks_mut(bb)
            .enumerate()
            .map(|(i, d)| {
                let r = row_ptr[i]..row_ptr[i + 1];
                let e = r.start + col[r].binary_search(&(i as u32)).expect("diagonal block");
                let blk = &vals[e * bb..(e + 1) * bb];
                if invert_spd(blk, b, d) {
                    return usize::MAX;
                }
                // Numerically singular block (e.g. a TD block without damping): plain Jacobi.
                d.fill(0.0);
                for a in 0..b {
                    let m = blk[a * b + a];
                    if !(m > 0.0 && m.is_finite()) {
                        return i;
                    }
                    d[a * b + a] = 1.0 / m;
                }
                usize::MAX
            })
            .min()
            .unwrap_or(usize::MAX);
        if bad != usize::MAX {
            return Err(PcgFailure::NotPositiveDefinite { index: bad });
        }
        Ok(())
    }

    /// `y = A x`.
    fn matvec(&self, x: &[f64], y: &mut [f64]) {
        let b = self.b;
        let bb = b * b;
        if b == 3 {
            // The same sums, in the same order, with the block size known to the compiler.
            y.par_chunks_mut(3)
                .with_min_len(64)
                .enumerate()
                .for_each(|(i, yi)| {
                    let mut acc = [0.0f64; 3];
                    for e in self.row_ptr[i]..self.row_ptr[i + 1] {
                        let j = self.col[e] as usize;
                        let blk: &[f64; 9] =
                            self.vals[e * 9..e * 9 + 9].try_into().expect("3×3 block");
                        let xj: &[f64; 3] = x[3 * j..3 * j + 3].try_into().expect("3-vector");
                        for (a, acc) in acc.iter_mut().enumerate() {
                            let row = &blk[3 * a..3 * a + 3];
                            *acc += (row[0] * xj[0] + row[1] * xj[1]) + row[2] * xj[2];
                        }
                    }
                    yi.copy_from_slice(&acc);
                });
            return;
        }
        y.par_chunks_mut(b).enumerate().for_each(|(i, yi)| {
            let mut acc = [0.0f64; 3];
            for e in self.row_ptr[i]..self.row_ptr[i + 1] {
                let j = self.col[e] as usize;
                let blk = &self.vals[e * bb..(e + 1) * bb];
                let xj = &x[b * j..b * j + b];
                for a in 0..b {
                    let row = &blk[a * b..a * b + b];
                    acc[a] += row.iter().zip(xj).map(|(m, x)| m * x).sum::<f64>();
                }
            }
            yi.copy_from_slice(&acc[..b]);
        });
    }

    /// `z = M⁻¹ r` (block Jacobi).
    fn precondition(&self, r: &[f64], z: &mut [f64]) {
        let b = self.b;
        let bb = b * b;
        z.par_chunks_mut(b).enumerate().for_each(|(i, zi)| {
            let d = &self.dinv[i * bb..(i + 1) * bb];
            let ri = &r[b * i..b * i + b];
            for a in 0..b {
                zi[a] = (0..b).map(|c| d[a * b + c] * ri[c]).sum();
            }
        });
    }

    /// PCG on one right-hand side (`x` holds `b` on entry). Returns (iterations, relative
    /// residual).
    fn solve_one(
        &self,
        x: &mut [f64],
        tol: f64,
        max_iter: usize,
    ) -> Result<(usize, f64), PcgFailure> {
        let dim = x.len();
        let mut r = x.to_vec();
        let bnorm = dot(&r, &r).sqrt();
        x.fill(0.0);
        if bnorm == 0.0 || !bnorm.is_finite() {
            return Ok((0, 0.0));
        }
        let mut z = vec![0.0; dim];
        let mut ap = vec![0.0; dim];
        self.precondition(&r, &mut z);
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let mut rnorm = bnorm;
        let mut it = 0;
        while it < max_iter && rnorm > tol * bnorm {
            self.matvec(&p, &mut ap);
            let pap = dot(&p, &ap);
            if pap <= 0.0 || !pap.is_finite() {
                return Err(PcgFailure::NotPositiveDefinite { index: it });
            }
            let alpha = rz / pap;
            axpy_pair(alpha, &p, x, &ap, &mut r);
            it += 1;
            rnorm = dot(&r, &r).sqrt();
            self.precondition(&r, &mut z);
            let rz_new = dot(&r, &z);
            let beta = rz_new / rz;
            rz = rz_new;
            p.par_chunks_mut(CHUNK)
                .zip(z.par_chunks(CHUNK))
                .for_each(|(p, z)| {
                    for (p, z) in p.iter_mut().zip(z) {
                        *p = z + beta * *p;
                    }
                });
        }
        Ok((it, rnorm / bnorm))
    }
}

/// `xᵀy`, summed per fixed chunk then serially (deterministic for any thread count).
fn dot(x: &[f64], y: &[f64]) -> f64 {
    let parts: Vec<f64> = x
        .par_chunks(CHUNK)
        .zip(y.par_chunks(CHUNK))
        .map(|(a, b)| a.iter().zip(b).map(|(a, b)| a * b).sum::<f64>())
        .collect();
    parts.iter().sum()
}

/// `x += α p`, `r −= α Ap`.
fn axpy_pair(alpha: f64, p: &[f64], x: &mut [f64], ap: &[f64], r: &mut [f64]) {
    x.par_chunks_mut(CHUNK)
        .zip(r.par_chunks_mut(CHUNK))
        .zip(p.par_chunks(CHUNK).zip(ap.par_chunks(CHUNK)))
        .for_each(|((x, r), (p, ap))| {
            for k in 0..x.len() {
                x[k] += alpha * p[k];
                r[k] -= alpha * ap[k];
            }
        });
}

/// Inverse of a symmetric positive definite `b×b` block (`b` ≤ 3, row-major) into `out`;
/// false when it is not positive definite.
fn invert_spd(m: &[f64], b: usize, out: &mut [f64]) -> bool {
    if b == 1 {
        if m[0] > 0.0 && m[0].is_finite() {
            out[0] = 1.0 / m[0];
            return true;
        }
        return false;
    }
    let (a, bb, c, d, e, f) = (m[0], m[1], m[2], m[4], m[5], m[8]);
    // Sylvester's criterion on the leading minors.
    let m2 = a * d - bb * bb;
    let c00 = d * f - e * e;
    let c01 = c * e - bb * f;
    let c02 = bb * e - c * d;
    let det = a * c00 + bb * c01 + c * c02;
    if !(a > 0.0 && m2 > 0.0 && det > 0.0 && det.is_finite()) {
        return false;
    }
    let c11 = a * f - c * c;
    let c12 = bb * c - a * e;
    let c22 = m2;
    let inv = 1.0 / det;
    let adj = [c00, c01, c02, c01, c11, c12, c02, c12, c22];
    for (o, v) in out.iter_mut().zip(adj) {
        *o = v * inv;
    }
    true
}
