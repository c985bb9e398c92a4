//! The [`Target`]: a scan normalized into the unit cube, indexed, with per-point normals and
//! local quadrics (Cheng 2004 §3 steps 1–2 and §4.1; Cheng 2007 §II-C), ready for foot-point
//! queries ([`crate::project`]) and the IMLS distance ([`crate::imls`]).

use std::time::Instant;

use rayon::prelude::*;
use subfit_mesh::{Cancel, Cancelled, PolyMesh};

use crate::angular_gap::{boundary_flags, RIM_GAP, RIM_NEIGHBORS};
use crate::closest::TriangleBvh;
use crate::error::TargetError;
use crate::estimate::{
    estimate_all, estimate_point, graph_stride, EstimateParams, Neighborhood, PointEstimate,
    Scratch, DESCENT_K,
};
use crate::layout::QueryLayout;
use crate::neighbors::PointIndex;
use crate::normalize::Normalization;
use crate::options::{
    NormalOrigin, NormalSource, Phase, Progress, ProgressFn, TargetOptions, TargetStats,
};
use crate::orient::{orient_normals, KnnGraph, OrientInput, FIELD_MAX_NEIGHBORS};
use crate::quadric::{sym3_eigen, FitQuality, LocalQuadric};
use crate::tessellation::Facets;
use subfit_mesh::vec3::{add, cross, dot, normalize, scale, sub};

/// Fraction of the neighbourhood radius doubled into the foot-point shortcut diameter. 0 keeps
/// the shortcut exact (only the nearest-neighbour spacing: results identical to always doing the
/// second query). 1.0 was measured ~15 % faster on Igea with unchanged analytic-test errors, but
/// changes some foot points on real data (bench checksum 32.995 → 34.511); not enabled.
const FOOT_SHORTCUT: f64 = 0.0;

