//! Interned local topologies ("shapes") below the memoised levels, and each local refinement
//! step between them as a sparse matrix over the parent's local vertices (computed and applied
//! in module `chain`).
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

use super::basis::{child_maps, ChildMap};
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
    pub(super) kids: Vec<OnceLock<Option<Arc<Step>>>>,
}

/// One local refinement step: the child neighbourhood's shape and the rows of its vertices
/// over the parent's local vertices (sparse, by child vertex).
#[derive(Debug)]
pub(super) struct Step {
    /// The shape of the child neighbourhood.
    pub(super) child: Arc<Shape>,
    /// Row offsets (`nv_child + 1`).
    pub(super) off: Vec<u32>,
    /// Parent local vertex of each weight.
    pub(super) idx: Vec<u32>,
    /// Weights.
    pub(super) w: Vec<f64>,
}

impl Step {
    /// The weights of child vertex `i` over parent local vertices.
    pub(super) fn row(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let r = self.off[i] as usize..self.off[i + 1] as usize;
        self.idx[r.clone()]
            .iter()
            .zip(&self.w[r])
            .map(|(&j, &w)| (j as usize, w))
    }

    /// Approximate heap bytes (array payloads).
    pub(super) fn heap_bytes(&self) -> usize {
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
