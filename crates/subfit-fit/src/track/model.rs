//! The embedded deformation model (Sumner, Schmid & Pauly 2007, §3, eq. 1 and 3; see
//! [`super`]'s module docs): the graph of nodes ([`DeformationGraph`], through space, inside
//! the body or laid over the surface), the skinning of points to their nearest nodes (`Skin`,
//! `w_k ∝ (1 − ‖x − g_k‖ / d_{s+1})²`), the per-node affine motions ([`NodeMotion`]) and the
//! layout of their unknowns ([`PER`]). The driver ([`super::track`]) and the normal system
//! (`system`) both build on it.

use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use subfit_mesh::vec3::{dist2, dot as dot3, sub};

use super::geodesic;

/// Unknowns per node: `A` row-major (9), then `t` (3).
pub(super) const PER: usize = 12;

/// The nodes of an embedded deformation: their rest positions and each node's nearest nodes
/// (fixed at construction).
#[derive(Clone, Debug)]
pub struct DeformationGraph {
    pub(super) positions: Vec<[f64; 3]>,
    pub(super) neighbors: Vec<Vec<u32>>,
    /// Per node, the projector `I − Π` (row-major, `q × q` over the node and its neighbours)
    /// that removes a field's best linear trend in position (the second-order term).
    pub(super) detrend: Vec<Vec<f64>>,
    /// The skinning of the surface samples the graph was laid over, by surface distance
    /// ([`Self::on_surface`]); `None` for a graph through space.
    pub(super) surface: Option<SurfaceSkin>,
}

/// The samples a graph was laid over, their skinning rows and an index to find the nearest.
#[derive(Clone, Debug)]
pub(super) struct SurfaceSkin {
    pub(super) rest: Vec<[f64; 3]>,
    pub(super) skin: Skin,
}

impl DeformationGraph {
    /// Picks `count` nodes among `points` by farthest-point sampling (from point 0) and links
    /// each to its `neighbors` nearest nodes. Cost: O(n · count + count²).
    pub fn new(points: &[[f64; 3]], count: usize, neighbors: usize) -> Self {
        let positions: Vec<[f64; 3]> = farthest_points(points, count)
            .into_iter()
            .map(|i| points[i])
            .collect();
        let k = neighbors.min(positions.len().saturating_sub(1));
        let neighbors: Vec<Vec<u32>> = positions
            .par_iter()
            .map(|&a| {
                let mut by: Vec<(f64, u32)> = positions
                    .iter()
                    .enumerate()
                    .map(|(j, &b)| (dist2(a, b), j as u32))
                    .filter(|&(d, _)| d > 0.0)
                    .collect();
                by.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
                by.truncate(k);
                by.into_iter().map(|(_, j)| j).collect()
            })
            .collect();
        Self::with_links(positions, neighbors, None)
    }

    fn with_links(
        positions: Vec<[f64; 3]>,
        neighbors: Vec<Vec<u32>>,
        surface: Option<SurfaceSkin>,
    ) -> Self {
        let detrend = neighbors
            .iter()
            .enumerate()
            .map(|(k, nb)| detrend(&positions, k, nb))
            .collect();
        Self {
            positions,
            neighbors,
            detrend,
            surface,
        }
    }

    /// Nodes inside a closed body laid out along its surface ([`geodesic`]): as
    /// [`Self::interior`] (`depth` of the way to the medial points, `count` nodes by
    /// farthest-point sampling), but each node's `neighbors` and each sample's `skin` nearest
    /// nodes are found by distance over the surface mesh `faces` (over the samples, e.g. the
    /// limit mesh they are the vertices of) from the sample each node was placed from (a
    /// variant that took the nearest in space among the nodes not much farther round than
    /// through — a cross-section as one piece — tracked the dance worse: drift RMS 1.10 %
    /// against 0.78 %, and the generated tube's spin no better). Points
    /// other than the samples ([`super::deform`], markers) take the skinning of their nearest sample.
    /// Cost: [`Self::interior`] plus one Dijkstra per node over the samples.
    ///
    /// # Panics
    /// If `samples` and `normals` differ in length.
    #[track_caller]
    pub fn on_surface(
        samples: &[[f64; 3]],
        normals: &[[f64; 3]],
        faces: &subfit_mesh::Polygons,
        depth: f64,
        (count, neighbors, skin): (usize, usize, usize),
    ) -> Self {
        assert_eq!(samples.len(), normals.len(), "one normal per sample");
        let inner = inner_points(samples, normals, depth);
        let anchors = farthest_points(&inner, count);
        let positions: Vec<[f64; 3]> = anchors.iter().map(|&i| inner[i]).collect();
        let dist = geodesic::distances_from(samples, faces, &anchors);
        let links = geodesic::neighbours(&dist, &anchors, neighbors);
        let (nodes, weights) = geodesic::skin_rows(&dist, samples, &positions, skin);
        let per = skin.min(positions.len()).max(1);
        let surface = SurfaceSkin {
            rest: samples.to_vec(),
            skin: Skin {
                nodes,
                weights,
                per,
            },
        };
        Self::with_links(positions, links, Some(surface))
    }

