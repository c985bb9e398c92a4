//! Fill-reducing orderings computed on the *block* graph of the normal matrix (one node per
//! control point; DESIGN.md §3.3) and expanded to its 3×3 blocks: approximate minimum degree
//! (Amestoy, Davis & Duff 1996, via `faer`) and nested dissection (George 1973) with
//! breadth-first level-set separators, which suit the surface-like graphs of control meshes
//! (separators of O(√n) nodes, fill O(n log n)).
//!
//! An ordering is an elimination order `order[k]` = the node eliminated `k`-th (`faer`'s
//! forward permutation).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::amd;
use faer::sparse::SymbolicSparseColMatRef;

use crate::assemble::Pattern;

/// Which fill-reducing ordering the sparse Cholesky uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum FillOrdering {
    /// `faer`'s AMD on the scalar `3n × 3n` pattern.
    ScalarAmd,
    /// AMD on the `n × n` block pattern, expanded to 3×3 blocks: the same fill as
    /// [`Self::ScalarAmd`] (AMD finds the 3×3 supervariables itself) from a 9× smaller graph,
    /// so a cheaper analysis. The default.
    #[default]
    BlockAmd,
    /// Nested dissection of the block graph with level-set separators, expanded to 3×3
    /// blocks. On Igea at 10k control points its factor is 1.45× AMD's: the sample
    /// stencils make the graph too wide for level-set separators.
    NestedDissection,
}

/// Symmetric adjacency of the block graph of a [`Pattern`] (CSR, no self loops).
#[derive(Clone, Debug, Default)]
pub struct BlockGraph {
    ptr: Vec<usize>,
    adj: Vec<u32>,
}

impl BlockGraph {
    /// The block graph of `pattern`: `i ~ j` when block `(i, j)` of `H` is stored.
    /// Cost: O(n + block nnz).
    pub fn from_pattern(pattern: &Pattern) -> Self {
        let n = pattern.num_points();
        let mut deg = vec![0usize; n + 1];
        for j in 0..n {
            for &i in pattern.block_col(j) {
                if i as usize != j {
                    deg[i as usize + 1] += 1;
                    deg[j + 1] += 1;
                }
            }
        }
        for j in 0..n {
            deg[j + 1] += deg[j];
        }
        let mut next = deg.clone();
        let mut adj = vec![0u32; deg[n]];
        for j in 0..n {
            for &i in pattern.block_col(j) {
                if i as usize != j {
                    adj[next[i as usize]] = j as u32;
                    next[i as usize] += 1;
                    adj[next[j]] = i;
                    next[j] += 1;
                }
            }
        }
        Self { ptr: deg, adj }
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.ptr.len().saturating_sub(1)
    }

    /// True without nodes.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Neighbours of node `i`.
    pub fn neighbors(&self, i: usize) -> &[u32] {
        &self.adj[self.ptr[i]..self.ptr[i + 1]]
    }
}

/// AMD elimination order of the block pattern of `pattern` (`n` entries).
/// Cost: about that of AMD on a graph with `n` nodes and the block nonzeros.
pub fn block_amd(pattern: &Pattern) -> Result<Vec<usize>, String> {
    let n = pattern.num_points();
    let mut col_ptr = Vec::with_capacity(n + 1);
    let mut row_idx = Vec::new();
    col_ptr.push(0usize);
    for j in 0..n {
        row_idx.extend(pattern.block_col(j).iter().map(|&i| i as usize));
        col_ptr.push(row_idx.len());
    }
    let a = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
    let mut fwd = vec![0usize; n];
    let mut inv = vec![0usize; n];
    let mut buf = MemBuffer::try_new(amd::order_scratch::<usize>(n, row_idx.len()))
        .map_err(|e| format!("{e:?}"))?;
    amd::order(
        &mut fwd,
        &mut inv,
        a,
        amd::Control::default(),
        MemStack::new(&mut buf),
    )
    .map_err(|e| format!("{e:?}"))?;
    Ok(fwd)
}

/// Nested-dissection elimination order of `g` (`n` entries): each connected part is split by
/// the middle level of a breadth-first level structure rooted at a pseudo-peripheral node
/// (separator nodes without a neighbour in the far part are moved to the near part); parts of
/// at most `leaf` nodes are ordered breadth-first. Deterministic.
///
/// Cost: O((n + |E|) · log n).
pub fn nested_dissection(g: &BlockGraph, leaf: usize) -> Vec<usize> {
    let n = g.len();
    let mut nd = Dissection {
        g,
        part: vec![0u32; n],
        level: vec![u32::MAX; n],
        next_part: 1,
        leaf: leaf.max(1),
    };
    let mut order = Vec::with_capacity(n);
    let all: Vec<u32> = (0..n as u32).collect();
    nd.order(all, &mut order);
    debug_assert_eq!(order.len(), n);
    order
}

