//! The foot-point error terms PD, TD and SD (Cheng et al. 2007, §II-D, eq. 3, 4 and 6; Cheng
//! et al. 2004, §4.4; DESIGN.md §3.2–3.3) as a [`DataTerm`].
//!
//! Each sample `S_k` is projected onto the fixed target (Cheng: foot points come from the
//! target, not the surface), which gives the foot point `V_k`, the signed distance `d_k`, the
//! normal `N`, the principal directions `T1`, `T2` and radii `ρ1`, `ρ2`
//! ([`subfit_target::FootPoint`]). The true squared error is `‖S_k − V_k‖²`; every term is a
//! quadratic form `f_k² = (S_k − V_k)ᵀ Q_k (S_k − V_k)` in the variable sample point, with the
//! foot point and the frame frozen at the current iterate:
//!
//! * PD (eq. 3): `Q = I`;
//! * TD (eq. 4): `Q = N Nᵀ`;
//! * SD (eq. 6): `Q = N Nᵀ + [α1]₊ T1 T1ᵀ + [α2]₊ T2 T2ᵀ`, `α_i = d / (d − ρ_i)`.
//!
//! Since `S_k − V_k` is along `N` at a foot point, every model has the true error's value and
//! gradient there (PD exactly, TD and SD through `Q (S − V) = S − V`).
//!
//! Sign convention (§II-D3): `d > 0` when the sample lies on the side `N` points to; `ρ_i > 0`
//! when the centre of curvature of the normal section along `T_i` lies on that side. For a sphere
//! of radius `r` with outward normals `ρ = −r`, and a sample at distance `d > 0` outside gets
//! `α = d / (d + r)`. The `[α]₊` values come precomputed from
//! [`subfit_target::FootPoint`] (which also zeroes them beyond the focal point).
//!
//! Where the foot points come from ([`FootPointSource`]): a point cloud has only its local
//! quadrics ([`Target::foot_points`]); a mesh target also has its triangles, and then the exact
//! closest point on them is the better foot point ([`Target::mesh_foot_point`]).
//!
//! With a [`Coverage`] (weight [`FitOptions::coverage`] > 0) the term also pulls the surface
//! over data it leaves uncovered: each projection of all samples assigns every data point to
//! its nearest sample and adds its quadratic to that sample's model and objective share
//! ([`crate::coverage`]). The measured error ([`DataTerm::squared_error`], and everything
//! from [`DataTerm::project_fresh`]) stays the surface → data distance.
//!
//! With an error power `p > 2` ([`FitOptions::error_power`]) the surface → data part is the
//! mean of `e_k^p / r^(p−2)` instead of `e_k²`, `r` the RMS error at the term's first
//! projection of all samples: every projection weights each sample's quadratic by
//! `w_k = (e_k / r)^(p−2)` (clamped to [[`POWER_WEIGHT_MIN`], [`POWER_WEIGHT_MAX`]]), which
//! is iteratively reweighted least squares for the `L_p` norm (Lawson's algorithm tends to the
//! minimax fit as `p` grows). The objective `Σ w_k e_k²` is then a function of the control
//! points alone (the weights follow the errors), so the step controls compare trials as
//! before. A larger `p` lowers the largest errors at some cost in RMS: the stages' last
//! polish ([`crate::StageOptions::polish_power`]).

use std::sync::{Mutex, PoisonError};

use rayon::prelude::*;
use subfit_mesh::vec3::dot;
use subfit_target::{FootPoint, Target};

use crate::coverage::{CoverSum, Coverage};
use crate::options::{FitOptions, FootPointSource, Method};
use crate::term::{add_mat, mul, DataTerm, Mat3, IDENTITY};

/// The smallest weight `(e_k / r)^(p−2)` a sample gets with an error power `p > 2` (see the
/// module docs): samples far below the RMS keep a twentieth of their pull, so the surface
/// where it fits does not drift while the largest errors are lowered.
pub const POWER_WEIGHT_MIN: f64 = 0.05;

