//! Quad cages with edge flow: a cross field over the surface, a lattice of quads aligned with
//! it, and the cage read off the lattice (Jakob, Tarini, Panozzo & Sorkine-Hornung, "Instant
//! field-aligned meshes", SIGGRAPH Asia 2015; Bommes et al., "Quad-mesh generation and
//! processing: a survey", CGF 2013, §4 for why a field: the cage's edges then follow the
//! principal directions and feature lines, and its irregular vertices sit where the field has
//! its singularities, which the shape decides).
//!
//! [`quad_cage`] reads as its steps:
//!
//! 1. **Working mesh**: the target's mesh (or a point cloud's contour), simplified to about
//!    [`QuadCageOptions::working_per_vertex`] vertices per lattice vertex, or split 1 → 4
//!    while coarser than half that (a coarse CAD export), so that every lattice cell holds a
//!    few mesh vertices; the cost is then bounded by the cage's size, not the scan's. Holes
//!    shorter than [`SMALL_HOLE`] spacings are capped, and reopened in the cage as the face
//!    nearest each cap.
//! 2. **Orientation field** (`field.rs`): smooth extrinsic 4-RoSy on a multiresolution
//!    hierarchy, held along creases (dihedral above [`QuadCageOptions::crease_angle_deg`]) and
//!    boundaries, optionally drawn to the target's direction of largest curvature
//!    ([`QuadCageOptions::curvature_weight`]).
//! 3. **Position field** (`field.rs`): a lattice of spacing `s = √(area / n)` (or following
//!    the shape, [`QuadCageOptions::adaptive`]); its dislocations are paired away
//!    (`offsets.rs`, after QuadriFlow §4.2).
//! 4. **Extraction** (`extract.rs`): the lattice's regions, their dual triangulated cage (holes
//!    closed by ghost cones meanwhile, so they come back bounded by the regions along them),
//!    each cell's two triangles merged across its diagonal, the rest paired
//!    ([`crate::quads::pair_triangles`]).
//! 5. **Count**: the spacing is corrected by `√(count / n)` and the cage taken again until its
//!    count is within the budget (at most [`MAX_ATTEMPTS`] takes); the largest within it is
//!    kept.
//! 6. **Choice**: the lattice is taken at the count and at a quarter of it with every face then
//!    split into quads (an `n`-gon into `n`, as one Catmull-Clark step does: fewer defects on a
//!    coarser lattice, all quads), each from hierarchies of several coarsest sizes
//!    ([`QuadCageOptions::coarsest`]); the cage with the fewest irregular vertices is kept
//!    ([`QuadCageOptions::quads_only`]: the split ones only).
//! 7. **Rotations** (`rotate.rs`, in every take, before the split and after it): interior
//!    edges between two quads turned, in sequences of up to five, where that cancels
//!    valence-3/5 pairs, with the vertices around them relaxed on the surface and every quad
//!    there kept convex ([`QuadCageOptions::rotate_edges`]).
//!
//! Measured (`quad_cage` at the count, irregular vertices without → with the rotations of
//! step 7; QuadriFlow 1.0's at about the same count in brackets, through the peers'
//! `pyquadriflow`): Keenan Crane's Bob at 334, 26 → 17 (16; the artist's own cage 20); a
//! torus at 200, 19 → 14 (0); an icosphere at 400, 15 → 8 (8); the 3,485-vertex bunny at 479,
//! 48 → 36 (40); Fertility at 600, 111 → 94; Igea at 600, 43 → 27; the rocker arm at 500,
//! 41 → 32. The rotations add about a third to the time (Bob 1.6 → 2.0 s). Instant Meshes gives 52 on Bob. The remaining gap is the extraction: after the
//! dislocations are paired away, QuadriFlow solves the positions again under the integer
//! offsets so that every lattice point gets its own cell; here the regions keep the first
//! positions, and thin regions along the pairing paths are merged into their neighbours.
//!
//! The cage has the working mesh's genus and boundary loops or the call fails
//! ([`QuadCageError::Extraction`]); callers fall back to the paired QEM cage.

