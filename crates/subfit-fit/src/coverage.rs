//! The data → surface part of the objective ("coverage"; DESIGN.md decision 11;
//! boundary-aware fitting, Lavoué et al. 2005 §4.2 and §5.2 on boundaries that must reach the
//! data's edge).
//!
//! Cheng et al.'s terms (2007 §II-D) are one-sided: every sample of the limit surface is pulled
//! onto the data, but nothing pulls the surface over data it does not cover. An open surface's
//! limit boundary is a B-spline of the control boundary and lies inside it, so its rim shrinks
//! away from the data's edge with zero one-sided error (a 96-vertex neck rim 16% of the diagonal
//! from the limit surface; holes that close up; sharp tips cut off). This module adds the other
//! direction, in the form of the same per-sample quadratic model the fitter already solves:
//!
//! ```text
//! F = (1/m) Σ_k e_k(S_k)²  +  (w/N) Σ_j (S_k(j) − p_j)ᵀ Q_j (S_k(j) − p_j)
//! ```
//!
//! for the `N` data points `p_j`, each with its nearest sample `S_k(j)` (a kd-tree over the
//! samples, rebuilt at every projection, so the assignment follows the surface). A pair counts
//! where the surface ends — the nearest sample is on the tessellation's boundary and `p_j`
//! lies beyond it (data just inside would pull the rim inward and bunch its samples up) — or
//! the data does — `p_j` is a boundary vertex of a mesh target — with `Q_j = I`
//! (point-to-point): there the gap is tangential and must be closed along the surface.
//! Interior pairs (point-to-plane, `Q_j = n_j n_jᵀ`) count only where the data is uncovered —
//! the data point farther than two mean sample spacings from its nearest sample, full weight
//! from four (a thin tip or a deep fold the cage cuts off, a limb or tentacle the initial cage
//! collapsed) — on every mesh target, open or closed, and off on point clouds
//! ([`Coverage::with_interior`] sets them); where the surface covers the data they add
//! nothing, so there the fit is the papers' objective. Where such a gap runs along the surface
//! (more than 60° from the data normal, [`TANGENTIAL_GAP`]: a tip the cage cuts off, whose
//! tangent plane passes through the sample) the pair pulls point-to-point instead, except
//! within [`CREASE_ZONE_EDGES`] of a crease of the cage, where a gap along a face is the
//! crease's (the feature term's). A sphere with a seven-vertex spike
//! (`crates/subfit/tests/thin_tips.rs`): the tip 0.98 % of the diagonal off before, 0.68 %
//! after; camel head 707 → 300 control points, Hausdorff 0.69 % → 0.31 %. A pair is also left out when the
//! sample's normal (from the sample tessellation) faces away from the data normal (the other
//! sheet of a thin part; the orientation of the whole cage is taken from the majority of
//! pairs, so either winding works).
//!
//! **Noisy point clouds** ([`subfit_target::TargetStats::is_noisy`]): interior pairs count
//! everywhere at full weight, point-to-plane along the surface's normal at the sample
//! (`Q_j = n_k n_kᵀ`; a noisy cloud's own normals are noisier). Cheng et al.'s one-sided term
//! is small for any surface inside the band of noisy points — every sample has a point near
//! it — so the surface drifts within the band; the data → surface least squares pins it to
//! the middle of the band (the scan's mean). Measured on 150k-point clouds with 0.3 % noise
//! and 3 % outliers (`hard_cases noisy`), `subfit fit` with defaults, two-sided RMS to the
//! clean mesh as a fraction of its diagonal, before → after: Lucy 1.84e-3 → 1.37e-3,
//! armadillo 1.36e-3 → 1.03e-3, camel head 1.15e-3 → 1.00e-3, bunny 1.08e-3 → 9.9e-4, Igea
//! 9.4e-4 → 8.9e-4, rocker arm 6.7e-4 → 5.7e-4, fertility 5.6e-4 → 4.8e-4; the beetle, fitted
//! to its 5,000-point budget, 7.9e-4 → 1.02e-3 (at about 30 points per control point the
//! pairs' own noise, σ·√(3·#control points / #points), is no longer small).
//!
//! Per sample the assigned data points sum to one quadratic `eᵀ Q e − 2 eᵀ b + c` in
//! `e = S_k − x₀` (`x₀` the sample at the projection), added to the sample's own model. The
//! weight `w` is [`crate::FitOptions::coverage`] (1: both directions count alike; 0: off, the
//! papers' one-sided objective). It applies to projections of all samples; the samples of an
//! active set (local stages) get none, since the nearest sample of a data point is only known
//! over all of them.
//!
//! **Feature curves** ([`Coverage::with_features`]): with the data's sharp feature curves
//! given (segments, e.g. the sharp edges the feature-aligned cage was built along), each
//! segment's midpoint also pulls its nearest sample on a crease of the tessellation, across
//! the data curve only (`Q = I − t tᵀ`), so the crease curve of the limit surface is fitted to
//! the feature curve rather than left to the surface samples on either side of it.
//! Weighted by [`FEATURE_WEIGHT`].
//!
//! Cost per projection: a kd-tree over the `m` samples (O(m log m), parallel above 50k), one
//! nearest query per data point (about 1 µs each), the sample normals (O(#tessellation
//! faces)), and a serial accumulation (O(N)).

