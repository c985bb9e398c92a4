//! Adaptive changes of the control mesh between fitting stages (Cheng et al. 2004 §4.5–4.6,
//! Cheng et al. 2007 §II-F): per-face fitting errors, local 1-to-4 refinement of the faces with
//! large errors with red-green closure (Bank, Sherman & Weiser 1983) so that no T-vertex
//! appears, and edge flips in high-error regions.
//!
//! The face scores work for any cage and scheme; the red-green split is for triangle cages
//! (Loop), polygon cages (Catmull-Clark and other schemes) are split by
//! [`crate::refine_polygons`]; flips change triangle pairs only, in either kind of cage.

use std::collections::HashMap;

use subfit_mesh::{FaceId, PolyMesh, Polygons, Tags};
use subfit_subdiv::mask::loop_beta;
use subfit_subdiv::SamplingOperator;

/// Fitting error gathered per control face from the samples of its limit patch.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FaceError {
    /// Sum over the face's level-`l` sub-faces of the mean squared sample error of their
    /// corners (normalized units²).
    pub sum_sq: f64,
    /// Number of level-`l` sub-faces (the weight of `sum_sq`).
    pub count: u32,
    /// Largest sample error at a corner of one of the face's sub-faces.
    pub max: f64,
}

impl FaceError {
    /// Root-mean-square error over the face's sub-faces.
    pub fn rms(&self) -> f64 {
        if self.count == 0 {
            0.0
        } else {
            (self.sum_sq / self.count as f64).sqrt()
        }
    }
}

/// For each face of the level-`l` mesh of `op`, the control face it descends from. Relies on
/// the documented child order of the refinement (children of a face are consecutive) and on
/// the face splits of the schemes: a quad gives 4 quads and an `n`-gon (`n ≥ 5`) `n` quads under
/// every scheme; a triangle gives 4 triangles (Loop, the quad/triangle hybrid) or 3 quads
/// (Catmull-Clark). Which of the two is read off the refined faces: a level `l ≥ 1` with no
/// triangle means triangles became quads. Works for triangle, quad and mixed cages. Cost
/// O(#faces at level `l`).
pub fn face_owners(control_faces: &Polygons, op: &SamplingOperator) -> Vec<u32> {
    let mut owners: Vec<u32> = (0..control_faces.len() as u32).collect();
    let mut sizes: Vec<usize> = control_faces.iter().map(<[u32]>::len).collect();
    let triangles_stay = op.faces.iter().any(|f| f.len() == 3);
    for _ in 0..op.level {
        let mut next = Vec::with_capacity(owners.len() * 4);
        let mut next_sizes = Vec::with_capacity(owners.len() * 4);
        for (&o, &s) in owners.iter().zip(&sizes) {
            let (children, child_size) = match s {
                3 if triangles_stay => (4, 3),
                3 => (3, 4),
                4 => (4, 4),
                n => (n, 4),
            };
            for _ in 0..children {
                next.push(o);
                next_sizes.push(child_size);
            }
        }
        owners = next;
        sizes = next_sizes;
    }
    debug_assert_eq!(owners.len(), op.faces.len());
    owners
}

/// Per-control-face errors from per-sample squared errors `err2` (one per row of `op`).
pub fn face_errors(
    control_faces: &Polygons,
    op: &SamplingOperator,
    err2: &[f64],
) -> Vec<FaceError> {
    let owners = face_owners(control_faces, op);
    let mut out = vec![FaceError::default(); control_faces.len()];
    for (f, &o) in op.faces.iter().zip(&owners) {
        let e = &mut out[o as usize];
        let mut s = 0.0;
        for &v in f {
            let d2 = err2[v as usize];
            s += d2;
            e.max = e.max.max(d2.sqrt());
        }
        e.sum_sq += s / f.len() as f64;
        e.count += 1;
    }
    out
}

/// What [`refine_red_green`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RefineStats {
    /// Faces asked for (marked) and split 1-to-4.
    pub marked: usize,
    /// Faces split 1-to-4 in total (marked plus red closure).
    pub red: usize,
    /// Faces bisected to close the refinement (green).
    pub green: usize,
    /// Control points added (one per split edge).
    pub new_points: usize,
}

fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// The crease sharpness from which an edge is refined by the sharp rules
/// ([`refine_red_green_with_parents`]): at the first level of a semi-sharp crease of
/// sharpness `s ≥ 1` the sharp rules apply (DeRose et al. 1998), below 1 the smooth ones.
pub const SHARP: f64 = 1.0;

/// Splits the marked triangles 1-to-4 (Loop's split); a neighbour with two or three split
/// edges is split 1-to-4 as well (red), one with a single split edge is bisected (green), so
/// the result has no T-vertices (red-green refinement, Bank et al. 1983; Cheng 2004 §4.5).
///
/// New control points sit at Loop's edge points of the current cage (3/8, 3/8, 1/8, 1/8;
/// midpoints on boundary edges); an interior old control point whose faces are all split moves
/// to Loop's vertex point, and a boundary point whose two boundary edges are split to Loop's
/// boundary vertex point (1/8, 3/4, 1/8), so that the limit surface and its boundary curve are
/// unchanged where the refinement is uniform; other old points stay. Old points keep their ids, new ones are appended. Winding
/// is preserved. Returns `None` when the cage is not all triangles.
pub fn refine_red_green(mesh: &PolyMesh, marked: &[bool]) -> Option<(PolyMesh, RefineStats)> {
    refine_red_green_with_parents(mesh, &Tags::new(), marked).map(|(m, s, _)| (m, s))
}

/// [`refine_red_green`] of a cage with crease and corner `tags`, also giving the parent face
/// of every output face (children of a face are consecutive). A sharp crease edge (sharpness
/// at least 1, [`SHARP`]) follows the rules of a boundary edge — its new point is its midpoint,
/// a point on two split sharp edges moves to (1/8, 3/4, 1/8) of them — and a corner (a corner
/// tag, or three or more sharp edges) stays, as the crease rules of Hoppe et al. 1994 and
/// OpenSubdiv place them; with Loop's smooth masks instead, the refined cage of a CAD part
/// moved off its creases (adis16480: the surface → data maximum went from 0.21 % to 1.4 % of
/// the diagonal after the first refinement, and no later stage recovered).
pub fn refine_red_green_with_parents(
    mesh: &PolyMesh,
    tags: &Tags,
    marked: &[bool],
) -> Option<(PolyMesh, RefineStats, Vec<u32>)> {
    if !mesh.faces.is_triangles() {
        return None;
    }
    let tris: Vec<[u32; 3]> = mesh.faces.iter().map(|f| [f[0], f[1], f[2]]).collect();
    // Opposite vertices of each edge (for the edge-point mask).
    let mut opposite: HashMap<(u32, u32), Vec<u32>> = HashMap::with_capacity(tris.len() * 2);
    for t in &tris {
        for i in 0..3 {
            opposite
                .entry(key(t[i], t[(i + 1) % 3]))
                .or_default()
                .push(t[(i + 2) % 3]);
        }
    }
    let (red, mut split) = red_closure(&tris, marked);
    let mut positions = vertex_points(mesh, tags, &tris, &opposite, &red, &split);
    edge_points(mesh, tags, &tris, &opposite, &mut split, &mut positions);
    let mut stats = RefineStats {
        marked: marked.iter().filter(|&&m| m).count(),
        new_points: split.len(),
        ..RefineStats::default()
    };
    let (out, parents) = split_faces(&tris, &red, &split, &mut stats);
    Some((
        PolyMesh::new(positions, Polygons::from_triangles(&out)),
        stats,
        parents,
    ))
}

