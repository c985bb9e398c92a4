//! Outlier detection and noise estimation of a raw scan, before any per-point fit.
//!
//! Robust statistics of the `k` nearest neighbours of every point (statistical outlier removal
//! by the distance to the neighbours, Rusu et al. 2008, "Towards 3D point cloud based object
//! maps", §4; residual of a local height-function fit, as in Pauly et al. 2002):
//!
//! 1. **Sparse.** `d_i`, the distance to the `k`-th neighbour, against the median `D` over the
//!    cloud: a point with `d_i > SPARSE_RATIO · D` lies where the surface sampling is not (a
//!    point scattered in the bounding box is typically 10–20 spacings from the surface).
//!    On clean scans a sparse point is kept, here and in rule 2, when its nearest neighbour is
//!    within `CONNECTED_RATIO` (3) × the median nearest-neighbour distance or when it lies on
//!    the height function of its neighbours (rule 3's residual within `OFF_FLOOR · D`): a
//!    single-view range scan is sparse where the surface turns away from the scanner (returns
//!    up to 80° from the view are up to 6 pixels apart across the rim but one along it; bumps
//!    near the silhouette leave single returns on the surface's continuation) and in slivers
//!    seen through gaps; those are data. On six simulated scans of `bunny.off` the
//!    rules without this exemption dropped 6–41 such points each, and the fitted surface
//!    ended 1.6–5.4 % of the diagonal from them; with it, 0–4 are dropped. A point scattered in
//!    space has neither (900 uniform outliers around a clean 30k-point sphere: 827 caught
//!    before, 790 with the exemption; the others lie on the sphere's surface, within a quarter
//!    spacing of its height function).
//! 2. **Locally sparse.** `d_i` against the median `d_j` of its neighbours: above
//!    `LOCAL_RATIO` (2.5; 2 on noisy scans) the point is farther from its neighbours than they
//!    are from theirs (a point a few spacings off a noisy surface, whose neighbours form a bowl
//!    that no plane fits).
//! 3. **Off the surface.** `r_i`, the distance of the point to the height function
//!    `h = a u² + b uv + c v² + d u + e v + f` fitted to its neighbours (itself left out) in their
//!    PCA frame, so that curvature does not count. Outlier when `r_i` exceeds a ratio times the
//!    neighbours' own spread about the fit (`1.4826 · median_j r_j`, high at creases and thin
//!    parts, so those are kept), clamped to `[1, 2] ×` a base: on clean scans ratio 3 and base
//!    `OFF_FLOOR · D` (a clean sampling, whose residuals are ~0, loses nothing); on noisy ones
//!    (`σ > NOISY · D`) ratio 2.5 and base `σ`.
//! 4. **Past the edge** (clean scans). A point flagged by rules 1–3 is kept when it lies past
//!    the data's edge, close to it: within `RIM_REACH` (4) × `D` of a kept neighbour that is on
//!    the edge of the cloud (its kept neighbours leave an angular gap wider than 150° around it,
//!    [`crate::cloud_rim`]'s criterion) and in the direction of that gap. A single-view range
//!    scan leaves lone returns there where the surface turns away near the silhouette, 1–3.5 `D`
//!    beyond the last row (returns up to 80° from the view). On six simulated scans of
//!    `bunny.off`, rules 1–3 dropped 0–4 such points per view, and the fitted surface
//!    ended 1.5–2.2 % of the diagonal from them; this rule keeps all seven. A stray point above a
//!    closed surface is never past an edge; around an open one, those beside its rim are
//!    (`subfit analyze --json`, 900 points uniform in the box around 30k points of a clean
//!    unit sphere: 817 removed before, 806 with the rule; of a hemisphere: 832, 801).
//! 5. **A handful past the edge** (clean scans). When what rules 1–4 leave flagged is at most
//!    one point in [`FEW_PER`] (2,000), rule 4 runs again with the reach [`LONE_REACH`] (8 `D`):
//!    a clean scan flags that few where it sees small parts alone past an occluding edge (a
//!    claw through a gap, a toe's tip behind another), not where it is contaminated, whose
//!    stray returns come at a rate. On six simulated views of the armadillo rules 1–4
//!    dropped 0–4 points each, all within 5e-4 of the diagonal of the true surface and 1.3–2.6 %
//!    from the rest of the scan; the init's specks then cover them (`subfit_init::specks`, in
//!    the crate that builds cages). A point above the middle of a surface is not past an edge:
//!    three stray points 4 `D` off a clean closed scan of the armadillo stay outliers (kept,
//!    they made the closed cloud's contour open and the fit's maximum 3.5 % of the diagonal).
//!    Scattered outliers are many (900 around a 30k-point sphere) and keep rules 1–4; a noisy
//!    scan never gets this rule.
//!
//! **Noise level.** `σ = 1.4826 · median_i r_i` over the kept points: about the standard
//! deviation of Gaussian noise along the normal (measured within 10 % on the noisy analytic
//! shapes); on a clean sampling the unfitted shape detail over a neighbourhood (below
//! `0.06 · D` on the shared scans except the coarse `lucy.ply`, 0.24). Reported absolute
//! (normalized units) and relative to `D`, and used to widen the estimation neighbourhood of
//! noisy scans ([`noisy_knn`]).
//!
//! Measured (`noisy_bench` example): 150k points with 0.3 % noise and 3 % outliers lose 90 % of
//! the outliers (the rest lie within ~2.5 σ of the surface) and ~0.8 % of the surface samples
//! (the noise's far tail); the shared clean scans lose at most 0.2 %.
//!
//! Cost: one k-nearest query per point (O(P · k log P), parallel) and a 3×3 eigenproblem and a
//! 6×6 solve per point; memory O(P · k).