use rayon::prelude::*;
use subfit_mesh::vec3::{cross, dot, normalize, sub};
use subfit_mesh::{Polygons, SHARPNESS_INFINITE};
use subfit_subdiv::SamplingOperator;
use subfit_target::{boundary_vertices, PointIndex, Target};

use crate::term::Mat3;

/// Weight of the feature-curve term ([`Coverage::with_features`]) relative to the data →
/// surface part: the mean squared distance of the data's feature curves to the surface's
/// creases counts a tenth of the mean over the surface. Measured on fandisk (`subfit fit`, Loop,
/// `subfit compare` over 200k area samples, unit cube): with defaults, 0 / 0.1 / 0.3 / 1 gave
/// data → surface mean 8.8e-5 / 5.9e-5 / 6.2e-5 / 6.1e-5 and Hausdorff 3.3e-3 / 2.2e-3 /
/// 2.3e-3 / 2.4e-3 of the diagonal (302–316 control points); at a budget of 75 control
/// points, mean 4.28e-4 / 4.18e-4 / 5.9e-4 / 6.7e-4 — a cage too coarse to follow the curves
/// pays for a heavy curve term on its surface. On a generated washer (200 control points), 0.1
/// lowered the Hausdorff from 1.59e-4 to 1.48e-4 of the diagonal.
pub const FEATURE_WEIGHT: f64 = 0.1;

/// The cosine between an uncovered interior data point's gap to its nearest sample and the
/// data normal below which the gap runs along the surface and the pair pulls point-to-point
/// ([`Coverage::with_interior`]): beyond 60° from the normal, the point-to-plane pull of a
/// tip the cage cuts off is less than half its gap.
pub const TANGENTIAL_GAP: f64 = 0.5;

/// How far from a crease of the cage, in cage edges, pairs pull point-to-plane only, whatever
/// the gap's direction ([`TANGENTIAL_GAP`]): the sample rings within `CREASE_ZONE_EDGES · 2^l`
/// of a crease sample at sample level `l`. Two sample rings (a quarter of a cage edge at level
/// 3) still let tangential pulls near the creases of a CAD part's faceted cage undo its start
/// (tray-bottom: stage 0 surface → data 0.36 % → 1.02 % of the diagonal, the fit ending
/// outside its 0.2 % tolerance).
pub const CREASE_ZONE_EDGES: usize = 2;

/// The data points a surface must cover, with the rule for each (see the module docs).
#[derive(Clone, Debug)]
pub struct Coverage {
    points: Vec<[f64; 3]>,
    /// Unit data normals (zero: unknown, point-to-point).
    normals: Vec<[f64; 3]>,
    /// Data point on the boundary of a mesh target (point-to-point).
    boundary: Vec<bool>,
    weight: f64,
    /// Whether interior pairs (point-to-plane) count too; see [`Self::with_interior`].
    interior: bool,
    /// A noisy point cloud: interior pairs count everywhere, along the sample's normal (see
    /// the module docs).
    noisy: bool,
    /// The fitter's sample tessellation (faces over sample rows), set by [`Self::prepare`].
    faces: Polygons,
    /// Sample rows on the tessellation's boundary.
    sample_boundary: Vec<bool>,
    /// Whether a data point is on the boundary or has no normal ([`Self::any_pair_counts`]),
    /// computed on first use.
    data_pairs: std::sync::OnceLock<bool>,
    /// Tessellation neighbours of the boundary samples (empty elsewhere).
    rings: Vec<Vec<u32>>,
    /// The data's sharp feature curves, as points with their unit tangent and weight (see
    /// [`Self::with_features`]).
    features: Vec<FeaturePoint>,
    /// Sample rows on the tessellation's crease edges (infinitely sharp tags of the level-`l`
    /// mesh), ascending; set by [`Self::prepare`].
    crease_samples: Vec<u32>,
    /// Sample rows within [`CREASE_ZONE_EDGES`] cage edges of a crease sample (no tangential
    /// pull there); set by [`Self::prepare`].
    near_crease: Vec<bool>,
}

