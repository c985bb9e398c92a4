//! Exact evaluation of the limit surface at any `(face, u, v)`, with derivatives and the sparse
//! weight row over control points.
//!
//! Method: Stam 1998 (*Exact evaluation of Catmull-Clark subdivision surfaces at arbitrary
//! parameter values*; *Evaluation of Loop subdivision surfaces*), in its "repeated subdivision of
//! the local patch" form rather than the eigen-basis form: the two-ring neighbourhood of the face
//! is refined locally (module `local`, with the masks of [`crate::mask`]) and the child face
//! containing the point is kept, until that face is regular; then the regular polynomial patch
//! ([`crate::patch`]: quartic box spline for Loop, bicubic B-spline for Catmull-Clark) is
//! evaluated. Both steps are exact, so the result is exact to rounding, near extraordinary
//! vertices too (no Gregory or other approximation). Exactly at an irregular vertex the limit
//! masks ([`Scheme::limit_masks`]) give the position and two limit tangents.
//!
//! # Parametrisation
//! * Loop triangle `(c0, c1, c2)` (corner order of the face): barycentric, the point is
//!   `(1 − u − v) c0 + u c1 + v c2` on the domain triangle, `u, v ≥ 0`, `u + v ≤ 1`.
//! * Catmull-Clark quad `(c0, c1, c2, c3)`: `(u, v) ∈ [0,1]²`, `c0` at `(0,0)`, `c1` at `(1,0)`,
//!   `c2` at `(1,1)`, `c3` at `(0,1)`.
//! * Catmull-Clark `n`-gon (`n ≠ 4`): sub-patch `k` (`0 ≤ k < n`) is the quad of the first-level
//!   split at corner `k`, `(v_k, e_{k,k+1}, F, e_{k−1,k})` with `e_{i,j}` the edge point of edge
//!   `v_i v_j` and `F` the face point (the order of [`mod@crate::refine`]); `(u, v) ∈ [0,1]²` on it
//!   with the quad convention above (`v_k` at `(0,0)`, `e_{k,k+1}` at `(1,0)`, `F` at `(1,1)`,
//!   `e_{k−1,k}` at `(0,1)`). Each sub-patch covers a quarter-like sector of the `n`-gon.
//!
//! Closest points on the surface: [`crate::closest`].
//!
//! A [`SurfaceParam`] is `(face, sub, u, v)`; `sub` is 0 except for Catmull-Clark `n`-gons.
//! Dyadic parameters `(i / 2^l, j / 2^l)` are the level-`l` vertices of uniform refinement
//! (level `l − 1` of the sub-quads for `n`-gons).
//!
//! # Boundaries, creases, corners
//! Boundary edges and infinitely sharp creases (sharpness ≥ [`subfit_mesh::SHARPNESS_INFINITE`])
//! follow [`mod@crate::refine`]'s rules exactly (`EdgeOnly` and `EdgeAndCorner`); regular patches
//! along them use phantom points (module `local`), so they are exact as well. Semi-sharp tags
//! are treated as smooth, as in the rest of the crate.

use crate::error::SubdivError;
use crate::local::{
    child_nfaces, child_row, children, corner_points, regular_patch, two_ring, ChildVertex, Combo,
    LocalMesh, BOUNDARY, SHARP,
};
use crate::mask::Mask;
use crate::patch::{bicubic_bspline, loop_box_spline};
use crate::scheme::{Options, Scheme};
use crate::topology::Topology;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;
use subfit_mesh::{Polygons, Tags};

/// Refinement depth after which a point that is still not inside a regular patch is taken to be
/// at the nearest corner (it is then within `2^-MAX_DEPTH` of it in parameter space).
pub const MAX_DEPTH: u32 = 60;

/// A point of the parameter domain: `(face, sub, u, v)`, see the module docs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceParam {
    /// Control-mesh face.
    pub face: u32,
    /// Sub-patch: the corner of a Catmull-Clark `n`-gon (`n ≠ 4`), else 0.
    pub sub: u32,
    /// First parameter.
    pub u: f64,
    /// Second parameter.
    pub v: f64,
}

impl SurfaceParam {
    /// A parameter on face `face` (sub-patch 0).
    pub fn new(face: u32, u: f64, v: f64) -> Self {
        Self { face, sub: 0, u, v }
    }
}

