//! Issue 13's artist check, on a model of our own making: a dense mesh whose Catmull-Clark
//! limit comes from an artist-like mixed cage of 201 points (`shapes::creature_cage`) plus
//! sculpted detail of RMS 5e-4 of the diagonal that no 201-point cage holds. The artist's cage
//! then fits the model at 5.0e-4 (RMS) and 1.7e-3 (Hausdorff) of the diagonal, as the hidden
//! model's does (4.97e-4, 2.18e-3). Measured by `subfit compare` (exact closest points on the
//! limit surface, both ways), `subfit fit --max-control-points 201` with both quad schemes
//! beats the artist's RMS with a cage of ≥ 70 % quads. The issue asks for the Hausdorff
//! distance too: fitted from three starts under the budget (`subfit::BUDGET_STARTS`), the
//! better kept, and with left-over triangles merged in hexagons (`subfit_init::hexagons`),
//! the fits' is 1.72e-3 (Catmull-Clark) and 1.57e-3 (quad/tri) of the diagonal, below this
//! artist's 1.74e-3 and the hidden artist's 2.18e-3. From one start at 0.6 of the budget
//! they were 2.20e-3 and 1.80e-3; started at the budget, Catmull-Clark was at 3.11e-3, the
//! largest errors at the legs' junctions with the body. The test holds the Hausdorff distance
//! below the 2.18e-3 and within 1.1× of this artist's.

#![allow(clippy::print_stdout)]

mod common;

use std::path::Path;

use common::subfit;
use subfit::io::{read_file, write_file, ReadOptions, WriteOptions};
use subfit::mesh::shapes::{creature_cage, XorShift};
use subfit::mesh::vec3::dot;

/// `(two-sided RMS, Hausdorff)` of `a` against `b` as fractions of the diagonal
/// (`subfit compare --json`).
fn compare(a: &Path, b: &Path, scheme: &str) -> (f64, f64) {
    let out = subfit(&[
        "compare",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--scheme",
        scheme,
        "--samples",
        "100000",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    (
        v["two_sided_rms_fraction"].as_f64().unwrap(),
        v["hausdorff_fraction"].as_f64().unwrap(),
    )
}

/// The model: the cage's Catmull-Clark limit at level 4 (55k points), every point moved along
/// its limit normal by a sum of 12 plane waves of random directions and phases (wavelength 0.08 ×
/// the diagonal, ±30 %), scaled to RMS 5e-4 of the diagonal.
fn sculpt(cage: &Path, model: &Path, dir: &Path) {
    let base = dir.join("base.ply");
    let out = subfit(&[
        "subdivide",
        cage.to_str().unwrap(),
        "--scheme",
        "catmull-clark",
        "--levels",
        "4",
        "--limit",
        "-o",
        base.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (mut m, _) = read_file(&base, &ReadOptions::default()).unwrap();
    // `--limit` writes the limit surface's own unit normals.
    let normals = m.normals.take().expect("limit normals in base.ply");
    let (lo, hi) = m.bounding_box().unwrap();
    let diagonal = (0..3).map(|i| (hi[i] - lo[i]).powi(2)).sum::<f64>().sqrt();
    let mut rng = XorShift::new(1);
    let waves: Vec<([f64; 3], f64, f64)> = (0..12)
        .map(|_| {
            let d = [rng.normal(), rng.normal(), rng.normal()];
            let l = dot(d, d).sqrt();
            let wavelength = 0.08 * diagonal * (0.7 + 0.6 * rng.uniform());
            (
                d.map(|x| x / l),
                wavelength,
                std::f64::consts::TAU * rng.uniform(),
            )
        })
        .collect();
    let h: Vec<f64> = m
        .positions
        .iter()
        .map(|&p| {
            waves
                .iter()
                .map(|&(d, w, phase)| (std::f64::consts::TAU * dot(p, d) / w + phase).sin())
                .sum()
        })
        .collect();
    let rms = (h.iter().map(|x| x * x).sum::<f64>() / h.len() as f64).sqrt();
    let scale = 5e-4 * diagonal / rms;
    for ((p, n), h) in m.positions.iter_mut().zip(&normals).zip(&h) {
        for i in 0..3 {
            p[i] += scale * h * n[i];
        }
    }
    write_file(model, &m, &WriteOptions::default()).unwrap();
}

#[test]
fn at_201_control_points_both_quad_schemes_beat_the_artists_rms() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let cage = d.join("cage.obj");
    write_file(&cage, &creature_cage(), &WriteOptions::default()).unwrap();
    let model = d.join("model.ply");
    sculpt(&cage, &model, d);
    let (artist_rms, artist_max) = compare(&cage, &model, "catmull-clark");
    println!("artist's cage: RMS {artist_rms:.3e}, Hausdorff {artist_max:.3e} of the diagonal");
    // The model is made as the hidden one is described.
    assert!((4e-4..6e-4).contains(&artist_rms), "{artist_rms}");
    assert!((1.2e-3..3e-3).contains(&artist_max), "{artist_max}");
    for scheme in ["catmull-clark", "quad-tri"] {
        let out = d.join(scheme);
        let r = subfit(&[
            "fit",
            model.to_str().unwrap(),
            "--scheme",
            scheme,
            "--max-control-points",
            "201",
            "-o",
            out.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&r.stderr);
        assert!(matches!(r.status.code(), Some(0 | 1)), "{scheme}: {stderr}");
        let report: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
        let points = report["control_points"].as_u64().unwrap();
        let quads = report["control_quad_fraction"].as_f64().unwrap();
        let (rms, max) = compare(&out.join("control.obj"), &model, scheme);
        println!(
            "{scheme}: {points} control points, {:.0} % quads, RMS {rms:.3e}, Hausdorff {max:.3e}",
            100.0 * quads
        );
        assert!(points <= 201, "{scheme}: {points}");
        assert!(quads >= 0.7, "{scheme}: {quads}");
        assert!(
            rms < artist_rms,
            "{scheme}: RMS {rms} vs the artist's {artist_rms}"
        );
        assert!(
            max < 2.18e-3 && max < 1.1 * artist_max,
            "{scheme}: Hausdorff {max} vs the artist's {artist_max} (and the issue's 2.18e-3)"
        );
    }
}
