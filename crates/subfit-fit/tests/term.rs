//! The `DataTerm` seam: a second, analytic term (point distance to a sphere,
//! `V = c + r (x − c)/|x − c|`) fits through `Fitter::with_term`; `Fitter::new` is
//! `with_term(FootPointTerm::from_options(..))`; and the foot-point terms' `model` is the
//! Gauss-Newton model of their `squared_error`: the gradient of `Σ_k e_k²` with respect to the
//! control points is `2 Cᵀ r` (finite differences) — PD exactly (with re-projection, on the
//! analytic sphere), TD and SD at fixed foot points (where `Q (S − V) = S − V`).

mod common;

use subfit_fit::{
    DataTerm, FitOptions, Fitter, FootPointSource, FootPointTerm, Mat3, Method, StopReason, Variant,
};
use subfit_mesh::shapes::octahedron_mesh;
use subfit_mesh::{PolyMesh, Tags};
use subfit_subdiv::{refine, sampling_operator, Options, Scheme, StencilMatrix};

use common::{ellipsoid_target, fourteen_vertex_mesh, normalized};

/// Distance to the sphere `|x − c| = r`: PD (`Q = I`) or, not isotropic, TD (`Q = N Nᵀ`).
struct Sphere {
    c: [f64; 3],
    r: f64,
    isotropic: bool,
}

impl Sphere {
    fn foot(&self, x: [f64; 3]) -> [f64; 3] {
        let d: [f64; 3] = std::array::from_fn(|a| x[a] - self.c[a]);
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        std::array::from_fn(|a| self.c[a] + self.r * d[a] / l)
    }
}

impl DataTerm for Sphere {
    /// The foot point `V`.
    type Sample = [f64; 3];

    fn isotropic(&self) -> bool {
        self.isotropic
    }

    fn project(&self, rows: Option<&[u32]>, xs: &[[f64; 3]]) -> Vec<[f64; 3]> {
        if let Some(rows) = rows {
            assert_eq!(rows.len(), xs.len());
        }
        self.project_fresh(xs)
    }

    fn project_fresh(&self, xs: &[[f64; 3]]) -> Vec<[f64; 3]> {
        xs.iter().map(|&x| self.foot(x)).collect()
    }

    fn squared_error(&self, v: &[f64; 3], x: [f64; 3]) -> f64 {
        (0..3).map(|a| (x[a] - v[a]).powi(2)).sum()
    }

    fn model(&self, v: &[f64; 3], x: [f64; 3]) -> (Mat3, [f64; 3]) {
        let e: [f64; 3] = std::array::from_fn(|a| x[a] - v[a]);
        if self.isotropic {
            let q = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            return (q, e);
        }
        let n: [f64; 3] = std::array::from_fn(|a| (v[a] - self.c[a]) / self.r);
        let q: Mat3 = std::array::from_fn(|i| std::array::from_fn(|j| n[i] * n[j]));
        let ne = n[0] * e[0] + n[1] * e[1] + n[2] * e[2];
        (q, n.map(|a| a * ne))
    }

    fn bbox_diagonal(&self) -> f64 {
        2.0 * self.r * 3f64.sqrt()
    }
}

/// The octahedron around `c`, 1.4 r from it, refined once (18 points).
fn sphere_cage(c: [f64; 3], r: f64) -> PolyMesh {
    let oct = octahedron_mesh(1.4 * r, 1.4 * r, 1.4 * r);
    let rf = refine(
        &oct.faces,
        oct.num_vertices(),
        &Tags::new(),
        &Options::new(Scheme::Loop),
    )
    .unwrap();
    let p = rf
        .matrix
        .apply(&oct.positions)
        .into_iter()
        .map(|p| std::array::from_fn(|a| c[a] + p[a]))
        .collect();
    PolyMesh::new(p, rf.faces)
}

