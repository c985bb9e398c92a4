//! Edge rotations that move a quad cage's valences towards regular (module step 7).
//!
//! Two quads sharing an interior edge `(a, b)` form a hexagon `b c d a e f`; the edge can be
//! turned to either of the hexagon's other two long diagonals, `(c, e)` or `(d, f)` — the
//! quad-mesh counterpart of a triangle edge flip (Bommes et al. 2013, "Quad-mesh generation
//! and processing: a survey", §6.1, connectivity editing by edge rotation). `a` and `b` lose
//! one edge each, the ends of the new diagonal gain one, so the total deviation from regular
//! valence (4 inside; on a boundary one more than the
//! quarter turns in the boundary's angle there) changes by at most 4: when `a`, `b` are of
//! valence 5 and the new ends of valence 3, four irregular vertices become regular without a vertex
//! added or removed. A lone rotation of a valence-3/5 pair only moves it along, so pairs that
//! must meet before they cancel are searched for as sequences of up to [`MAX_DEPTH`]
//! rotations (depth first from the faces at irregular vertices) whose gains add up to more
//! than zero.
//!
//! A sequence found is taken only if the cage stays a good quad mesh there: the vertices of
//! the rotated quads are relaxed towards their neighbours' centroid and projected back onto
//! the surface ([`RELAX_SWEEPS`] sweeps), and every quad around them must keep its corners
//! convex and facing the surface ([`MIN_CORNER_SINE`]; where quads were already worse, no more
//! of them and none worse than the worst before). Otherwise the
//! sequence is undone and its first rotation not tried again.
//!
//! Measured: see the parent module (Keenan Crane's Bob at 334, 26 → 17 irregular vertices;
//! fitted as Catmull-Clark at that count, two-sided RMS / Hausdorff 0.018 % / 0.15 % of the
//! diagonal before and after). Fertility at 600 goes 111 → 94, but its rotated cage fits
//! worse on Hausdorff (0.32 % against 0.22 % of the diagonal), so the fit keeps the paired
//! QEM cage there (0.25 %); why the rotated cage fits worse there is not yet measured.
//! The paired QEM cage ([`crate::InitOptions::rotate_edges`]) gets the same rotations, its
//! creases and corners kept. Catmull-Clark at a fixed count (irregular vertices and two-sided
//! RMS / Hausdorff, % of the diagonal, paired → paired and rotated): Fertility at 600
//! 292 → 126, 0.030 / 0.253 → 0.030 / 0.272; Igea at 600 328 → 113, 0.061 / 0.715 → 0.067 /
//! 0.630; the rocker arm at 500 264 → 123, 0.039 / 0.573 → 0.035 / 0.538; the 3,485-vertex
//! bunny at 479 269 → 116, 0.069 / 0.587 → 0.069 / 0.553; the Stanford bunny all quads
//! (`--quads only`) at ≤ 479, 445 points, Hausdorff 0.557 → 0.489 (QuadriFlow's 463-vertex
//! cage fitted the same way: 1.48; irregular vertices: ours 77, QuadriFlow's 62).
//! With quads already folded in a region, the sequence must not add to them (the depth-first
//! search otherwise trades one fold for several).
//!
//! Cost: passes over the faces at irregular vertices, each searched from until it yields
//! nothing; a search tries up to `b^d` rotations, `b` ≈ 40 (the interior edges near two
//! quads, two rotations each), `d` = [`MAX_DEPTH`], but only through steps that keep the
//! deviation (gain 0), so far fewer in practice; at most `4 · deviation + 64` sequences are
//! taken or undone. Bob at 334: 1.6 → 2.0 s for `quad_cage` (every take rotated).

use std::collections::{HashMap, HashSet};

use subfit_mesh::bvh::TriangleBvh;
use subfit_mesh::vec3::{add, cross, dot, norm, scale, sub};
use subfit_mesh::{PolyMesh, Polygons, Tags};

/// Rotations in one improving sequence at most.
pub const MAX_DEPTH: usize = 5;

