//! Foot-point queries: the closest point on the target to any point `x`, with the local frame,
//! signed distance and curvature data of the SD error term (Cheng 2007 §II-D3, eq. 5–6;
//! DESIGN.md §3.2).
//!
//! Method: the nearest data point by kd-tree (or, in batches and for warm-started queries, by
//! certified greedy descent over the 16-nearest-neighbour graph from a nearby point, with the
//! kd-tree as fallback: same result, fewer tree traversals), then the closest point on that
//! point's local quadric (Newton on the height function,
//! [`LocalQuadric::project_local`](crate::quadric::LocalQuadric::project_local)).
//! Where that one quadric is not to be trusted — next to a point whose quadric disagrees with
//! its neighbours' (creases, scanner debris), or over a sampling gap — the foot point is
//! instead blended over the quadrics of the 16 nearest data points (`blend` module; Ohtake et
//! al. 2003's partition of unity of local quadrics).
//!
//! The foot point on one quadric and the signs of its distance and radii ([`FootPoint`],
//! [`foot_point_on`], [`alpha_plus`]) live in the crate-private module `foot` and are
//! re-exported here.

use rayon::prelude::*;

use crate::blend::{blended, needs_blend, BLEND_K};
use crate::closest::MeshClosestPoint;
pub use crate::foot::{alpha_plus, foot_point_on, FootPoint};
use crate::target::Target;
use subfit_mesh::vec3::{cross, dot, scale, sub};

/// How much farther than the closest triangle a facing one may be
/// ([`Target::mesh_foot_points_facing`]): across a thin part the opposite wall is at most its
/// thickness away, while a facing triangle much farther off belongs to another part.
pub const FACING_REACH: f64 = 3.0;

/// Batches at least this large are processed in Morton order.
const SPATIAL_SORT_MIN: usize = 4096;

/// Queries per run in batches: within a run, each nearest-point search starts from the previous
/// query's nearest point; runs are processed in parallel.
const CHAIN: usize = 256;

impl Target {
    /// The foot point of `x` (normalized coordinates). Cost: one nearest-neighbour query (≈1 µs)
    /// plus a few Newton steps. Accurate where the nearest data point's quadric represents the
    /// surface (dense sampling, `|d|` well below the local radii of curvature); not checked.
    ///
    /// When the data point nearest to the first foot point may differ from the one nearest to
    /// `x` (queries far from the surface or near strong curvature), the projection is redone once
    /// on that point's quadric, which represents the surface better there. That second query is
    /// skipped when the foot point lies within half the nearest-neighbour spacing of the data
    /// point (then no other data point can be nearer to it: triangle inequality), so the result
    /// is the same as with the second query.
    ///
    /// Next to an untrusted quadric ([`crate::TargetStats::untrusted_quadrics`]) or over a
    /// sampling gap (the foot point farther than 0.4 of the neighbourhood radius from the data
    /// point whose quadric gave it), the signed distances
    /// and normals of the projections on the 16 nearest points' quadrics are blended instead
    /// (weights `exp(−|x − p_j|² / (R_j/2)²)`, points of an opposite-facing sheet left out);
    /// this costs one 16-nearest query and 16 projections more.
    pub fn foot_point(&self, x: [f64; 3]) -> FootPoint {
        self.foot_point_from(x, None).0
    }

    /// The slot (see `QueryLayout`) of the data point nearest to `x`: by greedy descent over
    /// the neighbour graph from slot `start` when given (see `NeighborGraph::descend`), else, or
    /// when the descent cannot certify its result, by the kd-tree. Exact either way (up to
    /// ties). (A kd-tree radius query bounded by the descent's distance was tried for the
    /// fallback: no faster on Igea, and much slower when the start is poor, as the radius then
    /// holds many points.)
    #[inline]
    fn nearest_from(&self, x: &[f64; 3], start: Option<u32>) -> u32 {
        let l = self.layout();
        match start.and_then(|s| l.descent.descend(&l.points, x, s)) {
            Some((c, true)) => c.index,
            _ => l.slot[self.index().nearest(x).index as usize],
        }
    }

