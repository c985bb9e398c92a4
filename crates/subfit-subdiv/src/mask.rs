//! Masks: the weights a scheme assigns to a vertex's neighbourhood, filled independently of mesh
//! storage (OpenSubdiv `Sdc::Scheme` style).
//!
//! * Refinement masks — Loop 1987 (vertex β of Loop's thesis,
//!   `β = (5/8 − (3/8 + 1/4 cos 2π/n)²)/n`; edge points 3/8, 3/8, 1/8, 1/8) and Catmull & Clark
//!   1978 (vertex point `(n−2)/n V + 1/n² Σ E + 1/n² Σ F` over ring vertices and face points;
//!   edge point ¼ of ends and face points); crease and corner rules of Hoppe et al. 1994
//!   (crease edge: midpoint; crease vertex: 1/8, 3/4, 1/8; corner: fixed).
//! * Limit masks — Halstead et al. 1993 for Catmull-Clark positions (`n² V + 4 Σ E + Σ F` over
//!   `n(n+5)`, with F the diagonal vertices of the quads), Loop's limit
//!   (`1/(n + 3/(8β))` per neighbour); the cubic B-spline 1/6, 2/3, 1/6 on creases; tangents as
//!   OpenSubdiv 3.5 `sdc/loopScheme.h` and `sdc/catmarkScheme.h` (cos/sin weights around the
//!   ring; Biermann et al. 2000 cross-boundary tangents), including OpenSubdiv's scale factors,
//!   so that `normalize(t1 × t2)` reproduces OpenSubdiv's normals and follows the face winding.
//! * Quad/triangle (Stam & Loop 2003, *Quad/triangle subdivision*; Lavoué et al. §3.1, Fig. 8):
//!   the scheme is linear subdivision (edge midpoints, face centroids of non-triangles) followed
//!   by averaging, where each vertex moves to the average of the centroids of its incident
//!   children, a triangle's centroid weighting its own corner 1/4 and the other two 3/8. Worked
//!   out over the coarse mesh this is: a vertex on triangles only → Loop's vertex rule; on no
//!   triangle → Catmull-Clark's; on both (`k` faces) → `(1/k) Σ_f`, with a triangle `(v, a, b)`
//!   contributing `5/8 v + 3/16 (a + b)` and any other face `v/2 + (a + b)/8 + F/4` (F its
//!   centroid). An edge point is the weighted mean of its faces' contributions: a triangle
//!   `(a, b, c)` gives `9/8 (a + b) + 3/4 c` (weight 3), another face `(a + b)/2 + F` (weight 2):
//!   Loop's 3/8, 1/8 between two triangles, Catmull-Clark's 1/4 between two quads, and
//!   `13/40 (a + b) + 3/20 c + 1/5 F` on a quad/triangle seam. At a regular seam vertex (three
//!   triangles, two quads) the local subdivision matrix has the spectrum 1, 1/2, 1/2, 1/4, 1/4
//!   of the regular schemes (checked in module `mixed`). Boundary, crease and corner rules are
//!   the same as Loop's and Catmull-Clark's. Limit masks: Loop's or Catmull-Clark's where the
//!   ring is pure, eigenvectors of the local subdivision matrix where it is mixed (module
//!   `mixed`).

pub use crate::mask_types::{EdgeMask, FaceWeights, Mask};
use crate::scheme::{EdgeNeighborhood, FaceKinds, Neighborhood, Scheme, VertexRule};
use std::f64::consts::PI;

/// Quad/triangle vertex point on a mixed ring (module docs): `(1/k) Σ_f` of the face
/// contributions.
fn mixed_vertex_point(hood: &Neighborhood, mask: &mut Mask) {
    let (n, nf) = (hood.num_edges, hood.num_faces);
    mask.reset(n, nf, FaceWeights::Centers);
    let k = nf as f64;
    for i in 0..nf {
        let j = (i + 1) % n;
        if hood.faces.is_triangle(i) {
            mask.vertex += 0.625 / k;
            mask.edges[i] += 0.1875 / k;
            mask.edges[j] += 0.1875 / k;
        } else {
            mask.vertex += 0.5 / k;
            mask.edges[i] += 0.125 / k;
            mask.edges[j] += 0.125 / k;
            mask.faces[i] = 0.25 / k;
        }
    }
}

/// Loop's β for a smooth vertex of valence `n` (Loop 1987): `(5/8 − (3/8 + ¼ cos 2π/n)²) / n`.
pub fn loop_beta(n: usize) -> f64 {
    let c = 0.375 + 0.25 * (2.0 * PI / n as f64).cos();
    (0.625 - c * c) / n as f64
}

