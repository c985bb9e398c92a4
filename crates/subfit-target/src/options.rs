//! Options, statistics and progress reporting of target construction.

use std::time::Duration;

use subfit_mesh::Cancel;

pub use crate::estimate::Neighborhood;

/// Where the target's normals come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NormalSource {
    /// Input normals when given (zero-length ones estimated and oriented from their
    /// neighbours), else area-weighted face normals for meshes, else estimated from the points
    /// (PCA + quadric, oriented by MST propagation).
    #[default]
    Auto,
    /// Always estimate from the points (input normals and faces are ignored for normals).
    Estimate,
}

/// Options of [`crate::Target`] construction. All lengths are in normalized units (the target
/// scaled into the unit cube).
#[derive(Clone, Debug, PartialEq)]
pub struct TargetOptions {
    /// Neighbourhood for normals and curvature. Default `Knn(24)`; `Knn(k)` needs `k ≥ 10`,
    /// `Radius(r)` needs a finite `r > 0` (at least the 10 nearest are always used).
    pub neighborhood: Neighborhood,
    /// Degree of the local polynomial (jet) fitted per point: 2 (quadric, as Cheng 2004 §4.1)
    /// or 3 (cubic terms too: normals and curvatures one order more accurate on clean data).
    /// Default 3.
    pub jet_degree: u8,
    /// Normal source. Default [`NormalSource::Auto`].
    pub normals: NormalSource,
    /// Neighbours per point in the orientation graph. Default 10, valid `1..=neighbourhood`.
    pub orientation_k: usize,
    /// Extra cost `τ` on orientation-graph edges leaving the tangent plane (see
    /// [`crate::orient`]); 0 is Hoppe's plain `1 − |n_i·n_j|`. Default 1.0, valid `≥ 0`.
    pub orientation_tangent_penalty: f64,
    /// A point's normal is counted ambiguous when the smallest two covariance eigenvalues of its
    /// neighbourhood satisfy `λ0 ≥ ratio · λ1`. Default 0.5, valid `(0, 1]`.
    pub ambiguity_ratio: f64,
    /// Support radius `h` of the IMLS kernel (normalized units). Default `None`: twice the median
    /// neighbourhood radius. Valid: finite, `> 0`.
    pub imls_radius: Option<f64>,
    /// Build the triangle BVH for exact closest points when the input has faces. Default true.
    pub mesh_closest_point: bool,
    /// Recognise a mesh that is a CAD tessellation ([`crate::tessellation`]): its noise level
    /// is then 0 (the vertex spacing is the exporter's, not noise) and its foot points come from
    /// the facets ([`crate::Target::mesh_foot_point`]). Default true.
    pub recognise_tessellation: bool,
    /// Drop outliers of point clouds before estimation: points whose 16th neighbour is more
    /// than 4× the median distance away, or whose distance to the plane of their neighbours is
    /// more than 3× the largest of the neighbours' spread, the noise level and a quarter of that
    /// median distance (see `outliers` in the crate source). Inputs with faces keep every vertex.
    /// Removed points are counted in [`TargetStats::outliers_removed`]; their input indices map
    /// to the nearest kept point. Default true.
    pub remove_outliers: bool,
    /// Widen a `Knn(k)` neighbourhood on noisy scans: when the estimated noise level
    /// ([`TargetStats::noise_level`]) exceeds 0.1 × the point spacing
    /// ([`TargetStats::point_spacing`]), `k` is raised (up to 96) so that the neighbourhood
    /// radius is about 8 noise levels, and the smaller neighbourhood otherwise tried where the
    /// full one is not surface-like is not (in noise it fits the noise); clean scans keep `k`.
    /// The `k` used is [`TargetStats::neighborhood_k`]. Default true.
    pub adapt_to_noise: bool,
    /// The map into normalized units. Default `None`: the input's bounding box scaled into the
    /// unit cube (Cheng 2004 §3 step 1). A sequence gives every frame the first frame's map, so
    /// that one cage moves between frames in one set of units.
    pub normalization: Option<crate::Normalization>,
    /// Cancellation token, polled by every long step of construction (per chunk of the
    /// per-point fits, per pass of the orientation and its winding-number and field checks);
    /// once cancelled, construction returns [`crate::TargetError::Interrupted`] within a few
    /// tens of milliseconds of work per thread. Default: a fresh token, never cancelled.
    pub cancel: Cancel,
}

