//! Opening the contour of an open point cloud: the faces of the IMLS contour that no data
//! supports are cut away, leaving a manifold surface with boundary.
//!
//! The contour of an implicit function is always closed ([`crate::contour()`]). For a cloud that
//! samples an open surface — a single-view range scan, a patch — the octree band leaks around
//! the scan's rim (see the contour module's "sign far from the data"), and the zero set becomes
//! a thin closed shell: a front sheet on the data, a back sheet along the inner side of the band,
//! about `band_cells` band cells (≥ 1.6 `h`, `h` the IMLS radius) behind it, and a rim joining
//! them. Cheng et al. 2004 §4.3 and Cheng et al. 2007 §II-C assume a closed target; Lavoué et al.
//! 2007 §4 build open control meshes from the boundary curves of an open target, which is what
//! this step recovers for point clouds: the initial mesh must have the target's topology
//! (DESIGN.md §3.6), boundary loops included.
//!
//! **The rule.** A contour vertex is *supported* when the data point nearest to it lies within
//! `τ = min(support_spacings · s, support_band_fraction · w)`, and a face when its three vertices
//! are; `s` is that data point's
//! local spacing (its distance to its [`SPACING_NEIGHBOURS`]-th nearest neighbour, the quantity
//! whose median is [`subfit_target::TargetStats::point_spacing`]) and `w` the width of the
//! contour's band (`band_cells` cells of the band level). Why this rule:
//! * *Local spacing, not a global one*: range scans are denser facing the scanner than at
//!   grazing angles; a global threshold either punches holes in sparse regions or keeps the
//!   back sheet behind dense ones. On a sampled surface the nearest data point of any point of
//!   the contour is within about the distance between neighbouring samples (a quarter of `s`)
//!   plus the IMLS smoothing of curved parts (a fraction of `h ≈ 2.5 s`): the default
//!   `1.5 s` leaves a wide margin.
//! * *A tighter edge*: the cut overhangs the data's edge by up to `τ`, and the fit keeps that
//!   overhang; on a single-view range scan the true surface turns away behind the last
//!   returns, so the overhang lies off it. Where a region is removed (a boundary, once the
//!   small holes are kept), the faces next to it with a vertex farther than
//!   [`TrimOptions::edge_spacings`] (`0.75 s`) from data go too, spreading outward from the
//!   cut, except faces at a vertex that is the nearest contour vertex of some data point (a
//!   sparse strip of grazing returns would go otherwise). What is a hole and what stays closed
//!   is still decided at `1.5 s` (tightening the support rule itself turned sampling gaps into
//!   holes). On the hemisphere of the tests the rim's mean distance to the data falls from 0.79
//!   to 0.63 spacings (its largest stays). On six 400 × 400 range scans of `bunny.off`
//!   (`hard_cases range-scan`, seeds 1–6) the fits' surface → true mesh RMS went from
//!   5.9–10.4e-4 of the diagonal to 6.0–8.3e-4, the largest distance of a return to the surface
//!   from 0.47–0.88 % to 0.42–0.67 %; on five of the armadillo from 1.59, 1.16, 1.26, 1.37,
//!   1.39e-3 to 1.45, 1.05, 0.86, 1.04, 2.13e-3 (the last, a side view, worse); `bun000`
//!   526 → 598 control points, two-sided RMS 7.5e-4 → 7.0e-4 of the diagonal.
//! * *The band cap*: the back sheet is at least about one band width `w` from every data point,
//!   so `τ ≤ w / 2` separates it from the front sheet even where the local spacing is large
//!   (sparse regions, the rim), while the front sheet is always well within it.
//! * *All vertices*, not the centroid: the boundary of the result is made of supported
//!   vertices, so it follows the scan's rim to within `τ` (the cage overhangs the data by at
//!   most `τ`). Testing centroids let boundary vertices stand up to `τ` plus an edge off the
//!   data (3.5 spacings on the simulated torus scan, 2 with the vertex test). It is also one
//!   query per vertex instead of one per face.
//!
//! **Cleaning**, so that noise does not punch holes and the result is a manifold surface with
//! boundary:
//! 1. Regions of unsupported faces (edge-connected) that are small — fewer than
//!    [`TrimOptions::min_hole_faces`] faces, or all their vertices within a ball of diameter
//!    [`TrimOptions::max_hole_diameter`] band widths — are kept: a gap that small is a sampling
//!    gap, not a boundary, and a closed cloud stays closed.
//! 2. Ears (kept faces with two or three edges on removed faces) are removed, repeatedly: they
//!    are slivers hanging off the cut.
//! 3. Bow-ties: at a vertex whose kept faces form several fans, only the largest fan is kept.
//!    Steps 2 and 3 repeat until nothing changes (each pass only removes faces).
//! 4. Components that carry less than [`TrimOptions::min_component_data`] of the data (each data
//!    point counted for the component of its nearest kept vertex) are dropped: islands
//!    supported by a few stray points. The share of the data, not the face count, decides,
//!    because a single-view scan can hold real disconnected pieces (the bunny scan `bun000`
//!    has a strip of about 1 % of its points whose surface is about 1 % of the main one's:
//!    dropping it left data 0.15 unit cube from the cage). A component that alone covers data —
//!    at least [`crate::islands::MIN_ISLAND_POINTS`] points farther than a band width from every
//!    other kept component — stays whatever its share ([`crate::islands`]).
//! 5. The boundary loops are smoothed ([`TrimOptions::boundary_smoothing`] passes of moving each
//!    boundary vertex halfway to the midpoint of its loop neighbours, unless a face would turn
//!    by more than 60°): the cut follows the marching tetrahedra's faces and zig-zags by about a
//!    cell, and the simplification, which keeps boundaries in shape, then spends its vertices on
//!    the zig-zag (on `bun000` at 301 control points: 221 boundary vertices unsmoothed, 132
//!    after 10 passes, 116 after 60).
//!
//! **Genus.** A part of a surface has at most its genus, so trimming never adds a handle; it
//! does not cut the handles the contour already has either. The IMLS contour of a cloud with
//! holes can bridge them with spurious handles (measured with the vertices alone: the bunny
//! `stanford-bunny.obj`, genus 3 where the data has 0; `beetle.off`, genus 2, though all 11 of
//! its boundary loops are found). When [`crate::InitOptions::expected_genus`] is set and missed,
//! [`crate::initial_control_mesh`] falls back to the closed carved wrap.
//!
//! When nothing is removed the contour is returned unchanged (a closed cloud stays exactly as
//! before). Cost: one nearest query per contour vertex and one `k`-nearest query per distinct
//! nearest data point (parallel, in `subfit-target`), `O(#F)` per cleaning pass, and one nearest
//! query per data point when the result has several components.