mod extract;
pub(crate) mod field;
mod offsets;
mod rotate;
pub use rotate::rotate_for_valence;
mod spacing;

use std::time::Instant;

use rayon::prelude::*;

use subfit_mesh::bvh::TriangleBvh;
use subfit_mesh::vec3::{add, cross, dot, norm, normalize, scale, sub};
use subfit_mesh::{Cancel, Cancelled, HalfEdgeMesh, PolyMesh, Polygons, Tags};
use subfit_target::Target;

use crate::quads::{pair_triangles, PairOptions};
use crate::simplify::{simplify, SimplifyOptions};
use extract::{dual_cage, regions};
use field::{orientation_field, position_field, Graph, Hierarchy, Lines};

/// Most takes of the lattice while the count is corrected (step 5).
pub const MAX_ATTEMPTS: usize = 8;

/// Options of [`quad_cage`].
#[derive(Clone, Debug, PartialEq)]
pub struct QuadCageOptions {
    /// Every face a quad: the lattice taken at about a quarter of the count and each face of
    /// its cage split into quads. Default false: that cage and the lattice's own at the count
    /// are both taken, and the one with fewer irregular vertices kept (on Keenan Crane's Bob,
    /// 5,344 vertices, at 334: 37 irregular split, 50 not; on a 3,485-vertex closed bunny at 479:
    /// 49 and 85).
    pub quads_only: bool,
    /// Working-mesh vertices per lattice vertex (step 1). Default 16: a cell of about 4 × 4
    /// mesh vertices, enough for the regions to be discs with clean borders.
    pub working_per_vertex: f64,
    /// Gauss-Seidel sweeps of the orientation field per level of the hierarchy (four times
    /// that on the coarsest). Default 30.
    pub orientation_sweeps: usize,
    /// Gauss-Seidel sweeps of the position field per level and take (four times that on the
    /// coarsest). Default 30.
    pub position_sweeps: usize,
    /// Weight of the direction of largest curvature relative to one neighbour, at full
    /// anisotropy (`|k₂ − k₁| / (|k₁| + |k₂|) = 1` and `|k₂ − k₁| · s ≥ 1`). Default 1.
    pub curvature_weight: f64,
    /// Lattice spacing that follows the shape: where a QEM simplification to the same count
    /// puts its vertices closer, the lattice is finer (`spacing.rs`). Default false: measured
    /// at fixed connectivity (Catmull-Clark, `--control-points` = budget), two-sided RMS /
    /// Hausdorff in % of the diagonal, uniform → adaptive: Keenan Crane's Bob at 334
    /// 0.0175 / 0.158 (332 points) → 0.0242 / 0.182 (286 points: fewer cells where the
    /// simplification is sparse); fertility at 600 0.0297 / 0.253 → 0.0324 / 0.280; Igea at
    /// 600 0.082 / 0.739 → 0.078 / 0.685; the 3,485-vertex bunny at 479, all quads, 0.17 / 1.7
    /// both ways (its ears need more than a smooth spacing gives).
    pub adaptive: bool,
    /// Dihedral angle (degrees) above which a working-mesh edge is a crease the field is held
    /// along. Default 45.
    pub crease_angle_deg: f64,
    /// Sizes (vertices) of the hierarchy's coarsest level to take the fields from, one take
    /// each; the cage with the fewest irregular vertices is kept. Where the fields' local
    /// minima fall depends on the hierarchy, and a take costs a fraction of a second: on Keenan
    /// Crane's Bob at 334, 27–39 irregular vertices over coarsest sizes 4–1024. Default
    /// `[16, 64, 256]`.
    pub coarsest: Vec<usize>,
    /// Interior edges between two quads rotated while that brings valences closer to regular
    /// (`rotate.rs`, step 7). Default true.
    pub rotate_edges: bool,
    /// Options of the pairing into quads.
    pub pairing: PairOptions,
    /// Cancellation, polled between steps and takes.
    pub cancel: Cancel,
}

