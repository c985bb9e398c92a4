//! The initial control mesh of an open mesh target from its boundaries and its lines of
//! curvature (Lavoué et al. 2007, "Subdivision surface fitting with quad/triangle meshes" §4),
//! the other initializer beside QEM simplification ([`crate::initial_control_mesh`]):
//!
//! 1. **Boundary curves** (§4.2, [`boundary_curve`]): each boundary loop of the target, with its
//!    sharp turns ([`subfit_target::boundary_corners`]) as corners, is approximated by a closed
//!    subdivision curve with Hoppe's boundary rules (eq. 2) and corner rule (eq. 3), fitted by
//!    the curve version of squared-distance minimization, its control-point count chosen by the
//!    loop's turning and a tolerance. These control points are the cage's vertices: the cage
//!    boundary subdivides to the curve, since Loop, Catmull-Clark and quad/triangle surfaces
//!    use the same boundary rules; corners are tagged.
//! 2. **Edge scores** (§4.3, eq. 4): a candidate edge between two control points is scored by
//!    the mean angle, over the vertices of the pseudo-geodesic (Dijkstra) path between their
//!    loop vertices on the target, between the segment and the minimum or maximum curvature
//!    direction (the smaller of the two sums), 45° at isotropic points
//!    (`quads::direction_angles`, as the quad pairing scores its quads).
//! 3. **Topological contour** (§4.4): with `n` boundary loops, `n − 1` linking edges (smallest
//!    scores first, a spanning tree of the loops; Kruskal with the paths re-scored after each
//!    link) cut the target into a disc; the contour is its border walk, the linked control
//!    points appearing twice. The paper picks the walk's continuation at a doubled point with a
//!    shortest-path test on triangles; here the mesh itself is cut along the link's path
//!    (`regions`) and the walk follows its border, which answers the same question.
//! 4. **Recursive cutting** (§4.4): the best-scored edge of a contour cuts it (and the target
//!    region inside it) in two, until what is left is planar (control points within
//!    [`CurvatureLineOptions::planar_tolerance`] of a plane, relative to the contour's size) or
//!    has at most four control points; each planar contour becomes one facet when convex, else
//!    convex pieces by Hertel & Mehlhorn ([`convex`]), split into quads and triangles for a
//!    quad/triangle cage.
//!
//! Differences from the paper, each for robustness: a path's inner vertices must be off every
//! border (forbidding it makes every cut a chord that splits a disc into two discs), and the
//! paper's 90° for a path vertex on a boundary is given at the cage's scale: to an inner vertex
//! nearer the border than [`NEAR_BORDER`] × its distance to the path's nearer end (on a target
//! of fine triangles a path one triangle inside a boundary touches nothing, and on a saddle the
//! path just inside a straight side follows a principal direction and scored best); a cut that
//! leaves one side a sliver along it is refused ([`SLIVER_RATIO`]); between equal scores the
//! cut that halves the contour is preferred ([`BALANCE_DEGREES`]); a target of genus above 0 or
//! in several pieces is refused ([`CurvatureLineError::Topology`]): the topological contour of
//! §4.4 is a disc only for a sphere with holes; a contour with no legal cut whose convex
//! pieces would repeat an edge of the cage (a narrow band between two holes: the armadillo with
//! 27 holes had one) is closed by a fan of quads from a control point whose diagonals are new.
//!
//! Cost: the curve fits near-linear in the boundary vertices; one Dijkstra per control point of
//! a contour, over the contour's region (`O(R log R)`), per cut; the cut regions shrink, so
//! about `O(C · V log V · depth)` for `C` boundary control points on `V` target vertices.

pub mod boundary_curve;
pub mod convex;
mod regions;

use std::collections::{BinaryHeap, HashSet};

use rayon::prelude::*;
use subfit_mesh::vec3::{cross, dot, norm, sub};
use subfit_mesh::{Cancel, HalfEdgeMesh, PolyMesh, Polygons, Tags, UnionFind, SHARPNESS_INFINITE};
use subfit_target::{boundary_corners, BoundaryCorners, SurfaceFrame, Target};

use boundary_curve::fit_boundary_curve;
use regions::{Path, Surface, NONE};

/// Between candidate edges of nearly equal score, the one that splits the contour more evenly:
/// a cut leaving all but two control points on one side costs this many degrees more than one
/// that halves it.
pub const BALANCE_DEGREES: f64 = 2.0;