use rayon::prelude::*;
use subfit_mesh::{Cancel, Cancelled};

use crate::angular_gap::{AngularGap, RIM_GAP};
use crate::estimate::pca;
use crate::neighbors::PointIndex;
use crate::quadric::sym3_eigen;
use nalgebra::{SMatrix, SVector};
use subfit_mesh::vec3::{dot, norm, sub};

/// Neighbours used per point (the point itself excluded).
pub(crate) const OUTLIER_K: usize = 16;
/// A point is sparse when its `k`-th neighbour is farther than this × the median.
const SPARSE_RATIO: f64 = 4.0;
/// On clean scans, a point is off the surface when its residual exceeds this × the local
/// spread, clamped to `[1, SPREAD_CAP] ×` [`OFF_FLOOR`] × the median `k`-th neighbour distance.
const OFF_RATIO: f64 = 3.0;
/// On noisy scans ([`NOISY`]), a point is off the surface when its residual exceeds this × the
/// local spread, clamped to `[1, SPREAD_CAP] ×` the noise level.
const OFF_RATIO_NOISY: f64 = 2.5;
/// A point is sparse for its neighbourhood when its `k`-th neighbour is farther than this × the
/// median of its neighbours' `k`-th neighbour distances (noisy scans).
const LOCAL_RATIO_NOISY: f64 = 2.0;
/// [`LOCAL_RATIO_NOISY`] for clean scans, whose sampling density varies more (meshes with
/// triangles of very different sizes).
const LOCAL_RATIO: f64 = 2.5;
/// On clean scans, a point whose nearest neighbour is within this × the median nearest-neighbour
/// distance is never sparse (see the module docs, rule 1).
const CONNECTED_RATIO: f64 = 3.0;
/// The local spread counts in the off-surface threshold up to this × the global level.
const SPREAD_CAP: f64 = 2.0;
/// Floor of the off-surface threshold, in units of the median `k`-th neighbour distance.
const OFF_FLOOR: f64 = 0.25;
/// Median absolute deviation → standard deviation of a Gaussian.
const MAD_TO_SIGMA: f64 = 1.4826;