impl Default for QuadCageOptions {
    fn default() -> Self {
        Self {
            quads_only: false,
            working_per_vertex: 16.0,
            orientation_sweeps: 30,
            position_sweeps: 30,
            curvature_weight: 0.0,
            adaptive: false,
            crease_angle_deg: 45.0,
            coarsest: vec![16, 64, 256],
            rotate_edges: true,
            pairing: PairOptions::default(),
            cancel: Cancel::default(),
        }
    }
}

/// What [`quad_cage`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct QuadCageReport {
    /// Whether the cage kept is the lattice's at about a quarter of the count with every face
    /// split into quads (otherwise the lattice's at the count, quad-dominant).
    pub split: bool,
    /// Vertices of the working mesh.
    pub working_vertices: usize,
    /// Triangles of the working mesh where the orientation field is singular (it turns by a
    /// quarter around them): where the cage's irregular vertices (or triangles) go.
    pub singularities: usize,
    /// Lattice spacing of the cage kept (normalized units).
    pub spacing: f64,
    /// Takes of the lattice (step 5).
    pub attempts: usize,
    /// Edges rotated towards regular valence in the cage kept (step 7).
    pub rotations: usize,
    /// Faces by size: `(corners, count)`, ascending.
    pub face_sizes: Vec<(usize, usize)>,
    /// Vertices by valence (edges at the vertex): `(valence, count)` over interior vertices.
    pub valences: Vec<(usize, usize)>,
    /// Irregular vertices: interior of valence ≠ 4, boundary of valence ≠ 3 (corners of two
    /// boundary edges excepted).
    pub irregular: usize,
    /// Seconds spent.
    pub seconds: f64,
}

/// Why [`quad_cage`] failed.
#[derive(Debug, thiserror::Error)]
pub enum QuadCageError {
    /// The working mesh is not a manifold or too small.
    #[error("the surface cannot carry a cross field: {0}")]
    Surface(String),
    /// No take of the lattice gave a manifold cage within the budget.
    #[error("no field-aligned cage within {budget} control points: {reason}")]
    Extraction {
        /// The budget.
        budget: usize,
        /// The last take's failure.
        reason: String,
    },
    /// Cancelled.
    #[error("interrupted")]
    Interrupted,
}

impl From<Cancelled> for QuadCageError {
    fn from(_: Cancelled) -> Self {
        Self::Interrupted
    }
}

/// A field-aligned quad-dominant (or, with [`QuadCageOptions::quads_only`], all-quad) cage of
/// at most `n` vertices for the surface `mesh` (normalized coordinates, any polygons) of
/// `target`, with `mesh`'s genus and boundary loops. See the module docs for the steps.
///
/// Cost: `O(W log W)` for the working mesh of `W ≈ 16 n` vertices plus
/// `O(sweeps · W)` per field and take; the simplification of `mesh` to it `O(E log E)`.
pub fn quad_cage(
    target: &Target,
    mesh: &PolyMesh,
    n: usize,
    options: &QuadCageOptions,
) -> Result<(PolyMesh, QuadCageReport), QuadCageError> {
    let t0 = Instant::now();
    let splits: &[bool] = if options.quads_only {
        &[true]
    } else {
        &[false, true]
    };
    let mut best: Option<(PolyMesh, QuadCageReport)> = None;
    let mut failure = None;
    for &split in splits {
        let w = match Working::new(mesh, n, if split { 0.25 } else { 1.0 }, options) {
            Ok(w) => w,
            Err(QuadCageError::Interrupted) => return Err(QuadCageError::Interrupted),
            Err(e) => {
                failure = Some(e);
                continue;
            }
        };
        // The takes of one working mesh are independent: in parallel, then compared in
        // their listed order (deterministic).
        let takes: Vec<_> = options
            .coarsest
            .par_iter()
            .map(|&coarsest| lattice_cage(target, &w, n, split, coarsest, options))
            .collect();
        for taken in takes {
            match taken {
                Ok((cage, report)) => {
                    let better = best.as_ref().is_none_or(|(b, r)| {
                        (report.irregular, std::cmp::Reverse(cage.num_vertices()))
                            < (r.irregular, std::cmp::Reverse(b.num_vertices()))
                    });
                    if better {
                        best = Some((cage, report));
                    }
                }
                Err(QuadCageError::Interrupted) => return Err(QuadCageError::Interrupted),
                Err(e) => failure = Some(e),
            }
        }
    }
    match (best, failure) {
        (Some((cage, mut report)), _) => {
            report.seconds = t0.elapsed().as_secs_f64();
            Ok((cage, report))
        }
        (None, Some(e)) => Err(e),
        (None, None) => Err(QuadCageError::Surface("no lattice was taken".into())),
    }
}

