//! Topology-preserving mesh simplification by quadric-error edge collapse.
//!
//! Garland & Heckbert 1997 ("Surface simplification using quadric error metrics"): every vertex
//! carries the sum of the area-weighted squared-distance quadrics of the planes of its faces;
//! an edge `ab` costs `pᵀ(Q_a + Q_b)p` at the position `p` minimizing it (a 3×3 solve, with the
//! endpoints and the midpoint as fallbacks); edges are collapsed cheapest first from a 4-ary
//! heap whose stale entries are recognised by per-vertex version stamps (lazy invalidation).
//!
//! A collapse is legal only when
//! * it satisfies the **link condition** of Dey, Edelsbrunner, Guha & Nekhayev 1999
//!   ("Topology preserving edge contraction"): `Lk(a) ∩ Lk(b) = Lk(ab)`. Boundaries are handled
//!   as in that paper by a virtual vertex `ω` joined to every boundary vertex, so an interior edge
//!   between two boundary vertices is never collapsed (it would pinch), boundary loops are never
//!   closed or merged, and a boundary vertex is never moved into the interior;
//! * no remaining face changes orientation: each changed face normal rotates by at most
//!   [`SimplifyOptions::max_normal_rotation_deg`];
//! * no remaining face becomes degenerate (shape quality below
//!   [`SimplifyOptions::min_triangle_quality`], unless it was already that bad).
//!
//! Boundary edges add constraint planes through the edge, perpendicular to its face (weight
//! [`SimplifyOptions::boundary_weight`] × edge length²), so boundaries keep their shape. When
//! exactly one endpoint of an edge is on the boundary, the collapse keeps the boundary vertex
//! where it is.
//!
//! **Sharp features** ([`simplify_with_features`]): the sharp edges of the input (from
//! `subfit_target::detect_features`) stay edges of the output. A vertex on a feature curve is
//! removed only by a collapse along its curve into a neighbour on the same curve (the kept
//! vertex stays where it is, so the cage's sharp edges stay on the data's), and only when it has
//! exactly two sharp edges and is not a corner; corners, darts and junctions are never removed.
//! Each sharp edge adds the constraint planes of a boundary edge for both of its faces, so a
//! curve's shape costs as a boundary's does. The surviving sharp edges come back as
//! infinitely sharp crease tags, the corners as corner tags (OpenSubdiv semantics; Lavoué et al.
//! 2005 §6 tag patch boundaries the same way; Hoppe et al. 1994 tag by hand).
//!
//! Data structure: a flat triangle list with per-vertex face lists updated per collapse. Cost:
//! `O(E log E)` overall; each collapse touches the two-ring of the kept vertex.

use std::cmp::Ordering;

use crate::heap::{Entry, QuadHeap};
use subfit_mesh::vec3::{add, cross, dot, norm, scale, sub};
use subfit_mesh::{Cancel, Cancelled, HalfEdgeMesh, PolyMesh, Polygons, Tags, SHARPNESS_INFINITE};

mod options;
mod quadric;

pub use options::{FeatureLock, SimplifyError, SimplifyOptions, SimplifyReport};
use quadric::{add_q, eval_q, plane_quadric, q_minimizer, q_weight, Quadric};

/// Candidate collapses examined between two polls of [`SimplifyOptions::cancel`] (well under a
/// millisecond of work).
const COLLAPSE_BATCH: usize = 1024;

/// Simplifies a manifold, oriented polygon mesh (faces are fan-triangulated) by
/// topology-preserving quadric edge collapses until `options.target_vertices` vertices remain or
/// no legal collapse is left (see the module docs). Genus, boundary loops and components are
/// preserved; unreferenced input vertices are dropped.
///
/// Returns a compact triangle mesh (`#V' by 3` positions, re-indexed; attributes dropped) and a
/// report. Cost: `O(E log E)` time, `O(V + F)` memory. [`SimplifyError::Interrupted`] once
/// [`SimplifyOptions::cancel`] is cancelled.
pub fn simplify(
    mesh: &PolyMesh,
    options: &SimplifyOptions,
) -> Result<(PolyMesh, SimplifyReport), SimplifyError> {
    let (out, _, report) = simplify_with_features(mesh, &FeatureLock::default(), options)?;
    Ok((out, report))
}

