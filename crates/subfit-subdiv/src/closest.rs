//! Closest point on the limit surface from any query point.
//!
//! 1. Start: a BVH ([`subfit_mesh::bvh`]) over a tessellation of the limit surface (each patch's
//!    domain cut into an `r × r` grid, corners evaluated exactly and remembered as
//!    `(face, sub, u, v)`) gives the nearest tessellation triangle; its barycentric point is
//!    mapped to parameters.
//! 2. Refine: Newton's method on `F(u, v) = ½ |S(u, v) − q|²` with the exact first and second
//!    derivatives of [`crate::eval`] (Hessian `JᵀJ + Σ r·S_ij`), Levenberg-Marquardt damping when
//!    the Hessian is not positive definite or a step does not decrease `F`. Steps that leave the
//!    patch stop at its edge and continue in the adjacent patch with the parameters mapped across
//!    the shared edge (control-mesh edges, and the inner edges of Catmull-Clark `n`-gons'
//!    sub-quads).
//!
//! Convergence: the residual is `|r − (r·n) n| / |r|` with `r = S − q` — the sine of the angle
//! between `r` and the normal, i.e. the gradient of the squared distance projected on the tangent
//! plane, relative to the distance — and the search stops below `tolerance` (default 1e-10), or
//! when `|r|` is below 1e-14 of the mesh size (the query is on the surface). At a mesh boundary
//! the closest point may be on the boundary curve, where this residual need not vanish: there the
//! domain constraint is active (moving into the surface does not decrease `F`), the Newton step
//! is restricted to the boundary edge (a projected Newton step, 1-D along the edge), and the
//! residual counts only the gradient along the boundary (`|r·S_t| / (|r| |S_t|)` with `S_t` the
//! derivative along the edge); at a boundary corner with both constraints active it is 0. So
//! queries whose closest point is on the boundary converge too.

use crate::eval::{EvalError, EvalKind, Evaluator, SurfaceParam, SurfacePoint};
use crate::scheme::Scheme;
use rayon::prelude::*;
use std::collections::HashMap;
use subfit_mesh::bvh::TriangleBvh;
use subfit_mesh::vec3::{dot, sub};

/// Other patches [`ClosestPointFinder::closest`] descends from when the starts near the
/// nearest tessellation triangle stop short of a stationary point.
const MAX_OTHER_PATCHES: usize = 16;

/// A descent that ends farther than twice the query's distance to the tessellation plus this
/// fraction of the mesh size is retried ([`ClosestPointFinder::closest`]): it stopped at a
/// stationary point across a crease (the rounded prism's cap, 2.5e-3 from a point on it).
/// Below it the tessellation's own chordal error could be the difference.
const SUSPECT: f64 = 1e-4;

/// Options of the closest-point search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestOptions {
    /// Tessellation resolution per patch edge for the starting guess. Default 4 (16 quads or
    /// 16 triangles per patch).
    pub resolution: u32,
    /// Iteration limit of the Newton search. Default 50.
    pub max_iterations: u32,
    /// Residual tolerance (dimensionless sine, see the module docs). Default 1e-10.
    pub tolerance: f64,
}

impl Default for ClosestOptions {
    fn default() -> Self {
        Self {
            resolution: 4,
            max_iterations: 50,
            tolerance: 1e-10,
        }
    }
}

/// The closest point found for one query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestPoint {
    /// Parameters of the closest point.
    pub param: SurfaceParam,
    /// The closest point on the limit surface.
    pub position: [f64; 3],
    /// Unit normal there (front side by face winding).
    pub normal: [f64; 3],
    /// `|q − S|`.
    pub distance: f64,
    /// `(q − S) · n`: positive on the side the normal points to.
    pub signed_distance: f64,
    /// Final residual (see the module docs).
    pub residual: f64,
    /// Newton iterations used.
    pub iterations: u32,
    /// Whether the residual reached the tolerance.
    pub converged: bool,
}