/// What [`detect`] found.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct OutlierScan {
    /// Per point: whether it is an outlier (`#P`).
    pub outlier: Vec<bool>,
    /// Number of outliers.
    pub count: usize,
    /// Noise level `σ` (normalized units).
    pub noise: f64,
    /// Median distance to the `k`-th neighbour `D` (normalized units).
    pub spacing: f64,
}

/// Per-point statistics: `(d_i, r_i, local spread)`; fills `row` with the neighbours
/// (`OUTLIER_K`, padded with `u32::MAX`).
fn point_stats(
    points: &[[f64; 3]],
    index: &PointIndex,
    i: usize,
    row: &mut [u32],
) -> (f64, f64, f64) {
    let p = points[i];
    let nb = index.k_nearest(&p, OUTLIER_K + 1);
    row.fill(u32::MAX);
    for (r, n) in row
        .iter_mut()
        .zip(nb.iter().filter(|n| n.index as usize != i))
    {
        *r = n.index;
    }
    let others: Vec<[f64; 3]> = nb
        .iter()
        .filter(|n| n.index as usize != i)
        .take(OUTLIER_K)
        .map(|n| points[n.index as usize])
        .collect();
    let d = nb.last().map_or(0.0, |n| n.distance);
    if others.len() < 3 {
        return (d, 0.0, 0.0);
    }
    let inv = 1.0 / others.len() as f64;
    let mut c = [0.0; 3];
    for q in &others {
        for k in 0..3 {
            c[k] += q[k] * inv;
        }
    }
    let mut cv = [[0.0; 3]; 3];
    for q in &others {
        let e = sub(*q, c);
        for a in 0..3 {
            for b in 0..3 {
                cv[a][b] += e[a] * e[b];
            }
        }
    }
    let (_, vecs) = sym3_eigen(cv);
    let (n, t1, t2) = (vecs[0], vecs[2], vecs[1]);
    let local = |q: [f64; 3]| {
        let e = sub(q, c);
        (dot(t1, e), dot(t2, e), dot(n, e))
    };
    // Height function h = a u² + b uv + c v² + d u + e v + f over the neighbours (the point
    // left out), so that curvature is not counted as noise; a plane when that is singular.
    let basis = |u: f64, v: f64| SVector::<f64, 6>::new(u * u, u * v, v * v, u, v, 1.0);
    let mut ata = SMatrix::<f64, 6, 6>::zeros();
    let mut atb = SVector::<f64, 6>::zeros();
    for q in &others {
        let (u, v, h) = local(*q);
        let b = basis(u, v);
        ata += b * b.transpose();
        atb += b * h;
    }
    let coef = if others.len() >= 8 {
        ata.cholesky().map(|ch| ch.solve(&atb))
    } else {
        None
    };
    let resid = |q: [f64; 3]| {
        let (u, v, h) = local(q);
        match &coef {
            Some(x) => (h - basis(u, v).dot(x)).abs(),
            None => h.abs(),
        }
    };
    let r = resid(p);
    let mut res: Vec<f64> = others.iter().map(|q| resid(*q)).collect();
    (d, r, MAD_TO_SIGMA * median(&mut res))
}

/// Median of `v` (0 when empty); reorders `v`.
fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mid = v.len() / 2;
    let (_, m, _) = v.select_nth_unstable_by(mid, f64::total_cmp);
    *m
}