/// An inner vertex of a path nearer the border than this fraction of its distance to the
/// path's nearer end point counts as touching the border (90° in eq. 4, see `Scorer::score`).
pub const NEAR_BORDER: f64 = 0.5;

/// A cut is refused when the control points on one side of it all lie within this fraction
/// of its length of its line ([`sliver`]).
pub const SLIVER_RATIO: f64 = 0.15;

/// The most control points the boundary curves may have together; a target whose loops need
/// more is left to the QEM initializer ([`CurvatureLineError::TooManyControlPoints`]).
pub const MAX_CURVE_CONTROL_POINTS: usize = 400;

/// Options of [`curvature_line_cage`]. Lengths in the target's normalized units.
#[derive(Clone, Debug)]
pub struct CurvatureLineOptions {
    /// Largest distance of a boundary vertex from its boundary curve. Default 2.5e-3.
    pub curve_tolerance: f64,
    /// A contour is a facet when its control points lie within this fraction of its diameter
    /// of their best plane. Default 0.08.
    pub planar_tolerance: f64,
    /// A boundary vertex is a corner when the loop turns by at least this angle (radians) there,
    /// measured with chords of [`Self::corner_scale`]. Default 1.0 (57°).
    pub corner_turn: f64,
    /// Arc length of the chords measuring a boundary turn. Default 0.02.
    pub corner_scale: f64,
    /// The most control points (boundary curves together). Default
    /// [`MAX_CURVE_CONTROL_POINTS`].
    pub max_control_points: usize,
    /// Cancellation, polled per contour. Default: never cancelled.
    pub cancel: Cancel,
}

impl Default for CurvatureLineOptions {
    fn default() -> Self {
        Self {
            curve_tolerance: 2.5e-3,
            planar_tolerance: 0.08,
            corner_turn: 1.0,
            corner_scale: 0.02,
            max_control_points: MAX_CURVE_CONTROL_POINTS,
            cancel: Cancel::default(),
        }
    }
}

/// What [`curvature_line_cage`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CurvatureLineReport {
    /// Boundary loops of the target.
    pub boundary_loops: usize,
    /// Corners among the boundary curves' control points.
    pub corners: usize,
    /// Control points per boundary curve.
    pub curve_control_points: Vec<usize>,
    /// Largest distance of a boundary vertex from its curve (normalized units).
    pub curve_max_error: f64,
    /// Edges linking the boundary loops into one contour (`loops − 1`).
    pub links: usize,
    /// Cuts of the recursive cutting.
    pub cuts: usize,
    /// Contours closed by a fan because no cut was legal and their convex pieces would have
    /// repeated an edge of the cage (narrow bands between holes).
    pub fans: usize,
    /// Faces of the cage.
    pub faces: usize,
    /// Seconds spent on the boundary curves, the links between loops (with the target
    /// analysis of the paths) and the recursive cutting.
    pub seconds: CurvatureLineTimes,
}

/// Wall-clock seconds per step of [`curvature_line_cage`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CurvatureLineTimes {
    /// Boundary curves (§4.2).
    pub curves: f64,
    /// The mesh's half-edges and the links of the topological contour (§4.4).
    pub links: f64,
    /// Recursive cutting and facets (§4.4).
    pub cuts: f64,
}

/// Why [`curvature_line_cage`] gave no cage.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CurvatureLineError {
    /// The target is not a sphere with holes.
    #[error("curvature-line cages need an open surface of genus 0 in one piece; the target has genus {genus}, {loops} boundary loop(s), {components} piece(s)")]
    Topology {
        /// Genus.
        genus: u32,
        /// Boundary loops.
        loops: usize,
        /// Connected components.
        components: usize,
    },
    /// The mesh is not a manifold triangle mesh.
    #[error("the target mesh: {0}")]
    Mesh(String),
    /// The boundary curves need more control points than allowed.
    #[error("the boundary curves need {needed} control points, more than {allowed}")]
    TooManyControlPoints {
        /// Control points of the curves.
        needed: usize,
        /// [`CurvatureLineOptions::max_control_points`].
        allowed: usize,
    },
    /// A contour could be neither cut nor made into facets (or the loops could not be linked).
    #[error("no legal cut of a contour of {0} control points")]
    Stuck(usize),
    /// The cage came out not a manifold (a diagonal of a facet that another facet has too).
    #[error("the cage came out not a manifold: {0}")]
    Cage(String),
    /// The cage came out with another topology than the target's.
    #[error("the cage came out with genus {genus} and {loops} boundary loop(s)")]
    Result {
        /// Genus of the cage.
        genus: u32,
        /// Boundary loops of the cage.
        loops: usize,
    },
    /// Cancelled.
    #[error("interrupted")]
    Interrupted,
}

