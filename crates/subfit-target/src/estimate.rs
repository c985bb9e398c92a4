//! Per-point local surface estimation: PCA frame of the neighbourhood, then a weighted quadric
//! fit in that frame (Cheng 2004 §4.1; Cheng 2007 §II-C). The PCA normal is the eigenvector of
//! the smallest eigenvalue of `CV = Σ_j (V_j − V_c)(V_j − V_c)ᵀ`; the refined normal is that of
//! the fitted quadric at the data point. Orientation is decided elsewhere ([`crate::orient`]).

use rayon::prelude::*;
use subfit_mesh::{Cancel, Cancelled};

use crate::neighbors::{morton_order, Neighbor, PointIndex};
use crate::quadric::{sym3_eigen, FitQuality, LocalQuadric};
use subfit_mesh::vec3::{any_orthogonal, dot, normalize, scale, sub};

/// How the neighbourhood of a data point is chosen for normal and curvature estimation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Neighborhood {
    /// The `k` nearest points (the point itself included). Adapts to the local density.
    /// Valid: `k ≥ 10`.
    Knn(usize),
    /// All points within this radius (normalized units), but at least the 10 nearest.
    Radius(f64),
}

impl Default for Neighborhood {
    /// `Knn(24)`.
    fn default() -> Self {
        Neighborhood::Knn(24)
    }
}

/// Result of the estimation at one point.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PointEstimate {
    pub quadric: LocalQuadric,
    pub quality: FitQuality,
    pub ambiguous: bool,
    pub size: u32,
    pub radius: f64,
    /// Distance to the nearest other point (`+∞` if none).
    pub nn_dist: f64,
}

/// Per-point estimation settings (from [`crate::TargetOptions`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct EstimateParams {
    pub hood: Neighborhood,
    pub ambiguity_ratio: f64,
    pub graph_k: usize,
    pub degree: u8,
    /// Try the nearest [`SMALL_K`] where the full neighbourhood is not surface-like (off for
    /// noisy scans).
    pub small_fallback: bool,
}

/// Minimum number of neighbours used in any fit.
pub(crate) const MIN_NEIGHBORS: usize = 10;

/// Estimates the local quadric at `points[i]`.
///
/// `prescribed`: a unit normal to use as the frame normal instead of the PCA one.
/// `ambiguity_ratio`: the point is flagged ambiguous when `λ0 ≥ ratio · λ1` (smallest two
/// covariance eigenvalues nearly equal). `graph_row` (any length, see [`graph_stride`]) receives
/// the nearest neighbours in increasing distance (the point itself excluded), padded with
/// `u32::MAX`. `scratch` is reused between calls.
pub(crate) fn estimate_point(
    points: &[[f64; 3]],
    index: &PointIndex,
    i: usize,
    prescribed: Option<[f64; 3]>,
    params: &EstimateParams,
    graph_row: &mut [u32],
    scratch: &mut Scratch,
) -> PointEstimate {
    let EstimateParams {
        hood,
        ambiguity_ratio,
        graph_k: _,
        degree,
        small_fallback,
    } = *params;
    let p = points[i];
    let nb: Vec<Neighbor> = match hood {
        Neighborhood::Knn(k) => index.k_nearest(&p, k.max(MIN_NEIGHBORS)),
        Neighborhood::Radius(r) => {
            let w = index.within(&p, r);
            if w.len() < MIN_NEIGHBORS {
                index.k_nearest(&p, MIN_NEIGHBORS)
            } else {
                w
            }
        }
    };
    let Scratch { rel: rel_all, w } = scratch;
    rel_all.clear();
    rel_all.extend(nb.iter().map(|n| sub(points[n.index as usize], p)));
    let (_, mut lam, mut vecs) = pca(rel_all);
    let mut m = rel_all.len();
    // Adaptive scale: where the full neighbourhood is not surface-like (ambiguous, or large
    // surface variation λ0/Σλ, e.g. it crosses a thin part), try the nearest SMALL_K. Only for
    // `Knn`: a `Radius` neighbourhood is an explicit choice of scale (e.g. to average noise).
    if small_fallback && prescribed.is_none() && matches!(hood, Neighborhood::Knn(_)) && m > SMALL_K
    {
        let full_var = variation(&lam);
        if lam[0] >= ambiguity_ratio * lam[1] || full_var > MAX_VARIATION {
            let (_, lam2, vecs2) = pca(&rel_all[..SMALL_K]);
            if variation(&lam2) < full_var {
                (lam, vecs, m) = (lam2, vecs2, SMALL_K);
            }
        }
    }
    let used = &nb[..m];
    let rel = &rel_all[..m];
    let radius = used.last().map_or(0.0, |n| n.distance);
    let ambiguous = prescribed.is_none() && lam[0] >= ambiguity_ratio * lam[1];
    let n = prescribed
        .or_else(|| normalize(vecs[0]))
        .unwrap_or([0.0, 0.0, 1.0]);
    let e1 =
        normalize(sub(vecs[2], scale(n, dot(vecs[2], n)))).unwrap_or_else(|| any_orthogonal(n));
    let h = if radius > 0.0 { radius } else { 1.0 };
    w.clear();
    w.extend(used.iter().map(|n| (-(n.distance / h).powi(2)).exp()));
    let (quadric, quality) = LocalQuadric::fit(n, e1, rel, w, h, degree);
    graph_row.fill(u32::MAX);
    for (g, n) in graph_row
        .iter_mut()
        .zip(nb.iter().filter(|n| n.index as usize != i))
    {
        *g = n.index;
    }
    let nn_dist = nb
        .iter()
        .find(|n| n.index as usize != i)
        .map_or(f64::INFINITY, |n| n.distance);
    PointEstimate {
        nn_dist,
        quadric,
        quality,
        ambiguous,
        size: m as u32,
        radius,
    }
}