/// Fewest (distinct) points a target may have.
pub const MIN_POINTS: usize = 10;

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
    /// `2 FOOT_SHORTCUT ×` the neighbourhood radius (foot points within half of it are accepted).
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
        let mut stats = TargetStats::default();
        let n_in = mesh.positions.len();

        // Validate.
        let t = Instant::now();
        report(Phase::Validate, 0, n_in);
        validate_options(options)?;
        validate_input(mesh)?;
        stats.input_points = n_in;
        stats.timings.validate = t.elapsed();
        report(Phase::Validate, n_in, n_in);

        // Normalize.
        let cancel = &options.cancel;
        cancel.check()?;
        let t = Instant::now();
        report(Phase::Normalize, 0, n_in);
        let (lo, hi) = mesh.bounding_box().unwrap_or(([0.0; 3], [0.0; 3]));
        let Some(normalization) = options
            .normalization
            .or_else(|| Normalization::from_bounds(lo, hi))
        else {
            return Err(TargetError::TooFewDistinctPoints {
                distinct: 1,
                input: n_in,
                merged: n_in - 1,
                required: MIN_POINTS,
            });
        };
        let normalized: Vec<[f64; 3]> = mesh
            .positions
            .par_iter()
            .map(|&p| normalization.to_normalized(p))
            .collect();
        stats.timings.normalize = t.elapsed();
        report(Phase::Normalize, n_in, n_in);

        // Merge exact duplicates.
        cancel.check()?;
        let t = Instant::now();
        report(Phase::Merge, 0, n_in);
        let (mut points, mut input_to_point) = merge_duplicates(&normalized);
        stats.points = points.len();
        stats.merged_duplicates = n_in - points.len();
        if points.len() < MIN_POINTS {
            return Err(TargetError::TooFewDistinctPoints {
                distinct: points.len(),
                input: n_in,
                merged: stats.merged_duplicates,
                required: MIN_POINTS,
            });
        }
        check_not_collinear(&points)?;
        stats.timings.merge = t.elapsed();
        report(Phase::Merge, n_in, n_in);

        // A mesh's facets: is it a CAD tessellation?
        let triangles: Vec<[u32; 3]> = mesh
            .faces
            .triangulate_fan()
            .into_iter()
            .map(|t| t.map(|v| input_to_point[v as usize]))
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
            .collect();
        let facets = (options.recognise_tessellation && !triangles.is_empty())
            .then(|| {
                let magnitude = lo.iter().chain(&hi).fold(0.0f64, |m, c| m.max(c.abs()));
                let tol = Facets::float32_tolerance(magnitude, 1.0 / normalization.scale);
                let f = Facets::new(&points, &triangles, tol);
                stats.tessellation = Some(f.stats(&points));
                f
            })
            .filter(|_| stats.tessellation.is_some_and(|t| t.is_tessellation));

        // kd-tree.
        cancel.check()?;
        let t = Instant::now();
        report(Phase::Index, 0, points.len());
        let too_few = |found: usize| TargetError::TooFewPoints {
            found,
            required: MIN_POINTS,
        };
        let mut index = PointIndex::new(&points).ok_or(too_few(points.len()))?;
        stats.timings.index = t.elapsed();
        report(Phase::Index, points.len(), points.len());

        // Outliers and noise level (point clouds only: a mesh's vertices are its faces').
        cancel.check()?;
        let t = Instant::now();
        report(Phase::Outliers, 0, points.len());
        let remove = options.remove_outliers && mesh.faces.is_empty();
        let scan = crate::outliers::detect(&points, &index, remove, cancel)?;
        let mut removed_inputs = Vec::new();
        // A tessellation's vertex spacing is the exporter's, not noise: its facets are exact.
        stats.noise_level = if facets.is_some() { 0.0 } else { scan.noise };
        stats.point_spacing = scan.spacing;
        if scan.count > 0 && points.len() - scan.count >= MIN_POINTS {
            removed_inputs = (0..n_in as u32)
                .filter(|&i| scan.outlier[input_to_point[i as usize] as usize])
                .collect();
            let (kept, mut map) = drop_outliers(&points, &scan.outlier);
            index = PointIndex::new(&kept).ok_or(too_few(kept.len()))?;
            remap_outliers(&points, &index, &mut map, &mut input_to_point);
            points = kept;
            stats.outliers_removed = scan.count;
            stats.points = points.len();
            check_not_collinear(&points)?;
        }
        stats.timings.outliers = t.elapsed();
        report(Phase::Outliers, points.len(), points.len());

        // Prescribed normals (input or faces), per distinct point.
        let (prescribed, origin) = prescribed_normals(mesh, options, &points, &input_to_point);

        // Per-point estimation.
        let t = Instant::now();
        let np = points.len();
        report(Phase::Estimate, 0, np);
        let tick = |done: usize| report(Phase::Estimate, done, np);
        let hood = match options.neighborhood {
            Neighborhood::Knn(k) if options.adapt_to_noise => Neighborhood::Knn(
                crate::outliers::noisy_knn(stats.noise_level, stats.point_spacing, k),
            ),
            h => h,
        };
        let widened = match (hood, options.neighborhood) {
            (Neighborhood::Knn(k), Neighborhood::Knn(k0)) => {
                stats.neighborhood_k = k;
                k > k0
            }
            _ => false,
        };
        let params = EstimateParams {
            hood,
            ambiguity_ratio: options.ambiguity_ratio,
            graph_k: options.orientation_k,
            degree: options.jet_degree,
            small_fallback: !widened,
        };
        cancel.check()?;
        let (estimates, graph) =
            estimate_all(&points, &index, &prescribed, &params, &tick, cancel)?;
        stats.timings.estimate = t.elapsed();
        summarize_estimates(&estimates, &mut stats);
        cancel.check()?;

        // Orientation.
        let t = Instant::now();
        report(Phase::Orient, 0, np);
        let mut quadrics: Vec<LocalQuadric> = estimates.iter().map(|e| e.quadric).collect();
        let nn_dist: Vec<f64> = estimates
            .iter()
            .map(|e| e.nn_dist.min(f64::MAX).max(FOOT_SHORTCUT * e.radius))
            .collect();
        let mut normals: Vec<[f64; 3]> = quadrics
            .par_iter()
            .zip(&prescribed)
            .map(|(q, p)| p.unwrap_or_else(|| q.frame_at(0.0, 0.0).normal))
            .collect();
        let mut fixed: Vec<bool> = prescribed.iter().map(Option::is_some).collect();
        let mut n_fixed = fixed.iter().filter(|&&f| f).count();
        stats.normal_origin = match (origin, n_fixed) {
            (_, 0) => NormalOrigin::Estimated,
            (o, f) if f == np => o,
            _ => NormalOrigin::Mixed,
        };
        let stride = graph_stride(&params);
        if origin == NormalOrigin::Input && n_fixed > 0 && triangles.is_empty() {
            // A cloud's input normals with inconsistent signs are oriented like estimated
            // ones. A mesh's are left alone: its faces orient it, and on a coarse mesh the
            // neighbours across a thin part (a leg, an ear of a 398-vertex cat) rightly face
            // away from each other (20 % of pairs).
            let opposed = crate::consistency::opposed_fraction(&normals, &fixed, &graph, stride);
            stats.opposed_input_normals = opposed;
            if opposed > crate::consistency::MAX_OPPOSED_FRACTION {
                stats.reoriented_input_normals = true;
                fixed.fill(false);
                n_fixed = 0;
            }
        }
        if n_fixed < np {
            let k = options.orientation_k;
            let orient_graph = prefix_rows(&graph, stride, k);
            let ambiguous: Vec<bool> = estimates.iter().map(|e| e.ambiguous).collect();
            let area: Vec<f64> = estimates.iter().map(|e| e.radius * e.radius).collect();
            let trusted: Vec<bool> = estimates
                .iter()
                .map(|e| e.size as usize > FIELD_MAX_NEIGHBORS)
                .collect();
            let o = orient_normals(
                &points,
                &mut normals,
                KnnGraph {
                    targets: &orient_graph,
                    stride: k,
                },
                &OrientInput {
                    ambiguous: &ambiguous,
                    fixed: &fixed,
                    area: &area,
                    tangent_penalty: options.orientation_tangent_penalty,
                    trusted: &trusted,
                    cancel,
                },
            )?;
            for (q, &f) in quadrics.iter_mut().zip(&o.flipped) {
                if f {
                    *q = q.flipped();
                }
            }
            if !o.redirected.is_empty() {
                refit_redirected(
                    &points,
                    &index,
                    &normals,
                    &o.redirected,
                    &params,
                    &mut quadrics,
                    cancel,
                )?;
            }
            stats.flipped_normals = o.flipped.iter().filter(|&&f| f).count();
            stats.orientation_components = o.components;
            stats.winding_flips = o.winding_flips;
            stats.field_suspicious = o.field_suspicious;
            stats.field_iterations = o.field_iterations;
            stats.field_flips = o.field_flips;
            stats.field_redirected = o.redirected.iter().filter(|&&r| r).count();
            stats.timings.orient_propagate = o.propagate_time;
            stats.timings.orient_winding = o.winding_time;
            stats.timings.orient_field = o.field_time;
        }
        cancel.check()?;
        let radius: Vec<f64> = estimates.iter().map(|e| e.radius).collect();
        let mut layout = QueryLayout::new(
            &points,
            &quadrics,
            &nn_dist,
            &radius,
            &prefix_rows(&graph, stride, DESCENT_K),
        );
        layout.untrusted = crate::blend::mark_untrusted(&layout);
        stats.untrusted_quadrics = layout.untrusted.iter().filter(|&&u| u).count();
        drop(graph);
        stats.timings.orient = t.elapsed();
        report(Phase::Orient, np, np);

        // Mesh BVH.
        cancel.check()?;
        let t = Instant::now();
        let bvh = if options.mesh_closest_point && !mesh.faces.is_empty() {
            report(Phase::MeshIndex, 0, 1);
            stats.triangles = triangles.len();
            report(Phase::MeshIndex, 1, 1);
            // Built once, queried every iteration: SAH splits (CAD slivers).
            Some(TriangleBvh::with_sah(points.clone(), triangles))
        } else {
            None
        };
        stats.timings.mesh_index = t.elapsed();

        let imls_radius = options
            .imls_radius
            .unwrap_or(2.0 * stats.neighborhood_radius.1)
            .max(f64::MIN_POSITIVE);
        stats.imls_radius = imls_radius;
        stats.timings.total = t_all.elapsed();
        Ok(Self {
            normalization,
            points,
            normals,
            quadrics,
            index,
            layout,
            bvh,
            input_to_point,
            removed_inputs,
            nn_dist,
            imls_radius,
            stats,
            facets,
            rim: std::sync::OnceLock::new(),
            triangle_components: std::sync::OnceLock::new(),
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

/// Refits the quadric of every redirected point in the frame of its new normal (`normals`,
/// `redirected`: `#P`). Parallel, O(R·k) for `R` redirected points; `cancel` polled per point.
fn refit_redirected(
    points: &[[f64; 3]],
    index: &PointIndex,
    normals: &[[f64; 3]],
    redirected: &[bool],
    params: &EstimateParams,
    quadrics: &mut [LocalQuadric],
    cancel: &Cancel,
) -> Result<(), Cancelled> {
    let stride = graph_stride(params);
    quadrics
        .par_iter_mut()
        .enumerate()
        .filter(|(i, _)| redirected[*i])
        .for_each_init(
            || (Scratch::default(), vec![u32::MAX; stride]),
            |(scratch, row), (i, q)| {
                if cancel.is_cancelled() {
                    return;
                }
                let e = estimate_point(points, index, i, Some(normals[i]), params, row, scratch);
                *q = e.quadric;
            },
        );
    cancel.check()
}

/// Removes the points marked `outlier` (`#P`). Returns the kept points (in order) and the map
/// old point → new point (`u32::MAX` for a removed one). O(P).
fn drop_outliers(points: &[[f64; 3]], outlier: &[bool]) -> (Vec<[f64; 3]>, Vec<u32>) {
    let mut map = vec![u32::MAX; points.len()];
    let mut kept = Vec::with_capacity(points.len());
    for (i, (p, &o)) in points.iter().zip(outlier).enumerate() {
        if !o {
            map[i] = kept.len() as u32;
            kept.push(*p);
        }
    }
    (kept, map)
}

/// Rewrites `input_to_point` through `map` (from [`drop_outliers`]), pointing each input point
/// whose point was removed at the kept point nearest to it (`index` over the kept points,
/// `old_points` the points before removal). Parallel, O(#input + #removed · log P).
fn remap_outliers(
    old_points: &[[f64; 3]],
    index: &PointIndex,
    map: &mut [u32],
    input_to_point: &mut [u32],
) {
    map.par_iter_mut().enumerate().for_each(|(i, m)| {
        if *m == u32::MAX {
            *m = index.nearest(&old_points[i]).index;
        }
    });
    input_to_point
        .par_iter_mut()
        .for_each(|j| *j = map[*j as usize]);
}

/// The first `k` entries of each row of a graph with rows of `stride` entries (`k ≤ stride`);
/// the graph itself when `k == stride`.
fn prefix_rows(graph: &[u32], stride: usize, k: usize) -> Vec<u32> {
    if k == stride {
        return graph.to_vec();
    }
    graph
        .par_chunks(stride)
        .flat_map_iter(|row| row[..k].iter().copied())
        .collect()
}

fn validate_options(o: &TargetOptions) -> Result<(), TargetError> {
    let bad = |name, reason: &str| {
        Err(TargetError::InvalidOption {
            name,
            reason: reason.to_string(),
        })
    };
    match o.neighborhood {
        Neighborhood::Knn(k) if k < crate::estimate::MIN_NEIGHBORS => {
            return bad("neighborhood", "Knn(k) needs k >= 10")
        }
        Neighborhood::Radius(r) if !(r.is_finite() && r > 0.0) => {
            return bad("neighborhood", "Radius(r) needs a finite r > 0")
        }
        _ => {}
    }
    if !(2..=3).contains(&o.jet_degree) {
        return bad("jet_degree", "must be 2 or 3");
    }
    if o.orientation_k == 0 {
        return bad("orientation_k", "must be at least 1");
    }
    if !(o.orientation_tangent_penalty.is_finite() && o.orientation_tangent_penalty >= 0.0) {
        return bad("orientation_tangent_penalty", "must be finite and >= 0");
    }
    if !(o.ambiguity_ratio > 0.0 && o.ambiguity_ratio <= 1.0) {
        return bad("ambiguity_ratio", "must be in (0, 1]");
    }
    if let Some(h) = o.imls_radius {
        if !(h.is_finite() && h > 0.0) {
            return bad("imls_radius", "must be finite and > 0");
        }
    }
    if let Some(n) = o.normalization {
        if !(n.scale.is_finite() && n.scale > 0.0 && n.min.iter().all(|c| c.is_finite())) {
            return bad(
                "normalization",
                "needs a finite scale > 0 and a finite corner",
            );
        }
    }
    Ok(())
}

fn validate_input(mesh: &PolyMesh) -> Result<(), TargetError> {
    let n = mesh.positions.len();
    if n < MIN_POINTS {
        return Err(TargetError::TooFewPoints {
            found: n,
            required: MIN_POINTS,
        });
    }
    if let Some(i) = mesh
        .positions
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(TargetError::NonFinitePoint {
            index: i,
            coordinates: mesh.positions[i],
        });
    }
    if let Some(normals) = &mesh.normals {
        if normals.len() != n {
            return Err(TargetError::NormalCountMismatch {
                points: n,
                normals: normals.len(),
            });
        }
        if let Some(i) = normals
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(TargetError::NonFiniteNormal {
                index: i,
                components: normals[i],
            });
        }
    }
    for (f, face) in mesh.faces.iter().enumerate() {
        if let Some(&v) = face.iter().find(|&&v| v as usize >= n) {
            return Err(TargetError::FaceIndexOutOfRange {
                face: f,
                vertex: v,
                vertices: n,
            });
        }
    }
    Ok(())
}

