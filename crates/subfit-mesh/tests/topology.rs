//! Half-edge construction, navigation and diagnostics on a corpus of generated meshes.

mod common;

use common::*;
use subfit_mesh::{
    diagnose, face_components, EdgeId, FaceId, HalfEdgeMesh, MeshReport, Polygons, Tags,
    TopologyError, VertexId, SHARPNESS_INFINITE,
};

/// Checks that the diagnostics agree with the half-edge view on a valid mesh.
fn check_report(faces: &Polygons, nv: usize, genus: u32, loops: usize) -> MeshReport {
    let m = check_invariants(faces, nv);
    let r = diagnose(faces, nv, None);
    assert_eq!(r.num_edges, m.num_edges());
    assert_eq!(r.boundary_edges, m.num_boundary_edges());
    assert_eq!(r.boundary_loops, loops);
    assert_eq!(m.boundary_loops().len(), loops);
    assert_eq!(r.euler_characteristic, m.euler_characteristic());
    assert_eq!(r.genus, Some(genus));
    assert_eq!(m.genus(), genus);
    assert!(r.is_manifold && r.is_consistently_oriented);
    assert_eq!(r.is_closed, loops == 0);
    assert_eq!(
        r.non_manifold_edges + r.non_manifold_vertices + r.inconsistent_edges,
        0
    );
    assert_eq!(
        r.duplicate_faces + r.degenerate_faces + r.out_of_range_faces,
        0
    );
    assert_eq!(r.num_components, m.components().count);
    r
}

#[test]
fn tetrahedron_cube_icosahedron() {
    let (t, nv) = tetrahedron();
    let r = check_report(&t, nv, 0, 0);
    assert_eq!((r.num_edges, r.euler_characteristic), (6, 2));

    let (c, pos) = cube();
    let r = check_report(&c, pos.len(), 0, 0);
    assert_eq!(r.num_edges, 12);
    assert_eq!(r.face_sizes, vec![(4, 6)]);
    assert_eq!(diagnose(&c, 8, Some(&pos)).zero_area_faces, Some(0));

    let (ico, pos) = icosahedron();
    let r = check_report(&ico, pos.len(), 0, 0);
    assert_eq!(r.num_edges, 30);
    let m = HalfEdgeMesh::new(&ico, 12).unwrap();
    assert!((0..12).all(|v| m.valence(VertexId(v)) == 5));
    // Geometric check of the winding: every face normal points away from the centre.
    for f in ico.iter() {
        let [a, b, c] = [pos[f[0] as usize], pos[f[1] as usize], pos[f[2] as usize]];
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        assert!(n[0] * a[0] + n[1] * a[1] + n[2] * a[2] > 0.0);
    }
}

#[test]
fn tori_spheres_and_double_torus() {
    for tri in [false, true] {
        let (p, nv) = torus(5, 7, tri);
        let r = check_report(&p, nv, 1, 0);
        assert_eq!(r.euler_characteristic, 0);
        let (p, nv) = uv_sphere(6, 4, tri);
        check_report(&p, nv, 0, 0);
    }
    let (p, nv) = double_torus(4);
    let r = check_report(&p, nv, 2, 0);
    assert_eq!(r.euler_characteristic, -2);
    assert_eq!(r.unreferenced_vertices, 4);
}

#[test]
fn disk_and_annulus() {
    let (p, nv) = grid(4, 3, false, false, false);
    let r = check_report(&p, nv, 0, 1);
    assert_eq!(r.boundary_edges, 14);
    let m = HalfEdgeMesh::new(&p, nv).unwrap();
    let loops = m.boundary_loops();
    assert_eq!(loops[0].len(), 14);
    // Corner vertex 0: two neighbours, one face; interior vertex: valence 4.
    assert_eq!(m.valence(VertexId(0)), 2);
    assert_eq!(m.vertex_face_count(VertexId(0)), 1);
    assert!(m.is_boundary_vertex(VertexId(0)));
    assert!(!m.is_boundary_vertex(VertexId(5)));
    assert_eq!(m.valence(VertexId(5)), 4);

    let (p, nv) = grid(6, 2, true, false, true);
    let r = check_report(&p, nv, 0, 2);
    assert_eq!(r.euler_characteristic, 0);
    assert_eq!(r.components[0].boundary_loops, 2);
}

