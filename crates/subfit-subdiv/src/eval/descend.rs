//! Evaluation below the memoised levels: repeated local refinement until the point lies in a
//! regular patch (Stam 1998), as a walk through interned shapes whose refinement steps are
//! cached sparse matrices (module `shape`), and the limit masks exactly at an irregular vertex
//! (once no finite sharpness is left around it, [`crate::crease`]). Where the walk cannot be
//! used (memory budget spent, limit at a vertex, a failed refinement), repeated local
//! refinement of the rows themselves, reusing one local subdivision matrix once the
//! neighbourhood is self-similar.

use super::basis::{best_child, best_map, chain_basis, child_local, mul2, PatchCoef};
use super::shape::{Shape, Step as ShapeStep};
use super::types::{EvalError, EvalKind, EvalWeights};
use super::Evaluator;
use crate::local::{
    child_nfaces, child_row, children, corner_points, patch_scheme, regular_patch, two_ring,
    Adjacency, ChildVertex, LocalMesh,
};
use crate::mask::Mask;
use crate::scheme::Scheme;
use std::sync::{Arc, OnceLock};

/// Refinement depth after which a point that is still not inside a regular patch is taken to be
/// at the nearest corner (it is then within `2^-MAX_DEPTH` of it in parameter space).
pub const MAX_DEPTH: u32 = 60;

/// Where a descent starts: face `t` of the neighbourhood, parameters `(u, v)` on it, Jacobian
/// `a` = ∂(parameters)/∂(original parameters), refinement `depth`, and the control face (for
/// errors).
pub(super) type Start = (usize, f64, f64, [[f64; 2]; 2], u32, u32);

impl Evaluator {
    /// Evaluation below the memoised levels from `mesh` (rows over control points): walks the
    /// interned shapes (`shape` caches the one of `mesh`, if given) and multiplies the cached
    /// step matrices into the regular patch at the end; falls back to [`Self::descend_rows`]
    /// where the walk cannot be used. Cost per level O(16 · nnz(step)) once the shapes and
    /// steps on the way are known, plus one O(16 · nv · K) product at the end.
    pub(super) fn descend(
        &self,
        mesh: &LocalMesh,
        shape: Option<&OnceLock<Arc<Shape>>>,
        (t, mut u, mut v, mut a, mut depth, face): Start,
    ) -> Result<EvalWeights, EvalError> {
        let scheme = self.options.scheme;
        let intern = || {
            let (s, bytes) = self.shapes.intern(mesh, t, scheme);
            self.memo.add_shape_bytes(bytes);
            s
        };
        // Shapes and steps are borrowed, not reference-counted, on the way down: they live
        // as long as `self` (and `owned`), and atomic counts would contend between threads.
        let owned: Arc<Shape>;
        let first: &Shape = match shape.and_then(OnceLock::get) {
            Some(s) => s,
            None if self.memo.shapes_full() => {
                return self.descend_rows(mesh.clone(), t, u, v, a, depth, face)
            }
            None => match shape {
                Some(cell) => cell.get_or_init(intern),
                None => {
                    owned = intern();
                    &owned
                }
            },
        };
        let mut cur = first;
        let mut chain: Vec<&ShapeStep> = Vec::new();
        let fallback = |chain: &[&ShapeStep], cur: &Shape, u, v, a, depth| {
            let m = Self::chain_mesh(mesh, chain);
            self.descend_rows(m, cur.t, u, v, a, depth, face)
        };
        loop {
            if let Some(c) = &cur.patch {
                let (_, vals) = chain_basis(c.len(), scheme, u, v, a);
                return Ok(Self::chain_eval(mesh, &chain, cur, c, &vals, depth));
            }
            let limit_ok = scheme == Scheme::Loop || depth >= 1;
            if limit_ok && (depth >= MAX_DEPTH || self.vertex_limit_at(cur, u, v)) {
                return fallback(&chain, cur, u, v, a, depth);
            }
            let which = best_map(&cur.maps, u, v);
            let step = match cur.step(which) {
                Some(s) => s.as_deref(),
                None if self.memo.shapes_full() => return fallback(&chain, cur, u, v, a, depth),
                None => self.shape_step(cur, which),
            };
            let Some(step) = step else {
                return fallback(&chain, cur, u, v, a, depth);
            };
            let (cu, cv, ca) = cur.maps[which].local(u, v);
            u = cu;
            v = cv;
            a = mul2(ca, a);
            depth += 1;
            cur = &step.child;
            chain.push(step);
        }
    }

