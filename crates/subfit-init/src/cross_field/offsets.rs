//! Integer offsets between the lattice points of neighbouring vertices, and the removal of
//! the position field's singularities (Huang, Zhou, Niessner, Guibas & Zhou, "QuadriFlow: a
//! scalable and robust method for quadrangulation", SGP 2018, §4.2).
//!
//! Each mesh edge `a → b` (`a < b`) carries the integer vector `d` from `a`'s lattice point
//! to `b`'s in `a`'s lattice frame. Around a triangle where the orientation field turns by no
//! quarter turn, the three vectors (carried into one frame) sum to zero unless the position
//! field has a singularity there: a dislocation, a row of lattice cells that ends. Every
//! dislocation becomes an irregular vertex pair or a left-over triangle in the cage.
//! QuadriFlow removes them with a minimum-cost flow; here each is paired greedily with the
//! nearest triangle that cancels it (an opposite dislocation, an orientation singularity, or
//! the mesh boundary) by a breadth-first search over the triangles, and the offsets of the
//! edges crossed on the way are changed so that every triangle between is consistent. What
//! was a dislocation is then a lattice row that thins out over the path's cells.
//!
//! Cost: `O(E log E)` for the offsets; `O(D · B)` for `D` dislocations and searches of at
//! most `B` triangles ([`SEARCH_TRIANGLES`]).

use std::collections::VecDeque;

use subfit_mesh::vec3::dot;

use super::field::{compat_position, lattice_of, matched, pair_spacing, Graph};

/// Most triangles one search for a dislocation's partner visits.
pub(crate) const SEARCH_TRIANGLES: usize = 50_000;

/// The offsets of a mesh's edges, and its triangles' adjacency.
pub(crate) struct Offsets {
    /// Edges `(a, b)`, `a < b`, sorted.
    edges: Vec<(u32, u32)>,
    /// Per edge: the vector from `a`'s lattice point to `b`'s, in `a`'s frame.
    d: Vec<[i32; 2]>,
    /// Per vertex: its lattice frame's first axis.
    q: Vec<[f64; 3]>,
    /// Per vertex: second axis.
    t: Vec<[f64; 3]>,
}

/// Quarter turns `k` such that `k` turns of `b`'s frame (`qb`, `tb`) give the axis nearest `qa`.
fn turns(qa: [f64; 3], qb: [f64; 3], tb: [f64; 3]) -> u8 {
    let (x, y) = (dot(qa, qb), dot(qa, tb));
    if x.abs() >= y.abs() {
        if x >= 0.0 {
            0
        } else {
            2
        }
    } else if y >= 0.0 {
        1
    } else {
        3
    }
}

/// Integer coordinates `v` in a frame, in the frame turned `k` quarter turns from it.
fn turn(v: [i32; 2], k: u8) -> [i32; 2] {
    match k % 4 {
        0 => v,
        1 => [v[1], -v[0]],
        2 => [-v[0], -v[1]],
        _ => [-v[1], v[0]],
    }
}

impl Offsets {
    /// The offsets of the position field `p` (lattice points) of `graph` with orientation `o`
    /// and spacing `s`.
    pub fn new(graph: &Graph, o: &[[f64; 3]], p: &[[f64; 3]], s: &[f64]) -> Self {
        let mut edges = Vec::new();
        let mut d = Vec::new();
        for a in 0..graph.len() {
            let la = lattice_of(graph, o, p, a);
            let na = graph.normals[a];
            for &b in graph.neighbors(a) {
                let b = b as usize;
                if b <= a {
                    continue;
                }
                let nb = graph.normals[b];
                let lb = matched(&la, na, &lattice_of(graph, o, p, b), nb);
                let ((_, ia), (_, ib)) = compat_position(
                    graph.positions[a],
                    na,
                    &la,
                    graph.positions[b],
                    nb,
                    &lb,
                    pair_spacing(s, a, b),
                );
                edges.push((a as u32, b as u32));
                d.push([(ia[0] - ib[0]) as i32, (ia[1] - ib[1]) as i32]);
            }
        }
        // Neighbours are sorted per vertex and `a` ascends: the edges are sorted.
        let t = (0..graph.len())
            .map(|v| subfit_mesh::vec3::cross(graph.normals[v], o[v]))
            .collect();
        Self {
            edges,
            d,
            q: o.to_vec(),
            t,
        }
    }

