//! [`Evaluator`]: construction (validation, regular level-0 patches), the walk down each patch's
//! memoised refinement tree, and single and batch evaluation.

use super::basis::{best_map, mul2, PatchCoef};
use super::memo::{make_node, MemoBudget, Node, CACHE_DEPTH, DEFAULT_CACHE_BYTES};
use super::shape::Shapes;
use super::types::{EvalError, EvalWeights, SurfaceParam, SurfacePoint};
use crate::error::SubdivError;
use crate::local::{
    corner_points, patch_scheme, regular_patch, two_ring, LocalMesh, BOUNDARY, SHARP,
};
use crate::scheme::{Options, Scheme};
use crate::topology::Topology;
use rayon::prelude::*;
use std::sync::OnceLock;
use subfit_mesh::{Polygons, Tags};

/// Exact evaluator of the limit surface of one control mesh (topology only; positions are passed
/// to each call, so one evaluator serves a fitter whose control points move).
///
/// Construction validates the mesh, classifies every patch and caches the control points of the
/// patches that are regular at level 0 (the common case). Cost O(#F · s) with `s` the size of a
/// two-ring (parallel); memory about 16–20 weights per cached patch point.
///
/// Memory after construction: evaluations memoise the local refinements of irregular patches
/// (up to [`CACHE_DEPTH`] levels, or `⌈s⌉ + 1` for the largest finite sharpness `s` of the
/// tags if more; tens of kB per patch evaluated near an irregular vertex), and the interned
/// neighbourhood topologies and refinement steps below them (shared by all patches; 3 MB on a
/// 1,143-face mixed torus), within a budget ([`Self::set_cache_budget`], default
/// [`DEFAULT_CACHE_BYTES`]); past it, evaluation stays exact but is not memoised.
/// [`Self::cache_bytes`] reports the memoised amount and [`Self::clear_cache`] drops it.
#[derive(Clone, Debug)]
pub struct Evaluator {
    pub(super) options: Options,
    faces: Polygons,
    num_vertices: usize,
    vf_off: Vec<u32>,
    vf: Vec<u32>,
    /// Per face corner: flags of the edge to the next corner.
    flags: Vec<u8>,
    /// Per face corner: finite sharpness of the edge to the next corner (empty without
    /// semi-sharp tags).
    semi: Vec<f32>,
    corner: Vec<bool>,
    /// Per vertex: finite corner sharpness (empty without semi-sharp tags).
    vsemi: Vec<f32>,
    /// Levels memoised per patch: [`CACHE_DEPTH`], or more with semi-sharp tags (one more than
    /// the levels their sharpness takes to decay, after which patches next to them are regular).
    cache_depth: u32,
    /// First patch of each face (`#F + 1` entries).
    patch_start: Vec<u32>,
    /// Memoised local-refinement tree of each patch (built on first use; regular level-0
    /// patches at construction).
    roots: Vec<OnceLock<Node>>,
    /// Bytes held by nodes memoised after construction, and the budget they may use.
    pub(super) memo: MemoBudget,
    /// Interned local topologies below the memoised levels and the steps between them
    /// (counted in `memo`).
    pub(super) shapes: Shapes,
}