/// The largest weight a sample gets with an error power `p > 2`: one sample (an outlier the
/// cleaning left, a spike) cannot take over the fit.
pub const POWER_WEIGHT_MAX: f64 = 20.0;

/// `Q_k` of `method` for one foot point (see the module docs). Cost: O(1).
pub fn error_matrix(method: Method, foot: &FootPoint) -> Mat3 {
    match method {
        Method::Pdm => IDENTITY,
        Method::Tdm | Method::Imls => outer(foot.normal, foot.normal, 1.0),
        Method::Sdm => {
            let mut q = outer(foot.normal, foot.normal, 1.0);
            add_outer(&mut q, foot.t1, sanitize(foot.alpha1));
            add_outer(&mut q, foot.t2, sanitize(foot.alpha2));
            q
        }
    }
}

/// Cheng's foot-point terms on a [`Target`]: the samples are projected onto the target from
/// `source`, and `method` makes the quadratic model. The nearest data point of every sample is
/// kept as the warm start of the next projection of the same sample row
/// ([`Target::foot_points_hinted`]; the triangle path needs none), so a term serves one
/// sampling operator (one [`crate::Fitter`]).
#[derive(Debug)]
pub struct FootPointTerm<'t> {
    target: &'t Target,
    method: Method,
    source: FootPointSource,
    /// Nearest data point of every sample row at its last projection (`u32::MAX`: none).
    hints: Mutex<Vec<u32>>,
    /// The data → surface part of the objective, if any.
    coverage: Option<Coverage>,
    /// With coverage on an open target: which data points are on its edge — a mesh target's
    /// boundary vertices, a cloud's points by the angle criterion
    /// ([`subfit_target::cloud_boundary_points`]) — so that a sample whose foot point is there
    /// and which lies beyond the data's edge is pulled point-to-point (see
    /// [`DataTerm::model`]); empty for a closed target.
    rim: Vec<bool>,
    /// The error power `p` ([`FitOptions::error_power`]; 2: least squares).
    power: f64,
    /// With `p > 2`: the mean squared error `r²` at the first projection of all samples.
    reference: std::sync::OnceLock<f64>,
    /// Whether foot points on a mesh target face the sample's side inside thin parts
    /// ([`FitOptions::facing`]).
    facing: bool,
    /// The sample tessellation (from [`DataTerm::prepare`]), for the samples' normals.
    sample_faces: Option<(subfit_mesh::Polygons, usize)>,
}

/// What [`FootPointTerm`] keeps per sample: the foot point and, on projections of all samples
/// with coverage, the data points assigned to the sample. Dereferences to the foot point.
#[derive(Clone, Debug)]
pub struct FootSample {
    /// The foot point of the sample on the target.
    pub foot: FootPoint,
    /// The data points whose nearest sample this is (see [`crate::coverage`]).
    pub cover: Option<Box<CoverSum>>,
    /// The weight of the sample's own quadratic: 1, or `(e_k / r)^(p−2)` with an error power
    /// `p > 2` (see the module docs).
    pub weight: f64,
}

impl std::ops::Deref for FootSample {
    type Target = FootPoint;
    fn deref(&self) -> &FootPoint {
        &self.foot
    }
}

fn plain(feet: Vec<FootPoint>) -> Vec<FootSample> {
    feet.into_iter()
        .map(|foot| FootSample {
            foot,
            cover: None,
            weight: 1.0,
        })
        .collect()
}

impl<'t> FootPointTerm<'t> {
    /// The term `method` with foot points on `target` from `source`.
    pub fn new(target: &'t Target, method: Method, source: FootPointSource) -> Self {
        Self {
            target,
            method,
            source,
            hints: Mutex::new(Vec::new()),
            coverage: None,
            rim: Vec::new(),
            power: 2.0,
            reference: std::sync::OnceLock::new(),
            facing: false,
            sample_faces: None,
        }
    }

