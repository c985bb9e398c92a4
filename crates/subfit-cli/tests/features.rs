//! Issue 15 end to end: sharp features become creases. `subfit fit` with its defaults on
//! generated CAD-like boxes (open and closed), an L-shaped bracket (concave corners) and on fandisk at Lavoué et al.'s 75 control
//! points (`SUBFIT_DATA`), each measured independently by `subfit compare` against the exact
//! limit surface of the written control.obj, whose crease and corner tags it reads.
//!
//! Without `SUBFIT_DATA` the fandisk test fails when `CI=true`, else prints a notice and passes.
#![allow(clippy::print_stdout)]

mod common;

use std::path::Path;

use common::{data_dir, subfit};
use subfit::mesh::shapes::{gridded_box, l_prism};
use subfit::mesh::{PolyMesh, Polygons};

fn json(args: &[&str]) -> serde_json::Value {
    let r = subfit(args);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{args:?}: {}",
        String::from_utf8_lossy(&r.stderr)
    );
    serde_json::from_slice(&r.stdout).unwrap()
}

/// Fits `model` with `extra` flags into `out` (exit code `code`: 1 is a fit written without
/// reaching its tolerance); returns report.json and `subfit compare` of the cage's limit
/// surface (under the `--scheme` of `extra`, Loop without) with the model.
fn fit_and_compare(
    model: &Path,
    out: &Path,
    extra: &[&str],
    code: i32,
) -> (serde_json::Value, serde_json::Value) {
    let mut args = vec!["fit", model.to_str().unwrap(), "-o", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    let r = subfit(&args);
    assert_eq!(
        r.status.code(),
        Some(code),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    let scheme = extra
        .iter()
        .position(|&a| a == "--scheme")
        .map_or("loop", |i| extra[i + 1]);
    let cmp = json(&[
        "compare",
        out.join("control.obj").to_str().unwrap(),
        model.to_str().unwrap(),
        "--scheme",
        scheme,
        "--samples",
        "50000",
        "--json",
    ]);
    (report, cmp)
}

/// `shapes::rounded_prism(0.08, 40)` (fillets of two facets, sharp rims) written to `dir`.
fn rounded_prism(dir: &Path) -> std::path::PathBuf {
    let prism = dir.join("rounded.obj");
    subfit::io::write_file(
        &prism,
        &subfit::mesh::shapes::rounded_prism(0.08, 40),
        &Default::default(),
    )
    .unwrap();
    prism
}

#[test]
fn boxes_fit_with_creased_cages_of_few_control_points() {
    let d = tempfile::tempdir().unwrap();
    for (name, open) in [("open-box.obj", true), ("box.obj", false)] {
        let model = d.path().join(name);
        subfit::io::write_file(&model, &gridded_box(40, open), &Default::default()).unwrap();
        let out = d.path().join(name.replace(".obj", ""));
        let (report, cmp) = fit_and_compare(&model, &out, &[], 0);
        let (cp, hausdorff) = (
            report["control_points"].as_u64().unwrap(),
            cmp["hausdorff_fraction"].as_f64().unwrap(),
        );
        println!(
            "{name}: {cp} control points, {} creases, {} corners, Hausdorff {hausdorff:.2e} of the diagonal",
            report["tags"]["creases"], report["tags"]["corners"]
        );
        assert!(cp <= 40, "{name}: {cp} control points");
        assert!(hausdorff <= 1e-3, "{name}: Hausdorff {hausdorff}");
        assert!(report["tags"]["creases"].as_u64().unwrap() >= if open { 8 } else { 12 });
        let usda = std::fs::read_to_string(out.join("control.usda")).unwrap();
        for attr in ["creaseIndices", "creaseSharpnesses", "cornerIndices"] {
            assert!(usda.contains(attr), "{name}: control.usda has no {attr}");
        }
        let obj = std::fs::read_to_string(out.join("control.obj")).unwrap();
        assert!(
            obj.contains("\nt crease 2/1/0 "),
            "{name}: control.obj has no crease"
        );
        // The sidecar holds the same tags as the OBJ's `t` lines.
        let sidecar: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("control.tags.json")).unwrap()).unwrap();
        let tags = subfit::io::read_tags_file(&out.join("control.obj"), cp as usize).unwrap();
        assert_eq!(sidecar["vertex_count"].as_u64(), Some(cp));
        let creases: Vec<((u32, u32), f64)> = sidecar["creases"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| {
                let v = c["vertices"].as_array().unwrap();
                let a = v[0].as_u64().unwrap() as u32;
                let b = v[1].as_u64().unwrap() as u32;
                ((a, b), c["sharpness"].as_f64().unwrap())
            })
            .collect();
        assert_eq!(creases, tags.creases(), "{name}");
        assert_eq!(
            sidecar["corners"].as_array().unwrap().len(),
            tags.corners().len()
        );
    }
    // Without features: a smooth cage, no tags, and a rounded box.
    let model = d.path().join("box.obj");
    let (report, cmp) = fit_and_compare(&model, &d.path().join("smooth"), &["--no-features"], 0);
    assert_eq!(report["tags"]["creases"], 0);
    assert!(cmp["hausdorff_fraction"].as_f64().unwrap() > 1e-3);
}