    fn edge(&self, a: u32, b: u32) -> Option<usize> {
        self.edges.binary_search(&(a.min(b), a.max(b))).ok()
    }

    /// Quarter turns from `b`'s frame to `a`'s.
    fn turns(&self, a: u32, b: u32) -> u8 {
        turns(self.q[a as usize], self.q[b as usize], self.t[b as usize])
    }

    /// The vector from `a`'s lattice point to `b`'s in `a`'s frame.
    pub fn get(&self, a: u32, b: u32) -> Option<[i32; 2]> {
        let e = self.edge(a, b)?;
        Some(if a < b {
            self.d[e]
        } else {
            let back = self.d[e];
            turn([-back[0], -back[1]], self.turns(a, b))
        })
    }

    /// Whether the edge `a`–`b` joins two vertices of one lattice point.
    pub fn is_zero(&self, a: u32, b: u32) -> bool {
        self.get(a, b) == Some([0, 0])
    }

    /// The triangle's curl in its first vertex's frame, or `None` where the orientation field
    /// turns around it (an orientation singularity).
    pub fn curl(&self, t: [u32; 3]) -> Option<[i32; 2]> {
        let [i, j, k] = t;
        let (kij, kjk, kki) = (self.turns(i, j), self.turns(j, k), self.turns(k, i));
        if (kij + kjk + kki) % 4 != 0 {
            return None;
        }
        let a = self.get(i, j)?;
        let b = turn(self.get(j, k)?, kij);
        let c = turn(self.get(k, i)?, (kij + kjk) % 4);
        Some([a[0] + b[0] + c[0], a[1] + b[1] + c[1]])
    }

    /// Changes the offset of the edge of triangle `t` from its corner `u` to `w` so that the
    /// triangle's curl is zero.
    fn cancel_across(&mut self, t: [u32; 3], u: u32, w: u32) -> bool {
        let Some(c) = self.curl(t) else {
            return false;
        };
        let Some(e) = self.edge(u, w) else {
            return false;
        };
        // The curl in u's frame, then in the edge's base frame (its smaller end).
        let c_u = turn(c, self.turns(u, t[0]));
        let base = u.min(w);
        let c_base = if base == u {
            c_u
        } else {
            turn(c_u, self.turns(w, u))
        };
        // t runs u → w: its term is +get(u, w); if u is the base that is +d, else −d turned.
        let sign = if base == u { -1 } else { 1 };
        self.d[e][0] += sign * c_base[0];
        self.d[e][1] += sign * c_base[1];
        self.curl(t) == Some([0, 0])
    }

    /// Removes the dislocations of `tris` (module docs). Returns `(found, removed)`.
    pub fn remove_dislocations(&mut self, tris: &[[u32; 3]]) -> (usize, usize) {
        let adjacency = triangle_adjacency(tris);
        let curls: Vec<Option<[i32; 2]>> = tris.iter().map(|&t| self.curl(t)).collect();
        let todo: Vec<usize> = (0..tris.len())
            .filter(|&f| matches!(curls[f], Some(c) if c != [0, 0]))
            .collect();
        let mut removed = 0;
        for &f in &todo {
            let Some(c) = self.curl(tris[f]) else {
                continue;
            };
            if c == [0, 0] {
                continue;
            }
            let Some(path) = self.partner(f, c, tris, &adjacency) else {
                continue;
            };
            if self.push_along(&path, tris) {
                removed += 1;
            }
        }
        (todo.len(), removed)
    }

