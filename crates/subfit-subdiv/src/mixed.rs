//! Limit masks of the quad/triangle scheme at vertices where triangles and quads meet.
//!
//! Stam & Loop 2003 give no closed form there, so the masks come from the eigenstructure of the
//! local subdivision matrix `S` of the vertex's 1-ring (the vertex, its ring vertices and the
//! diagonal vertex of each quad): one refinement maps the 1-ring of `v` onto the 1-ring of its
//! child with the same configuration (triangles stay triangles, quads quads), so `S` is square
//! and repeated refinement is `S^k`. Then (Halstead et al. 1993 §A; Zorin & Schröder, SIGGRAPH
//! 2000 course notes, ch. 4):
//!
//! * the limit position is `l₀ · P` with `l₀` the left eigenvector of the eigenvalue 1, scaled to
//!   sum to 1 (the dominant eigenvalue of an affine-invariant, convergent scheme);
//! * at a smooth (or dart) vertex the tangent plane is spanned by the left invariant subspace of
//!   the two subdominant eigenvalues `λ₁, λ₂` (real, a double pair, or a complex pair alike: the
//!   null space of `(Sᵀ − λ₁)(Sᵀ − λ₂)`, a real matrix);
//! * at a crease or boundary vertex one tangent runs along the crease (`(n_{c0} − n_{c1}) / 2`,
//!   the crease B-spline's derivative, an exact eigenvector of eigenvalue 1/2) and the other is
//!   the eigenvector of the largest remaining eigenvalue whose mask does not vanish across the
//!   crease.
//!
//! Tangent masks are normalized like OpenSubdiv's conventions (see [`Scheme::limit_masks`]):
//! on a planar embedding of the ring (edge 0 along x, faces counter-clockwise, a triangle
//! spanning 60° and a quad 90°, a crease's interior span mapped to the upper half-plane) `t1`
//! evaluates to `(1, 0)` and `t2` to `(0, 1)`, so `t1` points toward edge 0 (or along the crease
//! toward the leading crease edge) and `t1 × t2` follows the face winding.
//!
//! The matrix rows are the refinement rules of [`Scheme::vertex_point_mask`] and
//! [`Scheme::edge_point_mask`] themselves, so masks and refinement cannot disagree. Each
//! configuration (rule, face kinds, crease ends) is analysed once per process and cached;
//! cost O(m³) with `m = 1 + valence + #quads` (a dense eigen-analysis of a 10–30 wide matrix,
//! tens of microseconds).
//!
//! Checked (tests here and in `tests/quad_triangle.rs`): the regular seam vertex has the
//! spectrum 1, 1/2, 1/2, 1/4, 1/4; masks are invariant under refinement (a vertex's limit at
//! level k equals its child's at level k + 1); refinement converges to them.

use crate::mask_types::{EdgeMask, FaceWeights, Mask};
use crate::scheme::{EdgeNeighborhood, Neighborhood, Scheme, VertexRule};
use nalgebra::{Complex, DMatrix};
use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::{Arc, OnceLock, RwLock};

/// The three masks of one configuration.
type Masks = Arc<[Mask; 3]>;

fn cache() -> &'static RwLock<HashMap<Neighborhood, Masks>> {
    static CACHE: OnceLock<RwLock<HashMap<Neighborhood, Masks>>> = OnceLock::new();
    CACHE.get_or_init(Default::default)
}

/// Fills the limit position and tangent masks of a mixed quad/triangle vertex (smooth, dart or
/// crease rule; faces triangles and quads). Face weights are [`FaceWeights::Opposite`] (the
/// quad's diagonal vertex; zero for triangles).
pub(crate) fn limit_masks(hood: &Neighborhood, pos: &mut Mask, t1: &mut Mask, t2: &mut Mask) {
    let found = cache()
        .read()
        .unwrap_or_else(|e| e.into_inner())
        .get(hood)
        .cloned();
    let masks = match found {
        Some(m) => m,
        None => {
            let m: Masks = Arc::new(analyse(hood));
            cache()
                .write()
                .unwrap_or_else(|e| e.into_inner())
                .insert(*hood, m.clone());
            m
        }
    };
    pos.clone_from(&masks[0]);
    t1.clone_from(&masks[1]);
    t2.clone_from(&masks[2]);
}

