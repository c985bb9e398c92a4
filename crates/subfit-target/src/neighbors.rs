//! Neighbour search over the target's points: k-nearest and radius queries on a kd-tree
//! (`kiddo` 6, immutable tree), single and batched in parallel with rayon.
//!
//! All distances taken and returned here are **Euclidean (not squared)**, in the units of the
//! points given (normalized units inside a [`crate::Target`]). kiddo itself works with squared
//! distances; the conversion happens here.

use std::num::NonZeroUsize;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;
use subfit_mesh::vec3::dist2;

/// One neighbour: index of the point in the indexed slice and its Euclidean distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neighbor {
    /// Index into the point slice the index was built from.
    pub index: u32,
    /// Euclidean distance to the query point (not squared).
    pub distance: f64,
}

/// A kd-tree over a fixed set of 3-D points.
///
/// Built once in O(n log n); a nearest query costs about 1 µs, a k-nearest query grows with `k`.
/// The points themselves are not stored (only the tree), so the caller keeps them.
pub struct PointIndex {
    tree: ImmutableKdTree<f64, 3>,
    len: usize,
}

impl std::fmt::Debug for PointIndex {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PointIndex")
            .field("len", &self.len)
            .finish()
    }
}

impl PointIndex {
    /// Builds the tree over `points` (`#P by 3`).
    ///
    /// Returns `None` when `points` is empty or has more than `u32::MAX` entries. Coordinates are
    /// not checked for finiteness (the [`crate::Target`] constructor rejects NaN/Inf first).
    pub fn new(points: &[[f64; 3]]) -> Option<Self> {
        if points.is_empty() || points.len() > u32::MAX as usize {
            return None;
        }
        let tree = if points.len() > 50_000 {
            ImmutableKdTree::new_from_slice_parallel(points).ok()?
        } else {
            ImmutableKdTree::new_from_slice(points).ok()?
        };
        Some(Self {
            tree,
            len: points.len(),
        })
    }

    /// Number of indexed points.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the index is empty (never true for a constructed index).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The nearest indexed point to `q`. Cost: O(log n), about 1 µs.
    pub fn nearest(&self, q: &[f64; 3]) -> Neighbor {
        let r = self
            .tree
            .query(q)
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        Neighbor {
            index: r.item,
            distance: r.distance.max(0.0).sqrt(),
        }
    }

    /// The nearest indexed point to `q` among those within squared distance `bound2`
    /// (inclusive), `None` when there is none. With a tight bound (e.g. the distance to a point
    /// known to be near) much cheaper than [`Self::nearest`] for queries off the surface: fewer
    /// tree nodes are visited, no allocation.
    pub fn nearest_within2(&self, q: &[f64; 3], bound2: f64) -> Option<Neighbor> {
        if !(bound2 >= 0.0) {
            return None;
        }
        let mut best: Option<(f64, u32)> = None;
        self.tree
            .query(q)
            .within::<SquaredEuclidean<f64>>(bound2)
            .unsorted()
            .visit(|r| {
                if best.is_none_or(|(d, _)| r.distance < d) {
                    best = Some((r.distance, r.item));
                }
            });
        best.map(|(d, i)| Neighbor {
            index: i,
            distance: d.max(0.0).sqrt(),
        })
    }

    /// The `k` nearest points to `q`, sorted by increasing distance (fewer when the index has
    /// fewer than `k` points). `k == 0` gives an empty list. A point of the index queried at its
    /// own position finds itself first.
    pub fn k_nearest(&self, q: &[f64; 3], k: usize) -> Vec<Neighbor> {
        let Some(k) = NonZeroUsize::new(k.min(self.len)) else {
            return Vec::new();
        };
        self.tree
            .query(q)
            .nearest_n::<SquaredEuclidean<f64>>(k)
            .execute()
            .into_iter()
            .map(|r| Neighbor {
                index: r.item,
                distance: r.distance.max(0.0).sqrt(),
            })
            .collect()
    }

    /// All points within `radius` (inclusive) of `q`, sorted by increasing distance.
    /// Cost grows with the number of points found.
    pub fn within(&self, q: &[f64; 3], radius: f64) -> Vec<Neighbor> {
        if !(radius >= 0.0) {
            return Vec::new();
        }
        self.tree
            .query(q)
            .within::<SquaredEuclidean<f64>>(radius * radius)
            .execute()
            .into_iter()
            .map(|r| Neighbor {
                index: r.item,
                distance: r.distance.max(0.0).sqrt(),
            })
            .collect()
    }

    /// Calls `f(index)` for every point within `radius` (inclusive) of `q`, in the order of
    /// [`Self::within_unsorted`], without collecting them: no allocation, for kernels that
    /// only sum over the neighbourhood (IMLS).
    #[inline]
    pub fn for_each_within(&self, q: &[f64; 3], radius: f64, mut f: impl FnMut(u32)) {
        if !(radius >= 0.0) {
            return;
        }
        self.tree
            .query(q)
            .within::<SquaredEuclidean<f64>>(radius * radius)
            .unsorted()
            .visit(|r| f(r.item));
    }

