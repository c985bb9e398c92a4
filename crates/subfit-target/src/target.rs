//! The [`Target`]: a scan normalized into the unit cube, indexed, with per-point normals and
//! local quadrics (Cheng 2004 §3 steps 1–2 and §4.1; Cheng 2007 §II-C), ready for foot-point
//! queries ([`crate::project`]) and the IMLS distance ([`crate::imls`]).

use std::time::Instant;

use rayon::prelude::*;
use subfit_mesh::PolyMesh;

use crate::angular_gap::{boundary_flags, RIM_GAP, RIM_NEIGHBORS};
use crate::build_steps::{
    estimate, index_and_drop_outliers, merge, mesh_bvh, normalize_positions, orient,
    recognise_tessellation, validate, Report,
};
use crate::closest::TriangleBvh;
use crate::error::TargetError;
use crate::layout::QueryLayout;
use crate::neighbors::PointIndex;
use crate::normalize::Normalization;
use crate::options::{Phase, Progress, ProgressFn, TargetOptions, TargetStats};
use crate::quadric::LocalQuadric;
use crate::tessellation::Facets;
use subfit_mesh::vec3::{cross, dot, normalize, scale, sub};

pub use crate::build_steps::MIN_POINTS;

/// The shape being fitted, in normalized coordinates (unit cube, longest side 1, minimum corner
/// at the origin).
///
/// Holds `#P` distinct points (exact duplicates of the input merged), a unit normal and a local
/// quadric per point, a kd-tree, and for mesh inputs a triangle BVH. Immutable once built;
/// queries take `&self` and are safe to run from many threads.
#[derive(Debug)]
pub struct Target {
    normalization: Normalization,
    points: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
    quadrics: Vec<LocalQuadric>,
    index: PointIndex,
    /// Copies of the per-point data of foot-point queries in Morton order (memory locality),
    /// with the 16-nearest-neighbour graph for warm-started nearest queries.
    layout: QueryLayout,
    bvh: Option<TriangleBvh>,
    input_to_point: Vec<u32>,
    /// Input indices of the points dropped as outliers, ascending.
    removed_inputs: Vec<u32>,
    /// Per point: the larger of the distance to the nearest other point and
    /// `2 FOOT_SHORTCUT ×` the neighbourhood radius (foot points within half of it are
    /// accepted; `FOOT_SHORTCUT` is in module `build_steps`).
    nn_dist: Vec<f64>,
    imls_radius: f64,
    stats: TargetStats,
    /// The facets of a mesh recognised as a CAD tessellation ([`crate::tessellation`]): its
    /// foot points then come from the facets themselves.
    facets: Option<Facets>,
    /// The cloud's boundary points at the default criterion ([`Self::cloud_rim`]), computed on
    /// first use: every fitter, contour and start borrows the one copy (STYLE.md rule 11).
    rim: std::sync::OnceLock<Vec<bool>>,
    /// The connected component of every triangle of [`Self::mesh`] and whether each
    /// component is closed ([`Self::triangle_components`]), computed on first use.
    pub(crate) triangle_components: std::sync::OnceLock<(Vec<u32>, Vec<bool>)>,
    /// The radius of a cloud's local surface ([`Self::data_reach`]), computed on first use.
    pub(crate) reach: std::sync::OnceLock<f64>,
}

/// Per-point outputs for writers (e.g. the `subfit analyze` PLY): all arrays have `#P` rows, in
/// the target's point order, normalized units (curvatures in 1/normalized units: divide by
/// [`Normalization::scale`] for 1/original units).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointAttributes {
    /// Points, `#P by 3`, normalized.
    pub points: Vec<[f64; 3]>,
    /// Unit normals, `#P by 3`.
    pub normals: Vec<[f64; 3]>,
    /// Signed principal curvature of smaller magnitude, `#P` (Cheng 2007 §II-D3 sign).
    pub k1: Vec<f64>,
    /// Signed principal curvature of larger magnitude, `#P`.
    pub k2: Vec<f64>,
    /// Unit principal direction of `k1`, `#P by 3`, ⟂ normal.
    pub t1: Vec<[f64; 3]>,
    /// Unit principal direction of `k2`, `#P by 3`, ⟂ normal and `t1`.
    pub t2: Vec<[f64; 3]>,
}