    /// Whether [`Self::descend_rows`] would take the limit at a vertex for `(u, v)` on `shape`:
    /// `(u, v)` is exactly a corner whose vertex is irregular and has no finite sharpness left.
    fn vertex_limit_at(&self, shape: &Shape, u: f64, v: f64) -> bool {
        let (mesh, t) = (&shape.mesh, shape.t);
        let corners: &[[f64; 2]] = match patch_scheme(self.options.scheme, mesh.face(t).len()) {
            Scheme::Loop => &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            _ => &[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
        };
        let Some(k) = corners.iter().position(|c| c[0] == u && c[1] == v) else {
            return false;
        };
        let adj = mesh.adjacency();
        let x = mesh.face(t)[k];
        let settled = mesh
            .ring(&adj, x)
            .is_some_and(|r| !mesh.semi_sharp_at(x, &r));
        settled && !corner_points(mesh, &adj, self.options.scheme, t, k, &mut |_, _| {})
    }

    /// Evaluation by repeated local refinement from `mesh` (face `t`, parameters `(u, v)`,
    /// Jacobian `a` to the original parameters, at refinement `depth`), without memoisation.
    #[allow(clippy::too_many_arguments, reason = "the state of the descent")]
    pub(super) fn descend_rows(
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
            let corners: &[[f64; 2]] = match patch_scheme(scheme, mesh.face(t).len()) {
                Scheme::Loop => &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
                _ => &[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
            };
            let at = corners.iter().position(|c| c[0] == u && c[1] == v);
            let limit_ok = scheme == Scheme::Loop || depth >= 1;
            if let (Some(k), true) = (at, limit_ok) {
                // With finite sharpness left at the corner vertex its limit needs more levels.
                let x = mesh.face(t)[k];
                let settled = mesh
                    .ring(&adj, x)
                    .is_some_and(|r| !mesh.semi_sharp_at(x, &r));
                if settled && !corner_points(&mesh, &adj, scheme, t, k, &mut |_, _| {}) {
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
        adj: &Adjacency,
        x: u32,
        depth: u32,
        scratch: &mut Mask,
    ) -> Option<EvalWeights> {
        let ring = mesh.ring(adj, x)?;
        let hood = mesh.neighborhood(adj, x, &ring, self.options.boundary);
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
    pub(super) fn refine_local(
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
        let mut csharp: Vec<Vec<f32>> = Vec::new();
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
                csharp.push(c.sharpness);
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
        let (mut mask, mut scratch) = (Mask::default(), Mask::default());
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
                &mut scratch,
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
            fs: Vec::new(),
            vs: Vec::new(),
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
                    out.vs.push(match key {
                        ChildVertex::Vertex(x) => crate::crease::decrement(mesh.vs[x as usize]),
                        _ => 0.0,
                    });
                }
                out.fv.push(remap[li]);
                out.fe.push(cflags[f as usize][j]);
                out.fs.push(csharp[f as usize][j]);
            }
            out.fo.push(out.fv.len() as u32);
        }
        (new_t != usize::MAX).then_some((out, new_t, target_which))
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
        p.fo == m.fo
            && p.fv == m.fv
            && p.fe == m.fe
            && p.fs == m.fs
            && p.vs == m.vs
            && p.nfaces == m.nfaces
            && p.corner == m.corner
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
