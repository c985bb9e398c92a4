//! The command line, end to end: exit codes, one-line errors naming file/line/element, atomic
//! outputs, and conversions.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn subfit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_subfit"))
        .args(args)
        .output()
        .expect("run subfit")
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// Runs `subfit info FILE` and checks exit code 2 with one stderr line containing every
/// fragment.
#[track_caller]
fn expect_bad(path: &Path, fragments: &[&str]) {
    let out = subfit(&["info", path.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "one line expected: {err}"
    );
    let name = path.file_name().unwrap().to_str().unwrap();
    assert!(err.contains(name), "no file name in: {err}");
    for f in fragments {
        assert!(err.contains(f), "missing `{f}` in: {err}");
    }
    assert!(out.stdout.is_empty());
}

const CUBE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

#[test]
fn malformed_files_give_exit_code_2_and_a_located_message() {
    let d = tempfile::tempdir().unwrap();
    let d = d.path();

    // Truncated binary PLY: header promises 3 vertices, data holds 2.5.
    let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n".to_vec();
    ply.extend(std::iter::repeat_n(0u8, 12 * 2 + 6));
    expect_bad(&write(d, "truncated.ply", &ply), &["vertex 2"]);

    // Wrong counts: OFF announces 10 vertices, holds 3.
    expect_bad(
        &write(
            d,
            "counts.off",
            b"OFF\n10 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
        ),
        &[],
    );

    // Index out of range in OBJ, at line 4.
    expect_bad(
        &write(d, "range.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n"),
        &["line 4", "99", "out of range"],
    );

    // NaN coordinate in an XYZ file at line 2.
    expect_bad(
        &write(d, "nan.xyz", b"0 0 0\n1 nan 0\n0 1 0\n"),
        &["line 2", "non-finite"],
    );
    // Inf in ascii PLY.
    expect_bad(
        &write(
            d,
            "inf.ply",
            b"ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\nproperty double z\nend_header\n0 0 0\n1 inf 0\n",
        ),
        &["non-finite"],
    );

    // Empty (whitespace only) and 0-byte files.
    expect_bad(&write(d, "blank.obj", b"  \n\n"), &["empty"]);
    expect_bad(&write(d, "zero.ply", b""), &["empty"]);
    expect_bad(&write(d, "zero.stl", b""), &["empty"]);

    // Binary garbage with a PLY extension.
    let garbage: Vec<u8> = (0..4096u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
        .collect();
    expect_bad(&write(d, "garbage.ply", &garbage), &[]);

    // A directory.
    let sub = d.join("adir.ply");
    std::fs::create_dir(&sub).unwrap();
    expect_bad(&sub, &["directory"]);

    // A missing file and an unknown format.
    expect_bad(&d.join("missing.obj"), &[]);
    expect_bad(&write(d, "mesh.foo", b"hello\n"), &["unknown file format"]);
}

#[test]
fn usage_errors_exit_with_2() {
    assert_eq!(subfit(&[]).status.code(), Some(2));
    assert_eq!(subfit(&["info"]).status.code(), Some(2));
    assert_eq!(subfit(&["frobnicate"]).status.code(), Some(2));
    assert_eq!(subfit(&["demo", "--points", "3"]).status.code(), Some(2));
    assert_eq!(subfit(&["--help"]).status.code(), Some(0));
}

#[test]
fn info_reports_counts_and_topology_as_text_and_json() {
    let d = tempfile::tempdir().unwrap();
    let p = write(d.path(), "cube.obj", CUBE_OBJ.as_bytes());
    let out = subfit(&["info", p.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("obj"), "{text}");
    assert!(text.contains("genus"), "{text}");

    let out = subfit(&["info", "--json", p.to_str().unwrap()]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["format"], "obj");
    assert_eq!(v["vertices"], 8);
    assert_eq!(v["faces"], 6);
    assert_eq!(v["faces_by_size"]["4"], 6);
    assert_eq!(v["bbox"]["diagonal"].as_f64().unwrap(), 3f64.sqrt());
    assert_eq!(v["topology"]["genus"], 0);
    assert_eq!(v["topology"]["boundary_loops"], 0);
    assert_eq!(v["topology"]["components"], 1);
    assert_eq!(v["topology"]["euler_characteristic"], 2);
}

#[test]
fn convert_round_trips_through_every_format_and_never_leaves_partial_files() {
    let d = tempfile::tempdir().unwrap();
    let d = d.path();
    let src = write(d, "cube.obj", CUBE_OBJ.as_bytes());
    for (name, extra) in [
        ("a.ply", &[][..]),
        ("b.ply", &["--encoding", "ascii"][..]),
        ("c.ply", &["--encoding", "binary-be"][..]),
        ("d.off", &[][..]),
        ("e.obj", &[][..]),
    ] {
        let out_path = d.join(name);
        let mut args = vec!["convert", src.to_str().unwrap(), out_path.to_str().unwrap()];
        args.extend_from_slice(extra);
        let out = subfit(&args);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let info = subfit(&["info", "--json", out_path.to_str().unwrap()]);
        let v: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
        assert_eq!(v["vertices"], 8, "{name}");
        assert_eq!(v["faces_by_size"]["4"], 6, "{name}");
    }
    // STL triangulates and welds: 8 vertices, 12 triangles.
    let stl = d.join("f.stl");
    assert!(
        subfit(&["convert", src.to_str().unwrap(), stl.to_str().unwrap()])
            .status
            .success()
    );
    let v: serde_json::Value =
        serde_json::from_slice(&subfit(&["info", "--json", stl.to_str().unwrap()]).stdout).unwrap();
    assert_eq!(v["vertices"], 8);
    assert_eq!(v["faces_by_size"]["3"], 12);

    // A failing conversion leaves nothing behind.
    let bad = write(d, "bad.obj", b"v 0 0 0\nf 1 2 3\n");
    let target = d.join("never.ply");
    let out = subfit(&["convert", bad.to_str().unwrap(), target.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(!target.exists());
    let leftovers: Vec<_> = std::fs::read_dir(d)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty());
    // Unknown output extension is a usage error before any work.
    let out = subfit(&[
        "convert",
        src.to_str().unwrap(),
        d.join("x.abc").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn demo_writes_the_builtin_shapes() {
    let d = tempfile::tempdir().unwrap();
    let out_dir = d.path().join("demo");
    let out = subfit(&[
        "demo",
        "-o",
        out_dir.to_str().unwrap(),
        "--points",
        "500",
        "--no-fit",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for name in ["ellipsoid", "torus", "genus2"] {
        let p = out_dir.join(format!("{name}.ply"));
        let info = subfit(&["info", "--json", p.to_str().unwrap()]);
        let v: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
        assert_eq!(v["normals"], true, "{name}");
        assert_eq!(v["faces"], 0, "{name}");
        let n = v["vertices"].as_u64().unwrap();
        assert!((475..=500).contains(&n), "{name}: {n}");
    }
}

#[test]
fn subdivide_refines_and_evaluates_the_limit() {
    let d = tempfile::tempdir().unwrap();
    let d = d.path();
    let cube = write(d, "cube.obj", CUBE_OBJ.as_bytes());
    let out = d.join("cube2.ply");
    let r = subfit(&[
        "subdivide",
        cube.to_str().unwrap(),
        "--levels",
        "2",
        "--limit",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let v: serde_json::Value =
        serde_json::from_slice(&subfit(&["info", "--json", out.to_str().unwrap()]).stdout).unwrap();
    // Catmull-Clark: V + E + F per level: 8 → 26 → 98 vertices, 6 → 24 → 96 quads.
    assert_eq!(v["vertices"], 98);
    assert_eq!(v["faces_by_size"]["4"], 96);
    assert_eq!(v["normals"], true);
    assert_eq!(v["topology"]["genus"], 0);
    // The limit of the unit cube lies strictly inside it.
    for k in 0..3 {
        assert!(v["bbox"]["min"][k].as_f64().unwrap() > 0.0);
        assert!(v["bbox"]["max"][k].as_f64().unwrap() < 1.0);
    }

    // Loop on quads is refused with exit code 2, and nothing is written.
    let bad_out = d.join("never.obj");
    let r = subfit(&[
        "subdivide",
        cube.to_str().unwrap(),
        "--scheme",
        "loop",
        "-o",
        bad_out.to_str().unwrap(),
    ]);
    assert_eq!(r.status.code(), Some(2));
    assert!(!bad_out.exists());

    // Loop on an octahedron: 6 + 12 vertices and 32 triangles after one level.
    let octa = write(
        d,
        "octa.obj",
        b"v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n",
    );
    let out = d.join("octa1.off");
    assert!(subfit(&[
        "subdivide",
        octa.to_str().unwrap(),
        "-o",
        out.to_str().unwrap()
    ])
    .status
    .success());
    let v: serde_json::Value =
        serde_json::from_slice(&subfit(&["info", "--json", out.to_str().unwrap()]).stdout).unwrap();
    assert_eq!(v["vertices"], 18);
    assert_eq!(v["faces_by_size"]["3"], 32);
}

#[test]
fn analyze_writes_normals_curvatures_and_directions() {
    let d = tempfile::tempdir().unwrap();
    let demo = d.path().join("demo");
    assert!(subfit(&[
        "demo",
        "-o",
        demo.to_str().unwrap(),
        "--points",
        "4000",
        "--no-fit"
    ])
    .status
    .success());
    let cloud = demo.join("ellipsoid.ply");
    let out = d.path().join("an.ply");
    let r = subfit(&[
        "analyze",
        cloud.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--json",
        "--estimate-normals",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let s: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    assert_eq!(s["points"], 4000);
    assert_eq!(s["normal_origin"], "estimated");
    // A clean sampling: no outliers, a noise level far below the spacing.
    assert_eq!(s["outliers_removed"], 0, "{s}");
    let noise = s["noise_level"].as_f64().unwrap();
    assert!(
        noise >= 0.0 && noise < 0.1 * s["point_spacing"].as_f64().unwrap(),
        "{s}"
    );
    // The ellipsoid is convex: with outward normals both curvatures are negative (Cheng 2007
    // §II-D3: the centre of curvature lies on the side opposite the normal) at almost all points.
    assert!(s["k1_quantiles"][3].as_f64().unwrap() < 0.0, "{s}");
    assert!(s["k2_quantiles"][3].as_f64().unwrap() < 0.0, "{s}");

    let bytes = std::fs::read(&out).unwrap();
    let header = String::from_utf8_lossy(&bytes[..600]);
    for p in ["nx", "k1", "k2", "t1x", "t1y", "t1z", "t2x", "t2y", "t2z"] {
        assert!(
            header.contains(&format!("property double {p}\n")),
            "{p}: {header}"
        );
    }
    let v: serde_json::Value =
        serde_json::from_slice(&subfit(&["info", "--json", out.to_str().unwrap()]).stdout).unwrap();
    assert_eq!(v["vertices"], 4000);
    // Normalized into the unit cube, longest side 1.
    assert_eq!(v["bbox"]["size"][2].as_f64().unwrap(), 1.0);

    // Bad option values are rejected before any work.
    let r = subfit(&["analyze", cloud.to_str().unwrap(), "--radius", "-1"]);
    assert_eq!(r.status.code(), Some(2));
    let r = subfit(&[
        "analyze",
        cloud.to_str().unwrap(),
        "-o",
        d.path().join("x.obj").to_str().unwrap(),
    ]);
    assert_eq!(r.status.code(), Some(2));
    // Too few points: a clear error, exit code 2.
    let few = write(d.path(), "few.xyz", b"0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 0\n");
    let r = subfit(&["analyze", few.to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&r.stderr).contains("few.xyz"));
}

#[test]
fn eval_writes_exact_limit_samples_with_their_parameters() {
    let d = tempfile::tempdir().unwrap();
    let cube = write(d.path(), "cube.obj", CUBE_OBJ.as_bytes());
    let out = d.path().join("samples.ply");
    let r = subfit(&[
        "eval",
        cube.to_str().unwrap(),
        "--samples",
        "500",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let bytes = std::fs::read(&out).unwrap();
    let header = String::from_utf8_lossy(&bytes[..400]);
    for p in ["nx", "face", "sub", "u", "v"] {
        assert!(
            header.contains(&format!("property double {p}\n")),
            "{p}: {header}"
        );
    }
    let v: serde_json::Value =
        serde_json::from_slice(&subfit(&["info", "--json", out.to_str().unwrap()]).stdout).unwrap();
    assert_eq!(v["vertices"], 500);
    // The Catmull-Clark limit of the unit cube lies inside it, around its centre.
    for k in 0..3 {
        let lo = v["bbox"]["min"][k].as_f64().unwrap();
        let hi = v["bbox"]["max"][k].as_f64().unwrap();
        assert!(lo > 0.0 && hi < 1.0 && lo < 0.5 && hi > 0.5, "{lo} {hi}");
    }
    // XYZ output: points and normals only.
    let xyz = d.path().join("samples.xyz");
    assert!(subfit(&[
        "eval",
        cube.to_str().unwrap(),
        "--samples",
        "10",
        "-o",
        xyz.to_str().unwrap()
    ])
    .status
    .success());
    let text = std::fs::read_to_string(&xyz).unwrap();
    assert_eq!(text.lines().count(), 10);
    assert_eq!(text.lines().next().unwrap().split_whitespace().count(), 6);
}

const ELLIPSOID_OCTAHEDRON: &[u8] =
    b"v 0.25 0 0\nv -0.25 0 0\nv 0 0.5 0\nv 0 -0.5 0\nv 0 0 1\nv 0 0 -1\n\
f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";

#[test]
fn fit_writes_cage_limit_log_and_report() {
    let d = tempfile::tempdir().unwrap();
    let demo = d.path().join("demo");
    assert!(subfit(&[
        "demo",
        "-o",
        demo.to_str().unwrap(),
        "--points",
        "8000",
        "--no-fit"
    ])
    .status
    .success());
    let target = demo.join("ellipsoid.ply");
    let init = write(d.path(), "octa.obj", ELLIPSOID_OCTAHEDRON);
    let out = d.path().join("fit");
    let args = |extra: &[&str]| {
        let mut v = vec![
            "fit".to_string(),
            target.to_str().unwrap().to_string(),
            "--init".into(),
            init.to_str().unwrap().into(),
            "-o".into(),
            out.to_str().unwrap().into(),
            "--max-iterations".into(),
            "8".into(),
        ];
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    let run = |extra: &[&str]| {
        let a = args(extra);
        subfit(&a.iter().map(String::as_str).collect::<Vec<_>>())
    };
    // A single stage on the given cage (no refinement), a tolerance it reaches: success.
    let r = run(&[
        "--lambda",
        "0",
        "--no-refine",
        "--tolerance",
        "0.05",
        "--stage-iterations",
        "8",
    ]);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    let e0 = report["initial"]["e_rms"].as_f64().unwrap();
    let e1 = report["final"]["e_rms"].as_f64().unwrap();
    assert!(e1 < e0 / 5.0, "{e0} -> {e1}");
    assert_eq!(report["control_points"], 6);
    let rows = report["iterations"].as_array().unwrap().len();
    assert!((1..=8).contains(&rows));
    let csv = std::fs::read_to_string(out.join("log.csv")).unwrap();
    assert_eq!(
        csv.lines().count(),
        rows + 2,
        "header + initial row + iterations"
    );
    // The cage is in the target's coordinates; the limit has normals and faces.
    let cage: serde_json::Value = serde_json::from_slice(
        &subfit(&["info", "--json", out.join("control.obj").to_str().unwrap()]).stdout,
    )
    .unwrap();
    assert_eq!(cage["vertices"], 6);
    let z = cage["bbox"]["max"][2].as_f64().unwrap();
    // Loop limits shrink: the fitted apex lies outside the target to pull the limit out to it.
    assert!(z > 1.0 && z < 4.0, "{z}");
    let limit: serde_json::Value = serde_json::from_slice(
        &subfit(&["info", "--json", out.join("limit.ply").to_str().unwrap()]).stdout,
    )
    .unwrap();
    assert_eq!(limit["normals"], true);
    assert_eq!(limit["topology"]["genus"], 0);
    let lz = limit["bbox"]["max"][2].as_f64().unwrap();
    assert!((lz - 1.0).abs() < 0.1, "{lz}");

    // An unreachable tolerance: exit code 1, outputs still written.
    std::fs::remove_dir_all(&out).unwrap();
    let r = run(&["--tolerance", "1e-9", "--no-refine"]);
    assert_eq!(r.status.code(), Some(1));
    for f in [
        "report.json",
        "control.obj",
        "control.usda",
        "control.tags.json",
        "limit.ply",
        "error.ply",
        "log.csv",
        "preview.png",
        "report.html",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }

    // Bad options: exit code 2 before any work.
    for bad in [
        &["--lambda", "-1"][..],
        &["--tolerance", "3"][..],
        &["--method", "xdm"][..],
    ] {
        assert_eq!(run(bad).status.code(), Some(2), "{bad:?}");
    }
    let r = subfit(&[
        "fit",
        target.to_str().unwrap(),
        "--init",
        "/nonexistent.obj",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(r.status.code(), Some(2));
}

#[test]
fn compare_measures_two_sided_distances_between_concentric_cubes() {
    let d = tempfile::tempdir().unwrap();
    let inner = write(d.path(), "inner.obj", CUBE_OBJ.as_bytes());
    // The same cube grown by 0.05 on every side.
    let outer_obj: String = CUBE_OBJ
        .lines()
        .map(|l| match l.strip_prefix("v ") {
            Some(xyz) => {
                let c: Vec<f64> = xyz
                    .split_whitespace()
                    .map(|t| t.parse::<f64>().unwrap() * 1.1 - 0.05)
                    .collect();
                format!("v {} {} {}\n", c[0], c[1], c[2])
            }
            None => format!("{l}\n"),
        })
        .collect();
    let outer = write(d.path(), "outer.obj", outer_obj.as_bytes());
    let r = subfit(&[
        "compare",
        inner.to_str().unwrap(),
        outer.to_str().unwrap(),
        "--json",
        "--samples",
        "4000",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let c: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    let g = |a: &str, b: &str| c[a][b].as_f64().unwrap();
    // Every point of the inner cube is 0.05 from the outer one.
    assert!((g("a_to_b", "rms") - 0.05).abs() < 1e-12);
    assert!((g("a_to_b", "max") - 0.05).abs() < 1e-12);
    // Points of the outer cube are between 0.05 (face centres) and 0.05·√3 (corners) away.
    assert!(g("b_to_a", "mean") > 0.05 && g("b_to_a", "max") <= 0.05 * 3f64.sqrt() + 1e-12);
    assert!((c["hausdorff"].as_f64().unwrap() - g("b_to_a", "max")).abs() < 1e-15);
    assert_eq!(c["a_to_b"]["samples"], 4000);

    // A point set against a mesh: its own vertices lie on it.
    let pts = write(d.path(), "corners.xyz", b"0 0 0\n1 0 0\n0 1 0\n1 1 1\n");
    let r = subfit(&[
        "compare",
        pts.to_str().unwrap(),
        inner.to_str().unwrap(),
        "--json",
        "--samples",
        "500",
    ]);
    let c: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    assert_eq!(c["a_to_b"]["samples"], 4);
    assert!(c["a_to_b"]["max"].as_f64().unwrap() < 1e-15);
}

/// The unit cube's faces as 60 × 60 grids, each point nudged off the grid (a fixed,
/// aperiodic pattern) so the cloud is not a lattice: 12 crease curves, 8 corners. XYZ text.
fn cube_cloud() -> String {
    let mut text = String::new();
    let m = 60;
    for face in 0..6 {
        let (axis, side) = (face / 2, (face % 2) as f64);
        for i in 0..m {
            for j in 0..m {
                let k = (face * m * m + i * m + j) as f64;
                let u = (i as f64 + 0.5 + 0.3 * (k * 0.618).sin()) / m as f64;
                let v = (j as f64 + 0.5 + 0.3 * (k * 1.414).cos()) / m as f64;
                let mut p = [0.0; 3];
                p[axis] = side;
                p[(axis + 1) % 3] = u;
                p[(axis + 2) % 3] = v;
                text.push_str(&format!("{} {} {}\n", p[0], p[1], p[2]));
            }
        }
    }
    text
}

#[test]
fn init_with_cloud_features_tags_the_creases_of_a_point_cloud() {
    let d = tempfile::tempdir().unwrap();
    let cloud = write(d.path(), "cube.xyz", cube_cloud().as_bytes());
    let out = d.path().join("cage.obj");
    let r = subfit(&[
        "init",
        cloud.to_str().unwrap(),
        "--control-points",
        "200",
        "--cloud-features",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let obj = std::fs::read_to_string(&out).unwrap();
    let creases = obj.lines().filter(|l| l.starts_with("t crease")).count();
    let corners = obj.lines().filter(|l| l.starts_with("t corner")).count();
    assert!(
        creases >= 1 && corners >= 1,
        "{creases} crease, {corners} corner lines"
    );
    // Without the flag a cloud's cage is smooth.
    let plain = d.path().join("plain.obj");
    let r = subfit(&[
        "init",
        cloud.to_str().unwrap(),
        "--control-points",
        "200",
        "-o",
        plain.to_str().unwrap(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let obj = std::fs::read_to_string(&plain).unwrap();
    assert!(
        !obj.lines().any(|l| l.starts_with("t ")),
        "tags without --cloud-features"
    );
}

#[test]
fn analyze_traces_the_sharp_features_of_a_point_cloud() {
    let d = tempfile::tempdir().unwrap();
    let cloud = write(d.path(), "cube.xyz", cube_cloud().as_bytes());
    let out = d.path().join("features.ply");
    let r = subfit(&[
        "analyze",
        cloud.to_str().unwrap(),
        "--features",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let s: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    let f = &s["features"];
    assert_eq!(f["source"], "cloud", "{s}");
    assert_eq!(
        (&f["curves"], &f["corners"], &f["darts"]),
        (&12.into(), &8.into(), &0.into()),
        "{s}"
    );
    assert!(f["feature_points"].as_u64().unwrap() > 100, "{s}");
    let ply = std::fs::read_to_string(&out).unwrap();
    let edges = f["sharp_edges"].as_u64().unwrap();
    assert!(ply.contains(&format!("element edge {edges}\n")), "{ply}");
    // The corners come first (kind 1), at the cube's corners.
    let body = ply.split("end_header\n").nth(1).unwrap();
    for l in body.lines().take(8) {
        let w: Vec<f64> = l.split(' ').map(|x| x.parse().unwrap()).collect();
        assert_eq!(w[3], 1.0, "{l}");
        assert!(w[..3].iter().all(|&x| x.min(1.0 - x).abs() < 0.02), "{l}");
    }
    // The text summary names the curves.
    let r = subfit(&[
        "analyze",
        cloud.to_str().unwrap(),
        "--features",
        out.to_str().unwrap(),
    ]);
    let text = String::from_utf8_lossy(&r.stdout);
    assert!(text.contains("features      12 curves"), "{text}");
}

#[test]
fn analyze_writes_the_sharp_features_of_a_mesh() {
    let d = tempfile::tempdir().unwrap();
    // The project's cube with each face a fan of 4 triangles around its centre (analysis needs
    // 10+ points): 12 crease edges, 8 corners (the fan edges are flat).
    let mut cube_mesh = subfit::mesh::shapes::cube_mesh(0.5);
    let quads: Vec<Vec<u32>> = cube_mesh.faces.iter().map(<[u32]>::to_vec).collect();
    let mut fans = subfit::mesh::Polygons::new();
    for q in &quads {
        let c = cube_mesh.positions.len() as u32;
        let centre = [0, 1, 2].map(|k| {
            q.iter()
                .map(|&v| cube_mesh.positions[v as usize][k])
                .sum::<f64>()
                / 4.0
        });
        cube_mesh.positions.push(centre);
        for i in 0..4 {
            fans.push(&[q[i], q[(i + 1) % 4], c]);
        }
    }
    cube_mesh.faces = fans;
    let cube = d.path().join("cube.obj");
    subfit::io::write_file(&cube, &cube_mesh, &Default::default()).unwrap();
    let out = d.path().join("features.ply");
    let r = subfit(&[
        "analyze",
        cube.to_str().unwrap(),
        "--features",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let s: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    let f = &s["features"];
    assert_eq!(
        (&f["sharp_edges"], &f["curves"], &f["corners"], &f["darts"]),
        (&12.into(), &12.into(), &8.into(), &0.into()),
        "{s}"
    );
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.contains("element vertex 8\n") && text.contains("element edge 12\n"),
        "{text}"
    );
    let body = text.split("end_header\n").nth(1).unwrap();
    let kinds: Vec<&str> = body
        .lines()
        .take(8)
        .map(|l| l.split(' ').nth(3).unwrap())
        .collect();
    assert_eq!(kinds, vec!["1"; 8], "every feature vertex is a corner");

    let r = subfit(&["analyze", cube.to_str().unwrap(), "--feature-angle", "200"]);
    assert_eq!(r.status.code(), Some(2));
}

/// A reader that goes away (`subfit compare … | head -1`) ends the command quietly: exit 0,
/// no panic on the broken pipe. The read end is closed before the command has measured
/// anything; if it were slower than the command, the output would fit in the pipe and the
/// result would be the same.
#[test]
fn a_closed_stdout_is_not_a_panic() {
    let d = tempfile::tempdir().unwrap();
    let cube = write(d.path(), "cube.obj", CUBE_OBJ.as_bytes());
    let mut child = Command::new(env!("CARGO_BIN_EXE_subfit"))
        .args(["compare", cube.to_str().unwrap(), cube.to_str().unwrap()])
        .args(["--samples", "2000"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(out.status.code(), Some(0), "{err}");
}

/// `subdivide` and `eval` honour the crease and corner tags of the cage they read (an OBJ's
/// `t` lines, as `fit` writes control.obj): a cube with every edge an infinitely sharp crease
/// and every vertex a corner has the cube itself as its Catmull-Clark limit, where the
/// untagged cube rounds to a blob well inside it.
#[test]
fn subdivide_and_eval_honour_the_cages_tags() {
    let d = tempfile::tempdir().unwrap();
    let mut obj = CUBE_OBJ.to_string();
    for (a, b) in [
        (0, 1),
        (1, 2),
        (2, 3),
        (3, 0),
        (4, 5),
        (5, 6),
        (6, 7),
        (7, 4),
        (0, 4),
        (1, 5),
        (2, 6),
        (3, 7),
    ] {
        obj.push_str(&format!("t crease 2/1/0 {a} {b} 10\n"));
    }
    for v in 0..8 {
        obj.push_str(&format!("t corner 1/1/0 {v} 10\n"));
    }
    let tagged = write(d.path(), "tagged.obj", obj.as_bytes());
    let plain = write(d.path(), "plain.obj", CUBE_OBJ.as_bytes());
    // Distance of a point inside the unit cube to its surface.
    let inside = |p: &[f64]| {
        p.iter()
            .map(|&c| c.min(1.0 - c))
            .fold(f64::INFINITY, f64::min)
    };
    let worst = |cage: &Path, command: &[&str]| -> f64 {
        let out = d.path().join("out.obj");
        let mut args = vec![command[0], cage.to_str().unwrap()];
        args.extend_from_slice(&command[1..]);
        args.extend_from_slice(&["-o", out.to_str().unwrap()]);
        let r = subfit(&args);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let text = std::fs::read_to_string(&out).unwrap();
        text.lines()
            .filter_map(|l| l.strip_prefix("v "))
            .map(|xyz| {
                let p: Vec<f64> = xyz
                    .split_whitespace()
                    .take(3)
                    .map(|t| t.parse().unwrap())
                    .collect();
                inside(&p)
            })
            .fold(0.0, f64::max)
    };
    for command in [
        &["subdivide", "--levels", "3", "--limit"][..],
        &["subdivide", "--levels", "2"][..],
        &["eval", "--samples", "500"][..],
    ] {
        let sharp = worst(&tagged, command);
        let round = worst(&plain, command);
        assert!(sharp < 1e-12, "{command:?}: {sharp}");
        assert!(round > 0.05, "{command:?}: {round}");
    }
}