/// Local indices of the 1-ring: the vertex, ring vertex `i`, the diagonal of quad face `i`.
struct Layout {
    n: usize,
    nf: usize,
    diag: Vec<Option<usize>>,
    size: usize,
}

impl Layout {
    fn new(hood: &Neighborhood) -> Self {
        let (n, nf) = (hood.num_edges, hood.num_faces);
        let mut size = 1 + n;
        let diag = (0..nf)
            .map(|i| {
                (!hood.faces.is_triangle(i)).then(|| {
                    size += 1;
                    size - 1
                })
            })
            .collect();
        Self { n, nf, diag, size }
    }

    fn ring(&self, i: usize) -> usize {
        1 + i % self.n
    }

    /// Adds `w ×` the centroid of quad face `f` to `row`.
    fn center(&self, row: &mut [f64], f: usize, w: f64) {
        let d = self.diag[f].expect("a quad face");
        for j in [0, self.ring(f), d, self.ring(f + 1)] {
            row[j] += 0.25 * w;
        }
    }

    /// The faces on either side of ring edge `i` (`None` past a boundary).
    fn edge_faces(&self, i: usize) -> [Option<usize>; 2] {
        let closed = self.nf == self.n;
        let before = if i > 0 {
            Some(i - 1)
        } else if closed {
            Some(self.nf - 1)
        } else {
            None
        };
        let after = (i < self.nf).then_some(i);
        [before, after]
    }
}

/// Whether ring edge `i` is infinitely sharp under `hood`'s rule.
fn sharp_edge(hood: &Neighborhood, i: usize) -> bool {
    match hood.rule {
        VertexRule::Crease => hood.crease_ends.contains(&i),
        VertexRule::Dart => hood.crease_ends[0] == i,
        _ => false,
    }
}

/// The local subdivision matrix (rows: child 1-ring, columns: parent 1-ring).
fn subdivision_matrix(hood: &Neighborhood, lay: &Layout) -> DMatrix<f64> {
    let m = lay.size;
    let mut s = DMatrix::<f64>::zeros(m, m);
    let mut row = vec![0.0; m];
    let mut mask = Mask::default();
    Scheme::QuadTriangle.vertex_point_mask(hood, &mut mask);
    row[0] += mask.vertex;
    for (i, &w) in mask.edges.iter().enumerate() {
        row[lay.ring(i)] += w;
    }
    for (f, &w) in mask.faces.iter().enumerate() {
        if w != 0.0 {
            lay.center(&mut row, f, w);
        }
    }
    set_row(&mut s, 0, &mut row);
    for i in 0..lay.n {
        let faces = lay.edge_faces(i);
        let present: Vec<usize> = faces.iter().flatten().copied().collect();
        let mut triangles = [false; 2];
        for (k, &f) in present.iter().enumerate() {
            triangles[k] = hood.faces.is_triangle(f);
        }
        let em: EdgeMask = Scheme::QuadTriangle.edge_point_mask(&EdgeNeighborhood {
            num_faces: present.len(),
            sharp: sharp_edge(hood, i) || present.len() < 2,
            triangles,
        });
        row[0] += em.end;
        row[lay.ring(i)] += em.end;
        for (k, &f) in present.iter().enumerate() {
            let w = em.face[k];
            if w == 0.0 {
                continue;
            }
            match em.face_weights[k] {
                FaceWeights::Opposite => {
                    // Face f spans ring edges f and f + 1: the third vertex is the other one.
                    let other = if f == i { f + 1 } else { f };
                    row[lay.ring(other)] += w;
                }
                FaceWeights::Centers => lay.center(&mut row, f, w),
            }
        }
        set_row(&mut s, lay.ring(i), &mut row);
    }
    for f in 0..lay.nf {
        if let Some(d) = lay.diag[f] {
            lay.center(&mut row, f, 1.0);
            set_row(&mut s, d, &mut row);
        }
    }
    s
}