    /// [`Self::foot_point`] with the nearest-point search started at slot `start`; also returns
    /// the slot of the data point nearest to `x`. Same result as [`Self::foot_point`] (up to
    /// distance ties).
    #[inline]
    fn foot_point_from(&self, x: [f64; 3], start: Option<u32>) -> (FootPoint, u32) {
        let l = self.layout();
        let i = self.nearest_from(&x, start);
        let (f, j) = self.nearest_quadric_foot(x, i);
        if !needs_blend(l, j as usize, &f) {
            return (f, i);
        }
        let near = self
            .index()
            .k_nearest(&x, BLEND_K)
            .into_iter()
            .map(|n| l.slot[n.index as usize] as usize);
        (blended(l, x, near, f), i)
    }

    /// The foot point of `x` on the quadric of its nearest data point (slot `i`), redone on
    /// the quadric of the data point nearest to that foot point when it is another one; also
    /// returns the slot whose quadric was used.
    #[inline]
    fn nearest_quadric_foot(&self, x: [f64; 3], i: u32) -> (FootPoint, u32) {
        let l = self.layout();
        let pi = l.points[i as usize];
        let f = foot_point_on(&l.quadrics[i as usize], pi, x, l.point[i as usize]);
        let d = sub(f.point, pi);
        let h = 0.5 * l.shortcut[i as usize];
        if dot(d, d) < h * h {
            return (f, i);
        }
        // The foot point is on the surface near point i: the descent from i almost always
        // certifies, sparing the second kd-tree query.
        let j = self.nearest_from(&f.point, Some(i));
        if j == i {
            return (f, i);
        }
        let g = foot_point_on(
            &l.quadrics[j as usize],
            l.points[j as usize],
            x,
            l.point[j as usize],
        );
        (g, j)
    }

    /// [`Self::foot_point`] for many points, in parallel (rayon); `#Q` results in order.
    /// Large batches are processed in Morton (Z-curve) order of the queries; within a run of
    /// consecutive queries the nearest-point search starts from the previous query's result
    /// (certified greedy descent, kd-tree fallback), so results equal [`Self::foot_point`]'s.
    pub fn foot_points(&self, xs: &[[f64; 3]]) -> Vec<FootPoint> {
        let mut out = vec![FootPoint::default(); xs.len()];
        self.foot_points_into(xs, &mut out);
        out
    }

    /// [`Self::foot_points`] into a caller-owned buffer (`out.len()` must equal `xs.len()`).
    ///
    /// # Panics
    /// If the lengths differ.
    #[track_caller]
    pub fn foot_points_into(&self, xs: &[[f64; 3]], out: &mut [FootPoint]) {
        assert_eq!(xs.len(), out.len(), "foot_points_into: length mismatch");
        if xs.len() < SPATIAL_SORT_MIN {
            out.par_chunks_mut(CHAIN)
                .zip(xs.par_chunks(CHAIN))
                .for_each(|(o, x)| {
                    let mut prev = None;
                    for (o, &x) in o.iter_mut().zip(x) {
                        let (f, i) = self.foot_point_from(x, prev);
                        (*o, prev) = (f, Some(i));
                    }
                });
            return;
        }
        let order = crate::neighbors::morton_order(xs);
        let mut sorted = vec![FootPoint::default(); xs.len()];
        sorted
            .par_chunks_mut(CHAIN)
            .zip(order.par_chunks(CHAIN))
            .for_each(|(o, q)| {
                let mut prev = None;
                for (o, &q) in o.iter_mut().zip(q) {
                    let (f, i) = self.foot_point_from(xs[q as usize], prev);
                    (*o, prev) = (f, Some(i));
                }
            });
        let mut rank = vec![0u32; xs.len()];
        for (r, &q) in order.iter().enumerate() {
            rank[q as usize] = r as u32;
        }
        out.par_iter_mut()
            .zip(rank.par_iter())
            .for_each(|(o, &r)| *o = sorted[r as usize]);
    }