#[test]
fn edges_faces_and_tags() {
    let (p, nv) = grid(2, 1, false, false, false);
    let m = HalfEdgeMesh::new(&p, nv).unwrap();
    // Vertices (i, j) → 2i + j; the shared edge is 2–3.
    let e = m.find_edge(VertexId(2), VertexId(3)).unwrap();
    assert!(!m.is_boundary_edge(e));
    let (f0, f1) = m.edge_faces(e);
    assert_eq!((f0, f1), (FaceId(0), Some(FaceId(1))));
    let b = m.find_edge(VertexId(0), VertexId(1)).unwrap();
    assert!(m.is_boundary_edge(b));
    assert_eq!(m.edge_faces(b).1, None);
    assert_eq!(
        m.face_neighbors(FaceId(0)).flatten().collect::<Vec<_>>(),
        [FaceId(1)]
    );
    let mut tags = Tags::new();
    tags.set_crease(3, 2, SHARPNESS_INFINITE);
    tags.set_corner(0, 2.0);
    assert_eq!(m.edge_sharpness(e, &tags), SHARPNESS_INFINITE);
    let s = m.edge_sharpness_array(&tags);
    assert_eq!(s.iter().filter(|&&x| x > 0.0).count(), 1);
    assert_eq!(s[e.idx()], SHARPNESS_INFINITE);
    assert_eq!(m.vertex_sharpness(VertexId(0), &tags), 2.0);
    assert_eq!(m.edge_sharpness(EdgeId(0), &Tags::new()), 0.0);
}

#[test]
fn bowtie_vertex() {
    let p = Polygons::from_triangles(&[[0, 1, 2], [0, 3, 4]]);
    let r = diagnose(&p, 5, None);
    assert_eq!(r.non_manifold_vertices, 1);
    assert_eq!(r.examples.non_manifold_vertices, vec![0]);
    assert_eq!(r.non_manifold_edges, 0);
    assert_eq!(r.num_components, 1);
    assert_eq!(r.boundary_loops, 0);
    assert_eq!(r.untraced_boundary_components, 1);
    assert!(!r.is_manifold);
    assert_eq!(r.genus, None);
    assert!(matches!(
        HalfEdgeMesh::new(&p, 5),
        Err(TopologyError::NonManifoldVertex {
            vertex: VertexId(0),
            fan: 1,
            total: 2
        })
    ));
    // Two cones touching at their apex: closed fans, still non-manifold.
    let (mut q, nv) = uv_sphere(4, 2, true);
    let n = nv as u32;
    for f in uv_sphere(4, 2, true).0.iter() {
        let g: Vec<u32> = f.iter().map(|&v| if v == 0 { 0 } else { v + n }).collect();
        q.push(&g);
    }
    let r = diagnose(&q, 2 * nv, None);
    assert_eq!(r.non_manifold_vertices, 1);
    assert_eq!(r.unreferenced_vertices, 1);
    assert!(HalfEdgeMesh::new(&q, 2 * nv).is_err());
}

