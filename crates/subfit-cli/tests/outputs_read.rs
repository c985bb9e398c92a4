//! Every kind of file subfit writes opens in the readers users reach for first — trimesh,
//! Open3D, meshio and MeshLab's (pymeshlab) (`tests/checks/open_outputs.py`) — with the vertex
//! and face counts we wrote (read back with our own reader). The fit is a quad/triangle one, whose limit
//! tessellation has quads and triangles: `limit.ply` is triangles by default (trimesh refuses
//! a PLY whose faces differ in size: "PLY is unexpected length"), and `--limit-quads` keeps
//! the quads for the readers that take them. Without the Python packages
//! (tools/output-checks/requirements.txt) the test fails when `CI=true` and prints a notice
//! and passes otherwise.

mod common;

use std::path::{Path, PathBuf};

use common::{available, run_check, subfit};

use subfit::io::{Encoding, WriteOptions};
use subfit::mesh::shapes::Shape;

/// Runs `subfit ARGS`, asserting exit code 0.
fn ok(args: &[&str]) -> String {
    let r = subfit(args);
    assert_eq!(
        r.status.code(),
        Some(0),
        "subfit {args:?}: {}",
        String::from_utf8_lossy(&r.stderr)
    );
    String::from_utf8_lossy(&r.stdout).into_owned()
}

