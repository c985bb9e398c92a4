//! Boundary loops of a mesh target and the sharp turns along them (Lavoué et al. 2005 §4.2:
//! "corner rules (eq. 3) at detected sharp turns" of a boundary).
//!
//! A boundary loop is the cycle of edges used by one triangle. A turn is measured at the
//! scale of the shape, not of its triangles: at a boundary vertex the chords to the boundary
//! points an arc length `s` before and after it (`s` a fraction of the bounding-box diagonal)
//! make the turning angle `π − ∠(prev − v, next − v)`. A vertex is a corner when that angle is
//! at least `min_turn` and it is the largest within `±s` along the loop (one vertex per corner,
//! whatever the resolution). A jagged scan rim has many small teeth but no turn at the chord
//! scale, so it yields no corner; a cut CAD patch's corners (90°) do.
//!
//! Cost: O(#triangles log #triangles) for the loops, O(B · k) for the turns with `B` boundary
//! vertices and `k` of them within `s`.

use rayon::prelude::*;
use subfit_mesh::vec3::{dot, norm, sub};

/// Sharp turns along the boundary of a triangle mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BoundaryCorners {
    /// The boundary loops, each an ordered cycle of vertex ids (first not repeated).
    pub loops: Vec<Vec<u32>>,
    /// Corner vertex ids (sorted).
    pub corners: Vec<u32>,
}

/// The boundary loops of `tris` over `points` and their corners: turns of at least `min_turn`
/// radians measured with chords of arc length `scale` (units of `points`). Loops through a
/// vertex on more than two boundary edges are followed as found; loops shorter than 3
/// vertices are dropped. Cost: see the module docs.
pub fn boundary_corners(
    points: &[[f64; 3]],
    tris: &[[u32; 3]],
    min_turn: f64,
    scale: f64,
) -> BoundaryCorners {
    let loops = boundary_loops(tris);
    let mut corners = Vec::new();
    for l in &loops {
        corners.extend(loop_corners(points, l, min_turn, scale));
    }
    corners.sort_unstable();
    corners.dedup();
    BoundaryCorners { loops, corners }
}

/// Ordered boundary loops: directed edges of one triangle, followed head to tail.
fn boundary_loops(tris: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let mut edges: Vec<(u32, u32)> = tris
        .iter()
        .flat_map(|t| (0..3).map(move |i| (t[i], t[(i + 1) % 3])))
        .collect();
    let mut undirected: Vec<(u32, u32)> =
        edges.iter().map(|&(a, b)| (a.min(b), a.max(b))).collect();
    undirected.sort_unstable();
    let once = |a: u32, b: u32| {
        let k = (a.min(b), a.max(b));
        let i = undirected.partition_point(|&e| e < k);
        undirected.get(i) == Some(&k) && undirected.get(i + 1) != Some(&k)
    };
    edges.retain(|&(a, b)| once(a, b));
    edges.sort_unstable();
    let mut used = vec![false; edges.len()];
    let mut loops = Vec::new();
    for start in 0..edges.len() {
        if used[start] {
            continue;
        }
        let mut l = Vec::new();
        let mut e = start;
        loop {
            used[e] = true;
            let (a, b) = edges[e];
            l.push(a);
            let i = edges.partition_point(|&(x, _)| x < b);
            match (i..edges.len())
                .take_while(|&j| edges[j].0 == b)
                .find(|&j| !used[j])
            {
                Some(j) => e = j,
                None => break,
            }
        }
        if l.len() >= 3 {
            loops.push(l);
        }
    }
    loops
}

