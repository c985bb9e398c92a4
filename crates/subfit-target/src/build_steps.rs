//! The phases of [`Target::build`](crate::Target::build), in order: validate, normalize into the
//! unit cube, merge exact duplicates, recognise a CAD tessellation, build the kd-tree and drop
//! outliers, estimate a PCA frame and a quadric per point, orient the normals, build the mesh
//! BVH (Cheng 2004 §3 steps 1–2 and §4.1; Cheng 2007 §II-C). Each phase reports its progress,
//! records its figures in the [`TargetStats`] and polls the cancel flag; none names the
//! target itself, which assembles their outputs.

use std::time::Instant;

use rayon::prelude::*;
use subfit_mesh::{Cancel, Cancelled, PolyMesh};

use crate::closest::TriangleBvh;
use crate::error::TargetError;
use crate::estimate::{
    estimate_all, estimate_point, graph_stride, EstimateParams, Neighborhood, PointEstimate,
    Scratch, DESCENT_K,
};
use crate::layout::QueryLayout;
use crate::neighbors::PointIndex;
use crate::normalize::Normalization;
use crate::options::{NormalOrigin, NormalSource, Phase, TargetOptions, TargetStats};
use crate::orient::{orient_normals, KnnGraph, OrientInput, Orientation, FIELD_MAX_NEIGHBORS};
use crate::quadric::{sym3_eigen, FitQuality, LocalQuadric};
use crate::tessellation::Facets;
use subfit_mesh::vec3::{add, cross, normalize, scale, sub};

/// Fraction of the neighbourhood radius doubled into the foot-point shortcut diameter. 0 keeps
/// the shortcut exact (only the nearest-neighbour spacing: results identical to always doing the
/// second query). 1.0 was measured ~15 % faster on Igea with unchanged analytic-test errors, but
/// changes some foot points on real data (bench checksum 32.995 → 34.511); not enabled.
const FOOT_SHORTCUT: f64 = 0.0;

/// Fewest (distinct) points a target may have.
pub const MIN_POINTS: usize = 10;

/// The progress callback of one build: `(phase, done, total)`.
pub(crate) type Report<'a> = &'a (dyn Fn(Phase, usize, usize) + Sync);

/// The input's bounding box `(lo, hi)`, original units.
pub(crate) type Bounds = ([f64; 3], [f64; 3]);

/// What the per-point estimation hands to the orientation.
pub(crate) struct Estimated {
    /// The estimation settings (the neighbourhood possibly widened for noise).
    pub(crate) params: EstimateParams,
    /// Unit normals prescribed by the input, per distinct point (`#P`).
    pub(crate) prescribed: Vec<Option<[f64; 3]>>,
    /// Where the prescribed normals came from.
    pub(crate) origin: NormalOrigin,
    /// The estimate of each point (`#P`).
    pub(crate) estimates: Vec<PointEstimate>,
    /// The neighbour graph, rows of `graph_stride(params)` entries.
    pub(crate) graph: Vec<u32>,
}

/// The oriented per-point data and the query layout built on it.
pub(crate) struct Oriented {
    /// Unit normals, `#P by 3`.
    pub(crate) normals: Vec<[f64; 3]>,
    /// Local quadrics, `#P`, oriented like the normals.
    pub(crate) quadrics: Vec<LocalQuadric>,
    /// Foot-point shortcut diameters, `#P`.
    pub(crate) nn_dist: Vec<f64>,
    /// The Morton-ordered query data.
    pub(crate) layout: QueryLayout,
}

/// Validate: the options and the input (finite coordinates and normals, face indices).
pub(crate) fn validate(
    mesh: &PolyMesh,
    options: &TargetOptions,
    report: Report<'_>,
    stats: &mut TargetStats,
) -> Result<(), TargetError> {
    let n_in = mesh.positions.len();
    let t = Instant::now();
    report(Phase::Validate, 0, n_in);
    validate_options(options)?;
    validate_input(mesh)?;
    stats.input_points = n_in;
    stats.timings.validate = t.elapsed();
    report(Phase::Validate, n_in, n_in);
    Ok(())
}