    /// The skinning of `points` (rest positions) over `s` nodes: the surface samples' own
    /// rows when `points` are those samples, the nearest sample's rows for other points of a
    /// graph laid over a surface, the nearest nodes in space otherwise.
    pub(super) fn skin_of(&self, points: &[[f64; 3]], s: usize) -> Skin {
        match &self.surface {
            Some(sf) if sf.rest.as_slice() == points => sf.skin.clone(),
            Some(sf) => match subfit_target::neighbors::PointIndex::new(&sf.rest) {
                Some(index) => sf.skin.gather(
                    &points
                        .iter()
                        .map(|p| index.nearest(p).index as usize)
                        .collect::<Vec<_>>(),
                ),
                None => Skin::new(points, &self.positions, s),
            },
            None => Skin::new(points, &self.positions, s),
        }
    }

    /// Nodes inside a closed body: [`Self::new`] over the points `depth` of the way from each
    /// sample (unit outward `normals`) to its medial point ([`medial_points`]); `depth` 0 puts
    /// them on the surface. Inner nodes carry a cross-section as one piece (its bend, twist,
    /// change of thickness), where nodes on the surface let each side slide on its own.
    ///
    /// # Panics
    /// If `samples` and `normals` differ in length.
    #[track_caller]
    pub fn interior(
        samples: &[[f64; 3]],
        normals: &[[f64; 3]],
        depth: f64,
        count: usize,
        neighbors: usize,
    ) -> Self {
        assert_eq!(samples.len(), normals.len(), "one normal per sample");
        Self::new(&inner_points(samples, normals, depth), count, neighbors)
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// True without nodes.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// The nodes' rest positions.
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.positions
    }

    /// Node `k` and its neighbours, in the order of its second-order projector.
    pub(super) fn neighbourhood(&self, k: usize) -> Vec<usize> {
        neighbourhood(k, &self.neighbors[k])
    }
}

fn neighbourhood(k: usize, nb: &[u32]) -> Vec<usize> {
    std::iter::once(k)
        .chain(nb.iter().map(|&l| l as usize))
        .collect()
}

/// `I − Π` over node `k` and its neighbours `nb`, `Π` the least-squares projector onto the
/// fields linear in position (`1, x, y, z`), from the thin SVD of that basis over the nodes
/// (directions with a singular value below 1e-6 of the largest are dropped: on a flat
/// neighbourhood the fields linear in its plane); empty with fewer than 5 nodes.
fn detrend(g: &[[f64; 3]], k: usize, nb: &[u32]) -> Vec<f64> {
    let ids = neighbourhood(k, nb);
    let q = ids.len();
    if q < 5 {
        return Vec::new();
    }
    let scale = ids
        .iter()
        .map(|&l| dist2(g[l], g[k]))
        .fold(0.0, f64::max)
        .sqrt()
        .max(1e-300);
    let b = nalgebra::DMatrix::<f64>::from_fn(q, 4, |r, c| {
        if c == 0 {
            1.0
        } else {
            (g[ids[r]][c - 1] - g[k][c - 1]) / scale
        }
    });
    let svd = b.svd(true, false);
    let Some(u) = svd.u else {
        return Vec::new();
    };
    let top = svd.singular_values.max();
    let kept: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&c| svd.singular_values[c] > 1e-6 * top)
        .collect();
    (0..q * q)
        .map(|e| {
            let (r, c) = (e / q, e % q);
            let pi: f64 = kept.iter().map(|&m| u[(r, m)] * u[(c, m)]).sum();
            f64::from(u8::from(r == c)) - pi
        })
        .collect()
}

/// The points `depth` of the way from each sample to its medial point.
fn inner_points(samples: &[[f64; 3]], normals: &[[f64; 3]], depth: f64) -> Vec<[f64; 3]> {
    medial_points(samples, normals)
        .iter()
        .zip(samples)
        .map(|(c, p)| std::array::from_fn(|a| p[a] + depth * (c[a] - p[a])))
        .collect()
}

