//! The judge's inputs, options, results and errors (plain serde structs; see [`super`] for how
//! the figures are measured).

use serde::{Deserialize, Serialize};
use subfit::mesh::{PolyMesh, Tags};
use subfit::subdiv::{BoundaryRule, EvalError, Scheme};

/// What a result is measured against: the input scan, in its own units.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Reference {
    /// A triangle mesh. `positions` is `#V by 3`, `triangles` `#T by 3` (indices into
    /// `positions`, any winding). Vertices no triangle uses are not measured (but must be
    /// finite).
    Mesh {
        /// Vertex positions, `#V by 3`.
        positions: Vec<[f64; 3]>,
        /// Triangles, `#T by 3`.
        triangles: Vec<[u32; 3]>,
    },
    /// A point cloud, `#P by 3`; the judge builds its local surface (discs, see [`super`]).
    Points {
        /// Point positions, `#P by 3`.
        positions: Vec<[f64; 3]>,
    },
}

impl Reference {
    /// The reference of a mesh as read from a file: its polygons fan-triangulated
    /// ([`subfit::mesh::Polygons::triangulate_fan`]), or its points when it has no faces.
    /// Nothing is checked here; [`super::judge`] validates.
    pub fn from_polymesh(mesh: &PolyMesh) -> Self {
        if mesh.faces.is_empty() {
            Self::Points {
                positions: mesh.positions.clone(),
            }
        } else {
            Self::Mesh {
                positions: mesh.positions.clone(),
                triangles: mesh.faces.triangulate_fan(),
            }
        }
    }

    /// All positions (used by triangles or not).
    pub fn positions(&self) -> &[[f64; 3]] {
        match self {
            Self::Mesh { positions, .. } | Self::Points { positions } => positions,
        }
    }
}

/// What is judged, in the reference's units.
#[derive(Clone, Debug, PartialEq)]
pub enum Candidate {
    /// A subdivision cage: its exact limit surface is judged.
    Limit {
        /// Control points and faces (as `subfit fit` writes `control.obj`).
        cage: PolyMesh,
        /// Crease and corner tags.
        tags: Tags,
        /// The subdivision scheme.
        scheme: Scheme,
        /// The boundary interpolation rule (subfit fits with [`BoundaryRule::EdgeOnly`]).
        boundary: BoundaryRule,
    },
    /// A triangle mesh (a peer's result, e.g. Poisson + QEM): judged as it is, flat.
    Mesh {
        /// Vertex positions, `#V by 3`.
        positions: Vec<[f64; 3]>,
        /// Triangles, `#T by 3`.
        triangles: Vec<[u32; 3]>,
    },
}

impl Candidate {
    /// The limit surface of `cage` under `scheme` with the default boundary rule
    /// ([`BoundaryRule::EdgeOnly`], the one `subfit fit` uses).
    pub fn limit(cage: PolyMesh, tags: Tags, scheme: Scheme) -> Self {
        Self::Limit {
            cage,
            tags,
            scheme,
            boundary: BoundaryRule::EdgeOnly,
        }
    }

    /// A polygon mesh judged flat: its polygons fan-triangulated. Nothing is checked here.
    pub fn mesh_from_polymesh(mesh: &PolyMesh) -> Self {
        Self::Mesh {
            positions: mesh.positions.clone(),
            triangles: mesh.faces.triangulate_fan(),
        }
    }
}

/// How much the judge samples. Every count is a count of points or triangles; the figures do
/// not depend on the thread count, only on these and the seed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct JudgeOptions {
    /// Area-uniform samples of a mesh candidate's triangles measured against the reference
    /// (surface → data). Default 200,000; at least 1. A limit surface is measured at every
    /// vertex of the judge's tessellation instead (exact limit points, weighted by area).
    pub surface_samples: usize,
    /// Area-uniform samples of a mesh reference's triangles added to its vertices (data →
    /// surface). Default 100,000; 0 measures the vertices only. Unused for point references.
    pub data_samples: usize,
    /// Triangles of the limit tessellation the judge builds: the deepest uniform refinement
    /// level with at most 1.5 times this many is taken (so 0.375–1.5 times it). Default
    /// 1,000,000 (about half as many limit points; about 450 bytes per triangle at the peak,
    /// so under 700 MB); at least 1.
    pub tessellation_triangles: usize,
    /// Data points whose distance to a limit surface is polished exactly (Newton steps on the
    /// exact evaluator): the farthest ones by the tessellation's distance, which set the
    /// maximum. Default 1,000; 0 keeps every tessellation distance (each within
    /// [`Judgement::tessellation_deviation`] of exact).
    pub polished_points: usize,
    /// Seed of every random choice. Default 1.
    pub seed: u64,
    /// Worker threads; `None` (default) uses the current rayon pool. Results do not depend on
    /// it.
    pub threads: Option<usize>,
}

