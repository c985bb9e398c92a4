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

use std::time::{Duration, Instant};

use subfit_mesh::bvh::TriangleBvh;
use subfit_mesh::{
    split_concave_corners, Cancel, Cancelled, ConcaveSplits, HalfEdgeMesh, PolyMesh, Tags,
    TopologyError,
};
use subfit_target::{
    detect_cloud_features, detect_features, fillet_widths, FeatureOptions, Target,
};

use crate::semi_sharp::semi_sharp_tags;

use crate::carve::carve_cancellable;
use crate::contour::{contour, ContourError, ContourOptions, ContourReport};
use crate::cross_field::{
    quad_cage, rotate_for_valence, split_into_quads_tagged, QuadCageError, QuadCageOptions,
    QuadCageReport,
};
use crate::quads::{pair_triangles, PairOptions, PairReport};
use crate::simplify::{
    simplify_with_features, FeatureLock, SimplifyError, SimplifyOptions, SimplifyReport,
};
use crate::snap::snap_to_features;
use crate::specks::Speck;
use crate::trim::{boundary_polylines, trim_unsupported, TrimError, TrimOptions, TrimReport};

/// Options of [`initial_control_mesh`].
#[derive(Clone, Debug, PartialEq)]
pub struct InitOptions {
    /// Simplification options; `target_vertices` is replaced by the requested vertex count.
    pub simplify: SimplifyOptions,
    /// Contouring options (point clouds only).
    pub contour: ContourOptions,
    /// Trimming the contour where no data supports it (point clouds only; see
    /// [`crate::trim`](mod@crate::trim)): an open cloud gives an open cage. Default: enabled.
    pub trim: TrimOptions,
    /// Genus the caller expects for a point cloud (compared in the report). When the IMLS
    /// contour has another genus, the space-carving fallback ([`crate::carve()`], which ignores
    /// the normals) is tried and used if it matches. Default `None`: the contour's genus is
    /// reported as the target's. Ignored for mesh targets (their genus is
    /// computed).
    pub expected_genus: Option<u32>,
    /// Boundary loops the caller knows a point cloud has (its mesh's, when a mesh is read as
    /// points). When it is more than 0 the cloud is known to be open, and the space-carving
    /// fallback of [`Self::expected_genus`] is not tried: a carved wrap is closed and lies its
    /// carving radius off the data everywhere, so it misses the boundary loops as well; an open
    /// trimmed contour with a spurious handle fits the data far better (the bunny's points at
    /// 4,667 control points: two-sided RMS 4.5e-4 of the diagonal, against 1.8e-3 from the
    /// wrap). Default `None`.
    pub expected_boundary_loops: Option<usize>,
    /// Fail with [`InitError::GenusMismatch`] when the result's genus differs from the target's.
    /// Default `false` (the mismatch is only reported).
    pub require_genus: bool,
    /// Point clouds: when the contour has fewer than this many vertices per requested control
    /// vertex and [`ContourOptions::resolution`] is automatic, the cloud is contoured again on a
    /// finer octree (the vertex count grows with the resolution squared; at most
    /// [`ContourOptions::max_resolution`]), so that the simplification has room to place the
    /// control vertices. Default 8.
    pub contour_vertices_per_control: f64,
    /// Pair the simplified triangle cage into a quad-dominant one
    /// ([`crate::quads::pair_triangles`], along the target's principal directions) for
    /// Catmull-Clark or quad/triangle fits. The vertices (control points) do not change.
    /// Default `false` (all triangles, for Loop).
    pub quad_dominant: bool,
    /// Options of the pairing (used with [`Self::quad_dominant`]).
    pub pairing: PairOptions,
    /// Build the cage from a cross field instead ([`crate::cross_field::quad_cage`]: edges
    /// along the field, irregular vertices at its singularities; all quads with
    /// [`QuadCageOptions::quads_only`]) when the target has no sharp features to keep as tags;
    /// on failure the simplified, paired cage is used and
    /// [`InitReport::cross_field_failure`] says why. Default `None`.
    pub cross_field: Option<QuadCageOptions>,
    /// With [`Self::quad_dominant`]: split every face of the paired cage into quads (an
    /// `n`-gon into `n`), the simplification taken at about a quarter of the count
    /// ([`QUARTER_SPLIT`]), so that the cage is all quads. Default `false`.
    pub split_into_quads: bool,
    /// With [`Self::quad_dominant`]: the paired (and split) cage's interior quad–quad edges
    /// rotated towards regular valence ([`crate::cross_field::rotate_for_valence`]), its
    /// creases and corners kept. Default `true`.
    pub rotate_edges: bool,
    /// Detect sharp features with these options and keep them as crease and corner tags of a
    /// feature-aligned cage: a mesh target's sharp edges, or (with [`Self::cloud_features`]) a
    /// point cloud's crease curves with the contour snapped to them
    /// ([`crate::snap`](mod@crate::snap)). Default `None` (no tags).
    pub features: Option<FeatureOptions>,
    /// With [`Self::features`]: give each crease a finite OpenSubdiv sharpness from the data's
    /// fillet width along its curve ([`crate::semi_sharp`]), instead of infinitely sharp.
    /// Default `false`.
    pub semi_sharp: bool,
    /// Point clouds: apply [`Self::features`] too (trace the cloud's crease curves and snap the
    /// contour to them). Default `false`: experimental — on a box and a capped cylinder sampled
    /// as clouds the fitted surfaces were not yet closer to the shapes than without it.
    pub cloud_features: bool,
    /// Point clouds found open (trimmed: a single-view scan): contour and simplify again for
    /// `round(open_cloud_scale · n)` control vertices (at most [`Self::max_control_points`])
    /// instead of the `n` asked, when this is above 1; the report's
    /// [`InitReport::open_cloud_control_points`] says so. `subfit fit`'s default start,
    /// `1.5 √points`, is calibrated on closed scans whose points cover the whole surface; a
    /// view covers about half of it, thinned at grazing angles, and the stages' refinement
    /// spends points less well than a simplification places them (a simulated 400 × 400 view
    /// of the armadillo, 23.5k points: from 230 the fit refined to 1,302 points and returned
    /// its 366-point cage, data → surface RMS 1.44e-3 of the diagonal; from 460, 734 points and
    /// 7.7e-4). Default 1 (off); `subfit fit` uses [`OPEN_CLOUD_SCALE`] for its default start.
    pub open_cloud_scale: f64,
    /// Point clouds found one-sided (trimming removed at least [`ONE_SIDED_TRIM`] of the
    /// contour's faces: a single view, whose contour closes behind the data): contour again
    /// with at least this many levels of refinement ([`ContourOptions::refine_levels`]), kept
    /// when still open;
    /// [`InitReport::one_sided_refined`] says so. On simulated single-view scans the band level
    /// alone blends surfaces that meet at grazing angles (the side and the sole of the
    /// armadillo's foot seen along −z: the fitted surface stayed 2 % of the diagonal from 25
    /// returns); one level more resolves them (see [`ONE_SIDED_REFINE`]). A closed cloud with
    /// holes (trimming removes less) keeps [`ContourOptions::refine_levels`]: on the Stanford
    /// bunny's points one level more closed a hole and doubled the Hausdorff distance.
    /// Default 0 (off); `subfit fit` uses [`ONE_SIDED_REFINE`] unless `--contour-refine` is
    /// given.
    pub one_sided_refine: usize,
    /// The most control points the cage may have after its concave corners are split
    /// ([`subfit_mesh::concave`]: a corner whose concave sector has no interior vertex gets one
    /// inserted); splits that would go beyond it are skipped. Default `usize::MAX`.
    pub max_control_points: usize,
    /// Cancellation token for every step (contouring, the carving fallback, simplification;
    /// it replaces the tokens in [`Self::contour`] and [`Self::simplify`]), polled per octree
    /// level and per batch of cells, evaluations and edge collapses; once cancelled,
    /// [`initial_control_mesh`] returns [`InitError::Interrupted`]. Default: a fresh token,
    /// never cancelled.
    pub cancel: Cancel,
}

