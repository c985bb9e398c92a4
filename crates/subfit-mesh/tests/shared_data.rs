//! The figures of `../shared/data/SOURCES.md`, recomputed on the real meshes (OFF and OBJ files
//! only, read by the minimal test reader in `common`). Files that are missing are skipped, so
//! the test passes on machines without the shared data.

mod common;

use std::path::PathBuf;
use subfit_mesh::{diagnose, HalfEdgeMesh};

/// `(file, vertices, faces, unreferenced, boundary edges, loops, χ, genus)`.
type Expected = (&'static str, usize, usize, usize, usize, usize, i64, u32);

const TABLE: &[Expected] = &[
    ("armadillo.obj", 43243, 86482, 0, 0, 0, 2, 0),
    ("beetle.off", 19887, 38656, 0, 1136, 11, -9, 0),
    ("bunny.off", 3485, 6966, 0, 0, 0, 2, 0),
    ("camelhead.off", 11381, 22704, 0, 56, 1, 1, 0),
    ("decimated-max.obj", 5272, 10540, 0, 0, 0, 2, 0),
    ("face.obj", 25905, 51712, 0, 96, 1, 1, 0),
    ("fandisk.obj", 6475, 12946, 0, 0, 0, 2, 0),
    ("fertility.off", 4494, 9000, 0, 0, 0, -6, 4),
    ("rocker-arm.off", 10044, 20088, 0, 0, 0, 0, 1),
    ("stanford-bunny.obj", 35947, 69451, 1113, 223, 5, -3, 0),
];

fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
}

#[test]
fn shared_data_matches_sources_table() {
    let mut checked = 0;
    for &(file, vertices, nf, unreferenced, boundary_edges, loops, chi, genus) in TABLE {
        let path = data_dir().join(file);
        let Some((faces, nv)) = common::read_simple(&path) else {
            assert!(!path.exists(), "{} exists but could not be read", file);
            continue;
        };
        checked += 1;
        let r = diagnose(&faces, nv, None);
        let got = (
            r.num_vertices,
            r.num_faces,
            r.unreferenced_vertices,
            r.boundary_edges,
            r.boundary_loops,
            r.euler_characteristic,
            r.genus,
        );
        let want = (
            vertices,
            nf,
            unreferenced,
            boundary_edges,
            loops,
            chi,
            Some(genus),
        );
        assert_eq!(got, want, "{}", file);
        assert_eq!(r.num_components, 1, "{}", file);
        assert!(r.is_manifold && r.is_consistently_oriented, "{}", file);
        let m = HalfEdgeMesh::new(&faces, nv).unwrap_or_else(|e| panic!("{}: {e}", file));
        assert_eq!(m.genus(), genus, "{}", file);
        assert_eq!(m.boundary_loops().len(), loops, "{}", file);
    }
    if data_dir().exists() {
        assert_eq!(checked, TABLE.len());
    }
}
