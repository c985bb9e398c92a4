//! The initial control mesh (DESIGN.md §3.6: it has the target's topology, checked and reported).
//!
//! Mesh targets are simplified ([`crate::simplify`](mod@crate::simplify), Garland & Heckbert 1997 with the link
//! condition of Dey et al. 1999), like the method of reference 13 in Cheng et al. 2007 §I; point
//! clouds are contoured first ([`crate::contour()`](mod@crate::contour): IMLS of Xie et al. 2023 on an adaptive octree, marching
//! tetrahedra) and then simplified, as Cheng et al. 2004 §4.3 (marching cubes on an octree, then
//! simplification). Between the two, the contour of an open cloud is cut where no data supports
//! it ([`crate::trim`](mod@crate::trim)), so that the cage has the open target's boundary loops
//! (DESIGN.md §3.6; the open surfaces of Lavoué et al. 2007 §4). With
//! [`InitOptions::features`], a mesh target's sharp features
//! ([`subfit_target::detect_features`]) are kept by the simplification as cage edges and come
//! back as crease and corner tags ([`InitReport::tags`]): a feature-aligned cage (Lavoué et al.
//! §6 mark patch boundaries as sharp control edges); a point cloud's crease curves
//! ([`subfit_target::detect_cloud_features`]) are traced on its contour first
//! ([`crate::snap`](mod@crate::snap)).

use std::time::Instant;

use subfit_mesh::bvh::TriangleBvh;
use subfit_mesh::{split_concave_corners, Cancel, HalfEdgeMesh, PolyMesh};
use subfit_target::{
    detect_cloud_features, detect_features, fillet_widths, FeatureOptions, Features, Target,
};

use crate::semi_sharp::semi_sharp_tags;

use crate::carve::carve_cancellable;
use crate::contour::{contour, ContourError, ContourOptions, ContourReport};
use crate::cross_field::{
    quad_cage, rotate_for_valence, split_into_quads_tagged, QuadCageError, QuadCageOptions,
};
use crate::quads::pair_triangles;
use crate::simplify::{simplify_with_features, FeatureLock, SimplifyOptions};
use crate::snap::snap_to_features;
use crate::specks::Speck;
use crate::trim::{boundary_polylines, trim_unsupported};

pub use crate::init_options::{
    default_control_points, min_vertices_for_topology, FeatureCounts, InitError, InitOptions,
    InitReport, InitSource, InitTimings, ONE_SIDED_REFINE, ONE_SIDED_TRIM, OPEN_CLOUD_SCALE,
    QUARTER_SPLIT,
};