impl Evaluator {
    /// Builds an evaluator for `faces` over `num_vertices` control points with crease/corner
    /// `tags` and `options` (scheme and boundary rule).
    ///
    /// Errors: bad topology or non-triangles for Loop ([`EvalError::Topology`]).
    pub fn new(
        faces: &Polygons,
        num_vertices: usize,
        tags: &Tags,
        options: &Options,
    ) -> Result<Self, EvalError> {
        if options.scheme == Scheme::Loop {
            if let Some((face, f)) = faces.iter().enumerate().find(|(_, f)| f.len() != 3) {
                return Err(SubdivError::NotTriangles { face, len: f.len() }.into());
            }
        }
        let topo = Topology::new(faces, num_vertices)?;
        let nf = faces.len();
        let mut flags = vec![0u8; faces.indices().len()];
        for f in 0..nf {
            let first = topo.face_first_corner(f);
            let fv = topo.face(f);
            for (i, &e) in topo.face_edges(f).iter().enumerate() {
                let (a, b) = (fv[i], fv[(i + 1) % fv.len()]);
                let mut fl = 0;
                if topo.is_boundary_edge(e) {
                    fl |= BOUNDARY | SHARP;
                }
                if !tags.is_empty() && tags.is_sharp_edge(a, b) {
                    fl |= SHARP;
                }
                flags[first + i] = fl;
            }
        }
        let corner = (0..num_vertices as u32)
            .map(|v| !tags.is_empty() && tags.is_corner(v))
            .collect();
        let (semi, vsemi) = if crate::refine::has_semi_sharp(tags) {
            let edges = crate::refine::semi_sharp_edges(&topo, tags);
            let semi = (0..nf)
                .flat_map(|f| topo.face_edges(f).iter().map(|&e| edges[e as usize]))
                .collect();
            (semi, crate::refine::semi_sharp_vertices(num_vertices, tags))
        } else {
            (Vec::new(), Vec::new())
        };
        let mut vf_off = vec![0u32; num_vertices + 1];
        for &v in faces.indices() {
            vf_off[v as usize + 1] += 1;
        }
        for i in 0..num_vertices {
            vf_off[i + 1] += vf_off[i];
        }
        let mut fill = vf_off.clone();
        let mut vf = vec![0u32; faces.indices().len()];
        for (f, face) in faces.iter().enumerate() {
            for &v in face {
                vf[fill[v as usize] as usize] = f as u32;
                fill[v as usize] += 1;
            }
        }
        let mut patch_start = Vec::with_capacity(nf + 1);
        patch_start.push(0u32);
        for face in faces.iter() {
            // n-gons (Catmull-Clark: any non-quad; quad/triangle: five sides or more) are
            // split into quad sub-patches.
            let n = match (options.scheme, face.len()) {
                (Scheme::CatmullClark, n) if n != 4 => n as u32,
                (Scheme::QuadTriangle, n) if n > 4 => n as u32,
                _ => 1,
            };
            patch_start.push(patch_start.last().unwrap() + n);
        }
        let mut ev = Self {
            options: *options,
            faces: faces.clone(),
            num_vertices,
            vf_off,
            vf,
            flags,
            cache_depth: CACHE_DEPTH.max(
                semi.iter()
                    .chain(&vsemi)
                    .fold(0.0f32, |a, &b| a.max(b))
                    .ceil() as u32
                    + 1,
            ),
            semi,
            corner,
            vsemi,
            patch_start,
            roots: Vec::new(),
            memo: MemoBudget::new(DEFAULT_CACHE_BYTES),
            shapes: Shapes::default(),
        };
        let regular: Vec<Option<PatchCoef>> = (0..nf)
            .into_par_iter()
            .map(|f| {
                let len = ev.faces.face_len(subfit_mesh::FaceId(f as u32));
                if len != patch_scheme(options.scheme, len).regular_face_size() {
                    return None;
                }
                let (mesh, t) = ev.extract(f as u32);
                let adj = mesh.adjacency();
                regular_patch(&mesh, &adj, options.scheme, t).map(|c| PatchCoef::new(&mesh, &c))
            })
            .collect();
        // One entry per patch: n-gon sub-patches are never regular at level 0.
        let mut roots = Vec::with_capacity(*ev.patch_start.last().unwrap() as usize);
        for (f, r) in regular.into_iter().enumerate() {
            let n = ev.patch_start[f + 1] - ev.patch_start[f];
            if n == 1 {
                let cell = OnceLock::new();
                if let Some(pc) = r {
                    let _ = cell.set(Node::Regular(pc));
                }
                roots.push(cell);
            } else {
                roots.extend((0..n).map(|_| OnceLock::new()));
            }
        }
        ev.roots = roots;
        Ok(ev)
    }

    /// Sets the memory budget (bytes) of the local refinements memoised by [`Self::weights`]
    /// (default [`DEFAULT_CACHE_BYTES`]; the per-patch nodes and the shared shapes of the walk
    /// below them may each use this much). Once the memoised nodes hold this much, further
    /// evaluations still work and give the same results (to round-off), but go on from the
    /// deepest memoised node each time (through the shared shapes while they fit, by plain
    /// local refinement after) instead of memoising more; 0 turns memoisation off.
    /// The budget is checked before each node is added, so concurrent evaluations may exceed it
    /// by one node (tens of kB) per thread. Does not drop what is already memoised (see
    /// [`Self::clear_cache`]).
    pub fn set_cache_budget(&mut self, bytes: usize) {
        self.memo.budget = bytes;
    }