/// The cage of one lattice: at the count itself, or (`split`) at about a quarter of it with
/// every face then split into quads.
/// The working mesh of one lattice size (step 1) with what every take on it shares.
struct Working {
    /// The working mesh with its small holes capped (module step 1).
    mesh: PolyMesh,
    /// Centroids of the capped holes: each reopened as the cage face nearest it.
    caps: Vec<[f64; 3]>,
    tris: Vec<[u32; 3]>,
    graph: Graph,
    /// The working mesh for closest-point queries (the rotations' relaxation, step 7).
    surface: TriangleBvh,
    boundary: Vec<Vec<u32>>,
    genus: u32,
    area: f64,
    lattice_n: f64,
}

impl Working {
    /// The working mesh of `mesh` for a lattice at `share` of `n` vertices.
    fn new(
        mesh: &PolyMesh,
        n: usize,
        share: f64,
        options: &QuadCageOptions,
    ) -> Result<Self, QuadCageError> {
        let lattice_n = (n as f64 * share).max(4.0);
        let (working, _) = working_mesh(mesh, lattice_n, options)?;
        options.cancel.check()?;
        let he =
            HalfEdgeMesh::from_mesh(&working).map_err(|e| QuadCageError::Surface(e.to_string()))?;
        let spacing = (surface_area(&working) / lattice_n).sqrt();
        let (working, caps) = cap_small_holes(&working, &he, SMALL_HOLE * spacing);
        let tris = working.faces.triangulate_fan();
        let he =
            HalfEdgeMesh::from_mesh(&working).map_err(|e| QuadCageError::Surface(e.to_string()))?;
        let boundary = he
            .boundary_loops()
            .into_iter()
            .map(|l| l.into_iter().map(|v| v.0).collect())
            .collect();
        let graph = Graph::new(working.positions.clone(), &tris);
        let surface = TriangleBvh::new(working.positions.clone(), tris.clone());
        let area = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| graph.positions[v as usize]);
                0.5 * norm(cross(sub(b, a), sub(c, a)))
            })
            .sum();
        Ok(Self {
            genus: he.genus(),
            caps,
            mesh: working,
            tris,
            graph,
            surface,
            boundary,
            area,
            lattice_n,
        })
    }
}

