//! A linear, 2:1-balanced octree and a conforming tetrahedralization of its leaves, for
//! contouring a function sampled at the leaves' nodes by marching tetrahedra
//! ([`crate::contour()`]).
//!
//! **Octree.** The root is a cube of `2^root_level` finest cells; a cell of level `l` has edge
//! `2^l` finest cells (level 0 is the finest). The tree is stored as the sorted set of *split*
//! cells per level (a linear octree, Gargantini 1982); leaves are the children of split cells
//! that are not split themselves. Balance: whenever a cell is split, every cell of its size
//! that touches it (across a face, an edge or a corner) exists, so leaves that touch differ
//! by at most one level (see [`Octree::balance`]). Then a leaf's face, edge and corner
//! neighbours are at most one level finer, and the only nodes on a leaf of edge `2s` lie on
//! the `3 × 3 × 3` lattice of spacing `s`: corners, edge midpoints and face centres (hanging
//! nodes).
//!
//! **Tetrahedralization** (marching tetrahedra on an adaptive grid, as in the crack-free
//! alternative to Schaefer & Warren's dual marching cubes that Cheng et al. 2007 §II-C use).
//! Each leaf face is triangulated by one global rule that depends only on the face and the
//! nodes on it, so the two leaves sharing a face triangulate it alike:
//! * face centre is a node (the leaf across is split): the 4 sub-squares, each cut along its
//!   diagonal from its lowest to its highest corner (the rule the finer side uses);
//! * else, some edge midpoint is a node: a fan from a Steiner point at the face centre over the
//!   boundary nodes in cyclic order (the leaf across has the same size and sees the same nodes);
//! * else: the diagonal from the lowest to the highest corner.
//!
//! A leaf with no hanging node is cut into the 6 tetrahedra of the Kuhn triangulation around its
//! main diagonal, whose faces follow the third rule; every other leaf into tetrahedra from its
//! centre to its face triangles. The union is a conforming tetrahedral mesh (every two
//! tetrahedra meet in a common face, edge, vertex or not at all), so the zero set of the
//! piecewise-linear interpolant is a closed 2-manifold without cracks at level transitions, for
//! any values with no exact zero.
//!
//! Coordinates are finest-lattice integers packed as `x | y << 21 | z << 42` ([`pack`]), whose
//! order is the z-major order of a uniform grid's node index.

/// Bits per packed coordinate; coordinates are below `2^21`.
const BITS: u32 = 21;
const MASK: u64 = (1 << BITS) - 1;

/// Packs lattice coordinates (each `< 2^21`) into one key; keys sort z-major, then y, then x.
pub(crate) fn pack(c: [u64; 3]) -> u64 {
    debug_assert!(c.iter().all(|&v| v <= MASK));
    c[0] | c[1] << BITS | c[2] << (2 * BITS)
}

/// The coordinates of a [`pack`]ed key.
pub(crate) fn unpack(k: u64) -> [u64; 3] {
    [k & MASK, (k >> BITS) & MASK, k >> (2 * BITS)]
}

/// The keys of `cells` (sorted) moved by every offset in `lo..=hi` along `axis`, clipped to
/// `0..limit`; sorted, without duplicates. Along x (the lowest bits) the output comes in order;
/// along y and z it is the merge of one sorted run per offset. Cost `O(m log(hi − lo + 1))` for
/// `m = |cells|·(hi − lo + 1)`.
pub(crate) fn dilate(cells: &[u64], axis: usize, lo: i64, hi: i64, limit: u64) -> Vec<u64> {
    debug_assert!(cells.windows(2).all(|w| w[0] < w[1]));
    let mut out = Vec::with_capacity(cells.len() * (hi - lo + 1) as usize);
    let moved = |k: u64, d: i64| {
        let mut c = unpack(k);
        let v = c[axis] as i64 + d;
        (0..limit as i64).contains(&v).then(|| {
            c[axis] = v as u64;
            pack(c)
        })
    };
    if axis == 0 {
        for &k in cells {
            for n in (lo..=hi).filter_map(|d| moved(k, d)) {
                if out.last().is_none_or(|&l| l < n) {
                    out.push(n);
                }
            }
        }
    } else {
        for d in lo..=hi {
            out.extend(cells.iter().filter_map(|&k| moved(k, d)));
        }
        // The stable sort finds the sorted runs and merges them.
        out.sort();
        out.dedup();
    }
    out
}

/// [`dilate`] along the three axes: the cells within Chebyshev offset `lo..=hi` of `cells`.
pub(crate) fn dilate3(cells: &[u64], lo: i64, hi: i64, limit: u64) -> Vec<u64> {
    let z = dilate(cells, 2, lo, hi, limit);
    let y = dilate(&z, 1, lo, hi, limit);
    dilate(&y, 0, lo, hi, limit)
}

