//! The orientation and position fields of Jakob, Tarini, Panozzo & Sorkine-Hornung, "Instant
//! field-aligned meshes", SIGGRAPH Asia 2015, §§3–4, on a triangle mesh's vertices.
//!
//! * **Orientation** (§3, 4-RoSy, extrinsic): per vertex a unit tangent `o_i`, standing for the
//!   four directions `±o_i, ±n_i × o_i`. Gauss-Seidel sweeps set each `o_i` to the running
//!   average of its neighbours' representatives closest to it (eq. 3's `compat`), projected
//!   into the tangent plane. Extrinsic smoothness follows the shape: on a cylinder the field
//!   lines up with the axis and the rings. Where the surface is clearly anisotropic the
//!   principal direction of curvature joins the average as one more neighbour, weighted by
//!   its anisotropy ([`Lines::weight`]); crease and boundary vertices are held along their
//!   edge (the field follows feature lines).
//! * **Position** (§4, 4-PoSy): per vertex a lattice point `p_i` of spacing `s` in the frame
//!   `(o_i, n_i × o_i)`; sweeps move `p_i` to the average of the lattice points of its
//!   neighbours nearest to theirs (the `compat` of eq. 7, through the point of the two tangent
//!   planes nearest to both vertices), then round it to the lattice point nearest the vertex.
//!
//! Cost: `O(sweeps · E)` for `E` edges of the mesh; deterministic (vertex order, no hashing).

use subfit_mesh::vec3::{add, cross, dot, norm, normalize, scale, sub};

/// A triangle mesh's vertices with their neighbours (CSR) and unit normals.
#[derive(Clone, Debug)]
pub(crate) struct Graph {
    /// Positions, `#V by 3`.
    pub positions: Vec<[f64; 3]>,
    /// Unit normals, `#V by 3` (area-weighted face normals).
    pub normals: Vec<[f64; 3]>,
    /// `#V + 1` offsets into [`Self::adjacent`].
    pub offsets: Vec<u32>,
    /// Neighbour vertex ids, sorted per vertex.
    pub adjacent: Vec<u32>,
}

