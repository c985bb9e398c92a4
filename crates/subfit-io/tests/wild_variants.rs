//! The format variants met in the wild (`SUBFIT_CORPUS/refused/`): every file is read with the
//! vertex and face counts, normals and bounding-box diagonal of its manifest row (computed by a
//! separate Python script with its own readers, see the corpus's SOURCES.md), or refused with
//! the expected message; plus checks of values and warnings on the files whose variant is
//! about them. Without `SUBFIT_CORPUS`: a failure when `CI=true`, else skipped with a notice.

use std::path::{Path, PathBuf};

use subfit_io::{read_file, FileInfo, ReadOptions};
use subfit_mesh::PolyMesh;

/// The corpus directory, or `None` (with a notice) when it is not set outside CI.
fn corpus() -> Option<PathBuf> {
    match std::env::var_os("SUBFIT_CORPUS") {
        Some(d) => Some(PathBuf::from(d)),
        None => {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "SUBFIT_CORPUS is not set (needed on CI: the directory of shared/corpus)"
            );
            #[allow(clippy::print_stdout)]
            {
                println!("notice: SUBFIT_CORPUS not set, skipping a test that needs the corpus");
            }
            None
        }
    }
}

/// One manifest row of the `refused` category.
struct Row {
    file: String,
    vertices: usize,
    faces: usize,
    normals: bool,
    diagonal: f64,
}

fn refused_rows(dir: &Path) -> Vec<Row> {
    let text = std::fs::read_to_string(dir.join("manifest.tsv")).expect("manifest.tsv");
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().expect("header").split('\t').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).expect(name);
    let (f, c, v, fa, n, d) = (
        col("file"),
        col("category"),
        col("vertices"),
        col("faces"),
        col("normals"),
        col("diagonal"),
    );
    lines
        .map(|l| l.split('\t').collect::<Vec<_>>())
        .filter(|r| r[c] == "refused")
        .map(|r| Row {
            file: r[f].to_string(),
            vertices: r[v].parse().expect("vertex count"),
            faces: r[fa].parse().expect("face count"),
            normals: r[n] == "yes",
            diagonal: r[d].parse().expect("diagonal"),
        })
        .collect()
}

/// Files that must be refused, with the parts their message must hold.
const REFUSALS: &[(&str, &[&str])] = &[(
    "refused/xyz-truncated-ipad.xyz",
    &[
        "xyz-truncated-ipad.xyz",
        "line 35936",
        "seems truncated",
        "without a line break",
        "holds 1 of the 3 values",
    ],
)];

/// Files read with per-vertex colours.
const COLOURED: &[&str] = &[
    "refused/ply-vertex-face-colors.ply",
    "refused/xyz-rgb.xyz",
    "refused/xyz-rgba-7col.xyz",
];

/// Files whose reading must say something, with a part of the warning.
const WARNED: &[(&str, &str)] = &[
    (
        "refused/off-binary.off",
        "little-endian without per-face colour counts",
    ),
    ("refused/obj-mni-format.obj", "MNI"),
    ("refused/ply-header-junk-lines.ply", "line 15 `bye`"),
    ("refused/pts-vtk-cactus.pts", "`p x y z`"),
    ("refused/xyz-rgb.xyz", "colours, not normals"),
    ("refused/xyz-rgba-7col.xyz", "alpha in column 7"),
    ("refused/obj-v-vn-corners.obj", "normalized mean"),
];

fn diagonal(m: &PolyMesh) -> f64 {
    let (lo, hi) = m.bounding_box().expect("points");
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
}

fn check_read(row: &Row, m: &PolyMesh, info: &FileInfo) {
    let name = &row.file;
    assert_eq!(m.positions.len(), row.vertices, "{name}: vertices");
    assert_eq!(m.faces.len(), row.faces, "{name}: faces");
    assert_eq!(m.normals.is_some(), row.normals, "{name}: normals");
    assert_eq!(
        m.colors.is_some(),
        COLOURED.contains(&name.as_str()),
        "{name}: colours"
    );
    // The manifest prints 6 significant digits.
    let d = diagonal(m);
    assert!(
        (d - row.diagonal).abs() <= 1e-5 * row.diagonal,
        "{name}: diagonal {d}, manifest {}",
        row.diagonal
    );
    assert!(m
        .faces
        .indices()
        .iter()
        .all(|&i| (i as usize) < m.positions.len()));
    if let Some(n) = &m.normals {
        assert_eq!(n.len(), m.positions.len(), "{name}");
    }
    for (file, part) in WARNED {
        if file == name {
            assert!(
                info.warnings.iter().any(|w| w.contains(part)),
                "{name}: no warning with {part:?} in {:?}",
                info.warnings
            );
        }
    }
}