/// Hashes integer keys (packed coordinates, node-id pairs) with the splitmix64 finalizer: a few
/// nanoseconds a key against ~20 for the standard SipHash, which dominated building the node
/// table; these keys come from our own lattice, so flooding resistance is not needed.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct KeyHash(u64);

impl std::hash::Hasher for KeyHash {
    fn finish(&self) -> u64 {
        let mut z = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = self.0.rotate_left(8) ^ u64::from(b);
        }
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = self.0.rotate_left(32) ^ v;
    }
    fn write_usize(&mut self, v: usize) {
        self.write_u64(v as u64);
    }
}

/// A `HashMap` with [`KeyHash`].
pub(crate) type KeyMap<K, V> =
    std::collections::HashMap<K, V, std::hash::BuildHasherDefault<KeyHash>>;

/// A leaf of the octree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Leaf {
    /// Packed finest-lattice coordinates of the lowest corner.
    pub(crate) min: u64,
    /// Level (edge `2^level` finest cells).
    pub(crate) level: u32,
}

impl Leaf {
    /// Packed key of the local lattice point `l ∈ {0, 1, 2}³` (spacing half the edge; a level-0
    /// leaf has only its corners, `l` even).
    pub(crate) fn point(&self, l: [u64; 3]) -> u64 {
        let m = unpack(self.min);
        pack([0, 1, 2].map(|k| m[k] + ((l[k] << self.level) >> 1)))
    }
    /// Packed key of local lattice point number `i = x + 3y + 9z`.
    pub(crate) fn point_at(&self, i: usize) -> u64 {
        self.point(local(i))
    }
}

/// Local lattice coordinates of point number `i = x + 3y + 9z` (`0..27`).
pub(crate) fn local(i: usize) -> [u64; 3] {
    [(i % 3) as u64, (i / 3 % 3) as u64, (i / 9) as u64]
}

/// Local index of corner `c = dx + 2dy + 4dz`.
pub(crate) const CORNERS: [usize; 8] = [0, 2, 6, 8, 18, 20, 24, 26];
/// Mask of the corners among the 27 local points.
pub(crate) const CORNER_MASK: u32 = {
    let mut m = 0;
    let mut c = 0;
    while c < 8 {
        m |= 1 << CORNERS[c];
        c += 1;
    }
    m
};
/// Local index of the leaf centre.
pub(crate) const CENTRE: usize = 13;
/// Local indices of the 12 edge midpoints and 6 face centres (the possible hanging nodes).
pub(crate) const HANGING: [usize; 18] = [
    1, 3, 5, 7, 9, 11, 15, 17, 19, 21, 23, 25, 4, 10, 12, 14, 16, 22,
];

/// Kuhn triangulation of a cube (corner `c = dx + 2dy + 4dz`) into 6 tetrahedra around the
/// diagonal 0–7; each face is cut along the diagonal from its lowest to its highest corner.
pub(crate) const KUHN: [[usize; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 1, 5, 7],
    [0, 2, 3, 7],
    [0, 2, 6, 7],
    [0, 4, 5, 7],
    [0, 4, 6, 7],
];

/// The local index of point `(u, v)` of face `f` (`f = 2·axis + side`, the face at local
/// coordinate `2·side` along `axis`; `u`, `v` run along the two other axes in increasing order).
fn face_point(f: usize, u: usize, v: usize) -> usize {
    let (axis, side) = (f / 2, 2 * (f % 2));
    let (a, b) = match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let mut l = [0; 3];
    l[axis] = side;
    l[a] = u;
    l[b] = v;
    l[0] + 3 * l[1] + 9 * l[2]
}

/// The local index of the centre of face `f`.
pub(crate) fn face_centre(f: usize) -> usize {
    face_point(f, 1, 1)
}

/// The boundary points of a face in cyclic order: corners and edge midpoints.
const CYCLE: [(usize, usize); 8] = [
    (0, 0),
    (1, 0),
    (2, 0),
    (2, 1),
    (2, 2),
    (1, 2),
    (0, 2),
    (0, 1),
];

/// Whether face `f` of a leaf with node mask `mask` needs a Steiner point at its centre: some
/// edge midpoint on it is a node, the centre is not.
pub(crate) fn face_needs_steiner(mask: u32, f: usize) -> bool {
    let has = |i: usize| mask & (1 << i) != 0;
    let mut midpoints = CYCLE.iter().skip(1).step_by(2);
    !has(face_point(f, 1, 1)) && midpoints.any(|&(u, v)| has(face_point(f, u, v)))
}

