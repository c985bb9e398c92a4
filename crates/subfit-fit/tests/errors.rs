//! Typed errors: bad options, bad input, non-finite control points; other schemes fit too.

mod common;

use subfit_fit::{fit, FitError, FitOptions, Fitter, Variant};
use subfit_mesh::shapes::cube_mesh;
use subfit_mesh::Polygons;
use subfit_subdiv::Scheme;

#[test]
fn bad_option_is_typed() {
    let target = common::ellipsoid_target(3_000);
    let mesh = common::normalized(&target, &common::fourteen_vertex_mesh());
    let opts = FitOptions::default().with_lambda(-1.0);
    match fit(&target, &mesh, &opts) {
        Err(FitError::BadOption { name, .. }) => assert_eq!(name, "lambda"),
        other => panic!("expected BadOption, got {other:?}"),
    }
}

#[test]
fn non_finite_and_empty_input_are_typed() {
    let target = common::ellipsoid_target(3_000);
    let mesh = common::normalized(&target, &common::fourteen_vertex_mesh());
    let opts = FitOptions::default();
    let mut fitter = Fitter::new(&target, &mesh.faces, mesh.num_vertices(), &opts).unwrap();
    let mut p = mesh.positions.clone();
    p[3][1] = f64::NAN;
    assert!(matches!(
        fitter.run(&mut p, None),
        Err(FitError::NonFinite { iteration: 0, .. })
    ));
    let mut short = mesh.positions[..5].to_vec();
    assert!(matches!(
        fitter.run(&mut short, None),
        Err(FitError::BadInput(_))
    ));
    assert!(matches!(
        Fitter::new(&target, &Polygons::new(), 0, &opts),
        Err(FitError::BadInput(_))
    ));
    // Quads are not valid for Loop.
    let cube = common::normalized(&target, &cube_mesh(0.4));
    assert!(matches!(
        fit(&target, &cube, &opts),
        Err(FitError::ControlMesh(_))
    ));
}

/// Catmull-Clark: a cube cage fitted to the ellipsoid by SDMLM descends and stays finite.
#[test]
fn catmull_clark_cube_fits_ellipsoid() {
    let target = common::ellipsoid_target(6_000);
    let mut cube = cube_mesh(1.0);
    for p in &mut cube.positions {
        *p = target.to_normalized([p[0] * 0.25, p[1] * 0.5, p[2] * 1.0]);
    }
    let opts = FitOptions::variant(Variant::SdmLm)
        .with_scheme(Scheme::CatmullClark)
        .with_lambda(1e-5)
        .with_sample_level(3)
        .with_max_iterations(8);
    let r = fit(&target, &cube, &opts).unwrap();
    assert!(r.control_points.iter().flatten().all(|x| x.is_finite()));
    assert!(
        r.report.last().e_rms < 0.3 * r.report.initial.e_rms,
        "{} -> {}",
        r.report.initial.e_rms,
        r.report.last().e_rms
    );
}