#[test]
fn an_analytic_sphere_term_fits_through_with_term() {
    let (c, r) = ([0.5, 0.5, 0.5], 0.3);
    let cage = sphere_cage(c, r);
    let mut converged = Vec::new();
    for (isotropic, variant) in [(true, Variant::PdmSc), (false, Variant::TdmLm)] {
        let opts = FitOptions::variant(variant)
            .with_lambda(0.0)
            .with_max_iterations(60);
        let opts = FitOptions {
            min_relative_decrease: 1e-6,
            ..opts
        };
        let term = Sphere { c, r, isotropic };
        let mut fitter = Fitter::with_term(term, &cage.faces, cage.num_vertices(), &opts).unwrap();
        let mut p = cage.positions.clone();
        let report = fitter.run(&mut p, None).unwrap();
        let (first, last) = (report.initial, report.last());
        // From 0.4 r off to the best an 18-point Loop cage does (about 0.2 % of r), where the
        // iteration stalls.
        assert!(first.e_rms > 0.3 * r, "{isotropic}: {first:?}");
        assert_eq!(report.stop, StopReason::Stalled, "{isotropic}: {report:?}");
        assert!(last.e_rms < 0.005 * r, "{isotropic}: {last:?}");
        // The relative errors are over the term's bounding-box diagonal.
        let diag = 2.0 * r * 3f64.sqrt();
        assert!((last.e_rms_diag - last.e_rms / diag).abs() <= 1e-15);
        // The step control judged every step on the true error: it never went up.
        let mut f = first.objective;
        for row in &report.iterations {
            assert!(row.errors.objective <= f, "{isotropic}: {row:?}");
            f = row.errors.objective;
        }
        // Fresh errors of the result agree with the report.
        let s = fitter.sampling_operator().position.apply(&p);
        let e2 = fitter.squared_errors(&s);
        let rms = (e2.iter().sum::<f64>() / e2.len() as f64).sqrt();
        assert!((rms - last.e_rms).abs() <= 1e-12, "{rms} {}", last.e_rms);
        converged.push(last.objective);
        // An active set goes through the term's rows as well.
        let mask: Vec<bool> = (0..cage.num_vertices()).map(|i| i % 2 == 0).collect();
        fitter.set_active(Some(mask)).unwrap();
        let mut q = cage.positions.clone();
        let rep = fitter.run(&mut q, None).unwrap();
        assert!(rep.last().objective < rep.initial.objective);
        for (i, (a, b)) in q.iter().zip(&cage.positions).enumerate() {
            if i % 2 == 1 {
                assert_eq!(a, b);
            }
        }
    }
    // PD (linear convergence: 9 iterations here) and TD with LM (Gauss-Newton: 3) stop at the
    // same minimum of the true squared distance.
    let (pd, td) = (converged[0], converged[1]);
    assert!((pd - td).abs() <= 1e-5 * pd, "{pd:e} {td:e}");
}

#[test]
fn new_is_with_term_of_the_foot_point_term() {
    let target = ellipsoid_target(6_000);
    let mesh = normalized(&target, &fourteen_vertex_mesh());
    for v in [Variant::SdmLm, Variant::Pdm, Variant::TdmSc] {
        let opts = FitOptions::variant(v)
            .with_lambda(1e-3)
            .with_max_iterations(4);
        let mut a = Fitter::new(&target, &mesh.faces, mesh.num_vertices(), &opts).unwrap();
        let term = FootPointTerm::from_options(&target, &opts);
        assert_eq!(term.isotropic(), v == Variant::Pdm);
        let mut b = Fitter::with_term(term, &mesh.faces, mesh.num_vertices(), &opts).unwrap();
        let (mut pa, mut pb) = (mesh.positions.clone(), mesh.positions.clone());
        let ra = a.run(&mut pa, None).unwrap();
        let rb = b.run(&mut pb, None).unwrap();
        assert_eq!(pa, pb, "{v:?}");
        assert_eq!(ra.iterations.len(), rb.iterations.len());
        for (x, y) in ra.iterations.iter().zip(&rb.iterations) {
            assert_eq!(x.errors, y.errors, "{v:?}");
        }
    }
}

/// `Σ_k e_k²(C P)` with the per-sample state `fixed` (`None`: projected afresh at every
/// evaluation).
fn energy<T: DataTerm>(
    term: &T,
    op: &StencilMatrix,
    p: &[[f64; 3]],
    fixed: Option<&[T::Sample]>,
) -> f64 {
    let s = op.apply(p);
    let fresh;
    let proj = match fixed {
        Some(f) => f,
        None => {
            fresh = term.project_fresh(&s);
            &fresh[..]
        }
    };
    s.iter()
        .zip(proj)
        .map(|(&x, f)| term.squared_error(f, x))
        .sum()
}