/// The cage built from `dense` (the target's mesh in normalized units, triangles, manifold
/// and oriented) and the curvature of `target` (built from the same vertices): see the module
/// docs. Returns the cage (polygons of 3 and 4 control points, and convex polygons of more
/// where a planar contour needed them), its corner tags and a report. Cost: see the module docs.
pub fn curvature_line_cage(
    target: &Target,
    dense: &PolyMesh,
    options: &CurvatureLineOptions,
) -> Result<(PolyMesh, Tags, CurvatureLineReport), CurvatureLineError> {
    let loops = check_topology(dense)?;
    let tris = dense.faces.triangulate_fan();
    let mut report = CurvatureLineReport::default();
    let bc = boundary_corners(
        &dense.positions,
        &tris,
        options.corner_turn,
        options.corner_scale,
    );
    report.boundary_loops = bc.loops.len();

    // 1. Boundary curves: their control points are the cage's vertices.
    let t = std::time::Instant::now();
    let BoundaryCage {
        points: cage,
        tags,
        id_at,
        mut edges,
    } = boundary_cage(dense, &bc, options, &mut report)?;
    report.seconds.curves = t.elapsed().as_secs_f64();
    let t = std::time::Instant::now();
    let mut surface = Surface::new(dense.positions.clone(), tris);
    let scorer = Scorer::new(target, &dense.positions);

    // 2–3. Link the loops into one contour.
    let loop_of: Vec<Vec<u32>> = bc
        .loops
        .iter()
        .map(|l| {
            l.iter()
                .copied()
                .filter(|&v| id_at[v as usize] != NONE)
                .collect()
        })
        .collect();
    report.links = link_loops(&mut surface, &scorer, &loop_of, &id_at, &mut edges)?;

    report.seconds.links = t.elapsed().as_secs_f64();
    let t = std::time::Instant::now();

    // 4. Cut recursively; planar contours become facets.
    let faces = cut_into_faces(
        &mut surface,
        &scorer,
        &cage,
        &id_at,
        &mut edges,
        options,
        &mut report,
    )?;
    let mut polys = Polygons::new();
    for f in &faces {
        polys.push(f);
    }
    let out = PolyMesh::new(cage, polys);
    let he = HalfEdgeMesh::from_mesh(&out).map_err(|e| CurvatureLineError::Cage(e.to_string()))?;
    if he.genus() != 0 || he.boundary_loops().len() != loops {
        return Err(CurvatureLineError::Result {
            genus: he.genus(),
            loops: he.boundary_loops().len(),
        });
    }
    report.faces = out.faces.len();
    report.seconds.cuts = t.elapsed().as_secs_f64();
    Ok((out, tags, report))
}

/// The topology [`curvature_line_cage`] needs of `dense`: genus 0, one component, at least one
/// boundary loop. Returns the number of boundary loops.
fn check_topology(dense: &PolyMesh) -> Result<usize, CurvatureLineError> {
    let he = HalfEdgeMesh::from_mesh(dense).map_err(|e| CurvatureLineError::Mesh(e.to_string()))?;
    let (genus, loops, components) = (he.genus(), he.boundary_loops().len(), he.components().count);
    if genus != 0 || loops == 0 || components != 1 {
        return Err(CurvatureLineError::Topology {
            genus,
            loops,
            components,
        });
    }
    drop(he);
    Ok(loops)
}

/// The cage after step 1: its control points, tags, the control point of each dense vertex
/// (`NONE` for the others) and its edges (`key` pairs).
struct BoundaryCage {
    points: Vec<[f64; 3]>,
    tags: Tags,
    id_at: Vec<u32>,
    edges: HashSet<(u32, u32)>,
}