/// Normalize: the normalization (given or from the bounding box), the bounding box and the
/// normalized positions (`#input by 3`).
pub(crate) fn normalize_positions(
    mesh: &PolyMesh,
    options: &TargetOptions,
    report: Report<'_>,
    stats: &mut TargetStats,
) -> Result<(Normalization, Bounds, Vec<[f64; 3]>), TargetError> {
    let n_in = mesh.positions.len();
    options.cancel.check()?;
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
    Ok((normalization, (lo, hi), normalized))
}

/// Merge exact duplicates of the `normalized` positions: the distinct points and the point of
/// each input position. Errors below [`MIN_POINTS`] distinct points or when they are collinear.
pub(crate) fn merge(
    normalized: &[[f64; 3]],
    options: &TargetOptions,
    report: Report<'_>,
    stats: &mut TargetStats,
) -> Result<(Vec<[f64; 3]>, Vec<u32>), TargetError> {
    let n_in = normalized.len();
    options.cancel.check()?;
    let t = Instant::now();
    report(Phase::Merge, 0, n_in);
    let (points, input_to_point) = merge_duplicates(normalized);
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
    Ok((points, input_to_point))
}

/// A mesh's facets: is it a CAD tessellation ([`crate::tessellation`])? Returns the mesh's
/// fan-triangulated faces over the distinct points (degenerate ones left out) and, when it is
/// one, its facets.
pub(crate) fn recognise_tessellation(
    mesh: &PolyMesh,
    options: &TargetOptions,
    points: &[[f64; 3]],
    input_to_point: &[u32],
    normalization: &Normalization,
    (lo, hi): Bounds,
    stats: &mut TargetStats,
) -> (Vec<[u32; 3]>, Option<Facets>) {
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
            let f = Facets::new(points, &triangles, tol);
            stats.tessellation = Some(f.stats(points));
            f
        })
        .filter(|_| stats.tessellation.is_some_and(|t| t.is_tessellation));
    (triangles, facets)
}

/// The kd-tree, then the outlier scan and noise level (point clouds only: a mesh's vertices
/// are its faces'); drops the outliers from `points` and remaps `input_to_point`. Returns the
/// kd-tree over the kept points and the input indices of the dropped ones, ascending.
/// `tessellation`: the mesh was recognised as a CAD tessellation (its noise level is 0).
pub(crate) fn index_and_drop_outliers(
    mesh: &PolyMesh,
    options: &TargetOptions,
    tessellation: bool,
    points: &mut Vec<[f64; 3]>,
    input_to_point: &mut [u32],
    report: Report<'_>,
    stats: &mut TargetStats,
) -> Result<(PointIndex, Vec<u32>), TargetError> {
    let n_in = mesh.positions.len();
    let cancel = &options.cancel;

    // kd-tree.
    cancel.check()?;
    let t = Instant::now();
    report(Phase::Index, 0, points.len());
    let too_few = |found: usize| TargetError::TooFewPoints {
        found,
        required: MIN_POINTS,
    };
    let mut index = PointIndex::new(points.as_slice()).ok_or(too_few(points.len()))?;
    stats.timings.index = t.elapsed();
    report(Phase::Index, points.len(), points.len());

    // Outliers and noise level (point clouds only: a mesh's vertices are its faces').
    cancel.check()?;
    let t = Instant::now();
    report(Phase::Outliers, 0, points.len());
    let remove = options.remove_outliers && mesh.faces.is_empty();
    let scan = crate::outliers::detect(points.as_slice(), &index, remove, cancel)?;
    let mut removed_inputs = Vec::new();
    // A tessellation's vertex spacing is the exporter's, not noise: its facets are exact.
    stats.noise_level = if tessellation { 0.0 } else { scan.noise };
    stats.point_spacing = scan.spacing;
    if scan.count > 0 && points.len() - scan.count >= MIN_POINTS {
        removed_inputs = (0..n_in as u32)
            .filter(|&i| scan.outlier[input_to_point[i as usize] as usize])
            .collect();
        let (kept, mut map) = drop_outliers(points.as_slice(), &scan.outlier);
        index = PointIndex::new(&kept).ok_or(too_few(kept.len()))?;
        remap_outliers(points.as_slice(), &index, &mut map, input_to_point);
        *points = kept;
        stats.outliers_removed = scan.count;
        stats.points = points.len();
        check_not_collinear(points.as_slice())?;
    }
    stats.timings.outliers = t.elapsed();
    report(Phase::Outliers, points.len(), points.len());
    Ok((index, removed_inputs))
}