/// The largest deviation of the central-difference gradient of [`energy`] at `p` from the
/// model's `2 Cᵀ r`, relative to the largest component of `2 Cᵀ r`.
fn gradient_mismatch<T: DataTerm>(
    term: &T,
    op: &StencilMatrix,
    p: &[[f64; 3]],
    reproject: bool,
) -> f64 {
    let s = op.apply(p);
    let proj = term.project_fresh(&s);
    let mut g = vec![[0.0; 3]; p.len()];
    for (k, (&x, f)) in s.iter().zip(&proj).enumerate() {
        let (_, r) = term.model(f, x);
        let (idx, w) = op.row(k);
        for (&j, &w) in idx.iter().zip(w) {
            for a in 0..3 {
                g[j as usize][a] += 2.0 * w * r[a];
            }
        }
    }
    let fixed = (!reproject).then_some(&proj[..]);
    let h = 1e-6;
    let scale = g.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut worst = 0.0f64;
    for j in 0..p.len() {
        for a in 0..3 {
            let (mut pp, mut pm) = (p.to_vec(), p.to_vec());
            pp[j][a] += h;
            pm[j][a] -= h;
            let fd = (energy(term, op, &pp, fixed) - energy(term, op, &pm, fixed)) / (2.0 * h);
            worst = worst.max((fd - g[j][a]).abs() / scale);
        }
    }
    worst
}

#[test]
fn the_model_is_the_gauss_newton_model_of_the_squared_error() {
    let target = ellipsoid_target(20_000);
    let mesh = normalized(&target, &fourteen_vertex_mesh());
    let op = sampling_operator(
        &mesh.faces,
        mesh.num_vertices(),
        &Tags::new(),
        &Options::new(Scheme::Loop),
        3,
    )
    .unwrap()
    .position;
    // Off the surface by a few percent: foot points on both sides, distances well above
    // the projection tolerance.
    let p: Vec<[f64; 3]> = mesh
        .positions
        .iter()
        .enumerate()
        .map(|(i, x)| {
            let s = 1.0 + 0.03 * ((i as f64 * 1.7).sin());
            std::array::from_fn(|a| 0.5 + s * (x[a] - 0.5))
        })
        .collect();
    for method in [Method::Pdm, Method::Tdm, Method::Sdm] {
        let term = FootPointTerm::new(&target, method, FootPointSource::Quadric);
        let worst = gradient_mismatch(&term, &op, &p, false);
        assert!(worst < 1e-7, "{method:?}: {worst:e}");
        // At the expansion point the model's value is the true error, and for PD it is the
        // error at any displacement with the foot point fixed.
        let s = op.apply(&p);
        for (&x, f) in s.iter().zip(&term.project_fresh(&s)) {
            let (q, r) = term.model(f, x);
            let e: [f64; 3] = std::array::from_fn(|a| x[a] - f.point[a]);
            let value: f64 = (0..3).map(|a| e[a] * r[a]).sum();
            let e2 = term.squared_error(f, x);
            assert!((value - e2).abs() <= 1e-9 * e2.max(1e-12), "{method:?}");
            if method == Method::Pdm {
                assert_eq!(q, [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
                assert_eq!(r, e);
            }
        }
    }
    // PD exactly: the gradient of the true squared distance, re-projected at every
    // evaluation, is 2 Cᵀ (S − V) (on an analytic sphere, where it is smooth).
    let (c, r) = ([0.5, 0.5, 0.5], 0.3);
    let cage = sphere_cage(c, r);
    let op = sampling_operator(
        &cage.faces,
        cage.num_vertices(),
        &Tags::new(),
        &Options::new(Scheme::Loop),
        2,
    )
    .unwrap()
    .position;
    for isotropic in [true, false] {
        let term = Sphere { c, r, isotropic };
        let worst = gradient_mismatch(&term, &op, &cage.positions, true);
        assert!(worst < 1e-7, "{isotropic}: {worst:e}");
    }
}
