//! The deformation graph laid out along the surface: node neighbours and the samples' skinning
//! by distances *over the surface* (Dijkstra on the sampled limit mesh), not through space —
//! an arm that hangs beside the body, two legs side by side, fingers, are near in space and
//! far apart on the surface, and a graph whose edges or skinning cross that gap ties limbs
//! together that move apart (Sumner et al. 2007 §3 build their graph over the mesh for this
//! reason; Li et al. 2009 §4 likewise weigh samples by geodesic distance to the nodes).
//!
//! Each node keeps an *anchor*: the surface sample it was placed from (it lies inside the body
//! on that sample's way to the medial axis, [`super::medial_points`]); a node's distance to a
//! sample is the surface distance from its anchor. Cost: one Dijkstra per node over the
//! sample mesh's edges, O(m · E log S).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use subfit_mesh::vec3::dist2;
use subfit_mesh::Polygons;

/// Surface distances from each of `sources` (sample indices) to every sample over the edges
/// of `faces` (`m × S`, `f64::INFINITY` where a sample is not reachable).
pub(super) fn distances_from(
    samples: &[[f64; 3]],
    faces: &Polygons,
    sources: &[usize],
) -> Vec<Vec<f64>> {
    use rayon::prelude::*;
    let adjacency = adjacency(samples, faces);
    sources
        .par_iter()
        .map(|&s| dijkstra(&adjacency, s))
        .collect()
}

/// Per sample, its neighbours over `faces` with the edge lengths.
fn adjacency(samples: &[[f64; 3]], faces: &Polygons) -> Vec<Vec<(u32, f64)>> {
    let mut adj: Vec<Vec<(u32, f64)>> = vec![Vec::new(); samples.len()];
    for f in faces.iter() {
        for k in 0..f.len() {
            let (a, b) = (f[k] as usize, f[(k + 1) % f.len()] as usize);
            if a >= samples.len() || b >= samples.len() || a == b {
                continue;
            }
            let d = dist2(samples[a], samples[b]).sqrt();
            if !adj[a].iter().any(|e| e.0 as usize == b) {
                adj[a].push((b as u32, d));
                adj[b].push((a as u32, d));
            }
        }
    }
    adj
}

fn dijkstra(adj: &[Vec<(u32, f64)>], source: usize) -> Vec<f64> {
    let mut d = vec![f64::INFINITY; adj.len()];
    let mut heap = BinaryHeap::new();
    d[source] = 0.0;
    heap.push(Reverse((Ordered(0.0), source as u32)));
    while let Some(Reverse((Ordered(du), u))) = heap.pop() {
        let u = u as usize;
        if du > d[u] {
            continue;
        }
        for &(v, w) in &adj[u] {
            let nd = du + w;
            if nd < d[v as usize] {
                d[v as usize] = nd;
                heap.push(Reverse((Ordered(nd), v)));
            }
        }
    }
    d
}

/// An `f64` ordered by `total_cmp` (the heap's key).
#[derive(Clone, Copy, PartialEq)]
struct Ordered(f64);

impl Eq for Ordered {}

impl PartialOrd for Ordered {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Ordered {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// Each node's `k` nearest other nodes by surface distance between anchors (`dist[node]` over
/// samples, `anchors[node]` a sample); nodes not reachable are not neighbours.
pub(super) fn neighbours(dist: &[Vec<f64>], anchors: &[usize], k: usize) -> Vec<Vec<u32>> {
    (0..anchors.len())
        .map(|a| {
            let mut by: Vec<(f64, u32)> = anchors
                .iter()
                .enumerate()
                .filter(|&(b, _)| b != a)
                .map(|(b, &s)| (dist[a][s], b as u32))
                .filter(|e| e.0.is_finite())
                .collect();
            by.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
            by.truncate(k);
            by.into_iter().map(|e| e.1).collect()
        })
        .collect()
}

/// Each sample's `s` nearest nodes by surface distance with the weights of Sumner et al. eq. 3
/// (`(1 − d / d_{s+1})²`, normalized), as `(nodes, weights)` rows of `s` (padded with weight
/// 0). A sample no node reaches takes the node nearest in space.
pub(super) fn skin_rows(
    dist: &[Vec<f64>],
    samples: &[[f64; 3]],
    nodes: &[[f64; 3]],
    s: usize,
) -> (Vec<u32>, Vec<f64>) {
    use rayon::prelude::*;
    let per = s.min(nodes.len()).max(1);
    let rows: Vec<(Vec<u32>, Vec<f64>)> = (0..samples.len())
        .into_par_iter()
        .map(|i| {
            let mut by: Vec<(f64, u32)> = (0..nodes.len())
                .map(|k| (dist[k][i], k as u32))
                .filter(|e| e.0.is_finite())
                .collect();
            if by.is_empty() {
                let k = (0..nodes.len())
                    .min_by(|&a, &b| {
                        dist2(samples[i], nodes[a]).total_cmp(&dist2(samples[i], nodes[b]))
                    })
                    .unwrap_or(0);
                let mut ids = vec![k as u32; per];
                let mut w = vec![0.0; per];
                ids[0] = k as u32;
                w[0] = 1.0;
                return (ids, w);
            }
            by.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
            let take = (per + 1).min(by.len());
            let dmax = by[take - 1].0.max(1e-12);
            let used = per.min(by.len());
            let mut w: Vec<f64> = by[..used]
                .iter()
                .map(|e| (1.0 - e.0 / dmax).max(0.0).powi(2))
                .collect();
            let sum: f64 = w.iter().sum();
            if sum > 0.0 {
                w.iter_mut().for_each(|v| *v /= sum);
            } else {
                w.iter_mut().for_each(|v| *v = 1.0 / used as f64);
            }
            let mut ids: Vec<u32> = by[..used].iter().map(|e| e.1).collect();
            while ids.len() < per {
                ids.push(ids[0]);
                w.push(0.0);
            }
            (ids, w)
        })
        .collect();
    let mut ids = Vec::with_capacity(samples.len() * per);
    let mut weights = Vec::with_capacity(samples.len() * per);
    for (i, w) in rows {
        ids.extend(i);
        weights.extend(w);
    }
    (ids, weights)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip folded into a U: its two arms are close in space, far over the surface.
    #[test]
    fn distances_go_over_the_surface() {
        // Vertices along a polyline (0,0) → (1,0) → (1,0.1) → (0,0.1), two rows in z.
        let path: Vec<[f64; 2]> = (0..=10)
            .map(|i| [f64::from(i) / 10.0, 0.0])
            .chain((0..=10).map(|i| [1.0 - f64::from(i) / 10.0, 0.1]))
            .collect();
        let n = path.len();
        let samples: Vec<[f64; 3]> = (0..2)
            .flat_map(|z| path.iter().map(move |p| [p[0], p[1], f64::from(z) * 0.1]))
            .collect();
        let mut faces = Polygons::new();
        for i in 0..n - 1 {
            faces.push(&[i as u32, (i + 1) as u32, (n + i + 1) as u32, (n + i) as u32]);
        }
        let d = distances_from(&samples, &faces, &[0]);
        // Sample n − 1 is (0, 0.1, 0): 0.1 away in space, about 2.1 over the strip.
        assert!(d[0][n - 1] > 2.0, "{}", d[0][n - 1]);
        assert!((d[0][10] - 1.0).abs() < 1e-12);
    }
}