/// Prescribed normals (input or faces), then the per-point estimation: a PCA frame and a
/// quadric per point over a neighbourhood widened for noise ([`TargetOptions::adapt_to_noise`]).
pub(crate) fn estimate(
    mesh: &PolyMesh,
    points: &[[f64; 3]],
    index: &PointIndex,
    input_to_point: &[u32],
    options: &TargetOptions,
    report: Report<'_>,
    stats: &mut TargetStats,
) -> Result<Estimated, TargetError> {
    let cancel = &options.cancel;
    // Prescribed normals (input or faces), per distinct point.
    let (prescribed, origin) = prescribed_normals(mesh, options, points, input_to_point);

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
    let (estimates, graph) = estimate_all(points, index, &prescribed, &params, &tick, cancel)?;
    stats.timings.estimate = t.elapsed();
    summarize_estimates(&estimates, stats);
    cancel.check()?;
    Ok(Estimated {
        params,
        prescribed,
        origin,
        estimates,
        graph,
    })
}

/// Orientation: normals from the prescribed ones or the quadrics, the free ones oriented
/// consistently (flipping their quadrics), then the query layout. `no_triangles`: the input
/// has no faces left (a point cloud).
pub(crate) fn orient(
    points: &[[f64; 3]],
    index: &PointIndex,
    est: Estimated,
    no_triangles: bool,
    options: &TargetOptions,
    report: Report<'_>,
    stats: &mut TargetStats,
) -> Result<Oriented, TargetError> {
    let np = points.len();
    let t = Instant::now();
    report(Phase::Orient, 0, np);
    let mut quadrics: Vec<LocalQuadric> = est.estimates.iter().map(|e| e.quadric).collect();
    let nn_dist: Vec<f64> = est
        .estimates
        .iter()
        .map(|e| e.nn_dist.min(f64::MAX).max(FOOT_SHORTCUT * e.radius))
        .collect();
    let mut normals: Vec<[f64; 3]> = quadrics
        .par_iter()
        .zip(&est.prescribed)
        .map(|(q, p)| p.unwrap_or_else(|| q.frame_at(0.0, 0.0).normal))
        .collect();
    let stride = graph_stride(&est.params);
    let (fixed, n_fixed) = fixed_normals(&normals, &est, stride, no_triangles, stats);
    if n_fixed < np {
        let o = orient_free(
            points,
            index,
            &est,
            &fixed,
            &mut normals,
            &mut quadrics,
            options,
        )?;
        record_orientation(&o, stats);
    }
    options.cancel.check()?;
    let radius: Vec<f64> = est.estimates.iter().map(|e| e.radius).collect();
    let mut layout = QueryLayout::new(
        points,
        &quadrics,
        &nn_dist,
        &radius,
        &prefix_rows(&est.graph, stride, DESCENT_K),
    );
    layout.untrusted = crate::blend::mark_untrusted(&layout);
    stats.untrusted_quadrics = layout.untrusted.iter().filter(|&&u| u).count();
    drop(est);
    stats.timings.orient = t.elapsed();
    report(Phase::Orient, np, np);
    Ok(Oriented {
        normals,
        quadrics,
        nn_dist,
        layout,
    })
}