/// The red-green closure of `marked` over `tris`: the faces split 1-to-4 (red: the marked
/// ones and every face with two or more split edges) and the split edges (each mapped to
/// `u32::MAX`, its new point not numbered yet).
fn red_closure(tris: &[[u32; 3]], marked: &[bool]) -> (Vec<bool>, HashMap<(u32, u32), u32>) {
    let mut red: Vec<bool> = marked.to_vec();
    red.resize(tris.len(), false);
    let mut split: HashMap<(u32, u32), u32> = HashMap::new();
    // Closure: mark edges of red faces; faces with ≥ 2 split edges turn red.
    loop {
        for (t, _) in tris.iter().zip(&red).filter(|(_, &r)| r) {
            for i in 0..3 {
                split.entry(key(t[i], t[(i + 1) % 3])).or_insert(u32::MAX);
            }
        }
        let mut changed = false;
        for (t, r) in tris.iter().zip(red.iter_mut()) {
            if *r {
                continue;
            }
            let k = (0..3)
                .filter(|&i| split.contains_key(&key(t[i], t[(i + 1) % 3])))
                .count();
            if k >= 2 {
                *r = true;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    (red, split)
}

/// The old points after the refinement: Loop's vertex point where all faces around are red,
/// Loop's boundary vertex point where both boundary edges are split, else unchanged.
fn vertex_points(
    mesh: &PolyMesh,
    tags: &Tags,
    tris: &[[u32; 3]],
    opposite: &HashMap<(u32, u32), Vec<u32>>,
    red: &[bool],
    split: &HashMap<(u32, u32), u32>,
) -> Vec<[f64; 3]> {
    // Old points whose faces are all split 1-to-4 take Loop's vertex point, so that where the
    // refinement is uniform the limit surface does not change at all; elsewhere they stay.
    let nv = mesh.num_vertices();
    let mut all_red = vec![true; nv];
    let mut on_boundary = vec![false; nv];
    let mut ring: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for (t, &r) in tris.iter().zip(red) {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            all_red[a as usize] &= r;
            if !ring[a as usize].contains(&b) {
                ring[a as usize].push(b);
            }
            if !ring[b as usize].contains(&a) {
                ring[b as usize].push(a);
            }
            if opposite[&key(a, b)].len() != 2 {
                on_boundary[a as usize] = true;
                on_boundary[b as usize] = true;
            }
        }
    }
    // Sharp crease neighbours (each edge once), for the crease rule below.
    let mut sharp_ring: Vec<Vec<u32>> = vec![Vec::new(); nv];
    if !tags.is_empty() {
        for ((a, b), s) in tags.creases() {
            let (a, b) = (a.min(b), a.max(b));
            if s >= SHARP && (b as usize) < nv && opposite.contains_key(&(a, b)) {
                sharp_ring[a as usize].push(b);
                sharp_ring[b as usize].push(a);
            }
        }
    }
    let mut positions = mesh.positions.clone();
    // Boundary neighbours and incident faces, for the boundary rule below.
    let mut boundary_ring: Vec<Vec<u32>> = vec![Vec::new(); nv];
    let mut incident = vec![0u32; nv];
    for t in tris {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            incident[a as usize] += 1;
            if opposite[&key(a, b)].len() == 1 {
                boundary_ring[a as usize].push(b);
                boundary_ring[b as usize].push(a);
            }
        }
    }
    for v in 0..nv {
        let n = ring[v].len();
        if on_boundary[v] {
            // Loop's boundary vertex point (1/8, 3/4, 1/8) when both boundary edges are split:
            // the boundary curve (a cubic B-spline of the boundary polygon) is then unchanged
            // there. Left in place, the refined polygon's curve would jump out toward the
            // control polygon. A vertex of one face (a corner under the edge-and-corner rule)
            // or of more than two boundary edges stays.
            let br = &boundary_ring[v];
            if br.len() == 2
                && incident[v] > 1
                && br.iter().all(|&w| split.contains_key(&key(v as u32, w)))
            {
                positions[v] = curve_point(mesh, v, br);
            }
            continue;
        }
        let sharp = &sharp_ring[v];
        if sharp.len() >= 3 || tags.corner(v as u32) > 0.0 {
            continue;
        }
        if sharp.len() == 2 {
            // A crease point: the crease curve's rule when both its crease edges are split.
            if sharp.iter().all(|&w| split.contains_key(&key(v as u32, w))) {
                positions[v] = curve_point(mesh, v, sharp);
            }
            continue;
        }
        if !all_red[v] || n < 3 {
            continue;
        }
        let beta = loop_beta(n);
        let p = mesh.positions[v];
        positions[v] = std::array::from_fn(|k| {
            (1.0 - n as f64 * beta) * p[k]
                + beta
                    * ring[v]
                        .iter()
                        .map(|&w| mesh.positions[w as usize][k])
                        .sum::<f64>()
        });
    }
    positions
}

/// Loop's vertex point of `v` on a curve (a boundary or a sharp crease) through its two curve
/// neighbours `ends`: (1/8, 3/4, 1/8).
fn curve_point(mesh: &PolyMesh, v: usize, ends: &[u32]) -> [f64; 3] {
    let (p, a, b) = (
        mesh.positions[v],
        mesh.positions[ends[0] as usize],
        mesh.positions[ends[1] as usize],
    );
    std::array::from_fn(|k| 0.75 * p[k] + 0.125 * (a[k] + b[k]))
}

/// Numbers the new points of the split edges and appends them to `positions`: Loop's edge
/// points (3/8, 3/8, 1/8, 1/8; midpoints on boundary and sharp crease edges).
fn edge_points(
    mesh: &PolyMesh,
    tags: &Tags,
    tris: &[[u32; 3]],
    opposite: &HashMap<(u32, u32), Vec<u32>>,
    split: &mut HashMap<(u32, u32), u32>,
    positions: &mut Vec<[f64; 3]>,
) {
    // New points, in a deterministic order: by first appearance over faces and corners.
    for t in tris {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            if let Some(id) = split.get_mut(&key(a, b)) {
                if *id == u32::MAX {
                    *id = positions.len() as u32;
                    let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
                    let opp = &opposite[&key(a, b)];
                    let sharp = !tags.is_empty() && tags.crease(a, b) >= SHARP;
                    let p = if opp.len() == 2 && !sharp {
                        let (pc, pd) = (
                            mesh.positions[opp[0] as usize],
                            mesh.positions[opp[1] as usize],
                        );
                        std::array::from_fn(|k| 0.375 * (pa[k] + pb[k]) + 0.125 * (pc[k] + pd[k]))
                    } else {
                        std::array::from_fn(|k| 0.5 * (pa[k] + pb[k]))
                    };
                    positions.push(p);
                }
            }
        }
    }
}