impl Target {
    /// Builds a target from a point cloud, with optional per-point normals (`#P by 3`, any
    /// length; zero-length rows are estimated). See [`Target::build`].
    pub fn from_points(
        points: &[[f64; 3]],
        normals: Option<&[[f64; 3]]>,
        options: &TargetOptions,
    ) -> Result<Self, TargetError> {
        let mesh = PolyMesh::point_cloud(points.to_vec(), normals.map(<[_]>::to_vec));
        Self::build(&mesh, options, None)
    }

    /// Builds a target from a mesh or point cloud (a `PolyMesh` without faces). See
    /// [`Target::build`].
    pub fn from_mesh(mesh: &PolyMesh, options: &TargetOptions) -> Result<Self, TargetError> {
        Self::build(mesh, options, None)
    }

    /// Builds a target: validate, normalize into the unit cube, merge exact duplicates, build the
    /// kd-tree, drop outliers of point clouds and estimate the noise level
    /// ([`TargetOptions::remove_outliers`], [`TargetOptions::adapt_to_noise`]), fit a PCA frame
    /// and a quadric per point, orient normals, and for meshes build the triangle BVH. Faces (any polygon size, fan-triangulated) are used for area-weighted
    /// normals and exact closest points; colours are ignored.
    ///
    /// Errors: NaN/Inf coordinates or normals (with the input index), fewer than
    /// [`MIN_POINTS`] points or distinct points (this covers duplicate-only input), all points on
    /// one line, face indices out of range, invalid options; [`TargetError::Interrupted`] once
    /// [`TargetOptions::cancel`] is cancelled (polled between phases and inside the long ones). A planar point set is valid: its
    /// normals are the plane's (oriented `+z`, or `+x`/`+y` for a vertical plane) and its
    /// curvatures 0.
    ///
    /// Cost: O(P log P) plus O(P·k) for the outlier scan and the fits, parallel; the
    /// orientation O(P·k_o log P), its field refinement capped at a number of point evaluations
    /// linear in P. Progress goes to `progress`, never to stdout/stderr.
    pub fn build(
        mesh: &PolyMesh,
        options: &TargetOptions,
        progress: Option<ProgressFn<'_>>,
    ) -> Result<Self, TargetError> {
        let t_all = Instant::now();
        let report = |phase: Phase, done: usize, total: usize| {
            if let Some(p) = progress {
                p(Progress { phase, done, total });
            }
        };
        let report: Report<'_> = &report;
        let mut stats = TargetStats::default();

        validate(mesh, options, report, &mut stats)?;
        let (normalization, bounds, normalized) =
            normalize_positions(mesh, options, report, &mut stats)?;
        let (mut points, mut input_to_point) = merge(&normalized, options, report, &mut stats)?;
        let (triangles, facets) = recognise_tessellation(
            mesh,
            options,
            &points,
            &input_to_point,
            &normalization,
            bounds,
            &mut stats,
        );
        let (index, removed_inputs) = index_and_drop_outliers(
            mesh,
            options,
            facets.is_some(),
            &mut points,
            &mut input_to_point,
            report,
            &mut stats,
        )?;
        let est = estimate(
            mesh,
            &points,
            &index,
            &input_to_point,
            options,
            report,
            &mut stats,
        )?;
        let oriented = orient(
            &points,
            &index,
            est,
            triangles.is_empty(),
            options,
            report,
            &mut stats,
        )?;
        let bvh = mesh_bvh(mesh, options, &points, triangles, report, &mut stats)?;

        let imls_radius = options
            .imls_radius
            .unwrap_or(2.0 * stats.neighborhood_radius.1)
            .max(f64::MIN_POSITIVE);
        stats.imls_radius = imls_radius;
        stats.timings.total = t_all.elapsed();
        Ok(Self {
            normalization,
            points,
            normals: oriented.normals,
            quadrics: oriented.quadrics,
            index,
            layout: oriented.layout,
            bvh,
            input_to_point,
            removed_inputs,
            nn_dist: oriented.nn_dist,
            imls_radius,
            stats,
            facets,
            rim: std::sync::OnceLock::new(),
            triangle_components: std::sync::OnceLock::new(),
            reach: std::sync::OnceLock::new(),
        })
    }

    /// The map between original and normalized coordinates.
    pub fn normalization(&self) -> &Normalization {
        &self.normalization
    }

    /// Original → normalized point (shorthand for `normalization().to_normalized`).
    pub fn to_normalized(&self, p: [f64; 3]) -> [f64; 3] {
        self.normalization.to_normalized(p)
    }