/// Merges bitwise-identical points. Returns the distinct points (in order of first occurrence)
/// and the map input index → distinct index. O(n log n).
fn merge_duplicates(points: &[[f64; 3]]) -> (Vec<[f64; 3]>, Vec<u32>) {
    let n = points.len();
    let key = |p: &[f64; 3]| p.map(|c| (c + 0.0).to_bits()); // +0.0 folds -0.0 into 0.0
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.par_sort_unstable_by_key(|&i| (key(&points[i as usize]), i));
    let mut rep = vec![0u32; n];
    let mut g = 0;
    while g < n {
        let first = order[g];
        let k = key(&points[first as usize]);
        let mut e = g;
        while e < n && key(&points[order[e] as usize]) == k {
            rep[order[e] as usize] = first; // sorted by index within the group: first is min
            e += 1;
        }
        g = e;
    }
    let mut map = vec![0u32; n];
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        if rep[i] as usize == i {
            map[i] = out.len() as u32;
            out.push(points[i]);
        } else {
            map[i] = map[rep[i] as usize];
        }
    }
    (out, map)
}

fn check_not_collinear(points: &[[f64; 3]]) -> Result<(), TargetError> {
    let inv = 1.0 / points.len() as f64;
    let mut c = [0.0; 3];
    for p in points {
        c = add(c, scale(*p, inv));
    }
    let mut cv = [[0.0; 3]; 3];
    for p in points {
        let d = sub(*p, c);
        for a in 0..3 {
            for b in 0..3 {
                cv[a][b] += d[a] * d[b] * inv;
            }
        }
    }
    let (lam, _) = sym3_eigen(cv);
    let spread = (lam[1].max(0.0) / lam[2].max(f64::MIN_POSITIVE)).sqrt();
    if !(spread > 1e-8) {
        return Err(TargetError::Collinear {
            points: points.len(),
            spread,
        });
    }
    Ok(())
}

