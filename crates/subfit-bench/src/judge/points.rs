//! The local surface of a point reference: every point is a disc centred on it, normal to the
//! principal axis of least variance of its [`NEIGHBOURS`] nearest points (PCA, as Hoppe et al.
//! 1992 estimate tangent planes), with one radius for all: the median over the points of the
//! distance to their [`NEIGHBOURS`]-th nearest neighbour. A point whose neighbours span no
//! plane (duplicates, a line) stays a point. A point of the candidate is measured
//! to the nearest disc — to the disc, not its plane, so surface that overhangs the data's edge
//! by more than the radius is measured as far as it overhangs.
//!
//! Why that radius: with a sampling of density `ρ` per unit area, `k` neighbours fill a disc of
//! area `k / ρ`, so the `k`-th-neighbour distance is about `√(k / (πρ))`, about twice the mean
//! spacing for `k = 12`; the largest empty circle among `N` random points has area about
//! `ln N / ρ` (`ln N < 12` up to 160,000 points), so discs of that radius leave no false gaps
//! inside the data, and the distance grows continuously past a disc's rim. The price: an
//! overhang shorter than the radius is not seen; [`super::Judgement::point_spacing`] states it.

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::Matrix3;
use std::num::NonZeroUsize;
use subfit::mesh::vec3::{dot, norm, sub};

/// Neighbours of the normal estimate and of the radius.
pub(super) const NEIGHBOURS: usize = 12;
/// Extra neighbours fetched to find ties with the last of the [`NEIGHBOURS`].
const TIES: usize = 4;
/// A point whose [`NEIGHBOURS`]-th neighbour is farther than this many disc radii (the median of
/// that distance) is an isolated return: a stray point of a range scan with no surface around
/// it (a handful of them, 40–60 radii from any other data, in the corpus's single views). It is
/// not data → surface data: its distance would be the Hausdorff distance of every fit, however
/// good. Ten radii is five times the spacing of a sparse patch (2 radii), far above the sampling
/// variation of a real surface.
pub(super) const ISOLATED: f64 = 10.0;
/// Nearest points whose discs are tried first for a query; discs of farther points are tried
/// only while they could still be nearer.
const FIRST_TRIED: usize = 8;

/// A point cloud's local surface: one disc per point.
pub(super) struct Discs<'a> {
    points: &'a [[f64; 3]],
    normals: Vec<[f64; 3]>,
    radius: f64,
    tree: ImmutableKdTree<f64, 3>,
    isolated: Vec<bool>,
}

impl<'a> Discs<'a> {
    /// Builds the discs of `points` (at least `NEIGHBOURS + 1`, finite; checked by the caller).
    /// Cost: O(n log n) for the tree, a `NEIGHBOURS + 1`-nearest query and a 3×3 eigen
    /// decomposition per point (parallel).
    pub fn new(points: &'a [[f64; 3]]) -> Result<Self, String> {
        use rayon::prelude::*;
        let tree = ImmutableKdTree::new_from_slice(points).map_err(|e| e.to_string())?;
        // The point itself, its NEIGHBOURS nearest, and a few more to find ties with the last.
        let k = NonZeroUsize::new(NEIGHBOURS + 1 + TIES).expect("positive");
        let (normals, reach): (Vec<[f64; 3]>, Vec<f64>) = points
            .par_iter()
            .map(|p| {
                let near = tree
                    .query(p)
                    .nearest_n::<SquaredEuclidean<f64>>(k)
                    .execute();
                let last = near.get(NEIGHBOURS).map_or(0.0, |r| r.distance.max(0.0));
                // Neighbours tied with the last (within 1e-9 relative, squared) join it, so the
                // set does not hang on rounding (symmetric data, scaled copies).
                let idx: Vec<usize> = near
                    .iter()
                    .enumerate()
                    .take_while(|(i, r)| *i <= NEIGHBOURS || r.distance <= last * (1.0 + 2e-9))
                    .map(|(_, r)| r.item as usize)
                    .collect();
                (pca_normal(points, &idx), last.sqrt())
            })
            .unzip();
        let mut sorted = reach.clone();
        let mid = sorted.len() / 2;
        let (_, radius, _) = sorted.select_nth_unstable_by(mid, f64::total_cmp);
        let radius = *radius;
        let isolated = reach.iter().map(|&r| r > ISOLATED * radius).collect();
        Ok(Self {
            points,
            normals,
            radius,
            tree,
            isolated,
        })
    }

    /// Whether point `i` is isolated (see [`ISOLATED`]).
    pub fn isolated(&self, i: usize) -> bool {
        self.isolated[i]
    }