/// `count` indices of `points` by farthest-point sampling from point 0 (fewer when points
/// coincide). Cost: O(n · count).
fn farthest_points(points: &[[f64; 3]], count: usize) -> Vec<usize> {
    let n = points.len();
    let count = count.min(n);
    let mut picks = Vec::with_capacity(count);
    let mut d2 = vec![f64::INFINITY; n];
    let mut next = 0usize;
    while picks.len() < count {
        let g = points[next];
        picks.push(next);
        d2.par_iter_mut()
            .zip(points.par_iter())
            .for_each(|(d, &p)| *d = d.min(dist2(p, g)));
        next = (0..n).max_by(|&a, &b| d2[a].total_cmp(&d2[b])).unwrap_or(0);
        if d2[next] == 0.0 {
            break;
        }
    }
    picks
}

/// Shrinking-ball medial points (Ma, Bae & Mukherjee, "3D medial axis point approximation
/// using nearest neighbors and the normal field", Visual Computer 2012): for each sample `p`
/// with unit outward normal `n`, the centre `p − r n` of the largest ball touching `p` that
/// holds no other sample, `r` shrunk from half the samples' diagonal by
/// `r = ‖p − q‖² / (2 nᵀ(p − q))` through the nearest sample `q` to the centre until `p` itself
/// is nearest. A sample whose ball never touches another (the open side of a sheet) is its own
/// medial point.
/// Cost: O(n log n) for the kd-tree, then a few nearest-point queries per sample (parallel).
///
/// # Panics
/// If `samples` and `normals` differ in length.
#[track_caller]
pub fn medial_points(samples: &[[f64; 3]], normals: &[[f64; 3]]) -> Vec<[f64; 3]> {
    assert_eq!(samples.len(), normals.len(), "one normal per sample");
    let Some(index) = subfit_target::neighbors::PointIndex::new(samples) else {
        return samples.to_vec();
    };
    let bound =
        subfit_mesh::bounding_box(samples).map_or(0.0, |(lo, hi)| 0.5 * dist2(lo, hi).sqrt());
    (0..samples.len())
        .into_par_iter()
        .map(|i| {
            let (p, n) = (samples[i], normals[i]);
            let mut r = bound;
            let mut touched = false;
            for _ in 0..64 {
                let c = std::array::from_fn(|a| p[a] - r * n[a]);
                let q = index.nearest(&c);
                let j = q.index as usize;
                if j == i || q.distance >= r * (1.0 - 1e-9) {
                    break;
                }
                let d = sub(p, samples[j]);
                let den = 2.0 * dot3(n, d);
                if den <= 0.0 {
                    break;
                }
                let shrunk = dot3(d, d) / den;
                if shrunk >= r {
                    break;
                }
                r = shrunk;
                touched = true;
            }
            if !touched {
                return p;
            }
            std::array::from_fn(|a| p[a] - r * n[a])
        })
        .collect()
}

/// Points of the rest surface that [`super::track`] brings onto the frame, with their unit normals.
#[derive(Clone, Copy, Debug)]
pub struct Samples<'a> {
    /// Positions in the graph's rest configuration.
    pub positions: &'a [[f64; 3]],
    /// Unit outward normals, one per position.
    pub normals: &'a [[f64; 3]],
}

/// Per-node affine motions of one tracking step: `x ↦ A_k (x − g_k) + g_k + t_k`.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeMotion {
    /// `A_k`.
    pub linear: Vec<Matrix3<f64>>,
    /// `t_k`.
    pub translations: Vec<[f64; 3]>,
}

impl NodeMotion {
    /// The identity motion of `m` nodes.
    pub fn identity(m: usize) -> Self {
        Self {
            linear: vec![Matrix3::identity(); m],
            translations: vec![[0.0; 3]; m],
        }
    }

    /// The motion one step on at constant velocity, from `before` (the previous step's
    /// motion) through this one: each node's `A` and `t` extrapolated linearly (a turn by
    /// `δ` a step is predicted to `O(δ²)`).
    ///
    /// # Panics
    /// If the two have different numbers of nodes.
    #[track_caller]
    pub fn extrapolated(&self, before: &Self) -> Self {
        assert_eq!(self.linear.len(), before.linear.len(), "same nodes");
        Self {
            linear: self
                .linear
                .iter()
                .zip(&before.linear)
                .map(|(a, b)| 2.0 * a - b)
                .collect(),
            translations: self
                .translations
                .iter()
                .zip(&before.translations)
                .map(|(a, b)| std::array::from_fn(|k| 2.0 * a[k] - b[k]))
                .collect(),
        }
    }
}

