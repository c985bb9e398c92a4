//! Re-orienting faces consistently: random flips on closed and open surfaces of genus 0, 1 and 2
//! are undone (topology unchanged, the original's majority orientation kept, or the outward
//! one for closed surfaces with positions); Möbius strips and non-manifold edges are refused
//! with an error naming the element.

mod common;

use common::*;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use subfit_mesh::shapes::{cube_mesh, torus_mesh};
use subfit_mesh::{
    reorient_faces, FaceId, HalfEdgeMesh, Polygons, ReorientError, TopologyError, VertexId,
};

/// `faces` with the faces where `flip[f]` reversed (plain reversal, not the repair's).
fn flipped(faces: &Polygons, flip: &[bool]) -> Polygons {
    let mut out = Polygons::new();
    for (f, poly) in faces.iter().enumerate() {
        if flip[f] {
            let r: Vec<u32> = poly.iter().rev().copied().collect();
            out.push(&r);
        } else {
            out.push(poly);
        }
    }
    out
}

/// A face as its cyclic vertex sequence starting at its smallest vertex.
fn canonical(poly: &[u32]) -> Vec<u32> {
    let i = (0..poly.len()).min_by_key(|&i| poly[i]).unwrap_or(0);
    poly[i..].iter().chain(&poly[..i]).copied().collect()
}

fn same_orientation(a: &Polygons, b: &Polygons) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b.iter())
            .all(|(x, y)| canonical(x) == canonical(y))
}

/// A random flip pattern with about `fraction` of the faces flipped (at least one).
fn pattern(nf: usize, fraction: f64, seed: u64) -> Vec<bool> {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut p: Vec<bool> = (0..nf).map(|_| rng.random_bool(fraction)).collect();
    p[nf / 2] = true;
    p
}

/// A `10 × 10` open quad grid with three interior quads removed (one boundary loop plus three
/// holes), genus 0.
fn grid_with_holes() -> (Polygons, usize) {
    let (g, nv) = grid(10, 10, false, false, false);
    let mut out = Polygons::new();
    for (f, poly) in g.iter().enumerate() {
        if ![22, 45, 77].contains(&f) {
            out.push(poly);
        }
    }
    (out, nv)
}

#[test]
fn random_flips_are_undone_and_the_topology_is_kept() {
    let corpus: Vec<(&str, (Polygons, usize), u32, usize)> = vec![
        ("sphere", uv_sphere(12, 8, true), 0, 0),
        ("torus", torus(12, 8, true), 1, 0),
        ("torus quads", torus(9, 7, false), 1, 0),
        ("genus 2", double_torus(6), 2, 0),
        ("open grid with holes", grid_with_holes(), 0, 4),
    ];
    for (name, (faces, nv), genus, loops) in corpus {
        let original = HalfEdgeMesh::new(&faces, nv).unwrap();
        assert_eq!(
            (original.genus(), original.boundary_loops().len()),
            (genus, loops),
            "{name}"
        );
        for seed in 0..4 {
            let flip = pattern(faces.len(), 0.3, seed);
            let messy = flipped(&faces, &flip);
            assert!(
                matches!(
                    HalfEdgeMesh::new(&messy, nv),
                    Err(TopologyError::InconsistentOrientation { .. })
                ),
                "{name}"
            );
            let (fixed, report) = reorient_faces(&messy, nv, None).unwrap();
            let m = HalfEdgeMesh::new(&fixed, nv).expect(name);
            assert_eq!(
                (m.genus(), m.boundary_loops().len()),
                (genus, loops),
                "{name}"
            );
            // The majority (unflipped) orientation is the original's: the repair restores it.
            assert!(same_orientation(&fixed, &faces), "{name} seed {seed}");
            let n_flipped = flip.iter().filter(|&&f| f).count();
            assert_eq!(report.flipped_faces, n_flipped, "{name}");
            assert!(report.needed && report.inconsistent_edges > 0);
            assert_eq!((report.components, report.repaired_components), (1, 1));
            assert_eq!(report.decided_by_volume, 0);
        }
        // Already consistent: unchanged, nothing reported.
        let (same, report) = reorient_faces(&faces, nv, None).unwrap();
        assert_eq!(same, faces, "{name}");
        assert!(!report.needed && report.flipped_faces == 0 && report.inconsistent_edges == 0);
    }
}