/// Smallest cosine between the surface normals at a relaxed vertex's new and old places.
const SAME_SHEET: f64 = 0.5;

/// Relaxation sweeps over the vertices of a sequence's quads.
pub const RELAX_SWEEPS: usize = 6;

/// Smallest sine of a corner angle (30°) of a quad around a rotated edge after the
/// relaxation, signed against the surface's normal: a sequence that leaves a quad folded or
/// needle-like is undone (unless the quads there were already worse).
const MIN_CORNER_SINE: f64 = 0.5;

/// `cage` (on the surface `surface`, same coordinates) with interior quad–quad edges
/// rotated, and the vertices around them relaxed on the surface, while that lowers the
/// deviation from regular valence (see the module docs). The vertex count and every face that
/// is not a quad are kept; so are `tags`' creases (never rotated away) and the vertices on
/// them or tagged as corners (never moved). Returns the cage and the number of rotations.
pub fn rotate_for_valence(
    cage: &PolyMesh,
    surface: &TriangleBvh,
    tags: &Tags,
) -> (PolyMesh, usize) {
    let mut editor = Editor::new(cage, surface, tags);
    let mut rotations = 0;
    // Every sequence taken lowers the total deviation; every one undone is not tried again.
    let mut tries = 4 * editor.total_deviation() + 64;
    // Passes over the faces at irregular vertices, each searched from until it yields
    // nothing more; until a pass changes nothing.
    let mut changed = true;
    while changed && tries > 0 {
        changed = false;
        let starts: Vec<usize> = (0..editor.faces.len())
            .filter(|&f| editor.at_irregular(f))
            .collect();
        for f in starts {
            while tries > 0 && editor.at_irregular(f) {
                let Some(sequence) = editor.improve(&[f], MAX_DEPTH, 0) else {
                    break;
                };
                tries -= 1;
                if editor.relax_and_check(&sequence) {
                    rotations += sequence.len();
                    changed = true;
                } else {
                    for r in sequence.iter().rev() {
                        editor.set(r, true);
                    }
                    editor.tabu.insert(sequence[0].key());
                }
            }
        }
    }
    let mut polygons = Polygons::with_capacity(editor.faces.len(), 4 * editor.faces.len());
    for f in &editor.faces {
        polygons.push(f);
    }
    let mut out = cage.clone();
    out.positions = editor.positions;
    out.faces = polygons;
    (out, rotations)
}

/// A cage's connectivity under edit: faces, their directed edges, valences.
struct Editor<'a> {
    surface: &'a TriangleBvh,
    positions: Vec<[f64; 3]>,
    faces: Vec<Vec<u32>>,
    /// Faces at each vertex.
    vertex_faces: Vec<Vec<usize>>,
    /// Directed edge → the face it bounds.
    directed: HashMap<(u32, u32), usize>,
    /// Undirected edges (lower index first).
    edges: HashSet<(u32, u32)>,
    valence: Vec<i32>,
    /// Creases: never rotated away.
    locked_edges: HashSet<(u32, u32)>,
    /// Vertices on a crease, tagged corners, boundary vertices: never moved.
    pinned: Vec<bool>,
    /// The regular valence of each vertex: 4 inside; on a boundary, one more than the
    /// quarter turns in its angle (2 at a right-angled corner, 3 along a straight edge).
    regular: Vec<i32>,
    /// First rotations of sequences that were undone.
    tabu: HashSet<(usize, usize, u32, u32)>,
}

/// One rotation of the edge between faces `faces`: their new quads, the old ones kept for
/// undoing it, and what it does to the total deviation.
struct Rotation {
    faces: [usize; 2],
    old: [Vec<u32>; 2],
    new: [[u32; 4]; 2],
    gain: i32,
}

impl Rotation {
    fn key(&self) -> (usize, usize, u32, u32) {
        let (u, w) = key(self.new[0][0], self.new[0][3]);
        (self.faces[0], self.faces[1], u, w)
    }
}