    /// Warm-started [`Self::foot_points`] for queries that move little between calls (e.g. the
    /// fitter's samples between iterations). `hints[q]` is a data-point index near query `q`
    /// (typically the value this function stored there on the previous call); `u32::MAX` or any
    /// out-of-range value means none, and the previous query of the batch, or the kd-tree, is
    /// used instead. On return `hints[q]` holds the data point nearest to `xs[q]`.
    ///
    /// The nearest data point is found by greedy descent over a 16-nearest-neighbour graph from
    /// the hint. Greedy descent alone is not exact (it can stop at a local minimum); its result
    /// is accepted only when certified — at the local minimum `c`, at distance `d` from the
    /// query, `2d` is less than the distance from `c` to its 16th neighbour, which proves no
    /// other point is nearer — and otherwise the kd-tree is queried. So the results equal
    /// [`Self::foot_points`]' (up to exact distance ties); the hints only save time. Queries
    /// farther from the data than about the neighbour spacing (`d` above about 1.1 spacings)
    /// usually need the kd-tree, so the gain is largest near convergence. Parallel over
    /// chunks of consecutive queries, no reordering (give them in a spatially coherent order):
    /// cost O(#Q · steps · 16) when the hints are good.
    ///
    /// # Panics
    /// If `hints.len() != xs.len()` (a caller bug, like a length mismatch in
    /// [`Self::foot_points_into`]).
    #[track_caller]
    pub fn foot_points_hinted(&self, xs: &[[f64; 3]], hints: &mut [u32]) -> Vec<FootPoint> {
        assert_eq!(xs.len(), hints.len(), "foot_points_hinted: length mismatch");
        let n = self.len() as u32;
        let mut out = vec![FootPoint::default(); xs.len()];
        out.par_chunks_mut(CHAIN)
            .zip(xs.par_chunks(CHAIN))
            .zip(hints.par_chunks_mut(CHAIN))
            .for_each(|((o, x), h)| {
                let mut prev = None;
                let l = self.layout();
                for ((o, &x), h) in o.iter_mut().zip(x).zip(h.iter_mut()) {
                    let start = if *h < n {
                        Some(l.slot[*h as usize])
                    } else {
                        prev
                    };
                    let (f, i) = self.foot_point_from(x, start);
                    (*o, *h, prev) = (f, l.point[i as usize], Some(i));
                }
            });
        out
    }

    /// Exact closest point on the target's triangles (mesh targets only; `None` for point
    /// clouds or when the BVH was not built). Normalized coordinates.
    pub fn mesh_closest_point(&self, x: [f64; 3]) -> Option<MeshClosestPoint> {
        self.mesh()?.closest(x)
    }

    /// [`Self::mesh_closest_point`] for many points, in parallel.
    pub fn mesh_closest_points(&self, xs: &[[f64; 3]]) -> Option<Vec<MeshClosestPoint>> {
        let bvh = self.mesh()?;
        xs.par_iter().map(|&x| bvh.closest(x)).collect()
    }

    /// The foot point of `x` (normalized coordinates) on the target's triangles, with the frame
    /// and curvatures of the SD term (Cheng 2007 §II-D3): `point` is the exact closest point on
    /// the triangles ([`Self::mesh_closest_point`]); `normal` the barycentric blend of the
    /// vertex normals there, normalized (the triangle's own normal where that blend vanishes);
    /// `distance = (x − point)·normal`; the principal curvatures and directions are those of
    /// the quadric at the corner with the largest barycentric weight (`nearest`), their signs
    /// taken relative to `normal` and `t1` turned into its tangent plane, `t2 = normal × t1`.
    ///
    /// On a sparse or decimated mesh (a few thousand vertices) this is a better foot point
    /// than [`Self::foot_point`]'s: a quadric fitted to a handful of neighbours is off by more
    /// than a fitting tolerance. Falls back to [`Self::foot_point`] for point clouds, when the
    /// BVH was not built, or at a degenerate triangle. Cost: one BVH query (O(log #T)).
    ///
    /// On a CAD tessellation ([`Self::facets`]) the facets are the surface: see
    /// [`facet_foot_point`].
    pub fn mesh_foot_point(&self, x: [f64; 3]) -> FootPoint {
        self.mesh_foot_point_near(x, u32::MAX).0
    }