use subfit_mesh::{face_components, FaceId, HalfEdgeMesh, PolyMesh, Polygons, VertexId};
use subfit_target::Target;

/// Neighbours counted for a data point's local spacing (its distance to the 16th nearest other
/// point, as [`subfit_target::TargetStats::point_spacing`]).
pub const SPACING_NEIGHBOURS: usize = 16;

/// Options of [`trim_unsupported`]. Lengths relative to the data (spacings) or to the contour's
/// band (band widths), never absolute.
#[derive(Clone, Debug, PartialEq)]
pub struct TrimOptions {
    /// Whether to trim at all. Default `true`; `false` keeps the contour closed.
    pub enabled: bool,
    /// A face is supported when a data point lies within this many local spacings of its
    /// centroid (see the module docs). Default 1.5. Valid: finite, `> 0`.
    pub support_spacings: f64,
    /// Cap on the support distance, in band widths (the back sheet of an open scan's contour is
    /// about one band width behind the data). Default 0.5. Valid: finite, `> 0`.
    pub support_band_fraction: f64,
    /// Where the cut is a boundary, the faces next to it with a vertex farther than this many
    /// local spacings from the data are removed too (see the module docs). Default 0.75; at
    /// or above [`Self::support_spacings`] nothing more is removed. Valid: finite, `> 0`.
    pub edge_spacings: f64,
    /// Regions of unsupported faces with fewer faces than this are kept (not a boundary).
    /// Default 24.
    pub min_hole_faces: usize,
    /// Regions of unsupported faces whose vertices all lie within a ball of this diameter (in
    /// band widths, around their centroid) are kept. Default 2.
    pub max_hole_diameter: f64,
    /// After trimming, components carrying less than this fraction of the data points (each
    /// point counted for the component of its nearest kept vertex) are dropped; the component
    /// carrying the most is always kept. Default 0.002. Valid `[0, 1]`.
    pub min_component_data: f64,
    /// Passes of smoothing of the boundary loops of the result (cleaning step 5). Default 10;
    /// 0 keeps the marching tetrahedra's zig-zag.
    pub boundary_smoothing: usize,
}

