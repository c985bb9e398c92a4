//! Local refinement of a face's two-ring neighbourhood, for exact evaluation (Stam 1998: "repeated
//! subdivision of the local patch" until the evaluation point lies in a regular patch).
//!
//! A [`LocalMesh`] is a small patch of some refinement level of the control mesh: faces with local
//! vertex ids, per face-edge sharp/boundary flags, per vertex the number of faces it has in the
//! *whole* mesh (so a vertex whose star was cut off by the extraction is known to be incomplete),
//! and per vertex a dense row of weights over the `K` control points the neighbourhood started
//! from. Refinement applies the scheme's masks ([`crate::mask`], the same rules as
//! [`crate::refine`]) only where their full support is present, keeps the two-ring of the child
//! face that contains the evaluation point, and composes the rows, so the final weights refer to
//! the original control points.
//!
//! Semi-sharp creases and corners ([`crate::crease`]): face edges and vertices carry their
//! finite sharpness, child vertices blend the rules as [`crate::refine`] does, and the sharpness
//! decays by one per level; a corner with finite sharpness at it or on an incident edge is never
//! regular (and has no closed-form limit), so evaluation refines until it has decayed.
//!
//! Regular patches are gathered by walking each corner's ring; across boundary and infinitely
//! sharp crease edges the missing lattice points are phantoms: `2 b − i` (Catmull-Clark, linear
//! extrapolation across the edge) and `a + b − c` (Loop, the parallelogram reflection of the
//! triangle across the sharp edge). Both make the regular polynomial patch reproduce the crease
//! rules exactly (boundary curve = cubic B-spline of the crease polygon, crease vertex rule
//! 1/8, 3/4, 1/8, crease edge = midpoint), so boundary and crease patches are exact too.

use crate::crease;
use crate::mask::{FaceWeights, Mask};
use crate::patch::{BSPLINE_PATCH_GRID, LOOP_PATCH_LATTICE};
use crate::scheme::{BoundaryRule, EdgeNeighborhood, FaceKinds, Neighborhood, Scheme, VertexRule};

/// Face-edge flag: the edge is on the boundary of the whole mesh.
pub(crate) const BOUNDARY: u8 = 1;
/// Face-edge flag: the edge is infinitely sharp (boundary edges are too).
pub(crate) const SHARP: u8 = 2;

/// A small piece of a refined mesh with rows of weights over `cols` control points.
#[derive(Clone, Debug, Default)]
pub(crate) struct LocalMesh {
    /// Control-point ids of the columns (`K`).
    pub cols: Vec<u32>,
    /// `nv × K` row-major weights.
    pub rows: Vec<f64>,
    /// Face offsets (`#F + 1`).
    pub fo: Vec<u32>,
    /// Face vertices (local ids), concatenated.
    pub fv: Vec<u32>,
    /// Flags of face edge `corner → next corner`, parallel to `fv`.
    pub fe: Vec<u8>,
    /// Finite (semi-sharp) sharpness of face edge `corner → next corner`, parallel to `fv`
    /// (0 when smooth or infinitely sharp; see [`crate::crease`]).
    pub fs: Vec<f32>,
    /// Finite corner sharpness of each vertex (0 when none or infinite).
    pub vs: Vec<f32>,
    /// Faces around each vertex in the whole mesh ([`UNKNOWN`] if not known).
    pub nfaces: Vec<u32>,
    /// Corner-tagged vertices.
    pub corner: Vec<bool>,
}

/// Vertex → corner adjacency of a [`LocalMesh`].
pub(crate) struct Adjacency {
    vc_off: Vec<u32>,
    vc: Vec<u32>,
    cface: Vec<u32>,
}

/// The counter-clockwise ring of a complete vertex (OpenSubdiv `Vtr` order, see
/// [`Neighborhood`]): edge `i` leads to `verts[i]`, face `i` (corner `corners[i]`) lies between
/// edges `i` and `i + 1`; at a boundary edge 0 is the leading boundary edge.
pub(crate) struct Ring {
    pub verts: Vec<u32>,
    pub eflags: Vec<u8>,
    /// Sharpness of each ring edge as [`crate::crease`] reads it: [`crease::INFINITE`] for
    /// sharp (and boundary) edges, else the finite sharpness or 0.
    pub sharpness: Vec<f32>,
    pub corners: Vec<u32>,
    pub boundary: bool,
}

