//! Generated meshes (and a minimal OFF/OBJ reader for the shared data) used by the tests and
//! the benchmark.
#![allow(dead_code)]

use subfit_mesh::{HalfEdgeId, HalfEdgeMesh, Polygons, VertexId};

/// A grid of `n × m` quads (or `2nm` triangles), optionally periodic in `i` and/or `j`.
/// Periodic directions need at least 3 cells. Returns `(faces, #V)`.
pub fn grid(n: u32, m: u32, wrap_i: bool, wrap_j: bool, triangles: bool) -> (Polygons, usize) {
    let ni = if wrap_i { n } else { n + 1 };
    let nj = if wrap_j { m } else { m + 1 };
    let v = |i: u32, j: u32| (i % ni) * nj + (j % nj);
    let mut p = Polygons::with_capacity((n * m * 2) as usize, (n * m * 6) as usize);
    for i in 0..n {
        for j in 0..m {
            let q = [v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)];
            if triangles {
                p.push(&[q[0], q[1], q[2]]);
                p.push(&[q[0], q[2], q[3]]);
            } else {
                p.push(&q);
            }
        }
    }
    (p, (ni * nj) as usize)
}

/// A torus grid (genus 1).
pub fn torus(n: u32, m: u32, triangles: bool) -> (Polygons, usize) {
    grid(n, m, true, true, triangles)
}

/// A UV sphere: `n ≥ 3` vertices around, `rings ≥ 1` rings, two poles (genus 0).
pub fn uv_sphere(n: u32, rings: u32, triangles: bool) -> (Polygons, usize) {
    let v = |r: u32, k: u32| 2 + r * n + (k % n);
    let mut p = Polygons::new();
    for k in 0..n {
        p.push(&[0, v(0, k + 1), v(0, k)]);
        p.push(&[1, v(rings - 1, k), v(rings - 1, k + 1)]);
    }
    for r in 0..rings - 1 {
        for k in 0..n {
            let q = [v(r, k), v(r, k + 1), v(r + 1, k + 1), v(r + 1, k)];
            if triangles {
                p.push(&[q[0], q[1], q[2]]);
                p.push(&[q[0], q[2], q[3]]);
            } else {
                p.push(&q);
            }
        }
    }
    (p, (2 + n * rings) as usize)
}

/// A genus-2 surface: two `n × n` quad tori, each without quad (0, 0), glued along the hole
/// (the second torus is reversed so the orientations agree).
pub fn double_torus(n: u32) -> (Polygons, usize) {
    let (a, nv) = torus(n, n, false);
    let nv = nv as u32;
    let hole: Vec<u32> = a.face(subfit_mesh::FaceId(0)).to_vec();
    let map = |v: u32| if hole.contains(&v) { v } else { v + nv };
    let mut p = Polygons::new();
    for f in a.iter().skip(1) {
        p.push(f);
    }
    for f in a.iter().skip(1) {
        let g: Vec<u32> = f.iter().rev().map(|&v| map(v)).collect();
        p.push(&g);
    }
    (p, 2 * nv as usize)
}

/// A Möbius strip of `n ≥ 3` quads (non-orientable, one boundary loop).
pub fn moebius(n: u32) -> (Polygons, usize) {
    // Column `n` is column 0 turned over.
    let v = |i: u32, j: u32| if i == n { 1 - j } else { 2 * i + j };
    let mut p = Polygons::new();
    for i in 0..n {
        p.push(&[v(i, 0), v(i + 1, 0), v(i + 1, 1), v(i, 1)]);
    }
    (p, (2 * n) as usize)
}