impl Scheme {
    /// Fills the mask of the child vertex of a vertex (its "vertex point"). Face weights, when
    /// present, refer to face centres. Cost O(valence).
    pub fn vertex_point_mask(self, hood: &Neighborhood, mask: &mut Mask) {
        let n = hood.num_edges;
        match hood.rule {
            VertexRule::Corner => {
                mask.reset(n, 0, FaceWeights::Centers);
                mask.vertex = 1.0;
            }
            VertexRule::Crease => {
                mask.reset(n, 0, FaceWeights::Centers);
                mask.vertex = 0.75;
                mask.edges[hood.crease_ends[0]] = 0.125;
                mask.edges[hood.crease_ends[1]] = 0.125;
            }
            VertexRule::Smooth | VertexRule::Dart => match self.pure(hood.faces) {
                Scheme::QuadTriangle => mixed_vertex_point(hood, mask),
                Scheme::Loop => {
                    mask.reset(n, 0, FaceWeights::Centers);
                    let (v, e) = if n == 6 {
                        (0.625, 0.0625)
                    } else {
                        let b = loop_beta(n);
                        (1.0 - n as f64 * b, b)
                    };
                    mask.vertex = v;
                    mask.edges.fill(e);
                }
                Scheme::CatmullClark => {
                    let nf = hood.num_faces;
                    mask.reset(n, nf, FaceWeights::Centers);
                    let nn = n as f64;
                    mask.vertex = (nn - 2.0) / nn;
                    mask.edges.fill(1.0 / (nn * nn));
                    mask.faces.fill(1.0 / (nn * nn));
                }
            },
        }
    }

    /// The scheme whose rules apply on a ring of `faces`: Loop or Catmull-Clark themselves;
    /// for the quad/triangle scheme Loop on triangles only, Catmull-Clark without triangles, and
    /// `QuadTriangle` (its mixed rules) otherwise.
    pub fn pure(self, faces: FaceKinds) -> Scheme {
        match (self, faces) {
            (Scheme::QuadTriangle, FaceKinds::Triangles) => Scheme::Loop,
            (Scheme::QuadTriangle, FaceKinds::Polygons) => Scheme::CatmullClark,
            (s, _) => s,
        }
    }

    /// The mask of the child vertex of an edge (its "edge point"). Cost O(1).
    pub fn edge_point_mask(self, edge: &EdgeNeighborhood) -> EdgeMask {
        let tri = |i: usize| match self {
            Scheme::Loop => true,
            Scheme::CatmullClark => false,
            Scheme::QuadTriangle => edge.triangles[i],
        };
        let kind = |i: usize| {
            if tri(i) {
                FaceWeights::Opposite
            } else {
                FaceWeights::Centers
            }
        };
        let face_weights = [kind(0), kind(1)];
        if edge.sharp || edge.num_faces < 2 {
            return EdgeMask {
                end: 0.5,
                face: [0.0; 2],
                face_weights,
            };
        }
        // Contributions (module docs): a triangle 9/8 per end and 3/4 opposite (weight 3),
        // another face 1/2 per end and its centroid (weight 2).
        let (mut end, mut face, mut total) = (0.0, [0.0; 2], 0.0);
        for (i, f) in face.iter_mut().enumerate() {
            if tri(i) {
                end += 1.125;
                *f = 0.75;
                total += 3.0;
            } else {
                end += 0.5;
                *f = 1.0;
                total += 2.0;
            }
        }
        EdgeMask {
            end: end / total,
            face: face.map(|f| f / total),
            face_weights,
        }
    }