/// Detects outliers and estimates the noise level (see the module doc). When `remove` is false
/// only the noise level and spacing are measured (`outlier` all false). Polls `cancel` per chunk.
pub(crate) fn detect(
    points: &[[f64; 3]],
    index: &PointIndex,
    remove: bool,
    cancel: &Cancel,
) -> Result<OutlierScan, Cancelled> {
    const CHUNK: usize = 1 << 14;
    let n = points.len();
    let k = OUTLIER_K;
    let mut stats = Vec::with_capacity(n);
    let mut rows = vec![u32::MAX; n * k];
    for start in (0..n).step_by(CHUNK) {
        cancel.check()?;
        let end = (start + CHUNK).min(n);
        stats.par_extend(
            (start..end)
                .into_par_iter()
                .zip(rows[start * k..end * k].par_chunks_mut(k))
                .map(|(i, row)| point_stats(points, index, i, row)),
        );
    }
    cancel.check()?;
    let spacing = median(&mut stats.iter().map(|s| s.0).collect::<Vec<_>>());
    // Local sparsity: d_i over the median d_j of the neighbours.
    let local: Vec<f64> = rows
        .par_chunks(k)
        .zip(stats.par_iter())
        .map(|(row, s)| {
            let mut d: Vec<f64> = row
                .iter()
                .filter(|&&j| j != u32::MAX)
                .map(|&j| stats[j as usize].0)
                .collect();
            let m = median(&mut d);
            if m > 0.0 {
                s.0 / m
            } else {
                0.0
            }
        })
        .collect();
    let sparse = |s: &(f64, f64, f64)| s.0 > SPARSE_RATIO * spacing;
    // Noise from the points that are not sparse (the far outliers would inflate it).
    let mut dense_res: Vec<f64> = stats.iter().filter(|s| !sparse(s)).map(|s| s.1).collect();
    let mut noise = MAD_TO_SIGMA * median(&mut dense_res);
    let mut outlier: Vec<bool> = if remove {
        let noisy = noise > NOISY * spacing;
        let (ratio, base, local_ratio) = if noisy {
            (OFF_RATIO_NOISY, noise, LOCAL_RATIO_NOISY)
        } else {
            (OFF_RATIO, OFF_FLOOR * spacing, LOCAL_RATIO)
        };
        // On clean scans a sparse point with a close neighbour is a sparse part of the
        // surface (a grazing rim, a sliver seen through a gap), not a stray return.
        let nearest: Vec<f64> = rows
            .par_chunks(k)
            .enumerate()
            .map(|(i, row)| match row.first() {
                Some(&j) if j != u32::MAX => norm(sub(points[j as usize], points[i])),
                _ => f64::INFINITY,
            })
            .collect();
        let near = CONNECTED_RATIO * median(&mut nearest.clone());
        stats
            .par_iter()
            .zip(&local)
            .zip(&nearest)
            .map(|((s, &l), &d1)| {
                let limit = ratio * s.2.clamp(base, SPREAD_CAP * base);
                // Or it lies on its neighbours' surface, well within rule 3's floor.
                let on_surface = s.1 <= OFF_FLOOR * spacing;
                let connected = !noisy && (d1 <= near || on_surface);
                ((sparse(s) || l > local_ratio) && !connected) || s.1 > limit
            })
            .collect()
    } else {
        vec![false; n]
    };
    if remove && !is_noisy(noise, spacing) {
        keep_returns_past_the_rim(points, &rows, &mut outlier, RIM_REACH * spacing);
        keep_a_handful(points, &rows, &mut outlier, LONE_REACH * spacing);
    }
    let count = outlier.iter().filter(|&&o| o).count();
    if count > 0 {
        let mut kept: Vec<f64> = stats
            .iter()
            .zip(&outlier)
            .filter(|(_, &o)| !o)
            .map(|(s, _)| s.1)
            .collect();
        noise = MAD_TO_SIGMA * median(&mut kept);
    }
    Ok(OutlierScan {
        outlier,
        count,
        noise,
        spacing,
    })
}