/// A linear combination of at most three local vertices (a real or phantom lattice point).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Combo {
    pub n: u8,
    pub terms: [(u32, f64); 3],
}

impl Combo {
    fn one(v: u32) -> Self {
        Self {
            n: 1,
            terms: [(v, 1.0), (0, 0.0), (0, 0.0)],
        }
    }
    fn two(a: (u32, f64), b: (u32, f64)) -> Self {
        Self {
            n: 2,
            terms: [a, b, (0, 0.0)],
        }
    }
    fn three(a: (u32, f64), b: (u32, f64), c: (u32, f64)) -> Self {
        Self {
            n: 3,
            terms: [a, b, c],
        }
    }
}

impl LocalMesh {
    pub fn k(&self) -> usize {
        self.cols.len()
    }
    pub fn nv(&self) -> usize {
        self.nfaces.len()
    }
    pub fn nf(&self) -> usize {
        self.fo.len() - 1
    }
    pub fn face(&self, f: usize) -> &[u32] {
        &self.fv[self.fo[f] as usize..self.fo[f + 1] as usize]
    }
    pub fn row(&self, v: u32) -> &[f64] {
        let k = self.k();
        &self.rows[v as usize * k..(v as usize + 1) * k]
    }

    fn next(&self, adj: &Adjacency, c: u32) -> u32 {
        let f = adj.cface[c as usize] as usize;
        if c + 1 == self.fo[f + 1] {
            self.fo[f]
        } else {
            c + 1
        }
    }
    fn prev(&self, adj: &Adjacency, c: u32) -> u32 {
        let f = adj.cface[c as usize] as usize;
        if c == self.fo[f] {
            self.fo[f + 1] - 1
        } else {
            c - 1
        }
    }

    pub fn adjacency(&self) -> Adjacency {
        let nv = self.nv();
        let mut vc_off = vec![0u32; nv + 1];
        for &v in &self.fv {
            vc_off[v as usize + 1] += 1;
        }
        for i in 0..nv {
            vc_off[i + 1] += vc_off[i];
        }
        let mut fill = vc_off.clone();
        let mut vc = vec![0u32; self.fv.len()];
        let mut cface = vec![0u32; self.fv.len()];
        for f in 0..self.nf() {
            for c in self.fo[f]..self.fo[f + 1] {
                let v = self.fv[c as usize] as usize;
                vc[fill[v] as usize] = c;
                fill[v] += 1;
                cface[c as usize] = f as u32;
            }
        }
        Adjacency { vc_off, vc, cface }
    }