    /// Builder-style [`Self::set_cache_budget`].
    pub fn with_cache_budget(mut self, bytes: usize) -> Self {
        self.set_cache_budget(bytes);
        self
    }

    /// The memory budget of memoised local refinements, in bytes.
    pub fn cache_budget(&self) -> usize {
        self.memo.budget
    }

    /// Approximate heap bytes held by local refinements memoised since construction (array
    /// payloads; the regular level-0 patches built by [`Self::new`] are not counted): the
    /// per-patch nodes and the shared shapes, each kept within [`Self::cache_budget`].
    pub fn cache_bytes(&self) -> usize {
        self.memo.total()
    }

    /// Drops every memoised local refinement (keeping the regular level-0 patches built by
    /// [`Self::new`]). Cost O(#patches).
    pub fn clear_cache(&mut self) {
        for (pi, cell) in self.roots.iter_mut().enumerate() {
            let keep = matches!(cell.get(), Some(Node::Regular(_))) && {
                let f = self.patch_start.partition_point(|&s| s as usize <= pi) - 1;
                self.patch_start[f + 1] - self.patch_start[f] == 1
            };
            if !keep {
                *cell = OnceLock::new();
            }
        }
        self.shapes.clear();
        *self.memo.used.get_mut() = 0;
        *self.memo.shape_used.get_mut() = 0;
    }

    /// The options (scheme, boundary rule).
    pub fn options(&self) -> &Options {
        &self.options
    }

    /// The control faces.
    pub fn faces(&self) -> &Polygons {
        &self.faces
    }

    /// Number of control points.
    pub fn num_vertices(&self) -> usize {
        self.num_vertices
    }

    /// Number of parameter patches: one per face, except `n` per Catmull-Clark `n`-gon (`n ≠ 4`).
    pub fn num_patches(&self) -> usize {
        *self.patch_start.last().unwrap() as usize
    }

    /// Number of sub-patches of face `f` (1, or `n` for a Catmull-Clark `n`-gon with `n ≠ 4`).
    ///
    /// # Panics
    /// If `f` is out of range.
    #[track_caller]
    pub fn num_subpatches(&self, f: u32) -> usize {
        (self.patch_start[f as usize + 1] - self.patch_start[f as usize]) as usize
    }

    /// The `(face, sub)` of patch `p` (`0 ≤ p < num_patches()`), patches numbered face by face.
    ///
    /// # Panics
    /// If `p` is out of range.
    #[track_caller]
    pub fn patch(&self, p: usize) -> (u32, u32) {
        assert!(p < self.num_patches(), "patch {p} out of range");
        let f = self.patch_start.partition_point(|&s| s as usize <= p) - 1;
        (f as u32, (p - self.patch_start[f] as usize) as u32)
    }

    /// The patch index of `(face, sub)`.
    pub fn patch_index(&self, face: u32, sub: u32) -> usize {
        (self.patch_start[face as usize] + sub) as usize
    }

    /// Whether the patch of `(face, sub)` is regular at level 0 (evaluated directly, without
    /// local refinement).
    pub fn is_regular(&self, face: u32, sub: u32) -> bool {
        matches!(
            self.roots[self.patch_index(face, sub)].get(),
            Some(Node::Regular(_))
        )
    }

    /// Whether every patch of this evaluator is a triangle (Loop) rather than a quad.
    pub fn triangular(&self) -> bool {
        self.options.scheme == Scheme::Loop
    }

    /// Whether the patches of control face `face` are triangles (parameters `u, v ≥ 0`,
    /// `u + v ≤ 1`) rather than unit squares: a triangle under Loop or quad/triangle.
    pub fn triangle_patch(&self, face: u32) -> bool {
        let len = self.faces.face_len(subfit_mesh::FaceId(face));
        !self.options.scheme.splits_into_quads(len)
    }