/// The concave corners of an L-shaped bracket: without a crease into their 270° sectors the
/// limit surface folds over its rims there (Hausdorff 8.1e-3 of the diagonal with Loop, 1.2e-3
/// with Catmull-Clark, measured before `subfit_mesh::concave`); with it, the fit is as close
/// as the boxes'.
#[test]
fn an_l_bracket_does_not_fold_at_its_concave_corners() {
    let d = tempfile::tempdir().unwrap();
    let model = d.path().join("l.obj");
    subfit::io::write_file(&model, &l_prism(20), &Default::default()).unwrap();
    for scheme in ["loop", "catmull-clark"] {
        let out = d.path().join(scheme);
        let (report, cmp) = fit_and_compare(&model, &out, &["--scheme", scheme], 0);
        let features = &report["init"]["features"];
        let hausdorff = cmp["hausdorff_fraction"].as_f64().unwrap();
        println!(
            "L bracket, {scheme}: {} control points, {} creases ({} concave sectors split, {} points added), Hausdorff {hausdorff:.2e} of the diagonal",
            report["control_points"], report["tags"]["creases"], features["concave_sectors"], features["concave_points"]
        );
        // A CAD tessellation's own cage (subfit::start_cad) splits its concave sectors to
        // outline vertices; the QEM start reports its splits.
        if !report["init"]["source"]
            .as_str()
            .unwrap_or_default()
            .starts_with("Cad")
        {
            assert_eq!(features["concave_sectors"], 2, "{scheme}");
        }
        assert!(hausdorff <= 1e-3, "{scheme}: Hausdorff {hausdorff}");
    }
}

#[test]
fn fandisk_at_75_control_points_beats_lavoue_and_hoppe() {
    let Some(data) = data_dir() else { return };
    let model = data.join("fandisk.obj");
    let d = tempfile::tempdir().unwrap();
    let (report, cmp) =
    // The budget stops it before the default tolerance: exit code 1, outputs written.
        fit_and_compare(&model, &d.path().join("fit"), &["--max-control-points", "75"], 1);
    let cp = report["control_points"].as_u64().unwrap();
    // Data → surface over the model's surface, in the unit cube of the papers.
    let unit = report["normalized_unit_in_original_units"]
        .as_f64()
        .unwrap();
    let mean = cmp["b_to_a"]["mean"].as_f64().unwrap() / unit;
    let mean_sq = (cmp["b_to_a"]["rms"].as_f64().unwrap() / unit).powi(2);
    println!(
        "fandisk: {cp} control points, {} creases, {} corners; data → surface mean {mean:.3e}, mean squared {mean_sq:.3e} (Lavoué 75 V: 0.78e-3; Hoppe 87 V: L2 0.25e-5)",
        report["tags"]["creases"], report["tags"]["corners"]
    );
    assert!(cp <= 75, "{cp} control points");
    assert!(mean <= 0.78e-3, "mean {mean}");
    assert!(mean_sq <= 0.25e-5, "mean squared {mean_sq}");
    assert!(report["tags"]["creases"].as_u64().unwrap() > 0);
}