impl Default for TrimOptions {
    fn default() -> Self {
        Self {
            enabled: true,
            support_spacings: 1.5,
            edge_spacings: 0.75,
            support_band_fraction: 0.5,
            min_hole_faces: 24,
            max_hole_diameter: 2.0,
            min_component_data: 0.002,
            boundary_smoothing: 10,
        }
    }
}

/// What [`trim_unsupported`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TrimReport {
    /// Whether faces were removed (the cloud was found open).
    pub open: bool,
    /// Faces of the contour given.
    pub faces_before: usize,
    /// Faces that failed the support test.
    pub unsupported_faces: usize,
    /// Unsupported faces kept because their region is a small hole (cleaning step 1).
    pub hole_faces_kept: usize,
    /// Regions of unsupported faces kept closed.
    pub holes_kept: usize,
    /// Supported faces removed next to the cut for the tighter edge
    /// ([`TrimOptions::edge_spacings`]).
    pub edge_faces_removed: usize,
    /// Faces removed as ears or as minor fans of bow-tie vertices (steps 2–3).
    pub cleanup_faces_removed: usize,
    /// Components dropped (step 4).
    pub components_dropped: usize,
    /// Faces removed in all (`faces_before` − faces of the result).
    pub faces_trimmed: usize,
    /// Boundary loops of the result.
    pub boundary_loops: usize,
    /// Genus of the result (sum over its components).
    pub genus: u32,
    /// Median support distance `τ` over the supported contour vertices (normalized units; 0
    /// when none is).
    pub support_distance: f64,
}

/// Why [`trim_unsupported`] failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TrimError {
    /// An option is out of range.
    #[error("invalid trim option: {0}")]
    InvalidOption(&'static str),
    /// The contour given is not an oriented manifold triangle mesh.
    #[error("the contour is not an oriented manifold: {0}")]
    NotManifold(subfit_mesh::TopologyError),
}

/// Removes the faces of `contour` (a manifold triangle mesh in the target's normalized units,
/// usually closed: the output of [`crate::contour()`]) that no data point supports, and cleans
/// the result into a manifold surface with boundary (see the module docs for the rule).
/// `band_width` is the contour's band half-width in normalized units
/// ([`crate::ContourReport`]: `band_cells · cell_size · 2^band_level`).
///
/// Returns the trimmed mesh (vertices re-indexed, unused ones dropped; the input unchanged when
/// nothing is removed) and a report. When the trimming would remove every face the input is
/// returned unchanged (`open` false). Cost: see the module docs.
pub fn trim_unsupported(
    target: &Target,
    contour: &PolyMesh,
    band_width: f64,
    options: &TrimOptions,
) -> Result<(PolyMesh, TrimReport), TrimError> {
    validate(options)?;
    let mut report = TrimReport {
        faces_before: contour.num_faces(),
        ..TrimReport::default()
    };
    let he = HalfEdgeMesh::from_mesh(contour).map_err(TrimError::NotManifold)?;
    let unchanged = |mut report: TrimReport| {
        report.boundary_loops = he.boundary_loops().len();
        report.genus = he.genus();
        Ok((contour.clone(), report))
    };
    if !options.enabled || contour.num_faces() == 0 {
        return unchanged(report);
    }
    let (supported, near_edge, tau) = support(target, contour, band_width, options);
    report.support_distance = tau;
    report.unsupported_faces = supported.iter().filter(|&&s| !s).count();
    if report.unsupported_faces == 0 {
        return unchanged(report);
    }
    let mut keep = supported;
    let (holes, hole_faces) = keep_small_holes(&he, contour, &mut keep, band_width, options);
    report.holes_kept = holes;
    report.hole_faces_kept = hole_faces;
    report.edge_faces_removed = tighten_edge(target, contour, &he, &mut keep, &near_edge);
    report.cleanup_faces_removed = clean(&he, &mut keep);
    report.components_dropped = drop_small_components(
        target,
        contour,
        &he,
        &mut keep,
        options,
        crate::islands::island_gap(target, band_width),
    );
    let kept = keep.iter().filter(|&&k| k).count();
    if kept == 0 {
        return unchanged(report);
    }
    let mut out = extract(contour, &keep);
    let out_he = HalfEdgeMesh::from_mesh(&out).map_err(TrimError::NotManifold)?;
    smooth_boundary(&mut out, &out_he, options.boundary_smoothing);
    report.faces_trimmed = contour.num_faces() - out.num_faces();
    report.open = report.faces_trimmed > 0;
    report.boundary_loops = out_he.boundary_loops().len();
    report.genus = out_he.genus();
    Ok((out, report))
}