/// The refined triangles — red faces 1-to-4, faces with one split edge halved (green), the
/// rest kept — with the parent face of each; counts the red and green faces into `stats`.
fn split_faces(
    tris: &[[u32; 3]],
    red: &[bool],
    split: &HashMap<(u32, u32), u32>,
    stats: &mut RefineStats,
) -> (Vec<[u32; 3]>, Vec<u32>) {
    let mut out = Vec::with_capacity(tris.len() + 3 * split.len());
    let mut parents = Vec::with_capacity(tris.len() + 3 * split.len());
    for (f, (t, &r)) in tris.iter().zip(red).enumerate() {
        let mid = |i: usize| split.get(&key(t[i], t[(i + 1) % 3])).copied();
        if r {
            stats.red += 1;
            let (ab, bc, ca) = (mid(0).unwrap(), mid(1).unwrap(), mid(2).unwrap());
            let [a, b, c] = *t;
            out.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        } else if let Some(i) = (0..3).find(|&i| mid(i).is_some()) {
            stats.green += 1;
            let m = mid(i).unwrap();
            let (a, b, c) = (t[i], t[(i + 1) % 3], t[(i + 2) % 3]);
            out.extend_from_slice(&[[a, m, c], [m, b, c]]);
        } else {
            out.push(*t);
        }
        parents.resize(out.len(), f as u32);
    }
    (out, parents)
}

/// An interior edge `(a, b)` shared by triangles `(a, b, c)` and `(b, a, d)` that may be
/// flipped to `(c, d)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Flip {
    /// Index of the triangle `(a, b, c)`.
    pub face0: u32,
    /// Index of the triangle `(b, a, d)`.
    pub face1: u32,
    /// Edge ends.
    pub a: u32,
    /// Edge ends.
    pub b: u32,
    /// Opposite vertex in `face0`.
    pub c: u32,
    /// Opposite vertex in `face1`.
    pub d: u32,
}