/// The cage of one lattice on `w` (its hierarchy coarsened to `coarsest` vertices): at the
/// count itself, or (`split`) at about a quarter of it with every face then split into quads.
fn lattice_cage(
    target: &Target,
    w: &Working,
    n: usize,
    split: bool,
    coarsest: usize,
    options: &QuadCageOptions,
) -> Result<(PolyMesh, QuadCageReport), QuadCageError> {
    let mut report = QuadCageReport {
        split,
        working_vertices: w.mesh.num_vertices(),
        ..QuadCageReport::default()
    };
    let (graph, tris, working, lattice_n) = (&w.graph, &w.tris, &w.mesh, w.lattice_n);
    let mut s = (w.area / lattice_n).sqrt();
    let lines = field_lines(graph, tris, target, s, options);
    let hierarchy = Hierarchy::new(graph.clone(), coarsest);
    let o = orientation_field(&hierarchy, &lines, options.orientation_sweeps);
    report.singularities = field::singular_triangles(graph, &o, tris);
    options.cancel.check()?;
    // The spacing per vertex relative to the mean (`s` scales it to the count).
    let relative = if options.adaptive {
        spacing::relative_spacing(working, graph, tris, lattice_n, &options.cancel)?
    } else {
        vec![1.0; graph.len()]
    };
    let mut best: Option<(PolyMesh, f64, usize)> = None;
    let mut reason = String::from("no take");
    for attempt in 0..MAX_ATTEMPTS {
        report.attempts = attempt + 1;
        let spacing: Vec<f64> = relative.iter().map(|r| r * s).collect();
        let p = position_field(&hierarchy, &o, &spacing, options.position_sweeps);
        options.cancel.check()?;
        let taken = take(w, &o, &p, &spacing, target, options, split);
        let count = match taken {
            Ok((cage, rotations)) => {
                let m = cage.num_vertices();
                let better = m <= n && best.as_ref().is_none_or(|(b, _, _)| m > b.num_vertices());
                if better {
                    best = Some((cage, s, rotations));
                }
                m
            }
            Err(e) => {
                reason = e;
                // A failed take: a slightly different lattice may succeed.
                s *= 1.03;
                continue;
            }
        };
        let goal = 0.98 * n as f64;
        if count <= n && count as f64 >= 0.96 * n as f64 {
            break;
        }
        s *= (count as f64 / goal).sqrt();
    }
    let Some((cage, spacing, rotations)) = best else {
        return Err(QuadCageError::Extraction { budget: n, reason });
    };
    report.spacing = spacing;
    report.rotations = rotations;
    describe(&cage, &mut report);
    Ok((cage, report))
}

/// One take of the lattice `p` (steps 4): regions, dual, pairing, split; the genus and loops
/// checked against `want`. Errors: why, as text.
#[allow(clippy::too_many_arguments)]
fn take(
    w: &Working,
    o: &[[f64; 3]],
    p: &[[f64; 3]],
    s: &[f64],
    target: &Target,
    options: &QuadCageOptions,
    split: bool,
) -> Result<(PolyMesh, usize), String> {
    let (graph, tris, loops, caps) = (&w.graph, &w.tris, &w.boundary, &w.caps);
    let mut rotations = 0;
    // Step 7, before the split (a defect of the coarse cage is one of the split's too) and
    // after it.
    let mut rotate = |cage: PolyMesh| {
        if !options.rotate_edges {
            return cage;
        }
        let (rotated, k) = rotate::rotate_for_valence(&cage, &w.surface, &Tags::new());
        rotations += k;
        rotated
    };
    let want = (w.genus, w.boundary.len() + w.caps.len());
    let mut offsets = offsets::Offsets::new(graph, o, p, s);
    offsets.remove_dislocations(tris);
    let mut labels = regions(graph, &offsets);
    let protected = extract::keep_loops(&mut labels, loops);
    let (tri_cage, labels) =
        dual_cage(graph, tris, p, labels, &protected, loops).map_err(|e| format!("{e:?}"))?;
    let diagonal = extract::diagonal_pairs(graph, &offsets, &labels);
    let lattice_paired = extract::pair_diagonals(&tri_cage, &diagonal);
    let (paired, _) = pair_triangles(
        &lattice_paired,
        &Tags::new(),
        Some(target),
        &options.pairing,
    )
    .map_err(|e| e.to_string())?;
    let paired = rotate(paired);
    let cage = if split {
        rotate(split_into_quads(&paired))
    } else {
        paired
    };
    let cage = reopen_holes(cage, caps)?;
    let he = HalfEdgeMesh::from_mesh(&cage).map_err(|e| e.to_string())?;
    let got = (he.genus(), he.boundary_loops().len());
    if got != want {
        return Err(format!(
            "genus {} with {} boundary loops, the surface's {} with {}",
            got.0, got.1, want.0, want.1
        ));
    }
    Ok((cage, rotations))
}

/// A boundary loop shorter than this many lattice spacings is a small hole: capped while the
/// lattice is laid (a hole smaller than a cell cannot be bounded by cells of its own) and
/// reopened as one cage face.
pub const SMALL_HOLE: f64 = 4.0;

/// Area of a polygon mesh (its fan triangles).
fn surface_area(m: &PolyMesh) -> f64 {
    m.faces
        .triangulate_fan()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| m.positions[v as usize]);
            0.5 * norm(cross(sub(b, a), sub(c, a)))
        })
        .sum()
}