fn set_row(s: &mut DMatrix<f64>, r: usize, row: &mut [f64]) {
    for (j, w) in row.iter_mut().enumerate() {
        s[(r, j)] = *w;
        *w = 0.0;
    }
}

/// The planar embedding of the ring used to orient and scale the tangent masks (module docs):
/// columns x and y of the 1-ring points.
fn embedding(hood: &Neighborhood, lay: &Layout) -> Vec<[f64; 2]> {
    let width = |f: usize| if hood.faces.is_triangle(f) { 1.0 } else { 1.5 };
    let mut angle = vec![0.0; lay.n];
    match hood.rule {
        VertexRule::Crease => {
            let [c0, c1] = hood.crease_ends;
            // Faces c0 .. c1 − 1 span [0, π], the others [π, 2π].
            let inside: f64 = (c0..c1).map(width).sum();
            let outside: f64 = (0..lay.nf)
                .filter(|f| !(c0..c1).contains(f))
                .map(width)
                .sum();
            let mut a = 0.0;
            for k in 0..lay.n {
                let i = (c0 + k) % lay.n;
                angle[i] = a;
                let f = i;
                if f < lay.nf {
                    a += if (c0..c1).contains(&f) {
                        PI * width(f) / inside
                    } else {
                        PI * width(f) / outside
                    };
                }
            }
        }
        _ => {
            let total: f64 = (0..lay.nf).map(width).sum();
            let mut a = 0.0;
            for (i, slot) in angle.iter_mut().enumerate() {
                *slot = a;
                a += 2.0 * PI * width(i) / total;
            }
        }
    }
    let mut x = vec![[0.0; 2]; lay.size];
    for i in 0..lay.n {
        x[lay.ring(i)] = [angle[i].cos(), angle[i].sin()];
    }
    for f in 0..lay.nf {
        if let Some(d) = lay.diag[f] {
            let (a, b) = (x[lay.ring(f)], x[lay.ring(f + 1)]);
            x[d] = [a[0] + b[0], a[1] + b[1]];
        }
    }
    x
}

/// The eigenvalues of `s`. nalgebra's Francis iteration can stall on some exactly structured
/// matrices, so it runs with an iteration cap and, when the cap is hit, on a similar matrix
/// `Q S Qᵀ` (a fixed pseudo-random rotation `Q`), which has the same eigenvalues.
fn eigenvalues(s: &DMatrix<f64>) -> Vec<Complex<f64>> {
    let m = s.nrows();
    let mut a = s.clone();
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    for _ in 0..8 {
        if let Some(schur) = nalgebra::Schur::try_new(a.clone(), f64::EPSILON, 10_000) {
            return schur.complex_eigenvalues().iter().copied().collect();
        }
        let r = DMatrix::<f64>::from_fn(m, m, |_, _| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        });
        let q = r.qr().q();
        a = &q * s * q.transpose();
    }
    panic!("no eigenvalues for a {m}×{m} quad/triangle subdivision matrix");
}

/// Right singular vectors of the `k` smallest singular values of `a`.
fn null_space(a: &DMatrix<f64>, k: usize) -> Vec<Vec<f64>> {
    let svd = a.clone().svd(false, true);
    let vt = svd.v_t.expect("requested");
    let mut order: Vec<usize> = (0..svd.singular_values.len()).collect();
    order.sort_by(|&i, &j| svd.singular_values[i].total_cmp(&svd.singular_values[j]));
    order[..k]
        .iter()
        .map(|&r| vt.row(r).iter().copied().collect())
        .collect()
}