    /// The term with foot points that face the sample's side inside thin parts (`true`) or
    /// plain closest points (`false`, the default; see [`Target::mesh_foot_points_facing`]:
    /// mesh targets only, on projections of all samples).
    pub fn with_facing(mut self, facing: bool) -> Self {
        self.facing = facing;
        self
    }

    /// The term with error power `p` (`2 ≤ p ≤ 8`; see the module docs and
    /// [`FitOptions::error_power`]).
    pub fn with_power(mut self, p: f64) -> Self {
        self.power = p;
        self
    }

    /// With an error power `p > 2`: weights every sample `(e_k / r)^(p−2)` by its error `e_k`
    /// at `xs` (the first call over all samples fixes `r`). Cost: O(#samples).
    fn weigh(&self, out: &mut [FootSample], xs: &[[f64; 3]], all: bool) {
        if self.power <= 2.0 || out.is_empty() {
            return;
        }
        let e2: Vec<f64> = out
            .iter()
            .zip(xs)
            .map(|(f, &x)| self.squared_error(f, x))
            .collect();
        let mean = e2.iter().sum::<f64>() / e2.len() as f64;
        let r2 = if all {
            *self.reference.get_or_init(|| mean)
        } else {
            self.reference.get().copied().unwrap_or(mean)
        };
        if !(r2 > 0.0 && r2.is_finite()) {
            return;
        }
        let half = 0.5 * (self.power - 2.0);
        for (f, e) in out.iter_mut().zip(e2) {
            f.weight = (e / r2)
                .powf(half)
                .clamp(POWER_WEIGHT_MIN, POWER_WEIGHT_MAX);
        }
    }

    /// The term `options` name ([`FitOptions::method`], [`FitOptions::foot_points`], and
    /// [`FitOptions::coverage`] > 0 adds the data → surface part, with
    /// [`FitOptions::feature_segments`] fitted by the creases).
    pub fn from_options(target: &'t Target, options: &FitOptions) -> Self {
        let term = Self::new(target, options.method, options.foot_points)
            .with_power(options.error_power)
            .with_facing(options.facing);
        if options.coverage > 0.0 {
            let mut term = term.with_coverage(options.coverage);
            if let Some(f) = &options.feature_segments {
                term.coverage = term.coverage.take().map(|c| c.with_features(f));
            }
            term
        } else {
            term
        }
    }

    /// Adds the data → surface part with weight `weight` (> 0; see [`crate::coverage`]).
    /// Cost: O(#points + #triangles).
    pub fn with_coverage(mut self, weight: f64) -> Self {
        self.coverage = Some(Coverage::new(self.target, weight));
        if let Some(bvh) = self.target.mesh() {
            let b = subfit_target::boundary_vertices(bvh.triangles());
            if !b.is_empty() {
                self.rim = vec![false; self.target.len()];
                for v in b {
                    if let Some(r) = self.rim.get_mut(v as usize) {
                        *r = true;
                    }
                }
            }
        } else {
            // A point cloud: its edge by the angle criterion.
            let rim = self.target.cloud_rim();
            if rim.iter().any(|&b| b) {
                self.rim = rim.to_vec();
            }
        }
        self
    }

    /// Whether the sample at `x` with foot point `f` lies beyond the data's edge: its foot
    /// point is at a boundary vertex or edge of a mesh target (the nearest corner is a boundary
    /// vertex) and the offset `x − V` leans more along the surface than across it.
    #[inline]
    fn beyond_rim(&self, f: &FootPoint, e: [f64; 3]) -> bool {
        if !self.rim.get(f.nearest as usize).copied().unwrap_or(false) {
            return false;
        }
        let along = dot(e, f.normal);
        let all = dot(e, e);
        all > 0.0 && along * along < 0.5 * all
    }

    /// The data → surface part, if any.
    pub fn coverage(&self) -> Option<&Coverage> {
        self.coverage.as_ref()
    }