/// The boundary loops of `mesh` as closed polylines (the last point is not repeated), each
/// following the face winding (faces on the left), in the order of
/// [`HalfEdgeMesh::boundary_loops`]; positions in the mesh's units. Errors when `mesh` is not an
/// oriented manifold. Cost `O(#H)`.
pub fn boundary_polylines(
    mesh: &PolyMesh,
) -> Result<Vec<Vec<[f64; 3]>>, subfit_mesh::TopologyError> {
    let he = HalfEdgeMesh::from_mesh(mesh)?;
    Ok(he
        .boundary_loops()
        .iter()
        .map(|lp| lp.iter().map(|v| mesh.positions[v.idx()]).collect())
        .collect())
}

fn validate(o: &TrimOptions) -> Result<(), TrimError> {
    let positive = |x: f64| x.is_finite() && x > 0.0;
    if !positive(o.support_spacings) {
        return Err(TrimError::InvalidOption(
            "support_spacings must be finite and > 0",
        ));
    }
    if !positive(o.edge_spacings) {
        return Err(TrimError::InvalidOption(
            "edge_spacings must be finite and > 0",
        ));
    }
    if !positive(o.support_band_fraction) {
        return Err(TrimError::InvalidOption(
            "support_band_fraction must be finite and > 0",
        ));
    }
    if !(o.max_hole_diameter >= 0.0) || !o.max_hole_diameter.is_finite() {
        return Err(TrimError::InvalidOption(
            "max_hole_diameter must be finite and >= 0",
        ));
    }
    if !(0.0..=1.0).contains(&o.min_component_data) {
        return Err(TrimError::InvalidOption(
            "min_component_data must be in [0, 1]",
        ));
    }
    Ok(())
}

/// Per face whether it is supported (all its vertices are), whether all its vertices are
/// within [`TrimOptions::edge_spacings`] local spacings of data (under the same cap), and the
/// median support distance.
fn support(
    target: &Target,
    mesh: &PolyMesh,
    band_width: f64,
    options: &TrimOptions,
) -> (Vec<bool>, Vec<bool>, f64) {
    let index = target.index();
    let nearest = index.nearest_batch(&mesh.positions);
    // Local spacing of each distinct nearest data point.
    let mut slot = vec![u32::MAX; target.len()];
    let mut queries = Vec::new();
    for n in &nearest {
        if slot[n.index as usize] == u32::MAX {
            slot[n.index as usize] = queries.len() as u32;
            queries.push(target.points()[n.index as usize]);
        }
    }
    // The query point finds itself first.
    let spacing: Vec<f64> = index
        .k_nearest_batch(&queries, SPACING_NEIGHBOURS + 1)
        .iter()
        .map(|nb| nb.last().map_or(0.0, |n| n.distance))
        .collect();
    let cap = options.support_band_fraction * band_width;
    let taus: Vec<f64> = nearest
        .iter()
        .map(|n| (options.support_spacings * spacing[slot[n.index as usize] as usize]).min(cap))
        .collect();
    let vertex_ok: Vec<bool> = nearest
        .iter()
        .zip(&taus)
        .map(|(n, &tau)| n.distance <= tau)
        .collect();
    let supported = mesh
        .faces
        .iter()
        .map(|f| f.iter().all(|&v| vertex_ok[v as usize]))
        .collect();
    let edge = options.edge_spacings.min(options.support_spacings) / options.support_spacings;
    let near_edge = mesh
        .faces
        .iter()
        .map(|f| {
            f.iter()
                .all(|&v| nearest[v as usize].distance <= edge * taus[v as usize])
        })
        .collect();
    let mut taus: Vec<f64> = taus
        .iter()
        .zip(&vertex_ok)
        .filter_map(|(&t, &ok)| ok.then_some(t))
        .collect();
    let median = if taus.is_empty() {
        0.0
    } else {
        let mid = taus.len() / 2;
        *taus.select_nth_unstable_by(mid, f64::total_cmp).1
    };
    (supported, near_edge, median)
}