    fn vcorners<'a>(&self, adj: &'a Adjacency, v: u32) -> &'a [u32] {
        &adj.vc[adj.vc_off[v as usize] as usize..adj.vc_off[v as usize + 1] as usize]
    }

    /// Whether all faces of `v` in the whole mesh are present.
    pub fn complete(&self, adj: &Adjacency, v: u32) -> bool {
        self.vcorners(adj, v).len() as u32 == self.nfaces[v as usize]
    }

    /// The ordered ring of a complete vertex; `None` if incomplete or not a single fan.
    pub fn ring(&self, adj: &Adjacency, v: u32) -> Option<Ring> {
        if !self.complete(adj, v) {
            return None;
        }
        let cs = self.vcorners(adj, v);
        if cs.is_empty() {
            return None;
        }
        let vert = |c: u32| self.fv[c as usize];
        // CW neighbour of corner c: the corner of v whose previous vertex is c's next vertex.
        let cw = |c: u32| {
            let nx = vert(self.next(adj, c));
            cs.iter().copied().find(|&d| vert(self.prev(adj, d)) == nx)
        };
        let ccw = |c: u32| {
            let pv = vert(self.prev(adj, c));
            cs.iter().copied().find(|&d| vert(self.next(adj, d)) == pv)
        };
        let mut start = cs[0];
        let mut boundary = false;
        for _ in 0..cs.len() {
            match cw(start) {
                Some(d) if d != cs[0] => start = d,
                Some(_) => break,
                None => {
                    boundary = true;
                    break;
                }
            }
        }
        let mut ring = Ring {
            verts: Vec::with_capacity(cs.len() + 1),
            eflags: Vec::with_capacity(cs.len() + 1),
            sharpness: Vec::with_capacity(cs.len() + 1),
            corners: Vec::with_capacity(cs.len()),
            boundary,
        };
        let mut c = start;
        loop {
            ring.verts.push(vert(self.next(adj, c)));
            ring.eflags.push(self.fe[c as usize]);
            ring.sharpness.push(self.edge_sharpness(c));
            ring.corners.push(c);
            match ccw(c) {
                Some(d) if d == start => break,
                Some(d) if ring.corners.len() < cs.len() => c = d,
                Some(_) => return None,
                None => {
                    let p = self.prev(adj, c);
                    ring.verts.push(vert(p));
                    ring.eflags.push(self.fe[p as usize]);
                    ring.sharpness.push(self.edge_sharpness(p));
                    break;
                }
            }
        }
        (ring.corners.len() == cs.len()).then_some(ring)
    }

    /// The sharpness of face edge `c` as [`crate::crease`] reads it.
    fn edge_sharpness(&self, c: u32) -> f32 {
        if self.fe[c as usize] & SHARP != 0 {
            crease::INFINITE
        } else {
            self.fs[c as usize]
        }
    }

    /// Whether vertex `v` (with ring `ring`) or one of its edges has a finite sharpness: its
    /// rule may change at the next level, and no closed-form limit applies yet.
    pub fn semi_sharp_at(&self, v: u32, ring: &Ring) -> bool {
        self.vs[v as usize] > 0.0 || ring.sharpness.iter().any(|&s| crease::is_semi_sharp(s))
    }

    /// The scheme's view of a complete vertex (rule as in [`crate::refine`], from the boundary,
    /// infinitely sharp edges and corner tags; finite sharpness is read by [`child_row`]).
    pub fn neighborhood(
        &self,
        adj: &Adjacency,
        v: u32,
        ring: &Ring,
        boundary_rule: BoundaryRule,
    ) -> Neighborhood {
        let mut ends = [0usize; 2];
        let mut nsharp = 0;
        for (i, &f) in ring.eflags.iter().enumerate() {
            if f & SHARP != 0 {
                if nsharp < 2 {
                    ends[nsharp] = i;
                }
                nsharp += 1;
            }
        }
        let (ne, nf) = (ring.verts.len(), ring.corners.len());
        let rule = VertexRule::classify(ne, nf, nsharp, self.corner[v as usize], boundary_rule);
        Neighborhood {
            num_edges: ne,
            num_faces: nf,
            rule,
            crease_ends: ends,
            faces: FaceKinds::from_triangles(
                ring.corners
                    .iter()
                    .map(|&c| self.face(adj.cface[c as usize] as usize).len() == 3),
            ),
        }
    }

    /// Accumulates `w · row(v)` into `out`.
    fn axpy(&self, out: &mut [f64], v: u32, w: f64) {
        for (o, r) in out.iter_mut().zip(self.row(v)) {
            *o += w * r;
        }
    }

    /// Adds `w ·` (centroid of the face of corner `c`) into `out`.
    fn axpy_face(&self, adj: &Adjacency, out: &mut [f64], c: u32, w: f64) {
        let f = adj.cface[c as usize] as usize;
        let face = self.face(f);
        let wf = w / face.len() as f64;
        for &u in face {
            self.axpy(out, u, wf);
        }
    }

    /// Applies a vertex-centred mask (vertex, ring edges, ring faces) into `out`.
    pub fn apply_mask(&self, adj: &Adjacency, v: u32, ring: &Ring, m: &Mask, out: &mut [f64]) {
        self.axpy(out, v, m.vertex);
        for (&u, &w) in ring.verts.iter().zip(&m.edges) {
            self.axpy(out, u, w);
        }
        for (&c, &w) in ring.corners.iter().zip(&m.faces) {
            match m.face_weights {
                FaceWeights::Centers => self.axpy_face(adj, out, c, w),
                FaceWeights::Opposite => {
                    let d = self.next(adj, self.next(adj, c));
                    self.axpy(out, self.fv[d as usize], w);
                }
            }
        }
    }
}

