//! Interned local topologies ("shapes") below the memoised levels, and each local refinement
//! step between them as a sparse matrix over the parent's local vertices.
//!
//! Stam 1998 (*Exact evaluation of Catmull-Clark subdivision surfaces at arbitrary parameter
//! values*): near an irregular vertex the two-ring's topology repeats from level to level, so
//! one local subdivision matrix serves every level. The same holds along a quad/triangle seam
//! (Stam & Loop 2003, *Quad/triangle subdivision*), where patches are never regular at any
//! level and every point near a seam descends `log2(1 / distance)` levels: a handful of seam
//! topologies recur along every seam. So the topology of each local neighbourhood is interned
//! once per [`Evaluator`](super::Evaluator) (with its regular patch, if any, and its children's
//! parameter maps), each refinement step from a shape to a child is computed once (by local
//! refinement of identity rows) and kept as a sparse matrix, and a query only walks the shapes
//! and pulls the six evaluation rows (position, two first and three second derivatives) back
//! through the steps: `valsᵀ · C · S_d ⋯ S_1 · R` (`C` the regular patch's control points, `R`
//! the rows of the neighbourhood the walk started from), O(6 · nnz(S)) per level instead of
//! one local refinement.

use super::basis::{child_maps, patch_weights, ChildMap};
use super::types::EvalWeights;
use crate::local::{children, regular_patch, Combo, LocalMesh};
use crate::scheme::Scheme;
use std::collections::HashMap;
use std::sync::{Arc, OnceLock, RwLock};

/// The topology of a local neighbourhood (a [`LocalMesh`] without rows) and the face of
/// interest in it, with what evaluation needs of it.
#[derive(Debug)]
pub(super) struct Shape {
    /// The topology; `cols` and `rows` are empty.
    pub(super) mesh: LocalMesh,
    /// The face of interest.
    pub(super) t: usize,
    /// The regular patch's control points of face `t`, if it is regular.
    pub(super) patch: Option<Vec<Combo>>,
    /// The parameter maps of the children of face `t` (order of [`children`]).
    pub(super) maps: Vec<ChildMap>,
    /// Per child: the refinement step to its neighbourhood (`None`: local refinement failed).
    kids: Vec<OnceLock<Option<Arc<Step>>>>,
}

/// One local refinement step: the child neighbourhood's shape and the rows of its vertices
/// over the parent's local vertices (sparse, by child vertex).
#[derive(Debug)]
pub(super) struct Step {
    /// The shape of the child neighbourhood.
    pub(super) child: Arc<Shape>,
    /// Row offsets (`nv_child + 1`).
    off: Vec<u32>,
    /// Parent local vertex of each weight.
    idx: Vec<u32>,
    /// Weights.
    w: Vec<f64>,
}

impl Step {
    /// The weights of child vertex `i` over parent local vertices.
    fn row(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let r = self.off[i] as usize..self.off[i + 1] as usize;
        self.idx[r.clone()]
            .iter()
            .zip(&self.w[r])
            .map(|(&j, &w)| (j as usize, w))
    }

    fn heap_bytes(&self) -> usize {
        (self.off.len() + self.idx.len()) * 4 + self.w.len() * 8
    }
}

impl Shape {
    fn new(mesh: &LocalMesh, t: usize, scheme: Scheme) -> Self {
        let mesh = LocalMesh {
            cols: Vec::new(),
            rows: Vec::new(),
            ..mesh.clone()
        };
        let adj = mesh.adjacency();
        let patch = regular_patch(&mesh, &adj, scheme, t);
        let maps = child_maps(&children(&mesh, scheme, t));
        let kids = (0..maps.len()).map(|_| OnceLock::new()).collect();
        Self {
            mesh,
            t,
            patch,
            maps,
            kids,
        }
    }

    /// The step to child `which` if it has been computed.
    pub(super) fn step(&self, which: usize) -> Option<&Option<Arc<Step>>> {
        self.kids[which].get()
    }

    /// Approximate heap bytes (array payloads).
    fn heap_bytes(&self) -> usize {
        let m = &self.mesh;
        (m.fo.len() + m.fv.len() + m.fs.len() + m.vs.len() + m.nfaces.len()) * 4
            + m.fe.len()
            + m.corner.len()
            + self.maps.len() * std::mem::size_of::<ChildMap>()
    }
}

/// The interned shapes of one evaluator (thread-safe; cloned with the evaluator).
#[derive(Debug, Default)]
pub(super) struct Shapes {
    map: RwLock<HashMap<Vec<u32>, Arc<Shape>>>,
}

impl Clone for Shapes {
    fn clone(&self) -> Self {
        Self {
            map: RwLock::new(self.map.read().expect("shape table lock").clone()),
        }
    }
}

/// The interning key: every topology array of `mesh` (with lengths) and `t`.
fn key(mesh: &LocalMesh, t: usize) -> Vec<u32> {
    let mut k = Vec::with_capacity(4 + mesh.fo.len() + 3 * mesh.fv.len() + 4 * mesh.nv());
    k.extend([t as u32, mesh.fo.len() as u32, mesh.nv() as u32]);
    k.extend_from_slice(&mesh.fo);
    k.extend_from_slice(&mesh.fv);
    k.extend(mesh.fe.iter().map(|&f| u32::from(f)));
    k.extend(mesh.fs.iter().map(|s| s.to_bits()));
    k.extend(mesh.vs.iter().map(|s| s.to_bits()));
    k.extend_from_slice(&mesh.nfaces);
    k.extend(mesh.corner.iter().map(|&c| u32::from(c)));
    k
}

impl Shapes {
    /// The shape of `(mesh, t)`, interned, and the heap bytes it added (0 if it was known).
    pub(super) fn intern(&self, mesh: &LocalMesh, t: usize, scheme: Scheme) -> (Arc<Shape>, usize) {
        let k = key(mesh, t);
        if let Some(s) = self.map.read().expect("shape table lock").get(&k) {
            return (s.clone(), 0);
        }
        let shape = Arc::new(Shape::new(mesh, t, scheme));
        let bytes = k.len() * 4 + shape.heap_bytes();
        let mut map = self.map.write().expect("shape table lock");
        let mut added = 0;
        let s = map
            .entry(k)
            .or_insert_with(|| {
                added = bytes;
                shape
            })
            .clone();
        (s, added)
    }

    /// Drops every shape.
    pub(super) fn clear(&mut self) {
        self.map.get_mut().expect("shape table lock").clear();
    }
}

impl super::Evaluator {
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