/// A point of a data feature curve: the midpoint of a feature segment, its unit tangent and
/// its share of the curves' length.
#[derive(Clone, Copy, Debug, PartialEq)]
struct FeaturePoint {
    p: [f64; 3],
    t: [f64; 3],
    share: f64,
}

/// The data points assigned to one sample, summed into one quadratic in `e = x − x₀`:
/// `eᵀ q e − 2 eᵀ b + c` (normalized units², already weighted).
#[derive(Clone, Debug, PartialEq)]
pub struct CoverSum {
    /// The sample position at the assignment.
    x0: [f64; 3],
    q: Mat3,
    b: [f64; 3],
    c: f64,
    /// Data points assigned.
    count: u32,
}

impl CoverSum {
    fn new(x0: [f64; 3]) -> Self {
        Self {
            x0,
            q: [[0.0; 3]; 3],
            b: [0.0; 3],
            c: 0.0,
            count: 0,
        }
    }

    /// Adds `w (x − p)ᵀ Q (x − p)` with `Q = I` (`n = None`) or `n nᵀ`.
    fn add(&mut self, p: [f64; 3], n: Option<[f64; 3]>, w: f64) {
        let d = sub(p, self.x0);
        match n {
            None => {
                for (a, da) in d.iter().enumerate() {
                    self.q[a][a] += w;
                    self.b[a] += w * da;
                }
                self.c += w * dot(d, d);
            }
            Some(n) => {
                let dn = dot(d, n);
                for a in 0..3 {
                    for c in 0..3 {
                        self.q[a][c] += w * n[a] * n[c];
                    }
                    self.b[a] += w * n[a] * dn;
                }
                self.c += w * dn * dn;
            }
        }
        self.count += 1;
    }

    /// Adds `w (x − p)ᵀ (I − t tᵀ) (x − p)`: the squared distance to the line through `p`
    /// along the unit vector `t`.
    fn add_across(&mut self, p: [f64; 3], t: [f64; 3], w: f64) {
        let d = sub(p, self.x0);
        let dt = dot(d, t);
        for a in 0..3 {
            for c in 0..3 {
                let i = if a == c { 1.0 } else { 0.0 };
                self.q[a][c] += w * (i - t[a] * t[c]);
            }
            self.b[a] += w * (d[a] - t[a] * dt);
        }
        self.c += w * (dot(d, d) - dt * dt);
        self.count += 1;
    }

    /// The summed squared distances at `x`. Cost O(1).
    pub fn energy(&self, x: [f64; 3]) -> f64 {
        let e = sub(x, self.x0);
        let qe = crate::term::mul(&self.q, e);
        (dot(e, qe) - 2.0 * dot(e, self.b) + self.c).max(0.0)
    }

    /// The model at `x`: `Q` and half the gradient, `Q e − b`. Cost O(1).
    pub fn model(&self, x: [f64; 3]) -> (Mat3, [f64; 3]) {
        let e = sub(x, self.x0);
        let qe = crate::term::mul(&self.q, e);
        (self.q, std::array::from_fn(|a| qe[a] - self.b[a]))
    }

    /// Data points assigned to the sample.
    pub fn count(&self) -> u32 {
        self.count
    }
}