    fn check(&self, p: &SurfaceParam) -> Result<(f64, f64), EvalError> {
        let nf = self.faces.len();
        if p.face as usize >= nf {
            return Err(EvalError::FaceOutOfRange {
                face: p.face,
                num_faces: nf,
            });
        }
        let count = self.num_subpatches(p.face);
        if p.sub as usize >= count {
            return Err(EvalError::SubOutOfRange {
                face: p.face,
                sub: p.sub,
                count,
            });
        }
        const TOL: f64 = 1e-9;
        let bad = || EvalError::OutOfDomain {
            face: p.face,
            u: p.u,
            v: p.v,
        };
        if !p.u.is_finite() || !p.v.is_finite() {
            return Err(bad());
        }
        let (mut u, mut v) = (p.u, p.v);
        if u < -TOL || v < -TOL {
            return Err(bad());
        }
        u = u.max(0.0);
        v = v.max(0.0);
        if self.triangle_patch(p.face) {
            if u + v > 1.0 + TOL {
                return Err(bad());
            }
            if u + v > 1.0 {
                let s = u + v;
                u /= s;
                v /= s;
            }
        } else {
            if u > 1.0 + TOL || v > 1.0 + TOL {
                return Err(bad());
            }
            u = u.min(1.0);
            v = v.min(1.0);
        }
        Ok((u, v))
    }

    /// The level-0 two-ring of face `f` as a [`LocalMesh`] with identity rows, and the local
    /// index of `f`.
    fn extract(&self, f: u32) -> (LocalMesh, usize) {
        let faces_of = |v: u32| {
            self.vf[self.vf_off[v as usize] as usize..self.vf_off[v as usize + 1] as usize].to_vec()
        };
        let face_verts = |g: u32| self.faces.face(subfit_mesh::FaceId(g)).to_vec();
        let f2 = two_ring(&faces_of, &face_verts, f);
        let mut verts: Vec<u32> = f2.iter().flat_map(|&g| face_verts(g)).collect();
        verts.sort_unstable();
        verts.dedup();
        let k = verts.len();
        let mut rows = vec![0.0; k * k];
        for i in 0..k {
            rows[i * k + i] = 1.0;
        }
        let mut mesh = LocalMesh {
            cols: verts.clone(),
            rows,
            fo: vec![0],
            fv: Vec::new(),
            fe: Vec::new(),
            fs: Vec::new(),
            vs: verts
                .iter()
                .map(|&v| self.vsemi.get(v as usize).copied().unwrap_or(0.0))
                .collect(),
            nfaces: verts
                .iter()
                .map(|&v| self.vf_off[v as usize + 1] - self.vf_off[v as usize])
                .collect(),
            corner: verts.iter().map(|&v| self.corner[v as usize]).collect(),
        };
        let mut t = 0;
        for (i, &g) in f2.iter().enumerate() {
            if g == f {
                t = i;
            }
            let start = self.faces.offsets()[g as usize] as usize;
            for (j, &v) in face_verts(g).iter().enumerate() {
                mesh.fv
                    .push(verts.binary_search(&v).expect("vertex of the two-ring") as u32);
                mesh.fe.push(self.flags[start + j]);
                mesh.fs
                    .push(self.semi.get(start + j).copied().unwrap_or(0.0));
            }
            mesh.fo.push(mesh.fv.len() as u32);
        }
        (mesh, t)
    }