fn dot2(mask: &[f64], x: &[[f64; 2]]) -> [f64; 2] {
    let mut out = [0.0; 2];
    for (w, p) in mask.iter().zip(x) {
        out[0] += w * p[0];
        out[1] += w * p[1];
    }
    out
}

/// Eigen-analysis of one configuration: `[position, t1, t2]` masks.
fn analyse(hood: &Neighborhood) -> [Mask; 3] {
    let lay = Layout::new(hood);
    let m = lay.size;
    let s = subdivision_matrix(hood, &lay);
    let a = s.transpose();
    let id = DMatrix::<f64>::identity(m, m);
    // Limit position: the left eigenvector of eigenvalue 1.
    let mut l0 = null_space(&(&a - &id), 1).remove(0);
    let sum: f64 = l0.iter().sum();
    l0.iter_mut().for_each(|w| *w /= sum);
    // Eigenvalues by modulus, without the dominant 1.
    let mut eig = eigenvalues(&s);
    eig.sort_by(|x, y| y.norm().total_cmp(&x.norm()));
    let one = (0..eig.len())
        .min_by(|&i, &j| (eig[i] - 1.0).norm().total_cmp(&(eig[j] - 1.0).norm()))
        .expect("a non-empty matrix");
    eig.remove(one);
    let x = embedding(hood, &lay);
    let (t1, t2) = if hood.rule == VertexRule::Crease {
        crease_tangents(hood, &lay, &a, &id, &eig, &x)
    } else {
        // The subdominant pair: roots of z² − s z + p, real or conjugate.
        let (l1, l2) = (eig[0], eig[1]);
        let (sum, prod) = ((l1 + l2).re, (l1 * l2).re);
        let b = &a * &a - &a * sum + &id * prod;
        let basis = null_space(&b, 2);
        let g = [dot2(&basis[0], &x), dot2(&basis[1], &x)];
        let det = g[0][0] * g[1][1] - g[0][1] * g[1][0];
        // [t1; t2] = G⁻¹ [b1; b2], so that t·X = I.
        let inv = [
            [g[1][1] / det, -g[0][1] / det],
            [-g[1][0] / det, g[0][0] / det],
        ];
        let comb = |r: [f64; 2]| -> Vec<f64> {
            (0..m)
                .map(|j| r[0] * basis[0][j] + r[1] * basis[1][j])
                .collect()
        };
        (comb(inv[0]), comb(inv[1]))
    };
    [
        to_mask(hood, &lay, &l0),
        to_mask(hood, &lay, &t1),
        to_mask(hood, &lay, &t2),
    ]
}

/// Crease tangents: along the crease (exact), and the dominant mode across it.
fn crease_tangents(
    hood: &Neighborhood,
    lay: &Layout,
    a: &DMatrix<f64>,
    id: &DMatrix<f64>,
    eig: &[Complex<f64>],
    x: &[[f64; 2]],
) -> (Vec<f64>, Vec<f64>) {
    let m = lay.size;
    let [c0, c1] = hood.crease_ends;
    let mut t1 = vec![0.0; m];
    t1[lay.ring(c0)] = 0.5;
    t1[lay.ring(c1)] = -0.5;
    let mut seen: Vec<f64> = Vec::new();
    for z in eig {
        let lambda = z.re;
        if z.im.abs() > 1e-9 || seen.iter().any(|s| (s - lambda).abs() < 1e-9) {
            continue;
        }
        seen.push(lambda);
        let basis = null_space(&(a - id * lambda), 2);
        for b in basis {
            // Not an eigenvector: skip (the second singular vector of a simple eigenvalue).
            let r: f64 = (a * nalgebra::DVector::from_column_slice(&b)
                - nalgebra::DVector::from_column_slice(&b) * lambda)
                .norm();
            if r > 1e-9 {
                continue;
            }
            let p = dot2(&b, x);
            if p[1].abs() > 1e-6 {
                let t2 = (0..m).map(|j| (b[j] - p[0] * t1[j]) / p[1]).collect();
                return (t1, t2);
            }
        }
    }
    // No mode across the crease (cannot happen for a scheme that converges): fall back to the
    // span's middle edge direction.
    let mut t2 = vec![0.0; m];
    t2[lay.ring((c0 + c1) / 2)] = 1.0;
    t2[0] = -1.0;
    (t1, t2)
}