    /// The discs' radius, in the points' units.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Distance from `q` to disc `i` (to the point itself where its neighbours span no plane).
    fn disc_distance(&self, i: usize, q: [f64; 3]) -> f64 {
        let w = sub(q, self.points[i]);
        let n = self.normals[i];
        if n == [0.0; 3] {
            return norm(w);
        }
        let h = dot(w, n);
        let rho = norm(std::array::from_fn(|k| w[k] - h * n[k]));
        if rho <= self.radius {
            h.abs()
        } else {
            ((rho - self.radius).powi(2) + h * h).sqrt()
        }
    }

    /// Distance from `q` to the nearest disc. Exact over all discs: the disc of a point at
    /// distance `D` is at least `D − radius` away, so once the best disc found is nearer than
    /// that for every point not yet tried, the search stops. Cost: a few kd-tree queries.
    pub fn distance(&self, q: [f64; 3]) -> f64 {
        let k = NonZeroUsize::new(FIRST_TRIED.min(self.points.len())).expect("points");
        let near = self
            .tree
            .query(&q)
            .nearest_n::<SquaredEuclidean<f64>>(k)
            .execute();
        let mut best = near
            .iter()
            .map(|r| self.disc_distance(r.item as usize, q))
            .fold(f64::INFINITY, f64::min);
        let farthest = near.last().map_or(0.0, |r| r.distance.max(0.0).sqrt());
        if near.len() < self.points.len() && farthest < best + self.radius {
            let reach = best + self.radius;
            self.tree
                .query(&q)
                .within::<SquaredEuclidean<f64>>(reach * reach)
                .unsorted()
                .visit(|r| best = best.min(self.disc_distance(r.item as usize, q)));
        }
        best
    }
}

/// The unit normal of the points `idx` of `points`: the eigenvector of their covariance with the
/// smallest eigenvalue; zero when they span no plane (coincident or collinear: the middle
/// eigenvalue below 1e-12 of the largest, relative to rounding).
fn pca_normal(points: &[[f64; 3]], idx: &[usize]) -> [f64; 3] {
    let n = idx.len() as f64;
    let mut c = [0.0; 3];
    for &i in idx {
        for k in 0..3 {
            c[k] += points[i][k] / n;
        }
    }
    let mut m = Matrix3::<f64>::zeros();
    for &i in idx {
        let d = sub(points[i], c);
        for a in 0..3 {
            for b in 0..3 {
                m[(a, b)] += d[a] * d[b];
            }
        }
    }
    let e = m.symmetric_eigen();
    let mut order = [0, 1, 2];
    order.sort_by(|&a, &b| e.eigenvalues[a].total_cmp(&e.eigenvalues[b]));
    if e.eigenvalues[order[1]] <= 1e-12 * e.eigenvalues[order[2]] {
        return [0.0; 3];
    }
    let v = e.eigenvectors.column(order[0]);
    let l = v.norm();
    [v[0] / l, v[1] / l, v[2] / l]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn discs_of_a_square_grid() {
        // A 21 × 21 grid of spacing 0.1 in z = 0: the 12th neighbour of an interior point is at
        // distance 0.2 (4 at 0.1, 4 at 0.141, 4 at 0.2), so is the median.
        let mut p = Vec::new();
        for j in 0..21 {
            for i in 0..21 {
                p.push([0.1 * i as f64, 0.1 * j as f64, 0.0]);
            }
        }
        let d = Discs::new(&p).unwrap();
        assert!((d.radius() - 0.2).abs() < 1e-12, "{}", d.radius());
        assert!(d.normals.iter().all(|n| (n[2].abs() - 1.0).abs() < 1e-12));
        // Above the data: the height. Past its edge (x = 2): the distance to the rim.
        assert!((d.distance([1.03, 0.97, 0.25]) - 0.25).abs() < 1e-12);
        assert!((d.distance([2.5, 1.0, 0.0]) - 0.3).abs() < 1e-12);
        let far = d.distance([2.5, 1.0, 0.4]);
        assert!((far - (0.09f64 + 0.16).sqrt()).abs() < 1e-12, "{far}");
        // Thirteen copies of one point and a line: no plane, so points.
        let mut q = vec![[0.0; 3]; 13];
        q.extend((0..13).map(|i| [1.0 + i as f64, 0.0, 0.0]));
        let d = Discs::new(&q).unwrap();
        assert!(d.normals.iter().all(|&n| n == [0.0; 3]));
        assert!((d.distance([0.0, 0.5, 0.0]) - 0.5).abs() < 1e-15);
    }
}