    /// The weights of the limit position and derivatives at `p` over control points.
    ///
    /// Errors: out-of-range face/sub-patch, parameters outside the domain (by more than 1e-9;
    /// smaller excursions are clamped). Cost: one small dense product for a regular patch
    /// (a few µs); in an irregular patch about one local refinement per halving of the distance
    /// to the irregular vertex (`log2(1/distance)` levels of a ~30–60-vertex neighbourhood). The
    /// first [`CACHE_DEPTH`] levels (more with semi-sharp tags, see the type's docs) are memoised
    /// per patch, so only the first evaluation near a
    /// given corner pays for them. Deeper levels walk the evaluator's interned neighbourhood
    /// topologies, whose refinement steps are sparse matrices computed once (they recur near
    /// irregular vertices and along quad/triangle seams): O(6 · nnz(step)) per level plus one
    /// small product at the end. Thread-safe (`&self`; memoisation uses `OnceLock`).
    pub fn weights(&self, p: SurfaceParam) -> Result<EvalWeights, EvalError> {
        let (mut u, mut v) = self.check(&p)?;
        let scheme = self.options.scheme;
        let err = |depth| EvalError::Incomplete {
            face: p.face,
            depth,
        };
        let root_depth = u32::from(self.num_subpatches(p.face) > 1);
        let cell = &self.roots[self.patch_index(p.face, p.sub)];
        let owned;
        let mut node = match cell.get() {
            Some(n) => n,
            None if self.memo.full() => {
                owned = self.root_node(p.face, p.sub);
                &owned
            }
            None => cell.get_or_init(|| {
                let n = self.root_node(p.face, p.sub);
                self.memo.add(&n);
                n
            }),
        };
        let mut a = [[1.0, 0.0], [0.0, 1.0]];
        let mut depth = root_depth;
        loop {
            match node {
                Node::Failed => return Err(err(depth)),
                Node::Regular(pc) => return Ok(pc.eval(scheme, u, v, a, depth)),
                Node::Irregular {
                    mesh,
                    t,
                    kids,
                    maps,
                    shape,
                    ..
                } => {
                    let at = (*t, u, v, a, depth, p.face);
                    if self.irregular_corner(mesh, *t, u, v) {
                        return self.descend_rows((**mesh).clone(), *t, u, v, a, depth, p.face);
                    }
                    if depth >= self.cache_depth {
                        return self.descend(mesh, Some(shape), at);
                    }
                    let which = best_map(maps, u, v);
                    if kids[which].get().is_none() && self.memo.full() {
                        // Over the memory budget: refine from here without memoising.
                        return self.descend(mesh, Some(shape), at);
                    }
                    let (cu, cv, ca) = maps[which].local(u, v);
                    node = kids[which].get_or_init(|| {
                        let n = self
                            .refine_local(mesh, *t, which)
                            .map_or(Node::Failed, |(m, c, _)| make_node(m, c, scheme));
                        self.memo.add(&n);
                        n
                    });
                    u = cu;
                    v = cv;
                    a = mul2(ca, a);
                    depth += 1;
                }
            }
        }
    }

    /// The root of patch `(face, sub)`'s refinement tree.
    fn root_node(&self, face: u32, sub: u32) -> Node {
        let scheme = self.options.scheme;
        let (mesh, t) = self.extract(face);
        if self.options.scheme.splits_into_quads(mesh.face(t).len()) && mesh.face(t).len() != 4 {
            return self
                .refine_local(&mesh, t, sub as usize)
                .map_or(Node::Failed, |(m, c, _)| make_node(m, c, scheme));
        }
        make_node(mesh, t, scheme)
    }

    /// Whether `(u, v)` is exactly a corner of face `t` of `mesh` at an irregular vertex.
    fn irregular_corner(&self, mesh: &LocalMesh, t: usize, u: f64, v: f64) -> bool {
        let k = match (
            patch_scheme(self.options.scheme, mesh.face(t).len()) == Scheme::Loop,
            u,
            v,
        ) {
            (_, 0.0, 0.0) => 0,
            (_, 1.0, 0.0) => 1,
            (true, 0.0, 1.0) => 2,
            (false, 1.0, 1.0) => 2,
            (false, 0.0, 1.0) => 3,
            _ => return false,
        };
        let adj = mesh.adjacency();
        !corner_points(mesh, &adj, self.options.scheme, t, k, &mut |_, _| {})
    }

    /// Evaluates position, derivatives and normal at `p` for control points `positions`
    /// (`#V by 3`). Errors as [`Self::weights`], plus a wrong number of positions.
    pub fn evaluate(
        &self,
        positions: &[[f64; 3]],
        p: SurfaceParam,
    ) -> Result<SurfacePoint, EvalError> {
        if positions.len() != self.num_vertices {
            return Err(EvalError::PositionCount {
                expected: self.num_vertices,
                got: positions.len(),
            });
        }
        Ok(self.weights(p)?.apply(positions))
    }

    /// [`Self::evaluate`] for many parameters, in parallel (rayon); results in input order.
    /// Fails on the first bad parameter.
    pub fn evaluate_batch(
        &self,
        positions: &[[f64; 3]],
        params: &[SurfaceParam],
    ) -> Result<Vec<SurfacePoint>, EvalError> {
        params
            .par_iter()
            .map(|&p| self.evaluate(positions, p))
            .collect()
    }
}
