//! Target construction stops with `TargetError::Interrupted` once its cancellation token is
//! cancelled: before it starts, from inside the per-point fits, and at the start of the
//! orientation, without running the phases that follow.

use std::sync::Mutex;

use subfit_mesh::shapes::Shape;
use subfit_mesh::Cancel;
use subfit_target::{Phase, Progress, Target, TargetError, TargetOptions};

/// Builds the target of a 20k-point ellipsoid cloud (normals estimated), cancelling the token
/// when `when` says so; returns the result and the phases reported.
fn build_cancelling(
    when: impl Fn(Progress) -> bool + Sync,
) -> (Result<Target, TargetError>, Vec<Progress>) {
    let cloud = Shape::PAPER_ELLIPSOID.sample(20_000, 0.002, 5);
    let options = TargetOptions {
        cancel: Cancel::new(),
        ..TargetOptions::default()
    };
    let token = options.cancel.clone();
    let seen = Mutex::new(Vec::new());
    let progress = |p: Progress| {
        seen.lock().unwrap().push(p);
        if when(p) {
            token.cancel();
        }
    };
    let cloud = subfit_mesh::PolyMesh::point_cloud(cloud.positions, None);
    let result = Target::build(&cloud, &options, Some(&progress));
    (result, seen.into_inner().unwrap())
}

#[test]
fn a_cancelled_token_stops_the_construction_early() {
    // Already cancelled: nothing is estimated.
    let (r, seen) = build_cancelling(|p| p.phase == Phase::Validate);
    assert_eq!(r.unwrap_err(), TargetError::Interrupted);
    assert!(seen
        .iter()
        .all(|p| p.phase != Phase::Estimate || p.done == 0));

    // During the per-point fits (after the first chunk): the rest of them and the orientation
    // are not done.
    let (r, seen) = build_cancelling(|p| p.phase == Phase::Estimate && p.done > 0);
    assert_eq!(r.unwrap_err(), TargetError::Interrupted);
    let last = seen
        .iter()
        .rev()
        .find(|p| p.phase == Phase::Estimate)
        .unwrap();
    assert!(last.done < last.total, "{last:?}");
    assert!(seen.iter().all(|p| p.phase != Phase::Orient));

    // At the start of the orientation: it stops inside (spanning tree), before the end.
    let (r, seen) = build_cancelling(|p| p.phase == Phase::Orient);
    assert_eq!(r.unwrap_err(), TargetError::Interrupted);
    assert!(seen.iter().all(|p| p.phase != Phase::Orient || p.done == 0));

    // Never cancelled: the same cloud builds.
    let (r, _) = build_cancelling(|_| false);
    assert!(r.is_ok());
}

#[test]
fn options_differing_only_in_their_token_are_equal() {
    let a = TargetOptions::default();
    let b = TargetOptions {
        cancel: Cancel::new(),
        ..a.clone()
    };
    b.cancel.cancel();
    assert_eq!(a, b);
    assert!(!a.cancel.is_cancelled());
}
