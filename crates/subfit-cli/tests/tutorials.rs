//! The guide's tutorials run as written: every `sh` block of docs/guide/*.md is run in a
//! folder holding small inputs under the names the tutorials use (`scan.ply`, `part.stl`,
//! `frames/`, `scans/`), with `subfit` on the PATH. Lines of other tools (`usdview`, `pip`,
//! `python`) are skipped; a fit may exit 1 (a tolerance missed, outputs written), never 2.

mod common;

use std::path::Path;
use std::process::Command;

use subfit::io::{Encoding, WriteOptions};
use subfit::mesh::deforming::{DeformingParams, DeformingSequence};
use subfit::mesh::shapes::Shape;
use subfit::mesh::{PolyMesh, Polygons};

/// The `sh` blocks of a Markdown file.
fn sh_blocks(markdown: &str) -> Vec<String> {
    let mut blocks = Vec::new();
    let mut current: Option<String> = None;
    for line in markdown.lines() {
        match (&mut current, line.trim_start()) {
            (None, "```sh") => current = Some(String::new()),
            (Some(b), "```") => {
                blocks.push(std::mem::take(b));
                current = None;
            }
            (Some(b), _) => {
                b.push_str(line);
                b.push('\n');
            }
            _ => {}
        }
    }
    blocks
}

/// A closed box of `n × n` quads per side split into triangles (a CAD part: 12 sharp edges,
/// 8 corners), side 20 (millimetres, say).
fn cad_box(n: u32) -> PolyMesh {
    let mut positions = Vec::new();
    let mut index = std::collections::HashMap::new();
    let mut tris = Vec::new();
    let grid = |i: u32| 20.0 * f64::from(i) / f64::from(n);
    for axis in 0..3 {
        for side in [0, n] {
            let mut id = |a: u32, b: u32| {
                let mut c = [0u32; 3];
                c[axis] = side;
                c[(axis + 1) % 3] = a;
                c[(axis + 2) % 3] = b;
                *index.entry(c).or_insert_with(|| {
                    positions.push([grid(c[0]), grid(c[1]), grid(c[2])]);
                    (positions.len() - 1) as u32
                })
            };
            for a in 0..n {
                for b in 0..n {
                    let q = [id(a, b), id(a + 1, b), id(a + 1, b + 1), id(a, b + 1)];
                    // Outward orientation: flip the low side.
                    let (t0, t1) = ([q[0], q[1], q[2]], [q[0], q[2], q[3]]);
                    if side == 0 {
                        tris.push([t0[0], t0[2], t0[1]]);
                        tris.push([t1[0], t1[2], t1[1]]);
                    } else {
                        tris.push(t0);
                        tris.push(t1);
                    }
                }
            }
        }
    }
    PolyMesh::new(positions, Polygons::from_triangles(&tris))
}

fn write(path: &Path, mesh: &PolyMesh) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    let opts = WriteOptions {
        format: None,
        encoding: Encoding::BinaryLittleEndian,
        single_precision: false,
    };
    subfit::io::write_file(path, mesh, &opts).unwrap();
}

/// The tutorials' inputs, small.
fn inputs(dir: &Path) {
    let torus = Shape::builtin()
        .into_iter()
        .find(|(name, _)| *name == "torus")
        .unwrap()
        .1;
    write(&dir.join("scan.ply"), &torus.sample(3_000, 0.0, 1));
    write(&dir.join("part.stl"), &cad_box(6));
    write(&dir.join("scans/a.ply"), &torus.sample(2_000, 0.0, 2));
    write(
        &dir.join("scans/b.ply"),
        &Shape::PAPER_ELLIPSOID.sample(2_000, 0.0, 3),
    );
    let seq = DeformingSequence::new(DeformingParams {
        frames: 12,
        ..DeformingParams::default()
    })
    .unwrap();
    for i in 0..3 {
        write(
            &dir.join(format!("frames/frame_{i:03}.ply")),
            &seq.frame(i, 1_500, 7 + i as u64).mesh,
        );
    }
}

/// Runs one shell snippet in `dir` with `subfit` on the PATH; the exit code.
fn sh(dir: &Path, bin: &Path, script: &str) -> (Option<i32>, String) {
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let out = Command::new("sh")
        .arg("-c")
        .arg(script)
        .current_dir(dir)
        .env("PATH", path)
        .output()
        .expect("run sh");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Whether a line is a command of ours (or shell around it) rather than another tool's.
fn ours(line: &str) -> bool {
    let l = line.trim_start();
    l.is_empty()
        || l.starts_with('#')
        || ["subfit ", "for ", "done", "mkdir "]
            .iter()
            .any(|p| l.starts_with(p))
        || line.starts_with("  ")
}

#[test]
fn every_guide_runs_as_written() {
    let d = tempfile::tempdir().unwrap();
    let work = d.path().join("work");
    inputs(&work);
    let bin = d.path().join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_subfit"), bin.join("subfit")).unwrap();
    let guides = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/guide");
    let mut names: Vec<_> = std::fs::read_dir(&guides)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    names.sort();
    let mut ran = 0;
    for guide in names {
        for block in sh_blocks(&std::fs::read_to_string(&guide).unwrap()) {
            let script: String = block
                .lines()
                .filter(|l| ours(l))
                .map(|l| format!("{l}\n"))
                .collect();
            if !script.contains("subfit ") {
                continue;
            }
            let (code, err) = sh(&work, &bin, &script);
            assert!(
                code.is_some_and(|c| c <= 1),
                "{}: exit {code:?}:\n{script}\n{err}",
                guide.display()
            );
            ran += script.matches("subfit ").count();
        }
    }
    assert!(ran >= 8, "{ran} tutorial commands ran");
    // What the tutorials promise.
    let usda = std::fs::read_to_string(work.join("cage/control.usda")).unwrap();
    assert!(
        usda.contains("catmullClark"),
        "the Blender cage is Catmull-Clark"
    );
    let part = std::fs::read_to_string(work.join("part/control.usda")).unwrap();
    assert!(
        part.contains("creaseIndices"),
        "the CAD part's cage has creases"
    );
    assert!(work.join("seq2/sequence.usda").is_file());
    for scan in ["a", "b"] {
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(work.join(format!("out/{scan}.json"))).unwrap())
                .unwrap();
        assert!(json["control_points"].as_u64().unwrap() > 0, "{json}");
    }
}