/// An initial triangle control mesh with about `n_vertices` vertices and the target's topology
/// (quad-dominant with [`InitOptions::quad_dominant`]).
///
/// * `mesh = Some(m)` with faces: `m` (in the target's **original** coordinates, e.g. the mesh the
///   target was built from) is mapped into normalized units and simplified.
/// * otherwise the target's points (with their oriented normals) are contoured, the contour's
///   faces that no data supports are trimmed away ([`crate::trim`](mod@crate::trim): an open
///   cloud such as a single-view scan gives an open surface, `report.trim`,
///   `report.boundary_curves`; a closed cloud's contour is kept as is), then simplified, which
///   keeps the boundary loops. When [`InitOptions::expected_genus`] is set and the trimmed
///   contour misses it, the normal-free space-carving wrap ([`crate::carve()`], closed, not
///   trimmed) is tried instead (`report.carve_radius`).
///
/// The result is in the target's normalized units, manifold, consistently oriented (outward for
/// contours; as the input for meshes), closed when the target is (for a point cloud: when every
/// contour face is supported by data); it may keep more than
/// `n_vertices` vertices when no legal collapse remains (see `report.simplify.reached_target`).
///
/// Errors: [`InitError::TooFewVertices`] (`n_vertices < 4`), [`InitError::InvalidMesh`] /
/// [`InitError::NonFinite`] for a bad mesh target, [`InitError::TooFewForTopology`] when
/// `n_vertices` is below [`min_vertices_for_topology`] of the surface (checked after contouring
/// for point clouds), [`InitError::Contour`], [`InitError::GenusMismatch`] (only with
/// [`InitOptions::require_genus`]), [`InitError::Interrupted`] once [`InitOptions::cancel`] is
/// cancelled. A target with too few points fails earlier, in [`Target`]'s constructor.
///
/// Cost: contouring `O(n log n + n·k)` for the `n` octree points (proportional to the band around
/// the data, see [`crate::contour()`]) and `k` points per IMLS neighbourhood, simplification
/// `O(E log E)`, pairing `O(E log E)` (see [`crate::quads`](mod@crate::quads)).
pub fn initial_control_mesh(
    target: &Target,
    mesh: Option<&PolyMesh>,
    n_vertices: usize,
    options: &InitOptions,
) -> Result<(PolyMesh, InitReport), InitError> {
    let t0 = Instant::now();
    if n_vertices < 4 {
        return Err(InitError::TooFewVertices(n_vertices));
    }
    let mut report = InitReport::default();
    let (mut dense, specks) = dense_surface(target, mesh, n_vertices, options, &mut report)?;
    let n_vertices = report.open_cloud_control_points.unwrap_or(n_vertices);
    let loops_before = check_dense(&dense, mesh, n_vertices, options, &mut report)?;

    let t = Instant::now();
    let (lock, features) = lock_features(target, &mut dense, options, &mut report);
    let featureless = lock.edges.is_empty();
    if let Some(cage) = cross_field_cage(
        target,
        &dense,
        n_vertices,
        featureless,
        options,
        t,
        &mut report,
    )? {
        return finish(cage, report, loops_before, t0, options);
    }
    // All quads asked but the field's cage not taken: the paired cage of about a quarter of
    // the count, each face split into quads (V + E + F ≈ 4.4 V for a quad-dominant cage).
    let split = options.split_into_quads && options.quad_dominant;
    let sopt = SimplifyOptions {
        target_vertices: n_vertices,
        cancel: options.cancel.clone(),
        ..options.simplify.clone()
    };
    let sopt = if split {
        SimplifyOptions {
            target_vertices: ((n_vertices as f64 / QUARTER_SPLIT).round() as usize).max(4),
            ..sopt
        }
    } else {
        sopt
    };
    let out = simplified_cage(
        &dense,
        &lock,
        features.as_ref(),
        &sopt,
        options,
        specks,
        &mut report,
    )?;
    report.timings.simplify = t.elapsed();
    let out = quad_dominant_cage(target, &dense, out, split, options, &mut report)?;
    finish(out, report, loops_before, t0, options)
}

/// The dense surface the cage is simplified from: the target's mesh in normalized units, or
/// for a point cloud its trimmed contour ([`cloud_surface`]) with the specks found beside it.
/// Sets `report.source` and, for clouds, `report.timings.contour`.
fn dense_surface(
    target: &Target,
    mesh: Option<&PolyMesh>,
    n_vertices: usize,
    options: &InitOptions,
    report: &mut InitReport,
) -> Result<(PolyMesh, Vec<Speck>), InitError> {
    let mut specks = Vec::new();
    let dense = match mesh {
        Some(m) if !m.faces.is_empty() => {
            report.source = InitSource::Mesh;
            normalized_mesh(target, m)?
        }
        _ => {
            report.source = InitSource::Contour;
            let t = Instant::now();
            let (m, found) = cloud_surface(target, n_vertices, options, report)?;
            specks = found;
            report.timings.contour = t.elapsed();
            m
        }
    };
    Ok((dense, specks))
}

