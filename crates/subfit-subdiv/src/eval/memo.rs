//! The memoised local-refinement tree of each patch: the first [`CACHE_DEPTH`] levels of local
//! refinement around irregular vertices are kept, within a memory budget.

use super::basis::{child_maps, ChildMap, PatchCoef};
use super::shape::Shape;
use crate::local::{children, regular_patch, LocalMesh};
use crate::scheme::Scheme;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

/// Default budget of the memoised local refinements of an [`Evaluator`](super::Evaluator): 256 MiB.
pub const DEFAULT_CACHE_BYTES: usize = 256 << 20;

/// Heap bytes held by memoised nodes and by interned shapes (approximate: array payloads
/// only), and the budget beyond which no more of each are kept. The two are counted apart:
/// nodes are per patch and fill the budget on a large cage, shapes are shared by every patch of
/// the same local topology, and the shape walk is what keeps evaluation fast once the nodes
/// are full (a 5,000-vertex Loop cage of a noisy scan filled 256 MiB of nodes within 20k
/// evaluations, and each evaluation then refined from the root).
#[derive(Debug)]
pub(super) struct MemoBudget {
    pub(super) used: AtomicUsize,
    pub(super) shape_used: AtomicUsize,
    pub(super) budget: usize,
}

impl Clone for MemoBudget {
    fn clone(&self) -> Self {
        Self {
            used: AtomicUsize::new(self.used.load(Ordering::Relaxed)),
            shape_used: AtomicUsize::new(self.shape_used.load(Ordering::Relaxed)),
            budget: self.budget,
        }
    }
}

impl MemoBudget {
    pub(super) fn new(budget: usize) -> Self {
        Self {
            used: AtomicUsize::new(0),
            shape_used: AtomicUsize::new(0),
            budget,
        }
    }

    /// Whether the memoised nodes fill the budget.
    pub(super) fn full(&self) -> bool {
        self.used.load(Ordering::Relaxed) >= self.budget
    }

    /// Whether the interned shapes and steps fill the budget.
    pub(super) fn shapes_full(&self) -> bool {
        self.shape_used.load(Ordering::Relaxed) >= self.budget
    }

    pub(super) fn add_shape_bytes(&self, bytes: usize) {
        self.shape_used.fetch_add(bytes, Ordering::Relaxed);
    }

    /// Both counts.
    pub(super) fn total(&self) -> usize {
        self.used.load(Ordering::Relaxed) + self.shape_used.load(Ordering::Relaxed)
    }

    pub(super) fn add(&self, node: &Node) {
        self.add_bytes(node.heap_bytes());
    }

    pub(super) fn add_bytes(&self, bytes: usize) {
        self.used.fetch_add(bytes, Ordering::Relaxed);
    }
}

/// Local refinement levels whose results are memoised per patch: evaluations reuse the refined
/// neighbourhoods and the regular sub-patches of the first `CACHE_DEPTH` levels (memory: up to a
/// few tens of kB per irregular patch that has been evaluated near its irregular corners).
pub const CACHE_DEPTH: u32 = 4;

/// A node of a patch's memoised local-refinement tree.
#[derive(Clone, Debug)]
pub(super) enum Node {
    /// A regular (sub-)patch.
    Regular(PatchCoef),
    /// An irregular (sub-)patch: its refined neighbourhood and, lazily, its four children.
    Irregular {
        /// Boxed, so a node (and each of the four child cells) stays small.
        mesh: Box<LocalMesh>,
        t: usize,
        kids: Box<[OnceLock<Node>; 4]>,
        /// The parameter maps of the children of face `t` (order of [`children`]), kept so
        /// that walking the tree does not recompute them.
        maps: Vec<ChildMap>,
        /// The interned topology of `mesh`, for the walk below the memoised levels.
        shape: OnceLock<Arc<Shape>>,
    },
    /// Local refinement failed (a broken invariant, reported as [`EvalError::Incomplete`](super::EvalError::Incomplete)).
    Failed,
}

impl Node {
    /// Approximate heap bytes of this node (not of its children).
    fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        match self {
            Node::Regular(pc) => pc.cols.len() * 4 + pc.coef.len() * 8,
            Node::Irregular { mesh, maps, .. } => {
                mesh.cols.len() * 4
                    + mesh.rows.len() * 8
                    + (mesh.fo.len() + mesh.fv.len() + mesh.nfaces.len()) * 4
                    + mesh.fe.len()
                    + (mesh.fs.len() + mesh.vs.len()) * 4
                    + mesh.corner.len()
                    + maps.len() * size_of::<ChildMap>()
                    + size_of::<[OnceLock<Node>; 4]>()
            }
            Node::Failed => 0,
        }
    }
}

/// A tree node for face `t` of `mesh`: regular patch or irregular (to be refined further).
/// Columns of `mesh` whose weights are all zero are dropped first (exact: they contribute
/// nothing), so deep nodes keep only the few control points they depend on.
pub(super) fn make_node(mut mesh: LocalMesh, t: usize, scheme: Scheme) -> Node {
    compact(&mut mesh);
    let adj = mesh.adjacency();
    match regular_patch(&mesh, &adj, scheme, t) {
        Some(c) => Node::Regular(PatchCoef::new(&mesh, &c)),
        None => Node::Irregular {
            t,
            kids: Box::new(std::array::from_fn(|_| OnceLock::new())),
            maps: child_maps(&children(&mesh, scheme, t)),
            shape: OnceLock::new(),
            mesh: Box::new(mesh),
        },
    }
}

/// Drops the columns of `mesh` whose weights are zero in every row. Cost O(nv · K).
fn compact(mesh: &mut LocalMesh) {
    let k = mesh.k();
    let keep: Vec<usize> = (0..k)
        .filter(|&j| mesh.rows.chunks_exact(k).any(|r| r[j] != 0.0))
        .collect();
    if keep.len() == k {
        return;
    }
    let rows = mesh
        .rows
        .chunks_exact(k)
        .flat_map(|r| keep.iter().map(move |&j| r[j]))
        .collect();
    mesh.cols = keep.iter().map(|&j| mesh.cols[j]).collect();
    mesh.rows = rows;
}