impl Default for InitOptions {
    fn default() -> Self {
        Self {
            simplify: SimplifyOptions::default(),
            contour: ContourOptions::default(),
            trim: TrimOptions::default(),
            expected_genus: None,
            expected_boundary_loops: None,
            require_genus: false,
            contour_vertices_per_control: 8.0,
            quad_dominant: false,
            pairing: PairOptions::default(),
            cross_field: None,
            split_into_quads: false,
            rotate_edges: true,
            features: None,
            semi_sharp: false,
            cloud_features: false,
            open_cloud_scale: 1.0,
            one_sided_refine: 0,
            max_control_points: usize::MAX,
            cancel: Cancel::default(),
        }
    }
}

/// Vertices of a quad-dominant cage split into quads per vertex of the cage: `V + E + F`,
/// about 4.4 `V` on the paired QEM cages of the test models (a few triangles and a boundary
/// make it more than 4).
pub const QUARTER_SPLIT: f64 = 4.4;

/// The scale of the default start for a point cloud found open
/// ([`InitOptions::open_cloud_scale`]). Measured on simulated single-view scans (`hard_cases
/// range-scan`, 400 × 400, noise 2e-4; `subfit fit` from 1, 2 and 3 times the default start,
/// then `subfit compare` with the true mesh): with 2, the surface → true-mesh RMS fell on all
/// six views of the bunny (by 16–33 %), on the fertility view (4.0e-4 → 2.1e-4) and on four of
/// five views of the armadillo (1.45e-3 → 9.4e-4, 1.05e-3 → 7.8e-4, 8.6e-4 → 7.9e-4,
/// 2.13e-3 → 1.40e-3; the fifth 1.04e-3 → 1.16e-3). 3 was better still on the bunny but
/// not on the armadillo's views. `fit_scan` does not scale a cloud whose noise is half the
/// scan's RMS tolerance or more (the extra points would fit the noise).
pub const OPEN_CLOUD_SCALE: f64 = 2.0;