/// The tighter edge: from every removed face, kept faces that are not `near_edge` are removed,
/// spreading through edge neighbours (only from removed faces, so a kept region without a cut
/// next to it is never touched). A face with a vertex that is the nearest contour vertex of
/// some data point stays: a sparse strip of returns (grazing to the scanner) has its contour
/// vertices farther than the edge distance from its points, and removing them left points of
/// `bun000` 3.7 cells from the surface. Returns the faces removed. Cost: one nearest query per
/// data point over the contour's vertices.
fn tighten_edge(
    target: &Target,
    mesh: &PolyMesh,
    he: &HalfEdgeMesh,
    keep: &mut [bool],
    near_edge: &[bool],
) -> usize {
    let mut stack: Vec<usize> = (0..keep.len()).filter(|&f| !keep[f]).collect();
    if stack.is_empty() {
        return 0;
    }
    let Some(index) = subfit_target::PointIndex::new(&mesh.positions) else {
        return 0;
    };
    let mut covering = vec![false; mesh.num_vertices()];
    for n in index.nearest_batch(target.points()) {
        covering[n.index as usize] = true;
    }
    let movable = |g: usize| {
        !near_edge[g]
            && !he
                .face_vertices(FaceId(g as u32))
                .iter()
                .any(|v| covering[v.idx()])
    };
    let mut removed = 0;
    while let Some(f) = stack.pop() {
        for g in he.face_neighbors(FaceId(f as u32)).flatten() {
            let g = g.idx();
            if keep[g] && movable(g) {
                keep[g] = false;
                removed += 1;
                stack.push(g);
            }
        }
    }
    removed
}

/// Cleaning step 1: regions (edge-connected) of removed faces that are small are kept. Returns
/// the number of regions and faces kept.
fn keep_small_holes(
    he: &HalfEdgeMesh,
    mesh: &PolyMesh,
    keep: &mut [bool],
    band_width: f64,
    options: &TrimOptions,
) -> (usize, usize) {
    let n = keep.len();
    let mut seen = vec![false; n];
    let (mut holes, mut faces) = (0, 0);
    let mut stack = Vec::new();
    let mut region = Vec::new();
    let max_r = 0.5 * options.max_hole_diameter * band_width;
    for f0 in 0..n {
        if keep[f0] || seen[f0] {
            continue;
        }
        region.clear();
        seen[f0] = true;
        stack.push(f0);
        while let Some(f) = stack.pop() {
            region.push(f);
            for g in he.face_neighbors(FaceId(f as u32)).flatten() {
                let g = g.idx();
                if !keep[g] && !seen[g] {
                    seen[g] = true;
                    stack.push(g);
                }
            }
        }
        if region.len() < options.min_hole_faces || fits_in_ball(he, mesh, &region, max_r) {
            holes += 1;
            faces += region.len();
            for &f in &region {
                keep[f] = true;
            }
        }
    }
    (holes, faces)
}

/// Whether every vertex of the faces `region` lies within `r` of their centroid.
fn fits_in_ball(he: &HalfEdgeMesh, mesh: &PolyMesh, region: &[usize], r: f64) -> bool {
    let verts = || {
        region
            .iter()
            .flat_map(|&f| he.face_vertices(FaceId(f as u32)).iter())
            .map(|v| mesh.positions[v.idx()])
    };
    let mut c = [0.0; 3];
    let mut count = 0.0;
    for p in verts() {
        for k in 0..3 {
            c[k] += p[k];
        }
        count += 1.0;
    }
    let c = c.map(|x| x / count);
    verts().all(|p| {
        let d2: f64 = (0..3).map(|k| (p[k] - c[k]).powi(2)).sum();
        d2 <= r * r
    })
}