impl Coverage {
    /// The coverage of `target`'s points with weight `weight` (> 0): the target's normals, and
    /// for a mesh target only the vertices its triangles use, those on boundary edges (edges
    /// of one triangle) marked.
    /// Cost: O(#points + #triangles).
    pub fn new(target: &Target, weight: f64) -> Self {
        let all = target.points();
        // A mesh target's vertices that no triangle uses (left inside a hole that was cut,
        // say) are not data the surface must cover.
        let used: Vec<bool> = match target.mesh() {
            Some(bvh) => {
                let mut used = vec![false; all.len()];
                for &v in bvh.triangles().iter().flatten() {
                    if let Some(u) = used.get_mut(v as usize) {
                        *u = true;
                    }
                }
                used
            }
            None => vec![true; all.len()],
        };
        let mut on_rim = vec![false; all.len()];
        if let Some(bvh) = target.mesh() {
            for v in boundary_vertices(bvh.triangles()) {
                if let Some(b) = on_rim.get_mut(v as usize) {
                    *b = true;
                }
            }
        }
        let keep = |i: &usize| used[*i];
        let points = (0..all.len()).filter(keep).map(|i| all[i]).collect();
        let normals = (0..all.len())
            .filter(keep)
            .map(|i| normalize(target.normals()[i]).unwrap_or([0.0; 3]))
            .collect();
        let boundary: Vec<bool> = (0..all.len()).filter(keep).map(|i| on_rim[i]).collect();
        Self {
            points,
            normals,
            boundary,
            weight,
            // Mesh targets, open or closed (see `with_interior`).
            interior: target.mesh().is_some(),
            noisy: target.stats().is_noisy(),
            faces: Polygons::default(),
            sample_boundary: Vec::new(),
            data_pairs: std::sync::OnceLock::new(),
            rings: Vec::new(),
            features: Vec::new(),
            crease_samples: Vec::new(),
            near_crease: Vec::new(),
        }
    }

    /// Adds the data's sharp feature curves, given as segments (normalized units; e.g. the
    /// sharp edges of [`subfit_target::detect_features`]): the crease curve of the limit
    /// surface is fitted to them (Hoppe et al. 1994 §3 fit the creases of their
    /// tagged surfaces by the same point-to-surface energy, Lavoué et al. 2005 §4.2 fit
    /// boundary curves with a curve distance). Each segment's midpoint `p` pulls the nearest
    /// sample on a crease of the cage's tessellation perpendicular to the segment,
    /// `(x − p)ᵀ (I − t tᵀ) (x − p)` (the distance to the data curve's tangent line, so the
    /// samples may slide along it), weighted by the segment's length: the term is the mean
    /// squared distance of the data curves to the surface's creases, with
    /// [`FEATURE_WEIGHT`] times the weight of the data → surface part ([`Self::weight`]).
    /// Nothing happens while the cage has no crease
    /// (untagged cages, or none near a data curve). Degenerate segments are ignored.
    pub fn with_features(mut self, segments: &[[[f64; 3]; 2]]) -> Self {
        let mut out: Vec<FeaturePoint> = segments
            .iter()
            .filter_map(|&[a, b]| {
                let d = sub(b, a);
                let len = dot(d, d).sqrt();
                let t = normalize(d)?;
                (len.is_finite() && len > 0.0).then(|| FeaturePoint {
                    p: std::array::from_fn(|k| 0.5 * (a[k] + b[k])),
                    t,
                    share: len,
                })
            })
            .collect();
        let total: f64 = out.iter().map(|f| f.share).sum();
        if total > 0.0 {
            for f in &mut out {
                f.share /= total;
            }
        }
        self.features = out;
        self
    }

    /// Points of the data's feature curves ([`Self::with_features`]).
    pub fn num_feature_points(&self) -> usize {
        self.features.len()
    }

    /// Whether interior pairs (point-to-plane, the data point and its sample both away from a
    /// boundary) also count where the data is uncovered (see the module docs). Default: on for
    /// a mesh target, off for a point cloud. An open scan needs them (a camel's head's mouth
    /// and ears were left 2.6% of the diagonal uncovered without them, 0.67% with them, at 657
    /// control points instead of 888); so does closed data with thin parts, where the initial
    /// cage collapses a limb or a tentacle and nothing else pulls the surface back over it
    /// (`subfit bench corpus`, defaults, judged Hausdorff as a fraction of the diagonal,
    /// off → on: scan-actionfigure 12.9% → 0.76%, scan-octopus 11.6% → 0.84%, scan-vessel
    /// 6.6% → 0.58%). Counted everywhere, they traded surface → data error for data → surface
    /// error at sharp edges (rocker arm at 950 control points: two-sided RMS 3.5e-4, against
    /// 2.9e-4 without); gated to uncovered data, they reached a camel's head's tips (3% of the
    /// diagonal uncovered without them); the rocker arm's Table IV fit (closed; `--tolerance
    /// 0.0003 --max-error 0.0029 --max-control-points 950 --one-sided`) ends with them at 780
    /// control points, E_rms 2.98e-4 and E_max 2.0e-3 (two-sided 3.13e-4, 2.55e-3), within
    /// the table's figures. On single-view range clouds they
    /// helped one and hurt another (range-dragon-stand-0: Hausdorff 1.26% → 1.21%;
    /// range-dragon-stand-264: exit 0 → 1, RMS 0.068% → 0.073%), so clouds keep them off.
    pub fn with_interior(mut self, interior: bool) -> Self {
        self.interior = interior;
        self
    }