/// The contour refinement `subfit fit` uses for one-sided clouds
/// ([`InitOptions::one_sided_refine`]). Measured on simulated single-view scans (`hard_cases
/// range-scan`, 400 × 400, noise 2e-4; `subfit fit` defaults with `--contour-refine` 0 and 1;
/// fractions of the scan's diagonal, scan → surface max and surface → true-mesh RMS): six
/// views of the armadillo 1.04/0.74/0.67/0.73/0.55/2.04 % and 0.98/0.78/1.01/0.93/0.71/1.08e-3
/// → 0.94/0.70/0.81/0.58/0.43/0.66 % and 0.73/0.68/0.69/0.73/0.63/0.76e-3; six of the bunny
/// 4.4/4.5/6.8/6.3/5.5/4.0e-4 → 4.7/4.3/5.9/5.5/4.6/4.0e-4 (all below 1 % before and after);
/// the fertility view 2.1e-4 → 2.0e-4; `bun000_points.ply` 1,001 → 651 control points at the
/// same two-sided RMS (5.2e-4 → 5.3e-4 of the diagonal).
pub const ONE_SIDED_REFINE: usize = 1;

/// The fraction of a cloud's closed contour that trimming must remove for the cloud to count
/// as one-sided ([`InitOptions::one_sided_refine`]): simulated single views of the bunny, the
/// armadillo and the fertility statue and `bun000_points.ply` lose 60–70 % of it, a dome 48 %;
/// a sphere missing a cap of a tenth of its area less than 40 % (the test), the Stanford
/// bunny's points (a closed scan with holes) 1 %.
pub const ONE_SIDED_TRIM: f64 = 0.4;

/// The default control-vertex count for a target of `target_points` points:
/// `clamp(round(1.5·√points), 200, 2000)` — 550 for Igea's 134k points (Cheng et al. 2007
/// Tab. IV start from 526), 300 for the rocker arm's 40k. The same rule as `subfit fit`'s
/// default. Cost `O(1)`.
pub fn default_control_points(target_points: usize) -> usize {
    ((1.5 * (target_points as f64).sqrt()).round() as usize).clamp(200, 2000)
}