/// Cleaning steps 2–3, repeated until nothing changes: ears and minor bow-tie fans removed.
/// Returns the faces removed.
fn clean(he: &HalfEdgeMesh, keep: &mut [bool]) -> usize {
    let mut removed = 0;
    loop {
        let ears = remove_ears(he, keep);
        let fans = remove_minor_fans(he, keep);
        removed += ears + fans;
        if ears + fans == 0 {
            return removed;
        }
    }
}

/// Removes, until none is left, kept faces with at most one kept neighbour across their edges.
fn remove_ears(he: &HalfEdgeMesh, keep: &mut [bool]) -> usize {
    let kept_neighbours = |keep: &[bool], f: usize| {
        he.face_neighbors(FaceId(f as u32))
            .filter(|g| g.is_some_and(|g| keep[g.idx()]))
            .count()
    };
    let mut stack: Vec<usize> = (0..keep.len()).filter(|&f| keep[f]).collect();
    let mut removed = 0;
    while let Some(f) = stack.pop() {
        if !keep[f] || kept_neighbours(keep, f) > 1 {
            continue;
        }
        keep[f] = false;
        removed += 1;
        stack.extend(
            he.face_neighbors(FaceId(f as u32))
                .flatten()
                .map(|g| g.idx())
                .filter(|&g| keep[g]),
        );
    }
    removed
}

/// At every vertex whose kept faces form several fans, keeps the largest fan only.
fn remove_minor_fans(he: &HalfEdgeMesh, keep: &mut [bool]) -> usize {
    let mut removed = 0;
    let mut faces = Vec::new();
    for v in 0..he.num_vertices() {
        let v = VertexId(v as u32);
        faces.clear();
        faces.extend(he.vertex_faces(v).map(|f| f.idx()));
        let cyclic = !he.is_boundary_vertex(v);
        let runs = fans(&faces, keep, cyclic);
        if runs.len() < 2 {
            continue;
        }
        let largest = (0..runs.len())
            .max_by_key(|&i| (runs[i].len(), std::cmp::Reverse(i)))
            .unwrap_or(0);
        for (i, run) in runs.iter().enumerate() {
            if i != largest {
                for &f in run {
                    keep[f] = false;
                    removed += 1;
                }
            }
        }
    }
    removed
}

/// Maximal runs of kept faces in the sequence `faces` around a vertex (cyclic for an interior
/// vertex).
fn fans(faces: &[usize], keep: &[bool], cyclic: bool) -> Vec<Vec<usize>> {
    let n = faces.len();
    // Start after a removed face, so that a cyclic run is not split.
    let start = if cyclic {
        match (0..n).find(|&i| !keep[faces[i]]) {
            Some(i) => i + 1,
            None => return vec![faces.to_vec()],
        }
    } else {
        0
    };
    let mut runs: Vec<Vec<usize>> = Vec::new();
    let mut open = false;
    for k in 0..n {
        let f = faces[(start + k) % n];
        if keep[f] {
            if !open {
                runs.push(Vec::new());
                open = true;
            }
            if let Some(r) = runs.last_mut() {
                r.push(f);
            }
        } else {
            open = false;
        }
    }
    runs
}

/// Cleaning step 4: components (of the kept faces) carrying less than the fraction of the data
/// are removed. Returns the number dropped.
fn drop_small_components(
    target: &Target,
    mesh: &PolyMesh,
    he: &HalfEdgeMesh,
    keep: &mut [bool],
    options: &TrimOptions,
    gap: f64,
) -> usize {
    let mut polys = Polygons::new();
    for (f, &k) in keep.iter().enumerate() {
        let vs: &[VertexId] = if k {
            he.face_vertices(FaceId(f as u32))
        } else {
            &[]
        };
        polys.push(&vs.iter().map(|v| v.0).collect::<Vec<_>>());
    }
    let comps = face_components(&polys, he.num_vertices());
    if comps.count < 2 {
        return 0;
    }
    // Data points per component, by the nearest kept vertex.
    let used: Vec<usize> = (0..he.num_vertices())
        .filter(|&v| comps.vertex_labels[v] != u32::MAX)
        .collect();
    let positions: Vec<[f64; 3]> = used.iter().map(|&v| mesh.positions[v]).collect();
    let Some(index) = subfit_target::PointIndex::new(&positions) else {
        return 0;
    };
    let mut carried = vec![0usize; comps.count];
    for n in index.nearest_batch(target.points()) {
        carried[comps.vertex_labels[used[n.index as usize]] as usize] += 1;
    }
    let most = (0..comps.count).max_by_key(|&c| carried[c]).unwrap_or(0);
    let floor = options.min_component_data * target.len() as f64;
    let mut small: Vec<bool> = (0..comps.count)
        .map(|c| c != most && (carried[c] as f64) < floor)
        .collect();
    // An island that alone covers data stays ([`crate::islands`]).
    let kept: Vec<bool> = small.iter().map(|&s| !s).collect();
    let alone = crate::islands::uncovered_by_component(
        target.points(),
        &mesh.positions,
        &comps.vertex_labels,
        comps.count,
        &kept,
        gap,
    );
    for (s, &a) in small.iter_mut().zip(&alone) {
        *s &= a < crate::islands::MIN_ISLAND_POINTS;
    }
    for (f, k) in keep.iter_mut().enumerate() {
        let l = comps.face_labels[f];
        if *k && l != u32::MAX && small[l as usize] {
            *k = false;
        }
    }
    small.iter().filter(|&&s| s).count()
}