    /// The weight `w`.
    pub fn weight(&self) -> f64 {
        self.weight
    }

    /// Data points on the target's boundary.
    pub fn num_boundary_points(&self) -> usize {
        self.boundary.iter().filter(|&&b| b).count()
    }

    /// Takes the tessellation of the fitter's samples (for their normals and boundary).
    /// Cost: O(#tessellation faces).
    pub fn prepare(&mut self, op: &SamplingOperator) {
        self.faces = op.faces.clone();
        let tris: Vec<[u32; 3]> = op.faces.triangulate_fan();
        let mut sb = vec![false; op.num_vertices];
        for v in boundary_vertices(&tris) {
            sb[v as usize] = true;
        }
        // The tessellation neighbours of every boundary sample (for its outward direction).
        let mut rings: Vec<Vec<u32>> = vec![Vec::new(); op.num_vertices];
        for f in op.faces.iter() {
            for i in 0..f.len() {
                let (a, b) = (f[i], f[(i + 1) % f.len()]);
                for (u, w) in [(a, b), (b, a)] {
                    if sb[u as usize] && !rings[u as usize].contains(&w) {
                        rings[u as usize].push(w);
                    }
                }
            }
        }
        self.sample_boundary = sb;
        self.rings = rings;
        let mut creases: Vec<u32> = op
            .tags
            .creases()
            .into_iter()
            .filter(|&(_, s)| s >= SHARPNESS_INFINITE)
            .flat_map(|((a, b), _)| [a, b])
            .filter(|&v| (v as usize) < op.num_vertices)
            .collect();
        creases.sort_unstable();
        creases.dedup();
        let mut near = vec![false; op.num_vertices];
        for &v in &creases {
            near[v as usize] = true;
        }
        let rings = if creases.is_empty() {
            0
        } else {
            CREASE_ZONE_EDGES << op.level.min(8)
        };
        for _ in 0..rings {
            let before = near.clone();
            for f in op.faces.iter() {
                if f.iter().any(|&v| before[v as usize]) {
                    for &v in f {
                        near[v as usize] = true;
                    }
                }
            }
        }
        self.near_crease = near;
        self.crease_samples = creases;
    }

    /// Sample rows on the creases of the prepared tessellation.
    pub fn num_crease_samples(&self) -> usize {
        self.crease_samples.len()
    }

    /// Whether `p` lies beyond the boundary sample `k` (on the side away from the surface):
    /// the offset has a positive component along the sample's outward direction, the sample
    /// minus the mean of its tessellation neighbours.
    fn beyond(&self, xs: &[[f64; 3]], k: usize, p: [f64; 3]) -> bool {
        let ring = &self.rings[k];
        if ring.is_empty() {
            return true;
        }
        let mut c = [0.0; 3];
        for &w in ring {
            for a in 0..3 {
                c[a] += xs[w as usize][a] / ring.len() as f64;
            }
        }
        dot(sub(xs[k], c), sub(p, xs[k])) > 0.0
    }

    /// The direction along the rim at the boundary sample `k` towards `p`: to the boundary
    /// neighbour of `k` most nearly in line with `p − x_k` (at a corner sample, the edge `p`
    /// lies along). `None` when `k` has no boundary neighbour.
    fn rim_tangent(&self, xs: &[[f64; 3]], k: usize, p: [f64; 3]) -> Option<[f64; 3]> {
        let d = sub(p, xs[k]);
        self.rings[k]
            .iter()
            .filter(|&&w| self.sample_boundary[w as usize])
            .filter_map(|&w| normalize(sub(xs[w as usize], xs[k])))
            .max_by(|a, b| dot(*a, d).abs().total_cmp(&dot(*b, d).abs()))
    }