/// Unit normals prescribed by the input (per distinct point), and where they came from.
fn prescribed_normals(
    mesh: &PolyMesh,
    options: &TargetOptions,
    points: &[[f64; 3]],
    input_to_point: &[u32],
) -> (Vec<Option<[f64; 3]>>, NormalOrigin) {
    let np = points.len();
    if options.normals == NormalSource::Estimate {
        return (vec![None; np], NormalOrigin::Estimated);
    }
    let mut acc = vec![[0.0; 3]; np];
    let origin = if let Some(normals) = &mesh.normals {
        for (i, n) in normals.iter().enumerate() {
            let j = input_to_point[i] as usize;
            // Duplicates: sum of unit normals.
            if let Some(u) = normalize(*n) {
                acc[j] = add(acc[j], u);
            }
        }
        NormalOrigin::Input
    } else if !mesh.faces.is_empty() {
        for t in mesh.faces.triangulate_fan() {
            let [a, b, c] = t.map(|v| input_to_point[v as usize] as usize);
            // Twice the area times the unit normal: area weighting.
            let w = cross(sub(points[b], points[a]), sub(points[c], points[a]));
            for v in [a, b, c] {
                acc[v] = add(acc[v], w);
            }
        }
        NormalOrigin::Faces
    } else {
        return (vec![None; np], NormalOrigin::Estimated);
    };
    (acc.into_iter().map(normalize).collect(), origin)
}