/// The dense surface's topology before simplification: fills `report.genus_before` and
/// `report.genus_target` and returns its boundary loop count. Errors when it is not a valid
/// mesh (naming the input's polygons for a mesh target) or `n_vertices` cannot carry its
/// topology.
fn check_dense(
    dense: &PolyMesh,
    mesh: Option<&PolyMesh>,
    n_vertices: usize,
    options: &InitOptions,
    report: &mut InitReport,
) -> Result<usize, InitError> {
    let before = HalfEdgeMesh::from_mesh(dense).map_err(|e| match (report.source, mesh) {
        // The error names faces of the fan-triangulated copy: name the input's polygons.
        (InitSource::Mesh, Some(m)) => {
            let polygon: Vec<u32> = m
                .faces
                .iter()
                .enumerate()
                .flat_map(|(f, p)| std::iter::repeat_n(f as u32, p.len().saturating_sub(2)))
                .collect();
            InitError::InvalidMesh(e.map_faces(|t| {
                subfit_mesh::FaceId(polygon.get(t.0 as usize).copied().unwrap_or(t.0))
            }))
        }
        (InitSource::Mesh, None) => InitError::InvalidMesh(e),
        (InitSource::Contour, _) => InitError::Topology(e),
    })?;
    report.genus_before = before.genus();
    report.genus_target = match (report.source, options.expected_genus) {
        (InitSource::Contour, Some(g)) => g,
        _ => report.genus_before,
    };
    let loops_before = before.boundary_loops().len();
    check_topology_allows(&before, n_vertices)?;
    drop(before);
    options.cancel.check()?;
    Ok(loops_before)
}

/// With [`InitOptions::features`]: the sharp features the cage keeps — detected on a mesh
/// target, or for a point cloud detected on the cloud with `dense` snapped to them
/// ([`cloud_feature_lock`]) — as a lock for the simplification, with the mesh's features (for
/// semi-sharp tags). Fills `report.features` and `report.feature_segments`.
fn lock_features(
    target: &Target,
    dense: &mut PolyMesh,
    options: &InitOptions,
    report: &mut InitReport,
) -> (FeatureLock, Option<Features>) {
    let mut features = None;
    let lock = match (&options.features, report.source) {
        (Some(fo), InitSource::Mesh) => {
            let f = detect_features(&dense.positions, &dense.faces, fo);
            report.features = Some(FeatureCounts {
                edges: f.edges.len(),
                curves: f.curves.len(),
                corners: f.corners.len(),
                darts: f.darts.len(),
            });
            let lock = FeatureLock {
                edges: f.edges.clone(),
                corners: f.corners.clone(),
            };
            features = Some(f);
            lock
        }
        (Some(fo), InitSource::Contour) if options.cloud_features => {
            cloud_feature_lock(target, dense, fo, report)
        }
        _ => FeatureLock::default(),
    };
    // The feature edges as segments, for the fit's crease-curve term.
    report.feature_segments = lock
        .edges
        .iter()
        .filter_map(|&[a, b]| {
            Some([
                *dense.positions.get(a as usize)?,
                *dense.positions.get(b as usize)?,
            ])
        })
        .collect();
    (lock, features)
}

/// With [`InitOptions::cross_field`] and no sharp features (`featureless`): the cross-field
/// cage ([`quad_cage`]; `report.cross_field`, and `report.timings.simplify` since `t`).
/// `None` when it was not asked or failed (why in `report.cross_field_failure`).
fn cross_field_cage(
    target: &Target,
    dense: &PolyMesh,
    n_vertices: usize,
    featureless: bool,
    options: &InitOptions,
    t: Instant,
    report: &mut InitReport,
) -> Result<Option<PolyMesh>, InitError> {
    if let Some(qo) = options.cross_field.as_ref().filter(|_| featureless) {
        let qo = QuadCageOptions {
            cancel: options.cancel.clone(),
            ..qo.clone()
        };
        match quad_cage(target, dense, n_vertices, &qo) {
            Ok((cage, qrep)) => {
                report.timings.simplify = t.elapsed();
                report.cross_field = Some(qrep);
                return Ok(Some(cage));
            }
            Err(QuadCageError::Interrupted) => return Err(InitError::Interrupted),
            Err(e) => report.cross_field_failure = Some(e.to_string()),
        }
    } else if options.cross_field.is_some() {
        report.cross_field_failure =
            Some("the target's sharp features are kept as tags by the simplified cage".into());
    }
    Ok(None)
}