/// Rule 4 of the module docs: on a clean scan, unflags every flagged point that lies past the
/// data's edge — within `reach` of one of its [`RIM_TRIES`] nearest kept
/// neighbours `j` whose own kept neighbours leave an angular gap wider than [`RIM_GAP`] around
/// it (`j` is on the edge, [`crate::cloud_rim`]'s criterion in the plane of `j`'s
/// neighbourhood), in the direction of that gap. Cost: O(k²) per flagged point.
fn keep_returns_past_the_rim(points: &[[f64; 3]], rows: &[u32], outlier: &mut [bool], reach: f64) {
    let k = OUTLIER_K;
    let kept_row = |j: usize| {
        rows[j * k..(j + 1) * k]
            .iter()
            .filter(|&&m| m != u32::MAX && !outlier[m as usize])
            .map(|&m| points[m as usize])
    };
    let past_rim = |i: usize| {
        let p = points[i];
        rows[i * k..(i + 1) * k]
            .iter()
            .filter(|&&j| j != u32::MAX && !outlier[j as usize])
            .take(RIM_TRIES)
            .any(|&j| {
                let q = points[j as usize];
                if norm(sub(p, q)) > reach {
                    return false;
                }
                let near: Vec<[f64; 3]> = kept_row(j as usize).collect();
                if near.len() < 3 {
                    return false;
                }
                let (_, _, frame) = pca(&near);
                AngularGap::around(q, frame[0], near)
                    .is_some_and(|g| g.width > RIM_GAP && g.contains(q, p))
            })
    };
    let rescued: Vec<usize> = (0..outlier.len())
        .into_par_iter()
        .filter(|&i| outlier[i] && past_rim(i))
        .collect();
    for i in rescued {
        outlier[i] = false;
    }
}

/// Rule 5 of the module docs: on a clean scan, when at most one point in [`FEW_PER`] is still
/// flagged, rule 4 again with the longer `reach`.
fn keep_a_handful(points: &[[f64; 3]], rows: &[u32], outlier: &mut [bool], reach: f64) {
    let flagged = outlier.iter().filter(|&&o| o).count();
    if flagged > 0 && flagged * FEW_PER <= outlier.len() {
        keep_returns_past_the_rim(points, rows, outlier, reach);
    }
}

/// Rule 4: a flagged point is looked at from this many of its nearest kept neighbours.
const RIM_TRIES: usize = 4;
/// Rule 4: reach past the edge, in units of the median `k`-th neighbour distance.
const RIM_REACH: f64 = 4.0;
/// Rule 5: the reach past the edge, in units of the median `k`-th neighbour distance.
const LONE_REACH: f64 = 8.0;
/// Rule 5: one flagged point in this many is a handful.
const FEW_PER: usize = 2000;

/// Neighbourhood size for the normal and curvature fits of a cloud with noise `noise` and median
/// `k`-th ([`OUTLIER_K`]) neighbour distance `spacing`: the `k` whose neighbourhood radius is
/// about [`NOISE_RADII`] noise levels, so that the PCA normal's error (~ σ / radius) is a few
/// degrees; at least `k_min`, at most [`MAX_NOISY_K`]. Returns `k_min` when the noise is below
/// [`NOISY`] × the spacing (clean scans keep their neighbourhood).
pub(crate) fn noisy_knn(noise: f64, spacing: f64, k_min: usize) -> usize {
    if !is_noisy(noise, spacing) {
        return k_min;
    }
    // Radius of k neighbours on a surface ≈ spacing · (k / OUTLIER_K)^½.
    let r = NOISE_RADII * noise;
    let k = (OUTLIER_K as f64 * (r / spacing).powi(2)).ceil();
    (k.min(MAX_NOISY_K as f64) as usize).max(k_min)
}

/// Whether noise level `noise` makes a scan of median 16th-neighbour distance `spacing` noisy
/// (above [`NOISY`] × `spacing`).
pub(crate) fn is_noisy(noise: f64, spacing: f64) -> bool {
    spacing > 0.0 && noise > NOISY * spacing
}