    /// [`Self::mesh_foot_point`] with the closest-triangle search bounded by triangle `hint`
    /// (e.g. this query's closest triangle last time: [`TriangleBvh::closest_near`]); also
    /// returns the closest triangle (`u32::MAX` when the quadric fallback answered). The same
    /// result as [`Self::mesh_foot_point`]; a good hint spares most of the BVH traversal.
    ///
    /// [`TriangleBvh::closest_near`]: subfit_mesh::bvh::TriangleBvh::closest_near
    pub fn mesh_foot_point_near(&self, x: [f64; 3], hint: u32) -> (FootPoint, u32) {
        let Some(bvh) = self.mesh() else {
            return (self.foot_point(x), u32::MAX);
        };
        let Some(c) = bvh.closest_near(x, hint) else {
            return (self.foot_point(x), u32::MAX);
        };
        (self.mesh_foot_from(x, &c), c.triangle)
    }

    /// [`Self::mesh_foot_point_near`] for many points: `hints[q]` is
    /// the closest triangle of query `q` last time (any out-of-range value: none), updated on
    /// return. Same results as [`Self::mesh_foot_point`] per query, in parallel.
    ///
    /// # Panics
    /// If `hints.len() != xs.len()`.
    #[track_caller]
    pub fn mesh_foot_points_hinted(&self, xs: &[[f64; 3]], hints: &mut [u32]) -> Vec<FootPoint> {
        assert_eq!(
            xs.len(),
            hints.len(),
            "mesh_foot_points_hinted: length mismatch"
        );
        xs.par_iter()
            .zip(hints.par_iter_mut())
            .map(|(&x, h)| {
                let (f, t) = self.mesh_foot_point_near(x, *h);
                *h = t;
                f
            })
            .collect()
    }

