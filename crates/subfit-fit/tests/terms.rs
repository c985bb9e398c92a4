//! The SD term is the second-order Taylor model of the true squared distance (Cheng 2007
//! eq. 5–6, sign convention of §II-D3), checked on a sphere where everything is analytic.

use subfit_fit::internals::{error_matrix, mul, quadratic};
use subfit_fit::Method;
use subfit_target::FootPoint;

const C: [f64; 3] = [0.4, 0.5, 0.6];
const R: f64 = 0.3;

fn true_sq_dist(x: [f64; 3]) -> f64 {
    let d = ((x[0] - C[0]).powi(2) + (x[1] - C[1]).powi(2) + (x[2] - C[2]).powi(2)).sqrt();
    (d - R).powi(2)
}

/// The frame at the sphere point in direction (θ, φ), with the sample at signed distance `d`:
/// outward normal, ρ1 = ρ2 = −r (centre opposite to N), α = d/(d − ρ) = d/(d + r).
fn sphere_foot(theta: f64, phi: f64, d: f64) -> ([f64; 3], FootPoint) {
    let n = [
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    ];
    let t1 = [
        theta.cos() * phi.cos(),
        theta.cos() * phi.sin(),
        -theta.sin(),
    ];
    let t2 = [-phi.sin(), phi.cos(), 0.0];
    let v = [C[0] + R * n[0], C[1] + R * n[1], C[2] + R * n[2]];
    let x = [v[0] + d * n[0], v[1] + d * n[1], v[2] + d * n[2]];
    let rho = -R;
    let alpha = (d / (d - rho)).max(0.0);
    let foot = FootPoint {
        point: v,
        distance: d,
        normal: n,
        t1,
        t2,
        k1: 1.0 / rho,
        k2: 1.0 / rho,
        rho1: rho,
        rho2: rho,
        alpha1: alpha,
        alpha2: alpha,
        nearest: 0,
    };
    (x, foot)
}

fn model(method: Method, foot: &FootPoint, x: [f64; 3]) -> f64 {
    let e = [
        x[0] - foot.point[0],
        x[1] - foot.point[1],
        x[2] - foot.point[2],
    ];
    quadratic(&error_matrix(method, foot), e)
}

const DIRS: [[f64; 3]; 4] = [
    [1.0, 0.0, 0.0],
    [0.3, -0.8, 0.52],
    [-0.6, 0.1, 0.79],
    [0.0, 0.0, 1.0],
];

/// For a point at distance d = 0.05 outside, |model − true| = O(h³): halving h divides the
/// discrepancy by ≈ 8, and it is ≤ C h³.
#[test]
fn sd_is_second_order_model_of_squared_distance() {
    let (x0, foot) = sphere_foot(0.7, 1.1, 0.05);
    assert!((model(Method::Sdm, &foot, x0) - true_sq_dist(x0)).abs() < 1e-15);
    for dir in DIRS {
        let err = |h: f64| {
            let x = [x0[0] + h * dir[0], x0[1] + h * dir[1], x0[2] + h * dir[2]];
            (model(Method::Sdm, &foot, x) - true_sq_dist(x)).abs()
        };
        let (e1, e2, e3) = (err(1e-2), err(5e-3), err(2.5e-3));
        assert!(e1 < 50.0 * 1e-6, "{e1}");
        assert!(e2 < e1 / 6.0 && e3 < e2 / 6.0, "not cubic: {e1} {e2} {e3}");
    }
    // TD and PD are only first-order accurate tangentially: their error is O(h²) there.
    let tangent = foot.t1;
    let h = 1e-2;
    let x = [
        x0[0] + h * tangent[0],
        x0[1] + h * tangent[1],
        x0[2] + h * tangent[2],
    ];
    let sd = (model(Method::Sdm, &foot, x) - true_sq_dist(x)).abs();
    let td = (model(Method::Tdm, &foot, x) - true_sq_dist(x)).abs();
    let pd = (model(Method::Pdm, &foot, x) - true_sq_dist(x)).abs();
    assert!(
        sd < td / 100.0 && sd < pd / 100.0,
        "sd {sd} td {td} pd {pd}"
    );
}

/// Sign convention: inside the sphere (d < 0, centre on the side N does not point to… i.e.
/// ρ < 0 and d < 0 share the sign) `[α]₊ = 0`: SD reduces to TD.
#[test]
fn sd_reduces_to_td_inside_convex_surface() {
    let (_, foot) = sphere_foot(0.3, 0.2, -0.05);
    assert_eq!(foot.alpha1, 0.0);
    assert_eq!(
        error_matrix(Method::Sdm, &foot),
        error_matrix(Method::Tdm, &foot)
    );
}

fn fd_grad(f: impl Fn([f64; 3]) -> f64, x: [f64; 3], h: f64) -> [f64; 3] {
    std::array::from_fn(|a| {
        let mut p = x;
        let mut m = x;
        p[a] += h;
        m[a] -= h;
        (f(p) - f(m)) / (2.0 * h)
    })
}

/// The model's gradient `2Q(x − V)` matches finite differences of the true squared distance:
/// exactly at the sample point (any d), and to O(|x − x0|²) nearby; at zero residual (d = 0)
/// SD = TD = N Nᵀ, the true Hessian there.
#[test]
fn model_gradient_matches_true_squared_distance() {
    for d in [0.0, 0.03, -0.02] {
        let (x0, foot) = sphere_foot(1.2, -0.4, d);
        let q = error_matrix(Method::Sdm, &foot);
        let grad_model = |x: [f64; 3]| {
            let e = [
                x[0] - foot.point[0],
                x[1] - foot.point[1],
                x[2] - foot.point[2],
            ];
            let qe = mul(&q, e);
            [2.0 * qe[0], 2.0 * qe[1], 2.0 * qe[2]]
        };
        let g_true = fd_grad(true_sq_dist, x0, 1e-6);
        let g_model = grad_model(x0);
        for a in 0..3 {
            assert!(
                (g_true[a] - g_model[a]).abs() < 1e-8,
                "d={d}: {g_true:?} vs {g_model:?}"
            );
        }
        if d >= 0.0 {
            // Nearby, the gradients agree to second order (SD is the Newton model).
            for dir in DIRS {
                let errs: Vec<f64> = [1e-3, 5e-4]
                    .iter()
                    .map(|&h| {
                        let x = [x0[0] + h * dir[0], x0[1] + h * dir[1], x0[2] + h * dir[2]];
                        let gt = fd_grad(true_sq_dist, x, 1e-7);
                        let gm = grad_model(x);
                        (0..3).map(|a| (gt[a] - gm[a]).abs()).fold(0.0, f64::max)
                    })
                    .collect();
                assert!(errs[0] < 1e-5, "d={d}: {errs:?}");
                assert!(errs[1] < errs[0] / 2.5 || errs[1] < 1e-8, "d={d}: {errs:?}");
            }
        }
    }
}
