//! Tessellation recognition on the corpus (`SUBFIT_CORPUS`; skipped with a notice without it,
//! a failure under `CI=true`): every CAD export of the corpus is a tessellation — the gears
//! whose faces are fans of extreme slivers included — and no scan is.

#![allow(clippy::print_stdout, reason = "each file's figures are printed")]

mod common;

use subfit_mesh::vec3::{norm, sub};
use subfit_target::tessellation::Facets;

#[test]
fn cad_exports_are_tessellations_and_scans_are_not() {
    let Some(dir) = common::corpus_dir("the tessellation recognition on the corpus") else {
        return;
    };
    let manifest = std::fs::read_to_string(dir.join("manifest.tsv")).expect("manifest.tsv");
    let mut seen = [0; 2];
    for line in manifest.lines().skip(1) {
        let cols: Vec<&str> = line.split('\t').collect();
        let (file, category, kind) = (cols[0], cols[1], cols[2]);
        let expected = match (category, kind) {
            ("cad", _) => true,
            ("scan", "mesh") => false,
            _ => continue,
        };
        let (mesh, _) = subfit_io::read_file(&dir.join(file), &Default::default())
            .unwrap_or_else(|e| panic!("{e}"));
        let (lo, hi) = mesh.bounding_box().expect("a mesh");
        let magnitude = lo.iter().chain(&hi).fold(0.0f64, |m, c| m.max(c.abs()));
        let facets = Facets::new(
            &mesh.positions,
            &mesh.faces.triangulate_fan(),
            Facets::float32_tolerance(magnitude, 1.0),
        );
        let s = facets.stats(&mesh.positions);
        println!("{file}: {s:?} (diagonal {:.3})", norm(sub(hi, lo)));
        assert_eq!(s.is_tessellation, expected, "{file}: {s:?}");
        seen[usize::from(expected)] += 1;
    }
    assert!(seen[0] >= 10 && seen[1] >= 10, "scans, CAD parts: {seen:?}");
}