    /// The data points' quadratics summed per sample for the samples `xs` (all rows of the
    /// prepared tessellation, in order). `None` where no data point is assigned; all `None`
    /// when `xs` does not match the tessellation. Weighted so that the objective's mean over
    /// the `m = xs.len()` samples gives `(w/N) Σ_j`.
    pub fn assign(&self, xs: &[[f64; 3]]) -> Vec<Option<Box<CoverSum>>> {
        let m = xs.len();
        let mut out: Vec<Option<Box<CoverSum>>> = Vec::new();
        out.resize_with(m, || None);
        if m == 0 || self.points.is_empty() || self.sample_boundary.len() != m {
            return out;
        }
        let sample_normals = vertex_normals(&self.faces, xs);
        let spacing = mean_edge_length(&self.faces, xs);
        // Where no data point can pull its nearest sample the search is skipped.
        if self.any_pair_counts(&sample_normals) {
            self.assign_pairs(xs, &sample_normals, spacing, &mut out);
        }
        self.assign_features(xs, spacing, &mut out);
        out
    }

    /// The data points' part of [`Self::assign`]: every data point's pair with its nearest
    /// sample (normals of the samples `sample_normals`, mean sample spacing `spacing`).
    fn assign_pairs(
        &self,
        xs: &[[f64; 3]],
        sample_normals: &[[f64; 3]],
        spacing: f64,
        out: &mut [Option<Box<CoverSum>>],
    ) {
        let m = xs.len();
        let Some(index) = PointIndex::new(xs) else {
            return;
        };
        // Nearest sample and the normals' agreement of every data point.
        let pairs: Vec<(u32, f64, f64)> = self
            .points
            .par_iter()
            .zip(self.normals.par_iter())
            .map(|(p, n)| {
                let nb = index.nearest(p);
                (
                    nb.index,
                    dot(sample_normals[nb.index as usize], *n),
                    nb.distance,
                )
            })
            .collect();
        let orient: f64 = pairs.iter().map(|&(_, c, _)| c.signum()).sum();
        let s = if orient < 0.0 { -1.0 } else { 1.0 };
        let w = self.weight * m as f64 / self.points.len() as f64;
        for (j, &(k, cos, dist)) in pairs.iter().enumerate() {
            let n = self.normals[j];
            let known = n != [0.0; 3] && sample_normals[k as usize] != [0.0; 3];
            if known && s * cos <= 0.0 {
                continue;
            }
            // At the surface's rim only data beyond it pulls point-to-point: data just inside
            // would pull the rim samples inward along the surface and bunch them up.
            let past_rim =
                self.sample_boundary[k as usize] && self.beyond(xs, k as usize, self.points[j]);
            let point_to_point = !known || self.boundary[j] || past_rim;
            // An interior pair counts only where the data is uncovered: from 0 at two sample
            // spacings (a covered point is within about one of its nearest sample) to full
            // weight at four; on a noisy cloud everywhere.
            let gate = if point_to_point || self.noisy {
                1.0
            } else if self.interior && spacing > 0.0 {
                (dist / (2.0 * spacing) - 1.0).clamp(0.0, 1.0)
            } else {
                0.0
            };
            if gate <= 0.0 {
                continue;
            }
            // A data boundary point not beyond the surface's rim pulls its rim sample across
            // the rim only: along it the pull is one-sided where the rim ends (at a corner of
            // a coarse cage the samples within half a sample spacing of it pulled the corner
            // inward, uncovering the data's corner).
            let along = (self.boundary[j] && self.sample_boundary[k as usize] && !past_rim)
                .then(|| self.rim_tangent(xs, k as usize, self.points[j]))
                .flatten();
            let sum =
                out[k as usize].get_or_insert_with(|| Box::new(CoverSum::new(xs[k as usize])));
            let plane = if self.noisy {
                sample_normals[k as usize]
            } else {
                n
            };
            // An uncovered point whose gap to its sample runs along the surface (a tip the
            // cage cuts off, a flap folded back) pulls point-to-point: its plane passes
            // through the sample, so point-to-plane would not pull at all. Not near a crease
            // of the cage: there a gap along a face is the crease's, which the feature term
            // closes across the curve only (point-to-point pulls dragged a CAD part's creased
            // samples along its faces: tray-bottom 0.11 % → 0.32 % of the diagonal).
            let tangential = !point_to_point
                && !self.noisy
                && !self.near_crease.get(k as usize).copied().unwrap_or(false)
                && {
                    let d = sub(self.points[j], xs[k as usize]);
                    dot(d, plane).abs() < TANGENTIAL_GAP * dot(d, d).sqrt()
                };
            match along {
                Some(t) => sum.add_across(self.points[j], t, w * gate),
                None => sum.add(
                    self.points[j],
                    (!point_to_point && !tangential).then_some(plane),
                    w * gate,
                ),
            }
        }
    }