/// The parameters of a child face's corners in its parent's parameter domain, and the child
/// vertex each corner is, for the children of one parent face in [`crate::refine`]'s order.
pub(crate) struct ChildFace {
    /// Child vertex kinds of the corners.
    pub verts: Vec<ChildVertex>,
    /// Face-edge flags.
    pub flags: Vec<u8>,
    /// Finite face-edge sharpness (the parent edge's, decremented, on the two halves of a parent
    /// edge; 0 inside the parent face).
    pub sharpness: Vec<f32>,
    /// Parent-domain parameters of the corners (only for triangles and quads).
    pub params: Vec<[f64; 2]>,
}

/// What a child vertex is the point of.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub(crate) enum ChildVertex {
    /// Vertex point of a parent vertex.
    Vertex(u32),
    /// Edge point of a parent edge given by its sorted end vertices.
    Edge(u32, u32),
    /// Face point of a parent face.
    Face(u32),
}

fn edge_key(a: u32, b: u32) -> ChildVertex {
    if a < b {
        ChildVertex::Edge(a, b)
    } else {
        ChildVertex::Edge(b, a)
    }
}

const TRI_PARAMS: [[f64; 2]; 3] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
const QUAD_PARAMS: [[f64; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];

/// The scheme whose patch and split a face of `len` corners has: Loop's for a triangle under
/// Loop or quad/triangle, Catmull-Clark's otherwise (the per-face split table of the three
/// schemes).
pub(crate) fn patch_scheme(scheme: Scheme, len: usize) -> Scheme {
    if scheme.splits_into_quads(len) {
        Scheme::CatmullClark
    } else {
        Scheme::Loop
    }
}

fn mid(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
}

/// The children of parent face `f` of `mesh` (a triangle under Loop or quad/triangle: 4
/// triangles; otherwise one quad per corner), in [`crate::refine`]'s order and corner order.
pub(crate) fn children(mesh: &LocalMesh, scheme: Scheme, f: usize) -> Vec<ChildFace> {
    let face = mesh.face(f);
    let base = mesh.fo[f] as usize;
    let fl = &mesh.fe[base..base + face.len()];
    let n = face.len();
    let sh: Vec<f32> = mesh.fs[base..base + n]
        .iter()
        .map(|&s| crease::decrement(s))
        .collect();
    let e = |i: usize| edge_key(face[i % n], face[(i + 1) % n]);
    let vx = |i: usize| ChildVertex::Vertex(face[i % n]);
    match patch_scheme(scheme, n) {
        Scheme::Loop => {
            let p = TRI_PARAMS;
            let (ab, bc, ca) = (mid(p[0], p[1]), mid(p[1], p[2]), mid(p[2], p[0]));
            vec![
                ChildFace {
                    verts: vec![vx(0), e(0), e(2)],
                    flags: vec![fl[0], 0, fl[2]],
                    sharpness: vec![sh[0], 0.0, sh[2]],
                    params: vec![p[0], ab, ca],
                },
                ChildFace {
                    verts: vec![vx(1), e(1), e(0)],
                    flags: vec![fl[1], 0, fl[0]],
                    sharpness: vec![sh[1], 0.0, sh[0]],
                    params: vec![p[1], bc, ab],
                },
                ChildFace {
                    verts: vec![vx(2), e(2), e(1)],
                    flags: vec![fl[2], 0, fl[1]],
                    sharpness: vec![sh[2], 0.0, sh[1]],
                    params: vec![p[2], ca, bc],
                },
                ChildFace {
                    verts: vec![e(0), e(1), e(2)],
                    flags: vec![0, 0, 0],
                    sharpness: vec![0.0; 3],
                    params: vec![ab, bc, ca],
                },
            ]
        }
        _ => (0..n)
            .map(|i| {
                let params = if n == 4 {
                    let q = QUAD_PARAMS;
                    vec![
                        q[i],
                        mid(q[i], q[(i + 1) % 4]),
                        [0.5, 0.5],
                        mid(q[(i + 3) % 4], q[i]),
                    ]
                } else {
                    Vec::new()
                };
                ChildFace {
                    verts: vec![vx(i), e(i), ChildVertex::Face(f as u32), e(i + n - 1)],
                    flags: vec![fl[i], 0, 0, fl[(i + n - 1) % n]],
                    sharpness: vec![sh[i], 0.0, 0.0, sh[(i + n - 1) % n]],
                    params,
                }
            })
            .collect(),
    }
}

/// Computes the row of child vertex `cv` into `out` (zeroed by the caller); `false` if its
/// support is not complete in `mesh`.
#[allow(
    clippy::too_many_arguments,
    reason = "internal helper with scratch buffers"
)]
pub(crate) fn child_row(
    mesh: &LocalMesh,
    adj: &Adjacency,
    scheme: Scheme,
    boundary: BoundaryRule,
    cv: ChildVertex,
    mask: &mut Mask,
    scratch: &mut Mask,
    out: &mut [f64],
) -> bool {
    match cv {
        ChildVertex::Vertex(v) => {
            let Some(ring) = mesh.ring(adj, v) else {
                return false;
            };
            let hood = mesh.neighborhood(adj, v, &ring, boundary);
            if mesh.semi_sharp_at(v, &ring) {
                let vs = if hood.rule == VertexRule::Corner {
                    crease::INFINITE
                } else {
                    mesh.vs[v as usize]
                };
                scheme.semi_sharp_vertex_point_mask(
                    &hood,
                    vs,
                    &ring.sharpness,
                    boundary,
                    mask,
                    scratch,
                );
            } else {
                scheme.vertex_point_mask(&hood, mask);
            }
            mesh.apply_mask(adj, v, &ring, mask, out);
            true
        }
        ChildVertex::Edge(a, b) => {
            // The corners whose directed edge is a→b or b→a.
            let find = |x: u32, y: u32| {
                mesh.vcorners(adj, x)
                    .iter()
                    .copied()
                    .find(|&c| mesh.fv[mesh.next(adj, c) as usize] == y)
            };
            let cs: Vec<u32> = [find(a, b), find(b, a)].into_iter().flatten().collect();
            let Some(&c0) = cs.first() else {
                return false;
            };
            let flags = mesh.fe[c0 as usize];
            if cs.len() < 2 && flags & BOUNDARY == 0 {
                return false;
            }
            let tri = |k: usize| {
                cs.get(k)
                    .is_some_and(|&c| mesh.face(adj.cface[c as usize] as usize).len() == 3)
            };
            let semi = mesh.fs[c0 as usize];
            let mut em = scheme.edge_point_mask(&EdgeNeighborhood {
                num_faces: cs.len(),
                sharp: flags & SHARP != 0 || semi > 1.0,
                triangles: [tri(0), tri(1)],
            });
            crease::blend_edge_mask(&mut em, semi);
            mesh.axpy(out, a, em.end);
            mesh.axpy(out, b, em.end);
            for (k, &c) in cs.iter().enumerate() {
                let w = em.face[k];
                if w == 0.0 {
                    continue;
                }
                match em.face_weights[k] {
                    FaceWeights::Opposite => {
                        let o = mesh.fv[mesh.prev(adj, c) as usize];
                        mesh.axpy(out, o, w);
                    }
                    FaceWeights::Centers => mesh.axpy_face(adj, out, c, w),
                }
            }
            true
        }
        ChildVertex::Face(f) => {
            let c = mesh.fo[f as usize];
            mesh.axpy_face(adj, out, c, 1.0);
            true
        }
    }
}