/// The simplified cage: `dense` simplified keeping `lock` ([`simplify_with_features`]), its
/// tags made semi-sharp with [`InitOptions::semi_sharp`], concave corners split (mesh
/// targets) and `specks` added, all within [`InitOptions::max_control_points`]. Fills
/// `report.fillet_widths`, `report.concave`, `report.specks`, `report.simplify` and
/// `report.tags`.
fn simplified_cage(
    dense: &PolyMesh,
    lock: &FeatureLock,
    features: Option<&Features>,
    sopt: &SimplifyOptions,
    options: &InitOptions,
    mut specks: Vec<Speck>,
    report: &mut InitReport,
) -> Result<PolyMesh, InitError> {
    let (mut out, mut tags, srep) = simplify_with_features(dense, lock, sopt)?;
    if let (true, Some(f)) = (options.semi_sharp, features) {
        report.fillet_widths = fillet_widths(&dense.positions, &dense.faces, f);
        tags = semi_sharp_tags(&out, &tags, dense, f, &report.fillet_widths);
    }
    // A point cloud's traced crease graph has stray crease edges (T-junctions on flat sides)
    // where a split would only add creases off the data's features.
    if report.source == InitSource::Mesh {
        let room = options
            .max_control_points
            .saturating_sub(out.num_vertices());
        report.concave = split_concave_corners(&mut out, &mut tags, room);
    }
    // Specks within the budget only.
    let room = options
        .max_control_points
        .saturating_sub(out.num_vertices())
        / crate::specks::SPECK_VERTICES;
    specks.truncate(room);
    crate::specks::push_specks(&mut out, &specks);
    report.specks = specks.len();
    report.simplify = srep;
    report.tags = tags;
    Ok(out)
}

/// With [`InitOptions::quad_dominant`]: the cage's triangles paired into quads
/// ([`pair_triangles`]), edges rotated toward valence 4 on the target's mesh or the contour
/// `dense` ([`InitOptions::rotate_edges`]), and with `split` every face split into quads.
/// Fills `report.pairing`, `report.timings.pair` and updates `report.tags`.
fn quad_dominant_cage(
    target: &Target,
    dense: &PolyMesh,
    mut out: PolyMesh,
    split: bool,
    options: &InitOptions,
    report: &mut InitReport,
) -> Result<PolyMesh, InitError> {
    if options.quad_dominant {
        options.cancel.check()?;
        let t = Instant::now();
        let (paired, prep) = pair_triangles(&out, &report.tags, Some(target), &options.pairing)?;
        out = paired;
        report.timings.pair = t.elapsed();
        report.pairing = Some(prep);
    }
    // The surface the rotations relax vertices on: the target's mesh, or the contour.
    let rotate = options.quad_dominant && options.rotate_edges;
    let contour_surface = match (rotate, target.mesh()) {
        (true, None) => Some(TriangleBvh::new(
            dense.positions.clone(),
            dense.faces.triangulate_fan(),
        )),
        _ => None,
    };
    let surface = target.mesh().or(contour_surface.as_ref());
    if let (true, Some(surface)) = (rotate, surface) {
        out = rotate_for_valence(&out, surface, &report.tags).0;
    }
    if split {
        let (quads, tags) = split_into_quads_tagged(&out, &report.tags);
        out = quads;
        report.tags = tags;
        if let (true, Some(surface)) = (rotate, surface) {
            out = rotate_for_valence(&out, surface, &report.tags).0;
        }
    }
    Ok(out)
}

/// The cage `out` checked and reported: genus, boundary loops, components.
fn finish(
    out: PolyMesh,
    mut report: InitReport,
    loops_before: usize,
    t0: Instant,
    options: &InitOptions,
) -> Result<(PolyMesh, InitReport), InitError> {
    let after = HalfEdgeMesh::from_mesh(&out)?;
    report.genus_after = after.genus();
    let loops_after = after.boundary_loops().len();
    report.boundary_loops = (loops_before + report.specks, loops_after);
    report.closed = loops_after == 0;
    report.components = after.components().count;
    report.genus_matches = report.genus_after == report.genus_target;
    report.timings.total = t0.elapsed();
    if options.require_genus && !report.genus_matches {
        return Err(InitError::GenusMismatch {
            expected: report.genus_target,
            got: report.genus_after,
        });
    }
    Ok((out, report))
}