/// Fewest vertices of a triangulated surface of genus `genus` with `boundary_loops` boundary
/// loops (one component). Closed: Heawood's bound `⌈(7 + √(1 + 48g)) / 2⌉` (4 for a sphere,
/// 7 for a torus, 11 for genus 4), attained by minimal triangulations for every `g` but 2 (10;
/// Jungerman & Ringel 1980); with
/// boundary: at least 3 per loop, and Heawood's bound when `g > 0`. A necessary condition
/// only: simplification usually stops well above it (see
/// [`SimplifyReport::reached_target`]). Cost `O(1)`.
pub fn min_vertices_for_topology(genus: u32, boundary_loops: usize) -> usize {
    let heawood = ((7.0 + (1.0 + 48.0 * f64::from(genus)).sqrt()) / 2.0 - 1e-9).ceil() as usize;
    // Jungerman & Ringel 1980: the bound is attained for every orientable genus but 2.
    let heawood = if genus == 2 { 10 } else { heawood };
    match boundary_loops {
        0 => heawood.max(4),
        b if genus == 0 => (3 * b).max(3),
        b => (3 * b).max(heawood),
    }
}

/// Where the initial mesh came from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum InitSource {
    /// Simplification of the target's own mesh.
    #[default]
    Mesh,
    /// Contour of the point cloud's implicit function, then simplification.
    Contour,
}

/// Wall-clock times of the steps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct InitTimings {
    /// Contouring (zero for mesh targets).
    pub contour: Duration,
    /// Simplification.
    pub simplify: Duration,
    /// Pairing triangles into quads (zero unless [`InitOptions::quad_dominant`]).
    pub pair: Duration,
    /// Everything, including validation.
    pub total: Duration,
}

/// What [`initial_control_mesh`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InitReport {
    /// Mesh or point-cloud path.
    pub source: InitSource,
    /// Genus of the target: the input mesh's, the caller's expectation, or (point clouds without
    /// an expectation) the contour's.
    pub genus_target: u32,
    /// Genus of the simplified mesh before simplification (input mesh or contour).
    pub genus_before: u32,
    /// Genus of the result.
    pub genus_after: u32,
    /// Boundary loops before and after simplification (for a point cloud, "before" is the
    /// trimmed contour's: the loops found in the cloud).
    pub boundary_loops: (usize, usize),
    /// Connected components of the result.
    pub components: usize,
    /// Whether the result's genus equals `genus_target`.
    pub genus_matches: bool,
    /// Whether the result has no boundary.
    pub closed: bool,
    /// Simplification details (vertex counts before/after, rejections, error).
    pub simplify: SimplifyReport,
    /// Contouring details (point clouds only).
    pub contour: Option<ContourReport>,
    /// Point clouds: the trimming of the contour where no data supports it
    /// ([`crate::trim`](mod@crate::trim)); `trim.open` tells whether the cloud was found open,
    /// `trim.faces_trimmed` how many contour faces were cut, `trim.boundary_loops` how many
    /// boundary loops the trimmed contour has. `None` for mesh targets.
    pub trim: Option<TrimReport>,
    /// Point clouds: the boundary loops of the trimmed contour as closed polylines (normalized
    /// units, last point not repeated, faces on the left; see
    /// [`crate::trim::boundary_polylines`]), for fitting boundary curves. Empty for a closed
    /// cloud and for mesh targets.
    pub boundary_curves: Vec<Vec<[f64; 3]>>,
    /// Point clouds: the carving radius (normalized units) when the IMLS contour missed
    /// [`InitOptions::expected_genus`] and the space-carving fallback ([`crate::carve()`]) was
    /// used; `None` otherwise.
    pub carve_radius: Option<f64>,
    /// The pairing into quads, with [`InitOptions::quad_dominant`].
    pub pairing: Option<PairReport>,
    /// The cross-field cage, with [`InitOptions::cross_field`] when it was built.
    pub cross_field: Option<QuadCageReport>,
    /// Why [`InitOptions::cross_field`] was asked but the simplified cage used.
    pub cross_field_failure: Option<String>,
    /// Crease and corner tags of the result (infinitely sharp; empty without
    /// [`InitOptions::features`] or when none were found).
    pub tags: Tags,
    /// The sharp features detected on a mesh target with [`InitOptions::features`].
    pub features: Option<FeatureCounts>,
    /// Concave corners split by a crease into their sector so the limit surface does not fold
    /// there ([`subfit_mesh::concave`]; mesh targets); zero without tags.
    pub concave: ConcaveSplits,
    /// The sharp feature edges the cage was built along, as segments (normalized units): what
    /// the creases of the fitted surface should follow (`subfit_fit::FitOptions::feature_segments`).
    /// Empty without features.
    pub feature_segments: Vec<[[f64; 3]; 2]>,
    /// With [`InitOptions::semi_sharp`]: the fillet width of each feature curve (normalized
    /// units; 0 for a sharp crease, `None` where it could not be measured). Empty otherwise.
    pub fillet_widths: Vec<Option<f64>>,
    /// Step times.
    pub timings: InitTimings,
    /// Point clouds found open with [`InitOptions::open_cloud_scale`] above 1: the control
    /// vertices contoured and simplified for instead of the requested count. `None`
    /// otherwise.
    pub open_cloud_control_points: Option<usize>,
    /// Whether a one-sided cloud was contoured again with [`InitOptions::one_sided_refine`]
    /// levels of refinement.
    pub one_sided_refined: bool,
    /// Specks added to an open clean cloud's cage for lone returns no piece of its trimmed
    /// surface reaches ([`crate::specks`]), within [`InitOptions::max_control_points`].
    pub specks: usize,
}