/// Where a patch edge lies: a control-mesh edge `(a, b)` with `a < b` (parameter 0 at `a`), or
/// the inner spoke `m` of a Catmull-Clark `n`-gon (parameter 0 at the edge point of edge
/// `m − 1 → m`, 1 at the face point).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum EdgeKey {
    Mesh(u32, u32),
    Spoke(u32, u32),
}

#[derive(Clone, Copy, Debug)]
struct EdgeSpan {
    patch: u32,
    edge: u8,
    t0: f64,
    t1: f64,
}

/// A reusable closest-point searcher for one control mesh and one set of control points.
///
/// Construction evaluates the tessellation (`#patches · (r+1)²` exact evaluations, parallel) and
/// builds the BVH; a query costs one BVH descent plus a few exact evaluations per Newton step.
pub struct ClosestPointFinder<'a> {
    ev: &'a Evaluator,
    positions: Vec<[f64; 3]>,
    opts: ClosestOptions,
    bvh: TriangleBvh,
    tri_params: Vec<[SurfaceParam; 3]>,
    edges: HashMap<EdgeKey, Vec<EdgeSpan>>,
    patch_edges: Vec<[(EdgeKey, f64, f64); 4]>,
    scale: f64,
}

impl<'a> ClosestPointFinder<'a> {
    /// Builds a finder for `evaluator` with control points `positions` (`#V by 3`).
    ///
    /// Errors: wrong number of positions, or an evaluation failure.
    pub fn new(
        evaluator: &'a Evaluator,
        positions: &[[f64; 3]],
        opts: ClosestOptions,
    ) -> Result<Self, EvalError> {
        if positions.len() != evaluator.num_vertices() {
            return Err(EvalError::PositionCount {
                expected: evaluator.num_vertices(),
                got: positions.len(),
            });
        }
        let r = opts.resolution.max(1);
        let per_patch: Vec<Vec<TessTriangle>> = (0..evaluator.num_patches())
            .into_par_iter()
            .map(|pi| {
                let (face, sub) = evaluator.patch(pi);
                let tri = evaluator.triangle_patch(face);
                let prm = |i: u32, j: u32| SurfaceParam {
                    face,
                    sub,
                    u: i as f64 / r as f64,
                    v: j as f64 / r as f64,
                };
                let mut cache: HashMap<(u32, u32), [f64; 3]> = HashMap::new();
                let mut pos = |i: u32, j: u32| -> Result<[f64; 3], EvalError> {
                    if let Some(p) = cache.get(&(i, j)) {
                        return Ok(*p);
                    }
                    let p = evaluator.evaluate(positions, prm(i, j))?.position;
                    cache.insert((i, j), p);
                    Ok(p)
                };
                let mut out = Vec::new();
                let mut push =
                    |a: (u32, u32), b: (u32, u32), c: (u32, u32)| -> Result<(), EvalError> {
                        let t = [pos(a.0, a.1)?, pos(b.0, b.1)?, pos(c.0, c.1)?];
                        out.push((t, [prm(a.0, a.1), prm(b.0, b.1), prm(c.0, c.1)]));
                        Ok(())
                    };
                for j in 0..r {
                    for i in 0..r {
                        if tri {
                            if i + j < r {
                                push((i, j), (i + 1, j), (i, j + 1))?;
                            }
                            if i + j + 1 < r {
                                push((i + 1, j), (i + 1, j + 1), (i, j + 1))?;
                            }
                        } else {
                            push((i, j), (i + 1, j), (i + 1, j + 1))?;
                            push((i, j), (i + 1, j + 1), (i, j + 1))?;
                        }
                    }
                }
                Ok(out)
            })
            .collect::<Result<_, EvalError>>()?;
        let mut tris = Vec::new();
        let mut tri_params = Vec::new();
        for (t, p) in per_patch.into_iter().flatten() {
            tris.push(t);
            tri_params.push(p);
        }
        let scale = subfit_mesh::bounding_box(positions)
            .map(|(lo, hi)| {
                ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
            })
            .unwrap_or(1.0)
            .max(f64::MIN_POSITIVE);
        let (edges, patch_edges) = edge_spans(evaluator);
        Ok(Self {
            ev: evaluator,
            positions: positions.to_vec(),
            opts,
            bvh: TriangleBvh::from_triangles(tris),
            tri_params,
            edges,
            patch_edges,
            scale,
        })
    }

