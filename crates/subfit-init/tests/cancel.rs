//! Contouring, simplification and the initial control mesh stop with their `Interrupted`
//! errors once their cancellation token is cancelled; `InitOptions::cancel` is the one that
//! counts for `initial_control_mesh`.

use subfit_init::{
    contour, initial_control_mesh, simplify, ContourError, ContourOptions, InitError, InitOptions,
    SimplifyError, SimplifyOptions,
};
use subfit_mesh::shapes::{torus_mesh, Shape};
use subfit_mesh::Cancel;
use subfit_target::{Target, TargetOptions};

fn cancelled() -> Cancel {
    let c = Cancel::new();
    c.cancel();
    c
}

#[test]
fn cancelled_contouring_simplification_and_initial_mesh_return_interrupted() {
    let cloud = Shape::DEFAULT_TORUS.sample(8000, 0.0, 7);
    let t = Target::from_points(
        &cloud.positions,
        cloud.normals.as_deref(),
        &TargetOptions::default(),
    )
    .unwrap();
    let c = ContourOptions {
        cancel: cancelled(),
        ..ContourOptions::default()
    };
    assert_eq!(contour(&t, &c).unwrap_err(), ContourError::Interrupted);

    let mesh = torus_mesh(1.0, 0.35, 120, 60, true);
    let s = SimplifyOptions {
        target_vertices: 200,
        cancel: cancelled(),
        ..SimplifyOptions::default()
    };
    assert_eq!(simplify(&mesh, &s).unwrap_err(), SimplifyError::Interrupted);

    // Point-cloud and mesh paths of the entry point.
    let init = InitOptions {
        cancel: cancelled(),
        ..InitOptions::default()
    };
    assert_eq!(
        initial_control_mesh(&t, None, 200, &init).unwrap_err(),
        InitError::Interrupted
    );
    let mt = Target::from_mesh(&mesh, &TargetOptions::default()).unwrap();
    assert_eq!(
        initial_control_mesh(&mt, Some(&mesh), 200, &init).unwrap_err(),
        InitError::Interrupted
    );

    // The entry point uses its own token, not those of the step options.
    let init = InitOptions {
        contour: c,
        simplify: s,
        ..InitOptions::default()
    };
    let (m, _) = initial_control_mesh(&t, None, 200, &init).unwrap();
    assert!(m.num_vertices() <= 220);
    assert_eq!(ContourError::Interrupted.to_string(), "interrupted");
}
