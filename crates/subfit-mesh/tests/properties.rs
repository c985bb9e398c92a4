//! Property tests: Euler characteristic and genus invariants on random grid tori and spheres,
//! invariance under relabelling, and no panics on random polygon soups.

mod common;

use common::*;
use proptest::prelude::*;
use subfit_mesh::{diagnose, HalfEdgeMesh, Polygons};

/// Randomly relabels vertices, reorders faces and rotates each face's first corner (seeded
/// xorshift).
fn shuffle(faces: &Polygons, nv: usize, seed: u64) -> Polygons {
    let mut state = seed | 1;
    let mut rnd = move |n: usize| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % n as u64) as usize
    };
    let mut perm: Vec<u32> = (0..nv as u32).collect();
    for i in (1..nv).rev() {
        perm.swap(i, rnd(i + 1));
    }
    let mut order: Vec<usize> = (0..faces.len()).collect();
    for i in (1..order.len()).rev() {
        order.swap(i, rnd(i + 1));
    }
    let mut out = Polygons::new();
    for f in order {
        let face = faces.face(subfit_mesh::FaceId(f as u32));
        let s = rnd(face.len());
        let g: Vec<u32> = (0..face.len())
            .map(|i| perm[face[(i + s) % face.len()] as usize])
            .collect();
        out.push(&g);
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn tori_have_chi_zero_genus_one(n in 3u32..12, m in 3u32..12, tri: bool) {
        let (p, nv) = torus(n, m, tri);
        let mesh = check_invariants(&p, nv);
        prop_assert_eq!(mesh.euler_characteristic(), 0);
        prop_assert_eq!(mesh.genus(), 1);
        let r = diagnose(&p, nv, None);
        prop_assert_eq!(r.num_edges, mesh.num_edges());
        prop_assert_eq!(r.genus, Some(1));
        prop_assert!(r.is_closed && r.is_manifold && r.is_consistently_oriented);
    }

    #[test]
    fn spheres_have_chi_two(n in 3u32..12, rings in 1u32..8, tri: bool) {
        let (p, nv) = uv_sphere(n, rings, tri);
        let mesh = check_invariants(&p, nv);
        prop_assert_eq!(mesh.euler_characteristic(), 2);
        prop_assert_eq!(diagnose(&p, nv, None).genus, Some(0));
    }

    #[test]
    fn figures_survive_relabelling(
        n in 3u32..9, m in 3u32..9, wi: bool, wj: bool, tri: bool, seed: u64,
    ) {
        let (p, nv) = grid(n, m, wi, wj, tri);
        let q = shuffle(&p, nv, seed);
        let (a, b) = (diagnose(&p, nv, None), diagnose(&q, nv, None));
        prop_assert_eq!(
            (a.num_edges, a.boundary_edges, a.boundary_loops, a.euler_characteristic, a.genus),
            (b.num_edges, b.boundary_edges, b.boundary_loops, b.euler_characteristic, b.genus)
        );
        // Disk, annulus, torus.
        let wraps = usize::from(wi) + usize::from(wj);
        prop_assert_eq!((a.euler_characteristic, a.boundary_loops), [(1, 1), (0, 2), (0, 0)][wraps]);
        prop_assert_eq!(a.genus, Some(u32::from(wraps == 2)));
        check_invariants(&q, nv);
    }

    #[test]
    fn torus_with_faces_removed(n in 3u32..8, m in 3u32..8, drop in prop::collection::vec(any::<u16>(), 0..6)) {
        let (p, nv) = torus(n, m, true);
        let mut q = Polygons::new();
        for (f, face) in p.iter().enumerate() {
            if !drop.iter().any(|&d| d as usize % p.len() == f) {
                q.push(face);
            }
        }
        let r = diagnose(&q, nv, None);
        prop_assert!(r.is_consistently_oriented);
        if let Ok(mesh) = HalfEdgeMesh::new(&q, nv) {
            check_mesh(&mesh, &q, nv);
            prop_assert_eq!(r.genus, Some(mesh.genus()));
            prop_assert_eq!(r.boundary_loops, mesh.boundary_loops().len());
        } else {
            prop_assert!(!r.is_manifold);
        }
    }

    #[test]
    fn random_soups_do_not_panic(
        faces in prop::collection::vec(prop::collection::vec(0u32..12, 0..6), 0..30),
        nv in 0usize..12,
    ) {
        let mut p = Polygons::new();
        for f in &faces {
            p.push(f);
        }
        let r = diagnose(&p, nv, None);
        prop_assert_eq!(r.referenced_vertices + r.unreferenced_vertices, nv);
        match HalfEdgeMesh::new(&p, nv) {
            Ok(mesh) => {
                check_mesh(&mesh, &p, nv);
                prop_assert!(r.is_manifold && r.is_consistently_oriented);
                prop_assert_eq!(r.euler_characteristic, mesh.euler_characteristic());
                prop_assert_eq!(r.genus, Some(mesh.genus()));
            }
            Err(_) => prop_assert!(
                !r.is_manifold || !r.is_consistently_oriented
                    || r.degenerate_faces + r.repeated_vertex_faces + r.out_of_range_faces > 0
            ),
        }
    }
}