/// How many sharp features of each kind a mesh target has ([`InitReport::features`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FeatureCounts {
    /// Sharp edges of the target.
    pub edges: usize,
    /// Feature curves.
    pub curves: usize,
    /// Corners.
    pub corners: usize,
    /// Darts (curve ends in smooth regions).
    pub darts: usize,
}

impl InitReport {
    /// Whether the target is a point cloud whose contour was trimmed, i.e. found open (see
    /// [`crate::trim`](mod@crate::trim)). `false` for mesh targets and closed clouds.
    pub fn cloud_open(&self) -> bool {
        self.trim.as_ref().is_some_and(|t| t.open)
    }
}

/// Why [`initial_control_mesh`] failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum InitError {
    /// `n_vertices` is below 4 (no closed triangle mesh has fewer).
    #[error("at least 4 control vertices are needed, {0} requested")]
    TooFewVertices(usize),
    /// The mesh target is not an oriented 2-manifold (the error names the edge, vertex or
    /// face); its points can still be contoured (pass `mesh = None`).
    #[error("the target mesh is not an oriented manifold: {0}")]
    InvalidMesh(TopologyError),
    /// A mesh target's vertex has a NaN or infinite coordinate.
    #[error("target mesh vertex {0} has a non-finite coordinate")]
    NonFinite(usize),
    /// The requested vertex count is below what the topology allows
    /// ([`min_vertices_for_topology`], summed over the components).
    #[error(
        "{requested} control vertices requested, but a surface with {components} component(s), \
         genus {genus} and {boundary_loops} boundary loop(s) needs at least {minimum}"
    )]
    TooFewForTopology {
        /// The requested count.
        requested: usize,
        /// The smallest possible count.
        minimum: usize,
        /// Total genus of the surface to simplify.
        genus: u32,
        /// Its boundary loops.
        boundary_loops: usize,
        /// Its connected components.
        components: usize,
    },
    /// The mesh target cannot be simplified.
    #[error("simplification failed: {0}")]
    Simplify(SimplifyError),
    /// The point cloud cannot be contoured.
    #[error("contouring failed: {0}")]
    Contour(ContourError),
    /// The contour cannot be trimmed (an invalid [`InitOptions::trim`]).
    #[error("trimming the contour failed: {0}")]
    Trim(#[from] TrimError),
    /// The result is not manifold (an internal error).
    #[error("internal error: the initial mesh is not manifold: {0}")]
    Topology(#[from] TopologyError),
    /// The genus differs and [`InitOptions::require_genus`] is set.
    #[error("the initial mesh has genus {got}, the target {expected}")]
    GenusMismatch {
        /// The target's genus.
        expected: u32,
        /// The result's genus.
        got: u32,
    },
    /// [`InitOptions::cancel`] was cancelled (in any step).
    #[error("interrupted")]
    Interrupted,
}

impl From<SimplifyError> for InitError {
    fn from(e: SimplifyError) -> Self {
        match e {
            SimplifyError::Interrupted => InitError::Interrupted,
            e => InitError::Simplify(e),
        }
    }
}

impl From<ContourError> for InitError {
    fn from(e: ContourError) -> Self {
        match e {
            ContourError::Interrupted => InitError::Interrupted,
            e => InitError::Contour(e),
        }
    }
}

impl From<Cancelled> for InitError {
    fn from(_: Cancelled) -> Self {
        InitError::Interrupted
    }
}

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
    let mut specks = Vec::new();
    let mut dense = match mesh {
        Some(m) if !m.faces.is_empty() => {
            report.source = InitSource::Mesh;
            normalized_mesh(target, m)?
        }
        _ => {
            report.source = InitSource::Contour;
            let t = Instant::now();
            let (m, found) = cloud_surface(target, n_vertices, options, &mut report)?;
            specks = found;
            report.timings.contour = t.elapsed();
            m
        }
    };
    let n_vertices = report.open_cloud_control_points.unwrap_or(n_vertices);
    let before = HalfEdgeMesh::from_mesh(&dense).map_err(|e| match (report.source, mesh) {
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

    let t = Instant::now();
    let sopt = SimplifyOptions {
        target_vertices: n_vertices,
        cancel: options.cancel.clone(),
        ..options.simplify.clone()
    };
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
            cloud_feature_lock(target, &mut dense, fo, &mut report)
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
    if let Some(qo) = options
        .cross_field
        .as_ref()
        .filter(|_| lock.edges.is_empty())
    {
        let qo = QuadCageOptions {
            cancel: options.cancel.clone(),
            ..qo.clone()
        };
        match quad_cage(target, &dense, n_vertices, &qo) {
            Ok((cage, qrep)) => {
                report.timings.simplify = t.elapsed();
                report.cross_field = Some(qrep);
                return finish(cage, report, loops_before, t0, options);
            }
            Err(QuadCageError::Interrupted) => return Err(InitError::Interrupted),
            Err(e) => report.cross_field_failure = Some(e.to_string()),
        }
    } else if options.cross_field.is_some() {
        report.cross_field_failure =
            Some("the target's sharp features are kept as tags by the simplified cage".into());
    }
    // All quads asked but the field's cage not taken: the paired cage of about a quarter of
    // the count, each face split into quads (V + E + F ≈ 4.4 V for a quad-dominant cage).
    let split = options.split_into_quads && options.quad_dominant;
    let sopt = if split {
        SimplifyOptions {
            target_vertices: ((n_vertices as f64 / QUARTER_SPLIT).round() as usize).max(4),
            ..sopt
        }
    } else {
        sopt
    };
    let (mut out, mut tags, srep) = simplify_with_features(&dense, &lock, &sopt)?;
    if let (true, Some(f)) = (options.semi_sharp, &features) {
        report.fillet_widths = fillet_widths(&dense.positions, &dense.faces, f);
        tags = semi_sharp_tags(&out, &tags, &dense, f, &report.fillet_widths);
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
    report.timings.simplify = t.elapsed();
    report.simplify = srep;
    report.tags = tags;
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
    finish(out, report, loops_before, t0, options)
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