    /// The target.
    pub fn target(&self) -> &'t Target {
        self.target
    }

    /// The error term.
    pub fn method(&self) -> Method {
        self.method
    }

    /// Fresh foot points of `xs` (normalized coordinates) from the term's source, in parallel;
    /// the warm start is left alone. Same as [`DataTerm::project_fresh`].
    pub fn foot_points(&self, xs: &[[f64; 3]]) -> Vec<FootPoint> {
        match self.source {
            FootPointSource::Auto if self.target.mesh().is_some() => xs
                .par_iter()
                .map(|&x| self.target.mesh_foot_point(x))
                .collect(),
            _ => self.target.foot_points(xs),
        }
    }

    /// [`Self::foot_points`] warm-started: `hints` holds, per point, the nearest data point
    /// (a mesh target's closest triangle) found last time (resized to `xs.len()` with "no
    /// hint"; updated). Same results as [`Self::foot_points`] (the quadric path certifies
    /// every warm-started nearest point or falls back to the kd-tree, see
    /// [`Target::foot_points_hinted`]; the mesh path only bounds its BVH search by the hint,
    /// see [`Target::mesh_foot_points_hinted`]).
    fn foot_points_hinted(&self, xs: &[[f64; 3]], hints: &mut Vec<u32>) -> Vec<FootPoint> {
        match self.source {
            FootPointSource::Auto if self.target.mesh().is_some() => {
                hints.resize(xs.len(), u32::MAX);
                self.target.mesh_foot_points_hinted(xs, hints)
            }
            _ => {
                hints.resize(xs.len(), u32::MAX);
                self.target.foot_points_hinted(xs, hints)
            }
        }
    }
}

impl DataTerm for FootPointTerm<'_> {
    type Sample = FootSample;

    /// PD without coverage and error power: `Q = I` (coverage adds point-to-plane matrices,
    /// a power weights).
    fn isotropic(&self) -> bool {
        self.method == Method::Pdm && self.coverage.is_none() && self.power <= 2.0
    }

    fn prepare(&mut self, op: &subfit_subdiv::SamplingOperator) {
        if let Some(c) = self.coverage.as_mut() {
            c.prepare(op);
        }
        if self.facing {
            self.sample_faces = Some((op.faces.clone(), op.num_vertices));
        }
    }

    fn project(&self, rows: Option<&[u32]>, xs: &[[f64; 3]]) -> Vec<FootSample> {
        // A poisoned lock only loses the hints.
        let mut hints = self.hints.lock().unwrap_or_else(PoisonError::into_inner);
        let Some(rows) = rows else {
            let feet = match &self.sample_faces {
                Some((faces, n))
                    if self.facing
                        && *n == xs.len()
                        && matches!(self.source, FootPointSource::Auto)
                        && self.target.mesh().is_some() =>
                {
                    hints.resize(xs.len(), u32::MAX);
                    let normals = crate::coverage::vertex_normals(faces, xs);
                    self.target
                        .mesh_foot_points_facing(xs, &normals, &mut hints)
                        .0
                }
                _ => self.foot_points_hinted(xs, &mut hints),
            };
            drop(hints);
            let mut out = match &self.coverage {
                None => plain(feet),
                Some(c) => feet
                    .into_iter()
                    .zip(c.assign(xs))
                    .map(|(foot, cover)| FootSample {
                        foot,
                        cover,
                        weight: 1.0,
                    })
                    .collect(),
            };
            self.weigh(&mut out, xs, true);
            return out;
        };
        let need = rows.iter().max().map_or(0, |&k| k as usize + 1);
        if hints.len() < need {
            hints.resize(need, u32::MAX);
        }
        let mut sub: Vec<u32> = rows.iter().map(|&k| hints[k as usize]).collect();
        let feet = self.foot_points_hinted(xs, &mut sub);
        for (&k, &h) in rows.iter().zip(&sub) {
            hints[k as usize] = h;
        }
        let mut out = plain(feet);
        self.weigh(&mut out, xs, false);
        out
    }

    fn project_fresh(&self, xs: &[[f64; 3]]) -> Vec<FootSample> {
        plain(self.foot_points(xs))
    }

    /// `‖x − V‖²`.
    #[inline]
    fn squared_error(&self, f: &FootSample, x: [f64; 3]) -> f64 {
        (0..3).map(|a| (x[a] - f.point[a]).powi(2)).sum::<f64>()
    }

    /// `w ‖x − V‖²` (`w` the sample's weight) plus the assigned data points' share.
    #[inline]
    fn objective_error(&self, f: &FootSample, x: [f64; 3]) -> f64 {
        let own = f.weight * self.squared_error(f, x);
        f.cover.as_ref().map_or(own, |c| own + c.energy(x))
    }

    /// [`error_matrix`] and `Q (x − V)` (PD: `x − V`), times the sample's weight, plus the
    /// assigned data points' model.
    #[inline]
    fn model(&self, f: &FootSample, x: [f64; 3]) -> (Mat3, [f64; 3]) {
        let e = std::array::from_fn(|a| x[a] - f.point[a]);
        // Beyond the data's edge the gap is along the surface: point-to-point pulls the rim
        // back (SD/TD would leave it, their tangential weight being small).
        let (q, r) = if self.method == Method::Pdm || self.beyond_rim(f, e) {
            (IDENTITY, e)
        } else {
            let q = error_matrix(self.method, f);
            let r = mul(&q, e);
            (q, r)
        };
        let (q, r) = if f.weight == 1.0 {
            (q, r)
        } else {
            let w = f.weight;
            (q.map(|row| row.map(|v| w * v)), r.map(|v| w * v))
        };
        match &f.cover {
            None => (q, r),
            Some(c) => {
                let (qc, rc) = c.model(x);
                (add_mat(&q, &qc), std::array::from_fn(|a| r[a] + rc[a]))
            }
        }
    }

    fn measured_errors(&self, xs: &[[f64; 3]], err2: &mut [f64]) {
        self.target.to_local_surface(xs, err2);
    }

    fn bbox_diagonal(&self) -> f64 {
        bbox_diagonal(self.target.points())
    }
}