/// Whole-mesh face count of a child vertex.
pub(crate) fn child_nfaces(
    mesh: &LocalMesh,
    adj: &Adjacency,
    scheme: Scheme,
    cv: ChildVertex,
) -> u32 {
    match cv {
        ChildVertex::Vertex(v) => mesh.nfaces[v as usize],
        ChildVertex::Edge(a, b) => {
            // Boundary edge iff flagged BOUNDARY on any of its corners; each face on the edge
            // gives 3 children there if split as a triangle, 2 if into quads.
            let mut boundary = false;
            let mut seen = 0;
            let mut per_face = 0;
            for &c in mesh.vcorners(adj, a) {
                let nx = mesh.fv[mesh.next(adj, c) as usize];
                let pv = mesh.fv[mesh.prev(adj, c) as usize];
                let len = mesh.face(adj.cface[c as usize] as usize).len();
                let per = if patch_scheme(scheme, len) == Scheme::Loop {
                    3
                } else {
                    2
                };
                if nx == b {
                    boundary |= mesh.fe[c as usize] & BOUNDARY != 0;
                    seen += 1;
                    per_face += per;
                }
                if pv == b {
                    boundary |= mesh.fe[mesh.prev(adj, c) as usize] & BOUNDARY != 0;
                    seen += 1;
                    per_face += per;
                }
            }
            // Faces of the edge outside the local mesh count as the scheme's regular kind.
            let missing = if boundary { 1 } else { 2 } - seen.min(if boundary { 1 } else { 2 });
            let per = if scheme == Scheme::Loop { 3 } else { 2 };
            per_face + per * missing
        }
        ChildVertex::Face(f) => mesh.face(f as usize).len() as u32,
    }
}