impl<'a> Editor<'a> {
    fn new(cage: &PolyMesh, surface: &'a TriangleBvh, tags: &Tags) -> Self {
        let faces: Vec<Vec<u32>> = cage.faces.iter().map(|f| f.to_vec()).collect();
        let n = cage.num_vertices();
        let mut edges = HashSet::new();
        let mut directed = HashMap::new();
        let mut vertex_faces = vec![Vec::new(); n];
        for (fi, f) in faces.iter().enumerate() {
            for k in 0..f.len() {
                let (a, b) = (f[k], f[(k + 1) % f.len()]);
                edges.insert(key(a, b));
                directed.insert((a, b), fi);
                vertex_faces[a as usize].push(fi);
            }
        }
        let mut boundary = vec![false; n];
        for &(a, b) in directed.keys() {
            if !directed.contains_key(&(b, a)) {
                boundary[a as usize] = true;
                boundary[b as usize] = true;
            }
        }
        let mut angle = vec![0.0; n];
        for f in &faces {
            for k in 0..f.len() {
                let c = cage.positions[f[k] as usize];
                let next = sub(cage.positions[f[(k + 1) % f.len()] as usize], c);
                let prev = sub(cage.positions[f[(k + f.len() - 1) % f.len()] as usize], c);
                angle[f[k] as usize] += norm(cross(next, prev)).atan2(dot(next, prev));
            }
        }
        let regular = (0..n)
            .map(|v| {
                if boundary[v] {
                    ((angle[v] / std::f64::consts::FRAC_PI_2).round() as i32 + 1).max(2)
                } else {
                    4
                }
            })
            .collect();
        let mut valence = vec![0i32; n];
        for &(a, b) in &edges {
            valence[a as usize] += 1;
            valence[b as usize] += 1;
        }
        let mut pinned = boundary;
        let mut locked_edges = HashSet::new();
        for ((a, b), _) in tags.creases() {
            locked_edges.insert(key(a, b));
            for v in [a, b] {
                if let Some(p) = pinned.get_mut(v as usize) {
                    *p = true;
                }
            }
        }
        for (v, _) in tags.corners() {
            if let Some(p) = pinned.get_mut(v as usize) {
                *p = true;
            }
        }
        Self {
            surface,
            positions: cage.positions.clone(),
            faces,
            vertex_faces,
            directed,
            edges,
            valence,
            locked_edges,
            pinned,
            regular,
            tabu: HashSet::new(),
        }
    }

    /// Deviation of `v` from regular valence after its valence changes by `d`.
    fn deviation(&self, v: u32, d: i32) -> i32 {
        (self.valence[v as usize] + d - self.regular[v as usize]).abs()
    }

    /// Whether face `f` has an irregular corner.
    fn at_irregular(&self, f: usize) -> bool {
        self.faces[f].iter().any(|&v| self.deviation(v, 0) > 0)
    }

    fn total_deviation(&self) -> usize {
        (0..self.valence.len() as u32)
            .map(|v| self.deviation(v, 0) as usize)
            .sum()
    }