    /// [`Self::mesh_foot_points_hinted`] for points of a surface whose unit normals are
    /// `normals` (zero: unknown), taking the side of thin parts into account. Inside a thin
    /// part — a limb, a tentacle, a fin — a surface that has sunk past the middle is drawn by
    /// the plain closest point to the opposite wall, which pulls it further in: a fixed point
    /// of the closest-point fit whose error refinement cannot lower. So where a point lies
    /// behind its closest triangle, which faces away from the point's normal (cosine below
    /// −1/2), the closest triangle facing the same way (cosine above 1/2) within
    /// [`FACING_REACH`] times that distance is taken instead, if the point lies behind it too
    /// (inside the part both walls bound). This is the compatible-normals pairing of ICP
    /// (Turk & Levoy 1994; Rusinkiewicz & Levoy 2001) restricted to the inside of thin parts;
    /// it chooses which triangle pulls, while the error reported stays the plain distance
    /// ([`Self::mesh_foot_point`]). Outside the target (a web across a gap, a point in a
    /// narrow gap between two parts) the plain closest point is kept, and so it is on
    /// components that do not enclose a volume ([`Self::closed_components`]): a sheet has no
    /// inside.
    ///
    /// The triangles' orientation relative to the points' normals is taken by a majority of
    /// the points, on each connected component of the target's triangles
    /// ([`Self::triangle_components`]) on its own: a target oriented inwards, separate sheets
    /// oriented either way, or a surface facing the other way are handled. Returns the foot
    /// points and how many were taken on a facing triangle. `hints` as in
    /// [`Self::mesh_foot_points_hinted`] (the plain closest triangles are kept there).
    ///
    /// # Panics
    /// If `hints.len()` or `normals.len()` differs from `xs.len()`.
    #[track_caller]
    pub fn mesh_foot_points_facing(
        &self,
        xs: &[[f64; 3]],
        normals: &[[f64; 3]],
        hints: &mut [u32],
    ) -> (Vec<FootPoint>, usize) {
        assert_eq!(
            xs.len(),
            normals.len(),
            "mesh_foot_points_facing: length mismatch"
        );
        let mut feet = self.mesh_foot_points_hinted(xs, hints);
        let Some(bvh) = self.mesh() else {
            return (feet, 0);
        };
        let (labels, closed) = (self.triangle_components(), self.closed_components());
        let encloses = |t: u32| -> bool {
            let l = labels.get(t as usize).copied().unwrap_or(u32::MAX);
            closed.get(l as usize).copied().unwrap_or(false)
        };
        // The cosine between a point's normal and triangle t's normal.
        let cosine = |t: u32, n: [f64; 3]| -> f64 {
            let m = bvh.triangle_normal(t);
            let l = (dot(m, m) * dot(n, n)).sqrt();
            if l > 0.0 && l.is_finite() {
                dot(m, n) / l
            } else {
                0.0
            }
        };
        let cosines: Vec<f64> = hints
            .par_iter()
            .zip(normals.par_iter())
            .map(|(&t, &n)| {
                if (t as usize) < bvh.len() {
                    cosine(t, n)
                } else {
                    0.0
                }
            })
            .collect();
        // Per component: +1 when most points agree with its triangles, −1 when most disagree.
        let count = labels
            .iter()
            .filter(|&&l| l != u32::MAX)
            .map(|&l| l as usize + 1)
            .max();
        let mut votes = vec![0i64; count.unwrap_or(0)];
        for (&t, &c) in hints.iter().zip(&cosines) {
            if let Some(&l) = labels.get(t as usize) {
                if let Some(v) = votes.get_mut(l as usize) {
                    *v += i64::from(c > 0.0) - i64::from(c < 0.0);
                }
            }
        }
        let sign_of = |t: u32| -> f64 {
            let l = labels.get(t as usize).copied().unwrap_or(u32::MAX);
            match votes.get(l as usize) {
                Some(&v) if v < 0 => -1.0,
                _ => 1.0,
            }
        };
        // Whether x lies behind triangle t (oriented by its component's sign) at its point p.
        let behind = |t: u32, x: [f64; 3], p: [f64; 3]| -> bool {
            sign_of(t) * dot(sub(x, p), bvh.triangle_normal(t)) < 0.0
        };
        let swapped: Vec<(usize, FootPoint)> = cosines
            .par_iter()
            .enumerate()
            .filter(|&(i, &c)| {
                let t = hints[i];
                encloses(t) && sign_of(t) * c < -0.5 && behind(t, xs[i], feet[i].point)
            })
            .filter_map(|(i, _)| {
                let (x, n) = (xs[i], normals[i]);
                let d = sub(x, feet[i].point);
                let reach = FACING_REACH * FACING_REACH * dot(d, d);
                let c = bvh.closest_accepted(x, reach, |t| {
                    encloses(t) && sign_of(t) * cosine(t, n) > 0.5
                })?;
                behind(c.triangle, x, c.point).then(|| (i, self.mesh_foot_from(x, &c)))
            })
            .collect();
        let count = swapped.len();
        for (i, f) in swapped {
            feet[i] = f;
        }
        (feet, count)
    }