/// The faces within two rings of face `t` (faces sharing a vertex with a face that shares a
/// vertex with `t`), given per-vertex face lists. Sorted, unique.
pub(crate) fn two_ring(
    faces_of: &dyn Fn(u32) -> Vec<u32>,
    face_verts: &dyn Fn(u32) -> Vec<u32>,
    t: u32,
) -> Vec<u32> {
    let mut f1: Vec<u32> = face_verts(t).into_iter().flat_map(faces_of).collect();
    f1.sort_unstable();
    f1.dedup();
    let mut v2: Vec<u32> = f1.iter().flat_map(|&f| face_verts(f)).collect();
    v2.sort_unstable();
    v2.dedup();
    let mut f2: Vec<u32> = v2.into_iter().flat_map(faces_of).collect();
    f2.sort_unstable();
    f2.dedup();
    f2
}

/// The lattice directions of the ring slots of a regular Loop vertex (in the basis
/// `(c1 − c0, c2 − c0)` of the patch) and of a regular Catmull-Clark vertex.
const LOOP_DIRS: [[i32; 2]; 6] = [[1, 0], [0, 1], [-1, 1], [-1, 0], [0, -1], [1, -1]];
const CC_DIRS: [[i32; 2]; 8] = [
    [1, 0],
    [1, 1],
    [0, 1],
    [-1, 1],
    [-1, 0],
    [-1, -1],
    [0, -1],
    [1, -1],
];
const LOOP_CORNERS: [[i32; 2]; 3] = [[0, 0], [1, 0], [0, 1]];
const CC_CORNERS: [[i32; 2]; 4] = [[0, 0], [1, 0], [1, 1], [0, 1]];

/// The control points of the regular patch of face `t` as combinations of local vertices (12
/// for Loop, 16 for Catmull-Clark, in [`crate::patch`] order), or `None` if the face is not
/// regular: every corner must pass [`corner_points`].
pub(crate) fn regular_patch(
    mesh: &LocalMesh,
    adj: &Adjacency,
    scheme: Scheme,
    t: usize,
) -> Option<Vec<Combo>> {
    let face = mesh.face(t);
    let scheme = patch_scheme(scheme, face.len());
    if face.len() != scheme.regular_face_size() {
        return None;
    }
    let table: &[[i32; 2]] = match scheme {
        Scheme::Loop => &LOOP_PATCH_LATTICE,
        _ => &BSPLINE_PATCH_GRID,
    };
    let mut pts: Vec<Option<Combo>> = vec![None; table.len()];
    for k in 0..face.len() {
        let ok = corner_points(mesh, adj, scheme, t, k, &mut |lat, c| {
            if let Some(i) = table.iter().position(|&p| p == lat) {
                if pts[i].is_none() {
                    pts[i] = Some(c);
                }
            }
        });
        if !ok {
            return None;
        }
    }
    pts.into_iter().collect()
}