    /// Normalized → original point.
    pub fn to_original(&self, p: [f64; 3]) -> [f64; 3] {
        self.normalization.to_original(p)
    }

    /// Number of distinct points `#P`.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Always false for a built target (at least [`MIN_POINTS`] points).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Distinct points, `#P by 3`, normalized.
    pub fn points(&self) -> &[[f64; 3]] {
        &self.points
    }

    /// Unit normals, `#P by 3`, consistently oriented (outward for closed shapes when estimated).
    pub fn normals(&self) -> &[[f64; 3]] {
        &self.normals
    }

    /// The local quadric of each point, `#P`, oriented like [`Self::normals`].
    pub fn quadrics(&self) -> &[LocalQuadric] {
        &self.quadrics
    }

    /// Input indices of the points dropped as outliers (see
    /// [`TargetOptions::remove_outliers`]), ascending; [`Self::input_to_point`] maps them to the
    /// nearest kept point.
    pub fn removed_outliers(&self) -> &[u32] {
        &self.removed_inputs
    }

    /// For each input point, the index of its distinct point (`#input` entries); for a point
    /// dropped as an outlier, the nearest kept point.
    pub fn input_to_point(&self) -> &[u32] {
        &self.input_to_point
    }

    /// Per point: twice the radius within which a foot point computed on this point's quadric is
    /// accepted without a second kd-tree query (normalized units), `#P`: the larger of the
    /// nearest-neighbour spacing and the fitting neighbourhood's radius.
    pub fn foot_shortcut_diameters(&self) -> &[f64] {
        &self.nn_dist
    }

    /// The kd-tree over [`Self::points`].
    pub fn index(&self) -> &PointIndex {
        &self.index
    }

    /// The Morton-ordered query data (points, quadrics, shortcut diameters, descent graph).
    pub(crate) fn layout(&self) -> &QueryLayout {
        &self.layout
    }

    /// The triangle BVH (normalized coordinates, distinct-point indices) for mesh targets.
    pub fn mesh(&self) -> Option<&TriangleBvh> {
        self.bvh.as_ref()
    }

    /// The facets of a mesh recognised as a CAD tessellation (points of [`Self::points`],
    /// triangles of [`Self::mesh`]), `None` otherwise.
    pub fn facets(&self) -> Option<&Facets> {
        self.facets.as_ref()
    }

    /// Construction statistics and timings.
    pub fn stats(&self) -> &TargetStats {
        &self.stats
    }

    /// IMLS kernel support radius `h` (normalized units).
    pub fn imls_radius(&self) -> f64 {
        self.imls_radius
    }

    /// Whether each point is on the boundary of the cloud by the angle criterion at the
    /// defaults ([`crate::cloud_boundary_points`] with [`crate::RIM_NEIGHBORS`] and
    /// [`crate::RIM_GAP`]), `#P` flags. Computed on the first call (one 25-nearest query per
    /// point, in parallel) and kept: later calls cost nothing.
    pub fn cloud_rim(&self) -> &[bool] {
        self.rim.get_or_init(|| {
            boundary_flags(
                self.points(),
                self.normals(),
                self.index(),
                RIM_NEIGHBORS,
                RIM_GAP,
            )
        })
    }

    /// Sets the IMLS kernel support radius `h` (normalized units); ignored unless finite and > 0.
    pub fn set_imls_radius(&mut self, h: f64) {
        if h.is_finite() && h > 0.0 {
            self.imls_radius = h;
            self.stats.imls_radius = h;
        }
    }

    /// Per-point normals, principal curvatures and directions (evaluated on each point's
    /// quadric at the point), for writers. Parallel, O(P).
    pub fn point_attributes(&self) -> PointAttributes {
        let frames: Vec<_> = self
            .quadrics
            .par_iter()
            .zip(&self.normals)
            .map(|(q, &n)| {
                let f = q.frame_at(0.0, 0.0);
                // Input normals may differ slightly from the quadric's: keep t ⟂ n.
                let t1 = normalize(sub(f.t1, scale(n, dot(f.t1, n)))).unwrap_or(f.t1);
                (f.k1, f.k2, t1, cross(n, t1))
            })
            .collect();
        PointAttributes {
            points: self.points.clone(),
            normals: self.normals.clone(),
            k1: frames.iter().map(|f| f.0).collect(),
            k2: frames.iter().map(|f| f.1).collect(),
            t1: frames.iter().map(|f| f.2).collect(),
            t2: frames.iter().map(|f| f.3).collect(),
        }
    }
}