/// Why an evaluation was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EvalError {
    /// The control mesh is not a valid subdivision control mesh.
    #[error(transparent)]
    Topology(#[from] SubdivError),
    /// The face index is out of range.
    #[error("face {face} out of range: the mesh has {num_faces} faces")]
    FaceOutOfRange {
        /// The face asked for.
        face: u32,
        /// Number of faces.
        num_faces: usize,
    },
    /// The sub-patch index is out of range for the face.
    #[error("sub-patch {sub} out of range for face {face} ({count} sub-patches)")]
    SubOutOfRange {
        /// The face.
        face: u32,
        /// The sub-patch asked for.
        sub: u32,
        /// Number of sub-patches of the face.
        count: usize,
    },
    /// `(u, v)` is not finite or lies outside the face's domain by more than 1e-9.
    #[error("parameter ({u}, {v}) outside the domain of face {face}")]
    OutOfDomain {
        /// The face.
        face: u32,
        /// First parameter.
        u: f64,
        /// Second parameter.
        v: f64,
    },
    /// The positions array does not have one row per control point.
    #[error("expected {expected} control points, got {got}")]
    PositionCount {
        /// Number of control points of the mesh.
        expected: usize,
        /// Rows given.
        got: usize,
    },
    /// Local refinement lost part of the neighbourhood it needed (a broken invariant, reported
    /// rather than panicking so one bad sample does not abort a batch).
    #[error("internal: incomplete neighbourhood evaluating face {face} at depth {depth}")]
    Incomplete {
        /// The face.
        face: u32,
        /// The refinement depth.
        depth: u32,
    },
}

/// What the derivative fields of an evaluation mean.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EvalKind {
    /// Inside a regular patch (possibly after local refinement): `du`, `dv` are the parametric
    /// first derivatives and the second derivatives are present.
    Patch,
    /// Exactly at an irregular vertex (extraordinary, crease end, corner, …): the position is the
    /// limit mask's; `du`, `dv` are the two limit tangents of [`Scheme::limit_masks`] (directions
    /// spanning the tangent plane, OpenSubdiv's scale, not parametric derivatives, which do not
    /// exist there); no second derivatives.
    Vertex,
}

/// The weights of one evaluation over control points: the position and its derivatives are
/// `Σ_i w[i] · P[indices[i]]`.
#[derive(Clone, Debug, PartialEq)]
pub struct EvalWeights {
    /// Control-point ids, ascending, unique.
    pub indices: Vec<u32>,
    /// Position weights (sum 1).
    pub position: Vec<f64>,
    /// ∂/∂u weights (sum 0); limit tangent 1 for [`EvalKind::Vertex`].
    pub du: Vec<f64>,
    /// ∂/∂v weights (sum 0); limit tangent 2 for [`EvalKind::Vertex`].
    pub dv: Vec<f64>,
    /// `[∂²/∂u², ∂²/∂u∂v, ∂²/∂v²]` weights, `None` for [`EvalKind::Vertex`].
    pub second: Option<[Vec<f64>; 3]>,
    /// What the derivative weights mean.
    pub kind: EvalKind,
    /// Number of local refinement levels used (0 for a regular control-mesh face).
    pub depth: u32,
}

/// The limit surface at one parameter: position, derivatives and unit normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// Position, in the units of the control points.
    pub position: [f64; 3],
    /// ∂S/∂u (see [`EvalKind`]).
    pub du: [f64; 3],
    /// ∂S/∂v (see [`EvalKind`]).
    pub dv: [f64; 3],
    /// `[S_uu, S_uv, S_vv]`, `None` at an irregular vertex.
    pub second: Option<[[f64; 3]; 3]>,
    /// Unit normal `normalize(du × dv)`, on the side the face winding makes the front; zero if
    /// the tangents are parallel (a degenerate control mesh).
    pub normal: [f64; 3],
    /// What the derivative fields mean.
    pub kind: EvalKind,
    /// Local refinement levels used.
    pub depth: u32,
}

impl EvalWeights {
    /// Applies the weights to control points (`#V by 3`): position, derivatives and normal.
    /// Cost O(#weights).
    ///
    /// # Panics
    /// If an index is out of range of `positions`.
    #[track_caller]
    pub fn apply(&self, positions: &[[f64; 3]]) -> SurfacePoint {
        let dot = |w: &[f64]| {
            let mut s = [0.0; 3];
            for (&i, &wi) in self.indices.iter().zip(w) {
                let p = positions[i as usize];
                s[0] += wi * p[0];
                s[1] += wi * p[1];
                s[2] += wi * p[2];
            }
            s
        };
        let (du, dv) = (dot(&self.du), dot(&self.dv));
        SurfacePoint {
            position: dot(&self.position),
            du,
            dv,
            second: self
                .second
                .as_ref()
                .map(|[a, b, c]| [dot(a), dot(b), dot(c)]),
            normal: unit(cross(du, dv)),
            kind: self.kind,
            depth: self.depth,
        }
    }
}

pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn unit(n: [f64; 3]) -> [f64; 3] {
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if l > 0.0 && l.is_finite() {
        [n[0] / l, n[1] / l, n[2] / l]
    } else {
        [0.0; 3]
    }
}

/// The regular patch basis (value and five derivatives) padded to 16 entries, and its size.
fn basis(scheme: Scheme, u: f64, v: f64) -> (usize, [[f64; 16]; 6]) {
    let mut out = [[0.0; 16]; 6];
    match scheme {
        Scheme::Loop => {
            let b = loop_box_spline(u, v);
            for (o, x) in out
                .iter_mut()
                .zip([b.point, b.du, b.dv, b.duu, b.duv, b.dvv])
            {
                o[..12].copy_from_slice(&x);
            }
            (12, out)
        }
        Scheme::CatmullClark => {
            let b = bicubic_bspline(u, v);
            (16, [b.point, b.du, b.dv, b.duu, b.duv, b.dvv])
        }
    }
}

/// A regular patch's control points as dense rows over a few control points.
#[derive(Clone, Debug)]
struct PatchCoef {
    cols: Vec<u32>,
    /// `npts × cols.len()`.
    coef: Vec<f64>,
}

impl PatchCoef {
    fn new(mesh: &LocalMesh, combos: &[Combo]) -> Self {
        let k = mesh.k();
        let mut dense = vec![0.0; combos.len() * k];
        for (i, c) in combos.iter().enumerate() {
            for &(v, w) in &c.terms[..c.n as usize] {
                if w != 0.0 {
                    for (o, r) in dense[i * k..(i + 1) * k].iter_mut().zip(mesh.row(v)) {
                        *o += w * r;
                    }
                }
            }
        }
        let keep: Vec<usize> = (0..k)
            .filter(|&j| (0..combos.len()).any(|i| dense[i * k + j] != 0.0))
            .collect();
        let mut order: Vec<usize> = keep.clone();
        order.sort_by_key(|&j| mesh.cols[j]);
        let cols: Vec<u32> = order.iter().map(|&j| mesh.cols[j]).collect();
        let mut coef = Vec::with_capacity(combos.len() * cols.len());
        for i in 0..combos.len() {
            coef.extend(order.iter().map(|&j| dense[i * k + j]));
        }
        Self { cols, coef }
    }

    /// Evaluates at child parameters `(u, v)` with `a` = ∂(child params)/∂(original params).
    fn eval(&self, scheme: Scheme, u: f64, v: f64, a: [[f64; 2]; 2], depth: u32) -> EvalWeights {
        let (np, [p, du, dv, duu, duv, dvv]) = basis(scheme, u, v);
        let n = self.cols.len();
        let mut out = [
            vec![0.0; n],
            vec![0.0; n],
            vec![0.0; n],
            vec![0.0; n],
            vec![0.0; n],
            vec![0.0; n],
        ];
        // Chain rule: ∂f/∂x_j = Σ_i a[i][j] ∂f/∂c_i; H_x = aᵀ H_c a.
        for i in 0..np {
            let (gu, gv) = (du[i], dv[i]);
            let hx = [[duu[i], duv[i]], [duv[i], dvv[i]]];
            let g = [a[0][0] * gu + a[1][0] * gv, a[0][1] * gu + a[1][1] * gv];
            let mut h = [[0.0; 2]; 2];
            for (j, hj) in h.iter_mut().enumerate() {
                for (l, hjl) in hj.iter_mut().enumerate() {
                    let mut s = 0.0;
                    for (r, hr) in hx.iter().enumerate() {
                        for (c, hrc) in hr.iter().enumerate() {
                            s += a[r][j] * hrc * a[c][l];
                        }
                    }
                    *hjl = s;
                }
            }
            let vals = [p[i], g[0], g[1], h[0][0], h[0][1], h[1][1]];
            let row = &self.coef[i * n..(i + 1) * n];
            for (o, &val) in out.iter_mut().zip(&vals) {
                if val != 0.0 {
                    for (x, &r) in o.iter_mut().zip(row) {
                        *x += val * r;
                    }
                }
            }
        }
        let [position, du, dv, duu, duv, dvv] = out;
        EvalWeights {
            indices: self.cols.clone(),
            position,
            du,
            dv,
            second: Some([duu, duv, dvv]),
            kind: EvalKind::Patch,
            depth,
        }
    }
}

