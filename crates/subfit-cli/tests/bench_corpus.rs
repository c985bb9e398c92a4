//! `subfit bench corpus` on a plain folder of model files (no manifest): every file is fitted
//! with the defaults by the subfit binary and judged independently; `--rows` takes those rows
//! back without fitting, and a baseline whose error was much lower is an error regression.
#![allow(clippy::print_stdout)]

mod common;

use std::path::Path;
use std::process::Output;

use common::subfit;
use subfit::mesh::shapes::torus_mesh;

fn board(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// `subfit bench corpus MODELS --out OUT EXTRA...`.
fn bench(models: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "bench",
        "corpus",
        models.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    subfit(&args)
}

#[test]
fn a_plain_folder_is_scored_and_its_rows_reused() {
    let d = tempfile::tempdir().unwrap();
    let models = d.path().join("models");
    std::fs::create_dir(&models).unwrap();
    let torus = torus_mesh(0.35, 0.15, 48, 24, true);
    subfit::io::write_file(&models.join("torus.ply"), &torus, &Default::default()).unwrap();
    let out = d.path().join("board.json");
    let r = bench(&models, &out, &["--surface-samples", "20000"]);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let b = board(&out);
    let rows = b["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 1);
    let row = &rows[0];
    assert_eq!(row["kind"], "mesh");
    let (rms, haus) = (
        row["judge"]["rms_fraction"].as_f64().unwrap(),
        row["judge"]["hausdorff_fraction"].as_f64().unwrap(),
    );
    println!("torus: RMS {rms:.3e}, Hausdorff {haus:.3e} of the diagonal");
    // A smooth torus is fitted within the scan tolerances, and the judge agrees with them.
    assert!(rms > 0.0 && rms <= 7.5e-4 && haus <= 7e-3, "{rms} {haus}");
    assert!(out.with_extension("md").is_file());

    // The same rows taken back: no fit runs (no new run folder), the figures are the same.
    let again = d.path().join("again.json");
    let work = d.path().join("again-work");
    let r = bench(
        &models,
        &again,
        &[
            "--rows",
            out.to_str().unwrap(),
            "--work",
            work.to_str().unwrap(),
        ],
    );
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    assert!(!work.join("torus").exists(), "--rows must not fit again");
    let a = board(&again);
    assert_eq!(a["rows"][0]["judge"], row["judge"]);
    assert!(a["sources"][0].as_str().unwrap().contains("board.json"));

    // A row refreshed by a later file keeps the peers an earlier file judged for it.
    let committed: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../bench/corpus-baseline.json"),
        )
        .unwrap(),
    )
    .unwrap();
    let peer = committed["rows"]
        .as_array()
        .unwrap()
        .iter()
        .find_map(|r| r["peers"].as_array().and_then(|p| p.first()).cloned())
        .expect("a peer in the committed baseline");
    let mut peered = b.clone();
    peered["rows"][0]["peers"] = serde_json::json!([peer.clone()]);
    let peered_path = d.path().join("peered.json");
    std::fs::write(&peered_path, serde_json::to_vec(&peered).unwrap()).unwrap();
    let merged = d.path().join("merged.json");
    let r = bench(
        &models,
        &merged,
        &[
            "--rows",
            peered_path.to_str().unwrap(),
            "--rows",
            out.to_str().unwrap(),
        ],
    );
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let m = board(&merged);
    assert_eq!(m["rows"][0]["peers"], serde_json::json!([peer]));
    assert_eq!(m["rows"][0]["judge"], row["judge"]);

    // Against a baseline ten times better, the row is an error regression: exit 1.
    let mut base = b.clone();
    base["rows"][0]["judge"]["rms_fraction"] = serde_json::json!(rms / 10.0);
    let base_path = d.path().join("base.json");
    std::fs::write(&base_path, serde_json::to_vec(&base).unwrap()).unwrap();
    let third = d.path().join("third.json");
    let r = bench(
        &models,
        &third,
        &[
            "--rows",
            out.to_str().unwrap(),
            "--baseline",
            base_path.to_str().unwrap(),
            "--fail-on-regression",
        ],
    );
    assert_eq!(
        r.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&r.stdout)
    );
    assert!(String::from_utf8_lossy(&r.stdout).contains("regression: torus rms"));
}

/// A cage pair whose given cage has faces that disagree in orientation (as one of the
/// corpus's does): the given cage is re-oriented, as the fit's reader does for its input, and
/// judged next to ours, and the row says so.
#[test]
fn a_given_cage_with_flipped_faces_is_reoriented_and_judged() {
    let d = tempfile::tempdir().unwrap();
    let corpus = d.path().join("corpus");
    let pair = corpus.join("pair");
    std::fs::create_dir_all(&pair).unwrap();
    let mut cage = subfit::mesh::shapes::octahedron_mesh(1.0, 0.8, 0.6);
    let mut faces: Vec<Vec<u32>> = cage.faces.iter().map(<[u32]>::to_vec).collect();
    for f in faces.iter_mut().take(3) {
        f.reverse();
    }
    let mut polygons = subfit::mesh::Polygons::new();
    for f in &faces {
        polygons.push(f);
    }
    cage.faces = polygons;
    let dense = subfit::mesh::shapes::geodesic_sphere(3);
    subfit::io::write_file(&pair.join("control.obj"), &cage, &Default::default()).unwrap();
    subfit::io::write_file(&pair.join("dense.obj"), &dense, &Default::default()).unwrap();
    std::fs::write(
        corpus.join("manifest.tsv"),
        "file\tcategory\tkind\npair/control.obj\tcage\tcage-pair\npair/dense.obj\tcage\tcage-pair\n",
    )
    .unwrap();
    let out = d.path().join("board.json");
    let r = bench(&corpus, &out, &["--surface-samples", "20000"]);
    assert!(
        r.status.code().is_some(),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let b = board(&out);
    let row = &b["rows"][0];
    assert_eq!(row["kind"], "cage-pair");
    assert!(
        row["given"]["judge"]["rms_fraction"].as_f64().is_some(),
        "the given cage was not judged: {}",
        row["given"]
    );
    let note = row["note"].as_str().unwrap_or("");
    assert!(note.contains("3 faces re-oriented"), "{note}");
}

/// `--fit-arg` adds a flag to every fit (here `--facing`, and `--coverage 0`): the runs' own
/// reports show it, and the scoreboard records it.
#[test]
fn fit_args_reach_every_fit_and_are_recorded() {
    let d = tempfile::tempdir().unwrap();
    let models = d.path().join("models");
    std::fs::create_dir(&models).unwrap();
    let torus = torus_mesh(0.35, 0.15, 32, 16, true);
    subfit::io::write_file(&models.join("torus.ply"), &torus, &Default::default()).unwrap();
    let out = d.path().join("board.json");
    let work = d.path().join("work");
    let r = bench(
        &models,
        &out,
        &[
            "--surface-samples",
            "20000",
            "--work",
            work.to_str().unwrap(),
            "--fit-arg",
            "--facing",
            "--fit-arg",
            "--coverage",
            "--fit-arg",
            "0",
        ],
    );
    assert!(
        r.status.code() == Some(0),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let b = board(&out);
    assert_eq!(
        b["fit_args"],
        serde_json::json!(["--facing", "--coverage", "0"])
    );
    let report = board(&work.join("torus").join("fit").join("report.json"));
    assert_eq!(report["options"]["facing"], true);
    let md = std::fs::read_to_string(out.with_extension("md")).unwrap();
    assert!(md.contains("`--facing --coverage 0` added"), "{md}");
}