/// Cleaning step 5: `passes` passes of moving every boundary vertex halfway to the midpoint of
/// its two loop neighbours (a discrete curve-shortening flow), a move being skipped when it
/// would turn one of the vertex's faces by more than 60°. Cost `O(passes · #H)`.
fn smooth_boundary(mesh: &mut PolyMesh, he: &HalfEdgeMesh, passes: usize) {
    use subfit_mesh::vec3::{add, cross, dot, norm, scale, sub};
    let loops = he.boundary_loops();
    let normal = |pos: &[[f64; 3]], f: FaceId| {
        let v = he.face_vertices(f);
        let [a, b, c] = [0, 1, 2].map(|k| pos[v[k].idx()]);
        cross(sub(b, a), sub(c, a))
    };
    let cos60 = 0.5;
    for _ in 0..passes {
        for lp in &loops {
            let n = lp.len();
            if n < 4 {
                continue;
            }
            let old: Vec<[f64; 3]> = lp.iter().map(|v| mesh.positions[v.idx()]).collect();
            for i in 0..n {
                let v = lp[i];
                let mid = scale(add(old[(i + n - 1) % n], old[(i + 1) % n]), 0.5);
                let target = scale(add(old[i], mid), 0.5);
                let before: Vec<[f64; 3]> = he
                    .vertex_faces(v)
                    .map(|f| normal(&mesh.positions, f))
                    .collect();
                let keep = mesh.positions[v.idx()];
                mesh.positions[v.idx()] = target;
                let ok = he.vertex_faces(v).zip(&before).all(|(f, nb)| {
                    let na = normal(&mesh.positions, f);
                    dot(na, *nb) > cos60 * norm(na) * norm(*nb)
                });
                if !ok {
                    mesh.positions[v.idx()] = keep;
                }
            }
        }
    }
}

