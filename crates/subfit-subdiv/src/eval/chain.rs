//! The walk through interned shapes (module `shape`) as an [`Evaluator`]'s methods: each local
//! refinement step from a shape to a child computed on first use, and evaluation rows pulled
//! back through a chain of steps onto the control points.
//!
//! Stam 1998 (*Exact evaluation of Catmull-Clark subdivision surfaces at arbitrary parameter
//! values*): one local subdivision matrix serves every level where the topology repeats, so a
//! query applies `valsᵀ · C · S_d ⋯ S_1 · R` (`C` the regular patch's control points, `R` the
//! rows of the neighbourhood the walk started from), O(6 · nnz(S)) per level instead of one
//! local refinement.

use super::basis::patch_weights;
use super::evaluator::Evaluator;
use super::shape::{Shape, Step};
use super::types::EvalWeights;
use crate::local::{Combo, LocalMesh};
use std::sync::Arc;

impl Evaluator {
    /// The step from `shape` to its child `which`, computed on first use (local refinement of
    /// identity rows, [`Self::refine_local`]); `None` if that refinement fails. Memory is
    /// counted against the cache budget.
    pub(super) fn shape_step<'s>(&self, shape: &'s Shape, which: usize) -> Option<&'s Step> {
        shape.kids[which]
            .get_or_init(|| {
                let nv = shape.mesh.nv();
                let mut ident = LocalMesh {
                    cols: (0..nv as u32).collect(),
                    rows: vec![0.0; nv * nv],
                    ..shape.mesh.clone()
                };
                for i in 0..nv {
                    ident.rows[i * nv + i] = 1.0;
                }
                let (child, c, _) = self.refine_local(&ident, shape.t, which)?;
                let (mut off, mut idx, mut w) = (vec![0u32], Vec::new(), Vec::new());
                for i in 0..child.nv() {
                    for (j, &x) in child.row(i as u32).iter().enumerate() {
                        if x != 0.0 {
                            idx.push(j as u32);
                            w.push(x);
                        }
                    }
                    off.push(idx.len() as u32);
                }
                let (child, bytes) = self.shapes.intern(&child, c, self.options.scheme);
                let step = Step { child, off, idx, w };
                self.memo.add_shape_bytes(bytes + step.heap_bytes());
                Some(Arc::new(step))
            })
            .as_deref()
    }

    /// The evaluation at the end of `chain`: `vals` (per point of the regular patch `combos`
    /// of `last`, its six weights from [`chain_basis`](super::basis::chain_basis)) pulled back
    /// through the steps onto the control points of `rows` (`nv_0 × K`):
    /// `valsᵀ · C · S_d ⋯ S_1 · R`, six rows instead of the patch's 16 all the way down.
    /// Keeps the columns with a nonzero weight, by ascending control-point id.
    pub(super) fn chain_eval(
        rows: &LocalMesh,
        chain: &[&Step],
        last: &Shape,
        combos: &[Combo],
        vals: &[[f64; 6]; 16],
        depth: u32,
    ) -> EvalWeights {
        let mut nv = last.mesh.nv();
        let mut p = vec![0.0; 6 * nv];
        for (c, val) in combos.iter().zip(vals) {
            for &(v, w) in &c.terms[..c.n as usize] {
                for (o, &x) in val.iter().enumerate() {
                    p[o * nv + v as usize] += x * w;
                }
            }
        }
        let parents = chain
            .iter()
            .rev()
            .skip(1)
            .map(|s| s.child.mesh.nv())
            .chain([rows.nv()]);
        // One scratch buffer for all levels, swapped with `p` after each.
        let mut q = Vec::new();
        for (s, parent_nv) in chain.iter().rev().zip(parents) {
            q.clear();
            q.resize(6 * parent_nv, 0.0);
            for (po, qo) in p.chunks_exact(nv).zip(q.chunks_exact_mut(parent_nv)) {
                for (j, &x) in po.iter().enumerate() {
                    if x != 0.0 {
                        for (l, w) in s.row(j) {
                            qo[l] += x * w;
                        }
                    }
                }
            }
            std::mem::swap(&mut p, &mut q);
            nv = parent_nv;
        }
        let k = rows.k();
        let mut dense = vec![0.0; 6 * k];
        for (po, out) in p.chunks_exact(nv).zip(dense.chunks_exact_mut(k)) {
            for (j, &x) in po.iter().enumerate() {
                if x != 0.0 {
                    for (o, r) in out.iter_mut().zip(rows.row(j as u32)) {
                        *o += x * r;
                    }
                }
            }
        }
        let mut order: Vec<usize> = (0..k)
            .filter(|&j| (0..6).any(|o| dense[o * k + j] != 0.0))
            .collect();
        order.sort_by_key(|&j| rows.cols[j]);
        let pick = |o: usize| {
            order
                .iter()
                .map(|&j| dense[o * k + j])
                .collect::<Vec<f64>>()
        };
        let out = std::array::from_fn(pick);
        patch_weights(order.iter().map(|&j| rows.cols[j]).collect(), out, depth)
    }

    /// The neighbourhood at the end of `chain` with rows over `rows`' columns (forward
    /// application of the steps), for the rare cases the shape walk does not finish itself.
    pub(super) fn chain_mesh(rows: &LocalMesh, chain: &[&Step]) -> LocalMesh {
        let mut cur = rows.clone();
        let k = rows.k();
        for s in chain {
            let nc = s.child.mesh.nv();
            let mut next = vec![0.0; nc * k];
            for i in 0..nc {
                let out = &mut next[i * k..(i + 1) * k];
                for (j, w) in s.row(i) {
                    for (o, r) in out.iter_mut().zip(cur.row(j as u32)) {
                        *o += w * r;
                    }
                }
            }
            cur = LocalMesh {
                cols: rows.cols.clone(),
                rows: next,
                ..s.child.mesh.clone()
            };
        }
        cur
    }
}