/// Step 1: a curve fitted to each boundary loop `bc.loops` of `dense` (its corners kept), whose
/// control points become the cage's vertices and consecutive ones its edges; corners are
/// tagged. Errors when the curves need more than [`CurvatureLineOptions::max_control_points`].
fn boundary_cage(
    dense: &PolyMesh,
    bc: &BoundaryCorners,
    options: &CurvatureLineOptions,
    report: &mut CurvatureLineReport,
) -> Result<BoundaryCage, CurvatureLineError> {
    let mut cage = Vec::new();
    let mut tags = Tags::new();
    let mut id_at = vec![NONE; dense.positions.len()];
    let mut edges = HashSet::new();
    for l in &bc.loops {
        let pts: Vec<[f64; 3]> = l.iter().map(|&v| dense.positions[v as usize]).collect();
        let corners: Vec<usize> = (0..l.len())
            .filter(|&i| bc.corners.binary_search(&l[i]).is_ok())
            .collect();
        let room = options.max_control_points.saturating_sub(cage.len()).max(3);
        let curve = fit_boundary_curve(&pts, &corners, options.curve_tolerance, room);
        report.curve_max_error = report.curve_max_error.max(curve.max_error);
        report.curve_control_points.push(curve.control.len());
        let first = cage.len() as u32;
        let m = curve.control.len() as u32;
        for (i, (&c, &k)) in curve.control.iter().zip(&curve.corner).enumerate() {
            let id = first + i as u32;
            cage.push(c);
            id_at[l[curve.loop_index[i]] as usize] = id;
            if k {
                tags.set_corner(id, SHARPNESS_INFINITE);
                report.corners += 1;
            }
            edges.insert(key(id, first + (i as u32 + 1) % m));
        }
    }
    if cage.len() > options.max_control_points {
        return Err(CurvatureLineError::TooManyControlPoints {
            needed: cage.len(),
            allowed: options.max_control_points,
        });
    }
    Ok(BoundaryCage {
        points: cage,
        tags,
        id_at,
        edges,
    })
}

/// Step 4: the contour of each region (starting from region 0, the linked loops) is cut along
/// the best-scoring path between two of its control points until it is planar (or has at most
/// four control points); then it becomes facets. A contour that cannot be cut closes as convex
/// facets or a fan. Returns the faces over `cage`'s ids; adds their edges to `edges`.
fn cut_into_faces(
    surface: &mut Surface,
    scorer: &Scorer,
    cage: &[[f64; 3]],
    id_at: &[u32],
    edges: &mut HashSet<(u32, u32)>,
    options: &CurvatureLineOptions,
    report: &mut CurvatureLineReport,
) -> Result<Vec<Vec<u32>>, CurvatureLineError> {
    let mut faces: Vec<Vec<u32>> = Vec::new();
    let mut stack = vec![0u32];
    while let Some(r) = stack.pop() {
        options
            .cancel
            .check()
            .map_err(|_| CurvatureLineError::Interrupted)?;
        let walk = surface.contour(r).ok_or(CurvatureLineError::Stuck(0))?;
        let occ: Vec<u32> = walk
            .into_iter()
            .filter(|&v| id_at[v as usize] != NONE)
            .collect();
        let ids: Vec<u32> = occ.iter().map(|&v| id_at[v as usize]).collect();
        let distinct = ids.iter().collect::<HashSet<_>>().len() == ids.len();
        let pts: Vec<[f64; 3]> = ids.iter().map(|&i| cage[i as usize]).collect();
        if distinct && (ids.len() <= 4 || planar(&pts, options.planar_tolerance)) {
            let f = facets(&pts, &ids);
            // A diagonal that is already an edge elsewhere would make it non-manifold: cut.
            if inner_edges(&f, &ids).all(|e| !edges.contains(&e)) {
                edges.extend(inner_edges(&f, &ids));
                faces.extend(f);
                continue;
            }
        }
        // A contour through a control point twice (a link's end), or whose facets would add
        // an edge the cage has elsewhere, must be cut: a sliver is better than no cage.
        let f = distinct.then(|| facets(&pts, &ids));
        let closes = f
            .as_ref()
            .is_some_and(|f| inner_edges(f, &ids).all(|e| !edges.contains(&e)));
        let cut = best_cut(surface, scorer, r, &occ, id_at, edges, cage, false).or_else(|| {
            (!closes)
                .then(|| best_cut(surface, scorer, r, &occ, id_at, edges, cage, true))
                .flatten()
        });
        match (cut, f) {
            (Some((new, a, b)), _) => {
                edges.insert(key(a, b));
                report.cuts += 1;
                stack.push(r);
                stack.push(new);
            }
            (None, Some(f)) if closes => {
                edges.extend(inner_edges(&f, &ids));
                faces.extend(f);
            }
            (None, Some(_)) => {
                // No cut, and the convex pieces would repeat an edge: a fan from a control
                // point none of whose diagonals is an edge yet.
                let f = fan(&ids, edges).ok_or(CurvatureLineError::Stuck(ids.len()))?;
                report.fans += 1;
                edges.extend(inner_edges(&f, &ids));
                faces.extend(f);
            }
            (None, None) => return Err(CurvatureLineError::Stuck(ids.len())),
        }
    }
    Ok(faces)
}

fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Eq. 4 along target paths.
struct Scorer {
    /// Per dense vertex: the principal frame of its target point (the target merges
    /// duplicates; a vertex it does not know takes its nearest point's).
    frames: Vec<SurfaceFrame>,
}

impl Scorer {
    /// Evaluates the frames once (in parallel): a path's vertices are scored many times.
    fn new(target: &Target, positions: &[[f64; 3]]) -> Self {
        let map = target.input_to_point();
        let frames = positions
            .par_iter()
            .enumerate()
            .map(|(v, x)| {
                let p = match map.get(v) {
                    Some(&p) if map.len() == positions.len() => p as usize,
                    _ => target.index().nearest(x).index as usize,
                };
                target.quadrics()[p].frame_at(0.0, 0.0)
            })
            .collect();
        Self { frames }
    }

    /// `min(Σ θmin, Σ θmax) / n` in degrees over the path's vertices, against the segment
    /// between its end points (§4.3, eq. 4). An inner vertex nearer the border (`border`:
    /// distances from [`Surface::border_distance`]) than [`NEAR_BORDER`] × its distance to the
    /// nearer end point touches the border at the cage's scale and counts 90° (the paper's
    /// penalty, measured at the scale of the edge rather than of the target's triangles).
    fn score(&self, surface: &Surface, path: &Path, border: &[f64]) -> f64 {
        let (&a, &b) = (
            path.vertices.first().expect("a path"),
            path.vertices.last().expect("a path"),
        );
        let (pa, pb) = (surface.positions[a as usize], surface.positions[b as usize]);
        let d = sub(pb, pa);
        let len = norm(d);
        let (mut s1, mut s2) = (0.0, 0.0);
        let last = path.vertices.len() - 1;
        for (i, &v) in path.vertices.iter().enumerate() {
            let x = surface.positions[v as usize];
            let end = norm(sub(x, pa)).min(norm(sub(x, pb)));
            if i != 0 && i != last && border[v as usize] < NEAR_BORDER * end {
                s1 += 90.0;
                s2 += 90.0;
                continue;
            }
            let f = &self.frames[v as usize];
            let (t1, t2) = crate::quads::direction_angles(d, len, f);
            s1 += t1;
            s2 += t2;
        }
        s1.min(s2) / path.vertices.len() as f64
    }
}

/// Per-thread Dijkstra buffers.
struct Buffers {
    dist: Vec<f64>,
    pred: Vec<(u32, u32)>,
    touched: Vec<u32>,
}

impl Buffers {
    fn new(n: usize) -> Self {
        Self {
            dist: vec![f64::INFINITY; n],
            pred: vec![(NONE, NONE); n],
            touched: Vec::new(),
        }
    }

    fn reset(&mut self) {
        for &v in &self.touched {
            self.dist[v as usize] = f64::INFINITY;
        }
        self.touched.clear();
    }
}

/// The path from `a` to `b` in `region`, if any.
fn path(surface: &Surface, region: u32, a: u32, b: u32) -> Option<Path> {
    let mut buf = Buffers::new(surface.positions.len());
    surface.dijkstra(region, a, &mut buf.dist, &mut buf.pred, &mut buf.touched);
    Surface::path_to(a, b, &buf.dist, &buf.pred)
}