    /// Fills the limit position mask and the two limit tangent masks of a vertex.
    ///
    /// Requires the regular face size around the vertex for Catmull-Clark (quads: face weights
    /// are [`FaceWeights::Opposite`]), and for the quad/triangle scheme triangles and quads only
    /// (face weights of triangles are zero). Tangent conventions are OpenSubdiv's: at a smooth vertex
    /// `t1` points toward ring edge 0 and `t2` is rotated toward edge 1; at a crease `t1` runs
    /// along the crease toward the leading crease edge and `t2` points across the surface into the
    /// span between the crease edges; at a corner `t1`, `t2` point along edges 0 and 1. With the
    /// counter-clockwise ring of [`Neighborhood`], `t1 × t2` points to the side the face winding
    /// makes the front. Magnitudes are OpenSubdiv's (only directions are meaningful). A vertex
    /// without edges gets zero tangents. Cost O(valence).
    pub fn limit_masks(self, hood: &Neighborhood, pos: &mut Mask, t1: &mut Mask, t2: &mut Mask) {
        let n = hood.num_edges;
        let nf = hood.num_faces;
        let rule = match hood.rule {
            VertexRule::Smooth | VertexRule::Dart if nf == 2 && n == 2 => VertexRule::Corner,
            r => r,
        };
        match rule {
            VertexRule::Corner => {
                pos.reset(n, 0, FaceWeights::Opposite);
                pos.vertex = 1.0;
                t1.reset(n, 0, FaceWeights::Opposite);
                t2.reset(n, 0, FaceWeights::Opposite);
                if n >= 2 {
                    let s = match self.pure(hood.faces) {
                        Scheme::Loop => 3.0,
                        Scheme::CatmullClark | Scheme::QuadTriangle => 1.0,
                    };
                    t1.vertex = -s;
                    t1.edges[0] = s;
                    t2.vertex = -s;
                    t2.edges[1] = s;
                }
            }
            VertexRule::Crease => {
                pos.reset(n, 0, FaceWeights::Opposite);
                pos.vertex = 2.0 / 3.0;
                pos.edges[hood.crease_ends[0]] = 1.0 / 6.0;
                pos.edges[hood.crease_ends[1]] = 1.0 / 6.0;
                match self.pure(hood.faces) {
                    Scheme::Loop => loop_crease_tangents(hood, t1, t2),
                    Scheme::CatmullClark => catmark_crease_tangents(hood, t1, t2),
                    Scheme::QuadTriangle => crate::mixed::limit_masks(hood, pos, t1, t2),
                }
            }
            VertexRule::Smooth | VertexRule::Dart => match self.pure(hood.faces) {
                Scheme::Loop => loop_smooth_limit(n, pos, t1, t2),
                Scheme::CatmullClark => catmark_smooth_limit(n, pos, t1, t2),
                Scheme::QuadTriangle => crate::mixed::limit_masks(hood, pos, t1, t2),
            },
        }
    }
}

fn loop_smooth_limit(n: usize, pos: &mut Mask, t1: &mut Mask, t2: &mut Mask) {
    pos.reset(n, 0, FaceWeights::Opposite);
    let (v, e) = if n == 6 {
        (0.5, 1.0 / 12.0)
    } else {
        let e = 1.0 / (n as f64 + 3.0 / (8.0 * loop_beta(n)));
        (1.0 - n as f64 * e, e)
    };
    pos.vertex = v;
    pos.edges.fill(e);
    t1.reset(n, 0, FaceWeights::Opposite);
    t2.reset(n, 0, FaceWeights::Opposite);
    if n == 6 {
        let r = 0.5 * 3f64.sqrt();
        t1.edges.copy_from_slice(&[1.0, 0.5, -0.5, -1.0, -0.5, 0.5]);
        t2.edges.copy_from_slice(&[0.0, r, r, 0.0, -r, -r]);
    } else {
        let alpha = 2.0 * PI / n as f64;
        for i in 0..n {
            let a = alpha * i as f64;
            t1.edges[i] = a.cos();
            t2.edges[i] = a.sin();
        }
    }
}

fn catmark_smooth_limit(n: usize, pos: &mut Mask, t1: &mut Mask, t2: &mut Mask) {
    pos.reset(n, n, FaceWeights::Opposite);
    let (v, e, f) = if n == 4 {
        (4.0 / 9.0, 1.0 / 9.0, 1.0 / 36.0)
    } else {
        let nn = n as f64;
        let f = 1.0 / (nn * (nn + 5.0));
        let e = 4.0 * f;
        (1.0 - nn * (e + f), e, f)
    };
    pos.vertex = v;
    pos.edges.fill(e);
    pos.faces.fill(f);
    t1.reset(n, n, FaceWeights::Opposite);
    t2.reset(n, n, FaceWeights::Opposite);
    if n == 4 {
        t1.edges.copy_from_slice(&[4.0, 0.0, -4.0, 0.0]);
        t1.faces.copy_from_slice(&[1.0, -1.0, -1.0, 1.0]);
        t2.edges.copy_from_slice(&[0.0, 4.0, 0.0, -4.0]);
        t2.faces.copy_from_slice(&[1.0, 1.0, -1.0, -1.0]);
        return;
    }
    let theta = 2.0 * PI / n as f64;
    let (ct, cht) = (theta.cos(), (0.5 * theta).cos());
    // Subdominant eigenvalue of the Catmull-Clark subdivision matrix.
    let lambda = 5.0 / 16.0 + (ct + cht * (2.0 * (9.0 + ct)).sqrt()) / 16.0;
    let fscale = 1.0 / (4.0 * lambda - 1.0);
    for i in 0..n {
        let (ci, ci1) = ((theta * i as f64).cos(), (theta * (i + 1) as f64).cos());
        t1.edges[i] = 4.0 * ci;
        t1.faces[i] = fscale * (ci + ci1);
    }
    // t2 is t1 rotated one step toward edge 1.
    for i in 0..n {
        let j = (i + n - 1) % n;
        t2.edges[i] = t1.edges[j];
        t2.faces[i] = t1.faces[j];
    }
}