/// Corners of one loop (see the module docs).
fn loop_corners(points: &[[f64; 3]], l: &[u32], min_turn: f64, scale: f64) -> Vec<u32> {
    let n = l.len();
    let p = |i: usize| points[l[i % n] as usize];
    let seg: Vec<f64> = (0..n).map(|i| norm(sub(p(i + 1), p(i)))).collect();
    let total: f64 = seg.iter().sum();
    if !(total > 0.0) {
        return Vec::new();
    }
    let s = scale.min(total / 4.0);
    // The vertex index an arc length `s` ahead (+1) or behind (−1) of `i`, and how many
    // vertices lie within it.
    let reach = |i: usize, dir: isize| -> (usize, usize) {
        let (mut j, mut acc, mut k) = (i, 0.0, 0);
        while acc < s && k < n {
            let step = if dir > 0 {
                seg[j]
            } else {
                seg[(j + n - 1) % n]
            };
            acc += step;
            j = if dir > 0 {
                (j + 1) % n
            } else {
                (j + n - 1) % n
            };
            k += 1;
        }
        (j, k)
    };
    let turn: Vec<(f64, usize)> = (0..n)
        .map(|i| {
            let ((a, ka), (b, kb)) = (reach(i, -1), reach(i, 1));
            let (u, v) = (sub(p(a), p(i)), sub(p(b), p(i)));
            let c = dot(u, v) / (norm(u) * norm(v)).max(f64::MIN_POSITIVE);
            (std::f64::consts::PI - c.clamp(-1.0, 1.0).acos(), ka.max(kb))
        })
        .collect();
    (0..n)
        .filter(|&i| {
            let (t, k) = turn[i];
            t >= min_turn
                && (1..=k).all(|d| {
                    let (before, after) = (turn[(i + n - d) % n].0, turn[(i + d) % n].0);
                    // Ties go to the first of a plateau.
                    before < t && after <= t
                })
        })
        .map(|i| l[i])
        .collect()
}

/// Vertices on edges used by exactly one triangle (a mesh target's boundary), sorted. Cost
/// O(T log T).
pub fn boundary_vertices(tris: &[[u32; 3]]) -> Vec<u32> {
    let mut edges: Vec<(u32, u32)> = tris
        .iter()
        .flat_map(|t| (0..3).map(move |i| (t[i].min(t[(i + 1) % 3]), t[i].max(t[(i + 1) % 3]))))
        .collect();
    edges.par_sort_unstable();
    let mut out = Vec::new();
    let mut i = 0;
    while i < edges.len() {
        let mut j = i + 1;
        while j < edges.len() && edges[j] == edges[i] {
            j += 1;
        }
        if j - i == 1 {
            out.push(edges[i].0);
            out.push(edges[i].1);
        }
        i = j;
    }
    out.sort_unstable();
    out.dedup();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat `n × n` grid over `[0, 1]²`, two triangles per cell.
    fn grid(n: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut p = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                p.push([i as f64 / n as f64, j as f64 / n as f64, 0.0]);
            }
        }
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut t = Vec::new();
        for j in 0..n {
            for i in 0..n {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        (p, t)
    }

    #[test]
    fn a_square_has_four_corners_and_a_circle_none() {
        let (p, t) = grid(20);
        let b = boundary_corners(&p, &t, 40f64.to_radians(), 0.05);
        assert_eq!(b.loops.len(), 1);
        assert_eq!(b.loops[0].len(), 80);
        let mut want = vec![0u32, 20, 440, 420];
        want.sort_unstable();
        assert_eq!(b.corners, want);
        // A disc: the grid's points moved onto circles keep the topology, lose the corners.
        let q: Vec<[f64; 3]> = p
            .iter()
            .map(|&[x, y, _]| {
                let (u, v) = (2.0 * x - 1.0, 2.0 * y - 1.0);
                // The square-to-disc map (Shirley–Chiu-like elliptical grid).
                [
                    u * (1.0 - v * v / 2.0).sqrt(),
                    v * (1.0 - u * u / 2.0).sqrt(),
                    0.0,
                ]
            })
            .collect();
        let b = boundary_corners(&q, &t, 40f64.to_radians(), 0.1);
        assert!(b.corners.is_empty(), "{:?}", b.corners);
    }

    #[test]
    fn small_teeth_are_no_corners() {
        // The square's rim with every other boundary vertex pushed out by a tooth of a
        // twentieth of the chord scale.
        let (mut p, t) = grid(40);
        for i in (1..40).step_by(2) {
            p[i][1] -= 0.004;
        }
        let b = boundary_corners(&p, &t, 40f64.to_radians(), 0.08);
        assert_eq!(b.corners.len(), 4, "{:?}", b.corners);
    }
}