/// Links the boundary loops (`loop_of`: each loop's control-point vertices) by `loops − 1`
/// paths, smallest score first (Kruskal; a candidate whose path an earlier link changed is
/// scored again). Returns the number of links.
fn link_loops(
    surface: &mut Surface,
    scorer: &Scorer,
    loop_of: &[Vec<u32>],
    id_at: &[u32],
    edges: &mut HashSet<(u32, u32)>,
) -> Result<usize, CurvatureLineError> {
    if loop_of.len() < 2 {
        return Ok(0);
    }
    let owner: Vec<(u32, usize)> = loop_of
        .iter()
        .enumerate()
        .flat_map(|(l, vs)| vs.iter().map(move |&v| (v, l)))
        .collect();
    let loop_at = |v: u32| owner.iter().find(|o| o.0 == v).map(|o| o.1);
    let n = surface.positions.len();
    let s: &Surface = surface;
    let border = s.border_distance(0);
    let mut heap: BinaryHeap<Candidate> = owner
        .par_iter()
        .map_init(
            || Buffers::new(n),
            |buf, &(a, la)| {
                buf.reset();
                s.dijkstra(0, a, &mut buf.dist, &mut buf.pred, &mut buf.touched);
                owner
                    .iter()
                    .filter(|&&(b, lb)| lb > la && b != a)
                    .filter_map(|&(b, _)| {
                        let p = Surface::path_to(a, b, &buf.dist, &buf.pred)?;
                        Some(Candidate {
                            key: scorer.score(s, &p, &border),
                            a,
                            b,
                            stamp: 0,
                        })
                    })
                    .collect::<Vec<_>>()
            },
        )
        .flatten()
        .collect();
    let mut uf = UnionFind::new(loop_of.len());
    let mut links = 0;
    while links + 1 < loop_of.len() {
        let c = heap.pop().ok_or(CurvatureLineError::Stuck(owner.len()))?;
        let (la, lb) = (
            loop_at(c.a).expect("a control point"),
            loop_at(c.b).expect("a control point"),
        );
        if uf.find(la as u32) == uf.find(lb as u32) {
            continue;
        }
        let Some(p) = path(surface, 0, c.a, c.b) else {
            continue;
        };
        if c.stamp != links {
            let key = scorer.score(surface, &p, &surface.border_distance(0));
            heap.push(Candidate {
                key,
                stamp: links,
                ..c
            });
            continue;
        }
        surface.mark(&p);
        uf.union(la as u32, lb as u32);
        edges.insert(key(id_at[c.a as usize], id_at[c.b as usize]));
        links += 1;
    }
    Ok(links)
}

/// A candidate edge in a heap, smallest key first.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    key: f64,
    a: u32,
    b: u32,
    /// The number of links made when it was scored.
    stamp: usize,
}

impl PartialEq for Candidate {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other).is_eq()
    }
}
impl Eq for Candidate {}
impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        other
            .key
            .total_cmp(&self.key)
            .then(other.a.cmp(&self.a))
            .then(other.b.cmp(&self.b))
    }
}

/// Cuts region `r` (contour control points `occ`, mesh vertices in walk order) along its
/// best-scored legal edge: non-adjacent in the contour, two different control points not yet
/// joined by an edge, a path off the border, no sliver on either side unless
/// `allow_slivers`. Returns the new region and the edge's control points, or `None` when no
/// candidate cuts.
#[allow(clippy::too_many_arguments)]
fn best_cut(
    surface: &mut Surface,
    scorer: &Scorer,
    r: u32,
    occ: &[u32],
    id_at: &[u32],
    edges: &HashSet<(u32, u32)>,
    cage: &[[f64; 3]],
    allow_slivers: bool,
) -> Option<(u32, u32, u32)> {
    let k = occ.len();
    let at = |o: usize| cage[id_at[occ[o] as usize] as usize];
    let n = surface.positions.len();
    let s: &Surface = surface;
    let border = s.border_distance(r);
    let mut cands: Vec<(f64, usize, usize)> = (0..k)
        .into_par_iter()
        .map_init(
            || Buffers::new(n),
            |buf, i| {
                buf.reset();
                s.dijkstra(r, occ[i], &mut buf.dist, &mut buf.pred, &mut buf.touched);
                ((i + 2)..k)
                    .filter(|&j| !(i == 0 && j == k - 1))
                    .filter_map(|j| {
                        let (a, b) = (id_at[occ[i] as usize], id_at[occ[j] as usize]);
                        if a == b || edges.contains(&key(a, b)) {
                            return None;
                        }
                        // Neither side may be a sliver along the chord.
                        let sides = [(i..=j).collect::<Vec<_>>(), (j..k).chain(0..=i).collect()];
                        if !allow_slivers
                            && sides
                                .iter()
                                .any(|side| sliver(side.iter().map(|&o| at(o)), at(i), at(j)))
                        {
                            return None;
                        }
                        let p = Surface::path_to(occ[i], occ[j], &buf.dist, &buf.pred)?;
                        let side = (j - i + 1) as f64;
                        let imbalance = (side - (k as f64 + 2.0 - side)).abs() / k as f64;
                        Some((
                            scorer.score(s, &p, &border) + BALANCE_DEGREES * imbalance,
                            i,
                            j,
                        ))
                    })
                    .collect::<Vec<_>>()
            },
        )
        .flatten()
        .collect();
    cands.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
    for &(_, i, j) in cands.iter().take(8) {
        let p = path(surface, r, occ[i], occ[j])?;
        if let Some(new) = surface.cut(r, &p) {
            return Some((new, id_at[occ[i] as usize], id_at[occ[j] as usize]));
        }
    }
    None
}