fn loop_crease_tangents(hood: &Neighborhood, t1: &mut Mask, t2: &mut Mask) {
    let n = hood.num_edges;
    let [c0, c1] = hood.crease_ends;
    t1.reset(n, 0, FaceWeights::Opposite);
    t1.edges[c0] = 1.5;
    t1.edges[c1] = -1.5;
    t2.reset(n, 0, FaceWeights::Opposite);
    let interior = c1 - c0 - 1;
    match interior {
        0 => {
            t2.vertex = -6.0;
            t2.edges[c0] = 3.0;
            t2.edges[c1] = 3.0;
        }
        1 => {
            t2.vertex = -3.0;
            t2.edges[c0 + 1] = 3.0;
        }
        2 => {
            let r3 = 3f64.sqrt();
            t2.vertex = -r3;
            t2.edges[c0] = -0.5 * r3;
            t2.edges[c1] = -0.5 * r3;
            t2.edges[c0 + 1] = r3;
            t2.edges[c0 + 2] = r3;
        }
        k => {
            let theta = PI / (k + 1) as f64;
            let cw = -3.0 * theta.sin();
            let ecoef = -3.0 * (2.0 * theta.cos() - 2.0);
            t2.edges[c0] = cw;
            t2.edges[c1] = cw;
            for i in 1..=k {
                t2.edges[c0 + i] = ecoef * (i as f64 * theta).sin();
            }
        }
    }
}

fn catmark_crease_tangents(hood: &Neighborhood, t1: &mut Mask, t2: &mut Mask) {
    let (n, nf) = (hood.num_edges, hood.num_faces);
    let [c0, c1] = hood.crease_ends;
    t1.reset(n, nf, FaceWeights::Opposite);
    t1.edges[c0] = 0.5;
    t1.edges[c1] = -0.5;
    t2.reset(n, nf, FaceWeights::Opposite);
    let interior = c1 - c0 - 1;
    match interior {
        0 => {
            t2.vertex = -6.0;
            t2.edges[c0] = 3.0;
            t2.edges[c1] = 3.0;
        }
        1 => {
            // Regular boundary: the uniform B-spline cross tangent.
            t2.vertex = -4.0 / 6.0;
            t2.edges[c0] = -1.0 / 6.0;
            t2.edges[c0 + 1] = 4.0 / 6.0;
            t2.edges[c1] = -1.0 / 6.0;
            t2.faces[c0] = 1.0 / 6.0;
            t2.faces[c0 + 1] = 1.0 / 6.0;
        }
        _ => {
            // Biermann et al. 2000, as OpenSubdiv.
            let k = (interior + 1) as f64;
            let theta = PI / k;
            let (ct, st) = (theta.cos(), theta.sin());
            let denom = 1.0 / (k * (3.0 + ct));
            let r = (ct + 1.0) / st;
            t2.vertex = 4.0 * r * (ct - 1.0) * denom;
            let cw = -r * (1.0 + 2.0 * ct) * denom;
            t2.edges[c0] = cw;
            t2.edges[c1] = cw;
            t2.faces[c0] = st * denom;
            let mut s_next = st;
            for i in 1..=interior {
                let s_i = s_next;
                s_next = ((i + 1) as f64 * theta).sin();
                t2.edges[c0 + i] = 4.0 * s_i * denom;
                t2.faces[c0 + i] = (s_i + s_next) * denom;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hood(n: usize, nf: usize, rule: VertexRule, ends: [usize; 2]) -> Neighborhood {
        Neighborhood {
            num_edges: n,
            num_faces: nf,
            rule,
            crease_ends: ends,
            faces: FaceKinds::Triangles,
        }
    }

    #[test]
    fn masks_sum_to_one_and_tangents_to_zero() {
        let mut m = Mask::default();
        let (mut p, mut a, mut b) = (Mask::default(), Mask::default(), Mask::default());
        for scheme in [Scheme::Loop, Scheme::CatmullClark] {
            for n in 3..12 {
                let hs = [
                    hood(n, n, VertexRule::Smooth, [0, 0]),
                    hood(n, n - 1, VertexRule::Crease, [0, n - 1]),
                    hood(n, n, VertexRule::Crease, [1, n - 1]),
                    hood(n, n, VertexRule::Corner, [0, 0]),
                ];
                for h in &hs {
                    scheme.vertex_point_mask(h, &mut m);
                    assert!((m.sum() - 1.0).abs() < 1e-14);
                    scheme.limit_masks(h, &mut p, &mut a, &mut b);
                    assert!((p.sum() - 1.0).abs() < 1e-14);
                    assert!(a.sum().abs() < 1e-13 && b.sum().abs() < 1e-13, "{h:?}");
                }
            }
        }
        assert_eq!(loop_beta(6), 1.0 / 16.0);
        assert!((loop_beta(3) - 3.0 / 16.0).abs() < 1e-15);
    }
}
