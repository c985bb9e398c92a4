//! `subfit sequence`: a short generated sequence (`subfit::mesh::deforming`, every frame a
//! mesh of its own resolution) fitted end to end from files; every frame within tolerance,
//! one cage's connectivity in every frame_NNNN.obj, sequence.usda opened by usd-core with one
//! time sample per frame; a bad frame is refused by name with nothing written.
#![allow(clippy::print_stdout)]

mod common;

use common::{available, run_check, subfit};
use subfit::mesh::deforming::{DeformingParams, DeformingSequence};

/// Writes `count` frames of ~`vertices` vertices into `dir`; returns their paths.
fn frames(dir: &std::path::Path, count: usize, vertices: usize) -> Vec<String> {
    let seq = DeformingSequence::new(DeformingParams {
        frames: 12,
        ..DeformingParams::default()
    })
    .unwrap();
    (0..count)
        .map(|i| {
            let p = dir.join(format!("scan_{i}.obj"));
            let f = seq.frame(i, vertices, 7 + i as u64);
            subfit::io::write_file(&p, &f.mesh, &Default::default()).unwrap();
            p.to_str().unwrap().to_string()
        })
        .collect()
}

#[test]
fn a_generated_sequence_is_fitted_with_one_cage_and_plays_in_usd() {
    let dir = tempfile::tempdir().unwrap();
    let files = frames(dir.path(), 3, 3000);
    let out = dir.path().join("out");
    let mut args: Vec<&str> = vec!["sequence"];
    args.extend(files.iter().map(String::as_str));
    args.extend([
        "--control-points",
        "400",
        "--tolerance",
        "0.001",
        "--silhouette-views",
        "2",
        "--silhouette-resolution",
        "48",
        "--fps",
        "30",
        "-o",
        out.to_str().unwrap(),
    ]);
    let r = subfit(&args);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}{}",
        String::from_utf8_lossy(&r.stdout),
        String::from_utf8_lossy(&r.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    let fr = report["frames"].as_array().unwrap();
    assert_eq!(fr.len(), 3);
    for f in fr {
        let rms = f["two_sided"]["e_rms_fraction_of_diagonal"]
            .as_f64()
            .unwrap();
        assert!(rms <= 1e-3, "frame {}: two-sided RMS {rms}", f["index"]);
        assert!(f["drift"]["tangential_motion_rms"].as_f64().unwrap() >= 0.0);
    }
    // One cage: the same faces in every frame, different positions.
    let cages: Vec<_> = (0..3)
        .map(|i| {
            subfit::io::read_file(&out.join(format!("frame_{i:04}.obj")), &Default::default())
                .unwrap()
                .0
        })
        .collect();
    assert!(cages[0].num_vertices() <= 400);
    for c in &cages[1..] {
        assert_eq!(c.faces, cages[0].faces);
        assert_ne!(c.positions, cages[0].positions);
    }
    if available("pxr", None) {
        let usd = run_check(
            "sequence_usd.py",
            &[out.join("sequence.usda").to_str().unwrap()],
        );
        assert_eq!(usd["samples"], 3);
        assert_eq!(usd["start"], 0.0);
        assert_eq!(usd["end"], 2.0);
        assert_eq!(usd["fps"], 30.0);
        assert_eq!(usd["points_per_sample"][0], cages[0].num_vertices());
        assert_eq!(usd["scheme"], "loop");
    }
}

#[test]
fn a_bad_frame_is_named_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let mut files = frames(dir.path(), 2, 1500);
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap();
    files.push(bad.to_str().unwrap().to_string());
    let out = dir.path().join("out");
    let mut args: Vec<&str> = vec!["sequence"];
    args.extend(files.iter().map(String::as_str));
    args.extend(["--control-points", "80", "--silhouette-views", "0", "-o"]);
    args.push(out.to_str().unwrap());
    let r = subfit(&args);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(err.contains("bad.obj"), "{err}");
    let left: Vec<_> = std::fs::read_dir(&out)
        .map(|d| d.flatten().map(|e| e.file_name()).collect())
        .unwrap_or_default();
    assert!(left.is_empty(), "{left:?}");
}

/// `--markers`: a marker file is read and its markers reach the tracking of every frame
/// (report.json); a marker in a frame that is not given, a bad line, or markers without the
/// tracking step are refused with nothing written.
#[test]
fn markers_are_read_and_bad_marker_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let files = frames(dir.path(), 2, 1500);
    let seq = DeformingSequence::new(DeformingParams {
        frames: 12,
        ..DeformingParams::default()
    })
    .unwrap();
    let rest = seq.frame(0, 1500, 7);
    let mut csv = String::from("frame,marker,x,y,z\n");
    for i in rest.spread_vertices(6) {
        for t in 0..2 {
            let p = seq.deform(t, rest.material[i]);
            csv += &format!("{t},v{i},{},{},{}\n", p[0], p[1], p[2]);
        }
    }
    let run = |markers: &str, extra: &[&str], out: &std::path::Path| {
        let path = dir.path().join("markers.csv");
        std::fs::write(&path, markers).unwrap();
        let mut args: Vec<&str> = vec!["sequence"];
        args.extend(files.iter().map(String::as_str));
        args.extend(["--control-points", "80", "--silhouette-views", "0"]);
        args.extend(extra);
        args.extend([
            "--markers",
            path.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        subfit(&args)
    };
    let out = dir.path().join("ok");
    let r = run(&csv, &[], &out);
    // 80 control points may leave a frame short of the tolerance (exit 1, outputs written).
    assert!(
        matches!(r.status.code(), Some(0 | 1)),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["frames"][1]["tracking"]["markers"], 6, "{report}");
    for (markers, extra, says) in [
        (
            format!("{csv}2,v0,0,0,0\n"),
            &[][..],
            "given in frame 2, but only 2 frames",
        ),
        (
            "frame,marker,x,y,z\n0,a,1,2,x\n".to_string(),
            &[][..],
            "markers.csv:2: z must be",
        ),
        (
            csv.clone(),
            &["--track-nodes", "0"][..],
            "--markers needs the tracking step",
        ),
    ] {
        let out = dir.path().join("refused");
        let r = run(&markers, extra, &out);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{err}");
        assert!(err.contains(says), "{err}");
        assert!(!out.exists() || std::fs::read_dir(&out).unwrap().next().is_none());
    }
}