/// The kept faces of `mesh`, with their vertices re-indexed in order of first use.
fn extract(mesh: &PolyMesh, keep: &[bool]) -> PolyMesh {
    let mut map = vec![u32::MAX; mesh.num_vertices()];
    let mut positions = Vec::new();
    let mut faces = Polygons::new();
    let mut face = Vec::new();
    for (f, poly) in mesh.faces.iter().enumerate() {
        if !keep[f] {
            continue;
        }
        face.clear();
        for &v in poly {
            let m = &mut map[v as usize];
            if *m == u32::MAX {
                *m = positions.len() as u32;
                positions.push(mesh.positions[v as usize]);
            }
            face.push(*m);
        }
        faces.push(&face);
    }
    PolyMesh::new(positions, faces)
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfit_mesh::shapes::octahedron_mesh;

    #[test]
    fn fans_are_maximal_runs_and_wrap_around_interior_vertices() {
        let keep = [true, false, true, true, false, true];
        // Interior vertex: faces 5 and 0 are one run across the end of the list.
        assert_eq!(
            fans(&[0, 1, 2, 3, 4, 5], &keep, true),
            vec![vec![2, 3], vec![5, 0]]
        );
        // Boundary vertex: the list does not wrap.
        assert_eq!(
            fans(&[0, 1, 2, 3, 4, 5], &keep, false),
            vec![vec![0], vec![2, 3], vec![5]]
        );
        assert_eq!(fans(&[0, 2, 3], &keep, true), vec![vec![0, 2, 3]]);
        assert!(fans(&[1, 4], &keep, true).is_empty());
    }

    /// Two opposite faces of an octahedron touch at one vertex only (a bow-tie); cleaning keeps
    /// one of them, and the result is a manifold.
    #[test]
    fn bow_ties_keep_one_fan() {
        let m = octahedron_mesh(1.0, 1.0, 1.0);
        let he = HalfEdgeMesh::from_mesh(&m).unwrap();
        let v = VertexId(0);
        let around: Vec<usize> = he.vertex_faces(v).map(|f| f.idx()).collect();
        assert_eq!(around.len(), 4);
        let mut keep = vec![false; m.num_faces()];
        keep[around[0]] = true;
        keep[around[2]] = true;
        assert_eq!(remove_minor_fans(&he, &mut keep), 1);
        assert_eq!(keep.iter().filter(|&&k| k).count(), 1);
        let out = extract(&m, &keep);
        assert!(HalfEdgeMesh::from_mesh(&out).is_ok());
    }

    /// A strip one face wide is eaten from its ends; a face with two kept neighbours stays.
    #[test]
    fn ears_are_removed() {
        let m = octahedron_mesh(1.0, 1.0, 1.0);
        let he = HalfEdgeMesh::from_mesh(&m).unwrap();
        let mut keep = vec![true; m.num_faces()];
        assert_eq!(remove_ears(&he, &mut keep), 0);
        let mut keep = vec![false; m.num_faces()];
        keep[0] = true;
        let g = he.face_neighbors(FaceId(0)).flatten().next().unwrap().idx();
        keep[g] = true;
        assert_eq!(remove_ears(&he, &mut keep), 2);
        assert!(keep.iter().all(|&k| !k));
    }

    /// On a flat grid the boundary smoothing keeps every vertex in the plane, leaves the
    /// interior alone, flips no face, and straightens a zig-zag boundary.
    #[test]
    fn boundary_smoothing_straightens_zig_zags_in_the_plane() {
        let n = 8;
        let mut pos = Vec::new();
        for j in 0..n {
            for i in 0..n {
                // The bottom row zig-zags.
                let y = if j == 0 && i % 2 == 1 { 0.3 } else { j as f64 };
                pos.push([i as f64, y, 0.0]);
            }
        }
        let id = |i: usize, j: usize| (i + n * j) as u32;
        let mut tris = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let before = PolyMesh::new(pos, Polygons::from_triangles(&tris));
        let he = HalfEdgeMesh::from_mesh(&before).unwrap();
        let mut m = before.clone();
        smooth_boundary(&mut m, &he, 10);
        // Second differences along the bottom row, away from the (rounded) corners.
        let zig = |m: &PolyMesh| {
            let y = |i: usize| m.positions[i][1];
            (2..n - 2)
                .map(|i| (y(i - 1) - 2.0 * y(i) + y(i + 1)).abs())
                .fold(0.0, f64::max)
        };
        assert!(
            zig(&m) < 0.3 * zig(&before),
            "{} vs {}",
            zig(&m),
            zig(&before)
        );
        for (v, (p, q)) in m.positions.iter().zip(&before.positions).enumerate() {
            assert_eq!(p[2], 0.0);
            if !he.is_boundary_vertex(VertexId(v as u32)) {
                assert_eq!(p, q);
            }
        }
        for t in &tris {
            let [a, b, c] = t.map(|v| m.positions[v as usize]);
            let z = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            assert!(z > 0.0, "{t:?} flipped");
        }
    }

    #[test]
    fn invalid_options_are_errors() {
        for o in [
            TrimOptions {
                support_spacings: 0.0,
                ..TrimOptions::default()
            },
            TrimOptions {
                support_band_fraction: f64::INFINITY,
                ..TrimOptions::default()
            },
            TrimOptions {
                max_hole_diameter: -1.0,
                ..TrimOptions::default()
            },
            TrimOptions {
                min_component_data: 2.0,
                ..TrimOptions::default()
            },
        ] {
            assert!(matches!(validate(&o), Err(TrimError::InvalidOption(_))));
        }
        assert!(validate(&TrimOptions::default()).is_ok());
    }
}