    /// The foot point of `x` whose closest point on the triangles is `c`
    /// ([`Self::mesh_foot_point`]).
    fn mesh_foot_from(&self, x: [f64; 3], c: &MeshClosestPoint) -> FootPoint {
        let Some(bvh) = self.mesh() else {
            return self.foot_point(x);
        };
        if self.facets().is_some() && c.face_normal != [0.0; 3] {
            let tri = bvh.triangles()[c.triangle as usize];
            return facet_foot_point(x, c, tri[0]);
        }
        let tri = bvh.triangles()[c.triangle as usize];
        let normals = self.normals();
        let mut n = [0.0; 3];
        for (&v, &b) in tri.iter().zip(&c.barycentric) {
            for (k, nk) in n.iter_mut().enumerate() {
                *nk += b * normals[v as usize][k];
            }
        }
        let len = dot(n, n).sqrt();
        let n = if len > 1e-12 {
            n.map(|a| a / len)
        } else if dot(c.face_normal, c.face_normal) > 0.5 {
            c.face_normal
        } else {
            return self.foot_point(x);
        };
        // The corner with the largest barycentric weight lends its curvature frame.
        let k = (0..3)
            .max_by(|&i, &j| c.barycentric[i].total_cmp(&c.barycentric[j]))
            .unwrap_or(0);
        let corner = tri[k];
        let f = self.quadrics()[corner as usize].frame_at(0.0, 0.0);
        // Curvature signs are relative to the frame's normal: flip them if it faces the other way.
        let s = if dot(f.normal, n) < 0.0 { -1.0 } else { 1.0 };
        let (k1, k2) = (s * f.k1, s * f.k2);
        let (t1, t2) = tangent_frame(n, f.t1);
        let distance = dot(sub(x, c.point), n);
        FootPoint {
            point: c.point,
            distance,
            normal: n,
            t1,
            t2,
            k1,
            k2,
            rho1: 1.0 / k1,
            rho2: 1.0 / k2,
            alpha1: alpha_plus(distance, k1),
            alpha2: alpha_plus(distance, k2),
            nearest: corner,
        }
    }
}

/// The foot point of `x` on a tessellation's facets, the closest point `c` (on a triangle
/// whose first corner is `corner`): the facets are flat, so both curvatures are 0 (the SD
/// term is the TD term), and the normal is the direction from the foot point to `x` — the
/// gradient of the distance to the facets, which is the facet's normal over its inside and
/// turns around its edges and corners, so that `Q (S − V) = S − V` holds there too (the
/// blended vertex normals of a smooth mesh tilt across a box's edges). Its sign follows the
/// facet's normal; `x` on the facets takes the facet's normal.
pub fn facet_foot_point(x: [f64; 3], c: &MeshClosestPoint, corner: u32) -> FootPoint {
    let d = sub(x, c.point);
    let len = dot(d, d).sqrt();
    let n = if len > 1e-14 {
        let s = if dot(d, c.face_normal) < 0.0 {
            -1.0
        } else {
            1.0
        };
        d.map(|a| s * a / len)
    } else {
        c.face_normal
    };
    let (t1, t2) = tangent_frame(n, [1.0, 0.0, 0.0]);
    FootPoint {
        point: c.point,
        distance: dot(d, n),
        normal: n,
        t1,
        t2,
        k1: 0.0,
        k2: 0.0,
        rho1: f64::INFINITY,
        rho2: f64::INFINITY,
        alpha1: 0.0,
        alpha2: 0.0,
        nearest: corner,
    }
}

/// The tangent frame `(t1, t2)` at the unit normal `n`: `t` projected into the plane ⟂ `n` and
/// normalized (any unit vector ⟂ `n` when `t` is nearly parallel to it), and `t2 = n × t1`.
fn tangent_frame(n: [f64; 3], t: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let t1p = sub(t, scale(n, dot(t, n)));
    let l1 = dot(t1p, t1p).sqrt();
    let t1 = if l1 > 1e-9 {
        t1p.map(|a| a / l1)
    } else {
        let a = if n[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let p = sub(a, scale(n, dot(a, n)));
        let l = dot(p, p).sqrt();
        p.map(|x| x / l)
    };
    (t1, cross(n, t1))
}
