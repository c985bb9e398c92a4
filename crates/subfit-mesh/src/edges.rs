//! Grouping directed half-edges by undirected edge, and a union-find, shared by the half-edge
//! builder and the diagnostics.
//!
//! Half-edges are identified with face corners: half-edge `h` is corner `h` of the polygon list
//! (`indices[h]`), running from `indices[h]` to the next corner of the same face. Grouping is a
//! counting sort on the smaller endpoint (`O(#V + #H)`) followed by a sort of each (small) bucket
//! on the larger endpoint, so the cost is linear in practice and the order is deterministic:
//! edges come out sorted by `(min, max)` endpoint, and half-edges of one edge by id.

use crate::polygons::Polygons;

/// Half-edges grouped by undirected edge.
pub(crate) struct EdgeGroups {
    /// Half-edge ids (corner indices), edge after edge; `#H'` entries where `H'` counts the
    /// half-edges of the included faces.
    pub order: Vec<u32>,
    /// Start of each edge's run in `order` (`#E + 1` entries).
    pub starts: Vec<u32>,
}

impl EdgeGroups {
    /// Number of undirected edges.
    #[inline]
    pub fn len(&self) -> usize {
        self.starts.len() - 1
    }

    /// The half-edges of edge `e`.
    #[inline]
    pub fn group(&self, e: usize) -> &[u32] {
        &self.order[self.starts[e] as usize..self.starts[e + 1] as usize]
    }
}

/// Per half-edge (corner) the face it belongs to (`#H` entries). Cost `O(#H)`.
pub(crate) fn corner_faces(faces: &Polygons) -> Vec<u32> {
    let mut out = vec![0u32; faces.indices().len()];
    for (f, w) in faces.offsets().windows(2).enumerate() {
        out[w[0] as usize..w[1] as usize].fill(f as u32);
    }
    out
}

/// Per half-edge (corner) the next corner of the same face (`#H` entries). Cost `O(#H)`.
pub(crate) fn corner_next(faces: &Polygons) -> Vec<u32> {
    let mut out: Vec<u32> = (1..=faces.indices().len() as u32).collect();
    for w in faces.offsets().windows(2) {
        if w[1] > w[0] {
            out[w[1] as usize - 1] = w[0];
        }
    }
    out
}

/// Groups the half-edges of the faces with `include[f]` by undirected edge.
///
/// `next` is [`corner_next`]; every included face must have in-range vertex ids
/// (`< num_vertices`). Cost: `O(#V + #H)` plus a sort of each smaller-endpoint bucket.
pub(crate) fn group_edges(
    faces: &Polygons,
    next: &[u32],
    num_vertices: usize,
    include: impl Fn(usize) -> bool,
) -> EdgeGroups {
    let idx = faces.indices();
    let offs = faces.offsets();
    let key = |h: usize| {
        let (a, b) = (idx[h], idx[next[h] as usize]);
        (a.min(b), a.max(b))
    };
    // Counting sort by the smaller endpoint; entries are `(larger endpoint << 32) | half-edge`
    // so each bucket sorts as plain integers.
    let mut count = vec![0u32; num_vertices + 1];
    for (f, w) in offs.windows(2).enumerate() {
        if include(f) {
            for h in w[0] as usize..w[1] as usize {
                count[key(h).0 as usize + 1] += 1;
            }
        }
    }
    for i in 0..num_vertices {
        count[i + 1] += count[i];
    }
    let total = count[num_vertices] as usize;
    let mut packed = vec![0u64; total];
    let mut fill = count.clone();
    for (f, w) in offs.windows(2).enumerate() {
        if include(f) {
            for h in w[0] as usize..w[1] as usize {
                let (lo, hi) = key(h);
                let slot = &mut fill[lo as usize];
                packed[*slot as usize] = (u64::from(hi) << 32) | h as u64;
                *slot += 1;
            }
        }
    }
    drop(fill);
    // Sort each bucket, then split into runs of equal larger endpoint.
    let mut starts = Vec::with_capacity(total / 2 + 2);
    for v in 0..num_vertices {
        let (a, b) = (count[v] as usize, count[v + 1] as usize);
        let bucket = &mut packed[a..b];
        if bucket.len() > 1 {
            bucket.sort_unstable();
        }
        let mut prev = u64::MAX;
        for (i, &x) in bucket.iter().enumerate() {
            if x >> 32 != prev {
                starts.push((a + i) as u32);
                prev = x >> 32;
            }
        }
    }
    starts.push(total as u32);
    let order = packed.into_iter().map(|x| x as u32).collect();
    EdgeGroups { order, starts }
}

