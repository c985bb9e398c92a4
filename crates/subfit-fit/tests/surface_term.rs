//! A term on the whole sampled surface (`FitOptions::surface_term`): its weighted value is in
//! the objective the fitter reports and judges, and its gradient, pulled back through the
//! sampling operator, moves the fit the way the term asks.

mod common;

use std::sync::Arc;

use subfit_fit::{FitOptions, Fitter, SurfaceTerm, WeightedSurfaceTerm};

/// `mean_k (z_k − z0)²`: pulls every sample towards the plane `z = z0`.
struct Plane {
    z0: f64,
}

impl SurfaceTerm for Plane {
    fn value(&self, samples: &[[f64; 3]], _: &[[u32; 3]]) -> f64 {
        samples
            .iter()
            .map(|s| (s[2] - self.z0).powi(2))
            .sum::<f64>()
            / samples.len() as f64
    }

    fn value_and_gradient(&self, samples: &[[f64; 3]], t: &[[u32; 3]]) -> (f64, Vec<[f64; 3]>) {
        let m = samples.len() as f64;
        let g = samples
            .iter()
            .map(|s| [0.0, 0.0, 2.0 * (s[2] - self.z0) / m])
            .collect();
        (self.value(samples, t), g)
    }
}

fn options(weight: f64) -> FitOptions {
    FitOptions {
        max_iterations: 8,
        surface_term: (weight > 0.0).then(|| WeightedSurfaceTerm {
            term: Arc::new(Plane { z0: 0.5 }),
            weight,
            level: 3,
        }),
        ..FitOptions::default()
    }
}

#[test]
fn the_weighted_value_is_in_the_objective() {
    let target = common::ellipsoid_target(4000);
    let cage = common::normalized(&target, &common::fourteen_vertex_mesh());
    let plain = Fitter::new(&target, &cage.faces, cage.num_vertices(), &options(0.0)).unwrap();
    let with = Fitter::new(&target, &cage.faces, cage.num_vertices(), &options(0.3)).unwrap();
    let samples = plain.sampling_operator().position.apply(&cage.positions);
    let value = Plane { z0: 0.5 }.value(&samples, &[]);
    let (a, b) = (
        plain.evaluate(&cage.positions),
        with.evaluate(&cage.positions),
    );
    assert!(
        (b.objective - a.objective - 0.3 * value).abs() < 1e-12 * b.objective,
        "{} vs {} + 0.3 × {value}",
        b.objective,
        a.objective
    );
    // The distances are the data term's alone.
    assert_eq!(a.e_rms, b.e_rms);
}

#[test]
fn its_gradient_moves_the_fit_and_lm_stays_monotone() {
    let target = common::ellipsoid_target(4000);
    let cage = common::normalized(&target, &common::fourteen_vertex_mesh());
    let spread = |w: f64| {
        let mut f = Fitter::new(&target, &cage.faces, cage.num_vertices(), &options(w)).unwrap();
        let mut p = cage.positions.clone();
        let r = f.run(&mut p, None).unwrap();
        let accepted: Vec<f64> = r
            .iterations
            .iter()
            .filter(|i| i.accepted)
            .map(|i| i.errors.objective)
            .collect();
        assert!(accepted.len() >= 3, "w = {w}: {} accepted", accepted.len());
        assert!(
            accepted.windows(2).all(|x| x[1] <= x[0]),
            "w = {w}: objective not monotone: {accepted:?}"
        );
        let s = f.sampling_operator().position.apply(&p);
        Plane { z0: 0.5 }.value(&s, &[])
    };
    let (free, pulled) = (spread(0.0), spread(2.0));
    // The ellipsoid's long axis is z: flattening it towards z = 0.5 is what the term asks.
    assert!(
        pulled < 0.8 * free,
        "mean (z − 0.5)²: {pulled} with the term, {free} without"
    );
}