#[derive(Clone, Debug)]
pub(super) struct Skin {
    pub(super) nodes: Vec<u32>,
    pub(super) weights: Vec<f64>,
    pub(super) per: usize,
}

impl Skin {
    pub(super) fn new(points: &[[f64; 3]], g: &[[f64; 3]], s: usize) -> Self {
        let per = s.min(g.len()).max(1);
        let rows: Vec<(Vec<u32>, Vec<f64>)> = points
            .par_iter()
            .map(|&x| {
                let mut by: Vec<(f64, u32)> = g
                    .iter()
                    .enumerate()
                    .map(|(k, &gk)| (dist2(x, gk), k as u32))
                    .collect();
                let take = (per + 1).min(by.len());
                by.select_nth_unstable_by(take - 1, |a, b| a.0.total_cmp(&b.0));
                by.truncate(take);
                by.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
                let dmax = by.last().map_or(1.0, |e| e.0.sqrt()).max(1e-12);
                let used = per.min(by.len());
                let mut w: Vec<f64> = by[..used]
                    .iter()
                    .map(|e| (1.0 - e.0.sqrt() / dmax).max(0.0).powi(2))
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
        let mut nodes = Vec::with_capacity(points.len() * per);
        let mut weights = Vec::with_capacity(points.len() * per);
        for (i, w) in rows {
            nodes.extend(i);
            weights.extend(w);
        }
        Self {
            nodes,
            weights,
            per,
        }
    }

    /// The rows `rows` of this skin, in that order.
    pub(super) fn gather(&self, rows: &[usize]) -> Self {
        let mut nodes = Vec::with_capacity(rows.len() * self.per);
        let mut weights = Vec::with_capacity(rows.len() * self.per);
        for &r in rows {
            let (n, w) = self.row(r);
            nodes.extend_from_slice(n);
            weights.extend_from_slice(w);
        }
        Self {
            nodes,
            weights,
            per: self.per,
        }
    }

    pub(super) fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let r = i * self.per..(i + 1) * self.per;
        (&self.nodes[r.clone()], &self.weights[r])
    }

    pub(super) fn apply(&self, i: usize, x: [f64; 3], g: &[[f64; 3]], m: &NodeMotion) -> [f64; 3] {
        let (ids, w) = self.row(i);
        let mut out = Vector3::zeros();
        for (&k, &wk) in ids.iter().zip(w) {
            let k = k as usize;
            let gk = v(g[k]);
            out += wk * (m.linear[k] * (v(x) - gk) + gk + v(m.translations[k]));
        }
        [out.x, out.y, out.z]
    }

    /// The moved normal (cofactor of the blended linear part), unit.
    pub(super) fn normal(&self, i: usize, n: [f64; 3], m: &NodeMotion) -> [f64; 3] {
        let (ids, w) = self.row(i);
        let mut a = Matrix3::zeros();
        for (&k, &wk) in ids.iter().zip(w) {
            a += wk * m.linear[k as usize];
        }
        let c = a.try_inverse().map_or(a, |inv| inv.transpose());
        let out = c * v(n);
        let l = out.norm();
        if l > 0.0 {
            [out.x / l, out.y / l, out.z / l]
        } else {
            n
        }
    }
}

impl Skin {
    /// The gradient of `dirᵀx'` for point `i` at rest position `x` (sparse, into `j`):
    /// `δx' = Σ_k w_k (δA_k (x − g_k) + δt_k)`.
    pub(super) fn jacobian(
        &self,
        j: &mut Vec<(usize, f64)>,
        i: usize,
        x: [f64; 3],
        g: &[[f64; 3]],
        dir: [f64; 3],
    ) {
        j.clear();
        let (ids, w) = self.row(i);
        for (&k, &wk) in ids.iter().zip(w) {
            if wk == 0.0 {
                continue;
            }
            let k = k as usize;
            let d = sub(x, g[k]);
            for (a, &da) in dir.iter().enumerate() {
                if da == 0.0 {
                    continue;
                }
                for (c, &dc) in d.iter().enumerate() {
                    j.push((PER * k + 3 * a + c, wk * da * dc));
                }
                j.push((PER * k + 9 + a, wk * da));
            }
        }
    }
}

pub(super) fn v(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}