    /// The interior edges of faces `fs` and of the faces next to them, each once, in a
    /// fixed order.
    fn edges_near(&self, fs: &[usize]) -> Vec<(u32, u32)> {
        let mut near: Vec<usize> = fs.to_vec();
        for &f in fs {
            let q = &self.faces[f];
            for k in 0..q.len() {
                if let Some(&g) = self.directed.get(&(q[(k + 1) % q.len()], q[k])) {
                    near.push(g);
                }
            }
        }
        near.sort_unstable();
        near.dedup();
        let mut out: Vec<(u32, u32)> = near
            .iter()
            .flat_map(|&f| {
                let q = &self.faces[f];
                (0..q.len()).map(move |k| key(q[k], q[(k + 1) % q.len()]))
            })
            .filter(|&(a, b)| {
                self.directed.contains_key(&(a, b)) && self.directed.contains_key(&(b, a))
            })
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The rotations of edge `(a, b)` that keep the cage a manifold (both faces quads, six
    /// distinct hexagon corners, the new diagonal not an edge already).
    fn rotations(&self, a: u32, b: u32) -> Vec<Rotation> {
        let (Some(&f1), Some(&f2)) = (self.directed.get(&(a, b)), self.directed.get(&(b, a)))
        else {
            return Vec::new();
        };
        if self.faces[f1].len() != 4
            || self.faces[f2].len() != 4
            || self.locked_edges.contains(&key(a, b))
        {
            return Vec::new();
        }
        let q1 = starting_at(&self.faces[f1], a);
        let q2 = starting_at(&self.faces[f2], b);
        // The hexagon b c d a e f, oriented as the two quads.
        let h = [b, q1[2], q1[3], a, q2[2], q2[3]];
        if !distinct(&h) {
            return Vec::new();
        }
        let mut out = Vec::new();
        for s in [1, 2] {
            let (u, w) = (h[s], h[s + 3]);
            if self.edges.contains(&key(u, w)) {
                continue;
            }
            let gain = self.deviation(a, 0)
                + self.deviation(b, 0)
                + self.deviation(u, 0)
                + self.deviation(w, 0)
                - self.deviation(a, -1)
                - self.deviation(b, -1)
                - self.deviation(u, 1)
                - self.deviation(w, 1);
            let r = Rotation {
                faces: [f1, f2],
                old: [self.faces[f1].clone(), self.faces[f2].clone()],
                new: [
                    [h[s], h[s + 1], h[s + 2], h[s + 3]],
                    [h[s + 3], h[(s + 4) % 6], h[(s + 5) % 6], h[s]],
                ],
                gain,
            };
            if !self.tabu.contains(&r.key()) {
                out.push(r);
            }
        }
        out
    }

    /// Gives a rotation's faces their new quads, or (`undo`) their old ones back.
    fn set(&mut self, r: &Rotation, undo: bool) {
        for &f in &r.faces {
            let q = std::mem::take(&mut self.faces[f]);
            for k in 0..q.len() {
                let (a, b) = (q[k], q[(k + 1) % q.len()]);
                self.directed.remove(&(a, b));
                self.vertex_faces[a as usize].retain(|&g| g != f);
                if self.edges.remove(&key(a, b)) {
                    self.valence[a as usize] -= 1;
                    self.valence[b as usize] -= 1;
                }
            }
        }
        for (i, &f) in r.faces.iter().enumerate() {
            let q: Vec<u32> = if undo {
                r.old[i].clone()
            } else {
                r.new[i].to_vec()
            };
            for k in 0..q.len() {
                let (a, b) = (q[k], q[(k + 1) % q.len()]);
                self.directed.insert((a, b), f);
                self.vertex_faces[a as usize].push(f);
                if self.edges.insert(key(a, b)) {
                    self.valence[a as usize] += 1;
                    self.valence[b as usize] += 1;
                }
            }
            self.faces[f] = q;
        }
    }

    /// Searches, depth first from the interior edges near faces `fs`, for a sequence of at
    /// most `depth` rotations whose gains add up (with `gained` so far) to more than zero;
    /// leaves it applied and returns it in order.
    fn improve(&mut self, fs: &[usize], depth: usize, gained: i32) -> Option<Vec<Rotation>> {
        // Within a sequence (`fs` the last rotation's two faces), the same two faces are not
        // turned again: that only undoes or redoes the last step.
        let candidates: Vec<Rotation> = self
            .edges_near(fs)
            .into_iter()
            .flat_map(|(a, b)| self.rotations(a, b))
            .filter(|r| !(fs.len() == 2 && fs.contains(&r.faces[0]) && fs.contains(&r.faces[1])))
            .collect();
        // A rotation that completes a sequence here is taken before any deeper search, the
        // one that gains most first.
        let best = candidates
            .iter()
            .enumerate()
            .filter(|(_, r)| gained + r.gain > 0)
            .max_by_key(|&(i, r)| (r.gain, std::cmp::Reverse(i)));
        if let Some((i, _)) = best {
            let r = candidates.into_iter().nth(i)?;
            self.set(&r, false);
            return Some(vec![r]);
        }
        if depth == 1 {
            return None;
        }
        for r in candidates {
            // Steps before the last only move defects (gain 0): a step that adds defects
            // widens the search by ~100× per level and, measured, found no better cages.
            if gained + r.gain < 0 {
                continue;
            }
            self.set(&r, false);
            if let Some(mut rest) = self.improve(&r.faces, depth - 1, gained + r.gain) {
                rest.insert(0, r);
                return Some(rest);
            }
            self.set(&r, true);
        }
        None
    }

    /// Relaxes the interior vertices of the applied `sequence`'s quads on the surface; true
    /// when every face at them is then good (see the module docs), otherwise the positions
    /// are restored and false returned (the rotations are left for the caller to undo).
    fn relax_and_check(&mut self, sequence: &[Rotation]) -> bool {
        let mut moved: Vec<u32> = sequence
            .iter()
            .flat_map(|r| r.new.iter().flatten().copied())
            .filter(|&v| !self.pinned[v as usize])
            .collect();
        moved.sort_unstable();
        moved.dedup();
        let mut around: Vec<usize> = moved
            .iter()
            .flat_map(|&v| self.vertex_faces[v as usize].iter().copied())
            .collect();
        around.sort_unstable();
        around.dedup();
        let saved: Vec<[f64; 3]> = moved.iter().map(|&v| self.positions[v as usize]).collect();
        let after_faces: Vec<Vec<u32>> = around.iter().map(|&f| self.faces[f].clone()).collect();
        // The quality before: the same faces with the rotations undone.
        for r in sequence.iter().rev() {
            self.set(r, true);
        }
        let before = self.corners(&around);
        for r in sequence {
            self.set(r, false);
        }
        debug_assert!(around
            .iter()
            .zip(&after_faces)
            .all(|(&f, q)| &self.faces[f] == q));
        // Each vertex stays on its own sheet: a move whose foot point faces away from the
        // surface where the vertex was (the other side of a thin part) is not made.
        let sheets: Vec<Option<[f64; 3]>> = moved
            .iter()
            .map(|&v| {
                self.surface
                    .closest(self.positions[v as usize])
                    .map(|hit| hit.face_normal)
            })
            .collect();
        for _ in 0..RELAX_SWEEPS {
            for (&v, sheet) in moved.iter().zip(&sheets) {
                let c = self.neighbour_centroid(v);
                match (self.surface.closest(c), sheet) {
                    (Some(hit), Some(n)) if dot(hit.face_normal, *n) > SAME_SHEET => {
                        self.positions[v as usize] = hit.point;
                    }
                    _ => {}
                }
            }
        }
        let after = self.corners(&around);
        if after.0 >= MIN_CORNER_SINE.min(before.0) && after.1 <= before.1 {
            return true;
        }
        for (&v, &p) in moved.iter().zip(&saved) {
            self.positions[v as usize] = p;
        }
        false
    }

    /// Centroid of the vertices sharing an edge with `v`.
    fn neighbour_centroid(&self, v: u32) -> [f64; 3] {
        let mut sum = [0.0; 3];
        let mut count = 0.0;
        for &f in &self.vertex_faces[v as usize] {
            let q = &self.faces[f];
            if let Some(k) = q.iter().position(|&x| x == v) {
                // Each edge at an interior vertex is in two faces: once as the next corner.
                sum = add(sum, self.positions[q[(k + 1) % q.len()] as usize]);
                count += 1.0;
            }
        }
        if count == 0.0 {
            self.positions[v as usize]
        } else {
            scale(sum, 1.0 / count)
        }
    }

    /// The smallest corner sine over the faces `fs` (each against the surface normal
    /// nearest its centroid) and how many of them fall below [`MIN_CORNER_SINE`].
    fn corners(&self, fs: &[usize]) -> (f64, usize) {
        let sines: Vec<f64> = fs
            .iter()
            .map(|&f| {
                let q = &self.faces[f];
                let centroid = scale(
                    q.iter()
                        .fold([0.0; 3], |s, &v| add(s, self.positions[v as usize])),
                    1.0 / q.len() as f64,
                );
                let normal = match self.surface.closest(centroid) {
                    Some(hit) if norm(hit.face_normal) > 0.0 => hit.face_normal,
                    _ => newell(&self.positions, q),
                };
                min_corner_sine(&self.positions, q, normal)
            })
            .collect();
        let worst = sines.iter().copied().fold(f64::INFINITY, f64::min);
        (
            worst,
            sines.iter().filter(|&&x| x < MIN_CORNER_SINE).count(),
        )
    }
}

fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

fn distinct(h: &[u32; 6]) -> bool {
    (0..6).all(|i| (i + 1..6).all(|j| h[i] != h[j]))
}

/// The quad `q` cycled so that it starts at `v` (which it contains).
fn starting_at(q: &[u32], v: u32) -> [u32; 4] {
    let k = q.iter().position(|&x| x == v).unwrap_or(0);
    std::array::from_fn(|i| q[(k + i) % 4])
}

/// Newell's (area-weighted) normal of a polygon.
fn newell(p: &[[f64; 3]], f: &[u32]) -> [f64; 3] {
    let mut n = [0.0; 3];
    for k in 0..f.len() {
        let (a, b) = (p[f[k] as usize], p[f[(k + 1) % f.len()] as usize]);
        n = add(n, cross(a, b));
    }
    n
}

/// Smallest sine of a corner angle of polygon `q`, signed by the side of `normal` the corner
/// turns to (negative: a reflex or folded corner).
fn min_corner_sine(p: &[[f64; 3]], q: &[u32], normal: [f64; 3]) -> f64 {
    let nn = norm(normal);
    if nn == 0.0 {
        return -1.0;
    }
    let m = q.len();
    (0..m)
        .map(|k| {
            let c = p[q[k] as usize];
            let next = sub(p[q[(k + 1) % m] as usize], c);
            let prev = sub(p[q[(k + m - 1) % m] as usize], c);
            let l = norm(next) * norm(prev) * nn;
            if l == 0.0 {
                -1.0
            } else {
                dot(cross(next, prev), normal) / l
            }
        })
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cross_field::irregular_vertices;

    /// The `n × n`-vertex unit grid on the plane z = 0: its quads and, as the surface, its
    /// triangles.
    fn grid(n: usize) -> (Vec<[f64; 3]>, Vec<[u32; 4]>, TriangleBvh) {
        let positions: Vec<[f64; 3]> = (0..n * n)
            .map(|i| [(i % n) as f64, (i / n) as f64, 0.0])
            .collect();
        let v = |x: usize, y: usize| (y * n + x) as u32;
        let mut quads = Vec::new();
        let mut tris = Vec::new();
        for y in 0..n - 1 {
            for x in 0..n - 1 {
                let q = [v(x, y), v(x + 1, y), v(x + 1, y + 1), v(x, y + 1)];
                quads.push(q);
                tris.push([q[0], q[1], q[2]]);
                tris.push([q[0], q[2], q[3]]);
            }
        }
        let surface = TriangleBvh::new(positions.clone(), tris);
        (positions, quads, surface)
    }

    /// Turns the edge shared by the quads at `(x, y)` and `(x + 1, y)` of the `n × n` grid of
    /// [`grid`] to the hexagon's diagonal: two vertices of valence 5, two of valence 3.
    fn twist(quads: &mut [[u32; 4]], n: usize, x: usize, y: usize) {
        let v = |x: usize, y: usize| (y * n + x) as u32;
        let i = quads.iter().position(|q| q[0] == v(x, y)).unwrap();
        let j = quads.iter().position(|q| q[0] == v(x + 1, y)).unwrap();
        quads[i] = [v(x, y), v(x + 1, y), v(x + 2, y), v(x + 2, y + 1)];
        quads[j] = [v(x + 2, y + 1), v(x + 1, y + 1), v(x, y + 1), v(x, y)];
    }

    /// Two quads of a regular grid with their shared edge turned to the hexagon's diagonal:
    /// two vertices of valence 5, two of valence 3. One sequence makes the grid regular again
    /// with every quad convex, and the relaxed vertices stay on the surface.
    #[test]
    fn a_rotated_edge_in_a_grid_is_turned_back() {
        let n = 5;
        let (positions, mut quads, surface) = grid(n);
        twist(&mut quads, n, 1, 1);
        let twisted = PolyMesh::new(positions, Polygons::from_quads(&quads));
        assert_eq!(irregular_vertices(&twisted), 4);
        let (fixed, rotations) = rotate_for_valence(&twisted, &surface, &Tags::new());
        // One sequence (the search may first move the pair before cancelling it).
        assert!(
            (1..=MAX_DEPTH).contains(&rotations),
            "{rotations} rotations"
        );
        assert_eq!(irregular_vertices(&fixed), 0);
        assert_eq!(fixed.num_vertices(), twisted.num_vertices());
        for q in fixed.faces.iter() {
            assert!(min_corner_sine(&fixed.positions, q, [0.0, 0.0, 1.0]) > 0.5);
        }
        assert!(fixed.positions.iter().all(|p| p[2].abs() < 1e-12));
    }

    /// A regular grid has nothing to improve: no rotation, no vertex moved.
    #[test]
    fn a_regular_grid_is_left_as_it_is() {
        let (positions, quads, surface) = grid(6);
        let cage = PolyMesh::new(positions, Polygons::from_quads(&quads));
        let (same, rotations) = rotate_for_valence(&cage, &surface, &Tags::new());
        assert_eq!(rotations, 0);
        assert_eq!(same.positions, cage.positions);
        assert_eq!(same.faces.indices(), cage.faces.indices());
    }

    /// Two twisted pairs that cancel only together: the pass needs a sequence, and the
    /// relaxation must keep every quad convex.
    #[test]
    fn two_pairs_apart_are_cancelled_and_no_quad_folds() {
        let n = 8;
        let (positions, mut quads, surface) = grid(n);
        for (x, y) in [(1, 1), (4, 4)] {
            twist(&mut quads, n, x, y);
        }
        let twisted = PolyMesh::new(positions, Polygons::from_quads(&quads));
        assert_eq!(irregular_vertices(&twisted), 8);
        let (fixed, _) = rotate_for_valence(&twisted, &surface, &Tags::new());
        assert_eq!(irregular_vertices(&fixed), 0);
        for q in fixed.faces.iter() {
            assert!(min_corner_sine(&fixed.positions, q, [0.0, 0.0, 1.0]) > 0.5);
        }
    }

    /// A tagged crease is never rotated away and the vertices on it never move, though
    /// rotating it is what would make the grid regular (the first test).
    #[test]
    fn a_crease_is_kept_and_its_vertices_stay() {
        let n = 5;
        let v = |x: usize, y: usize| (y * n + x) as u32;
        let (positions, mut quads, surface) = grid(n);
        twist(&mut quads, n, 1, 1);
        let twisted = PolyMesh::new(positions, Polygons::from_quads(&quads));
        let mut tags = Tags::new();
        tags.set_crease(v(1, 1), v(3, 2), 10.0);
        let (out, _) = rotate_for_valence(&twisted, &surface, &tags);
        let has_edge = out.faces.iter().any(|q| {
            (0..q.len()).any(|k| key(q[k], q[(k + 1) % q.len()]) == key(v(1, 1), v(3, 2)))
        });
        assert!(has_edge, "the crease was rotated away");
        for w in [v(1, 1), v(3, 2)] {
            assert_eq!(out.positions[w as usize], twisted.positions[w as usize]);
        }
    }
}