    /// Whether any data point's pair with its nearest sample can count in [`Self::assign`]
    /// (the samples' vertex normals `sample_normals`): a pair is skipped there unless the
    /// cloud is noisy, interior pairs are on, it is point-to-point (a data point without a
    /// normal or on the data's boundary, a sample without a normal, or a sample on the
    /// surface's rim, the only place data can lie beyond it). When none of those can hold, no
    /// pair counts, whichever sample is nearest: on a closed cage over a closed, clean point
    /// cloud (interior pairs off) the nearest-sample search of every data point (a kd-tree over
    /// the samples and one query per data point, every projection) is skipped with the same
    /// result. Cost O(#points) the
    /// first time (cached per term), O(m) after.
    fn any_pair_counts(&self, sample_normals: &[[f64; 3]]) -> bool {
        let data = *self
            .data_pairs
            .get_or_init(|| self.boundary.iter().any(|&b| b) || self.normals.contains(&[0.0; 3]));
        self.noisy
            || self.interior
            || data
            || self.sample_boundary.iter().any(|&b| b)
            || sample_normals.contains(&[0.0; 3])
    }

    /// The feature part of [`Self::assign`]: every data feature point pulls its nearest crease
    /// sample, perpendicular to the data curve, where that sample is within four mean sample
    /// spacings (`spacing`): a data curve the cage has no crease for (dropped as too small by
    /// the simplification) must not pull another curve's samples.
    fn assign_features(&self, xs: &[[f64; 3]], spacing: f64, out: &mut [Option<Box<CoverSum>>]) {
        if self.features.is_empty() || self.crease_samples.is_empty() {
            return;
        }
        let at: Vec<[f64; 3]> = self
            .crease_samples
            .iter()
            .map(|&k| xs[k as usize])
            .collect();
        let Some(index) = PointIndex::new(&at) else {
            return;
        };
        let reach = 4.0 * spacing;
        let nearest: Vec<Option<u32>> = self
            .features
            .par_iter()
            .map(|f| {
                let nb = index.nearest(&f.p);
                (nb.distance <= reach).then(|| self.crease_samples[nb.index as usize])
            })
            .collect();
        let m = xs.len() as f64;
        for (f, k) in self.features.iter().zip(&nearest) {
            let Some(k) = *k else { continue };
            let sum =
                out[k as usize].get_or_insert_with(|| Box::new(CoverSum::new(xs[k as usize])));
            sum.add_across(f.p, f.t, FEATURE_WEIGHT * self.weight * m * f.share);
        }
    }
}

/// The mean edge length of the polygons `faces` over `xs` (each edge counted once per face
/// side). Cost O(#corners).
fn mean_edge_length(faces: &Polygons, xs: &[[f64; 3]]) -> f64 {
    let (mut sum, mut count) = (0.0, 0usize);
    for f in faces.iter() {
        for i in 0..f.len() {
            let (a, b) = (xs[f[i] as usize], xs[f[(i + 1) % f.len()] as usize]);
            sum += subfit_mesh::vec3::dist2(a, b).sqrt();
            count += 1;
        }
    }
    if count == 0 {
        0.0
    } else {
        sum / count as f64
    }
}