/// Noise level, relative to the median 16th-neighbour distance, above which a scan is noisy.
/// Clean scans measure below 0.02 (curvature sag); 0.3 % noise on 150k points about 0.25.
pub(crate) const NOISY: f64 = 0.3;
/// Target neighbourhood radius in noise levels for noisy scans (see [`noisy_knn`]).
const NOISE_RADII: f64 = 8.0;
/// Largest neighbourhood chosen by [`noisy_knn`].
pub(crate) const MAX_NOISY_K: usize = 96;

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize) -> Vec<[f64; 3]> {
        (0..n * n)
            .map(|i| {
                let (x, y) = ((i % n) as f64 / n as f64, (i / n) as f64 / n as f64);
                [x, y, 0.1 * (x * x + y * y)]
            })
            .collect()
    }

    /// [`detect`] with removal on `p`.
    fn scan(p: &[[f64; 3]]) -> OutlierScan {
        let idx = PointIndex::new(p).unwrap();
        detect(p, &idx, true, &Cancel::default()).unwrap()
    }

    #[test]
    fn clean_grid_keeps_everything_and_a_far_point_goes() {
        let mut p = grid(60);
        let s = scan(&p);
        assert_eq!(s.count, 0);
        assert!(s.noise < 0.01 * s.spacing, "{s:?}");
        p.push([0.5, 0.5, 0.6]);
        p.push([0.3, 0.7, 0.12]);
        let s = scan(&p);
        assert_eq!(s.count, 2);
        assert!(s.outlier[p.len() - 1] && s.outlier[p.len() - 2]);
    }

    #[test]
    fn a_lone_return_past_the_edge_is_kept_and_one_above_the_middle_is_not() {
        let mut p = grid(60);
        let d = scan(&p).spacing;
        // Past the last column (x = 59/60) by 3.5 D, a D below the surface's continuation:
        // the surface turning away, as near a range scan's silhouette.
        let x = 59.0 / 60.0 + 3.5 * d;
        p.push([x, 0.5, 0.1 * (x * x + 0.25) - d]);
        // The same height off the surface, above the middle of the patch, twice (two in
        // 3,602 points are more than a handful, rule 5).
        p.push([0.5, 0.5, 0.1 * 0.5 + d]);
        p.push([0.3, 0.6, 0.1 * 0.45 + d]);
        let s = scan(&p);
        assert!(!s.outlier[p.len() - 3], "{s:?}");
        assert!(s.outlier[p.len() - 2] && s.outlier[p.len() - 1]);
        assert_eq!(s.count, 2);
    }

    #[test]
    fn a_handful_of_returns_farther_past_the_edge_is_kept() {
        let mut p = grid(60);
        let d = scan(&p).spacing;
        // 6 D past the last column (beyond rule 4's reach, within rule 5's), 2 D below the
        // surface's continuation (a part behind the edge): the only point flagged in 3,601.
        let x = 59.0 / 60.0 + 6.0 * d;
        let past = [x, 0.5, 0.1 * (x * x + 0.25) - 2.0 * d];
        p.push(past);
        let s = scan(&p);
        assert_eq!(s.count, 0, "{s:?}");
        // 3 D above the middle instead: not past an edge, dropped though alone.
        *p.last_mut().unwrap() = [0.5, 0.5, 0.1 * 0.5 + 3.0 * d];
        let s = scan(&p);
        assert_eq!(s.count, 1);
        // Two past opposite edges in 3,602 points are not a handful: both dropped.
        *p.last_mut().unwrap() = past;
        let x = -6.0 * d;
        p.push([x, 0.5, 0.1 * (x * x + 0.25) - 2.0 * d]);
        let s = scan(&p);
        assert_eq!(s.count, 2);
    }

    #[test]
    fn noisy_knn_grows_with_noise_only() {
        assert_eq!(noisy_knn(0.0, 0.01, 24), 24);
        assert_eq!(noisy_knn(0.0005, 0.01, 24), 24);
        let k = noisy_knn(0.01, 0.01, 24);
        assert!(k > 48 && k <= MAX_NOISY_K, "{k}");
    }
}