/// Interior edges between two triangles of a cage (all triangles, or mixed: quads and
/// `n`-gons are left alone) whose flip keeps the mesh manifold (no existing edge `(c, d)`,
/// valences of `a` and `b` at least 4 before it), whose two faces both score
/// `≥ threshold`, ordered by decreasing score and chosen so that no two flips change the limit
/// surface on a common face: a flip changes the limit only on faces incident to `a, b, c, d`,
/// so the vertex sets are kept at least two rings apart (rings of faces: vertices sharing a
/// face). Then each flip can be judged on its own faces.
pub fn independent_flips(
    faces: &Polygons,
    num_vertices: usize,
    score: &[f64],
    threshold: f64,
) -> Vec<Flip> {
    let mut edge_face: HashMap<(u32, u32), u32> = HashMap::with_capacity(faces.indices().len());
    let mut valence = vec![0u32; num_vertices];
    // Edge neighbours (for the manifold test) and face neighbours (for the locking).
    let mut neighbors: Vec<Vec<u32>> = vec![Vec::new(); num_vertices];
    let mut face_neighbors: Vec<Vec<u32>> = vec![Vec::new(); num_vertices];
    for (f, t) in faces.iter().enumerate() {
        let n = t.len();
        for i in 0..n {
            let (a, b) = (t[i], t[(i + 1) % n]);
            edge_face.insert((a, b), f as u32);
            if !neighbors[a as usize].contains(&b) {
                neighbors[a as usize].push(b);
                neighbors[b as usize].push(a);
                valence[a as usize] += 1;
                valence[b as usize] += 1;
            }
            for &w in t {
                if w != a && !face_neighbors[a as usize].contains(&w) {
                    face_neighbors[a as usize].push(w);
                }
            }
        }
    }
    let mut cands: Vec<(f64, Flip)> = Vec::new();
    for (f, t) in faces.iter().enumerate() {
        if t.len() != 3 {
            continue;
        }
        for i in 0..3 {
            let (a, b, c) = (t[i], t[(i + 1) % 3], t[(i + 2) % 3]);
            if a > b {
                continue; // each interior edge once
            }
            let Some(&g) = edge_face.get(&(b, a)) else {
                continue;
            };
            let tg = faces.face(FaceId(g));
            if tg.len() != 3 {
                continue;
            }
            let j = (0..3).find(|&j| tg[j] == b).unwrap_or(0);
            let d = tg[(j + 2) % 3];
            let s = score[f].min(score[g as usize]);
            if s.is_nan() || s < threshold || c == d || neighbors[c as usize].contains(&d) {
                continue;
            }
            if valence[a as usize] <= 3 || valence[b as usize] <= 3 {
                continue;
            }
            cands.push((
                s,
                Flip {
                    face0: f as u32,
                    face1: g,
                    a,
                    b,
                    c,
                    d,
                },
            ));
        }
    }
    cands.sort_by(|x, y| y.0.total_cmp(&x.0));
    let mut locked = vec![false; num_vertices];
    let mut chosen = Vec::new();
    for (_, fl) in cands {
        let vs = [fl.a, fl.b, fl.c, fl.d];
        if vs.iter().any(|&v| locked[v as usize]) {
            continue;
        }
        for &v in &vs {
            locked[v as usize] = true;
            for &w in &face_neighbors[v as usize] {
                locked[w as usize] = true;
            }
        }
        chosen.push(fl);
    }
    chosen
}