/// `m` with every boundary loop of `he` shorter than `perimeter` capped by a fan to its
/// centroid (a new vertex); returns the centroids too.
fn cap_small_holes(m: &PolyMesh, he: &HalfEdgeMesh, perimeter: f64) -> (PolyMesh, Vec<[f64; 3]>) {
    let tris = m.faces.triangulate_fan();
    let mut positions = m.positions.clone();
    let mut faces = Polygons::from_triangles(&tris);
    let mut caps = Vec::new();
    let mut directed: Vec<(u32, u32)> = tris
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .collect();
    directed.sort_unstable();
    for l in he.boundary_loops() {
        let l: Vec<u32> = l.into_iter().map(|v| v.0).collect();
        let length: f64 = (0..l.len())
            .map(|i| {
                norm(sub(
                    positions[l[(i + 1) % l.len()] as usize],
                    positions[l[i] as usize],
                ))
            })
            .sum();
        if length >= perimeter || l.len() < 3 {
            continue;
        }
        let c = l
            .iter()
            .fold([0.0; 3], |s, &v| add(s, positions[v as usize]));
        let c = scale(c, 1.0 / l.len() as f64);
        positions.push(c);
        let g = (positions.len() - 1) as u32;
        for i in 0..l.len() {
            let (a, b) = (l[i], l[(i + 1) % l.len()]);
            // Run the loop edge opposite to the triangle beside it.
            if directed.binary_search(&(a, b)).is_ok() {
                faces.push(&[g, b, a]);
            } else {
                faces.push(&[g, a, b]);
            }
        }
        caps.push(c);
    }
    (PolyMesh::new(positions, faces), caps)
}

/// `cage` with, for each cap centroid, the face whose centroid is nearest removed (a hole
/// again); fails when a removed face would touch another hole.
fn reopen_holes(cage: PolyMesh, caps: &[[f64; 3]]) -> Result<PolyMesh, String> {
    if caps.is_empty() {
        return Ok(cage);
    }
    let centroid = |f: &[u32]| {
        let s = f
            .iter()
            .fold([0.0; 3], |s, &v| add(s, cage.positions[v as usize]));
        scale(s, 1.0 / f.len() as f64)
    };
    let mut removed = vec![false; cage.faces.len()];
    let mut touched = vec![false; cage.num_vertices()];
    let he = HalfEdgeMesh::from_mesh(&cage).map_err(|e| e.to_string())?;
    for l in he.boundary_loops() {
        for v in l {
            touched[v.0 as usize] = true;
        }
    }
    let centroids: Vec<[f64; 3]> = cage.faces.iter().map(centroid).collect();
    for c in caps {
        let f = (0..centroids.len())
            .filter(|&f| !removed[f])
            .min_by(|&a, &b| {
                let d = |f: usize| {
                    let x = sub(centroids[f], *c);
                    dot(x, x)
                };
                d(a).total_cmp(&d(b))
            })
            .ok_or("no face left to reopen a hole")?;
        let face = cage.faces.face(subfit_mesh::FaceId(f as u32));
        if face.iter().any(|&v| touched[v as usize]) {
            return Err("two holes would share a vertex".into());
        }
        for &v in face {
            touched[v as usize] = true;
        }
        removed[f] = true;
    }
    let mut faces = Polygons::new();
    for (f, p) in cage.faces.iter().enumerate() {
        if !removed[f] {
            faces.push(p);
        }
    }
    Ok(PolyMesh::new(cage.positions, faces))
}