/// Appends the triangles of face `f` (local indices; see the module docs for the rule) for a
/// leaf whose nodes are `mask` (bit `i` set when local point `i` is a node).
fn face_triangles(mask: u32, f: usize, out: &mut Vec<[usize; 3]>) {
    let has = |i: usize| mask & (1 << i) != 0;
    let p = |u, v| face_point(f, u, v);
    if has(p(1, 1)) {
        for (i, j) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            out.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
            out.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    } else if face_needs_steiner(mask, f) {
        let ring: Vec<usize> = CYCLE
            .iter()
            .map(|&(u, v)| p(u, v))
            .filter(|&i| has(i))
            .collect();
        for k in 0..ring.len() {
            out.push([p(1, 1), ring[k], ring[(k + 1) % ring.len()]]);
        }
    } else {
        out.push([p(0, 0), p(2, 0), p(2, 2)]);
        out.push([p(0, 0), p(2, 2), p(0, 2)]);
    }
}

/// Appends the tetrahedra (local indices) of a leaf whose nodes are `mask`: Kuhn's 6 when it
/// has no hanging node, else one from the centre ([`CENTRE`]) to each face triangle. The
/// centre and the Steiner points ([`face_needs_steiner`]) must then be points too.
pub(crate) fn leaf_tets(mask: u32, out: &mut Vec<[usize; 4]>) {
    if mask == CORNER_MASK {
        out.extend(KUHN.iter().map(|t| t.map(|c| CORNERS[c])));
        return;
    }
    let mut tris = Vec::with_capacity(48);
    for f in 0..6 {
        face_triangles(mask, f, &mut tris);
    }
    out.extend(tris.iter().map(|t| [CENTRE, t[0], t[1], t[2]]));
}

/// A 2:1-balanced linear octree (see the module docs).
#[derive(Clone, Debug)]
pub(crate) struct Octree {
    root_level: u32,
    /// `split[l]`: packed level-`l` coordinates of the split cells of level `l`, sorted once
    /// [`Octree::balance`] has run (`split[0]` is empty).
    split: Vec<Vec<u64>>,
}

impl Octree {
    /// An unsplit root of `2^root_level` finest cells a side (`root_level ≤ 20`).
    #[track_caller]
    pub(crate) fn new(root_level: u32) -> Self {
        assert!(root_level < BITS, "octree of 2^{root_level} cells a side");
        Self {
            root_level,
            split: vec![Vec::new(); root_level as usize + 1],
        }
    }

    /// Cells a side at `level`.
    pub(crate) fn cells_at(&self, level: u32) -> u64 {
        1 << (self.root_level - level)
    }

    /// Marks the given cells of `level` (packed level coordinates, `1 ≤ level ≤ root_level`)
    /// as split. Their ancestors are split by [`Octree::balance`].
    #[track_caller]
    pub(crate) fn split(&mut self, level: u32, cells: impl IntoIterator<Item = u64>) {
        assert!((1..=self.root_level).contains(&level));
        self.split[level as usize].extend(cells);
    }

    /// Whether cell `cell` (packed level coordinates) of `level` is split; valid after
    /// [`Octree::balance`]. Cost `O(log n)`.
    pub(crate) fn is_split(&self, level: u32, cell: u64) -> bool {
        level > 0 && self.split[level as usize].binary_search(&cell).is_ok()
    }

    /// Splits the ancestors of every split cell and, finest level first, the parents of every
    /// cell touching a split cell of the same level, so that touching leaves differ by at most
    /// one level. Cost `O(n log n)` for `n` split cells (27 candidates each).
    pub(crate) fn balance(&mut self) {
        for l in 1..=self.root_level {
            let cells = std::mem::take(&mut self.split[l as usize]);
            let mut cells = cells;
            cells.sort_unstable();
            cells.dedup();
            if l < self.root_level {
                let around = dilate3(&cells, -1, 1, self.cells_at(l));
                let parents = around.iter().map(|&k| pack(unpack(k).map(|c| c >> 1)));
                self.split[l as usize + 1].extend(parents);
            }
            self.split[l as usize] = cells;
        }
    }