    /// All points within `radius` of `q`, in no particular order (faster than [`Self::within`]).
    pub fn within_unsorted(&self, q: &[f64; 3], radius: f64) -> Vec<Neighbor> {
        if !(radius >= 0.0) {
            return Vec::new();
        }
        self.tree
            .query(q)
            .within::<SquaredEuclidean<f64>>(radius * radius)
            .unsorted()
            .execute()
            .into_iter()
            .map(|r| Neighbor {
                index: r.item,
                distance: r.distance.max(0.0).sqrt(),
            })
            .collect()
    }

    /// [`Self::nearest`] for every query, in parallel (rayon). Output `#Q` entries, in order.
    pub fn nearest_batch(&self, queries: &[[f64; 3]]) -> Vec<Neighbor> {
        queries.par_iter().map(|q| self.nearest(q)).collect()
    }

    /// The distance to the nearest point of every node of the uniform grid with `dims` nodes
    /// (x fastest) spaced `cell` from `origin`, where it is at most `bound`; `INFINITY` where
    /// it is larger. Rows in parallel (rayon); along a row the distance changes by at most
    /// `cell` per node, so after a node at distance `d > bound` the next `⌊(d − bound) / cell⌋`
    /// nodes are skipped without a query: a grid around a scan costs about one [`Self::nearest`]
    /// per node near the points. Values within `bound` are those of [`Self::nearest`].
    /// Only the slabs `zs` (a range of z indices) are computed: output
    /// `dims[0]·dims[1]·zs.len()` entries.
    pub fn grid_distances(
        &self,
        origin: [f64; 3],
        cell: f64,
        dims: [usize; 3],
        zs: std::ops::Range<usize>,
        bound: f64,
    ) -> Vec<f64> {
        let [nx, ny, _] = dims;
        let mut out = vec![f64::INFINITY; nx * ny * zs.len()];
        if nx == 0 || ny == 0 {
            return out;
        }
        out.par_chunks_mut(nx).enumerate().for_each(|(row, out)| {
            let (y, z) = (row % ny, zs.start + row / ny);
            let mut x = 0;
            while x < nx {
                let q = [
                    origin[0] + x as f64 * cell,
                    origin[1] + y as f64 * cell,
                    origin[2] + z as f64 * cell,
                ];
                let d = self.nearest(&q).distance;
                if d <= bound {
                    out[x] = d;
                    x += 1;
                } else {
                    // Nodes x + 1 ..= x + skip are farther than `bound` too.
                    let skip = ((d - bound) / cell).floor();
                    x += 1 + if skip.is_finite() { skip as usize } else { nx };
                }
            }
        });
        out
    }

    /// [`Self::k_nearest`] for every query, in parallel (rayon). Output `#Q` lists, in order.
    pub fn k_nearest_batch(&self, queries: &[[f64; 3]], k: usize) -> Vec<Vec<Neighbor>> {
        queries.par_iter().map(|q| self.k_nearest(q, k)).collect()
    }

    /// [`Self::within`] for every query, in parallel (rayon). Output `#Q` lists, in order.
    pub fn within_batch(&self, queries: &[[f64; 3]], radius: f64) -> Vec<Vec<Neighbor>> {
        queries.par_iter().map(|q| self.within(q, radius)).collect()
    }
}

/// A k-nearest-neighbour graph over a point set, with per-row radii, for warm-started nearest
/// queries by greedy descent ([`NeighborGraph::descend`]).
///
/// Row `i` holds the (up to) `stride` points nearest to point `i` (itself excluded), padded with
/// `u32::MAX`. `radius2[i]` is the squared distance of the last entry of row `i`; since a row
/// holds the nearest points, every point strictly closer to point `i` than that is in the row.
/// Memory: `#P · (4 · stride + 8)` bytes.
#[derive(Clone, Debug, Default)]
pub(crate) struct NeighborGraph {
    stride: usize,
    targets: Vec<u32>,
    radius2: Vec<f64>,
}

/// Descent steps after which [`NeighborGraph::descend`] gives up (the caller falls back to the
/// kd-tree). Descents from a nearby start take a handful.
const MAX_DESCENT_STEPS: usize = 16;

impl NeighborGraph {
    /// Builds the graph from rows of nearest neighbours (`#P · stride`, each row sorted by
    /// increasing distance, padded with `u32::MAX`) over `points` (`#P by 3`). O(#P · stride).
    pub(crate) fn new(points: &[[f64; 3]], targets: Vec<u32>, stride: usize) -> Self {
        let stride = stride.max(1);
        debug_assert_eq!(targets.len(), points.len() * stride);
        let radius2 = targets
            .par_chunks(stride)
            .zip(points.par_iter())
            .map(|(row, p)| {
                row.iter()
                    .take_while(|&&j| j != u32::MAX)
                    .map(|&j| dist2(*p, points[j as usize]))
                    .fold(0.0, f64::max)
            })
            .collect();
        Self {
            stride,
            targets,
            radius2,
        }
    }