/// Size of the smaller neighbourhood tried where the full one is not surface-like.
const SMALL_K: usize = 12;

/// Surface variation above which the smaller neighbourhood is tried.
const MAX_VARIATION: f64 = 0.05;

/// Surface variation `λ0 / (λ0 + λ1 + λ2)` (Pauly et al. 2002), 0 for a plane, 1/3 at most.
fn variation(lam: &[f64; 3]) -> f64 {
    let s = lam[0] + lam[1] + lam[2];
    if s > 0.0 {
        lam[0] / s
    } else {
        0.0
    }
}

/// Centroid (relative), eigenvalues (ascending) and eigenvectors of the covariance of `rel`.
pub fn pca(rel: &[[f64; 3]]) -> ([f64; 3], [f64; 3], [[f64; 3]; 3]) {
    let inv = 1.0 / rel.len() as f64;
    let mut c = [0.0; 3];
    for r in rel {
        for k in 0..3 {
            c[k] += r[k] * inv;
        }
    }
    let mut cv = [[0.0; 3]; 3];
    for r in rel {
        let d = sub(*r, c);
        for a in 0..3 {
            for b in a..3 {
                cv[a][b] += d[a] * d[b];
            }
        }
    }
    cv[1][0] = cv[0][1];
    cv[2][0] = cv[0][2];
    cv[2][1] = cv[1][2];
    let (lam, vecs) = sym3_eigen(cv);
    (c, lam, vecs)
}

/// Per-thread buffers of [`estimate_point`].
#[derive(Default)]
pub(crate) struct Scratch {
    rel: Vec<[f64; 3]>,
    w: Vec<f64>,
}

/// Neighbours kept per point by [`estimate_all`] for the nearest-point descent graph
/// ([`crate::neighbors::NeighborGraph`]).
pub(crate) const DESCENT_K: usize = 16;

/// Row length of the graph returned by [`estimate_all`]: `max(graph_k, DESCENT_K)`. The
/// orientation graph is the first `graph_k` entries of each row, the descent graph the first
/// [`DESCENT_K`].
pub(crate) fn graph_stride(params: &EstimateParams) -> usize {
    params.graph_k.max(DESCENT_K)
}

/// [`estimate_point`] for all points in parallel, in chunks, calling `tick(done)` after each.
/// Points are visited in Morton order (kd-tree locality); results are in point order, with the
/// nearest-neighbour graph as rows of [`graph_stride`] entries (sorted by distance, padded with
/// `u32::MAX`). `cancel` is polled before each chunk.
pub(crate) fn estimate_all(
    points: &[[f64; 3]],
    index: &PointIndex,
    prescribed: &[Option<[f64; 3]>],
    params: &EstimateParams,
    tick: &(dyn Fn(usize) + Sync),
    cancel: &Cancel,
) -> Result<(Vec<PointEstimate>, Vec<u32>), Cancelled> {
    // 8192 points: tens of milliseconds per chunk, so a cancellation is seen quickly.
    const CHUNK: usize = 1 << 13;
    let n = points.len();
    let k = graph_stride(params);
    let order = morton_order(points);
    let mut sorted = Vec::with_capacity(n);
    let mut graph_sorted = vec![u32::MAX; n * k];
    let mut start = 0;
    while start < n {
        cancel.check()?;
        let end = (start + CHUNK).min(n);
        let part: Vec<PointEstimate> = order[start..end]
            .par_iter()
            .zip(graph_sorted[start * k..end * k].par_chunks_mut(k))
            .map_init(Scratch::default, |scratch, (&i, row)| {
                let i = i as usize;
                estimate_point(
                    points,
                    index,
                    i,
                    prescribed.get(i).copied().flatten(),
                    params,
                    row,
                    scratch,
                )
            })
            .collect();
        sorted.extend(part);
        start = end;
        tick(start);
    }
    let mut rank = vec![0u32; n];
    for (r, &i) in order.iter().enumerate() {
        rank[i as usize] = r as u32;
    }
    let estimates = rank.par_iter().map(|&r| sorted[r as usize]).collect();
    let mut graph = vec![u32::MAX; n * k];
    graph
        .par_chunks_mut(k)
        .zip(rank.par_iter())
        .for_each(|(row, &r)| {
            let r = r as usize;
            row.copy_from_slice(&graph_sorted[r * k..(r + 1) * k]);
        });
    Ok((estimates, graph))
}