impl Default for JudgeOptions {
    fn default() -> Self {
        Self {
            surface_samples: 200_000,
            data_samples: 100_000,
            tessellation_triangles: 1_000_000,
            polished_points: 1_000,
            seed: 1,
            threads: None,
        }
    }
}

/// Distances measured one way, in the reference's units.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Direction {
    /// Root mean square.
    pub rms: f64,
    /// Mean.
    pub mean: f64,
    /// Largest.
    pub max: f64,
    /// 95th percentile (nearest rank).
    pub p95: f64,
    /// Number of distances.
    pub samples: usize,
}

/// The judge's verdict on one candidate; lengths in the reference's units.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Judgement {
    /// Reference points (vertices and area samples, or the cloud's points) to the candidate.
    pub data_to_surface: Direction,
    /// The candidate to the reference: every limit point of the judge's tessellation weighted
    /// by the area it stands for, or area-uniform samples of a mesh candidate.
    pub surface_to_data: Direction,
    /// Two-sided RMS: the worse RMS of the two directions (subfit's convention).
    pub rms: f64,
    /// Two-sided maximum: the worse maximum of the two directions (Hausdorff distance of the
    /// sample sets).
    pub hausdorff: f64,
    /// Bounding-box diagonal of the reference (points used by its triangles, or all points).
    pub diagonal: f64,
    /// `rms / diagonal`.
    pub rms_fraction: f64,
    /// `hausdorff / diagonal`.
    pub hausdorff_fraction: f64,
    /// How far the judge's limit tessellation may lie from the exact limit surface: a bound on
    /// the distance between a flat point and the exact surface point of the same parameter,
    /// measured one refinement level coarser (see [`super`]), so conservative; 0 for a mesh
    /// candidate. Data → surface distances are within this of exact, and exact for the
    /// polished points where the polish came to rest inside a patch.
    pub tessellation_deviation: f64,
    /// Triangles of the judge's limit tessellation (0 for a mesh candidate).
    pub tessellation_triangles: usize,
    /// Data points whose distance was polished on the exact limit surface (0 for a mesh
    /// candidate).
    pub polished_points: usize,
    /// For a point reference: the radius of the discs its local surface is made of (the median
    /// distance of a point to its 12th nearest neighbour); `None` for a mesh reference.
    pub point_spacing: Option<f64>,
    /// Points of a cloud reference left out of data → surface as isolated returns (farther from
    /// their 12th neighbour than ten times the median of that distance); 0 for a mesh.
    #[serde(default)]
    pub isolated_points: usize,
    /// Wall-clock seconds the judgement took (informative only).
    pub seconds: f64,
}

/// Why a judgement could not be made. Nothing is measured when one is returned.
#[derive(Debug, thiserror::Error)]
pub enum JudgeError {
    /// The reference or the candidate has nothing to measure.
    #[error("{what} is empty: {reason}")]
    Empty {
        /// Which input.
        what: &'static str,
        /// What is missing.
        reason: &'static str,
    },
    /// A coordinate is NaN or infinite.
    #[error("{what} {index} has a non-finite coordinate {position:?}")]
    NonFinite {
        /// Which input ("reference point", "cage vertex", …).
        what: &'static str,
        /// The vertex or point.
        index: usize,
        /// Its coordinates.
        position: [f64; 3],
    },
    /// A face refers to a vertex that does not exist.
    #[error("{what} {face} refers to vertex {vertex}, but there are only {count} vertices")]
    BadIndex {
        /// Which input ("reference triangle", "cage face", …).
        what: &'static str,
        /// The face.
        face: usize,
        /// The vertex id.
        vertex: u32,
        /// Number of vertices.
        count: usize,
    },
    /// All of the reference's points coincide: distances have no scale to be read against.
    #[error("the reference's bounding box has no extent (all its points coincide)")]
    Degenerate,
    /// A point reference with too few points to estimate a local surface.
    #[error("a point reference needs at least {needed} points to estimate normals, got {got}")]
    TooFewPoints {
        /// The minimum.
        needed: usize,
        /// Points given.
        got: usize,
    },
    /// An option outside its range.
    #[error("option {name} is {value}; {reason}")]
    BadOption {
        /// The option.
        name: &'static str,
        /// Its value.
        value: usize,
        /// What it must be.
        reason: &'static str,
    },
    /// The cage is not a valid control mesh for its scheme, or its limit could not be
    /// evaluated.
    #[error("the candidate cage: {0}")]
    Cage(#[from] EvalError),
    /// The kd-tree over the reference's points could not be built.
    #[error("the kd-tree over the reference's points: {0}")]
    KdTree(String),
    /// The worker thread pool could not be started.
    #[error("starting {threads} judge threads: {reason}")]
    Threads {
        /// Threads asked for.
        threads: usize,
        /// Why it failed.
        reason: String,
    },
}