    /// The leaves, sorted by their lowest corner (for level-0 leaves, the order of a uniform
    /// grid's cells). Valid after [`Octree::balance`]. Cost `O(n log n)`.
    pub(crate) fn leaves(&self) -> Vec<Leaf> {
        let r = self.root_level;
        if self.split[r as usize].is_empty() {
            return vec![Leaf { min: 0, level: r }];
        }
        let mut out = Vec::new();
        for l in (0..r).rev() {
            for &p in &self.split[l as usize + 1] {
                let pc = unpack(p);
                for c in 0..8u64 {
                    let cc = [0, 1, 2].map(|k| 2 * pc[k] + (c >> k & 1));
                    if !self.is_split(l, pack(cc)) {
                        out.push(Leaf {
                            min: pack(cc.map(|v| v << l)),
                            level: l,
                        });
                    }
                }
            }
        }
        out.sort_unstable_by_key(|f| f.min);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every leaf triangle (tetrahedron face) appears in exactly two tetrahedra or on the root
    /// boundary: the tetrahedralization is conforming.
    fn check_conforming(tree: &Octree) {
        let leaves = tree.leaves();
        let mut nodes = std::collections::HashSet::new();
        for f in &leaves {
            for &c in &CORNERS {
                nodes.insert(f.point_at(c));
            }
        }
        let mut faces: std::collections::HashMap<[u64; 3], usize> = Default::default();
        let mut tets = Vec::new();
        let mut volume = 0u64;
        for f in &leaves {
            let mut mask = CORNER_MASK;
            if f.level > 0 {
                for &h in &HANGING {
                    if nodes.contains(&f.point_at(h)) {
                        mask |= 1 << h;
                    }
                }
            }
            tets.clear();
            leaf_tets(mask, &mut tets);
            let mut leaf_volume = 0;
            for t in &tets {
                let p = t.map(|i| unpack(f.point_at(i)).map(|c| c as i64));
                let d = |a: usize| [0, 1, 2].map(|k| p[a][k] - p[0][k]);
                let (a, b, c) = (d(1), d(2), d(3));
                let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]);
                assert_ne!(det, 0, "degenerate tetrahedron in {f:?}");
                leaf_volume += det.unsigned_abs();
                for skip in 0..4 {
                    let mut tri = [0u64; 3];
                    let mut n = 0;
                    for (k, &i) in t.iter().enumerate() {
                        if k != skip {
                            tri[n] = f.point_at(i);
                            n += 1;
                        }
                    }
                    tri.sort_unstable();
                    *faces.entry(tri).or_default() += 1;
                }
            }
            // 6 × the leaf's volume: the tetrahedra tile the leaf.
            assert_eq!(leaf_volume, 6 << (3 * f.level), "{f:?}");
            volume += leaf_volume;
        }
        let side = 1u64 << tree.root_level;
        assert_eq!(volume, 6 * side * side * side);
        for (tri, n) in faces {
            let on_boundary = (0..3).any(|k| {
                let c = tri.map(|t| unpack(t)[k]);
                c.iter().all(|&v| v == 0) || c.iter().all(|&v| v == side)
            });
            assert_eq!(n, if on_boundary { 1 } else { 2 }, "{:?}", tri.map(unpack));
        }
    }

    #[test]
    fn balanced_tree_is_conforming_and_tiles_the_root() {
        // Split down to level 0 around one corner, and one isolated deep cell.
        let mut tree = Octree::new(4);
        tree.split(1, [pack([0, 0, 0]), pack([5, 2, 7])]);
        tree.balance();
        let leaves = tree.leaves();
        let levels: std::collections::BTreeSet<u32> = leaves.iter().map(|f| f.level).collect();
        assert_eq!(levels.len(), 4, "{levels:?}");
        // 2:1: touching leaves differ by at most one level.
        for a in &leaves {
            for b in &leaves {
                let (pa, pb) = (unpack(a.min), unpack(b.min));
                let touch = (0..3)
                    .all(|k| pa[k] <= pb[k] + (1 << b.level) && pb[k] <= pa[k] + (1 << a.level));
                if touch {
                    assert!(a.level.abs_diff(b.level) <= 1, "{a:?} {b:?}");
                }
            }
        }
        check_conforming(&tree);
    }

    #[test]
    fn unsplit_and_uniform_trees_are_conforming() {
        let tree = Octree::new(2);
        assert_eq!(tree.leaves().len(), 1);
        check_conforming(&tree);
        let mut tree = Octree::new(2);
        tree.split(1, (0..8).map(|c| pack([c & 1, c >> 1 & 1, c >> 2 & 1])));
        tree.balance();
        assert_eq!(tree.leaves().len(), 64);
        check_conforming(&tree);
    }

    #[test]
    fn dilation_is_clipped_and_sorted() {
        let d = dilate3(&[pack([0, 0, 0])], -1, 1, 4);
        assert_eq!(d.len(), 8);
        assert!(d.windows(2).all(|w| w[0] < w[1]));
    }
}