    /// The path of triangles (as `(triangle, edge corner u, w to cross)` steps) from `f` to the
    /// nearest triangle that absorbs curl `cv`; the last step may cross a boundary edge.
    fn partner(
        &self,
        f: usize,
        c: [i32; 2],
        tris: &[[u32; 3]],
        adjacency: &[[u32; 3]],
    ) -> Option<Vec<(usize, u32, u32)>> {
        // Per reached triangle: the step into it, and the curl carried to its base frame.
        let mut parent: Vec<Option<(usize, u32, u32)>> = vec![None; tris.len()];
        let mut queue = VecDeque::from([(f, c)]);
        parent[f] = Some((usize::MAX, 0, 0));
        let mut visited = 0;
        while let Some((g, carried)) = queue.pop_front() {
            visited += 1;
            if visited > SEARCH_TRIANGLES {
                return None;
            }
            let t = tris[g];
            for k in 0..3 {
                let (u, w) = (t[k], t[(k + 1) % 3]);
                let next = adjacency[g][k];
                if next == u32::MAX {
                    // A boundary edge: the dislocation leaves the surface here.
                    let mut path = vec![(g, u, w)];
                    path.extend(self.back(&parent, g));
                    path.reverse();
                    return Some(path);
                }
                let h = next as usize;
                if parent[h].is_some() {
                    continue;
                }
                parent[h] = Some((g, u, w));
                // The carried curl in h's base frame: through u, which both share.
                let at_u = turn(carried, self.turns(u, t[0]));
                let here = turn(at_u, self.turns(tris[h][0], u));
                let absorbs = match self.curl(tris[h]) {
                    None => true,
                    Some(d) => d != [0, 0] && d == [-here[0], -here[1]],
                };
                if absorbs {
                    let mut path = self.back(&parent, h);
                    path.reverse();
                    return Some(path);
                }
                queue.push_back((h, here));
            }
        }
        None
    }

    /// The steps from the search's root to `h` (reversed), each the triangle left and the edge
    /// crossed.
    fn back(&self, parent: &[Option<(usize, u32, u32)>], mut h: usize) -> Vec<(usize, u32, u32)> {
        let mut out = Vec::new();
        while let Some((g, u, w)) = parent[h] {
            if g == usize::MAX {
                break;
            }
            out.push((g, u, w));
            h = g;
        }
        out
    }

    /// Cancels the curl step by step along `path`; false if a step fails (the offsets are
    /// then left as changed so far, every triangle before it consistent).
    fn push_along(&mut self, path: &[(usize, u32, u32)], tris: &[[u32; 3]]) -> bool {
        for &(g, u, w) in path {
            if !self.cancel_across(tris[g], u, w) {
                return false;
            }
        }
        true
    }
}

/// Per triangle, per corner `k`: the triangle across its edge `t[k]`–`t[k+1]`, or `u32::MAX`.
fn triangle_adjacency(tris: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut half: Vec<((u32, u32), u32, u8)> = Vec::with_capacity(tris.len() * 3);
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            half.push(((a.min(b), a.max(b)), f as u32, k as u8));
        }
    }
    half.sort_unstable();
    let mut out = vec![[u32::MAX; 3]; tris.len()];
    let mut i = 0;
    while i < half.len() {
        let mut j = i + 1;
        while j < half.len() && half[j].0 == half[i].0 {
            j += 1;
        }
        if j - i == 2 {
            let (x, y) = (half[i], half[i + 1]);
            out[x.1 as usize][x.2 as usize] = y.1;
            out[y.1 as usize][y.2 as usize] = x.1;
        }
        i = j;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turning_four_times_is_the_identity_and_once_is_a_quarter() {
        let v = [2, -1];
        assert_eq!(turn(turn(turn(turn(v, 1), 1), 1), 1), v);
        assert_eq!(turn(v, 1), [-1, -2]);
        assert_eq!(turn(turn(v, 1), 3), v);
        let (q, t) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert_eq!(turns(q, q, t), 0);
        assert_eq!(turns(t, q, t), 1);
        assert_eq!(turns([-1.0, 0.0, 0.0], q, t), 2);
    }
}