/// The working mesh of step 1 (triangles) for a lattice of `lattice_n` vertices.
fn working_mesh(
    mesh: &PolyMesh,
    lattice_n: f64,
    options: &QuadCageOptions,
) -> Result<(PolyMesh, Vec<[u32; 3]>), QuadCageError> {
    let want = (options.working_per_vertex * lattice_n).ceil() as usize;
    let mut m = PolyMesh::new(
        mesh.positions.clone(),
        Polygons::from_triangles(&mesh.faces.triangulate_fan()),
    );
    if m.num_vertices() > want {
        let so = SimplifyOptions {
            target_vertices: want,
            cancel: options.cancel.clone(),
            ..SimplifyOptions::default()
        };
        m = simplify(&m, &so)
            .map_err(|e| QuadCageError::Surface(e.to_string()))?
            .0;
    }
    while (m.num_vertices() as f64) < 0.5 * want as f64 {
        m = split_triangles(&m);
    }
    let tris = m.faces.triangulate_fan();
    Ok((m, tris))
}

/// Every triangle of `m` split into four at its edges' midpoints (planar faces stay planar).
fn split_triangles(m: &PolyMesh) -> PolyMesh {
    let tris = m.faces.triangulate_fan();
    let mut positions = m.positions.clone();
    let mut mid = std::collections::BTreeMap::new();
    let mut midpoint = |a: u32, b: u32, positions: &mut Vec<[f64; 3]>| -> u32 {
        *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
            let p = scale(add(positions[a as usize], positions[b as usize]), 0.5);
            positions.push(p);
            (positions.len() - 1) as u32
        })
    };
    let mut out = Vec::with_capacity(tris.len() * 4);
    for [a, b, c] in tris {
        let ab = midpoint(a, b, &mut positions);
        let bc = midpoint(b, c, &mut positions);
        let ca = midpoint(c, a, &mut positions);
        out.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    PolyMesh::new(positions, Polygons::from_triangles(&out))
}

/// Every face of `m` split into quads (an `n`-gon into `n`) at its centroid and its edges'
/// midpoints, as one Catmull-Clark step splits it (positions not smoothed: they are fitted).
/// Vertices keep their ids; edge points follow, then face points.
pub fn split_into_quads(m: &PolyMesh) -> PolyMesh {
    split_into_quads_tagged(m, &Tags::new()).0
}

/// [`split_into_quads`] carrying `tags`: a crease edge's two halves keep its sharpness, corners
/// stay.
pub fn split_into_quads_tagged(m: &PolyMesh, tags: &Tags) -> (PolyMesh, Tags) {
    let mut positions = m.positions.clone();
    let mut mid = std::collections::BTreeMap::new();
    for f in m.faces.iter() {
        for i in 0..f.len() {
            let (a, b) = (f[i], f[(i + 1) % f.len()]);
            mid.entry((a.min(b), a.max(b))).or_insert(0u32);
        }
    }
    for ((a, b), id) in mid.iter_mut() {
        positions.push(scale(
            add(m.positions[*a as usize], m.positions[*b as usize]),
            0.5,
        ));
        *id = (positions.len() - 1) as u32;
    }
    let edge = |a: u32, b: u32| mid[&(a.min(b), a.max(b))];
    let mut quads = Vec::new();
    for f in m.faces.iter() {
        let c = f
            .iter()
            .fold([0.0; 3], |s, &v| add(s, m.positions[v as usize]));
        positions.push(scale(c, 1.0 / f.len() as f64));
        let center = (positions.len() - 1) as u32;
        let k = f.len();
        for i in 0..k {
            let (prev, v, next) = (f[(i + k - 1) % k], f[i], f[(i + 1) % k]);
            quads.push([v, edge(v, next), center, edge(prev, v)]);
        }
    }
    let mut out_tags = Tags::new();
    for ((a, b), sharpness) in tags.creases() {
        if let Some(&e) = mid.get(&(a.min(b), a.max(b))) {
            out_tags.set_crease(a, e, sharpness);
            out_tags.set_crease(e, b, sharpness);
        }
    }
    for (v, sharpness) in tags.corners() {
        out_tags.set_corner(v, sharpness);
    }
    (
        PolyMesh::new(positions, Polygons::from_quads(&quads)),
        out_tags,
    )
}

