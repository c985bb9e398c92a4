//! Step 1 of the cloud feature detection (see the parent module): the per-point test that
//! finds **feature points** — two normal clusters of the neighbourhood (Weber, Hahmann & Hagen
//! 2010, §3), a least-squares plane per cluster — and projects them onto the planes'
//! intersection line (Daniels et al. 2007, §3).

use subfit_mesh::vec3::{add, cross, dot, norm, normalize, scale, sub};

use crate::neighbors::PointIndex;
use crate::quadric::sym3_eigen;

/// Smallest fraction of the neighbourhood each normal cluster must hold for a feature point.
pub const MIN_SHARE: f64 = 0.2;

/// Largest RMS residual of the two planes, as a fraction of the neighbourhood radius (plus
/// twice the noise level), for a feature point: a designed crease is sharp at the scale of the
/// neighbourhood, a scan's fold (a nose's ridge, an ear's root) is rounded over it and leaves
/// residuals of 2–5 % (Igea).
pub const MAX_FIT: f64 = 0.015;

/// A point of the cloud projected onto the crease its neighbourhood straddles.
#[derive(Clone, Copy, Debug)]
pub(super) struct CreaseSample {
    /// Projection onto the two planes' intersection line.
    pub(super) pos: [f64; 3],
    /// Unit crease direction `n1 × n2`.
    pub(super) dir: [f64; 3],
    /// Distance from the original point to `pos`.
    pub(super) offset: f64,
    /// Neighbourhood radius.
    pub(super) radius: f64,
}

/// The per-point test of step 1 (module docs).
pub(super) fn crease_sample(
    i: usize,
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    index: &PointIndex,
    k: usize,
    cos_angle: f64,
    noise: f64,
) -> Option<CreaseSample> {
    let p = points[i];
    let nb = index.k_nearest(&p, k);
    let m = nb.len();
    if m < 8 {
        return None;
    }
    let radius = nb[m - 1].distance;
    let qs: Vec<[f64; 3]> = nb.iter().map(|n| points[n.index as usize]).collect();
    let ns: Vec<[f64; 3]> = nb.iter().map(|n| normals[n.index as usize]).collect();
    // Seeds: the normal farthest from this point's, then the one farthest from that.
    let farthest = |from: [f64; 3]| {
        (0..m)
            .min_by(|&a, &b| dot(from, ns[a]).total_cmp(&dot(from, ns[b])))
            .unwrap_or(0)
    };
    let a = farthest(normals[i]);
    let b = farthest(ns[a]);
    let half = (0.5 * cos_angle.clamp(-1.0, 1.0).acos()).cos();
    if !(dot(ns[a], ns[b]) < half) {
        return None;
    }
    // 2-means on the sphere.
    let mut centre = [ns[a], ns[b]];
    let mut label = vec![0usize; m];
    for _ in 0..4 {
        for j in 0..m {
            label[j] = usize::from(dot(ns[j], centre[1]) > dot(ns[j], centre[0]));
        }
        for (c, slot) in centre.iter_mut().enumerate() {
            let s = (0..m)
                .filter(|&j| label[j] == c)
                .fold([0.0; 3], |acc, j| add(acc, ns[j]));
            *slot = normalize(s)?;
        }
    }
    // Planes through each cluster's points, reassigned once by distance.
    let mut planes = [
        fit_plane(&qs, &label, 0, centre[0])?,
        fit_plane(&qs, &label, 1, centre[1])?,
    ];
    for j in 0..m {
        let d = planes.map(|pl| dot(sub(qs[j], pl.0), pl.1).abs());
        label[j] = usize::from(d[1] < d[0]);
    }
    planes = [
        fit_plane(&qs, &label, 0, planes[0].1)?,
        fit_plane(&qs, &label, 1, planes[1].1)?,
    ];
    let count1 = label.iter().filter(|&&l| l == 1).count();
    if (count1.min(m - count1) as f64) < MIN_SHARE * m as f64 {
        return None;
    }
    let (n0, n1) = (planes[0].1, planes[1].1);
    let g = dot(n0, n1);
    if !(g <= cos_angle) {
        return None;
    }
    // Two planes must explain the neighbourhood much better than one.
    let rms2 = ((0..m)
        .map(|j| {
            let pl = planes[label[j]];
            dot(sub(qs[j], pl.0), pl.1).powi(2)
        })
        .sum::<f64>()
        / m as f64)
        .sqrt();
    let all = vec![0usize; m];
    let one = fit_plane(&qs, &all, 0, n0)?;
    let rms1 = (one.2 / m as f64).sqrt();
    if !(rms2 <= 0.5 * rms1) || !(rms2 <= MAX_FIT * radius + 2.0 * noise.max(0.0)) {
        return None;
    }
    // Closest point to p on the intersection line.
    let det = 1.0 - g * g;
    if !(det > 1e-12) {
        return None;
    }
    let r0 = dot(n0, sub(planes[0].0, p));
    let r1 = dot(n1, sub(planes[1].0, p));
    let (ca, cb) = ((r0 - g * r1) / det, (r1 - g * r0) / det);
    let pos = add(p, add(scale(n0, ca), scale(n1, cb)));
    let offset = norm(sub(pos, p));
    if !(offset <= 0.5 * radius) {
        return None;
    }
    let dir = normalize(cross(n0, n1))?;
    Some(CreaseSample {
        pos,
        dir,
        offset,
        radius,
    })
}

/// Least-squares plane through the points of `qs` labelled `c`: (centroid, unit normal on the
/// side of `towards`, sum of squared residuals). `None` with fewer than 3 points.
fn fit_plane(
    qs: &[[f64; 3]],
    label: &[usize],
    c: usize,
    towards: [f64; 3],
) -> Option<([f64; 3], [f64; 3], f64)> {
    let sel: Vec<[f64; 3]> = qs
        .iter()
        .zip(label)
        .filter(|(_, &l)| l == c)
        .map(|(q, _)| *q)
        .collect();
    if sel.len() < 3 {
        return None;
    }
    let inv = 1.0 / sel.len() as f64;
    let mean = scale(sel.iter().fold([0.0; 3], |a, &q| add(a, q)), inv);
    let mut cov = [[0.0; 3]; 3];
    for q in &sel {
        let d = sub(*q, mean);
        for r in 0..3 {
            for s in 0..3 {
                cov[r][s] += d[r] * d[s];
            }
        }
    }
    let (vals, vecs) = sym3_eigen(cov);
    let mut n = vecs[0];
    if dot(n, towards) < 0.0 {
        n = scale(n, -1.0);
    }
    Some((mean, n, vals[0].max(0.0)))
}