/// Which normals are fixed (prescribed, and kept), how many, and where the normals come from
/// (recorded in `stats`).
fn fixed_normals(
    normals: &[[f64; 3]],
    est: &Estimated,
    stride: usize,
    no_triangles: bool,
    stats: &mut TargetStats,
) -> (Vec<bool>, usize) {
    let np = normals.len();
    let origin = est.origin;
    let mut fixed: Vec<bool> = est.prescribed.iter().map(Option::is_some).collect();
    let mut n_fixed = fixed.iter().filter(|&&f| f).count();
    stats.normal_origin = match (origin, n_fixed) {
        (_, 0) => NormalOrigin::Estimated,
        (o, f) if f == np => o,
        _ => NormalOrigin::Mixed,
    };
    if origin == NormalOrigin::Input && n_fixed > 0 && no_triangles {
        // A cloud's input normals with inconsistent signs are oriented like estimated
        // ones. A mesh's are left alone: its faces orient it, and on a coarse mesh the
        // neighbours across a thin part (a leg, an ear of a 398-vertex cat) rightly face
        // away from each other (20 % of pairs).
        let opposed = crate::consistency::opposed_fraction(normals, &fixed, &est.graph, stride);
        stats.opposed_input_normals = opposed;
        if opposed > crate::consistency::MAX_OPPOSED_FRACTION {
            stats.reoriented_input_normals = true;
            fixed.fill(false);
            n_fixed = 0;
        }
    }
    (fixed, n_fixed)
}

/// Orients the normals that are not `fixed` ([`orient_normals`]), flips their quadrics with
/// them and refits the quadrics of redirected points.
fn orient_free(
    points: &[[f64; 3]],
    index: &PointIndex,
    est: &Estimated,
    fixed: &[bool],
    normals: &mut [[f64; 3]],
    quadrics: &mut [LocalQuadric],
    options: &TargetOptions,
) -> Result<Orientation, TargetError> {
    let cancel = &options.cancel;
    let stride = graph_stride(&est.params);
    let k = options.orientation_k;
    let orient_graph = prefix_rows(&est.graph, stride, k);
    let ambiguous: Vec<bool> = est.estimates.iter().map(|e| e.ambiguous).collect();
    let area: Vec<f64> = est.estimates.iter().map(|e| e.radius * e.radius).collect();
    let trusted: Vec<bool> = est
        .estimates
        .iter()
        .map(|e| e.size as usize > FIELD_MAX_NEIGHBORS)
        .collect();
    let o = orient_normals(
        points,
        normals,
        KnnGraph {
            targets: &orient_graph,
            stride: k,
        },
        &OrientInput {
            ambiguous: &ambiguous,
            fixed,
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
            points,
            index,
            normals,
            &o.redirected,
            &est.params,
            quadrics,
            cancel,
        )?;
    }
    Ok(o)
}

/// Copies the figures of an orientation into `stats`.
fn record_orientation(o: &Orientation, stats: &mut TargetStats) {
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

/// Mesh BVH (mesh inputs with [`TargetOptions::mesh_closest_point`]): built once, queried every
/// iteration.
pub(crate) fn mesh_bvh(
    mesh: &PolyMesh,
    options: &TargetOptions,
    points: &[[f64; 3]],
    triangles: Vec<[u32; 3]>,
    report: Report<'_>,
    stats: &mut TargetStats,
) -> Result<Option<TriangleBvh>, TargetError> {
    options.cancel.check()?;
    let t = Instant::now();
    let bvh = if options.mesh_closest_point && !mesh.faces.is_empty() {
        report(Phase::MeshIndex, 0, 1);
        stats.triangles = triangles.len();
        report(Phase::MeshIndex, 1, 1);
        // Built once, queried every iteration: SAH splits (CAD slivers).
        Some(TriangleBvh::with_sah(points.to_vec(), triangles))
    } else {
        None
    };
    stats.timings.mesh_index = t.elapsed();
    Ok(bvh)
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
