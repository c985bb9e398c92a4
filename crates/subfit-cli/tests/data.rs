//! `subfit info` on every model of the shared data set, checked against the counts, boundary
//! loops and genus given in `shared/data/SOURCES.md`.
//!
//! Needs `SUBFIT_DATA`: without it the test fails under `CI=true` and is skipped with a notice
//! elsewhere.

#![allow(clippy::print_stderr)]

mod common;

use std::process::Command;

use common::data_dir;

/// `(file, vertices, faces, boundary loops, genus)`; `None` genus for point clouds.
const TABLE: &[(&str, u64, u64, u64, Option<u64>)] = &[
    ("armadillo.obj", 43243, 86482, 0, Some(0)),
    ("beetle.off", 19887, 38656, 11, Some(0)),
    ("bun000_points.ply", 40256, 0, 0, None),
    ("bunny.off", 3485, 6966, 0, Some(0)),
    ("camelhead.off", 11381, 22704, 1, Some(0)),
    ("decimated-max.obj", 5272, 10540, 0, Some(0)),
    ("face.obj", 25905, 51712, 1, Some(0)),
    ("fandisk.obj", 6475, 12946, 0, Some(0)),
    ("fertility.off", 4494, 9000, 0, Some(4)),
    ("igea.ply", 134345, 268686, 0, Some(0)),
    ("lucy.ply", 7502, 15000, 0, Some(0)),
    ("rocker-arm.off", 10044, 20088, 0, Some(1)),
    ("stanford-bunny.obj", 35947, 69451, 5, Some(0)),
];

#[test]
fn info_matches_sources_md_for_every_model() {
    let Some(dir) = data_dir() else { return };
    // Every file in the folder must be covered by the table, and every entry must exist.
    let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n != "SOURCES.md")
        .collect();
    on_disk.sort();
    let mut listed: Vec<String> = TABLE.iter().map(|t| t.0.to_string()).collect();
    listed.sort();
    assert_eq!(on_disk, listed, "the data folder and the test table differ");

    for &(name, verts, faces, loops, genus) in TABLE {
        let path = dir.join(name);
        let out = Command::new(env!("CARGO_BIN_EXE_subfit"))
            .args(["info", "--json", path.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["vertices"].as_u64(), Some(verts), "{name} vertices");
        assert_eq!(v["faces"].as_u64(), Some(faces), "{name} faces");
        match genus {
            None => {
                assert_eq!(v["point_cloud"], true, "{name}");
                assert!(v["topology"].is_null(), "{name}");
            }
            Some(g) => {
                let t = &v["topology"];
                assert_eq!(
                    t["boundary_loops"].as_u64(),
                    Some(loops),
                    "{name} boundary loops"
                );
                assert_eq!(t["genus"].as_u64(), Some(g), "{name} genus");
                assert_eq!(t["components"].as_u64(), Some(1), "{name} components");
                assert_eq!(t["non_manifold_edges"].as_u64(), Some(0), "{name}");
                assert_eq!(t["non_manifold_vertices"].as_u64(), Some(0), "{name}");
                assert_eq!(t["inconsistent_edges"].as_u64(), Some(0), "{name}");
            }
        }
    }
}

#[test]
fn stanford_bunny_reports_its_unreferenced_vertices() {
    let Some(dir) = data_dir() else { return };
    let out = Command::new(env!("CARGO_BIN_EXE_subfit"))
        .args([
            "info",
            "--json",
            dir.join("stanford-bunny.obj").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["topology"]["unreferenced_vertices"].as_u64(), Some(1113));
}