impl Default for TargetOptions {
    fn default() -> Self {
        Self {
            neighborhood: Neighborhood::default(),
            jet_degree: 3,
            normals: NormalSource::Auto,
            orientation_k: 10,
            orientation_tangent_penalty: 1.0,
            ambiguity_ratio: 0.5,
            imls_radius: None,
            mesh_closest_point: true,
            recognise_tessellation: true,
            remove_outliers: true,
            adapt_to_noise: true,
            normalization: None,
            cancel: Cancel::default(),
        }
    }
}

/// Where the final normals came from (reported in [`TargetStats`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NormalOrigin {
    /// All from input normals.
    Input,
    /// All from area-weighted face normals.
    Faces,
    /// All estimated (PCA + quadric) and MST-oriented.
    #[default]
    Estimated,
    /// Input or face normals, with some zero-length ones estimated.
    Mixed,
}

/// Phases of construction, as reported to the progress callback and timed in [`TargetStats`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Phase {
    /// Finite-ness, counts, indices.
    Validate,
    /// Scaling into the unit cube.
    Normalize,
    /// Merging exact duplicates.
    Merge,
    /// kd-tree construction.
    Index,
    /// Outlier detection and noise estimation (and the kd-tree rebuilt without the outliers).
    Outliers,
    /// Per-point PCA frame and quadric fit (normals, curvatures).
    Estimate,
    /// Normal orientation.
    Orient,
    /// Triangle BVH for mesh targets.
    MeshIndex,
}

/// A progress report: `done` of `total` units of `phase` (units are points, or 1 for phases
/// without a natural count). Sent at the start (`done = 0`) and end (`done = total`) of every
/// phase, and in between for [`Phase::Estimate`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// The current phase.
    pub phase: Phase,
    /// Units done.
    pub done: usize,
    /// Units in the phase.
    pub total: usize,
}

/// Progress callback: called from the constructing thread, never concurrently.
pub type ProgressFn<'a> = &'a (dyn Fn(Progress) + Sync);

/// Wall-clock duration of each construction phase.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TargetTimings {
    /// [`Phase::Validate`].
    pub validate: Duration,
    /// [`Phase::Normalize`].
    pub normalize: Duration,
    /// [`Phase::Merge`].
    pub merge: Duration,
    /// [`Phase::Index`].
    pub index: Duration,
    /// [`Phase::Outliers`].
    pub outliers: Duration,
    /// [`Phase::Estimate`].
    pub estimate: Duration,
    /// [`Phase::Orient`] (all of it: the steps below and the query layout).
    pub orient: Duration,
    /// Orientation: spanning tree, propagation and consensus.
    pub orient_propagate: Duration,
    /// Orientation: the global winding-number check.
    pub orient_winding: Duration,
    /// Orientation: the winding-field refinement (capped, see
    /// [`TargetStats::field_iterations`]).
    pub orient_field: Duration,
    /// [`Phase::MeshIndex`].
    pub mesh_index: Duration,
    /// Whole construction.
    pub total: Duration,
}