/// A washer (outer radius 1, inner 0.45, height 0.5) finely gridded in triangles: a CAD-like
/// part whose four rims are sharp circles.
fn washer() -> PolyMesh {
    let (na, nr, nh) = (128usize, 12usize, 10usize);
    let (big, small, h) = (1.0, 0.45, 0.5);
    let mut index = std::collections::HashMap::new();
    let mut pos: Vec<[f64; 3]> = Vec::new();
    let mut tris: Vec<[u32; 3]> = Vec::new();
    // Vertex at angle step `i`, radius step `j` of `nr` (0 inner, nr outer), height step `k`.
    let mut v = |i: usize, j: usize, k: usize| -> u32 {
        *index.entry((i % na, j, k)).or_insert_with(|| {
            let t = 2.0 * std::f64::consts::PI * (i % na) as f64 / na as f64;
            let r = small + (big - small) * j as f64 / nr as f64;
            pos.push([r * t.cos(), r * t.sin(), h * k as f64 / nh as f64]);
            (pos.len() - 1) as u32
        })
    };
    let mut quad = |q: [u32; 4]| {
        tris.push([q[0], q[1], q[2]]);
        tris.push([q[0], q[2], q[3]]);
    };
    for i in 0..na {
        for j in 0..nr {
            quad([
                v(i, j, nh),
                v(i, j + 1, nh),
                v(i + 1, j + 1, nh),
                v(i + 1, j, nh),
            ]);
            quad([
                v(i, j, 0),
                v(i + 1, j, 0),
                v(i + 1, j + 1, 0),
                v(i, j + 1, 0),
            ]);
        }
        for k in 0..nh {
            quad([
                v(i, nr, k),
                v(i + 1, nr, k),
                v(i + 1, nr, k + 1),
                v(i, nr, k + 1),
            ]);
            quad([
                v(i, 0, k),
                v(i, 0, k + 1),
                v(i + 1, 0, k + 1),
                v(i + 1, 0, k),
            ]);
        }
    }
    PolyMesh::new(pos, Polygons::from_triangles(&tris))
}

#[test]
fn a_washer_keeps_its_sharp_rims_with_fewer_control_points() {
    let d = tempfile::tempdir().unwrap();
    let model = d.path().join("washer.obj");
    subfit::io::write_file(&model, &washer(), &Default::default()).unwrap();
    let (report, cmp) = fit_and_compare(&model, &d.path().join("fit"), &[], 0);
    let (cp, rms, hausdorff) = (
        report["control_points"].as_u64().unwrap(),
        cmp["two_sided_rms_fraction"].as_f64().unwrap(),
        cmp["hausdorff_fraction"].as_f64().unwrap(),
    );
    // Without features the same defaults need 1,184 control points for a rounded washer
    // (Hausdorff 5.6e-3): not run here, it takes minutes.
    println!(
        "washer: {cp} control points, {} creases; two-sided RMS {rms:.2e}, Hausdorff {hausdorff:.2e} of the diagonal",
        report["tags"]["creases"],
    );
    assert!(cp <= 200, "{cp} control points");
    assert!(rms <= 4e-4, "two-sided RMS {rms}");
    assert!(hausdorff <= 2e-3, "Hausdorff {hausdorff}");
    // The exact closest points of compare agree with the fit's own measurement against the
    // limit tessellation (a search stuck near a crease once made compare's 20× larger).
    let fit_max = report["final"]["two_sided"]["e_max_fraction_of_diagonal"]
        .as_f64()
        .unwrap();
    assert!(
        hausdorff <= 2.0 * fit_max + 1e-6,
        "{hausdorff} vs {fit_max}"
    );
}