/// [`simplify`] keeping the sharp edges and corners of `features` (see the module docs): the
/// output's surviving sharp edges and corners are returned as infinitely sharp tags
/// ([`SHARPNESS_INFINITE`]) in the output's vertex ids. Feature edges that are not edges of
/// the mesh, and ids out of range, are ignored.
pub fn simplify_with_features(
    mesh: &PolyMesh,
    features: &FeatureLock,
    options: &SimplifyOptions,
) -> Result<(PolyMesh, Tags, SimplifyReport), SimplifyError> {
    if mesh.faces.is_empty() {
        return Err(SimplifyError::NoFaces);
    }
    if let Some(v) = mesh
        .positions
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        return Err(SimplifyError::NonFinite { vertex: v });
    }
    let tris = mesh.faces.triangulate_fan();
    let polys = Polygons::from_triangles(&tris);
    HalfEdgeMesh::new(&polys, mesh.num_vertices())?;

    let cancel = &options.cancel;
    cancel.check()?;
    let target = options.target_vertices;
    let mut c = collapse(mesh.positions.clone(), tris.clone(), features, options)?;
    // Stuck far above the target: the input's noise is the likely cause (see
    // [`crate::denoise`]); simplify a smoothed copy instead when that gets further.
    if c.alive_vertices > target + target / STUCK_FRACTION {
        let smoothed = crate::denoise::taubin(&mesh.positions, &tris, DENOISE_PASSES);
        let d = collapse(smoothed, tris, features, options)?;
        if d.alive_vertices < c.alive_vertices {
            c = d;
            c.report.smoothed = true;
        }
    }
    Ok(c.finish(&features.corners))
}

/// A simplification that stops more than `1/STUCK_FRACTION` of the target above it is rerun on
/// a smoothed copy of the input ([`SimplifyReport::smoothed`]).
const STUCK_FRACTION: usize = 10;

/// Taubin passes of that smoothing ([`crate::denoise`]): enough to flatten vertex noise of
/// the order of the edge length (the noisy Igea cut above: 1,631 → 541 vertices).
const DENOISE_PASSES: usize = 10;

/// Collapses cheapest first down to the target; when stuck before it, retries the rejected
/// collapses with relaxed geometric checks (never beyond a 90° normal rotation or a zero-area
/// face).
fn collapse(
    positions: Vec<[f64; 3]>,
    tris: Vec<[u32; 3]>,
    features: &FeatureLock,
    options: &SimplifyOptions,
) -> Result<Collapser, Cancelled> {
    let cancel = &options.cancel;
    let mut c = Collapser::new(positions, tris, features, options);
    c.run(options.target_vertices, cancel)?;
    for (deg, quality) in [(85.0, 0.25), (89.0, 0.02)] {
        if c.alive_vertices <= options.target_vertices {
            break;
        }
        c.relax(
            options.max_normal_rotation_deg.max(deg),
            options.min_triangle_quality * quality,
        );
        c.run(options.target_vertices, cancel)?;
    }
    Ok(c)
}

/// A collapse about to be checked or performed.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    cost: f64,
    keep: u32,
    remove: u32,
    pos: [f64; 3],
}

enum Verdict {
    Ok,
    Link,
    Boundary,
    Flip,
    Degenerate,
    Feature,
}

struct Collapser {
    pos: Vec<[f64; 3]>,
    quad: Vec<Quadric>,
    /// Sum of the area-weighted normals of the input faces merged into each vertex.
    vnormal: Vec<[f64; 3]>,
    tris: Vec<[u32; 3]>,
    face_alive: Vec<bool>,
    vfaces: Vec<Vec<u32>>,
    boundary: Vec<bool>,
    /// Sharp-edge neighbours of each vertex (empty off the features).
    sharp: Vec<Vec<u32>>,
    /// Corners, darts and junctions of the features: never removed.
    pinned: Vec<bool>,
    stamp: Vec<u32>,
    /// Whether a collapse of an edge at this vertex was rejected since its edges were last queued.
    dirty: Vec<bool>,
    alive_vertices: usize,
    heap: QuadHeap,
    min_cos: f64,
    min_quality: f64,
    min_area2: f64,
    exact_error: f64,
    report: SimplifyReport,
    scratch_a: Vec<u32>,
    scratch_b: Vec<u32>,
}

