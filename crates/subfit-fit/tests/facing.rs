//! Foot points that face the sample's side inside thin parts (`FitOptions::facing`,
//! `Target::mesh_foot_points_facing`): a wall of the limit surface that has sunk past the
//! middle of a thin plate is drawn by the plain closest point to the opposite wall and stays
//! there; facing foot points pull it back to its own side.

use subfit_fit::{FitOptions, Fitter};
use subfit_measure::MeshDistance;
use subfit_mesh::thin_shapes::coin;
use subfit_mesh::PolyMesh;
use subfit_subdiv::{sampling_operator, Options, Scheme};
use subfit_target::{Target, TargetOptions};

/// The largest distance from the level-3 limit samples of `control` to the target's triangles
/// (normalized units): the surface → data error a user would measure.
fn surface_to_data(target: &Target, data: &PolyMesh, cage: &PolyMesh, control: &[[f64; 3]]) -> f64 {
    let op = sampling_operator(
        &cage.faces,
        cage.num_vertices(),
        &Default::default(),
        &Options::new(Scheme::Loop),
        3,
    )
    .unwrap();
    let samples = op.position.apply(control);
    let points: Vec<[f64; 3]> = data
        .positions
        .iter()
        .map(|&p| target.to_normalized(p))
        .collect();
    MeshDistance::new(&points, &data.faces)
        .distances(&samples)
        .iter()
        .fold(0.0f64, |m, d| m.max(d.distance))
}

#[test]
fn facing_foot_points_pull_a_sunk_wall_out_of_a_thin_plate() {
    // A plate 0.04 thick and 1.04 across; the cage is a coarser plate whose bottom face is
    // pushed up past the middle within 0.25 of the axis.
    let thickness = 0.04;
    let data = coin(0.5, thickness, 96, 8);
    let target = Target::from_mesh(&data, &TargetOptions::default()).unwrap();
    let mut cage = coin(0.5, thickness, 24, 3);
    let mut dented = 0;
    for p in &mut cage.positions {
        if p[2] < -0.4 * thickness && p[0].hypot(p[1]) < 0.25 {
            p[2] = 0.2 * thickness;
            dented += 1;
        }
    }
    assert!(dented >= 4, "{dented} cage vertices dented");
    let cage_positions: Vec<[f64; 3]> = cage
        .positions
        .iter()
        .map(|&p| target.to_normalized(p))
        .collect();
    let thickness = thickness * target.normalization().scale;
    let mut errors = Vec::new();
    for facing in [false, true] {
        let opts = FitOptions {
            coverage: 1.0,
            facing,
            lambda: 1e-5,
            max_iterations: 40,
            ..FitOptions::default()
        };
        let mut fitter = Fitter::new(&target, &cage.faces, cage.num_vertices(), &opts).unwrap();
        let mut p = cage_positions.clone();
        fitter.run(&mut p, None).unwrap();
        errors.push(surface_to_data(&target, &data, &cage, &p) / thickness);
    }
    // Closest points leave the dent on the far wall; facing ones bring it home.
    assert!(
        errors[0] > 0.3,
        "closest points: {:.3} of the thickness",
        errors[0]
    );
    assert!(errors[1] < 0.1, "facing: {:.3} of the thickness", errors[1]);
}