/// Exact evaluator of the limit surface of one control mesh (topology only; positions are passed
/// to each call, so one evaluator serves a fitter whose control points move).
///
/// Construction validates the mesh, classifies every patch and caches the control points of the
/// patches that are regular at level 0 (the common case). Cost O(#F · s) with `s` the size of a
/// two-ring (parallel); memory about 16–20 weights per cached patch point.
///
/// Memory after construction: evaluations memoise the local refinements of irregular patches
/// (up to [`CACHE_DEPTH`] levels, tens of kB per patch evaluated near an irregular vertex),
/// within a budget ([`Self::set_cache_budget`], default [`DEFAULT_CACHE_BYTES`]); past it,
/// evaluation stays exact but is not memoised. [`Self::cache_bytes`] reports the memoised
/// amount and [`Self::clear_cache`] drops it.
#[derive(Clone, Debug)]
pub struct Evaluator {
    options: Options,
    faces: Polygons,
    num_vertices: usize,
    vf_off: Vec<u32>,
    vf: Vec<u32>,
    /// Per face corner: flags of the edge to the next corner.
    flags: Vec<u8>,
    corner: Vec<bool>,
    /// First patch of each face (`#F + 1` entries).
    patch_start: Vec<u32>,
    /// Memoised local-refinement tree of each patch (built on first use; regular level-0
    /// patches at construction).
    roots: Vec<OnceLock<Node>>,
    /// Bytes held by nodes memoised after construction, and the budget they may use.
    memo: MemoBudget,
}

/// Default budget of the memoised local refinements of an [`Evaluator`]: 256 MiB.
pub const DEFAULT_CACHE_BYTES: usize = 256 << 20;

/// Heap bytes held by memoised nodes (approximate: array payloads only), and the budget beyond
/// which no more nodes are memoised.
#[derive(Debug)]
struct MemoBudget {
    used: AtomicUsize,
    budget: usize,
}

impl Clone for MemoBudget {
    fn clone(&self) -> Self {
        Self {
            used: AtomicUsize::new(self.used.load(Ordering::Relaxed)),
            budget: self.budget,
        }
    }
}

impl MemoBudget {
    fn full(&self) -> bool {
        self.used.load(Ordering::Relaxed) >= self.budget
    }

    fn add(&self, node: &Node) {
        self.used.fetch_add(node.heap_bytes(), Ordering::Relaxed);
    }
}

/// Local refinement levels whose results are memoised per patch: evaluations reuse the refined
/// neighbourhoods and the regular sub-patches of the first `CACHE_DEPTH` levels (memory: up to a
/// few tens of kB per irregular patch that has been evaluated near its irregular corners).
pub const CACHE_DEPTH: u32 = 4;

/// A node of a patch's memoised local-refinement tree.
#[derive(Clone, Debug)]
enum Node {
    /// A regular (sub-)patch.
    Regular(PatchCoef),
    /// An irregular (sub-)patch: its refined neighbourhood and, lazily, its four children.
    Irregular {
        mesh: LocalMesh,
        t: usize,
        kids: Box<[OnceLock<Node>; 4]>,
    },
    /// Local refinement failed (a broken invariant, reported as [`EvalError::Incomplete`]).
    Failed,
}

