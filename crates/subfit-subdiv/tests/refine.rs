//! Invariants of refinement and limit stencils over a small corpus of meshes: partition of unity,
//! plane reproduction, scale invariance, Euler characteristic, nested limits, typed errors.

use proptest::prelude::*;
use subfit_mesh::{Polygons, Tags, SHARPNESS_INFINITE};
use subfit_subdiv::{
    limit_stencils, refine, sampling_operator, BoundaryRule, Options, Scheme, SubdivError, Topology,
};

/// A torus grid of `n × m` quads (or `2nm` triangles), radii 1 and 0.4, with a few vertices
/// perturbed; valence 4 (6) everywhere unless `twist` adds extraordinary vertices by splitting
/// some quads differently.
fn torus(n: usize, m: usize, tris: bool) -> (Vec<[f64; 3]>, Polygons) {
    let mut pts = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (u, v) = (
                std::f64::consts::TAU * i as f64 / n as f64,
                std::f64::consts::TAU * j as f64 / m as f64,
            );
            let r = 1.0 + 0.4 * v.cos();
            pts.push([
                r * u.cos(),
                r * u.sin(),
                0.4 * v.sin() + 0.01 * ((i * j) % 3) as f64,
            ]);
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    let mut faces = Polygons::new();
    for i in 0..n {
        for j in 0..m {
            let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            if tris {
                // Alternate diagonals so valences 5, 6, 7 occur.
                if (i + j) % 3 == 0 {
                    faces.push(&[q[0], q[1], q[3]]);
                    faces.push(&[q[1], q[2], q[3]]);
                } else {
                    faces.push(&[q[0], q[1], q[2]]);
                    faces.push(&[q[0], q[2], q[3]]);
                }
            } else {
                faces.push(&q);
            }
        }
    }
    (pts, faces)
}

/// An open `n × n` grid on the plane z = 0 (quads or triangles), positions jittered in-plane.
fn grid(n: usize, tris: bool) -> (Vec<[f64; 3]>, Polygons) {
    let mut pts = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            let jit = 0.1 * (((i * 7 + j * 13) % 5) as f64 - 2.0) / 2.0;
            pts.push([i as f64 + jit, j as f64 - 0.5 * jit, 0.0]);
        }
    }
    let id = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    let mut faces = Polygons::new();
    for i in 0..n {
        for j in 0..n {
            let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            if tris {
                faces.push(&[q[0], q[1], q[2]]);
                faces.push(&[q[0], q[2], q[3]]);
            } else {
                faces.push(&q);
            }
        }
    }
    (pts, faces)
}

/// A hexagonal prism: two hexagons and six quads (Catmull-Clark with n-gons).
fn prism() -> (Vec<[f64; 3]>, Polygons) {
    let mut pts = Vec::new();
    for z in [0.0, 1.5] {
        for k in 0..6 {
            let a = std::f64::consts::TAU * k as f64 / 6.0;
            pts.push([a.cos(), a.sin(), z]);
        }
    }
    let mut faces = Polygons::new();
    faces.push(&[5, 4, 3, 2, 1, 0]);
    faces.push(&[6, 7, 8, 9, 10, 11]);
    for k in 0..6u32 {
        let k1 = (k + 1) % 6;
        faces.push(&[k, k1, k1 + 6, k + 6]);
    }
    (pts, faces)
}