/// A local vector as a [`Mask`] (vertex, ring edges, faces' diagonals).
fn to_mask(hood: &Neighborhood, lay: &Layout, w: &[f64]) -> Mask {
    let mut mask = Mask::default();
    mask.reset(hood.num_edges, hood.num_faces, FaceWeights::Opposite);
    mask.vertex = w[0];
    for i in 0..lay.n {
        mask.edges[i] = w[lay.ring(i)];
    }
    for f in 0..lay.nf {
        if let Some(d) = lay.diag[f] {
            mask.faces[f] = w[d];
        }
    }
    mask
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::FaceKinds;

    fn smooth(pattern: &[bool]) -> Neighborhood {
        Neighborhood {
            num_edges: pattern.len(),
            num_faces: pattern.len(),
            rule: VertexRule::Smooth,
            crease_ends: [0, 0],
            faces: FaceKinds::from_triangles(pattern.iter().copied()),
        }
    }

    fn spectrum(hood: &Neighborhood) -> Vec<f64> {
        let lay = Layout::new(hood);
        let s = subdivision_matrix(hood, &lay);
        let mut e: Vec<f64> = eigenvalues(&s).iter().map(|z| z.norm()).collect();
        e.sort_by(|a, b| b.total_cmp(a));
        e
    }

    #[test]
    fn the_regular_seam_vertex_has_the_regular_spectrum() {
        // Three triangles and two quads: the configuration along a straight seam.
        let e = spectrum(&smooth(&[true, true, true, false, false]));
        for (got, want) in e.iter().zip([1.0, 0.5, 0.5, 0.25, 0.25]) {
            assert!((got - want).abs() < 1e-12, "{e:?}");
        }
    }

    #[test]
    fn mixed_vertices_have_a_dominant_one_and_a_subdominant_pair() {
        // Every mixed pattern of 3 to 7 faces: 1 > λ1 ≥ λ2 > |λ3| (tangent-plane continuity's
        // eigenvalue condition).
        for n in 3..=7usize {
            for bits in 1..(1u32 << n) - 1 {
                let p: Vec<bool> = (0..n).map(|i| bits >> i & 1 == 1).collect();
                let e = spectrum(&smooth(&p));
                assert!((e[0] - 1.0).abs() < 1e-12, "{p:?}: {e:?}");
                assert!(e[1] < 1.0 - 1e-9 && e[2] > e[3] + 1e-6, "{p:?}: {e:?}");
            }
        }
    }

    #[test]
    fn masks_are_affine_and_tangents_orient_with_the_embedding() {
        let (mut p, mut a, mut b) = (Mask::default(), Mask::default(), Mask::default());
        let hoods = [
            smooth(&[true, false, true, false]),
            smooth(&[true, true, false]),
            Neighborhood {
                num_edges: 4,
                num_faces: 3,
                rule: VertexRule::Crease,
                crease_ends: [0, 3],
                faces: FaceKinds::from_triangles([true, false, true]),
            },
        ];
        for h in &hoods {
            limit_masks(h, &mut p, &mut a, &mut b);
            assert!((p.sum() - 1.0).abs() < 1e-12, "{h:?}");
            assert!(a.sum().abs() < 1e-12 && b.sum().abs() < 1e-12, "{h:?}");
            // Weights of triangles' "diagonals" are zero.
            for f in 0..h.num_faces {
                if h.faces.is_triangle(f) {
                    assert_eq!(p.faces[f], 0.0);
                }
            }
            assert!(
                p.vertex > 0.0 && p.edges.iter().all(|&w| w > 0.0),
                "{h:?}: {p:?}"
            );
        }
    }
}