#[test]
fn three_faces_on_an_edge() {
    let p = Polygons::from_triangles(&[[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
    let r = diagnose(&p, 5, None);
    assert_eq!(r.non_manifold_edges, 1);
    assert_eq!(r.examples.non_manifold_edges, vec![[0, 1]]);
    assert_eq!(r.non_manifold_vertices, 0);
    assert_eq!(r.boundary_edges, 6);
    assert_eq!(r.genus, None);
    assert!(!r.is_manifold && !r.is_consistently_oriented);
    let err = HalfEdgeMesh::new(&p, 5).unwrap_err();
    assert_eq!(
        err,
        TopologyError::NonManifoldEdge {
            a: VertexId(0),
            b: VertexId(1),
            count: 3,
            f0: FaceId(0),
            f1: FaceId(1)
        }
    );
    assert!(err.to_string().contains("edge 0-1"));
}

#[test]
fn flipped_face_and_moebius() {
    let (mut ico, _) = icosahedron();
    ico.indices_mut()[..3].reverse();
    let r = diagnose(&ico, 12, None);
    assert_eq!(r.inconsistent_edges, 3);
    assert!(!r.is_consistently_oriented && r.is_manifold);
    assert!(r.components[0].orientable);
    assert_eq!(r.genus, Some(0));
    assert!(matches!(
        HalfEdgeMesh::new(&ico, 12),
        Err(TopologyError::InconsistentOrientation { .. })
    ));

    let (p, nv) = moebius(5);
    let r = diagnose(&p, nv, None);
    assert_eq!(r.boundary_loops, 1);
    assert_eq!(r.euler_characteristic, 0);
    assert!(!r.components[0].orientable);
    assert_eq!(r.genus, None);
    assert!(HalfEdgeMesh::new(&p, nv).is_err());
}

#[test]
fn duplicate_and_unreferenced() {
    let (mut t, _) = tetrahedron();
    t.push(&[1, 0, 2]);
    let r = diagnose(&t, 7, None);
    assert_eq!(r.duplicate_faces, 1);
    assert_eq!(r.examples.duplicate_faces, vec![4]);
    assert_eq!(r.unreferenced_vertices, 3);
    assert_eq!(r.referenced_vertices, 4);
    assert_eq!(r.non_manifold_edges, 3);
    let (t, _) = tetrahedron();
    let r = diagnose(&t, 7, None);
    assert_eq!((r.unreferenced_vertices, r.genus), (3, Some(0)));
    assert!(HalfEdgeMesh::new(&t, 7).is_ok());
}

#[test]
fn degenerate_and_out_of_range_faces() {
    let mut p = Polygons::from_triangles(&[[0, 1, 2]]);
    p.push(&[0, 1]);
    p.push(&[2, 2, 1]);
    p.push(&[0, 2, 1, 2, 3]);
    p.push(&[0, 1, 99]);
    p.push(&[]);
    let r = diagnose(&p, 4, None);
    assert_eq!(r.degenerate_faces, 3);
    assert_eq!(r.examples.degenerate_faces, vec![1, 2, 5]);
    assert_eq!(r.repeated_vertex_faces, 1);
    assert_eq!(r.out_of_range_faces, 1);
    assert_eq!(r.analysed_faces, 1);
    assert_eq!((r.num_edges, r.boundary_loops, r.genus), (3, 1, Some(0)));
    assert_eq!(r.face_sizes, vec![(0, 1), (2, 1), (3, 3), (5, 1)]);

    let one = |f: &[u32]| {
        let mut q = Polygons::new();
        q.push(f);
        HalfEdgeMesh::new(&q, 4).unwrap_err()
    };
    assert!(matches!(
        one(&[0, 1]),
        TopologyError::TooFewVertices { len: 2, .. }
    ));
    assert!(matches!(
        one(&[0, 1, 1]),
        TopologyError::RepeatedVertex {
            vertex: VertexId(1),
            ..
        }
    ));
    assert!(matches!(
        one(&[0, 1, 9]),
        TopologyError::VertexOutOfRange {
            vertex: 9,
            num_vertices: 4,
            ..
        }
    ));

    // Zero area: collinear triangle.
    let pos = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let q = Polygons::from_triangles(&[[0, 1, 2], [0, 1, 3]]);
    let r = diagnose(&q, 4, Some(&pos));
    assert_eq!(r.zero_area_faces, Some(1));
    assert_eq!(r.examples.zero_area_faces, vec![0]);
    // Short positions array: no panic.
    assert_eq!(diagnose(&q, 4, Some(&pos[..2])).zero_area_faces, Some(0));
}

#[test]
fn empty_and_components() {
    let r = diagnose(&Polygons::new(), 3, None);
    assert_eq!(
        (r.num_components, r.unreferenced_vertices, r.genus),
        (0, 3, Some(0))
    );
    let m = HalfEdgeMesh::new(&Polygons::new(), 0).unwrap();
    assert_eq!((m.num_edges(), m.genus()), (0, 0));

    // A torus and a sphere side by side.
    let (mut p, nv) = torus(3, 4, false);
    let (s, ns) = uv_sphere(3, 1, true);
    for f in s.iter() {
        let g: Vec<u32> = f.iter().map(|&v| v + nv as u32).collect();
        p.push(&g);
    }
    let r = check_report(&p, nv + ns, 1, 0);
    assert_eq!(r.num_components, 2);
    let g: Vec<_> = r.components.iter().map(|c| c.genus).collect();
    assert_eq!(g, vec![Some(1), Some(0)]);
    let m = HalfEdgeMesh::new(&p, nv + ns).unwrap();
    assert_eq!(m.component_genera(), vec![1, 0]);
    assert_eq!(face_components(&p, nv + ns).face_counts(), vec![12, 6]);
}

#[test]
fn report_serializes_to_json() {
    let (p, nv) = grid(3, 3, false, false, false);
    let r = diagnose(&p, nv + 2, None);
    let v = serde_json::to_value(&r).unwrap();
    assert_eq!(v["genus"], 0);
    assert_eq!(v["boundary_loops"], 1);
    assert_eq!(v["unreferenced_vertices"], 2);
    assert_eq!(v["face_sizes"][0], serde_json::json!([4, 9]));
    assert_eq!(v["components"][0]["genus"], 0);
    assert!(v["examples"]["non_manifold_edges"]
        .as_array()
        .unwrap()
        .is_empty());
}