/// `m` (original coordinates) mapped into the target's normalized units and fan-triangulated;
/// checked for non-finite coordinates.
fn normalized_mesh(target: &Target, m: &PolyMesh) -> Result<PolyMesh, InitError> {
    if let Some(v) = m
        .positions
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        return Err(InitError::NonFinite(v));
    }
    let positions = m
        .positions
        .iter()
        .map(|&p| target.to_normalized(p))
        .collect();
    let tris = m.faces.triangulate_fan();
    Ok(PolyMesh::new(
        positions,
        subfit_mesh::Polygons::from_triangles(&tris),
    ))
}

/// The surface of a point cloud: the contour ([`contour_for`]) trimmed where no data supports it
/// ([`trim_unsupported`]); when [`InitOptions::expected_genus`] is set and the trimmed contour
/// misses it, the space-carving wrap ([`carve_for`]) if that has the genus, unless
/// [`InitOptions::expected_boundary_loops`] says the cloud is open. A carved wrap lies
/// about the carving radius off the data on every side, so it is not trimmed (the support test
/// would remove it all). Fills `report.contour`, `report.trim`, `report.carve_radius` and
/// `report.boundary_curves`.
fn cloud_surface(
    target: &Target,
    n_vertices: usize,
    options: &InitOptions,
    report: &mut InitReport,
) -> Result<(PolyMesh, Vec<Speck>), InitError> {
    let (m, mut c) = contour_for(target, n_vertices, options)?;
    options.cancel.check()?;
    let band =
        |c: &ContourReport| c.band_cells as f64 * c.cell_size * (1u64 << c.band_level) as f64;
    let (mut m, mut tr) = trim_unsupported(target, &m, band(&c), &options.trim)?;
    let more = ((options.open_cloud_scale * n_vertices as f64).round() as usize)
        .min(options.max_control_points);
    let one_sided = tr.open && tr.faces_trimmed as f64 >= ONE_SIDED_TRIM * tr.faces_before as f64;
    let refine = one_sided && options.one_sided_refine > options.contour.refine_levels;
    if tr.open && (more > n_vertices || refine) {
        // An open cloud: contour and trim again for the larger count (the contour's
        // resolution follows the count) and, one-sided, finer; kept when it is still open.
        let mut again = options.clone();
        if refine {
            again.contour.refine_levels = options.one_sided_refine;
        }
        let count = more.max(n_vertices);
        let (m2, c2) = contour_for(target, count, &again)?;
        options.cancel.check()?;
        let (t2, tr2) = trim_unsupported(target, &m2, band(&c2), &options.trim)?;
        if tr2.open {
            (m, c, tr) = (t2, c2, tr2);
            report.open_cloud_control_points = (more > n_vertices).then_some(more);
            report.one_sided_refined = refine;
        }
    }
    let known_open = options.expected_boundary_loops.is_some_and(|b| b > 0);
    if let Some(g) = options
        .expected_genus
        .filter(|&g| g != tr.genus && !known_open)
    {
        if let Some((cm, cc, r)) = carve_for(target, &c, g, &options.cancel)? {
            report.carve_radius = Some(r);
            report.contour = Some(cc);
            return Ok((cm, Vec::new()));
        }
    }
    let mut specks = Vec::new();
    if tr.open {
        if !target.stats().is_noisy() {
            let gap = crate::islands::island_gap(target, band(&c));
            specks = crate::specks::find_specks(target, &m, gap);
        }
        report.boundary_curves = boundary_polylines(&m)?;
    }
    report.trim = Some(tr);
    report.contour = Some(c);
    Ok((m, specks))
}