/// The faces with the given flips applied: `face0` becomes `(a, d, c)` and `face1` becomes
/// `(b, c, d)` (face ids and winding kept; other faces, of any size, unchanged).
pub fn apply_flips(faces: &Polygons, flips: &[Flip]) -> Polygons {
    let mut replaced: HashMap<u32, [u32; 3]> = HashMap::with_capacity(2 * flips.len());
    for fl in flips {
        replaced.insert(fl.face0, [fl.a, fl.d, fl.c]);
        replaced.insert(fl.face1, [fl.b, fl.c, fl.d]);
    }
    let mut out = Polygons::with_capacity(faces.len(), faces.indices().len());
    for (f, face) in faces.iter().enumerate() {
        match replaced.get(&(f as u32)) {
            Some(t) => out.push(t),
            None => out.push(face),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfit_mesh::shapes::octahedron_mesh;
    use subfit_mesh::{HalfEdgeMesh, Tags};
    use subfit_subdiv::{sampling_operator, Options, Scheme};

    /// A triangle cage under Catmull-Clark: each triangle has 3 quad children at level 1, then
    /// 4 per level — not Loop's 4 triangles (this once broke every CC fit of a point cloud,
    /// whose initial cage is all triangles).
    #[test]
    fn face_owners_follow_the_scheme_not_the_cage() {
        let cage = octahedron_mesh(1.0, 1.0, 1.0);
        for (scheme, per_face) in [(Scheme::Loop, 16), (Scheme::CatmullClark, 12)] {
            let op = sampling_operator(
                &cage.faces,
                cage.positions.len(),
                &Tags::new(),
                &Options::new(scheme),
                2,
            )
            .unwrap();
            let owners = face_owners(&cage.faces, &op);
            assert_eq!(owners.len(), op.faces.len(), "{scheme:?}");
            for f in 0..cage.faces.len() as u32 {
                assert_eq!(owners.iter().filter(|&&o| o == f).count(), per_face);
            }
            assert!(owners.windows(2).all(|w| w[0] <= w[1]));
        }
    }

    fn edges_unique(m: &PolyMesh) -> bool {
        HalfEdgeMesh::from_mesh(m).is_ok()
    }

    /// Faces incident to any of `vertices` (sorted, unique).
    fn incident_faces(faces: &Polygons, vertices: &[u32]) -> Vec<u32> {
        faces
            .iter()
            .enumerate()
            .filter(|(_, f)| f.iter().any(|v| vertices.contains(v)))
            .map(|(i, _)| i as u32)
            .collect()
    }

    #[test]
    fn one_marked_face_gives_red_plus_three_green() {
        let m = octahedron_mesh(1.0, 1.0, 1.0);
        let mut marked = vec![false; m.faces.len()];
        marked[0] = true;
        let (r, s) = refine_red_green(&m, &marked).unwrap();
        assert_eq!(s.red, 1);
        assert_eq!(s.green, 3);
        assert_eq!(s.new_points, 3);
        assert_eq!(r.num_vertices(), 9);
        assert_eq!(r.faces.len(), 8 - 4 + 4 + 6);
        assert!(edges_unique(&r));
        let h = HalfEdgeMesh::from_mesh(&r).unwrap();
        assert_eq!(h.genus(), 0);
        assert!(h.boundary_loops().is_empty());
    }

    #[test]
    fn closure_turns_doubly_split_faces_red() {
        let m = octahedron_mesh(1.0, 1.0, 1.0);
        // Two faces sharing only a vertex: their common neighbours get two split edges.
        let marked: Vec<bool> = (0..8).map(|f| f == 0 || f == 2).collect();
        let (r, s) = refine_red_green(&m, &marked).unwrap();
        assert!(s.red > 2, "{s:?}");
        assert!(edges_unique(&r));
        // Every edge of the result is shared by exactly two faces (no T-vertex).
        assert!(HalfEdgeMesh::from_mesh(&r)
            .unwrap()
            .boundary_loops()
            .is_empty());
    }

    #[test]
    fn all_marked_is_uniform_loop_topology() {
        let m = octahedron_mesh(1.0, 2.0, 3.0);
        let (r, s) = refine_red_green(&m, &[true; 8]).unwrap();
        assert_eq!((s.red, s.green, s.new_points), (8, 0, 12));
        assert_eq!(r.faces.len(), 32);
        // Edge points use Loop's mask: on the octahedron with axes (1, 2, 3) the point of edge
        // (+x, +y) is 3/8 (x + y) + 1/8 (+z + −z) = 3/8 (x + y).
        let has = r
            .positions
            .iter()
            .any(|p| (p[0] - 0.375).abs() < 1e-15 && (p[1] - 0.75).abs() < 1e-15 && p[2] == 0.0);
        assert!(has);
        // Refining everything is one uniform Loop step: the same limit surface, exactly.
        let opts = Options::new(Scheme::Loop);
        let a = sampling_operator(&m.faces, 6, &Tags::new(), &opts, 2).unwrap();
        let b = sampling_operator(&r.faces, r.num_vertices(), &Tags::new(), &opts, 1).unwrap();
        let (pa, pb) = (
            a.position.apply(&m.positions),
            b.position.apply(&r.positions),
        );
        // The old vertices keep their ids at every level; compare their limit points.
        for v in 0..6 {
            for k in 0..3 {
                assert!((pa[v][k] - pb[v][k]).abs() < 1e-12, "{v}");
            }
        }
    }

    #[test]
    fn independent_flips_are_two_rings_apart_and_keep_manifold() {
        let m = octahedron_mesh(1.0, 1.0, 1.0);
        let (r, _) = refine_red_green(&m, &[true; 8]).unwrap();
        let (r, _) = refine_red_green(&r, &vec![true; r.faces.len()]).unwrap();
        let score = vec![1.0; r.faces.len()];
        let flips = independent_flips(&r.faces, r.num_vertices(), &score, 0.5);
        assert!(!flips.is_empty());
        for (i, x) in flips.iter().enumerate() {
            for y in &flips[i + 1..] {
                let fx = incident_faces(&r.faces, &[x.a, x.b, x.c, x.d]);
                let fy = incident_faces(&r.faces, &[y.a, y.b, y.c, y.d]);
                assert!(fx.iter().all(|f| !fy.contains(f)));
            }
        }
        let flipped = PolyMesh::new(r.positions.clone(), apply_flips(&r.faces, &flips));
        let h = HalfEdgeMesh::from_mesh(&flipped).unwrap();
        assert_eq!(h.genus(), 0);
        assert!(h.boundary_loops().is_empty());
        // Nothing scores above the threshold: no flip.
        assert!(independent_flips(&r.faces, r.num_vertices(), &score, 2.0).is_empty());
    }

    /// A sharp crease is refined by the crease rules: on an octahedron whose equator
    /// (0–2–1–3) is creased, the equator's points and its new midpoints stay in its plane
    /// (Loop's smooth masks pull them towards the poles), each equator point moves to
    /// (1/8, 3/4, 1/8) of its crease neighbours, and a tagged corner stays.
    #[test]
    fn sharp_creases_refine_by_the_crease_rules() {
        let mesh = subfit_mesh::shapes::octahedron_mesh(1.0, 1.0, 1.0);
        let mut tags = Tags::new();
        for (a, b) in [(0, 2), (2, 1), (1, 3), (3, 0)] {
            tags.set_crease(a, b, subfit_mesh::SHARPNESS_INFINITE);
        }
        tags.set_corner(4, subfit_mesh::SHARPNESS_INFINITE);
        let all = vec![true; mesh.faces.len()];
        let (refined, _, _) = refine_red_green_with_parents(&mesh, &tags, &all).unwrap();
        let (smooth, _) = refine_red_green(&mesh, &all).unwrap();
        let p = &refined.positions;
        for (v, q) in p.iter().enumerate().take(4) {
            assert!(
                q[2].abs() < 1e-15,
                "equator point {v} left its plane: {q:?}"
            );
            // 3/4 of itself and 1/8 of each neighbour on the equator: 0.75 of its radius.
            let r = (q[0] * q[0] + q[1] * q[1]).sqrt();
            assert!((r - 0.75).abs() < 1e-15, "equator point {v} at radius {r}");
        }
        assert_eq!(p[4], mesh.positions[4], "the tagged corner stays");
        assert_ne!(
            smooth.positions[4], mesh.positions[4],
            "Loop's mask moves it"
        );
        // The equator's new points are its edges' midpoints (in its plane); without the tags
        // they are Loop's edge points, pulled off it by the poles.
        let mut on_equator = 0;
        for (q, s) in p.iter().zip(&smooth.positions).skip(6) {
            let r = (q[0] * q[0] + q[1] * q[1]).sqrt();
            if q[2].abs() < 1e-15 && (r - 0.5f64.sqrt()).abs() < 1e-15 {
                on_equator += 1;
                assert_eq!(s[2], 0.0, "the poles balance on the equator");
                assert!((s[0] * s[0] + s[1] * s[1]).sqrt() < r, "{s:?}");
            }
        }
        assert_eq!(on_equator, 4, "four equator midpoints");
    }
}