/// With most faces flipped the majority is the wrong way round; on a closed surface with
/// positions the signed volume still picks the outward orientation.
#[test]
fn closed_surfaces_with_positions_are_oriented_outward_whatever_the_majority() {
    let torus = torus_mesh(1.0, 0.4, 16, 10, true);
    let torus_flips = pattern(torus.faces.len(), 0.7, 11);
    let cube_flips = vec![true, true, true, true, false, false];
    for (mesh, flip) in [(torus, torus_flips), (cube_mesh(0.5), cube_flips)] {
        let (faces, nv) = (&mesh.faces, mesh.num_vertices());
        assert!(flip.iter().filter(|&&f| f).count() * 2 > faces.len());
        let messy = flipped(faces, &flip);
        let (fixed, report) = reorient_faces(&messy, nv, Some(&mesh.positions)).unwrap();
        assert!(same_orientation(&fixed, faces));
        assert_eq!(
            (report.repaired_components, report.decided_by_volume),
            (1, 1)
        );
        // Without positions the majority wins: every face ends up reversed.
        let (majority, report) = reorient_faces(&messy, nv, None).unwrap();
        let all = vec![true; faces.len()];
        assert!(same_orientation(&majority, &flipped(faces, &all)));
        assert_eq!(report.decided_by_volume, 0);
        assert!(HalfEdgeMesh::new(&majority, nv).is_ok());
    }
}

/// Components are oriented independently; faces meeting at a vertex only are separate ones.
#[test]
fn components_are_repaired_independently() {
    let (a, na) = uv_sphere(8, 5, true);
    let (b, nb) = torus(8, 6, true);
    let mut faces = a.clone();
    for poly in b.iter() {
        let shifted: Vec<u32> = poly.iter().map(|&v| v + na as u32).collect();
        faces.push(&shifted);
    }
    let nv = na + nb;
    let mut flip = pattern(faces.len(), 0.25, 5);
    // Leave the sphere consistent.
    flip[..a.len()].fill(false);
    let (fixed, report) = reorient_faces(&flipped(&faces, &flip), nv, None).unwrap();
    assert!(same_orientation(&fixed, &faces));
    assert_eq!((report.components, report.repaired_components), (2, 1));
    let m = HalfEdgeMesh::new(&fixed, nv).unwrap();
    assert_eq!((m.genus(), m.components().count), (1, 2));
}

#[test]
fn a_moebius_strip_is_refused_naming_a_face() {
    let (faces, nv) = moebius(8);
    let err = reorient_faces(&faces, nv, None).unwrap_err();
    let ReorientError::NonOrientable { face } = err else {
        panic!("{err:?}");
    };
    assert!(face.idx() < faces.len());
    let msg = err.to_string();
    assert!(
        msg.contains(&format!("face {face}")) && msg.contains("Möbius"),
        "{msg}"
    );
    // Its faces flipped at random: still refused.
    let messy = flipped(&faces, &pattern(faces.len(), 0.5, 2));
    assert!(matches!(
        reorient_faces(&messy, nv, None),
        Err(ReorientError::NonOrientable { .. })
    ));
}

#[test]
fn a_non_manifold_edge_is_refused_naming_its_vertices() {
    // Three triangles on the edge 1-4, plus a consistent fan elsewhere.
    let faces = Polygons::from_triangles(&[[0, 1, 2], [4, 1, 0], [1, 4, 3], [4, 1, 5], [2, 1, 3]]);
    let err = reorient_faces(&faces, 6, None).unwrap_err();
    assert_eq!(
        err,
        ReorientError::NonManifoldEdge {
            a: VertexId(1),
            b: VertexId(4),
            count: 3,
            f0: FaceId(1),
            f1: FaceId(2),
        }
    );
    assert!(err.to_string().contains("edge 1-4"), "{err}");
    // Malformed faces are refused as by the half-edge builder.
    let bad = Polygons::from_triangles(&[[0, 1, 7]]);
    assert!(matches!(
        reorient_faces(&bad, 3, None),
        Err(ReorientError::Invalid(
            TopologyError::VertexOutOfRange { .. }
        ))
    ));
}
