//! Consistent normal orientation by minimum-spanning-tree propagation (Hoppe, DeRose, Duchamp,
//! McDonald, Stuetzle 1992, "Surface reconstruction from unorganized points", §3.3).
//!
//! The Riemannian graph is the symmetrized k-nearest-neighbour graph; an edge `(i, j)` costs
//! `1 − |n_i·n_j|` (Hoppe), plus optionally `τ · (|n_i·ê| + |n_j·ê|)/2` with `ê` the unit edge
//! direction: edges that leave the tangent plane (e.g. across a thin plate, where the unoriented
//! normals are parallel and Hoppe's cost is 0) become expensive. Each connected component is
//! seeded at its point of largest `z`, whose normal is oriented towards `+z` (outward for closed
//! shapes), and orientation is propagated along the minimum spanning tree (Prim's algorithm).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use crate::vec3::{dot, normalize, scale, sub};

/// Outcome of [`orient_normals`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Orientation {
    /// Per point: whether its normal was negated.
    pub flipped: Vec<bool>,
    /// Number of connected components of the graph (each seeded separately).
    pub components: usize,
}

/// Orients `normals` in place (see the module doc). `graph[i]` lists neighbours of `i`; the
/// graph is symmetrized here. Points with `fixed[i]` keep their normal and seed the propagation
/// first (their components need no `+z` seed). Cost O(E log E) for E edges, serial.
pub fn orient_normals(
    points: &[[f64; 3]],
    normals: &mut [[f64; 3]],
    graph: &[Vec<u32>],
    fixed: &[bool],
    tangent_penalty: f64,
) -> Orientation {
    let n = points.len();
    // Symmetric adjacency in compressed rows.
    let mut deg = vec![0u32; n + 1];
    for (i, g) in graph.iter().enumerate() {
        deg[i] += g.len() as u32;
        for &j in g {
            deg[j as usize] += 1;
        }
    }
    let mut off = vec![0usize; n + 1];
    for i in 0..n {
        off[i + 1] = off[i] + deg[i] as usize;
    }
    let mut fill = off.clone();
    let mut adj = vec![0u32; off[n]];
    for (i, g) in graph.iter().enumerate() {
        for &j in g {
            adj[fill[i]] = j;
            fill[i] += 1;
            adj[fill[j as usize]] = i as u32;
            fill[j as usize] += 1;
        }
    }
    let cost = |a: usize, b: usize, normals: &[[f64; 3]]| -> f64 {
        let mut c = 1.0 - dot(normals[a], normals[b]).abs();
        if tangent_penalty > 0.0 {
            if let Some(e) = normalize(sub(points[b], points[a])) {
                c += tangent_penalty * 0.5 * (dot(normals[a], e).abs() + dot(normals[b], e).abs());
            }
        }
        c.max(0.0)
    };
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.sort_unstable_by(|&a, &b| points[b as usize][2].total_cmp(&points[a as usize][2]));
    let mut visited = vec![false; n];
    let mut flipped = vec![false; n];
    let mut components = 0;
    let mut heap: BinaryHeap<(Reverse<u64>, u32, u32)> = BinaryHeap::new();
    if fixed.iter().any(|&f| f) {
        for (i, _) in fixed.iter().enumerate().filter(|(_, &f)| f) {
            visited[i] = true;
        }
        for (i, _) in fixed.iter().enumerate().filter(|(_, &f)| f) {
            push_edges(i, &off, &adj, &visited, normals, &cost, &mut heap);
        }
        propagate(
            &off,
            &adj,
            &mut visited,
            &mut flipped,
            normals,
            &cost,
            &mut heap,
        );
    }
    for &seed in &order {
        let seed = seed as usize;
        if visited[seed] {
            continue;
        }
        components += 1;
        visited[seed] = true;
        let nz = normals[seed];
        // Seed faces +z; ties (horizontal normal) towards +x, then +y.
        let key = if nz[2] != 0.0 {
            nz[2]
        } else if nz[0] != 0.0 {
            nz[0]
        } else {
            nz[1]
        };
        if key < 0.0 {
            normals[seed] = scale(nz, -1.0);
            flipped[seed] = true;
        }
        push_edges(seed, &off, &adj, &visited, normals, &cost, &mut heap);
        propagate(
            &off,
            &adj,
            &mut visited,
            &mut flipped,
            normals,
            &cost,
            &mut heap,
        );
    }
    Orientation {
        flipped,
        components,
    }
}

/// Prim's loop: grows the tree from the heap's frontier, orienting each new point like its parent.
fn propagate(
    off: &[usize],
    adj: &[u32],
    visited: &mut [bool],
    flipped: &mut [bool],
    normals: &mut [[f64; 3]],
    cost: &impl Fn(usize, usize, &[[f64; 3]]) -> f64,
    heap: &mut BinaryHeap<(Reverse<u64>, u32, u32)>,
) {
    while let Some((_, to, from)) = heap.pop() {
        let (to, from) = (to as usize, from as usize);
        if visited[to] {
            continue;
        }
        visited[to] = true;
        if dot(normals[from], normals[to]) < 0.0 {
            normals[to] = scale(normals[to], -1.0);
            flipped[to] = true;
        }
        push_edges(to, off, adj, visited, normals, cost, heap);
    }
}

fn push_edges(
    from: usize,
    off: &[usize],
    adj: &[u32],
    visited: &[bool],
    normals: &[[f64; 3]],
    cost: &impl Fn(usize, usize, &[[f64; 3]]) -> f64,
    heap: &mut BinaryHeap<(Reverse<u64>, u32, u32)>,
) {
    for &to in &adj[off[from]..off[from + 1]] {
        if !visited[to as usize] {
            // Non-negative floats order like their bit patterns.
            let w = cost(from, to as usize, normals).to_bits();
            heap.push((Reverse(w), to, from as u32));
        }
    }
}
