//! A thin spike the cage cuts off, fitted as a user runs `subfit fit` (issue 48: "data that is
//! far from the limit surface decides where control points go"). The data → surface part of
//! the objective pulls an uncovered data point towards its nearest limit sample along the data
//! normal (point-to-plane); at a tip the gap runs along the surface, the point's tangent plane
//! passes through the sample, and that pull is nil: the fit stalled with the tip cut off. Such
//! gaps now pull point-to-point (`subfit_fit::coverage::TANGENTIAL_GAP`).

#![allow(clippy::print_stdout)]

mod common;

use common::subfit;

use subfit::mesh::shapes::geodesic_sphere;
use subfit::mesh::PolyMesh;

/// A unit sphere (10,242 vertices) with a thin spike: the vertices within 3° of a direction
/// pushed out by up to 0.6 (seven vertices, the tip 1.6 from the centre).
fn spiked_sphere() -> PolyMesh {
    let mut mesh = geodesic_sphere(5);
    let d: [f64; 3] = {
        let d = [0.3f64, 0.2, 0.93];
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        d.map(|x| x / l)
    };
    let mut moved = 0;
    for p in &mut mesh.positions {
        let c = (p[0] * d[0] + p[1] * d[1] + p[2] * d[2]).clamp(-1.0, 1.0);
        let s = (1.0 - c.acos().to_degrees() / 3.0).max(0.0);
        if s > 0.0 {
            moved += 1;
        }
        *p = p.map(|x| x * (1.0 + 0.6 * s));
    }
    assert_eq!(moved, 7, "the spike's vertices");
    mesh
}

#[test]
fn a_thin_spike_is_covered_to_its_tip() {
    let d = tempfile::tempdir().unwrap();
    let model = d.path().join("spiked.obj");
    subfit::io::write_file(&model, &spiked_sphere(), &Default::default()).unwrap();
    let out = d.path().join("fit");
    let r = subfit(&[
        "fit",
        model.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]);
    let stderr = String::from_utf8_lossy(&r.stderr);
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    let two = &report["final"]["two_sided"];
    let diagonal = report["bbox_diagonal_unit_cube"].as_f64().unwrap();
    let to_surface = two["data_to_surface"]["max"].as_f64().unwrap() / diagonal;
    let cps = report["control_points"].as_u64().unwrap();
    println!(
        "spiked sphere: {cps} control points, data → surface max {:.3} % of the diagonal, exit {:?}",
        100.0 * to_surface,
        r.status.code()
    );
    // Before the tangential pull the tip stayed 0.86 % of the diagonal off (stalled above the
    // 0.70 % tolerance, exit 1); with it 0.66 %, within the tolerance.
    assert!(
        to_surface <= 7e-3,
        "the spike's tip is {:.3} % of the diagonal from the limit surface: {stderr}",
        100.0 * to_surface
    );
    assert_eq!(r.status.code(), Some(0), "{stderr}");
    assert!(cps <= 400, "{cps} control points");
    assert_eq!(report["target_topology"]["genus"], 0);
}