    /// The centre of `face`'s parameter domain (triangle or square).
    fn centre(&self, face: u32) -> (f64, f64) {
        if self.ev.triangle_patch(face) {
            (1.0 / 3.0, 1.0 / 3.0)
        } else {
            (0.5, 0.5)
        }
    }

    /// `(u, v)` on `base`'s patch, moved 1e-3 of the way towards its centre (off a corner,
    /// where the parametrisation may be singular).
    fn nudged(&self, base: SurfaceParam, u: f64, v: f64) -> SurfaceParam {
        let (cu, cv) = self.centre(base.face);
        let e = 1e-3;
        SurfaceParam {
            u: u + e * (cu - u),
            v: v + e * (cv - v),
            ..base
        }
    }

    /// The parameters of the point with `barycentric` coordinates in tessellation triangle
    /// `triangle`, [`Self::nudged`].
    fn param_at(&self, triangle: u32, barycentric: [f64; 3]) -> SurfaceParam {
        let ps = &self.tri_params[triangle as usize];
        let (mut u, mut v) = (0.0, 0.0);
        for (p, w) in ps.iter().zip(barycentric) {
            u += w * p.u;
            v += w * p.v;
        }
        self.nudged(ps[0], u, v)
    }

    /// Starting parameters: the nearest tessellation point, then (for a search that gets stuck)
    /// the corners of its triangle and the centre of its patch; all moved slightly towards the
    /// centre, off the patch corners where the parametrisation may be singular.
    ///
    /// Also returns `q`'s distance to the tessellation.
    fn starts(&self, q: [f64; 3]) -> Option<([SurfaceParam; 5], f64)> {
        let n = self.bvh.closest(q)?;
        let ps = &self.tri_params[n.triangle as usize];
        let (cu, cv) = self.centre(ps[0].face);
        let corner = |k: usize| self.nudged(ps[0], ps[k].u, ps[k].v);
        Some((
            [
                self.param_at(n.triangle, n.barycentric),
                corner(0),
                corner(1),
                corner(2),
                self.nudged(ps[0], cu, cv),
            ],
            n.distance,
        ))
    }

    fn eval(&self, p: SurfaceParam) -> Result<SurfacePoint, EvalError> {
        let r = self.ev.evaluate(&self.positions, p)?;
        if r.kind == EvalKind::Patch {
            return Ok(r);
        }
        // Exactly at an irregular vertex there are no parametric derivatives: nudge inside.
        let (cu, cv) = self.centre(p.face);
        let e = 1e-9;
        self.ev.evaluate(
            &self.positions,
            SurfaceParam {
                u: p.u + e * (cu - p.u),
                v: p.v + e * (cv - p.v),
                ..p
            },
        )
    }

