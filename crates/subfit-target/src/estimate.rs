//! Per-point local surface estimation: PCA frame of the neighbourhood, then a weighted quadric
//! fit in that frame (Cheng 2004 §4.1; Cheng 2007 §II-C). The PCA normal is the eigenvector of
//! the smallest eigenvalue of `CV = Σ_j (V_j − V_c)(V_j − V_c)ᵀ`; the refined normal is that of
//! the fitted quadric at the data point. Orientation is decided elsewhere ([`crate::orient`]).

use rayon::prelude::*;

use crate::neighbors::{Neighbor, PointIndex};
use crate::quadric::{sym3_eigen, FitQuality, LocalQuadric};
use crate::vec3::{any_orthogonal, dot, normalize, scale, sub};

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
#[derive(Clone, Debug)]
pub(crate) struct PointEstimate {
    pub quadric: LocalQuadric,
    pub quality: FitQuality,
    pub ambiguous: bool,
    pub size: u32,
    pub radius: f64,
    /// Nearest neighbours (excluding the point), for the orientation graph.
    pub graph: Vec<u32>,
}

/// Per-point estimation settings (from [`crate::TargetOptions`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct EstimateParams {
    pub hood: Neighborhood,
    pub ambiguity_ratio: f64,
    pub graph_k: usize,
    pub degree: u8,
}

/// Minimum number of neighbours used in any fit.
pub(crate) const MIN_NEIGHBORS: usize = 10;

/// Estimates the local quadric at `points[i]`.
///
/// `prescribed`: a unit normal to use as the frame normal instead of the PCA one.
/// `ambiguity_ratio`: the point is flagged ambiguous when `λ0 ≥ ratio · λ1` (smallest two
/// covariance eigenvalues nearly equal). `graph_k`: number of neighbours kept for orientation.
pub(crate) fn estimate_point(
    points: &[[f64; 3]],
    index: &PointIndex,
    i: usize,
    prescribed: Option<[f64; 3]>,
    params: &EstimateParams,
) -> PointEstimate {
    let EstimateParams {
        hood,
        ambiguity_ratio,
        graph_k,
        degree,
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
    let rel_all: Vec<[f64; 3]> = nb
        .iter()
        .map(|n| sub(points[n.index as usize], p))
        .collect();
    let (_, mut lam, mut vecs) = pca(&rel_all);
    let mut m = rel_all.len();
    // Adaptive scale: where the full neighbourhood is not surface-like (ambiguous, or large
    // surface variation λ0/Σλ, e.g. it crosses a thin part), try the nearest SMALL_K. Only for
    // `Knn`: a `Radius` neighbourhood is an explicit choice of scale (e.g. to average noise).
    if prescribed.is_none() && matches!(hood, Neighborhood::Knn(_)) && m > SMALL_K {
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
    let w: Vec<f64> = used
        .iter()
        .map(|n| (-(n.distance / h).powi(2)).exp())
        .collect();
    let (quadric, quality) = LocalQuadric::fit(n, e1, rel, &w, h, degree);
    let graph = nb
        .iter()
        .filter(|n| n.index as usize != i)
        .take(graph_k)
        .map(|n| n.index)
        .collect();
    PointEstimate {
        quadric,
        quality,
        ambiguous,
        size: m as u32,
        radius,
        graph,
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
fn pca(rel: &[[f64; 3]]) -> ([f64; 3], [f64; 3], [[f64; 3]; 3]) {
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

/// [`estimate_point`] for all points in parallel, in chunks, calling `tick(done)` after each.
pub(crate) fn estimate_all(
    points: &[[f64; 3]],
    index: &PointIndex,
    prescribed: &[Option<[f64; 3]>],
    params: &EstimateParams,
    tick: &(dyn Fn(usize) + Sync),
) -> Vec<PointEstimate> {
    const CHUNK: usize = 1 << 15;
    let mut out = Vec::with_capacity(points.len());
    let mut start = 0;
    while start < points.len() {
        let end = (start + CHUNK).min(points.len());
        let part: Vec<PointEstimate> = (start..end)
            .into_par_iter()
            .map(|i| {
                estimate_point(
                    points,
                    index,
                    i,
                    prescribed.get(i).copied().flatten(),
                    params,
                )
            })
            .collect();
        out.extend(part);
        start = end;
        tick(start);
    }
    out
}