impl Node {
    /// Approximate heap bytes of this node (not of its children).
    fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        match self {
            Node::Regular(pc) => pc.cols.len() * 4 + pc.coef.len() * 8,
            Node::Irregular { mesh, .. } => {
                mesh.cols.len() * 4
                    + mesh.rows.len() * 8
                    + (mesh.fo.len() + mesh.fv.len() + mesh.nfaces.len()) * 4
                    + mesh.fe.len()
                    + mesh.corner.len()
                    + size_of::<[OnceLock<Node>; 4]>()
            }
            Node::Failed => 0,
        }
    }
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
            let n = match (options.scheme, face.len()) {
                (Scheme::CatmullClark, n) if n != 4 => n as u32,
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
            corner,
            patch_start,
            roots: Vec::new(),
            memo: MemoBudget {
                used: AtomicUsize::new(0),
                budget: DEFAULT_CACHE_BYTES,
            },
        };
        let regular: Vec<Option<PatchCoef>> = (0..nf)
            .into_par_iter()
            .map(|f| {
                if ev.faces.face_len(subfit_mesh::FaceId(f as u32))
                    != options.scheme.regular_face_size()
                {
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
    /// (default [`DEFAULT_CACHE_BYTES`]). Once the memoised nodes hold this much, further
    /// evaluations still work and give the same results (to round-off), but refine from the
    /// deepest memoised node each time instead of memoising more; 0 turns memoisation off.
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
    /// payloads; the regular level-0 patches built by [`Self::new`] are not counted).
    pub fn cache_bytes(&self) -> usize {
        self.memo.used.load(Ordering::Relaxed)
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
        *self.memo.used.get_mut() = 0;
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

    /// Whether patches of this evaluator are triangles (Loop) rather than quads.
    pub fn triangular(&self) -> bool {
        self.options.scheme == Scheme::Loop
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
        if self.triangular() {
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
    /// first [`CACHE_DEPTH`] levels are memoised per patch, so only the first evaluation near a
    /// given corner pays for them; deeper levels reuse one local subdivision matrix once the
    /// neighbourhood is self-similar. Thread-safe (`&self`; memoisation uses `OnceLock`).
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
                Node::Irregular { mesh, t, kids } => {
                    if depth >= CACHE_DEPTH || self.irregular_corner(mesh, *t, u, v) {
                        return self.descend(mesh.clone(), *t, u, v, a, depth, p.face);
                    }
                    let ch = children(mesh, scheme, *t);
                    let which = best_child(&ch, u, v);
                    if kids[which].get().is_none() && self.memo.full() {
                        // Over the memory budget: refine from here without memoising.
                        return self.descend(mesh.clone(), *t, u, v, a, depth, p.face);
                    }
                    let (cu, cv, ca) = child_local(&ch[which].params, u, v);
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
        if scheme == Scheme::CatmullClark && mesh.face(t).len() != 4 {
            return self
                .refine_local(&mesh, t, sub as usize)
                .map_or(Node::Failed, |(m, c, _)| make_node(m, c, scheme));
        }
        make_node(mesh, t, scheme)
    }

    /// Whether `(u, v)` is exactly a corner of face `t` of `mesh` at an irregular vertex.
    fn irregular_corner(&self, mesh: &LocalMesh, t: usize, u: f64, v: f64) -> bool {
        let k = match (self.triangular(), u, v) {
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

    /// Evaluation by repeated local refinement from `mesh` (face `t`, parameters `(u, v)`,
    /// Jacobian `a` to the original parameters, at refinement `depth`), without memoisation.
    #[allow(clippy::too_many_arguments, reason = "the state of the descent")]
    fn descend(
        &self,
        mut mesh: LocalMesh,
        mut t: usize,
        mut u: f64,
        mut v: f64,
        mut a: [[f64; 2]; 2],
        mut depth: u32,
        face: u32,
    ) -> Result<EvalWeights, EvalError> {
        let scheme = self.options.scheme;
        let err = |depth| EvalError::Incomplete { face, depth };
        let mut mask = Mask::default();
        let mut step: Option<Step> = None;
        loop {
            let adj = mesh.adjacency();
            if let Some(c) = regular_patch(&mesh, &adj, scheme, t) {
                return Ok(PatchCoef::new(&mesh, &c).eval(scheme, u, v, a, depth));
            }
            let corners: &[[f64; 2]] = match scheme {
                Scheme::Loop => &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
                Scheme::CatmullClark => &[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
            };
            let at = corners.iter().position(|c| c[0] == u && c[1] == v);
            let limit_ok = scheme == Scheme::Loop || depth >= 1;
            if let (Some(k), true) = (at, limit_ok) {
                if !corner_points(&mesh, &adj, scheme, t, k, &mut |_, _| {}) {
                    return self
                        .vertex_limit(&mesh, &adj, mesh.face(t)[k], depth, &mut mask)
                        .ok_or(err(depth));
                }
            }
            if depth >= MAX_DEPTH && limit_ok {
                let k = (0..corners.len())
                    .min_by(|&i, &j| {
                        let d = |c: [f64; 2]| (c[0] - u).powi(2) + (c[1] - v).powi(2);
                        d(corners[i]).total_cmp(&d(corners[j]))
                    })
                    .unwrap_or(0);
                return self
                    .vertex_limit(&mesh, &adj, mesh.face(t)[k], depth, &mut mask)
                    .ok_or(err(depth));
            }
            // Near an irregular vertex the neighbourhood becomes self-similar: the same topology
            // and child at every level, so the step is one fixed local subdivision matrix
            // (Stam 1998). Refine the topology once with identity rows and reuse the matrix.
            let which = best_child(&children(&mesh, scheme, t), u, v);
            let reuse = step
                .as_ref()
                .is_some_and(|st: &Step| st.which == which && st.t == t && st.same_topology(&mesh));
            if !reuse {
                let mut ident = mesh.clone();
                let nv = mesh.nv();
                ident.cols = (0..nv as u32).collect();
                ident.rows = vec![0.0; nv * nv];
                for i in 0..nv {
                    ident.rows[i * nv + i] = 1.0;
                }
                let (child, c, _) = self.refine_local(&ident, t, which).ok_or(err(depth))?;
                step = Some(Step {
                    which,
                    t,
                    parent: mesh.clone(),
                    child,
                    c,
                });
            }
            let st = step.as_ref().expect("set above");
            let m = st.apply(&mesh);
            let c = st.c;
            let (cu, cv, ca) = self.child_param(&mesh, t, which, u, v);
            mesh = m;
            t = c;
            u = cu;
            v = cv;
            a = mul2(ca, a);
            depth += 1;
        }
    }

    /// Limit position and tangents at local vertex `x` (exactly at an irregular vertex).
    fn vertex_limit(
        &self,
        mesh: &LocalMesh,
        adj: &crate::local::Adjacency,
        x: u32,
        depth: u32,
        scratch: &mut Mask,
    ) -> Option<EvalWeights> {
        let ring = mesh.ring(adj, x)?;
        let hood = mesh.neighborhood(x, &ring, self.options.boundary);
        let (mut t1, mut t2) = (Mask::default(), Mask::default());
        self.options
            .scheme
            .limit_masks(&hood, scratch, &mut t1, &mut t2);
        let k = mesh.k();
        let mut rows = [vec![0.0; k], vec![0.0; k], vec![0.0; k]];
        for (m, out) in [&*scratch, &t1, &t2].into_iter().zip(rows.iter_mut()) {
            mesh.apply_mask(adj, x, &ring, m, out);
        }
        let keep: Vec<usize> = (0..k)
            .filter(|&j| rows.iter().any(|r| r[j] != 0.0))
            .collect();
        let mut order = keep;
        order.sort_by_key(|&j| mesh.cols[j]);
        let pick = |r: &Vec<f64>| order.iter().map(|&j| r[j]).collect::<Vec<f64>>();
        Some(EvalWeights {
            indices: order.iter().map(|&j| mesh.cols[j]).collect(),
            position: pick(&rows[0]),
            du: pick(&rows[1]),
            dv: pick(&rows[2]),
            second: None,
            kind: EvalKind::Vertex,
            depth,
        })
    }

    /// The child parameters of `(u, v)` in child `which` of parent face `t`, and the Jacobian
    /// ∂(child)/∂(parent).
    fn child_param(
        &self,
        mesh: &LocalMesh,
        t: usize,
        which: usize,
        u: f64,
        v: f64,
    ) -> (f64, f64, [[f64; 2]; 2]) {
        let ch = &children(mesh, self.options.scheme, t)[which];
        child_local(&ch.params, u, v)
    }

    /// One level of local refinement around face `t`: the two-ring of the chosen child of `t`
    /// in the refined mesh, with composed rows. `None` if a needed vertex is not computable.
    fn refine_local(
        &self,
        mesh: &LocalMesh,
        t: usize,
        which: usize,
    ) -> Option<(LocalMesh, usize, usize)> {
        let scheme = self.options.scheme;
        let adj = mesh.adjacency();
        // Child topology of every parent face.
        let mut cfaces: Vec<Vec<ChildVertex>> = Vec::new();
        let mut cflags: Vec<Vec<u8>> = Vec::new();
        let mut target = usize::MAX;
        let mut target_which = 0;
        for f in 0..mesh.nf() {
            let ch = children(mesh, scheme, f);
            for (i, c) in ch.into_iter().enumerate() {
                if f == t && i == which {
                    target = cfaces.len();
                    target_which = i;
                }
                cfaces.push(c.verts);
                cflags.push(c.flags);
            }
        }
        // Number the child vertices.
        let mut keys: Vec<ChildVertex> = cfaces.iter().flatten().copied().collect();
        keys.sort_unstable();
        keys.dedup();
        let id = |c: &ChildVertex| keys.binary_search(c).expect("child vertex") as u32;
        let ids: Vec<Vec<u32>> = cfaces.iter().map(|f| f.iter().map(id).collect()).collect();
        let mut vfo = vec![0u32; keys.len() + 1];
        for f in &ids {
            for &v in f {
                vfo[v as usize + 1] += 1;
            }
        }
        for i in 0..keys.len() {
            vfo[i + 1] += vfo[i];
        }
        let mut fill = vfo.clone();
        let mut vfs = vec![0u32; vfo[keys.len()] as usize];
        for (f, face) in ids.iter().enumerate() {
            for &v in face {
                vfs[fill[v as usize] as usize] = f as u32;
                fill[v as usize] += 1;
            }
        }
        let faces_of =
            |v: u32| vfs[vfo[v as usize] as usize..vfo[v as usize + 1] as usize].to_vec();
        let face_verts = |f: u32| ids[f as usize].clone();
        let f2 = two_ring(&faces_of, &face_verts, target as u32);
        // Rows of the needed child vertices.
        let mut used: Vec<u32> = f2
            .iter()
            .flat_map(|&f| ids[f as usize].iter().copied())
            .collect();
        used.sort_unstable();
        used.dedup();
        let k = mesh.k();
        let mut mask = Mask::default();
        let mut rows = vec![0.0; used.len() * k];
        let mut ok = vec![true; used.len()];
        for (i, &cv) in used.iter().enumerate() {
            ok[i] = child_row(
                mesh,
                &adj,
                scheme,
                self.options.boundary,
                keys[cv as usize],
                &mut mask,
                &mut rows[i * k..(i + 1) * k],
            );
        }
        let local = |cv: u32| used.binary_search(&cv).expect("used vertex");
        let mut out = LocalMesh {
            cols: mesh.cols.clone(),
            rows: Vec::new(),
            fo: vec![0],
            fv: Vec::new(),
            fe: Vec::new(),
            nfaces: Vec::new(),
            corner: Vec::new(),
        };
        let mut new_t = usize::MAX;
        let mut remap = vec![u32::MAX; used.len()];
        let mut nv = 0u32;
        for &f in &f2 {
            let face = &ids[f as usize];
            if !face.iter().all(|&cv| ok[local(cv)]) {
                if f as usize == target {
                    return None;
                }
                continue;
            }
            if f as usize == target {
                new_t = out.nf();
            }
            for (j, &cv) in face.iter().enumerate() {
                let li = local(cv);
                if remap[li] == u32::MAX {
                    remap[li] = nv;
                    nv += 1;
                    out.rows.extend_from_slice(&rows[li * k..(li + 1) * k]);
                    let key = keys[cv as usize];
                    out.nfaces.push(child_nfaces(mesh, &adj, scheme, key));
                    out.corner
                        .push(matches!(key, ChildVertex::Vertex(x) if mesh.corner[x as usize]));
                }
                out.fv.push(remap[li]);
                out.fe.push(cflags[f as usize][j]);
            }
            out.fo.push(out.fv.len() as u32);
        }
        (new_t != usize::MAX).then_some((out, new_t, target_which))
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

    /// `n` random parameters from a seeded generator (SplitMix64): a patch chosen uniformly,
    /// then a point uniform over its parameter domain (triangle or square). Deterministic for a
    /// given seed. Not area-uniform on the surface. Cost O(n).
    pub fn random_params(&self, n: usize, seed: u64) -> Vec<SurfaceParam> {
        let mut rng = SplitMix64(seed);
        let np = self.num_patches();
        if np == 0 {
            return Vec::new();
        }
        (0..n)
            .map(|_| {
                let p = (rng.next_f64() * np as f64) as usize;
                let (face, sub) = self.patch(p.min(np - 1));
                let (mut u, mut v) = (rng.next_f64(), rng.next_f64());
                if self.triangular() && u + v > 1.0 {
                    (u, v) = (1.0 - u, 1.0 - v);
                }
                SurfaceParam { face, sub, u, v }
            })
            .collect()
    }
}

/// One local refinement step as a matrix over the parent's local vertices, for a parent
/// topology (`parent`, rows ignored), face `t` and child `which`.
struct Step {
    which: usize,
    t: usize,
    parent: LocalMesh,
    /// The child neighbourhood with rows over the parent's local vertices (`nv_child × nv`).
    child: LocalMesh,
    c: usize,
}

impl Step {
    fn same_topology(&self, m: &LocalMesh) -> bool {
        let p = &self.parent;
        p.fo == m.fo && p.fv == m.fv && p.fe == m.fe && p.nfaces == m.nfaces && p.corner == m.corner
    }

    /// The child of `m` (same topology as `parent`): rows = matrix · rows of `m`.
    fn apply(&self, m: &LocalMesh) -> LocalMesh {
        let (nv, k) = (m.nv(), m.k());
        let nc = self.child.nv();
        let mut rows = vec![0.0; nc * k];
        for i in 0..nc {
            let w = &self.child.rows[i * nv..(i + 1) * nv];
            let out = &mut rows[i * k..(i + 1) * k];
            for (j, &wj) in w.iter().enumerate() {
                if wj != 0.0 {
                    for (o, r) in out.iter_mut().zip(m.row(j as u32)) {
                        *o += wj * r;
                    }
                }
            }
        }
        LocalMesh {
            cols: m.cols.clone(),
            rows,
            ..self.child.clone()
        }
    }
}

/// A tree node for face `t` of `mesh`: regular patch or irregular (to be refined further).
fn make_node(mesh: LocalMesh, t: usize, scheme: Scheme) -> Node {
    let adj = mesh.adjacency();
    match regular_patch(&mesh, &adj, scheme, t) {
        Some(c) => Node::Regular(PatchCoef::new(&mesh, &c)),
        None => Node::Irregular {
            mesh,
            t,
            kids: Box::new(std::array::from_fn(|_| OnceLock::new())),
        },
    }
}

fn mul2(a: [[f64; 2]; 2], b: [[f64; 2]; 2]) -> [[f64; 2]; 2] {
    [
        [
            a[0][0] * b[0][0] + a[0][1] * b[1][0],
            a[0][0] * b[0][1] + a[0][1] * b[1][1],
        ],
        [
            a[1][0] * b[0][0] + a[1][1] * b[1][0],
            a[1][0] * b[0][1] + a[1][1] * b[1][1],
        ],
    ]
}

/// Local parameters of parent point `(u, v)` in a child with corner parameters `params`
/// (triangle: affine on corners 0, 1, 2; quad: on corners 0, 1, 3), and ∂(child)/∂(parent).
fn child_local(params: &[[f64; 2]], u: f64, v: f64) -> (f64, f64, [[f64; 2]; 2]) {
    let p0 = params[0];
    let e1 = [params[1][0] - p0[0], params[1][1] - p0[1]];
    let q = if params.len() == 3 {
        params[2]
    } else {
        params[3]
    };
    let e2 = [q[0] - p0[0], q[1] - p0[1]];
    // parent = p0 + s e1 + t e2 ⇒ (s, t) = M⁻¹ (parent − p0), M = [e1 e2].
    let det = e1[0] * e2[1] - e2[0] * e1[1];
    let inv = [[e2[1] / det, -e2[0] / det], [-e1[1] / det, e1[0] / det]];
    let (du, dv) = (u - p0[0], v - p0[1]);
    let s = inv[0][0] * du + inv[0][1] * dv;
    let t = inv[1][0] * du + inv[1][1] * dv;
    (s, t, inv)
}

/// The child whose domain contains `(u, v)` best (largest minimum barycentric / box margin).
fn best_child(ch: &[crate::local::ChildFace], u: f64, v: f64) -> usize {
    let mut best = (f64::NEG_INFINITY, 0);
    for (i, c) in ch.iter().enumerate() {
        let (s, t, _) = child_local(&c.params, u, v);
        let margin = if c.params.len() == 3 {
            s.min(t).min(1.0 - s - t)
        } else {
            s.min(t).min(1.0 - s).min(1.0 - t)
        };
        if margin > best.0 {
            best = (margin, i);
        }
    }
    best.1
}

/// SplitMix64 (Steele, Lea & Flood 2014): a tiny seeded generator for reproducible samples.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// `n` random parameters of `evaluator` and the exact limit points and unit normals there, for
/// `subfit eval CONTROL --samples N` (see [`Evaluator::random_params`]). Parallel.
///
/// Errors: as [`Evaluator::evaluate`].
pub fn random_samples(
    evaluator: &Evaluator,
    positions: &[[f64; 3]],
    n: usize,
    seed: u64,
) -> Result<(Vec<SurfaceParam>, Vec<SurfacePoint>), EvalError> {
    let params = evaluator.random_params(n, seed);
    let pts = evaluator.evaluate_batch(positions, &params)?;
    Ok((params, pts))
}