/// Unit vertex normals of the polygon mesh `faces` over `xs` (Newell normals of the faces,
/// area-weighted, summed at their vertices; zero where they cancel). Cost O(#corners).
pub(crate) fn vertex_normals(faces: &Polygons, xs: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let mut acc = vec![[0.0; 3]; xs.len()];
    for f in faces.iter() {
        let mut n = [0.0; 3];
        for i in 0..f.len() {
            let (a, b) = (xs[f[i] as usize], xs[f[(i + 1) % f.len()] as usize]);
            let c = cross(a, b);
            for k in 0..3 {
                n[k] += c[k];
            }
        }
        for &v in f {
            for k in 0..3 {
                acc[v as usize][k] += n[k];
            }
        }
    }
    acc.into_iter()
        .map(|n| normalize(n).unwrap_or([0.0; 3]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The model's residual is half the gradient of the energy at `x`, by central differences.
    fn assert_half_gradient(s: &CoverSum, x: [f64; 3]) {
        let (_, r) = s.model(x);
        for a in 0..3 {
            let h = 1e-6;
            let (mut xp, mut xm) = (x, x);
            xp[a] += h;
            xm[a] -= h;
            let fd = (s.energy(xp) - s.energy(xm)) / (4.0 * h);
            assert!((fd - r[a]).abs() < 1e-6, "{a}: {fd} vs {}", r[a]);
        }
    }

    /// The skipped search gives what the search gives: on a closed torus target with a
    /// closed cage (clean data, every normal known) no data point's pair counts, so the full
    /// pair pass assigns nothing; a coverage with interior pairs on does search.
    #[test]
    fn no_pair_counts_on_closed_clean_data() {
        use subfit_mesh::shapes::torus_mesh;
        use subfit_subdiv::{sampling_operator, Options, Scheme};
        use subfit_target::{Target, TargetOptions};
        let dense = torus_mesh(1.0, 0.35, 48, 24, true);
        let target = Target::from_mesh(&dense, &TargetOptions::default()).unwrap();
        let cage = torus_mesh(1.0, 0.1, 16, 6, true);
        let cage_n: Vec<[f64; 3]> = cage
            .positions
            .iter()
            .map(|&p| target.to_normalized(p))
            .collect();
        let op = sampling_operator(
            &cage.faces,
            cage.num_vertices(),
            &subfit_mesh::Tags::new(),
            &Options::new(Scheme::Loop),
            2,
        )
        .unwrap();
        let xs = op.position.apply(&cage_n);
        let mut c = Coverage::new(&target, 1.0).with_interior(false);
        c.prepare(&op);
        let normals = vertex_normals(&c.faces, &xs);
        assert!(!c.any_pair_counts(&normals));
        let mut full: Vec<Option<Box<CoverSum>>> = Vec::new();
        full.resize_with(xs.len(), || None);
        c.assign_pairs(&xs, &normals, mean_edge_length(&c.faces, &xs), &mut full);
        assert!(full.iter().all(Option::is_none));
        assert!(c.assign(&xs).iter().all(Option::is_none));
        let mut inner = Coverage::new(&target, 1.0).with_interior(true);
        inner.prepare(&op);
        assert!(inner.any_pair_counts(&normals));
        // The cage sits 0.25 inside the tube (several sample spacings): interior pairs pull.
        assert!(inner.assign(&xs).iter().any(Option::is_some));
    }

    #[test]
    fn cover_sum_is_the_sum_of_its_parts() {
        let x0 = [0.1, -0.2, 0.3];
        let mut s = CoverSum::new(x0);
        let pts = [[0.0, 0.0, 0.0], [1.0, 0.5, -0.5], [0.3, 0.3, 0.9]];
        let n = normalize([1.0, 2.0, -0.5]).unwrap();
        s.add(pts[0], None, 2.0);
        s.add(pts[1], Some(n), 0.5);
        s.add(pts[2], None, 1.0);
        let x = [0.4, 0.1, -0.7];
        let direct = 2.0 * subfit_mesh::vec3::dist2(x, pts[0])
            + 0.5 * dot(sub(x, pts[1]), n).powi(2)
            + subfit_mesh::vec3::dist2(x, pts[2]);
        assert!((s.energy(x) - direct).abs() < 1e-12 * direct);
        assert_half_gradient(&s, x);
        assert_eq!(s.count(), 3);
    }

    #[test]
    fn across_is_the_distance_to_the_line() {
        let x0 = [0.2, 0.1, -0.3];
        let mut s = CoverSum::new(x0);
        let p = [1.0, -0.5, 0.25];
        let t = normalize([0.3, -1.0, 2.0]).unwrap();
        s.add_across(p, t, 1.5);
        let x = [-0.4, 0.7, 0.9];
        let d = sub(x, p);
        let along = dot(d, t);
        let direct = 1.5 * (dot(d, d) - along * along);
        assert!((s.energy(x) - direct).abs() < 1e-12 * direct.max(1.0));
        // Moving along the line costs nothing.
        let y = std::array::from_fn(|k| x[k] + 0.8 * t[k]);
        assert!((s.energy(y) - s.energy(x)).abs() < 1e-12);
        assert_half_gradient(&s, x);
    }

    #[test]
    fn boundary_vertices_of_a_strip() {
        // Two triangles sharing edge (1, 2): every vertex is on the boundary; a closed
        // tetrahedron has none.
        assert_eq!(boundary_vertices(&[[0, 1, 2], [2, 1, 3]]), vec![0, 1, 2, 3]);
        let tet = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        assert!(boundary_vertices(&tet).is_empty());
    }
}