    /// The neighbours of point `s` (sorted by distance, padded with `u32::MAX`; `stride`
    /// entries).
    ///
    /// # Panics
    /// If `s` is out of range.
    #[track_caller]
    pub(crate) fn row(&self, s: u32) -> &[u32] {
        let s = s as usize;
        &self.targets[s * self.stride..(s + 1) * self.stride]
    }

    /// Greedy descent towards `q` from point `start` over the graph of `points` (the slice the
    /// graph was built over): move to the row entry nearest to `q` while it is strictly nearer
    /// than the current point. Returns the local minimum `c` reached and whether it is
    /// certified to be the nearest point: at distance `d` from `q`, it is when `2d < R_c` (`R_c`
    /// the row radius), since a point `p` nearer to `q` than `c` has
    /// `|p − c| ≤ |p − q| + |q − c| < 2d < R_c`, so it is in the row and the descent would have
    /// moved to it. Uncertified results (typically `q` farther from the points than about the
    /// neighbour spacing, or [`MAX_DESCENT_STEPS`] reached) are still an upper bound on the
    /// nearest distance. `None` for an out-of-range `start`. Exact up to rounding of the squared
    /// distances (ties may resolve to either point). Cost: O(steps · stride).
    #[inline]
    pub(crate) fn descend(
        &self,
        points: &[[f64; 3]],
        q: &[f64; 3],
        start: u32,
    ) -> Option<(Neighbor, bool)> {
        let mut c = start as usize;
        let mut dc = dist2(*q, *points.get(c)?);
        let mut certified = false;
        for _ in 0..MAX_DESCENT_STEPS {
            let row = &self.targets[c * self.stride..(c + 1) * self.stride];
            let (mut best, mut bd) = (c, dc);
            for &j in row {
                if j == u32::MAX {
                    break;
                }
                let d = dist2(*q, points[j as usize]);
                if d < bd {
                    (best, bd) = (j as usize, d);
                }
            }
            if best == c {
                // 2d < R ⇔ 4d² < R², with a margin for rounding.
                certified = 4.0 * dc * (1.0 + 1e-12) < self.radius2[c];
                break;
            }
            (c, dc) = (best, bd);
        }
        let n = Neighbor {
            index: c as u32,
            distance: dc.sqrt(),
        };
        Some((n, certified))
    }
}

/// Spreads the low 21 bits of `x` to every third bit.
#[inline]
fn spread3(x: u64) -> u64 {
    let mut x = x & 0x1f_ffff;
    x = (x | x << 32) & 0x1f_0000_0000_ffff;
    x = (x | x << 16) & 0x1f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// Indices of `xs` sorted by the Morton code of the point (normalized coordinates, clamped to
/// the unit cube; 21 bits per axis). Parallel, O(n log n).
pub(crate) fn morton_order(xs: &[[f64; 3]]) -> Vec<u32> {
    let cell = |c: f64| -> u64 {
        let t = if c.is_finite() {
            c.clamp(0.0, 1.0)
        } else {
            0.0
        };
        (t * f64::from((1u32 << 21) - 1)) as u64
    };
    let mut keys: Vec<(u64, u32)> = xs
        .par_iter()
        .enumerate()
        .map(|(i, x)| {
            let code = spread3(cell(x[0])) | spread3(cell(x[1])) << 1 | spread3(cell(x[2])) << 2;
            (code, i as u32)
        })
        .collect();
    keys.par_sort_unstable();
    keys.into_iter().map(|(_, i)| i).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_grid_queries() {
        let mut pts = Vec::new();
        for i in 0..5 {
            for j in 0..5 {
                pts.push([i as f64, j as f64, 0.0]);
            }
        }
        let idx = PointIndex::new(&pts).unwrap();
        let n = idx.nearest(&[1.1, 2.2, 0.3]);
        assert_eq!(pts[n.index as usize], [1.0, 2.0, 0.0]);
        assert!((n.distance - (0.01f64 + 0.04 + 0.09).sqrt()).abs() < 1e-12);
        let k = idx.k_nearest(&[0.0, 0.0, 0.0], 3);
        assert_eq!(k.len(), 3);
        assert_eq!(k[0].index, 0);
        assert!((k[1].distance - 1.0).abs() < 1e-12);
        let w = idx.within(&[2.0, 2.0, 0.0], 1.0);
        assert_eq!(w.len(), 5);
        assert_eq!(idx.k_nearest(&[0.0; 3], 100).len(), 25);
        let b = idx.k_nearest_batch(&pts, 4);
        assert!(b.iter().zip(0..).all(|(l, i)| l[0].index == i));
    }
}