/// The diagonal of the bounding box of `p` (1 when empty or degenerate).
fn bbox_diagonal(p: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for x in p {
        for a in 0..3 {
            lo[a] = lo[a].min(x[a]);
            hi[a] = hi[a].max(x[a]);
        }
    }
    let d = (0..3).map(|a| (hi[a] - lo[a]).powi(2)).sum::<f64>().sqrt();
    if d.is_finite() && d > 0.0 {
        d
    } else {
        1.0
    }
}

/// `[α]₊` guarded against NaN (treated as 0, i.e. the TD term).
fn sanitize(a: f64) -> f64 {
    if a.is_finite() && a > 0.0 {
        a
    } else {
        0.0
    }
}

/// `s · a bᵀ`.
fn outer(a: [f64; 3], b: [f64; 3], s: f64) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for (r, row) in m.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v = s * a[r] * b[c];
        }
    }
    m
}

/// `q += s · t tᵀ` (skipped when `s == 0`).
fn add_outer(q: &mut Mat3, t: [f64; 3], s: f64) {
    if s == 0.0 {
        return;
    }
    for (r, row) in q.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v += s * t[r] * t[c];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfit_target::TargetOptions;

    /// A point cloud has no triangles: `Auto` takes the quadric foot points.
    #[test]
    fn a_point_cloud_takes_the_quadric_foot_points() {
        let mesh = subfit_mesh::shapes::torus_mesh(0.35, 0.15, 64, 32, true);
        let cloud = subfit_mesh::PolyMesh::point_cloud(mesh.positions.clone(), None);
        let t2 = Target::from_mesh(&cloud, &TargetOptions::default()).unwrap();
        let xs = [t2.to_normalized([0.5, 0.0, 0.0])];
        let term = FootPointTerm::new(&t2, Method::Sdm, FootPointSource::Auto);
        assert_eq!(term.foot_points(&xs)[0].point, t2.foot_points(&xs)[0].point);
    }
}