/// Whether corner `k` of face `t` is a regular vertex, calling `set(lattice position, point)`
/// for the lattice points of its ring (real or phantom) in the patch frame of `t`.
///
/// Regular: complete, not corner-tagged, faces around it of the regular size, and either smooth
/// with the regular valence and no sharp edge, or with exactly two sharp edges (crease or
/// boundary) and the regular number of faces (3 Loop, 2 Catmull-Clark) on `t`'s side.
pub(crate) fn corner_points(
    mesh: &LocalMesh,
    adj: &Adjacency,
    scheme: Scheme,
    t: usize,
    k: usize,
    set: &mut dyn FnMut([i32; 2], Combo),
) -> bool {
    let scheme = patch_scheme(scheme, mesh.face(t).len());
    let reg = scheme.regular_face_size();
    let (dirs, corners): (&[[i32; 2]], &[[i32; 2]]) = match scheme {
        Scheme::Loop => (&LOOP_DIRS, &LOOP_CORNERS),
        _ => (&CC_DIRS, &CC_CORNERS),
    };
    let nslots = dirs.len() as i32;
    let face = mesh.face(t);
    let v = face[k];
    if mesh.corner[v as usize] {
        return false;
    }
    let Some(ring) = mesh.ring(adj, v) else {
        return false;
    };
    if mesh.semi_sharp_at(v, &ring) {
        // The rules change around `v` at a later level: not a polynomial patch yet.
        return false;
    }
    let nf = ring.corners.len();
    let ne = ring.verts.len();
    if ring
        .corners
        .iter()
        .any(|&c| mesh.face(adj.cface[c as usize] as usize).len() != reg)
    {
        return false;
    }
    let nsharp = ring.eflags.iter().filter(|&&f| f & SHARP != 0).count();
    let Some(p) = ring
        .corners
        .iter()
        .position(|&c| adj.cface[c as usize] as usize == t)
    else {
        return false;
    };
    let corner = corners[k];
    // Corner k's ring is the base ring rotated by k steps of 60° (Loop) or 90° (Catmull-Clark),
    // i.e. 2k slots either way.
    let rot = 2 * k as i32;
    let dir = |slot: i32| {
        let d = dirs[((slot + rot).rem_euclid(nslots)) as usize];
        [corner[0] + d[0], corner[1] + d[1]]
    };
    let edge_vert = |i: usize| ring.verts[i % ne];
    let diag = |j: usize| {
        let c = ring.corners[j % nf];
        mesh.fv[mesh.next(adj, mesh.next(adj, c)) as usize]
    };
    match (nsharp, ring.boundary) {
        (0, false) => {
            if nf != scheme.regular_valence() {
                return false;
            }
            for j in 0..nf {
                let rel = j as i32 - p as i32;
                match scheme {
                    Scheme::Loop => set(dir(rel), Combo::one(edge_vert(j))),
                    _ => {
                        set(dir(2 * rel), Combo::one(edge_vert(j)));
                        set(dir(2 * rel + 1), Combo::one(diag(j)));
                    }
                }
            }
        }
        (2, _) => {
            let sharp: Vec<usize> = (0..ne).filter(|&i| ring.eflags[i] & SHARP != 0).collect();
            if ring.boundary && (sharp[0] != 0 || sharp[1] != ne - 1) {
                return false;
            }
            // The sector of faces between the two sharp edges that contains face p (face j lies
            // between edges j and j + 1; cyclic for an interior vertex, where ne == nf).
            let (lo, hi) = if ring.boundary {
                (0usize, nf - 1)
            } else if p >= sharp[0] && p < sharp[1] {
                (sharp[0], sharp[1] - 1)
            } else {
                (sharp[1], sharp[0] + nf - 1)
            };
            let want = if scheme == Scheme::Loop { 3 } else { 2 };
            if hi + 1 - lo != want {
                return false;
            }
            let pp = if p < lo { p + nf } else { p };
            let s = lo as i32 - pp as i32;
            let ev = |m: usize| edge_vert(lo + m);
            match scheme {
                Scheme::Loop => {
                    for m in 0..4 {
                        set(dir(s + m as i32), Combo::one(ev(m)));
                    }
                    set(
                        dir(s + 4),
                        Combo::three((v, 1.0), (ev(3), 1.0), (ev(2), -1.0)),
                    );
                    set(
                        dir(s + 5),
                        Combo::three((v, 1.0), (ev(0), 1.0), (ev(1), -1.0)),
                    );
                }
                _ => {
                    let s = 2 * s;
                    let (e0, d0, e1, d1, e2) = (ev(0), diag(lo), ev(1), diag(lo + 1), ev(2));
                    set(dir(s), Combo::one(e0));
                    set(dir(s + 1), Combo::one(d0));
                    set(dir(s + 2), Combo::one(e1));
                    set(dir(s + 3), Combo::one(d1));
                    set(dir(s + 4), Combo::one(e2));
                    set(dir(s + 5), Combo::two((e2, 2.0), (d1, -1.0)));
                    set(dir(s + 6), Combo::two((v, 2.0), (e1, -1.0)));
                    set(dir(s + 7), Combo::two((e0, 2.0), (d0, -1.0)));
                }
            }
        }
        _ => return false,
    }
    set(corner, Combo::one(v));
    true
}