    /// The closest point on the limit surface to `q`.
    ///
    /// Errors: evaluation failures (none are expected for a valid mesh); an empty mesh gives
    /// [`EvalError::FaceOutOfRange`].
    pub fn closest(&self, q: [f64; 3]) -> Result<ClosestPoint, EvalError> {
        let (starts, near) = self.starts(q).ok_or(EvalError::FaceOutOfRange {
            face: 0,
            num_faces: 0,
        })?;
        let mut best = self.descend(q, starts[0])?;
        // Stuck short of a stationary point (at a crease or a singular corner of the
        // parametrisation): try again from the other corners of the starting triangle and the
        // patch's centre, and keep the nearest point found.
        let better = |c: &ClosestPoint, best: &ClosestPoint| {
            c.distance < best.distance || (c.converged && c.distance <= best.distance)
        };
        for &p in &starts[1..] {
            if best.converged {
                break;
            }
            let c = self.descend(q, p)?;
            if better(&c, &best) {
                best = c;
            }
        }
        // Stuck (short of a stationary point, or at one on the wrong side of a crease: the
        // descent can step over the crease into a neighbouring patch and stop at its edge,
        // farther than the tessellation from the query): descend again from the start
        // patches without leaving them, and from the other patches that come that near.
        if !best.converged || best.distance > 2.0 * near + SUSPECT * self.scale {
            for &p in &starts {
                let c = self.descend_within(q, p, false)?;
                if better(&c, &best) {
                    best = c;
                }
            }
            let first = (starts[0].face, starts[0].sub);
            let mut tried = vec![first];
            let mut others = self.bvh.within(q, best.distance * (1.0 + 1e-9));
            others.sort_by(|a, b| a.distance.total_cmp(&b.distance));
            for n in others {
                if tried.len() > MAX_OTHER_PATCHES || best.distance <= 2.0 * near {
                    break;
                }
                let p = self.param_at(n.triangle, n.barycentric);
                if tried.contains(&(p.face, p.sub)) {
                    continue;
                }
                tried.push((p.face, p.sub));
                let c = self.descend(q, p)?;
                if better(&c, &best) {
                    best = c;
                }
            }
        }
        Ok(best)
    }

    /// The descent of [`Self::closest`] from the parameters `p`.
    fn descend(&self, q: [f64; 3], p: SurfaceParam) -> Result<ClosestPoint, EvalError> {
        self.descend_within(q, p, true)
    }