impl Collapser {
    fn new(
        pos: Vec<[f64; 3]>,
        tris: Vec<[u32; 3]>,
        features: &FeatureLock,
        options: &SimplifyOptions,
    ) -> Self {
        let nv = pos.len();
        let mut vfaces = vec![Vec::new(); nv];
        for (f, t) in tris.iter().enumerate() {
            for &v in t {
                vfaces[v as usize].push(f as u32);
            }
        }
        // Directed edges without a reverse are boundary edges (the input is oriented).
        let mut directed: Vec<(u32, u32)> = tris
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .collect();
        directed.sort_unstable();
        let has = |a: u32, b: u32| directed.binary_search(&(a, b)).is_ok();
        let mut quad = vec![[0.0; 10]; nv];
        let mut boundary = vec![false; nv];
        let mut vnormal = vec![[0.0; 3]; nv];
        let mut diag2: f64 = 0.0;
        for t in &tris {
            let [p0, p1, p2] = t.map(|v| pos[v as usize]);
            let n = cross(sub(p1, p0), sub(p2, p0));
            let len = norm(n);
            diag2 = diag2.max(dot(sub(p1, p0), sub(p1, p0)));
            for &v in t {
                vnormal[v as usize] = add(vnormal[v as usize], n);
            }
            if len > 0.0 {
                let nu = scale(n, 1.0 / len);
                let q = plane_quadric(nu, p0, 0.5 * len);
                for &v in t {
                    add_q(&mut quad[v as usize], &q);
                }
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    if !has(b, a) {
                        boundary[a as usize] = true;
                        boundary[b as usize] = true;
                        let e = sub(pos[b as usize], pos[a as usize]);
                        let m = cross(e, nu);
                        let ml = norm(m);
                        if ml > 0.0 {
                            let w = options.boundary_weight * dot(e, e);
                            let qb = plane_quadric(scale(m, 1.0 / ml), pos[a as usize], w);
                            add_q(&mut quad[a as usize], &qb);
                            add_q(&mut quad[b as usize], &qb);
                        }
                    }
                }
            }
        }
        let (sharp, pinned) = sharp_edges(&pos, &tris, &vfaces, features, options, &mut quad);
        let alive_vertices = vfaces.iter().filter(|f| !f.is_empty()).count();
        let report = SimplifyReport {
            vertices_before: alive_vertices,
            faces_before: tris.len(),
            ..SimplifyReport::default()
        };
        let nf = tris.len();
        let mut c = Self {
            pos,
            quad,
            vnormal,
            tris,
            face_alive: vec![true; nf],
            vfaces,
            boundary,
            sharp,
            pinned,
            stamp: vec![0; nv],
            dirty: vec![false; nv],
            alive_vertices,
            heap: QuadHeap(Vec::with_capacity(3 * nf / 2 + 16)),
            min_cos: options.max_normal_rotation_deg.to_radians().cos(),
            min_quality: options.min_triangle_quality,
            min_area2: (1e-14 * diag2.max(f64::MIN_POSITIVE)).powi(2),
            exact_error: options.exact_error.max(0.0),
            report,
            scratch_a: Vec::new(),
            scratch_b: Vec::new(),
        };
        for &(a, b) in &directed {
            if a < b || directed.binary_search(&(b, a)).is_err() {
                c.push(a, b);
            }
        }
        c
    }

    /// Sorted neighbours of `v` into `out`.
    fn ring(&self, v: u32, out: &mut Vec<u32>) {
        out.clear();
        for &f in &self.vfaces[v as usize] {
            for &u in &self.tris[f as usize] {
                if u != v {
                    out.push(u);
                }
            }
        }
        out.sort_unstable();
        out.dedup();
    }

    /// Whether removing `r` into `k` can keep the features and boundaries: `r` is not pinned,
    /// a curve vertex goes only along its curve, a boundary vertex only along the boundary.
    fn removable(&self, r: usize, k: u32) -> bool {
        !self.pinned[r]
            && (self.sharp[r].is_empty() || self.sharp[r].contains(&k))
            && (!self.boundary[r] || self.boundary[k as usize])
    }

    fn push(&mut self, a: u32, b: u32) {
        let (ai, bi) = (a as usize, b as usize);
        let (keep, remove) = match (self.removable(bi, a), self.removable(ai, b)) {
            (true, false) => (a, b),
            (false, true) => (b, a),
            // Along a curve either way: the cheaper of the two half-edge collapses.
            (true, true) if !self.sharp[ai].is_empty() => {
                if self.plan(bi, ai).0 < self.plan(ai, bi).0 {
                    (b, a)
                } else {
                    (a, b)
                }
            }
            _ if self.boundary[bi] && !self.boundary[ai] => (b, a),
            _ => (a, b),
        };
        let (ki, ri) = (keep as usize, remove as usize);
        let (cost, _) = self.plan(ki, ri);
        self.heap.push(Entry {
            cost,
            keep,
            remove,
            stamp_keep: self.stamp[ki],
            stamp_remove: self.stamp[ri],
        });
    }

    /// Cost and position of the collapse `remove → keep`: the quadric minimizer (near the
    /// edge), else the best of the endpoints and the midpoint; the kept vertex's position when
    /// only one is on the boundary or either is on a feature curve.
    fn plan(&self, ki: usize, ri: usize) -> (f64, [f64; 3]) {
        let mut q = self.quad[ki];
        add_q(&mut q, &self.quad[ri]);
        let pos = if self.boundary[ki] != self.boundary[ri]
            || !self.sharp[ki].is_empty()
            || !self.sharp[ri].is_empty()
        {
            self.pos[ki]
        } else {
            let (pa, pb) = (self.pos[ki], self.pos[ri]);
            let mid = scale(add(pa, pb), 0.5);
            let len = norm(sub(pa, pb));
            match q_minimizer(&q) {
                Some(p) if norm(sub(p, mid)) <= 2.0 * len => p,
                _ => [pa, pb, mid]
                    .into_iter()
                    .min_by(|x, y| eval_q(&q, *x).total_cmp(&eval_q(&q, *y)))
                    .unwrap_or(mid),
            }
        };
        (eval_q(&q, pos).max(0.0), pos)
    }

    /// Relaxes the geometric checks and re-queues the edges of every vertex that had a
    /// collapse rejected.
    fn relax(&mut self, max_rotation_deg: f64, min_quality: f64) {
        self.report.relaxations += 1;
        self.min_cos = max_rotation_deg.to_radians().cos();
        self.min_quality = min_quality;
        let mut ring = Vec::new();
        for v in 0..self.pos.len() as u32 {
            if !self.dirty[v as usize] || self.vfaces[v as usize].is_empty() {
                continue;
            }
            self.dirty[v as usize] = false;
            self.stamp[v as usize] = self.stamp[v as usize].wrapping_add(1);
            self.ring(v, &mut ring);
            for &u in &ring {
                self.push(v, u);
            }
        }
    }

    /// Collapses cheapest first until `target` vertices remain (then on, with
    /// [`SimplifyOptions::exact_error`], only collapses within it) or the heap is empty; polls
    /// `cancel` every [`COLLAPSE_BATCH`] candidates.
    fn run(&mut self, target: usize, cancel: &Cancel) -> Result<(), Cancelled> {
        let mut examined = 0usize;
        let exact2 = self.exact_error * self.exact_error;
        while self.alive_vertices > target || exact2 > 0.0 {
            if examined % COLLAPSE_BATCH == 0 {
                cancel.check()?;
            }
            examined += 1;
            let Some(e) = self.heap.pop() else { break };
            let (k, r) = (e.keep as usize, e.remove as usize);
            if self.stamp[k] != e.stamp_keep
                || self.stamp[r] != e.stamp_remove
                || self.vfaces[k].is_empty()
                || self.vfaces[r].is_empty()
            {
                continue;
            }
            let (cost, pos) = self.plan(k, r);
            if self.alive_vertices <= target {
                // Past the target: only collapses that keep the surface where it is.
                let mut q = self.quad[k];
                add_q(&mut q, &self.quad[r]);
                if cost > exact2 * q_weight(&q) {
                    continue;
                }
            }
            let mut c = Candidate {
                cost,
                keep: e.keep,
                remove: e.remove,
                pos,
            };
            let mut verdict = self.check(c.keep, c.remove, c.pos);
            if self.report.relaxations > 0
                && matches!(verdict, Verdict::Flip | Verdict::Degenerate)
                && self.boundary[k] == self.boundary[r]
                && self.sharp[k].is_empty()
                && self.sharp[r].is_empty()
            {
                // Stuck: try the half-edge collapses, which leave one endpoint where it is.
                let mut q = self.quad[k];
                add_q(&mut q, &self.quad[r]);
                for p in [self.pos[k], self.pos[r]] {
                    if matches!(self.check(c.keep, c.remove, p), Verdict::Ok) {
                        c.pos = p;
                        c.cost = eval_q(&q, p).max(0.0);
                        verdict = Verdict::Ok;
                        break;
                    }
                }
            }
            match verdict {
                Verdict::Ok => self.collapse(&c),
                Verdict::Link => self.report.rejected_link += 1,
                Verdict::Boundary => self.report.rejected_boundary += 1,
                Verdict::Flip => self.report.rejected_flip += 1,
                Verdict::Degenerate => self.report.rejected_degenerate += 1,
                Verdict::Feature => self.report.rejected_feature += 1,
            }
            if !matches!(verdict, Verdict::Ok) {
                self.dirty[k] = true;
                self.dirty[r] = true;
            }
        }
        self.report.reached_target = self.alive_vertices <= target;
        Ok(())
    }

    /// Faces containing both `a` and `b`, and their third vertices.
    fn edge_opposites(&self, a: u32, b: u32) -> ([u32; 2], usize) {
        let mut opp = [u32::MAX; 2];
        let mut n = 0;
        for &f in &self.vfaces[a as usize] {
            let t = self.tris[f as usize];
            if t.contains(&b) {
                if n < 2 {
                    opp[n] = t.iter().copied().find(|&u| u != a && u != b).unwrap_or(a);
                }
                n += 1;
            }
        }
        (opp, n)
    }

    fn check(&mut self, k: u32, r: u32, p: [f64; 3]) -> Verdict {
        if !self.removable(r as usize, k) {
            return Verdict::Feature;
        }
        // Along a curve: its next vertex must not already be the kept one's sharp neighbour
        // (a closed curve of three would fold onto one edge).
        if let [x, y] = self.sharp[r as usize][..] {
            let next = if x == k { y } else { x };
            if self.sharp[k as usize].contains(&next) {
                return Verdict::Feature;
            }
        }
        let (opp, n_opp) = self.edge_opposites(k, r);
        if n_opp == 0 || n_opp > 2 {
            return Verdict::Link;
        }
        let (ki, ri) = (k as usize, r as usize);
        // ω (the virtual vertex behind the boundary) is in Lk(k) ∩ Lk(r) but not in Lk(kr)
        // when both are boundary vertices and kr is an interior edge.
        if self.boundary[ki] && self.boundary[ri] && n_opp == 2 {
            return Verdict::Boundary;
        }
        // An isolated triangle (a boundary loop of length 3) would vanish.
        if n_opp == 1 && self.vfaces[ki].len() == 1 && self.vfaces[ri].len() == 1 {
            return Verdict::Boundary;
        }
        let mut ra = std::mem::take(&mut self.scratch_a);
        let mut rb = std::mem::take(&mut self.scratch_b);
        self.ring(k, &mut ra);
        self.ring(r, &mut rb);
        let link_ok = {
            let opp = &opp[..n_opp.min(2)];
            let (mut i, mut j) = (0, 0);
            let mut ok = true;
            while i < ra.len() && j < rb.len() {
                match ra[i].cmp(&rb[j]) {
                    Ordering::Less => i += 1,
                    Ordering::Greater => j += 1,
                    Ordering::Equal => {
                        if !opp.contains(&ra[i]) {
                            ok = false;
                            break;
                        }
                        i += 1;
                        j += 1;
                    }
                }
            }
            ok
        };
        self.scratch_a = ra;
        self.scratch_b = rb;
        if !link_ok {
            return Verdict::Link;
        }
        // Lk(k) ∩ Lk(r) must not contain the edge `cd` between the two opposite vertices (the
        // tetrahedron case). `cd` is in Lk(k) when the face (k, c, d) exists, in Lk(r) when
        // (r, c, d) does: only both together would duplicate a face. (One alone is the common
        // case of a valence-3 endpoint, which must stay collapsible: marching tetrahedra make
        // many, and blocking them stalled the Igea contour at ~2,400 vertices.)
        if n_opp == 2 {
            let (c, d) = (opp[0], opp[1]);
            let dup = [ki, ri].iter().all(|&v| {
                self.vfaces[v].iter().any(|&f| {
                    let t = self.tris[f as usize];
                    t.contains(&c) && t.contains(&d)
                })
            });
            if dup {
                return Verdict::Link;
            }
        }
        for &v in &[k, r] {
            for &f in &self.vfaces[v as usize] {
                let t = self.tris[f as usize];
                if t.contains(&k) && t.contains(&r) {
                    continue;
                }
                let old = t.map(|u| self.pos[u as usize]);
                let new = t.map(|u| {
                    if u == k || u == r {
                        p
                    } else {
                        self.pos[u as usize]
                    }
                });
                let n_old = cross(sub(old[1], old[0]), sub(old[2], old[0]));
                let n_new = cross(sub(new[1], new[0]), sub(new[2], new[0]));
                let (l_old, l_new) = (norm(n_old), norm(n_new));
                if !(l_new * l_new > self.min_area2) {
                    return Verdict::Degenerate;
                }
                // The rotation of a sliver's normal is noise: for those (quality below 0.1)
                // only the reference check below applies.
                let q_old = quality(&old, l_old);
                if q_old >= 0.1 && dot(n_old, n_new) < self.min_cos * l_old * l_new {
                    return Verdict::Flip;
                }
                // Against the accumulated input normals too, so that many small rotations
                // cannot add up to a fold.
                let reference = t.iter().fold([0.0; 3], |acc, &u| {
                    let n = if u == k || u == r {
                        add(self.vnormal[ki], self.vnormal[ri])
                    } else {
                        self.vnormal[u as usize]
                    };
                    let l = norm(n);
                    if l > 0.0 {
                        add(acc, scale(n, 1.0 / l))
                    } else {
                        acc
                    }
                });
                if dot(reference, n_new) <= 0.0 {
                    return Verdict::Flip;
                }
                let q_new = quality(&new, l_new);
                if q_new < self.min_quality && q_new < q_old {
                    return Verdict::Degenerate;
                }
            }
        }
        Verdict::Ok
    }

    fn collapse(&mut self, c: &Candidate) {
        let (k, r) = (c.keep, c.remove);
        let (ki, ri) = (k as usize, r as usize);
        let rfaces = std::mem::take(&mut self.vfaces[ri]);
        for &f in &rfaces {
            let fi = f as usize;
            let t = self.tris[fi];
            if t.contains(&k) {
                self.face_alive[fi] = false;
                for &u in &t {
                    if u != r {
                        self.vfaces[u as usize].retain(|&g| g != f);
                    }
                }
            } else {
                for u in self.tris[fi].iter_mut() {
                    if *u == r {
                        *u = k;
                    }
                }
                self.vfaces[ki].push(f);
            }
        }
        for c in std::mem::take(&mut self.sharp[ri]) {
            self.sharp[c as usize].retain(|&x| x != r);
            if c != k {
                self.sharp[c as usize].push(k);
                self.sharp[ki].push(c);
            }
        }
        let q_r = self.quad[ri];
        add_q(&mut self.quad[ki], &q_r);
        self.pos[ki] = c.pos;
        self.vnormal[ki] = add(self.vnormal[ki], self.vnormal[ri]);
        self.boundary[ki] |= self.boundary[ri];
        self.alive_vertices -= 1;
        self.report.collapses += 1;
        let w = q_weight(&self.quad[ki]);
        if w > 0.0 {
            self.report.max_error = self.report.max_error.max((c.cost / w).sqrt());
        }
        // Re-queue the edges of the kept vertex (their costs changed) and of the neighbours
        // that had a collapse rejected (it may have become legal).
        let mut around = std::mem::take(&mut self.scratch_a);
        self.ring(k, &mut around);
        around.retain(|&v| self.dirty[v as usize]);
        around.push(k);
        for &v in &around {
            self.stamp[v as usize] = self.stamp[v as usize].wrapping_add(1);
            self.dirty[v as usize] = false;
        }
        let mut ring = std::mem::take(&mut self.scratch_b);
        for &v in &around {
            self.ring(v, &mut ring);
            for &u in &ring {
                if u > v || !around.contains(&u) {
                    self.push(v, u);
                }
            }
        }
        self.scratch_a = around;
        self.scratch_b = ring;
    }

    fn finish(self, corners: &[u32]) -> (PolyMesh, Tags, SimplifyReport) {
        let mut map = vec![u32::MAX; self.pos.len()];
        let mut positions = Vec::with_capacity(self.alive_vertices);
        let mut tris = Vec::new();
        for (f, t) in self.tris.iter().enumerate() {
            if !self.face_alive[f] {
                continue;
            }
            let t = t.map(|v| {
                let m = &mut map[v as usize];
                if *m == u32::MAX {
                    *m = positions.len() as u32;
                    positions.push(self.pos[v as usize]);
                }
                *m
            });
            tris.push(t);
        }
        let mut tags = Tags::new();
        for (v, around) in self.sharp.iter().enumerate() {
            for &u in around {
                let (a, b) = (map[v], map[u as usize]);
                if (v as u32) < u && a != u32::MAX && b != u32::MAX {
                    tags.set_crease(a, b, SHARPNESS_INFINITE);
                }
            }
        }
        for &c in corners {
            if let Some(&m) = map.get(c as usize).filter(|&&m| m != u32::MAX) {
                tags.set_corner(m, SHARPNESS_INFINITE);
            }
        }
        let mut report = self.report;
        report.vertices_after = positions.len();
        report.faces_after = tris.len();
        (
            PolyMesh::new(positions, Polygons::from_triangles(&tris)),
            tags,
            report,
        )
    }
}