#[test]
fn every_refused_variant_reads_or_is_refused_clearly() {
    let Some(dir) = corpus() else { return };
    let rows = refused_rows(&dir);
    // Every file of the folder has a row, and every row is checked.
    let on_disk = std::fs::read_dir(dir.join("refused"))
        .expect("refused/")
        .count();
    assert_eq!(rows.len(), on_disk, "manifest rows vs files in refused/");
    for row in &rows {
        let path = dir.join(&row.file);
        let result = read_file(&path, &ReadOptions::default());
        match REFUSALS.iter().find(|(f, _)| *f == row.file) {
            Some((_, parts)) => {
                let e = match result {
                    Ok((m, _)) => panic!("{}: read {} points", row.file, m.positions.len()),
                    Err(e) => e.to_string(),
                };
                for p in *parts {
                    assert!(e.contains(p), "{}: {e:?} lacks {p:?}", row.file);
                }
            }
            None => {
                let (m, info) = result.unwrap_or_else(|e| panic!("{e}"));
                check_read(row, &m, &info);
            }
        }
    }
}

/// Values the variants are about, read from the files' own text.
#[test]
fn variant_values() {
    let Some(dir) = corpus() else { return };
    let read = |f: &str| read_file(&dir.join(f), &ReadOptions::default()).unwrap();
    // `665187.522077 5648349.895035 241.767693 117 73 49` (and `… 117.0 73.0 49.0 255.0`).
    for f in ["refused/xyz-rgb.xyz", "refused/xyz-rgba-7col.xyz"] {
        let (m, _) = read(f);
        assert_eq!(m.colors.unwrap()[0], [117, 73, 49], "{f}");
        assert_eq!(m.positions[0], [665187.522077, 5648349.895035, 241.767693]);
    }
    // `p 0.534901 0.582131 0.60291` after `d`, `s`, `g` lines.
    let (m, _) = read("refused/pts-vtk-cactus.pts");
    assert_eq!(m.positions[0], [0.534901, 0.582131, 0.60291]);
    // Count line, then `x y z nx ny nz` with unit normals.
    let (m, info) = read("range-dragon-stand-0-normals.pts");
    assert_eq!(m.positions.len(), 41841);
    let n = m.normals.unwrap();
    assert_eq!(n[0], [-0.00113938, 0.735288, -0.677754]);
    assert!(info.warnings.iter().any(|w| w.contains("unit vectors")));
    // The pentagon `f 1// 2// 3// 4// 5//`.
    let (m, _) = read("refused/obj-empty-slots.obj");
    assert_eq!(m.faces.iter().next().unwrap(), &[0, 1, 2, 3, 4]);
    // MNI: `P 0.3 0.3 0.4 10 1 1558`, first point ` -18 -16.85 2.5`.
    let (m, _) = read("refused/obj-mni-format.obj");
    assert_eq!(m.positions[0], [-18.0, -16.85, 2.5]);
}

/// Suzanne with a `vn` per face: the averaged vertex normals are unit vectors on the side the
/// faces around the vertex face (their area-weighted normal, computed from the positions).
#[test]
fn face_normals_become_vertex_normals() {
    let Some(dir) = corpus() else { return };
    let (m, _) = read_file(
        &dir.join("refused/obj-v-vn-corners.obj"),
        &ReadOptions::default(),
    )
    .unwrap();
    let normals = m.normals.as_ref().unwrap();
    let mut geometric = vec![[0.0f64; 3]; m.positions.len()];
    for f in m.faces.iter() {
        let p = |i: usize| m.positions[f[i] as usize];
        // Newell's normal of the polygon (twice its area vector).
        let mut a = [0.0; 3];
        for i in 0..f.len() {
            let (u, v) = (p(i), p((i + 1) % f.len()));
            a[0] += (u[1] - v[1]) * (u[2] + v[2]);
            a[1] += (u[2] - v[2]) * (u[0] + v[0]);
            a[2] += (u[0] - v[0]) * (u[1] + v[1]);
        }
        for &v in f {
            (0..3).for_each(|k| geometric[v as usize][k] += a[k]);
        }
    }
    for (v, (n, g)) in normals.iter().zip(&geometric).enumerate() {
        let len = n.iter().map(|c| c * c).sum::<f64>().sqrt();
        assert!((len - 1.0).abs() < 1e-3, "vertex {v}: |n| = {len}");
        let glen = g.iter().map(|c| c * c).sum::<f64>().sqrt();
        let cos = (0..3).map(|k| n[k] * g[k]).sum::<f64>() / glen;
        assert!(cos > 0.5, "vertex {v}: cos {cos} to its faces' normal");
    }
}