/// The directions of step 2: creases and boundaries held, curvature drawing.
fn field_lines(
    graph: &Graph,
    tris: &[[u32; 3]],
    target: &Target,
    s: f64,
    options: &QuadCageOptions,
) -> Lines {
    let n = graph.len();
    let mut lines = Lines {
        direction: vec![None; n],
        weight: vec![0.0; n],
    };
    // Curvature: the direction of largest curvature where the surface is anisotropic at s.
    for v in 0..n {
        let i = target.index().nearest(&graph.positions[v]).index as usize;
        let f = target.quadrics()[i].frame_at(0.0, 0.0);
        let spread = (f.k2 - f.k1).abs();
        let rel = spread / (f.k1.abs() + f.k2.abs() + 1e-12);
        let w = options.curvature_weight * rel * (spread * s).min(1.0);
        if w > 0.0 && w.is_finite() {
            lines.direction[v] = Some(f.t2);
            lines.weight[v] = w;
        }
    }
    // Creases and boundaries: per vertex its feature edges.
    let cos_max = options.crease_angle_deg.to_radians().cos();
    let mut edges: Vec<((u32, u32), [f64; 3])> = Vec::with_capacity(tris.len() * 3);
    for t in tris {
        let [a, b, c] = t.map(|v| graph.positions[v as usize]);
        let fnormal = normalize(cross(sub(b, a), sub(c, a))).unwrap_or([0.0; 3]);
        for k in 0..3 {
            let (u, w) = (t[k], t[(k + 1) % 3]);
            edges.push(((u.min(w), u.max(w)), fnormal));
        }
    }
    edges.sort_by_key(|x| x.0);
    let mut feature: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut i = 0;
    while i < edges.len() {
        let mut j = i + 1;
        while j < edges.len() && edges[j].0 == edges[i].0 {
            j += 1;
        }
        let (a, b) = edges[i].0;
        let sharp = j - i != 2 || dot(edges[i].1, edges[i + 1].1) < cos_max;
        if sharp {
            feature[a as usize].push(b);
            feature[b as usize].push(a);
        }
        i = j;
    }
    for (v, f) in feature.iter().enumerate() {
        let d = match f.as_slice() {
            [] => continue,
            [a] => sub(graph.positions[*a as usize], graph.positions[v]),
            [a, b] => sub(graph.positions[*b as usize], graph.positions[*a as usize]),
            [a, ..] => sub(graph.positions[*a as usize], graph.positions[v]),
        };
        if let Some(d) = normalize(d) {
            lines.direction[v] = Some(d);
            lines.weight[v] = f64::INFINITY;
        }
    }
    lines
}

/// Irregular vertices of a polygon cage: interior vertices of valence other than 4 and
/// boundary vertices of valence other than 2 or 3 (the regular ones of a quad mesh); 0 when
/// the cage is not a manifold. Cost `O(#faces)`.
pub fn irregular_vertices(cage: &PolyMesh) -> usize {
    let mut report = QuadCageReport::default();
    describe(cage, &mut report);
    report.irregular
}

/// Fills the report's face sizes, valences and irregular count of `cage`.
fn describe(cage: &PolyMesh, report: &mut QuadCageReport) {
    report.face_sizes = cage.faces.size_histogram();
    let Ok(he) = HalfEdgeMesh::from_mesh(cage) else {
        return;
    };
    let mut hist = std::collections::BTreeMap::new();
    let mut boundary = vec![false; cage.num_vertices()];
    for l in he.boundary_loops() {
        for v in l {
            boundary[v.0 as usize] = true;
        }
    }
    let mut valence = vec![0usize; cage.num_vertices()];
    for e in 0..he.num_edges() {
        let [a, b] = he.edge_vertices(subfit_mesh::EdgeId(e as u32));
        valence[a.0 as usize] += 1;
        valence[b.0 as usize] += 1;
    }
    report.irregular = 0;
    for v in 0..cage.num_vertices() {
        if boundary[v] {
            if valence[v] != 3 && valence[v] != 2 {
                report.irregular += 1;
            }
        } else {
            *hist.entry(valence[v]).or_insert(0) += 1;
            if valence[v] != 4 {
                report.irregular += 1;
            }
        }
    }
    report.valences = hist.into_iter().collect();
}