/// `--semi-sharp`: the rounded long edges of a filleted prism become finite creases (the limit
/// rounds them too), the sharp rims of its flat caps stay infinitely sharp, and a sharp box
/// keeps only infinite creases. The fit reaches the unit-cube tolerance 5e-4 either way.
#[test]
fn semi_sharp_creases_follow_the_fillets() {
    let d = tempfile::tempdir().unwrap();
    let prism = rounded_prism(d.path());
    let out = d.path().join("semi");
    let (report, cmp) = fit_and_compare(&prism, &out, &["--semi-sharp", "--tolerance", "5e-4"], 0);
    let cp = report["control_points"].as_u64().unwrap() as usize;
    let tags = subfit::io::read_tags_file(&out.join("control.obj"), cp).unwrap();
    let sharp = |s: f64| s >= subfit::mesh::SHARPNESS_INFINITE;
    let finite = tags.creases().iter().filter(|c| !sharp(c.1)).count();
    let infinite = tags.creases().iter().filter(|c| sharp(c.1)).count();
    println!(
        "rounded prism, --semi-sharp: {cp} control points, {finite} semi-sharp and {infinite} sharp creases, two-sided RMS {:.2e}, Hausdorff {:.2e} of the diagonal",
        cmp["two_sided_rms_fraction"].as_f64().unwrap(),
        cmp["hausdorff_fraction"].as_f64().unwrap()
    );
    assert!(finite >= 4, "{finite} semi-sharp creases");
    assert!(infinite >= 8, "{infinite} sharp creases (the caps' rims)");
    assert!(cmp["hausdorff_fraction"].as_f64().unwrap() <= 5e-3);
    // The sidecar and the USD carry the finite values.
    let usda = std::fs::read_to_string(out.join("control.usda")).unwrap();
    assert!(usda.contains("creaseSharpnesses"));

    let sharp_box = d.path().join("box.obj");
    subfit::io::write_file(&sharp_box, &gridded_box(24, false), &Default::default()).unwrap();
    let out = d.path().join("box");
    let (report, _) = fit_and_compare(
        &sharp_box,
        &out,
        &["--semi-sharp", "--tolerance", "5e-4"],
        0,
    );
    let cp = report["control_points"].as_u64().unwrap() as usize;
    let tags = subfit::io::read_tags_file(&out.join("control.obj"), cp).unwrap();
    assert!(!tags.creases().is_empty());
    assert!(
        tags.creases().iter().all(|c| sharp(c.1)),
        "{:?}",
        tags.creases()
    );
}

/// Issue 15's hidden check on a CAD-like part with sharp rims, with the defaults: the rounded
/// prism (fillets of two facets, sharp rims on both caps) is a CAD part, its features are
/// detected again from 20° (the facets meet the flat sides at 22.5° kinks), and the fit meets
/// the CAD tolerances: Hausdorff ≤ 2e-3 and two-sided RMS ≤ 4e-4 of the diagonal, tags in
/// control.usda. Before the second detection: 124 control points, Hausdorff 3.4e-3, exit 1.
/// Now the 24-point cage's limit is the prism itself (the fit measures 1e-15); `compare`
/// finds 3e-4 (one sample whose closest point it does not reach exactly) and found 1.4e-3
/// before its descent was retried across creases, hence the bound 1e-3 on it here.
#[test]
fn a_cad_part_with_sharp_rims_meets_the_cad_tolerances_with_the_defaults() {
    let d = tempfile::tempdir().unwrap();
    let prism = rounded_prism(d.path());
    let out = d.path().join("fit");
    let (report, cmp) = fit_and_compare(&prism, &out, &[], 0);
    let (rms, hausdorff) = (
        cmp["two_sided_rms_fraction"].as_f64().unwrap(),
        cmp["hausdorff_fraction"].as_f64().unwrap(),
    );
    println!(
        "rounded prism, defaults: {} control points, features from {}°, two-sided RMS {rms:.2e}, Hausdorff {hausdorff:.2e} of the diagonal",
        report["control_points"], report["init"]["features"]["angle_deg"]
    );
    assert_eq!(report["tolerance_kind"], "cad_part");
    // A CAD tessellation's own cage (subfit::start_cad) when its facets say it is one;
    // otherwise the features detected again from 20°.
    let source = report["init"]["source"].as_str().unwrap_or_default();
    if source.starts_with("Cad") {
        assert!(report["init"]["cad"]["crease_edges"].as_u64().unwrap() > 0);
    } else {
        assert_eq!(report["init"]["features"]["angle_deg"], 20.0);
    }
    assert!(rms <= 4e-4, "two-sided RMS {rms}");
    assert!(hausdorff <= 1e-3, "Hausdorff {hausdorff}");
    let usda = std::fs::read_to_string(out.join("control.usda")).unwrap();
    assert!(usda.contains("creaseIndices") && usda.contains("cornerIndices"));
    // An angle given is the angle used.
    let out = d.path().join("forty");
    // (It reaches the tolerances too since a tessellation's foot points are on its facets.)
    let (report, _) = fit_and_compare(&prism, &out, &["--feature-angle", "40"], 0);
    assert_eq!(report["init"]["features"]["angle_deg"], 40.0);
}