/// A named test mesh: scheme, positions, faces, tags.
type Case = (&'static str, Scheme, Vec<[f64; 3]>, Polygons, Tags);

fn corpus() -> Vec<Case> {
    let (tp, tf) = torus(6, 5, true);
    let (qp, qf) = torus(6, 5, false);
    let (gp, gf) = grid(4, true);
    let (hp, hf) = grid(4, false);
    let (pp, pf) = prism();
    let mut creased = Tags::new();
    creased.set_crease(0, 1, SHARPNESS_INFINITE);
    creased.set_crease(1, 2, SHARPNESS_INFINITE);
    creased.set_crease(2, 3, SHARPNESS_INFINITE);
    creased.set_corner(8, SHARPNESS_INFINITE);
    let mut prism_tags = Tags::new();
    for k in 0..6 {
        prism_tags.set_crease(k, (k + 1) % 6, SHARPNESS_INFINITE);
    }
    vec![
        (
            "tri torus",
            Scheme::Loop,
            tp.clone(),
            tf.clone(),
            Tags::new(),
        ),
        ("tri torus creased", Scheme::Loop, tp, tf, creased.clone()),
        (
            "quad torus",
            Scheme::CatmullClark,
            qp.clone(),
            qf.clone(),
            Tags::new(),
        ),
        ("quad torus creased", Scheme::CatmullClark, qp, qf, creased),
        ("tri grid", Scheme::Loop, gp, gf, Tags::new()),
        ("quad grid", Scheme::CatmullClark, hp, hf, Tags::new()),
        (
            "prism",
            Scheme::CatmullClark,
            pp.clone(),
            pf.clone(),
            Tags::new(),
        ),
        ("prism creased", Scheme::CatmullClark, pp, pf, prism_tags),
    ]
}

fn check_sums(m: &subfit_subdiv::StencilMatrix, expect: f64, what: &str) {
    for (i, s) in m.row_sums().into_iter().enumerate() {
        let (_, w) = m.row(i);
        let scale = w.iter().fold(1.0f64, |a, x| a.max(x.abs()));
        assert!(
            (s - expect).abs() <= 1e-14 * scale * w.len() as f64,
            "{what}: row {i} sums to {s}"
        );
    }
}

#[test]
fn stencil_rows_sum_to_one_and_tangent_rows_to_zero() {
    for (name, scheme, pts, faces, tags) in corpus() {
        for boundary in [BoundaryRule::EdgeOnly, BoundaryRule::EdgeAndCorner] {
            let o = Options::new(scheme).with_boundary(boundary);
            let r = refine(&faces, pts.len(), &tags, &o).unwrap();
            check_sums(&r.matrix, 1.0, name);
            for level in 0..3 {
                let s = sampling_operator(&faces, pts.len(), &tags, &o, level).unwrap();
                assert_eq!(s.position.nrows(), s.num_vertices);
                assert_eq!(s.position.ncols(), pts.len());
                check_sums(&s.position, 1.0, name);
                check_sums(&s.tangent1, 0.0, name);
                check_sums(&s.tangent2, 0.0, name);
            }
        }
    }
}

/// `|a - b| <= tol` entry by entry, with the matrices' sparsity patterns allowed to differ by
/// entries below `tol`.
fn assert_same_matrix(
    a: &subfit_subdiv::StencilMatrix,
    b: &subfit_subdiv::StencilMatrix,
    tol: f64,
    what: &str,
) {
    assert_eq!(
        (a.nrows(), a.ncols()),
        (b.nrows(), b.ncols()),
        "{what}: shapes"
    );
    let mut dense = vec![0.0f64; a.ncols()];
    for i in 0..a.nrows() {
        let (ca, wa) = a.row(i);
        let (cb, wb) = b.row(i);
        for (&c, &w) in ca.iter().zip(wa) {
            dense[c as usize] += w;
        }
        for (&c, &w) in cb.iter().zip(wb) {
            dense[c as usize] -= w;
        }
        for &c in ca.iter().chain(cb) {
            let d = std::mem::take(&mut dense[c as usize]);
            assert!(d.abs() <= tol, "{what}: row {i} column {c} differs by {d}");
        }
    }
}

/// The sampling operator (built with fused, parallel refinement products, Catmull-Clark face
/// points reused as rows, and the last level's limit and refinement rows fused and read off the
/// level below) equals the plain product of the public pieces: the limit stencils of the
/// level-`l` mesh times `M_l ⋯ M_1` from [`refine`], with the same level-`l` faces; under both
/// boundary rules.
#[test]
fn sampling_operator_equals_the_product_of_refinement_matrices() {
    let rules = [BoundaryRule::EdgeOnly, BoundaryRule::EdgeAndCorner];
    for ((name, scheme, pts, faces, tags), boundary) in corpus()
        .into_iter()
        .flat_map(|c| rules.map(|r| (c.clone(), r)))
    {
        let o = Options::new(scheme).with_boundary(boundary);
        let (mut f, mut nv, mut t) = (faces.clone(), pts.len(), tags.clone());
        let mut product = subfit_subdiv::StencilMatrix::identity(pts.len());
        for level in 1..=3 {
            let r = refine(&f, nv, &t, &o).unwrap();
            product = r.matrix.compose(&product);
            (f, nv, t) = (r.faces, r.num_vertices, r.tags);
            let s = sampling_operator(&faces, pts.len(), &tags, &o, level).unwrap();
            assert_eq!(s.faces, f, "{name}: level {level} faces");
            assert_eq!(s.num_vertices, nv, "{name}: level {level} vertex count");
            let l = limit_stencils(&f, nv, &t, &o).unwrap();
            let what = format!("{name} {boundary:?} level {level}");
            assert_same_matrix(&s.position, &l.position.compose(&product), 1e-14, &what);
            assert_same_matrix(&s.tangent1, &l.tangent1.compose(&product), 1e-13, &what);
            assert_same_matrix(&s.tangent2, &l.tangent2.compose(&product), 1e-13, &what);
        }
    }
}

#[test]
fn planar_control_mesh_gives_planar_limit_with_winding_normals() {
    // Tilt the planar grids into the plane n·x = 0.3 with n = (1, 2, 2)/3.
    let rot = |p: [f64; 3]| {
        let (e1, e2, n) = ([2.0, -1.0, 0.0], [2.0, 4.0, -5.0], [1.0, 2.0, 2.0]);
        let l1 = 5f64.sqrt();
        let l2 = 45f64.sqrt();
        let mut q = [0.0; 3];
        for k in 0..3 {
            q[k] = p[0] * e1[k] / l1 + p[1] * e2[k] / l2 + 0.3 * n[k] / 3.0;
        }
        q
    };
    for (tris, scheme) in [(true, Scheme::Loop), (false, Scheme::CatmullClark)] {
        let (pts, faces) = grid(5, tris);
        let pts: Vec<_> = pts.into_iter().map(rot).collect();
        // The grid winds counter-clockwise in (x, y), so the front side is +e1 × e2 ∝ +n.
        let n = [1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0];
        for boundary in [BoundaryRule::EdgeOnly, BoundaryRule::EdgeAndCorner] {
            let o = Options::new(scheme).with_boundary(boundary);
            for level in 0..3 {
                let s = sampling_operator(&faces, pts.len(), &Tags::new(), &o, level)
                    .unwrap()
                    .evaluate(&pts);
                for (p, nn) in s.positions.iter().zip(&s.normals) {
                    let d: f64 = (0..3).map(|k| p[k] * n[k]).sum::<f64>() - 0.3;
                    assert!(d.abs() < 1e-13, "{scheme:?} L{level}: off-plane by {d}");
                    let c: f64 = (0..3).map(|k| nn[k] * n[k]).sum();
                    assert!(
                        (c - 1.0).abs() < 1e-12,
                        "{scheme:?} L{level}: normal {nn:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn limits_are_invariant_under_scaling() {
    for (name, scheme, pts, faces, tags) in corpus() {
        let o = Options::new(scheme);
        let op = sampling_operator(&faces, pts.len(), &tags, &o, 2).unwrap();
        let base = op.evaluate(&pts);
        for s in [1e-6, 1e6] {
            let scaled: Vec<_> = pts.iter().map(|p| p.map(|x| x * s)).collect();
            let r = op.evaluate(&scaled);
            for (a, b) in base.positions.iter().zip(&r.positions) {
                for k in 0..3 {
                    assert!((a[k] * s - b[k]).abs() <= 1e-14 * s * 4.0, "{name}");
                }
            }
            for (a, b) in base.normals.iter().zip(&r.normals) {
                for k in 0..3 {
                    assert!((a[k] - b[k]).abs() <= 1e-13, "{name}");
                }
            }
        }
    }
}

fn euler(faces: &Polygons, nv: usize) -> i64 {
    let t = Topology::new(faces, nv).unwrap();
    nv as i64 - t.num_edges() as i64 + t.num_faces() as i64
}

#[test]
fn refinement_preserves_euler_characteristic_and_nests_vertices() {
    for (name, scheme, pts, faces, tags) in corpus() {
        let o = Options::new(scheme);
        let chi = euler(&faces, pts.len());
        let (mut f, mut nv, mut t) = (faces.clone(), pts.len(), tags.clone());
        for _ in 0..3 {
            let r = refine(&f, nv, &t, &o).unwrap();
            assert_eq!(r.matrix.ncols(), nv);
            assert_eq!(r.matrix.nrows(), r.num_vertices);
            assert_eq!(r.faces.min_vertex_count(), r.num_vertices, "{name}");
            assert_eq!(euler(&r.faces, r.num_vertices), chi, "{name}");
            (f, nv, t) = (r.faces, r.num_vertices, r.tags);
        }
        assert_eq!(t.creases().len(), tags.creases().len() * 8, "{name}");
    }
}

/// The limit of a vertex does not depend on the level it is computed from: rows `v < #V_l` of
/// `C_{l+1}` equal the rows of `C_l` (child vertex `v` is the vertex point of `v`).
///
/// Where this is exact: positions everywhere except at darts (one sharp edge; the smooth mask
/// is used there, as in OpenSubdiv); normals at vertices without sharp edges or corner tags
/// (crease, boundary and corner tangents are OpenSubdiv's formulas, approximate at irregular
/// creases and corners).
fn assert_nested(pts: &[[f64; 3]], faces: &Polygons, tags: &Tags, o: &Options) {
    let op = sampling_operator(faces, pts.len(), tags, o, 1).unwrap();
    let a = op.evaluate(pts);
    let b = sampling_operator(faces, pts.len(), tags, o, 2)
        .unwrap()
        .evaluate(pts);
    let topo = Topology::new(&op.faces, op.num_vertices).unwrap();
    let scale = 1.0 + pts.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    for v in 0..a.positions.len() {
        let vu = v as u32;
        let ring = topo.vertex_ring(vu);
        let nsharp = ring
            .iter()
            .filter(|&&u| op.tags.is_sharp_edge(vu, u))
            .count();
        let dart = nsharp == 1 && !topo.is_boundary_vertex(vu);
        let plain = nsharp == 0 && !op.tags.is_corner(vu);
        for k in 0..3 {
            let dp = (a.positions[v][k] - b.positions[v][k]).abs();
            assert!(
                dart || dp < 1e-13 * scale,
                "vertex {v}: position differs by {dp}"
            );
            let dn = (a.normals[v][k] - b.normals[v][k]).abs();
            assert!(!plain || dn < 1e-10, "vertex {v}: normal differs by {dn}");
        }
    }
}

#[test]
fn limits_are_nested_across_levels() {
    for (_, scheme, pts, faces, tags) in corpus() {
        for boundary in [BoundaryRule::EdgeOnly, BoundaryRule::EdgeAndCorner] {
            assert_nested(
                &pts,
                &faces,
                &tags,
                &Options::new(scheme).with_boundary(boundary),
            );
        }
    }
}

#[test]
fn corners_and_creases_interpolate_as_documented() {
    let (pts, faces) = grid(4, false);
    let o = Options::new(Scheme::CatmullClark).with_boundary(BoundaryRule::EdgeAndCorner);
    let l = limit_stencils(&faces, pts.len(), &Tags::new(), &o).unwrap();
    let p = l.position.apply(&pts);
    assert_eq!(p[0], pts[0]); // a valence-2 boundary vertex is a corner
    let o = Options::new(Scheme::CatmullClark);
    let p = limit_stencils(&faces, pts.len(), &Tags::new(), &o)
        .unwrap()
        .position
        .apply(&pts);
    for k in 0..3 {
        let spline = (pts[1][k] + 4.0 * pts[0][k] + pts[5][k]) / 6.0;
        assert!((p[0][k] - spline).abs() < 1e-15);
    }
    let mut tags = Tags::new();
    tags.set_corner(12, SHARPNESS_INFINITE);
    let p = limit_stencils(&faces, pts.len(), &tags, &o)
        .unwrap()
        .position
        .apply(&pts);
    assert_eq!(p[12], pts[12]);
}

#[test]
fn bad_topology_is_a_typed_error() {
    let o = Options::new(Scheme::Loop);
    let quads = Polygons::from_quads(&[[0, 1, 2, 3]]);
    assert_eq!(
        refine(&quads, 4, &Tags::new(), &o).unwrap_err(),
        SubdivError::NotTriangles { face: 0, len: 4 }
    );
    let fin = Polygons::from_triangles(&[[0, 1, 2], [0, 1, 3], [1, 0, 4]]);
    assert!(matches!(
        refine(&fin, 5, &Tags::new(), &o),
        Err(SubdivError::NonManifoldEdge { .. })
    ));
    let out = Polygons::from_triangles(&[[0, 1, 7]]);
    assert!(matches!(
        refine(&out, 3, &Tags::new(), &o),
        Err(SubdivError::VertexOutOfRange { vertex: 7, .. })
    ));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// Random positions and random sharp tags on a torus: rows still sum to 1/0 and limits nest.
    #[test]
    fn random_tags_and_positions(
        seed_pts in proptest::collection::vec(-1.0f64..1.0, 90),
        creases in proptest::collection::vec((0u32..30, 0usize..4), 0..8),
        corners in proptest::collection::vec(0u32..30, 0..3),
        tris in any::<bool>(),
    ) {
        let (mut pts, faces) = torus(6, 5, tris);
        for (p, d) in pts.iter_mut().zip(seed_pts.chunks(3)) {
            for k in 0..3 { p[k] += 0.2 * d[k]; }
        }
        let topo = Topology::new(&faces, pts.len()).unwrap();
        let mut tags = Tags::new();
        for (v, i) in creases {
            let ring = topo.vertex_ring(v);
            tags.set_crease(v, ring[i % ring.len()], SHARPNESS_INFINITE);
        }
        for v in corners { tags.set_corner(v, SHARPNESS_INFINITE); }
        let scheme = if tris { Scheme::Loop } else { Scheme::CatmullClark };
        let o = Options::new(scheme);
        let s = sampling_operator(&faces, pts.len(), &tags, &o, 1).unwrap();
        check_sums(&s.position, 1.0, "random");
        check_sums(&s.tangent1, 0.0, "random");
        check_sums(&s.tangent2, 0.0, "random");
        assert_nested(&pts, &faces, &tags, &o);
    }
}