    /// [`Self::descend`], crossing into neighbouring patches only when `cross`.
    fn descend_within(
        &self,
        q: [f64; 3],
        mut p: SurfaceParam,
        cross: bool,
    ) -> Result<ClosestPoint, EvalError> {
        let mut s = self.eval(p)?;
        let mut f = half_norm2(sub(s.position, q));
        let mut mu = 0.0f64;
        let mut iterations = 0;
        let mut came_from: Option<u32> = None;
        let mut f_at_cross = f64::INFINITY;
        let mut residual = self.residual(p, &s, q);
        while iterations < self.opts.max_iterations {
            if residual <= self.opts.tolerance {
                break;
            }
            iterations += 1;
            // Next to a patch corner the parametrisation may be singular (an extraordinary
            // vertex): try the corner itself, where the limit masks give the exact normal.
            if let Some((c, cs)) = self.corner_candidate(p)? {
                let cf = half_norm2(sub(cs.position, q));
                // The exact corner's tangents come from limit masks, not the parametrisation:
                // only the unconstrained residual is meaningful there.
                let cres = self.free_residual(&cs, q);
                if cf <= f * (1.0 + 1e-13) && cres <= self.opts.tolerance {
                    p = c;
                    s = cs;
                    residual = cres;
                    break;
                }
            }
            let r = sub(s.position, q);
            let (su, sv) = (s.du, s.dv);
            let g = [dot(su, r), dot(sv, r)];
            let mut h = [[dot(su, su), dot(su, sv)], [dot(su, sv), dot(sv, sv)]];
            let jtj = [h[0][0], h[1][1]];
            if let Some([suu, suv, svv]) = s.second {
                h[0][0] += dot(suu, r);
                h[0][1] += dot(suv, r);
                h[1][0] += dot(suv, r);
                h[1][1] += dot(svv, r);
            }
            let boundary = self.mesh_boundary_edges(p);
            let mut accepted = false;
            for _ in 0..30 {
                let a = [
                    [h[0][0] + mu * jtj[0], h[0][1]],
                    [h[1][0], h[1][1] + mu * jtj[1]],
                ];
                let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
                let free = (a[0][0] > 0.0 && det > 0.0).then(|| {
                    [
                        -(a[1][1] * g[0] - a[0][1] * g[1]) / det,
                        -(-a[1][0] * g[0] + a[0][0] * g[1]) / det,
                    ]
                });
                // On a mesh boundary where the constraint is active (moving into the surface
                // does not decrease F, or the Newton step points out of it): Newton along the
                // boundary edge only, which needs only positive curvature along the edge.
                let inward =
                    |b: &&BoundaryEdge, x: [f64; 2]| b.inward[0] * x[0] + b.inward[1] * x[1];
                let active = boundary
                    .iter()
                    .find(|b| inward(b, g) >= 0.0 || free.is_some_and(|d| inward(b, d) < 0.0));
                let d = match (active, free) {
                    (Some(b), _) => match b.restricted_step(g, a) {
                        Some(d) => d,
                        None => {
                            mu = (mu * 10.0).max(1e-3);
                            continue;
                        }
                    },
                    (None, Some(d)) => d,
                    (None, None) => {
                        mu = (mu * 10.0).max(1e-3);
                        continue;
                    }
                };
                let (mut cand, mut exit) = self.clip(p, d);
                if let Some(e) = exit {
                    // On the edge and pointing back into the patch just left: the minimum is on
                    // the shared edge, so move along it only.
                    let back = self
                        .cross(p, e)
                        .map(|(np, _)| self.ev.patch_index(np.face, np.sub) as u32);
                    if cand == p && back.is_some() && back == came_from && f >= f_at_cross {
                        (cand, exit) =
                            self.clip(p, along_edge(self.ev.triangle_patch(p.face), e, d));
                    }
                }
                let cs = self.eval(cand)?;
                let cf = half_norm2(sub(cs.position, q));
                // Near convergence F changes below its rounding: then accept a step that lowers
                // the residual without raising F beyond rounding.
                let flat = cf <= f * (1.0 + 1e-13) && self.residual(cand, &cs, q) < residual;
                if cf < f || flat || (cf <= f && exit.is_some()) {
                    let progressed = cf < f || flat;
                    p = cand;
                    s = cs;
                    f = cf;
                    mu *= 0.1;
                    if mu < 1e-12 {
                        mu = 0.0;
                    }
                    accepted = progressed;
                    if let Some(edge) = exit.filter(|_| cross) {
                        if let Some((np, left)) = self.cross(p, edge) {
                            let target = self.ev.patch_index(np.face, np.sub) as u32;
                            if progressed || came_from != Some(target) || f < f_at_cross {
                                came_from = Some(left);
                                f_at_cross = f;
                                p = np;
                                s = self.eval(p)?;
                                accepted = true;
                            }
                        }
                    }
                    break;
                }
                mu = (mu * 10.0).max(1e-3);
            }
            residual = self.residual(p, &s, q);
            if !accepted {
                break;
            }
        }
        let rr = sub(q, s.position);
        let distance = dot(rr, rr).sqrt();
        Ok(ClosestPoint {
            param: p,
            position: s.position,
            normal: s.normal,
            distance,
            signed_distance: dot(rr, s.normal),
            residual,
            iterations,
            converged: residual <= self.opts.tolerance,
        })
    }

    /// [`Self::closest`] for many queries in parallel (rayon), in input order.
    pub fn closest_batch(&self, queries: &[[f64; 3]]) -> Result<Vec<ClosestPoint>, EvalError> {
        queries.par_iter().map(|&q| self.closest(q)).collect()
    }