impl Graph {
    /// The graph of `tris` over `positions`. Cost `O(T log T)`.
    pub fn new(positions: Vec<[f64; 3]>, tris: &[[u32; 3]]) -> Self {
        let n = positions.len();
        let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(tris.len() * 6);
        let mut normals = vec![[0.0; 3]; n];
        for t in tris {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            let fnormal = cross(sub(b, a), sub(c, a));
            for k in 0..3 {
                let (u, v) = (t[k], t[(k + 1) % 3]);
                pairs.push((u, v));
                pairs.push((v, u));
                normals[u as usize] = add(normals[u as usize], fnormal);
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        let mut offsets = vec![0u32; n + 1];
        for &(u, _) in &pairs {
            offsets[u as usize + 1] += 1;
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let adjacent = pairs.iter().map(|&(_, v)| v).collect();
        let normals = normals
            .into_iter()
            .map(|m| {
                let l = norm(m);
                if l > 0.0 {
                    scale(m, 1.0 / l)
                } else {
                    [0.0, 0.0, 1.0]
                }
            })
            .collect();
        Self {
            positions,
            normals,
            offsets,
            adjacent,
        }
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// The neighbours of `v`.
    pub fn neighbors(&self, v: usize) -> &[u32] {
        &self.adjacent[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }
}

/// Directions the orientation field is drawn to or held at, per vertex.
#[derive(Clone, Debug, Default)]
pub(crate) struct Lines {
    /// A unit tangent per vertex (any of the four rotations), or `None`.
    pub direction: Vec<Option<[f64; 3]>>,
    /// Its weight relative to one neighbour; `f64::INFINITY` holds the vertex at it (creases,
    /// boundaries).
    pub weight: Vec<f64>,
}

/// Projects `v` into the plane of unit normal `n`.
fn tangent(v: [f64; 3], n: [f64; 3]) -> [f64; 3] {
    sub(v, scale(n, dot(v, n)))
}

/// Any unit tangent of the plane of unit normal `n`.
fn any_tangent(n: [f64; 3]) -> [f64; 3] {
    let a = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    normalize(tangent(a, n)).unwrap_or([1.0, 0.0, 0.0])
}

/// Of the four rotations of `o1` about `n1` and of `o0` about `n0`, the pair most nearly
/// parallel (Jakob et al. §3, `compat_orientation_extrinsic_4`).
pub(crate) fn compat_orientation(
    o0: [f64; 3],
    n0: [f64; 3],
    o1: [f64; 3],
    n1: [f64; 3],
) -> ([f64; 3], [f64; 3]) {
    let a = [o0, cross(n0, o0)];
    let b = [o1, cross(n1, o1)];
    let mut best = (-1.0, 0, 0);
    for (i, ai) in a.iter().enumerate() {
        for (j, bj) in b.iter().enumerate() {
            let d = dot(*ai, *bj).abs();
            if d > best.0 {
                best = (d, i, j);
            }
        }
    }
    let (_, i, j) = best;
    let sign = if dot(a[i], b[j]) < 0.0 { -1.0 } else { 1.0 };
    (a[i], scale(b[j], sign))
}

/// `lines`' directions where given, an arbitrary tangent elsewhere.
fn initial_orientation(graph: &Graph, lines: &Lines) -> Vec<[f64; 3]> {
    (0..graph.len())
        .map(|i| {
            let ni = graph.normals[i];
            lines.direction[i]
                .map(|d| tangent(d, ni))
                .filter(|d| norm(*d) > 1e-9)
                .and_then(normalize)
                .unwrap_or_else(|| any_tangent(ni))
        })
        .collect()
}

/// `sweeps` Gauss-Seidel sweeps of the orientation field `o` of `graph` (unit tangents).
fn orientation_sweeps(graph: &Graph, lines: &Lines, o: &mut [[f64; 3]], sweeps: usize) {
    let n = graph.len();
    for _ in 0..sweeps {
        for i in 0..n {
            if lines.weight[i].is_infinite() {
                continue;
            }
            let ni = graph.normals[i];
            let mut sum = o[i];
            let mut weight = 0.0;
            let mut join = |sum: &mut [f64; 3], oj: [f64; 3], nj: [f64; 3], w: f64| {
                let (a, b) = compat_orientation(*sum, ni, oj, nj);
                let s = add(scale(a, weight), scale(b, w));
                weight += w;
                let t = tangent(s, ni);
                let l = norm(t);
                if l > 1e-12 {
                    *sum = scale(t, 1.0 / l);
                }
            };
            for &j in graph.neighbors(i) {
                join(&mut sum, o[j as usize], graph.normals[j as usize], 1.0);
            }
            if let (Some(d), w) = (lines.direction[i], lines.weight[i]) {
                if w > 0.0 {
                    join(&mut sum, d, ni, w);
                }
            }
            o[i] = sum;
        }
    }
}

/// Triangles of `tris` around which the orientation field `o` turns by a quarter (or more):
/// its singularities (Jakob et al. §3: the index of a face). Cost `O(T)`.
pub(crate) fn singular_triangles(graph: &Graph, o: &[[f64; 3]], tris: &[[u32; 3]]) -> usize {
    tris.iter()
        .filter(|t| {
            let mut cur = o[t[0] as usize];
            for k in 1..4 {
                let v = t[k % 3] as usize;
                cur = rotated_to(cur, o[v], graph.normals[v]);
            }
            dot(cur, o[t[0] as usize]) < 0.5
        })
        .count()
}

/// The point of the two tangent planes `(p0, n0)`, `(p1, n1)` nearest to both points (Jakob et
/// al. §4, `middle_point`).
fn middle_point(p0: [f64; 3], n0: [f64; 3], p1: [f64; 3], n1: [f64; 3]) -> [f64; 3] {
    let (n0p0, n0p1) = (dot(n0, p0), dot(n0, p1));
    let (n1p0, n1p1) = (dot(n1, p0), dot(n1, p1));
    let n0n1 = dot(n0, n1);
    let denom = 1.0 / (1.0 - n0n1 * n0n1 + 1e-4);
    let l0 = 2.0 * (n0p1 - n0p0 - n0n1 * (n1p0 - n1p1)) * denom;
    let l1 = 2.0 * (n1p0 - n1p1 - n0n1 * (n0p1 - n0p0)) * denom;
    sub(
        scale(add(p0, p1), 0.5),
        scale(add(scale(n0, l0), scale(n1, l1)), 0.25),
    )
}

/// A vertex's lattice: origin (a lattice point), axes `q` and `t = n × q`, spacing `s`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lattice {
    /// A lattice point.
    pub origin: [f64; 3],
    /// First axis (unit).
    pub q: [f64; 3],
    /// Second axis (unit).
    pub t: [f64; 3],
}

impl Lattice {
    /// The lattice point at integer offset `(a, b)` from the origin, spacing `s`.
    pub fn at(&self, a: f64, b: f64, s: f64) -> [f64; 3] {
        add(self.origin, add(scale(self.q, a * s), scale(self.t, b * s)))
    }

    /// Integer coordinates of the lattice cell below `c` (floor) or nearest (round).
    pub fn index(&self, c: [f64; 3], s: f64, round: bool) -> [f64; 2] {
        let d = sub(c, self.origin);
        let f = |x: f64| if round { x.round() } else { x.floor() };
        [f(dot(self.q, d) / s), f(dot(self.t, d) / s)]
    }
}

/// A lattice point and its integer offset from its lattice's origin.
pub(crate) type LatticePoint = ([f64; 3], [f64; 2]);

/// Of the lattice points of `l0` and of `l1` near the middle point of the two vertices' tangent
/// planes, the pair nearest each other, with their integer offsets from the lattices' origins
/// (Jakob et al. §4, `compat_position_extrinsic_4`); `l1`'s axes must already be matched to
/// `l0`'s ([`compat_orientation`]).
pub(crate) fn compat_position(
    p0: [f64; 3],
    n0: [f64; 3],
    l0: &Lattice,
    p1: [f64; 3],
    n1: [f64; 3],
    l1: &Lattice,
    s: f64,
) -> (LatticePoint, LatticePoint) {
    let middle = middle_point(p0, n0, p1, n1);
    let i0 = l0.index(middle, s, false);
    let i1 = l1.index(middle, s, false);
    let mut best = (f64::INFINITY, ([0.0; 3], [0.0; 2]), ([0.0; 3], [0.0; 2]));
    for a in 0..4 {
        let ia = [i0[0] + (a & 1) as f64, i0[1] + (a >> 1) as f64];
        let x0 = l0.at(ia[0], ia[1], s);
        for b in 0..4 {
            let ib = [i1[0] + (b & 1) as f64, i1[1] + (b >> 1) as f64];
            let x1 = l1.at(ib[0], ib[1], s);
            let d = sub(x0, x1);
            let d2 = dot(d, d);
            if d2 < best.0 {
                best = (d2, (x0, ia), (x1, ib));
            }
        }
    }
    (best.1, best.2)
}

/// The lattice of vertex `i` with axes from `o`.
pub(crate) fn lattice_of(graph: &Graph, o: &[[f64; 3]], p: &[[f64; 3]], i: usize) -> Lattice {
    let n = graph.normals[i];
    Lattice {
        origin: p[i],
        q: o[i],
        t: cross(n, o[i]),
    }
}

/// Of the four rotations of `o1` about `n1`, the one nearest `o0`.
pub(crate) fn rotated_to(o0: [f64; 3], o1: [f64; 3], n1: [f64; 3]) -> [f64; 3] {
    let t1 = cross(n1, o1);
    let (a, b) = (dot(o0, o1), dot(o0, t1));
    if a.abs() >= b.abs() {
        scale(o1, a.signum())
    } else {
        scale(t1, b.signum())
    }
}

/// `l1`'s axes rotated to match `l0`'s (the representative of the 4-RoSy nearest), so that
/// integer offsets in the two lattices count along the same directions.
pub(crate) fn matched(l0: &Lattice, _n0: [f64; 3], l1: &Lattice, n1: [f64; 3]) -> Lattice {
    let q = rotated_to(l0.q, l1.q, n1);
    Lattice {
        origin: l1.origin,
        q,
        t: cross(n1, q),
    }
}

/// `sweeps` Gauss-Seidel sweeps of the position field `p` of `graph` for orientation `o` and
/// spacing `s`; each `p_i` ends at the lattice point nearest its vertex.
fn position_sweeps(graph: &Graph, o: &[[f64; 3]], p: &mut [[f64; 3]], s: &[f64], sweeps: usize) {
    let n = graph.len();
    for _ in 0..sweeps {
        for i in 0..n {
            let (vi, ni) = (graph.positions[i], graph.normals[i]);
            let mut sum = p[i];
            let mut weight = 0.0;
            for &j in graph.neighbors(i) {
                let j = j as usize;
                let li = Lattice {
                    origin: sum,
                    q: o[i],
                    t: cross(ni, o[i]),
                };
                let lj = matched(&li, ni, &lattice_of(graph, o, p, j), graph.normals[j]);
                let ((a, _), (b, _)) = compat_position(
                    vi,
                    ni,
                    &li,
                    graph.positions[j],
                    graph.normals[j],
                    &lj,
                    pair_spacing(s, i, j),
                );
                sum = scale(add(scale(a, weight), b), 1.0 / (weight + 1.0));
                weight += 1.0;
                sum = sub(sum, scale(ni, dot(ni, sub(sum, vi))));
            }
            let l = Lattice {
                origin: sum,
                q: o[i],
                t: cross(ni, o[i]),
            };
            let [a, b] = l.index(vi, s[i], true);
            p[i] = l.at(a, b, s[i]);
        }
    }
}

/// A multiresolution hierarchy of a graph (Jakob et al. §5.1): each level pairs the vertices
/// of the one below along their edges of most similar normals, so that a field solved on the
/// coarse levels first carries its long-range order down in a few sweeps a level (plain
/// Gauss-Seidel needs sweeps in proportion to the squared diameter in edges).
#[derive(Clone, Debug)]
pub(crate) struct Hierarchy {
    /// Level 0 is the working mesh's graph; the last is the coarsest.
    pub levels: Vec<Graph>,
    /// Per level above 0: the parent (in that level) of each vertex of the level below.
    pub parent: Vec<Vec<u32>>,
}

impl Hierarchy {
    /// Coarsens `graph` until a level has at most `coarsest` vertices or stops shrinking.
    /// Cost `O(E log V)` in all.
    pub fn new(graph: Graph, coarsest: usize) -> Self {
        let mut levels = vec![graph];
        let mut parent = Vec::new();
        while let Some(g) = levels.last() {
            if g.len() <= coarsest {
                break;
            }
            let (coarse, up) = coarsen(g);
            if coarse.len() as f64 > 0.9 * g.len() as f64 {
                break;
            }
            parent.push(up);
            levels.push(coarse);
        }
        Self { levels, parent }
    }
}

/// One level up: a greedy matching of `g`'s vertices by normal agreement.
fn coarsen(g: &Graph) -> (Graph, Vec<u32>) {
    let n = g.len();
    let mut edges: Vec<(f64, u32, u32)> = Vec::new();
    for i in 0..n {
        for &j in g.neighbors(i) {
            if (j as usize) > i {
                let d = dot(g.normals[i], g.normals[j as usize]);
                edges.push((-d, i as u32, j));
            }
        }
    }
    edges.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let mut up = vec![u32::MAX; n];
    let mut count = 0u32;
    for &(_, i, j) in &edges {
        if up[i as usize] == u32::MAX && up[j as usize] == u32::MAX {
            up[i as usize] = count;
            up[j as usize] = count;
            count += 1;
        }
    }
    for u in up.iter_mut() {
        if *u == u32::MAX {
            *u = count;
            count += 1;
        }
    }
    let m = count as usize;
    let mut pos = vec![[0.0; 3]; m];
    let mut nrm = vec![[0.0; 3]; m];
    let mut k = vec![0.0; m];
    for (i, &c) in up.iter().enumerate() {
        let c = c as usize;
        pos[c] = add(pos[c], g.positions[i]);
        nrm[c] = add(nrm[c], g.normals[i]);
        k[c] += 1.0;
    }
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    for i in 0..n {
        for &j in g.neighbors(i) {
            let (a, b) = (up[i], up[j as usize]);
            if a != b {
                pairs.push((a, b));
            }
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    let mut offsets = vec![0u32; m + 1];
    for &(a, _) in &pairs {
        offsets[a as usize + 1] += 1;
    }
    for c in 0..m {
        offsets[c + 1] += offsets[c];
    }
    let coarse = Graph {
        positions: pos
            .iter()
            .zip(&k)
            .map(|(p, &w)| scale(*p, 1.0 / w))
            .collect(),
        normals: nrm
            .into_iter()
            .enumerate()
            .map(|(c, v)| normalize(v).unwrap_or(g.normals[first_child(&up, c)]))
            .collect(),
        offsets,
        adjacent: pairs.iter().map(|&(_, b)| b).collect(),
    };
    (coarse, up)
}

fn first_child(up: &[u32], c: usize) -> usize {
    up.iter().position(|&u| u as usize == c).unwrap_or(0)
}

/// `lines` taken one level up (`g` the coarse level): a held child holds its parent;
/// otherwise the children's directions are averaged as 4-RoSy (each turned to the running
/// mean), weighted, and the parent's weight is their mean weight.
fn coarse_lines(lines: &Lines, up: &[u32], g: &Graph) -> Lines {
    let m = g.len();
    let mut out = Lines {
        direction: vec![None; m],
        weight: vec![0.0; m],
    };
    let mut children = vec![0.0f64; m];
    for (i, &c) in up.iter().enumerate() {
        let c = c as usize;
        let w = lines.weight[i];
        children[c] += 1.0;
        if out.weight[c].is_infinite() {
            continue;
        }
        if w.is_infinite() {
            out.weight[c] = w;
            out.direction[c] = lines.direction[i];
            continue;
        }
        let Some(d) = lines.direction[i].filter(|_| w > 0.0) else {
            continue;
        };
        let n = g.normals[c];
        out.direction[c] = Some(match out.direction[c] {
            None => d,
            Some(sum) => {
                let turned = rotated_to(sum, d, n);
                normalize(add(scale(sum, out.weight[c]), scale(turned, w))).unwrap_or(sum)
            }
        });
        out.weight[c] += w;
    }
    for (w, &k) in out.weight.iter_mut().zip(&children) {
        if w.is_finite() && k > 0.0 {
            *w /= k;
        }
    }
    out
}

/// The smooth orientation field of `h`'s finest level: solved on the coarsest from `lines`,
/// then carried down, `sweeps` sweeps a level. Returns a unit tangent per vertex.
pub(crate) fn orientation_field(h: &Hierarchy, lines: &Lines, sweeps: usize) -> Vec<[f64; 3]> {
    let mut all_lines = vec![lines.clone()];
    for (l, up) in h.parent.iter().enumerate() {
        let next = coarse_lines(&all_lines[l], up, &h.levels[l + 1]);
        all_lines.push(next);
    }
    let top = h.levels.len() - 1;
    let mut o = initial_orientation(&h.levels[top], &all_lines[top]);
    orientation_sweeps(&h.levels[top], &all_lines[top], &mut o, sweeps * 4);
    for l in (0..top).rev() {
        let g = &h.levels[l];
        let up = &h.parent[l];
        let held = initial_orientation(g, &all_lines[l]);
        let mut fine: Vec<[f64; 3]> = (0..g.len())
            .map(|i| {
                if all_lines[l].weight[i].is_infinite() {
                    return held[i];
                }
                normalize(tangent(o[up[i] as usize], g.normals[i])).unwrap_or(held[i])
            })
            .collect();
        orientation_sweeps(g, &all_lines[l], &mut fine, sweeps);
        o = fine;
    }
    o
}

/// The spacing between the lattices of vertices `i` and `j`: the mean of theirs.
pub(crate) fn pair_spacing(s: &[f64], i: usize, j: usize) -> f64 {
    0.5 * (s[i] + s[j])
}

/// The position field of `h`'s finest level for its orientation `o` and spacing `s` (per
/// vertex): the coarse levels' orientations taken from their first child and spacings
/// averaged over their children, solved on the coarsest, carried down, `sweeps` sweeps a
/// level. Returns per vertex the lattice point nearest it.
pub(crate) fn position_field(
    h: &Hierarchy,
    o: &[[f64; 3]],
    s: &[f64],
    sweeps: usize,
) -> Vec<[f64; 3]> {
    let mut all_s = vec![s.to_vec()];
    for (l, up) in h.parent.iter().enumerate() {
        let m = h.levels[l + 1].len();
        let (mut sum, mut k) = (vec![0.0; m], vec![0.0; m]);
        for (i, &c) in up.iter().enumerate() {
            sum[c as usize] += all_s[l][i];
            k[c as usize] += 1.0;
        }
        all_s.push(sum.iter().zip(&k).map(|(a, b)| a / b).collect());
    }
    let mut all_o = vec![o.to_vec()];
    for (l, up) in h.parent.iter().enumerate() {
        let g = &h.levels[l + 1];
        let mut co = vec![[0.0; 3]; g.len()];
        let mut set = vec![false; g.len()];
        for (i, &c) in up.iter().enumerate() {
            if !set[c as usize] {
                set[c as usize] = true;
                let n = g.normals[c as usize];
                co[c as usize] =
                    normalize(tangent(all_o[l][i], n)).unwrap_or_else(|| any_tangent(n));
            }
        }
        all_o.push(co);
    }
    let top = h.levels.len() - 1;
    let mut p = h.levels[top].positions.clone();
    position_sweeps(&h.levels[top], &all_o[top], &mut p, &all_s[top], sweeps * 4);
    for l in (0..top).rev() {
        let g = &h.levels[l];
        let up = &h.parent[l];
        let mut fine: Vec<[f64; 3]> = (0..g.len())
            .map(|i| {
                let (v, n) = (g.positions[i], g.normals[i]);
                let q = p[up[i] as usize];
                sub(q, scale(n, dot(n, sub(q, v))))
            })
            .collect();
        position_sweeps(g, &all_o[l], &mut fine, &all_s[l], sweeps);
        p = fine;
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat grid of `k × k` vertices, spacing `h`, two triangles a cell.
    fn grid(k: usize, h: f64) -> Graph {
        let positions = (0..k * k)
            .map(|v| [(v % k) as f64 * h, (v / k) as f64 * h, 0.0])
            .collect();
        let mut tris = Vec::new();
        for y in 0..k - 1 {
            for x in 0..k - 1 {
                let v = (y * k + x) as u32;
                let k = k as u32;
                tris.push([v, v + 1, v + k + 1]);
                tris.push([v, v + k + 1, v + k]);
            }
        }
        Graph::new(positions, &tris)
    }

    #[test]
    fn orientation_on_a_plane_becomes_one_direction_modulo_quarter_turns() {
        let g = grid(12, 0.1);
        // Start from directions turning with x: the smooth field has one direction.
        let lines = Lines {
            direction: (0..g.len())
                .map(|v| {
                    let a = (v % 12) as f64 * 0.3 + (v / 12) as f64 * 0.1;
                    Some([a.cos(), a.sin(), 0.0])
                })
                .collect(),
            weight: vec![0.0; g.len()],
        };
        let o = orientation_field(&Hierarchy::new(g.clone(), 8), &lines, 30);
        for i in 0..g.len() {
            for &j in g.neighbors(i) {
                let (a, b) = compat_orientation(o[i], g.normals[i], o[j as usize], [0.0, 0.0, 1.0]);
                assert!(dot(a, b) > 0.999, "{i}-{j}: {}", dot(a, b));
            }
        }
    }

    #[test]
    fn position_field_on_a_plane_is_one_lattice() {
        let g = grid(15, 0.1);
        let o = vec![[1.0, 0.0, 0.0]; g.len()];
        let s = 0.33;
        let p = position_field(&Hierarchy::new(g.clone(), 8), &o, &vec![s; g.len()], 30);
        // Every lattice point is one lattice: offsets between them are multiples of s.
        for q in &p {
            let d = sub(*q, p[0]);
            for x in [d[0], d[1]] {
                let r = x / s - (x / s).round();
                assert!(r.abs() < 1e-6, "{q:?} off the lattice of {:?}", p[0]);
            }
            assert!(d[2].abs() < 1e-12);
        }
        // And each is the lattice point nearest its vertex.
        for (v, q) in g.positions.iter().zip(&p) {
            assert!((v[0] - q[0]).abs() <= s / 2.0 + 1e-9 && (v[1] - q[1]).abs() <= s / 2.0 + 1e-9);
        }
    }
}