/// The sharp-edge neighbours of every vertex (the feature edges that are mesh edges) and the
/// pinned vertices (corners, and feature vertices without exactly two sharp edges); adds each
/// sharp edge's constraint planes (through the edge, perpendicular to each of its faces,
/// weighted as boundary edges) to the quadrics of its ends.
fn sharp_edges(
    pos: &[[f64; 3]],
    tris: &[[u32; 3]],
    vfaces: &[Vec<u32>],
    features: &FeatureLock,
    options: &SimplifyOptions,
    quad: &mut [Quadric],
) -> (Vec<Vec<u32>>, Vec<bool>) {
    let nv = pos.len();
    let mut sharp: Vec<Vec<u32>> = vec![Vec::new(); nv];
    let mut pinned = vec![false; nv];
    for &[a, b] in &features.edges {
        let (ai, bi) = (a as usize, b as usize);
        if a == b || ai >= nv || bi >= nv || sharp[ai].contains(&b) {
            continue;
        }
        let faces: Vec<u32> = vfaces[ai]
            .iter()
            .copied()
            .filter(|&f| tris[f as usize].contains(&b))
            .collect();
        if faces.is_empty() {
            continue;
        }
        sharp[ai].push(b);
        sharp[bi].push(a);
        let e = sub(pos[bi], pos[ai]);
        for f in faces {
            let [p0, p1, p2] = tris[f as usize].map(|v| pos[v as usize]);
            let m = cross(e, cross(sub(p1, p0), sub(p2, p0)));
            let ml = norm(m);
            if ml > 0.0 {
                let q = plane_quadric(
                    scale(m, 1.0 / ml),
                    pos[ai],
                    options.boundary_weight * dot(e, e),
                );
                add_q(&mut quad[ai], &q);
                add_q(&mut quad[bi], &q);
            }
        }
    }
    for &c in &features.corners {
        if let Some(p) = pinned.get_mut(c as usize) {
            *p = true;
        }
    }
    for (p, s) in pinned.iter_mut().zip(&sharp) {
        *p |= !s.is_empty() && s.len() != 2;
    }
    (sharp, pinned)
}