fn summarize_estimates(est: &[PointEstimate], stats: &mut TargetStats) {
    let n = est.len();
    stats.ambiguous_normals = est.iter().filter(|e| e.ambiguous).count();
    stats.degenerate_fits = est.iter().filter(|e| e.quality != FitQuality::Full).count();
    let (mut lo, mut hi, mut sum) = (usize::MAX, 0usize, 0usize);
    for e in est {
        lo = lo.min(e.size as usize);
        hi = hi.max(e.size as usize);
        sum += e.size as usize;
    }
    stats.neighborhood_size = (lo, sum as f64 / n.max(1) as f64, hi);
    let mut r: Vec<f64> = est.iter().map(|e| e.radius).collect();
    let mid = n / 2;
    if n > 0 {
        let (_, m, _) = r.select_nth_unstable_by(mid, f64::total_cmp);
        let m = *m;
        let lo = r.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = r.iter().copied().fold(0.0, f64::max);
        stats.neighborhood_radius = (lo, m, hi);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merge_keeps_first_occurrence_order() {
        let p = vec![
            [1.0, 0.0, 0.0],
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [-0.0, 0.0, 0.0],
            [2.0; 3],
        ];
        let (q, map) = merge_duplicates(&p);
        assert_eq!(q, vec![[1.0, 0.0, 0.0], [0.0; 3], [2.0; 3]]);
        assert_eq!(map, vec![0, 1, 0, 1, 2]);
    }
}