/// Expands a block elimination order to block size `b` (each node `i` becomes the scalar
/// unknowns `b·i .. b·i + b`).
pub fn expand(order: &[usize], b: usize) -> Vec<usize> {
    order
        .iter()
        .flat_map(|&i| (0..b).map(move |a| b * i + a))
        .collect()
}

/// The inverse of a permutation.
pub fn inverse(perm: &[usize]) -> Vec<usize> {
    let mut inv = vec![0usize; perm.len()];
    for (k, &i) in perm.iter().enumerate() {
        inv[i] = k;
    }
    inv
}

struct Dissection<'g> {
    g: &'g BlockGraph,
    /// Part id of each node (nodes of the part being processed share one id).
    part: Vec<u32>,
    /// BFS level scratch (valid for the nodes of the current BFS only).
    level: Vec<u32>,
    next_part: u32,
    leaf: usize,
}

impl Dissection<'_> {
    fn fresh_part(&mut self, nodes: &[u32]) -> u32 {
        let id = self.next_part;
        self.next_part += 1;
        for &v in nodes {
            self.part[v as usize] = id;
        }
        id
    }

    /// BFS within part `id` from `root`; returns nodes in visiting order and sets `level`.
    fn bfs(&mut self, root: u32, id: u32) -> Vec<u32> {
        let mut out = vec![root];
        self.level[root as usize] = 0;
        let mut head = 0;
        while head < out.len() {
            let v = out[head] as usize;
            head += 1;
            let lv = self.level[v];
            for &w in self.g.neighbors(v) {
                let wu = w as usize;
                if self.part[wu] == id && self.level[wu] == u32::MAX {
                    self.level[wu] = lv + 1;
                    out.push(w);
                }
            }
        }
        out
    }

    fn clear_levels(&mut self, nodes: &[u32]) {
        for &v in nodes {
            self.level[v as usize] = u32::MAX;
        }
    }

    /// Appends the elimination order of `nodes` (all of one part) to `out`.
    fn order(&mut self, nodes: Vec<u32>, out: &mut Vec<usize>) {
        if nodes.is_empty() {
            return;
        }
        let id = self.fresh_part(&nodes);
        let reached = self.bfs(nodes[0], id);
        if reached.len() < nodes.len() {
            // Several components: order each separately.
            self.clear_levels(&reached);
            let mut comps = Vec::new();
            for &v in &nodes {
                if self.part[v as usize] == id {
                    let c = self.bfs(v, id);
                    self.clear_levels(&c);
                    for &w in &c {
                        self.part[w as usize] = u32::MAX;
                    }
                    comps.push(c);
                }
            }
            for c in comps {
                self.order(c, out);
            }
            return;
        }
        if nodes.len() <= self.leaf {
            self.clear_levels(&reached);
            out.extend(reached.iter().map(|&v| v as usize));
            return;
        }
        // Pseudo-peripheral root: restart the BFS from the farthest node while the
        // eccentricity grows (at most 3 times).
        let mut levels = reached;
        for _ in 0..3 {
            let far = *levels.last().expect("non-empty");
            let ecc = self.level[far as usize];
            self.clear_levels(&levels);
            levels = self.bfs(far, id);
            if self.level[*levels.last().expect("non-empty") as usize] <= ecc {
                break;
            }
        }
        let depth_max = self.level[*levels.last().expect("non-empty") as usize];
        if depth_max < 2 {
            self.clear_levels(&levels);
            out.extend(levels.iter().map(|&v| v as usize));
            return;
        }
        // Middle level by count.
        let half = nodes.len() / 2;
        let sep_level = self.level[levels[half] as usize].clamp(1, depth_max - 1);
        let mut near = Vec::new();
        let mut far = Vec::new();
        let mut sep = Vec::new();
        for &v in &levels {
            let l = self.level[v as usize];
            if l < sep_level {
                near.push(v);
            } else if l > sep_level {
                far.push(v);
            } else {
                // Separator node: only needed when it touches the far side.
                let touches_far = self
                    .g
                    .neighbors(v as usize)
                    .iter()
                    .any(|&w| self.part[w as usize] == id && self.level[w as usize] == l + 1);
                if touches_far {
                    sep.push(v);
                } else {
                    near.push(v);
                }
            }
        }
        self.clear_levels(&levels);
        self.order(near, out);
        self.order(far, out);
        out.extend(sep.iter().map(|&v| v as usize));
    }
}