/// `4√3·A / Σ l²` with `2A = area2`.
fn quality(p: &[[f64; 3]; 3], area2: f64) -> f64 {
    let s = dot(sub(p[1], p[0]), sub(p[1], p[0]))
        + dot(sub(p[2], p[1]), sub(p[2], p[1]))
        + dot(sub(p[0], p[2]), sub(p[0], p[2]));
    if s > 0.0 {
        2.0 * 3f64.sqrt() * area2 / s
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadric_minimizer_of_three_planes_is_their_corner() {
        let mut q = plane_quadric([1.0, 0.0, 0.0], [0.3, 0.0, 0.0], 1.0);
        add_q(
            &mut q,
            &plane_quadric([0.0, 1.0, 0.0], [0.0, -0.2, 0.0], 2.0),
        );
        add_q(
            &mut q,
            &plane_quadric([0.0, 0.0, 1.0], [0.0, 0.0, 0.7], 0.5),
        );
        let p = q_minimizer(&q).unwrap();
        for (x, y) in p.iter().zip([0.3, -0.2, 0.7]) {
            assert!((x - y).abs() < 1e-12);
        }
        assert!(eval_q(&q, p).abs() < 1e-12);
        assert!((eval_q(&q, [0.3, -0.2, 1.7]) - 0.5).abs() < 1e-12);
        assert_eq!(q_weight(&q), 3.5);
    }
}