/// Whether the control points `side` (from one end of a chord `a`–`b` to the other) all lie
/// within [`SLIVER_RATIO`] × its length of the chord's line: the facet they would close is a
/// sliver (two control points of one straight side of the contour joined: on a saddle the
/// path just inside that side follows a principal direction and scored best).
fn sliver(side: impl Iterator<Item = [f64; 3]>, a: [f64; 3], b: [f64; 3]) -> bool {
    let d = sub(b, a);
    let len = norm(d);
    if len <= 0.0 {
        return true;
    }
    side.map(|p| norm(cross(sub(p, a), d)) / len)
        .all(|h| h <= SLIVER_RATIO * len)
}

/// Whether `pts` lie within `tolerance` × their diameter of their best plane (Newell normal
/// through the centroid).
fn planar(pts: &[[f64; 3]], tolerance: f64) -> bool {
    let n = pts.len() as f64;
    let c = pts.iter().fold([0.0; 3], |a, p| {
        [a[0] + p[0] / n, a[1] + p[1] / n, a[2] + p[2] / n]
    });
    let mut normal = [0.0; 3];
    for i in 0..pts.len() {
        let (a, b) = (sub(pts[i], c), sub(pts[(i + 1) % pts.len()], c));
        let x = cross(a, b);
        normal = [normal[0] + x[0], normal[1] + x[1], normal[2] + x[2]];
    }
    let Some(normal) = subfit_mesh::vec3::unit(normal) else {
        return false;
    };
    let diameter = pts
        .iter()
        .flat_map(|p| pts.iter().map(move |q| norm(sub(*p, *q))))
        .fold(0.0, f64::max);
    pts.iter()
        .all(|p| dot(sub(*p, c), normal).abs() <= tolerance * diameter)
}

/// The edges of `faces` (control point ids) that are not sides of the contour `ids` (its
/// consecutive pairs): the diagonals the facets add.
fn inner_edges<'a>(faces: &'a [Vec<u32>], ids: &[u32]) -> impl Iterator<Item = (u32, u32)> + 'a {
    let sides: HashSet<(u32, u32)> = (0..ids.len())
        .map(|i| key(ids[i], ids[(i + 1) % ids.len()]))
        .collect();
    faces
        .iter()
        .flat_map(|f| (0..f.len()).map(move |i| key(f[i], f[(i + 1) % f.len()])))
        .filter(move |e| !sides.contains(e))
}

/// A fan of quads (and one triangle for an odd count) over the contour `ids` (distinct control
/// points) from the first of its points whose diagonals are not yet `edges`, or `None`.
fn fan(ids: &[u32], edges: &HashSet<(u32, u32)>) -> Option<Vec<Vec<u32>>> {
    let n = ids.len();
    let at = |i: usize, k: usize| ids[(i + k) % n];
    let i = (0..n).find(|&i| (2..n - 1).all(|k| !edges.contains(&key(at(i, 0), at(i, k)))))?;
    let mut out = Vec::new();
    let mut k = 1;
    while k + 1 < n {
        if k + 3 <= n {
            out.push(vec![at(i, 0), at(i, k), at(i, k + 1), at(i, k + 2)]);
            k += 2;
        } else {
            out.push(vec![at(i, 0), at(i, k), at(i, k + 1)]);
            k += 1;
        }
    }
    Some(out)
}

/// The facets of a contour of distinct control points `ids` at `pts`: convex pieces
/// (Hertel–Mehlhorn) split into quads and triangles.
fn facets(pts: &[[f64; 3]], ids: &[u32]) -> Vec<Vec<u32>> {
    convex::convex_pieces(pts)
        .into_iter()
        .flat_map(|piece| convex::quads_and_triangles(pts, &piece))
        .map(|f| f.into_iter().map(|i| ids[i]).collect())
        .collect()
}