/// The fans of corners: a union-find over the corners (half-edge ids) of `faces` in which two
/// corners at a vertex are joined when their faces share an edge at it (through any number of
/// sides), for the edges `groups` of [`group_edges`] with `next` of [`corner_next`]. A vertex
/// whose corners have several roots is a bowtie. Cost `O(#H · α)`.
pub(crate) fn corner_fans(faces: &Polygons, groups: &EdgeGroups, next: &[u32]) -> UnionFind {
    let idx = faces.indices();
    let mut fans = UnionFind::new(idx.len());
    for e in 0..groups.len() {
        let g = groups.group(e);
        let a = idx[g[0] as usize];
        // Corner at the origin of h is h; at its destination, next[h].
        let (mut at_a, mut at_b) = (u32::MAX, u32::MAX);
        for &h in g {
            let (ca, cb) = if idx[h as usize] == a {
                (h, next[h as usize])
            } else {
                (next[h as usize], h)
            };
            for (c, first) in [(ca, &mut at_a), (cb, &mut at_b)] {
                if *first == u32::MAX {
                    *first = c;
                } else {
                    fans.union(*first, c);
                }
            }
        }
    }
    fans
}

/// Union-find over `0..n` with path halving and union by size. Each operation costs amortized
/// `O(α(n))`.
pub struct UnionFind {
    parent: Vec<u32>,
    size: Vec<u32>,
}

impl UnionFind {
    /// `n` singleton sets.
    pub fn new(n: usize) -> Self {
        Self {
            parent: (0..n as u32).collect(),
            size: vec![1; n],
        }
    }

    /// Representative of the set holding `x`.
    pub fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let gp = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = gp;
            x = gp;
        }
        x
    }

    /// Merges the sets of `a` and `b`; returns whether they were distinct.
    pub fn union(&mut self, a: u32, b: u32) -> bool {
        let (mut ra, mut rb) = (self.find(a), self.find(b));
        if ra == rb {
            return false;
        }
        if self.size[ra as usize] < self.size[rb as usize] {
            std::mem::swap(&mut ra, &mut rb);
        }
        self.parent[rb as usize] = ra;
        self.size[ra as usize] += self.size[rb as usize];
        true
    }
}

/// Union-find whose elements carry a parity relative to their root (for orientability: parity
/// 1 means "flipped relative to the root"). Amortized `O(log n)` per operation (path halving is
/// replaced by full path compression with parity accumulation).
pub(crate) struct ParityUnionFind {
    parent: Vec<u32>,
    parity: Vec<u8>,
    size: Vec<u32>,
}

impl ParityUnionFind {
    /// `n` singleton sets with parity 0.
    pub fn new(n: usize) -> Self {
        Self {
            parent: (0..n as u32).collect(),
            parity: vec![0; n],
            size: vec![1; n],
        }
    }

    /// Root of `x` and the parity of `x` relative to it.
    pub fn find(&mut self, x: u32) -> (u32, u8) {
        // First pass: find root and the parity along the path.
        let mut root = x;
        let mut p = 0u8;
        while self.parent[root as usize] != root {
            p ^= self.parity[root as usize];
            root = self.parent[root as usize];
        }
        // Second pass: compress, fixing each node's parity to be relative to the root.
        let mut cur = x;
        let mut cur_p = p;
        while self.parent[cur as usize] != root && cur != root {
            let next = self.parent[cur as usize];
            let next_p = cur_p ^ self.parity[cur as usize];
            self.parent[cur as usize] = root;
            self.parity[cur as usize] = cur_p;
            cur = next;
            cur_p = next_p;
        }
        (root, p)
    }

    /// Requires `parity(a) ^ parity(b) == rel`. Returns `false` when that contradicts what is
    /// already known (an odd cycle: non-orientable).
    pub fn relate(&mut self, a: u32, b: u32, rel: u8) -> bool {
        let (ra, pa) = self.find(a);
        let (rb, pb) = self.find(b);
        if ra == rb {
            return pa ^ pb == rel;
        }
        let (big, small) = if self.size[ra as usize] >= self.size[rb as usize] {
            (ra, rb)
        } else {
            (rb, ra)
        };
        self.parent[small as usize] = big;
        self.parity[small as usize] = pa ^ pb ^ rel;
        self.size[big as usize] += self.size[small as usize];
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_are_sorted_and_complete() {
        let p = Polygons::from_triangles(&[[0, 1, 2], [2, 1, 3]]);
        let next = corner_next(&p);
        let g = group_edges(&p, &next, 4, |_| true);
        assert_eq!(g.len(), 5);
        assert_eq!(g.order.len(), 6);
        // Edge (1, 2) is shared by corners 1 (1→2) and 3 (2→1).
        let shared: Vec<_> = (0..g.len()).filter(|&e| g.group(e).len() == 2).collect();
        assert_eq!(shared.len(), 1);
        assert_eq!(g.group(shared[0]), &[1, 3]);
    }

    #[test]
    fn parity_detects_odd_cycles() {
        let mut u = ParityUnionFind::new(3);
        assert!(u.relate(0, 1, 1));
        assert!(u.relate(1, 2, 1));
        assert!(u.relate(0, 2, 0));
        assert!(!u.relate(2, 0, 1));
        let mut s = UnionFind::new(3);
        assert!(s.union(0, 2));
        assert!(!s.union(2, 0));
        assert_eq!(s.find(0), s.find(2));
    }
}