/// Vertices, faces and triangles (fan triangulation) of a file, by our own reader.
fn written(path: &Path) -> (usize, usize, usize) {
    let (mesh, _) = subfit::io::read_file(path, &Default::default()).unwrap();
    let triangles = mesh.faces.triangulate_fan().len();
    (mesh.num_vertices(), mesh.num_faces(), triangles)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Whether `reader` is meant to read files ending in `ext`: meshio has no XYZ format and its
/// OFF reader takes plain `OFF` files of triangles only (ours may say `NOFF`, with normals, or
/// have quads); docs/outputs.md says so. MeshLab reads every kind checked here (PLY, OBJ, OFF,
/// STL, and XYZ as a point cloud); it has no USD importer, and `control.usda` is not among
/// these files (USD's own bindings and Blender open it: `tests/report_checks.rs`).
fn reads(reader: &str, ext: &str) -> bool {
    !(reader == "meshio" && (ext == "xyz" || ext == "off"))
}

/// Checks what each reader saw in `files` against what we wrote.
fn check_readers(files: &[PathBuf], readers: &[&str]) {
    let args: Vec<&str> = files.iter().map(|f| s(f)).collect();
    let seen = run_check("open_outputs.py", &args);
    for f in files {
        let got = &seen[s(f)];
        let ext = f.extension().unwrap().to_str().unwrap();
        if ext == "json" || ext == "csv" {
            assert!(got.get("error").is_none(), "{}: {got}", f.display());
            continue;
        }
        let (v, faces, tris) = written(f);
        for &reader in readers {
            if !reads(reader, ext) {
                continue;
            }
            let r = &got[reader];
            let count = |k: &str| {
                r[k].as_u64()
                    .unwrap_or_else(|| panic!("{reader} could not read {}: {r}", f.display()))
                    as usize
            };
            // STL stores every triangle's corners: readers differ in welding them.
            if ext != "stl" {
                assert_eq!(count("vertices"), v, "{reader}, {}: vertices", f.display());
            }
            assert_eq!(
                count("triangles"),
                tris,
                "{reader}, {}: triangles",
                f.display()
            );
            // meshio keeps polygons; MeshLab triangulates them on load (its "triangles" are
            // compared above) and gives them back from the diagonals it marked.
            if reader == "meshio" || reader == "meshlab" {
                assert_eq!(count("faces"), faces, "{reader}, {}: faces", f.display());
            }
        }
    }
}

#[test]
fn every_output_kind_opens_in_trimesh_open3d_meshio_and_meshlab() {
    if !available("trimesh, open3d, meshio, pymeshlab", None) {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let cloud = d.path().join("torus.ply");
    let opts = WriteOptions {
        format: None,
        encoding: Encoding::BinaryLittleEndian,
        single_precision: false,
    };
    let torus = Shape::builtin()
        .into_iter()
        .find(|(name, _)| *name == "torus")
        .expect("a built-in torus")
        .1;
    subfit::io::write_file(&cloud, &torus.sample(4_000, 0.0, 1), &opts).unwrap();
    // A quad/triangle fit: its limit tessellation mixes quads and triangles.
    let fit = d.path().join("fit");
    let quad_tri = [
        "--scheme",
        "quad-tri",
        "--control-points",
        "60",
        "--max-iterations",
        "6",
        "--sample-level",
        "2",
        "--quiet",
    ];
    let r = subfit(&[&["fit", s(&cloud), "-o", s(&fit)], &quad_tri[..]].concat());
    assert!(r.status.code().is_some_and(|c| c <= 1), "{r:?}");
    let (_, faces, tris) = written(&fit.join("limit.ply"));
    assert_eq!(faces, tris, "limit.ply is triangles by default");
    let control = written(&fit.join("control.obj"));
    assert!(control.2 > control.1, "the quad/tri cage has quads");

    // The same fit keeping the quads.
    let quads = d.path().join("quads");
    let r = subfit(
        &[
            &["fit", s(&cloud), "-o", s(&quads), "--limit-quads"],
            &quad_tri[..],
        ]
        .concat(),
    );
    assert!(r.status.code().is_some_and(|c| c <= 1), "{r:?}");
    let (v, faces_kept, tris_kept) = written(&quads.join("limit.ply"));
    assert!(faces_kept < tris_kept, "--limit-quads keeps quads");
    assert_eq!((tris_kept, v), (tris, written(&fit.join("limit.ply")).0));

    // The other commands' outputs.
    let analyze = d.path().join("analyze.ply");
    ok(&["analyze", s(&cloud), "-o", s(&analyze)]);
    let eval = d.path().join("eval.ply");
    ok(&[
        "eval",
        s(&fit.join("control.obj")),
        "--samples",
        "300",
        "-o",
        s(&eval),
    ]);
    let sub = d.path().join("subdivided.obj");
    ok(&[
        "subdivide",
        s(&fit.join("control.obj")),
        "--levels",
        "1",
        "-o",
        s(&sub),
    ]);
    let mut files = vec![cloud.clone(), analyze, eval, sub];
    for ext in ["obj", "off", "stl", "xyz"] {
        let to = d.path().join(format!("limit.{ext}"));
        ok(&["convert", s(&fit.join("limit.ply")), s(&to)]);
        files.push(to);
    }
    let control_off = d.path().join("control.off");
    ok(&["convert", s(&fit.join("control.obj")), s(&control_off)]);
    files.push(control_off);
    for f in [
        "control.obj",
        "control.tags.json",
        "limit.ply",
        "error.ply",
        "log.csv",
        "report.json",
    ] {
        files.push(fit.join(f));
    }
    check_readers(&files, &["trimesh", "open3d", "meshio", "meshlab"]);
    // Quads and triangles in one PLY: trimesh refuses it (the reason for the default).
    check_readers(&[quads.join("limit.ply")], &["open3d", "meshio", "meshlab"]);
}

/// `--json` prints one JSON object whose figures are the report's, and the files it lists exist.
#[test]
fn fit_json_prints_a_closing_summary_that_matches_the_report() {
    let d = tempfile::tempdir().unwrap();
    let cloud = d.path().join("ellipsoid.ply");
    let opts = WriteOptions {
        format: None,
        encoding: Encoding::BinaryLittleEndian,
        single_precision: false,
    };
    subfit::io::write_file(&cloud, &Shape::PAPER_ELLIPSOID.sample(3_000, 0.0, 2), &opts).unwrap();
    let out = d.path().join("fit");
    let r = subfit(&[
        "fit",
        s(&cloud),
        "-o",
        s(&out),
        "--json",
        "--control-points",
        "40",
        "--max-iterations",
        "6",
        "--sample-level",
        "2",
    ]);
    assert!(r.status.code().is_some_and(|c| c <= 1), "{r:?}");
    let summary: serde_json::Value = serde_json::from_slice(&r.stdout).expect("stdout is JSON");
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(summary["control_points"], report["control_points"]);
    let two = &report["final"]["two_sided"];
    assert_eq!(
        summary["two_sided_rms"]["units"],
        two["e_rms_original_units"]
    );
    assert_eq!(
        summary["two_sided_max"]["fraction_of_diagonal"],
        two["e_max_fraction_of_diagonal"]
    );
    assert_eq!(summary["largest_at"], report["final"]["largest_at"]);
    assert_eq!(
        summary["largest_at"]["data_to_surface"]
            .as_array()
            .unwrap()
            .len(),
        3
    );
    assert_eq!(
        summary["tolerance_reached"].as_bool(),
        Some(r.status.code() == Some(0))
    );
    let files = summary["files"].as_array().unwrap();
    assert_eq!(files.len(), subfit::OUTPUTS.len());
    for f in files {
        assert!(Path::new(f.as_str().unwrap()).is_file(), "{f}");
    }
    // The diagonal in the input's units: the ellipsoid's box is 0.5 × 1 × 2 (semi-axes
    // 0.25, 0.5, 1), diagonal √5.25, up to the sampling's reach.
    let diagonal = summary["diagonal"].as_f64().unwrap();
    assert!((diagonal - 5.25f64.sqrt()).abs() < 0.02, "{diagonal}");

    // --quiet prints nothing on stdout.
    let quiet = d.path().join("quiet");
    let r = subfit(&[
        "fit",
        s(&cloud),
        "-o",
        s(&quiet),
        "--quiet",
        "--control-points",
        "40",
        "--max-iterations",
        "3",
        "--sample-level",
        "2",
    ]);
    assert!(r.status.code().is_some_and(|c| c <= 1), "{r:?}");
    assert!(
        r.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&r.stdout)
    );
}
