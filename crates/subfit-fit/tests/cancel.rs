//! Fitting stops with `FitError::Interrupted` once the options' cancellation token is
//! cancelled: before the first iteration, and from a progress callback after the first
//! iteration (the next one is not run).

mod common;

use subfit_fit::{fit, fit_stages, FitError, FitOptions, Fitter, StageEvent, StageOptions};
use subfit_mesh::Cancel;

use common::{ellipsoid_target, fourteen_vertex_mesh, normalized};

fn options() -> FitOptions {
    FitOptions {
        cancel: Cancel::new(),
        ..FitOptions::default().with_max_iterations(10)
    }
}

#[test]
fn a_cancelled_token_stops_the_fitter_and_the_stages() {
    let target = ellipsoid_target(5_000);
    let mesh = normalized(&target, &fourteen_vertex_mesh());

    // Cancelled before: no iteration.
    let opts = options();
    opts.cancel.cancel();
    assert!(matches!(
        fit(&target, &mesh, &opts),
        Err(FitError::Interrupted)
    ));

    // Cancelled after the first iteration: the loop stops at the top of the second.
    let opts = options();
    let mut fitter = Fitter::new(&target, &mesh.faces, mesh.num_vertices(), &opts).unwrap();
    let mut control = mesh.positions.clone();
    let mut rows = 0;
    let token = opts.cancel.clone();
    let mut cb = |_: &subfit_fit::IterationRow| {
        rows += 1;
        token.cancel();
    };
    assert!(matches!(
        fitter.run(&mut control, Some(&mut cb)),
        Err(FitError::Interrupted)
    ));
    assert_eq!(rows, 1);
    assert!(FitError::Interrupted.to_string().contains("interrupted"));

    // The stages: cancelled at their first iteration, they stop there.
    let opts = options();
    let stages = StageOptions {
        tolerance_rms: 1e-6,
        max_control_points: 2000,
        ..StageOptions::default()
    };
    let token = opts.cancel.clone();
    let mut iterations = 0;
    let mut on_event = |e: StageEvent<'_>| {
        if let StageEvent::Iteration { .. } = e {
            iterations += 1;
            token.cancel();
        }
    };
    assert!(matches!(
        fit_stages(&target, &mesh, &opts, &stages, Some(&mut on_event)),
        Err(FitError::Interrupted)
    ));
    assert_eq!(iterations, 1);

    // Not cancelled: the same fit runs.
    assert!(fit(&target, &mesh, &options()).is_ok());
}