    /// The nearest patch corner and the surface there, when `p` is within 1e-3 of it.
    fn corner_candidate(
        &self,
        p: SurfaceParam,
    ) -> Result<Option<(SurfaceParam, SurfacePoint)>, EvalError> {
        let corners: &[(f64, f64)] = if self.ev.triangle_patch(p.face) {
            &[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]
        } else {
            &[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
        };
        for &(u, v) in corners {
            let d = (p.u - u).abs().max((p.v - v).abs());
            if d > 0.0 && d < 1e-3 {
                let c = SurfaceParam { u, v, ..p };
                return Ok(Some((c, self.ev.evaluate(&self.positions, c)?)));
            }
        }
        Ok(None)
    }

    /// The convergence measure at `p` (module docs): the tangential part of `r = S − q`
    /// relative to `|r|`; on a mesh boundary where moving into the surface would not decrease
    /// the distance (the constraint is active), only the part along the boundary counts, and at
    /// a boundary corner with both constraints active it is 0 (the KKT conditions hold).
    fn residual(&self, p: SurfaceParam, s: &SurfacePoint, q: [f64; 3]) -> f64 {
        let free = self.free_residual(s, q);
        if free == 0.0 {
            return 0.0;
        }
        let r = sub(s.position, q);
        let len = dot(r, r).sqrt();
        let g = [dot(s.du, r), dot(s.dv, r)];
        let active: Vec<BoundaryEdge> = self
            .mesh_boundary_edges(p)
            .into_iter()
            .filter(|b| b.inward[0] * g[0] + b.inward[1] * g[1] >= 0.0)
            .collect();
        match active.as_slice() {
            [] => free,
            [b] => {
                let st = [
                    b.tangent[0] * s.du[0] + b.tangent[1] * s.dv[0],
                    b.tangent[0] * s.du[1] + b.tangent[1] * s.dv[1],
                    b.tangent[0] * s.du[2] + b.tangent[1] * s.dv[2],
                ];
                let sl = dot(st, st).sqrt();
                if sl > 0.0 {
                    (dot(st, r).abs() / (sl * len)).min(free)
                } else {
                    free
                }
            }
            _ => 0.0,
        }
    }

    /// The tangential part of `r = S − q` relative to `|r|` (0 when `|r|` is below 1e-14 of the
    /// mesh size).
    fn free_residual(&self, s: &SurfacePoint, q: [f64; 3]) -> f64 {
        let r = sub(s.position, q);
        let len = dot(r, r).sqrt();
        if len <= 1e-14 * self.scale {
            return 0.0;
        }
        let rn = dot(r, s.normal);
        let t = [
            r[0] - rn * s.normal[0],
            r[1] - rn * s.normal[1],
            r[2] - rn * s.normal[2],
        ];
        dot(t, t).sqrt() / len
    }

    /// The edges of `p`'s patch that `p` lies on (within 1e-14 in parameters) and that are on
    /// the boundary of the surface (no patch across).
    fn mesh_boundary_edges(&self, p: SurfaceParam) -> Vec<BoundaryEdge> {
        const ON: f64 = 1e-14;
        let s2 = std::f64::consts::FRAC_1_SQRT_2;
        // (distance to the edge, inward normal, unit tangent, edge id)
        let cands: &[(f64, [f64; 2], [f64; 2], u8)] = if self.ev.triangle_patch(p.face) {
            &[
                (p.v, [0.0, 1.0], [1.0, 0.0], 0),
                (1.0 - p.u - p.v, [-1.0, -1.0], [-s2, s2], 1),
                (p.u, [1.0, 0.0], [0.0, 1.0], 2),
            ]
        } else {
            &[
                (p.v, [0.0, 1.0], [1.0, 0.0], 0),
                (1.0 - p.u, [-1.0, 0.0], [0.0, 1.0], 1),
                (1.0 - p.v, [0.0, -1.0], [1.0, 0.0], 2),
                (p.u, [1.0, 0.0], [0.0, 1.0], 3),
            ]
        };
        cands
            .iter()
            .filter(|c| c.0 <= ON && self.cross(p, c.3).is_none())
            .map(|&(_, inward, tangent, _)| BoundaryEdge { inward, tangent })
            .collect()
    }

    /// The point `p + d` clipped to the patch domain, and the patch edge where it was clipped.
    fn clip(&self, p: SurfaceParam, d: [f64; 2]) -> (SurfaceParam, Option<u8>) {
        let (u, v) = (p.u, p.v);
        // Each constraint: (value now, rate of change, edge id); value must stay ≥ 0.
        let tri = self.ev.triangle_patch(p.face);
        let cons: Vec<(f64, f64, u8)> = if tri {
            vec![(v, d[1], 0), (1.0 - u - v, -d[0] - d[1], 1), (u, d[0], 2)]
        } else {
            vec![
                (v, d[1], 0),
                (1.0 - u, -d[0], 1),
                (1.0 - v, -d[1], 2),
                (u, d[0], 3),
            ]
        };
        let mut alpha = 1.0;
        let mut edge = None;
        for (val, rate, e) in cons {
            if rate < 0.0 && val + rate < 0.0 {
                let a = (val / -rate).max(0.0);
                if a < alpha {
                    alpha = a;
                    edge = Some(e);
                }
            }
        }
        let mut c = SurfaceParam {
            u: u + alpha * d[0],
            v: v + alpha * d[1],
            ..p
        };
        // Land exactly on the edge.
        match (tri, edge) {
            (true, Some(0)) | (false, Some(0)) => c.v = 0.0,
            (true, Some(2)) | (false, Some(3)) => c.u = 0.0,
            (true, Some(1)) => {
                let s = c.u + c.v;
                if s > 0.0 {
                    c.u /= s;
                    c.v /= s;
                }
            }
            (false, Some(1)) => c.u = 1.0,
            (false, Some(2)) => c.v = 1.0,
            _ => {}
        }
        c.u = c.u.clamp(0.0, 1.0);
        c.v = c.v.clamp(0.0, 1.0);
        if tri && c.u + c.v > 1.0 {
            let s = c.u + c.v;
            c.u /= s;
            c.v /= s;
        }
        (c, edge)
    }

    /// The same surface point seen from the patch across `edge`, and the patch index left.
    fn cross(&self, p: SurfaceParam, edge: u8) -> Option<(SurfaceParam, u32)> {
        let s = edge_param(self.ev.triangle_patch(p.face), edge, p.u, p.v);
        let pi = self.ev.patch_index(p.face, p.sub) as u32;
        let (key, t0, t1) = self.patch_edges[pi as usize][edge as usize];
        let t = t0 + s * (t1 - t0);
        let other = self.edges.get(&key)?.iter().find(|e| {
            e.patch != pi && t >= e.t0.min(e.t1) - 1e-15 && t <= e.t0.max(e.t1) + 1e-15
        })?;
        let s2 = ((t - other.t0) / (other.t1 - other.t0)).clamp(0.0, 1.0);
        let (face, sub) = self.ev.patch(other.patch as usize);
        let (u, v) = edge_point(self.ev.triangle_patch(face), other.edge, s2);
        Some((SurfaceParam { face, sub, u, v }, pi))
    }
}

/// A patch edge on the boundary of the surface, in parameter space.
#[derive(Clone, Copy, Debug)]
struct BoundaryEdge {
    /// Normal pointing into the patch domain.
    inward: [f64; 2],
    /// Unit direction along the edge.
    tangent: [f64; 2],
}

impl BoundaryEdge {
    /// The (damped) Newton step restricted to the edge: `−(g·t)/(tᵀAt) t` for gradient `g`
    /// and the damped Hessian `a`; `None` when the curvature along the edge is not positive
    /// (then damping grows and the step is retried).
    fn restricted_step(&self, g: [f64; 2], a: [[f64; 2]; 2]) -> Option<[f64; 2]> {
        let t = self.tangent;
        let gt = g[0] * t[0] + g[1] * t[1];
        let ht =
            t[0] * (a[0][0] * t[0] + a[0][1] * t[1]) + t[1] * (a[1][0] * t[0] + a[1][1] * t[1]);
        if ht.is_nan() || ht <= 0.0 {
            return None;
        }
        let x = -gt / ht;
        // Exactly along the edge (no round-off component across it).
        Some(if t[0] == 0.0 {
            [0.0, x * t[1]]
        } else if t[1] == 0.0 {
            [x * t[0], 0.0]
        } else {
            [x * t[0], -x * t[0]]
        })
    }
}

/// The component of step `d` along patch edge `e`.
fn along_edge(tri: bool, e: u8, d: [f64; 2]) -> [f64; 2] {
    match (tri, e) {
        (true, 1) => {
            let t = 0.5 * (d[1] - d[0]);
            [-t, t]
        }
        (true, 0) | (false, 0) | (false, 2) => [d[0], 0.0],
        _ => [0.0, d[1]],
    }
}

/// Parameter along patch edge `e` (from corner `e` to corner `e + 1`) of the point `(u, v)`.
fn edge_param(tri: bool, e: u8, u: f64, v: f64) -> f64 {
    match (tri, e) {
        (true, 0) => u,
        (true, 1) => v / (u + v).max(f64::MIN_POSITIVE),
        (true, _) => 1.0 - v,
        (false, 0) => u,
        (false, 1) => v,
        (false, 2) => 1.0 - u,
        (false, _) => 1.0 - v,
    }
}

/// The point at parameter `s` along patch edge `e`.
fn edge_point(tri: bool, e: u8, s: f64) -> (f64, f64) {
    match (tri, e) {
        (true, 0) => (s, 0.0),
        (true, 1) => (1.0 - s, s),
        (true, _) => (0.0, 1.0 - s),
        (false, 0) => (s, 0.0),
        (false, 1) => (1.0, s),
        (false, 2) => (1.0 - s, 1.0),
        (false, _) => (0.0, 1.0 - s),
    }
}

/// A tessellation triangle: corner positions and corner parameters.
type TessTriangle = ([[f64; 3]; 3], [SurfaceParam; 3]);

type EdgeMaps = (
    HashMap<EdgeKey, Vec<EdgeSpan>>,
    Vec<[(EdgeKey, f64, f64); 4]>,
);

/// Where every patch edge lies on the control mesh (see [`EdgeKey`]).
fn edge_spans(ev: &Evaluator) -> EdgeMaps {
    let mesh_edge = |a: u32, b: u32, ta: f64, tb: f64| {
        // Parameter ta at a, tb at b, along the edge a→b measured from min(a, b).
        if a < b {
            (EdgeKey::Mesh(a, b), ta, tb)
        } else {
            (EdgeKey::Mesh(b, a), 1.0 - ta, 1.0 - tb)
        }
    };
    let mut per_patch = Vec::with_capacity(ev.num_patches());
    for (fi, face) in ev.faces().iter().enumerate() {
        let n = face.len();
        let nsub = ev.num_subpatches(fi as u32);
        if nsub == 1 {
            let mut e = [(EdgeKey::Mesh(0, 0), 0.0, 0.0); 4];
            for (j, ej) in e.iter_mut().enumerate().take(n) {
                *ej = mesh_edge(face[j], face[(j + 1) % n], 0.0, 1.0);
            }
            per_patch.push(e);
        } else {
            debug_assert_ne!(ev.options().scheme, Scheme::Loop);
            let f = fi as u32;
            for k in 0..n {
                let (vk, vn, vp) = (face[k], face[(k + 1) % n], face[(k + n - 1) % n]);
                per_patch.push([
                    // v_k → e_{k,k+1}: first half of edge (v_k, v_{k+1}).
                    mesh_edge(vk, vn, 0.0, 0.5),
                    // e_{k,k+1} → F: spoke k+1.
                    (EdgeKey::Spoke(f, ((k + 1) % n) as u32), 0.0, 1.0),
                    // F → e_{k−1,k}: spoke k, reversed.
                    (EdgeKey::Spoke(f, k as u32), 1.0, 0.0),
                    // e_{k−1,k} → v_k: second half of edge (v_{k−1}, v_k).
                    mesh_edge(vp, vk, 0.5, 1.0),
                ]);
            }
        }
    }
    let mut map: HashMap<EdgeKey, Vec<EdgeSpan>> = HashMap::new();
    for (pi, es) in per_patch.iter().enumerate() {
        let nedges = if ev.triangle_patch(ev.patch(pi).0) {
            3
        } else {
            4
        };
        for (j, &(key, t0, t1)) in es.iter().enumerate().take(nedges) {
            map.entry(key).or_default().push(EdgeSpan {
                patch: pi as u32,
                edge: j as u8,
                t0,
                t1,
            });
        }
    }
    (map, per_patch)
}

fn half_norm2(a: [f64; 3]) -> f64 {
    0.5 * dot(a, a)
}