/// The contour of the target's points, re-contoured once at a finer resolution when it has fewer
/// than [`InitOptions::contour_vertices_per_control`] vertices per requested control vertex
/// and the resolution is automatic; the finer contour is used only when its genus and
/// component count agree with the coarse one's.
fn contour_for(
    target: &Target,
    n_vertices: usize,
    options: &InitOptions,
) -> Result<(PolyMesh, ContourReport), InitError> {
    let coarse = ContourOptions {
        cancel: options.cancel.clone(),
        ..options.contour.clone()
    };
    let (m, c) = contour(target, &coarse)?;
    let wanted = options.contour_vertices_per_control * n_vertices as f64;
    if options.contour.resolution.is_some()
        || !(wanted > c.vertices as f64)
        || c.resolution >= options.contour.max_resolution
    {
        return Ok((m, c));
    }
    // Vertices grow with the square of the resolution; 10 % margin.
    let factor = (wanted / c.vertices.max(1) as f64).sqrt() * 1.1;
    let res = ((c.resolution as f64 * factor).ceil() as usize)
        .clamp(c.resolution + 1, options.contour.max_resolution);
    let finer = ContourOptions {
        resolution: Some(res),
        ..coarse
    };
    // A finer resolution resolves more of the IMLS function's noise: on thin parts it can open
    // spurious handles (the armadillo at 2.5 cells per radius). The coarse contour's topology
    // is the more trustworthy; keep it when the two disagree.
    match contour(target, &finer) {
        Ok((fm, fc)) if fc.genus == c.genus && fc.components_kept == c.components_kept => {
            Ok((fm, fc))
        }
        Err(ContourError::Interrupted) => Err(InitError::Interrupted),
        _ => Ok((m, c)),
    }
}

/// Carving runs on a uniform grid (`O(N³)` memory): its resolution stays below the 2 × 160 it
/// had when the IMLS contour was a uniform grid of at most 160 cells, now that the octree
/// contour can be much finer.
const MAX_CARVE_RESOLUTION: usize = 320;

/// The space-carving fallback: carving radii of 1, 1.5, 2 and 3 IMLS-contour cells on a grid
/// twice as fine (at most [`MAX_CARVE_RESOLUTION`]); the first result of genus `genus` with one
/// component, if any, with its radius. Only [`InitError::Interrupted`] is an error.
fn carve_for(
    target: &Target,
    imls: &ContourReport,
    genus: u32,
    cancel: &Cancel,
) -> Result<Option<(PolyMesh, ContourReport, f64)>, InitError> {
    let res = (2 * imls.resolution).clamp(32, MAX_CARVE_RESOLUTION);
    for k in [1.0, 1.5, 2.0, 3.0] {
        let r = k * imls.cell_size;
        match carve_cancellable(target, res, r, 1.0, cancel) {
            Ok((m, c)) if c.genus == genus && c.components_kept == 1 => return Ok(Some((m, c, r))),
            Err(ContourError::Interrupted) => return Err(InitError::Interrupted),
            _ => {}
        }
    }
    Ok(None)
}

/// [`InitError::TooFewForTopology`] when `n_vertices` is below the sum over the components of
/// [`min_vertices_for_topology`].
fn check_topology_allows(he: &HalfEdgeMesh, n_vertices: usize) -> Result<(), InitError> {
    let comps = he.components();
    let genera = he.component_genera();
    let mut loops = vec![0usize; comps.count];
    for lp in he.boundary_loops() {
        if let Some(l) = lp.first().map(|v| comps.vertex_labels[v.idx()] as usize) {
            loops[l] += 1;
        }
    }
    let minimum: usize = genera
        .iter()
        .zip(&loops)
        .map(|(&g, &b)| min_vertices_for_topology(g, b))
        .sum();
    let (genus, loops) = (genera.iter().sum(), loops.iter().sum());
    if n_vertices < minimum {
        return Err(InitError::TooFewForTopology {
            requested: n_vertices,
            minimum,
            genus,
            boundary_loops: loops,
            components: comps.count,
        });
    }
    Ok(())
}

/// The hook of [`initial_control_mesh`] for point clouds with
/// [`InitOptions::features`]: detects the cloud's features, snaps `dense` (the trimmed
/// contour, normalized units) to them and fills `report.features` (edges: contour edges
/// locked).
fn cloud_feature_lock(
    target: &Target,
    dense: &mut PolyMesh,
    options: &FeatureOptions,
    report: &mut InitReport,
) -> FeatureLock {
    let f = detect_cloud_features(target, options);
    let (lock, snap) = snap_to_features(dense, &f, Some((target.points(), target.index())));
    report.features = Some(FeatureCounts {
        edges: snap.edges,
        curves: f.curves.len(),
        corners: f.corners.len(),
        darts: f.darts,
    });
    lock
}
