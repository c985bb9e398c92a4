//! The options, report and errors of [`initial_control_mesh`](crate::initial_control_mesh)
//! (DESIGN.md §3.6), with the defaults and the topology bound it checks. Re-exported from
//! [`crate::init`](mod@crate::init), whose functions build the cage.

use std::time::Duration;

use subfit_mesh::{Cancel, Cancelled, ConcaveSplits, Tags, TopologyError};
use subfit_target::FeatureOptions;

use crate::contour::{ContourError, ContourOptions, ContourReport};
use crate::cross_field::{QuadCageOptions, QuadCageReport};
use crate::quads::{PairOptions, PairReport};
use crate::simplify::{SimplifyError, SimplifyOptions, SimplifyReport};
use crate::trim::{TrimError, TrimOptions, TrimReport};

/// Options of [`initial_control_mesh`](crate::initial_control_mesh).
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
    /// [`initial_control_mesh`](crate::initial_control_mesh) returns [`InitError::Interrupted`]. Default: a fresh token,
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

/// What [`initial_control_mesh`](crate::initial_control_mesh) did.
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

/// Why [`initial_control_mesh`](crate::initial_control_mesh) failed.
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
