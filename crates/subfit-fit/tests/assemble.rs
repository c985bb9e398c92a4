//! The in-place assembly equals a brute-force dense assembly; the sparse solve solves it; the
//! assembled gradient matches finite differences of the true objective on a sphere.

// The dense reference is written with explicit indices on purpose (it mirrors the formula).
#![allow(clippy::needless_range_loop)]
use subfit_fit::internals::{
    error_matrix, weighted_residuals, CholeskySolver, Laplacian, Pattern, SolveFailure,
};
use subfit_fit::{Mat3, Method};
use subfit_mesh::shapes::octahedron_mesh;
use subfit_mesh::vec3::{self, cross};
use subfit_mesh::{PolyMesh, Tags};
use subfit_subdiv::{sampling_operator, Options, SamplingOperator, Scheme};
use subfit_target::FootPoint;

fn setup(level: usize) -> (PolyMesh, SamplingOperator) {
    let mesh = octahedron_mesh(0.3, 0.4, 0.5);
    let op = sampling_operator(
        &mesh.faces,
        mesh.num_vertices(),
        &Tags::new(),
        &Options::new(Scheme::Loop),
        level,
    )
    .unwrap();
    (mesh, op)
}

/// A deterministic pseudo-random number in [-1, 1).
fn rnd(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// `v / |v|` ([`vec3::unit`]); NaN for a zero vector.
fn normalize(v: [f64; 3]) -> [f64; 3] {
    vec3::unit(v).unwrap_or([f64::NAN; 3])
}

/// The foot point of `x` on the sphere `|x − c| = r` (outward normal), exact.
fn sphere_foot(x: [f64; 3], c: [f64; 3], r: f64) -> FootPoint {
    let n = normalize([x[0] - c[0], x[1] - c[1], x[2] - c[2]]);
    let helper = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let t1 = normalize(cross(n, helper));
    let t2 = cross(n, t1);
    let dist = ((x[0] - c[0]).powi(2) + (x[1] - c[1]).powi(2) + (x[2] - c[2]).powi(2)).sqrt();
    let d = dist - r;
    let alpha = if d > 0.0 { d / (d + r) } else { 0.0 };
    FootPoint {
        point: [c[0] + r * n[0], c[1] + r * n[1], c[2] + r * n[2]],
        distance: d,
        normal: n,
        t1,
        t2,
        k1: -1.0 / r,
        k2: -1.0 / r,
        rho1: -r,
        rho2: -r,
        alpha1: alpha,
        alpha2: alpha,
        nearest: 0,
    }
}

/// Dense `H` from the definition, `b·n × b·n`.
fn dense_h(
    op: &SamplingOperator,
    mesh: &PolyMesh,
    q: &[Mat3],
    w_e: f64,
    w_s: f64,
    block: usize,
) -> Vec<Vec<f64>> {
    let n = mesh.num_vertices();
    let dim = block * n;
    let mut h = vec![vec![0.0; dim]; dim];
    // Dense C.
    for k in 0..op.position.nrows() {
        let mut c = vec![0.0; n];
        let (idx, w) = op.position.row(k);
        for (&i, &w) in idx.iter().zip(w) {
            c[i as usize] += w;
        }
        for i in 0..n {
            for j in 0..n {
                let cc = w_e * c[i] * c[j];
                if block == 1 {
                    h[i][j] += cc;
                } else {
                    for a in 0..3 {
                        for b in 0..3 {
                            h[3 * i + a][3 * j + b] += cc * q[k][a][b];
                        }
                    }
                }
            }
        }
    }
    // Dense umbrella Laplacian from the edges, independently of `Laplacian`.
    let mut adj = vec![vec![false; n]; n];
    for f in mesh.faces.iter() {
        for e in 0..f.len() {
            let (a, b) = (f[e] as usize, f[(e + 1) % f.len()] as usize);
            adj[a][b] = true;
            adj[b][a] = true;
        }
    }
    let mut l = vec![vec![0.0; n]; n];
    for i in 0..n {
        let deg = adj[i].iter().filter(|&&x| x).count() as f64;
        l[i][i] = 1.0;
        for j in 0..n {
            if adj[i][j] {
                l[i][j] = -1.0 / deg;
            }
        }
    }
    for i in 0..n {
        for j in 0..n {
            let ltl: f64 = (0..n).map(|r| l[r][i] * l[r][j]).sum();
            for a in 0..block {
                h[block * i + a][block * j + a] += w_s * ltl;
            }
        }
    }
    h
}

fn random_q(m: usize, method: Method, seed: u64) -> Vec<Mat3> {
    let mut s = seed;
    (0..m)
        .map(|_| {
            let x = [rnd(&mut s), rnd(&mut s), rnd(&mut s)];
            let r = 0.3 + 0.2 * rnd(&mut s);
            error_matrix(method, &sphere_foot(x, [0.0; 3], r))
        })
        .collect()
}

fn check_against_dense(method: Method, level: usize) {
    let (mesh, op) = setup(level);
    let n = mesh.num_vertices();
    let m = op.position.nrows();
    let lap = Laplacian::umbrella(&mesh.faces, n);
    let block = if method == Method::Pdm { 1 } else { 3 };
    let pattern = Pattern::new(&op.position, &lap, block);
    let q = random_q(m, method, 42);
    let (w_e, w_s) = (1.0 / m as f64, 1e-3 / n as f64);
    let mut values = vec![f64::NAN; pattern.nnz()];
    pattern.fill(&op.position, &q, w_e, w_s, &mut values);
    let h = dense_h(&op, &mesh, &q, w_e, w_s, block);
    let dim = block * n;
    let mut seen = vec![vec![false; dim]; dim];
    let scale = h.iter().flatten().fold(0.0f64, |a, &b| a.max(b.abs()));
    for (r, c, v) in pattern.triplets(&values) {
        assert!(r <= c, "upper triangle only");
        assert!(!seen[r][c], "duplicate entry ({r},{c})");
        seen[r][c] = true;
        assert!(
            (v - h[r][c]).abs() <= 1e-12 * scale,
            "{method:?} ({r},{c}): {v} vs {}",
            h[r][c]
        );
    }
    for r in 0..dim {
        for c in r..dim {
            if !seen[r][c] {
                assert!(h[r][c].abs() <= 1e-14 * scale, "missing entry ({r},{c})");
            }
        }
    }

    // The sparse Cholesky solves H x = b.
    let mut s = 5u64;
    let b: Vec<f64> = (0..3 * n).map(|_| rnd(&mut s)).collect();
    let mut x = b.clone();
    let nrhs = 3 / block;
    CholeskySolver::new()
        .solve(&pattern, &values, &mut x, nrhs)
        .expect("SPD");
    for col in 0..nrhs {
        for r in 0..dim {
            let hx: f64 = (0..dim).map(|c| h[r][c] * x[col * dim + c]).sum();
            let bb = b[col * dim + r];
            assert!(
                (hx - bb).abs() < 1e-8 * (1.0 + bb.abs()),
                "residual {}",
                hx - bb
            );
        }
    }
}

#[test]
fn sd_assembly_matches_dense() {
    check_against_dense(Method::Sdm, 2);
}

#[test]
fn td_assembly_matches_dense() {
    check_against_dense(Method::Tdm, 2);
}

#[test]
fn pd_assembly_matches_dense() {
    check_against_dense(Method::Pdm, 2);
}

/// `2g` equals the gradient of the true objective `1/m Σ dist²(S_k, sphere) + λ/n ‖LP‖²` with
/// respect to the control points (envelope theorem: foot points may be frozen), checked by
/// central differences.
#[test]
fn gradient_matches_finite_differences_of_true_objective() {
    let (mesh, op) = setup(2);
    let n = mesh.num_vertices();
    let m = op.position.nrows();
    let lap = Laplacian::umbrella(&mesh.faces, n);
    let pattern = Pattern::new(&op.position, &lap, 3);
    let (c, r) = ([0.01, -0.02, 0.03], 0.35);
    let (w_e, w_s) = (1.0 / m as f64, 1e-2 / n as f64);
    let objective = |p: &[[f64; 3]]| -> f64 {
        let s = op.position.apply(p);
        let e: f64 = s
            .iter()
            .map(|x| {
                let d =
                    ((x[0] - c[0]).powi(2) + (x[1] - c[1]).powi(2) + (x[2] - c[2]).powi(2)).sqrt();
                (d - r).powi(2)
            })
            .sum();
        w_e * e + w_s * lap.energy(p)
    };
    for method in [Method::Sdm, Method::Tdm, Method::Pdm] {
        let p = mesh.positions.clone();
        let s = op.position.apply(&p);
        let feet: Vec<FootPoint> = s.iter().map(|&x| sphere_foot(x, c, r)).collect();
        let q: Vec<Mat3> = feet.iter().map(|f| error_matrix(method, f)).collect();
        let v: Vec<[f64; 3]> = feet.iter().map(|f| f.point).collect();
        let res = weighted_residuals(&s, &v, Some(&q));
        let g = pattern.gradient(&res, &p, w_e, w_s);
        let h = 1e-6;
        for i in 0..n {
            for a in 0..3 {
                let mut pp = p.clone();
                pp[i][a] += h;
                let mut pm = p.clone();
                pm[i][a] -= h;
                let fd = (objective(&pp) - objective(&pm)) / (2.0 * h);
                assert!(
                    (2.0 * g[i][a] - fd).abs() < 1e-7,
                    "{method:?} ({i},{a}): {} vs {fd}",
                    2.0 * g[i][a]
                );
            }
        }
    }
}

/// An indefinite matrix gives a typed failure, not NaNs.
#[test]
fn indefinite_system_is_reported() {
    let (mesh, op) = setup(1);
    let n = mesh.num_vertices();
    let lap = Laplacian::umbrella(&mesh.faces, n);
    let pattern = Pattern::new(&op.position, &lap, 3);
    let q = random_q(op.position.nrows(), Method::Sdm, 3);
    let mut values = vec![0.0; pattern.nnz()];
    pattern.fill(&op.position, &q, 1.0, 0.0, &mut values);
    for v in &mut values {
        *v = -*v;
    }
    let mut rhs = vec![1.0; 3 * n];
    let r = CholeskySolver::new().solve(&pattern, &values, &mut rhs, 1);
    assert!(
        matches!(r, Err(SolveFailure::NotPositiveDefinite { .. })),
        "{r:?}"
    );
}