/// Counts and timings of one target construction (for `subfit analyze`, reports and benches).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TargetStats {
    /// Points in the input.
    pub input_points: usize,
    /// Distinct points kept.
    pub points: usize,
    /// Input points merged into an identical earlier point.
    pub merged_duplicates: usize,
    /// Outliers dropped (distinct points; see [`TargetOptions::remove_outliers`]).
    pub outliers_removed: usize,
    /// Estimated noise level: `1.4826 ×` the median distance of a point to the least-squares
    /// plane of its 16 nearest neighbours (itself left out), over the kept points (normalized
    /// units). About the standard deviation of the noise along the normal on noisy scans; the
    /// curvature sag of a neighbourhood on clean ones.
    pub noise_level: f64,
    /// Median distance of a point to its 16th nearest neighbour (normalized units), the scale
    /// the outlier tests and [`Self::noise_level`] are compared with.
    pub point_spacing: f64,
    /// `k` of the `Knn` neighbourhood used for the fits (after [`TargetOptions::adapt_to_noise`];
    /// 0 for a `Radius` neighbourhood).
    pub neighborhood_k: usize,
    /// Triangles in the mesh BVH (0 for point clouds).
    pub triangles: usize,
    /// Where the normals came from.
    pub normal_origin: NormalOrigin,
    /// Estimated normals negated by orientation (relative to the arbitrary PCA sign, or to agree
    /// with neighbouring input/face normals).
    pub flipped_normals: usize,
    /// Input normals only: the fraction of clearly (anti)parallel neighbour pairs whose input
    /// normals point opposite ways ([`crate::consistency`]; 0 for other normal origins).
    pub opposed_input_normals: f64,
    /// Whether the input normals were found inconsistently oriented (`opposed_input_normals`
    /// above [`crate::consistency::MAX_OPPOSED_FRACTION`]) and re-oriented: their directions
    /// kept, their signs chosen by [`crate::orient`].
    pub reoriented_input_normals: bool,
    /// Points whose smallest two covariance eigenvalues are nearly equal (see
    /// [`TargetOptions::ambiguity_ratio`]): normal direction unreliable.
    pub ambiguous_normals: usize,
    /// Points whose quadric fit was damped or reduced to a plane (degenerate neighbourhood).
    pub degenerate_fits: usize,
    /// Flips made by the global winding-number check of the orientation (see
    /// [`crate::orient`]; included in the net effect counted by `flipped_normals`).
    pub winding_flips: usize,
    /// Points whose quadric disagrees with its neighbours' (creases, scanner debris): foot
    /// points next to them are blended over the neighbouring quadrics (see
    /// [`crate::Target::foot_point`]).
    pub untrusted_quadrics: usize,
    /// Points failing the winding-field check of the orientation (field `w` outside `[0, 1]`
    /// or normal more than 60° from `−∇w`; see the `regularize` step of [`crate::orient`]).
    /// 0: the field refinement was skipped.
    pub field_suspicious: usize,
    /// Iterations of the field refinement (0 when skipped; capped, and bounded by a budget of
    /// point evaluations proportional to `#P`).
    pub field_iterations: usize,
    /// Sign changes made by the field refinement (included in the net `flipped_normals`).
    pub field_flips: usize,
    /// Normals whose direction the field refinement replaced (more than 30° from the local
    /// estimate); their quadrics are refitted in the new frame.
    pub field_redirected: usize,
    /// Connected components of the orientation graph (0 when no orientation was needed).
    pub orientation_components: usize,
    /// Smallest, mean and largest neighbourhood size (points, the point itself included).
    pub neighborhood_size: (usize, f64, usize),
    /// Smallest, median and largest neighbourhood radius (normalized units).
    pub neighborhood_radius: (f64, f64, f64),
    /// IMLS kernel support radius `h` in use (normalized units).
    pub imls_radius: f64,
    /// What the facets of a mesh target say ([`crate::tessellation`]); `None` for a point
    /// cloud.
    pub tessellation: Option<crate::tessellation::TessellationStats>,
    /// Phase durations.
    pub timings: TargetTimings,
}

impl TargetStats {
    /// Whether the scan is noisy: its [`Self::noise_level`] above 0.3 × [`Self::point_spacing`],
    /// the rule that also widens the fits' neighbourhoods (clean scans measure below 0.25,
    /// 0.3 % noise about 0.4). Always `false` for a mesh target or an empty cloud.
    pub fn is_noisy(&self) -> bool {
        self.triangles == 0 && crate::outliers::is_noisy(self.noise_level, self.point_spacing)
    }
}