/// The regular tetrahedron's faces (4 vertices), outward.
pub fn tetrahedron() -> (Polygons, usize) {
    (
        Polygons::from_triangles(&[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
        4,
    )
}

/// The unit cube as 6 quads (8 vertices, vertex `x + 2y + 4z`), outward, with positions.
pub fn cube() -> (Polygons, Vec<[f64; 3]>) {
    let faces = Polygons::from_quads(&[
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ]);
    let pos = (0..8)
        .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
        .collect();
    (faces, pos)
}

/// The icosahedron (12 vertices, 20 faces), outward, with positions (on the unit sphere).
pub fn icosahedron() -> (Polygons, Vec<[f64; 3]>) {
    let m = subfit_mesh::shapes::geodesic_sphere(0);
    (m.faces, m.positions)
}

/// Reads vertices and faces of an OFF or OBJ file (only what the shared data uses: OFF with
/// polygon faces; OBJ `v` and `f` lines with 1-based or negative indices). Test-only.
pub fn read_simple(path: &std::path::Path) -> Option<(Polygons, usize)> {
    let text = std::fs::read_to_string(path).ok()?;
    let ext = path.extension()?.to_str()?;
    let mut p = Polygons::new();
    match ext {
        "off" => {
            let mut toks = text
                .lines()
                .map(|l| l.split('#').next().unwrap_or(""))
                .flat_map(str::split_whitespace);
            if toks.next()? != "OFF" {
                return None;
            }
            let nv: usize = toks.next()?.parse().ok()?;
            let nf: usize = toks.next()?.parse().ok()?;
            toks.next()?;
            for _ in 0..3 * nv {
                toks.next()?;
            }
            let mut face = Vec::new();
            for _ in 0..nf {
                let k: usize = toks.next()?.parse().ok()?;
                face.clear();
                for _ in 0..k {
                    face.push(toks.next()?.parse().ok()?);
                }
                p.push(&face);
            }
            Some((p, nv))
        }
        "obj" => {
            let mut nv = 0usize;
            let mut face = Vec::new();
            for line in text.lines() {
                let mut it = line.split_whitespace();
                match it.next() {
                    Some("v") => nv += 1,
                    Some("f") => {
                        face.clear();
                        for t in it {
                            let i: i64 = t.split('/').next()?.parse().ok()?;
                            let i = if i < 0 { nv as i64 + i } else { i - 1 };
                            face.push(i as u32);
                        }
                        p.push(&face);
                    }
                    _ => {}
                }
            }
            Some((p, nv))
        }
        _ => None,
    }
}

/// Builds the half-edge view (it must succeed) and checks its invariants.
pub fn check_invariants(faces: &Polygons, nv: usize) -> HalfEdgeMesh {
    let m = HalfEdgeMesh::new(faces, nv).expect("valid mesh");
    check_mesh(&m, faces, nv);
    m
}

/// Checks the half-edge invariants and that navigation agrees with the face list.
pub fn check_mesh(m: &HalfEdgeMesh, faces: &Polygons, nv: usize) {
    assert_eq!(m.num_faces(), faces.len());
    assert_eq!(m.num_half_edges(), faces.indices().len());
    for h in (0..m.num_half_edges() as u32).map(HalfEdgeId) {
        assert_eq!(m.next(m.prev(h)), h);
        assert_eq!(m.prev(m.next(h)), h);
        assert_eq!(m.face(m.next(h)), m.face(h));
        if let Some(t) = m.twin(h) {
            assert_eq!(m.twin(t), Some(h));
            assert_eq!(m.origin(t), m.dest(h));
            assert_eq!(m.edge(t), m.edge(h));
        }
        let [a, b] = m.edge_vertices(m.edge(h));
        assert!((a, b) == (m.origin(h), m.dest(h)) || (b, a) == (m.origin(h), m.dest(h)));
    }
    let mut valence_sum = 0;
    let mut faces_sum = 0;
    for v in (0..nv as u32).map(VertexId) {
        let ring: Vec<_> = m.vertex_neighbors(v).collect();
        let fs: Vec<_> = m.vertex_faces(v).collect();
        assert_eq!(ring.len(), m.valence(v));
        valence_sum += ring.len();
        faces_sum += fs.len();
        if m.vertex_half_edge(v).is_none() {
            assert!(ring.is_empty());
            continue;
        }
        assert_eq!(ring.len(), fs.len() + usize::from(m.is_boundary_vertex(v)));
        // Face i of the fan holds v → ring[i] and ring[i+1] → v in its winding order.
        for (i, h) in m.outgoing(v).enumerate() {
            assert_eq!(m.origin(h), v);
            assert_eq!(m.face(h), fs[i]);
            assert_eq!(m.dest(h), ring[i]);
            assert_eq!(m.origin(m.prev(h)), ring[(i + 1) % ring.len()]);
        }
        let distinct: std::collections::BTreeSet<_> = ring.iter().collect();
        assert_eq!(
            distinct.len(),
            ring.len(),
            "one-ring of {v} repeats a vertex"
        );
    }
    assert_eq!(valence_sum, 2 * m.num_edges());
    assert_eq!(faces_sum, m.num_half_edges());
    let mut boundary = 0;
    for lp in m.boundary_loops() {
        for i in 0..lp.len() {
            let h = m
                .find_half_edge(lp[i], lp[(i + 1) % lp.len()])
                .expect("loop edge");
            assert!(m.is_boundary_half_edge(h));
            assert!(m.is_boundary_vertex(lp[i]));
        }
        boundary += lp.len();
    }
    assert_eq!(boundary, m.num_boundary_edges());
}
