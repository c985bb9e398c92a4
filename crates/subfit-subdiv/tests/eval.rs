//! Exact evaluation (`eval`): agreement with the level-`l` limit points of the sampling operator at
//! dyadic parameters (faces touching valence 3…9 vertices, boundaries, creases, `n`-gons),
//! derivatives against central differences, weight sums, planes, and scale invariance.
#![allow(
    clippy::print_stdout,
    reason = "the tests report the errors they measured"
)]
#![allow(
    clippy::needless_range_loop,
    reason = "coordinate loops index several arrays"
)]

use std::path::PathBuf;
use subfit_mesh::{Polygons, Tags, SHARPNESS_INFINITE};
use subfit_subdiv::{
    refine, sampling_operator, EvalKind, Evaluator, Options, Scheme, SurfaceParam,
};

type Mesh = (String, Scheme, Vec<[f64; 3]>, Polygons, Tags);

fn read_obj(path: &std::path::Path) -> (Vec<[f64; 3]>, Polygons) {
    let (mesh, _) = subfit_io::read_file(path, &subfit_io::ReadOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    (mesh.positions, mesh.faces)
}

/// Loop bicone: `n` ring vertices (valence 4) and two apices of valence `n`.
fn bicone(n: usize) -> (Vec<[f64; 3]>, Polygons) {
    let mut p = Vec::new();
    for i in 0..n {
        let a = std::f64::consts::TAU * i as f64 / n as f64;
        p.push([a.cos(), a.sin(), 0.1 * (3.0 * a).sin()]);
    }
    p.push([0.1, 0.0, 1.3]);
    p.push([0.0, -0.1, -0.9]);
    let (t, b) = (n as u32, n as u32 + 1);
    let mut f = Polygons::new();
    for i in 0..n as u32 {
        let j = (i + 1) % n as u32;
        f.push(&[i, j, t]);
        f.push(&[j, i, b]);
    }
    (p, f)
}

/// The two rings of `n` points of a slightly tapered, wavy prism (bottom ring first).
fn prism_points(n: usize) -> Vec<[f64; 3]> {
    let mut p = Vec::new();
    for z in [0.0, 1.0] {
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            p.push([
                a.cos() * (1.0 + 0.2 * z),
                a.sin(),
                z + 0.05 * (2.0 * a).cos(),
            ]);
        }
    }
    p
}

/// An `n`-gon prism (two `n`-gons, `n` quads) refined once by Catmull-Clark: quads only, with
/// valence-`n` face points.
fn cc_prism(n: usize) -> (Vec<[f64; 3]>, Polygons) {
    let p = prism_points(n);
    let mut f = Polygons::new();
    let nn = n as u32;
    f.push(&(0..nn).rev().collect::<Vec<_>>());
    f.push(&(nn..2 * nn).collect::<Vec<_>>());
    for i in 0..nn {
        let j = (i + 1) % nn;
        f.push(&[i, j, nn + j, nn + i]);
    }
    let r = refine(
        &f,
        p.len(),
        &Tags::new(),
        &Options::new(Scheme::CatmullClark),
    )
    .unwrap();
    (r.matrix.apply(&p), r.faces)
}

/// A Loop or Catmull-Clark grid over `[0,1]²` (open, with boundary), `n × n` cells.
fn grid(n: usize, tri: bool, z: impl Fn(f64, f64) -> f64) -> (Vec<[f64; 3]>, Polygons) {
    let mut p = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            p.push([x + 0.03 * (7.0 * y).sin(), y, z(x, y)]);
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut f = Polygons::new();
    for j in 0..n {
        for i in 0..n {
            let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            if tri {
                f.push(&[q[0], q[1], q[2]]);
                f.push(&[q[0], q[2], q[3]]);
            } else {
                f.push(&q);
            }
        }
    }
    (p, f)
}

fn corpus() -> Vec<Mesh> {
    let mut out: Vec<Mesh> = Vec::new();
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/golden/opensubdiv");
    for name in [
        "tri_tetrahedron",
        "tri_octahedron",
        "tri_icosahedron_jitter",
        "tri_torus_mixed_valence",
        "tri_bicone_valence9",
        "tri_open_patch",
        "quad_cube",
        "quad_torus",
        "quad_open_patch",
        "ngon_pentagonal_prism",
    ] {
        let path = dir.join(format!("{name}.obj"));
        if !path.exists() {
            println!("notice: {} missing, skipped", path.display());
            continue;
        }
        let (p, f) = read_obj(&path);
        let scheme = if name.starts_with("tri_") {
            Scheme::Loop
        } else {
            Scheme::CatmullClark
        };
        out.push((name.into(), scheme, p, f, Tags::new()));
    }
    for n in [3, 7, 8, 9] {
        let (p, f) = bicone(n);
        out.push((format!("bicone{n}"), Scheme::Loop, p, f, Tags::new()));
    }
    for n in [3, 5, 6, 7] {
        let (p, f) = cc_prism(n);
        out.push((
            format!("cc_prism{n}"),
            Scheme::CatmullClark,
            p,
            f,
            Tags::new(),
        ));
    }
    // Creased grids: an interior sharp crease line and a corner tag.
    for tri in [true, false] {
        let (p, f) = grid(4, tri, |x, y| 0.2 * (3.0 * x).sin() * y);
        let mut tags = Tags::new();
        for j in 0..4u32 {
            tags.set_crease(j * 5 + 2, (j + 1) * 5 + 2, SHARPNESS_INFINITE);
        }
        tags.set_corner(6, SHARPNESS_INFINITE);
        let scheme = if tri {
            Scheme::Loop
        } else {
            Scheme::CatmullClark
        };
        out.push((format!("creased_grid_tri{tri}"), scheme, p, f, tags));
    }
    // The quad/triangle scheme: on the pure meshes above it is Loop or Catmull-Clark; on mixed
    // ones (a half-quad, half-triangle grid, a prism with triangle caps, and the creased grid
    // made mixed) it has patches of both kinds.
    let pure: Vec<Mesh> = out
        .iter()
        .filter(|m| !m.0.starts_with("creased"))
        .map(|(n, _, p, f, t)| {
            (
                format!("{n} (quad-tri)"),
                Scheme::QuadTriangle,
                p.clone(),
                f.clone(),
                t.clone(),
            )
        })
        .collect();
    out.extend(pure);
    let (p, quads) = grid(4, false, |x, y| 0.2 * (3.0 * x).sin() * y + 0.1 * x * x);
    let mut half = Polygons::new();
    for (i, q) in quads.iter().enumerate() {
        if i % 4 >= 2 {
            half.push(&[q[0], q[1], q[2]]);
            half.push(&[q[0], q[2], q[3]]);
        } else {
            half.push(q);
        }
    }
    let mut tags = Tags::new();
    tags.set_crease(2, 7, SHARPNESS_INFINITE);
    tags.set_crease(7, 12, SHARPNESS_INFINITE);
    out.push((
        "half_grid (quad-tri)".into(),
        Scheme::QuadTriangle,
        p.clone(),
        half.clone(),
        Tags::new(),
    ));
    out.push((
        "half_grid_creased (quad-tri)".into(),
        Scheme::QuadTriangle,
        p,
        half,
        tags,
    ));
    for n in [3u32, 5, 6] {
        // A prism of quads with triangle-fan caps, and a triangular prism with triangle caps
        // (n = 3: quad/triangle vertices of valence 3).
        let mut p = prism_points(n as usize);
        let mut f = Polygons::new();
        if n == 3 {
            f.push(&[2, 1, 0]);
            f.push(&[3, 4, 5]);
        } else {
            p.push([0.0, 0.0, -0.2]);
            p.push([0.1, 0.0, 1.2]);
            for i in 0..n {
                let j = (i + 1) % n;
                f.push(&[2 * n, j, i]);
                f.push(&[2 * n + 1, n + i, n + j]);
            }
        }
        for i in 0..n {
            let j = (i + 1) % n;
            f.push(&[i, j, n + j, n + i]);
        }
        out.push((
            format!("capped_prism{n} (quad-tri)"),
            Scheme::QuadTriangle,
            p,
            f,
            Tags::new(),
        ));
    }
    out
}

fn diag(p: &[[f64; 3]]) -> f64 {
    let (lo, hi) = subfit_mesh::bounding_box(p).unwrap();
    ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
}

/// Dyadic parameters of level `l` on every patch of `ev`.
fn dyadic(ev: &Evaluator, l: u32) -> Vec<SurfaceParam> {
    let mut out = Vec::new();
    for p in 0..ev.num_patches() {
        let (face, sub) = ev.patch(p);
        let ll = if ev.num_subpatches(face) > 1 {
            l - 1
        } else {
            l
        };
        let m = 1u32 << ll;
        for j in 0..=m {
            for i in 0..=m {
                if ev.triangle_patch(face) && i + j > m {
                    continue;
                }
                out.push(SurfaceParam {
                    face,
                    sub,
                    u: i as f64 / m as f64,
                    v: j as f64 / m as f64,
                });
            }
        }
    }
    out
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[test]
fn exact_evaluation_matches_limit_points_at_dyadic_parameters() {
    let mut worst = 0.0f64;
    let mut worst_n = 0.0f64;
    for (name, scheme, p, f, tags) in corpus() {
        let opts = Options::new(scheme);
        let ev = Evaluator::new(&f, p.len(), &tags, &opts).unwrap();
        let d = diag(&p);
        for l in [2u32, 3] {
            let s = sampling_operator(&f, p.len(), &tags, &opts, l as usize).unwrap();
            let lim = s.evaluate(&p);
            let mut max_err = 0.0f64;
            let mut max_ang = 0.0f64;
            for q in dyadic(&ev, l) {
                let r = ev.evaluate(&p, q).unwrap();
                let (k, e) = lim
                    .positions
                    .iter()
                    .enumerate()
                    .map(|(k, x)| (k, dist(*x, r.position)))
                    .min_by(|a, b| a.1.total_cmp(&b.1))
                    .unwrap();
                max_err = max_err.max(e / d);
                let n = lim.normals[k];
                let c = n[0] * r.normal[0] + n[1] * r.normal[1] + n[2] * r.normal[2];
                let x = [
                    n[1] * r.normal[2] - n[2] * r.normal[1],
                    n[2] * r.normal[0] - n[0] * r.normal[2],
                    n[0] * r.normal[1] - n[1] * r.normal[0],
                ];
                let sn = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
                // Normals jump across sharp creases: compare them on untagged meshes only.
                if n != [0.0; 3] && tags.is_empty() {
                    max_ang = max_ang.max(sn.atan2(c));
                }
            }
            println!("{name} L{l}: max position error {max_err:.2e} (rel. diag), max normal angle {max_ang:.2e}");
            assert!(max_err < 1e-12, "{name} level {l}: {max_err:e}");
            assert!(max_ang < 1e-9, "{name} level {l}: normal angle {max_ang:e}");
            worst = worst.max(max_err);
            worst_n = worst_n.max(max_ang);
        }
    }
    println!("worst position error {worst:.2e}, worst normal angle {worst_n:.2e}");
}

#[test]
fn derivatives_match_central_differences_and_weights_sum() {
    for (name, scheme, p, f, tags) in corpus() {
        let ev = Evaluator::new(&f, p.len(), &tags, &Options::new(scheme)).unwrap();
        let d = diag(&p);
        let h = 1e-5;
        let mut max_rel = 0.0f64;
        for q in ev.random_params(60, 7) {
            // Keep the stencil inside the domain.
            let (u, v) = if ev.triangular() {
                let s = 0.9;
                (0.03 + s * q.u * 0.9, 0.03 + s * q.v * 0.9)
            } else {
                (0.03 + 0.94 * q.u, 0.03 + 0.94 * q.v)
            };
            let q = SurfaceParam { u, v, ..q };
            let w = ev.weights(q).unwrap();
            assert_eq!(w.kind, EvalKind::Patch);
            assert!((w.position.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            assert!(w.du.iter().sum::<f64>().abs() < 1e-10);
            assert!(w.dv.iter().sum::<f64>().abs() < 1e-10);
            let sec = w.second.as_ref().unwrap();
            for s in sec {
                assert!(
                    s.iter().sum::<f64>().abs() < 1e-8 * (1u64 << (2 * w.depth.min(20))) as f64
                );
            }
            let r = w.apply(&p);
            let at = |du: f64, dv: f64| {
                ev.evaluate(
                    &p,
                    SurfaceParam {
                        u: u + du,
                        v: v + dv,
                        ..q
                    },
                )
                .unwrap()
            };
            let (pu, mu, pv, mv) = (at(h, 0.0), at(-h, 0.0), at(0.0, h), at(0.0, -h));
            let sec = r.second.unwrap();
            let scale = d
                * (1.0
                    + (r.du
                        .iter()
                        .chain(&r.dv)
                        .map(|x| x.abs())
                        .fold(0.0, f64::max))
                        / d);
            for k in 0..3 {
                let checks = [
                    ((pu.position[k] - mu.position[k]) / (2.0 * h), r.du[k]),
                    ((pv.position[k] - mv.position[k]) / (2.0 * h), r.dv[k]),
                    ((pu.du[k] - mu.du[k]) / (2.0 * h), sec[0][k]),
                    ((pv.du[k] - mv.du[k]) / (2.0 * h), sec[1][k]),
                    ((pv.dv[k] - mv.dv[k]) / (2.0 * h), sec[2][k]),
                ];
                for (fd, ex) in checks {
                    let sc = scale.max(ex.abs());
                    max_rel = max_rel.max((fd - ex).abs() / sc);
                }
            }
        }
        println!("{name}: max finite-difference mismatch {max_rel:.2e}");
        assert!(max_rel < 1e-5, "{name}: {max_rel:e}");
    }
}

#[test]
fn vertex_evaluation_at_extraordinary_vertices() {
    let (p, f) = bicone(7);
    let ev = Evaluator::new(&f, p.len(), &Tags::new(), &Options::new(Scheme::Loop)).unwrap();
    // Corner 2 of face 0 is the valence-7 apex.
    let w = ev.weights(SurfaceParam::new(0, 0.0, 1.0)).unwrap();
    assert_eq!(w.kind, EvalKind::Vertex);
    assert!(w.second.is_none());
    assert!((w.position.iter().sum::<f64>() - 1.0).abs() < 1e-14);
    // Approaching the apex, positions converge to the vertex limit.
    let at = w.apply(&p).position;
    for e in [1e-3, 1e-6, 1e-9, 1e-12] {
        let r = ev
            .evaluate(&p, SurfaceParam::new(0, e, 1.0 - 2.0 * e))
            .unwrap();
        assert!(dist(r.position, at) < 10.0 * e.sqrt());
        assert!(r.depth > 0);
    }
}

#[test]
fn planar_control_mesh_gives_planar_surface_and_scaling_is_equivariant() {
    for tri in [true, false] {
        let scheme = if tri {
            Scheme::Loop
        } else {
            Scheme::CatmullClark
        };
        let (p, f) = grid(5, tri, |_, _| 0.0);
        let ev = Evaluator::new(&f, p.len(), &Tags::new(), &Options::new(scheme)).unwrap();
        for q in ev.random_params(200, 3) {
            let r = ev.evaluate(&p, q).unwrap();
            assert!(r.position[2].abs() < 1e-15);
            assert!(r.du[2].abs() < 1e-14 && r.dv[2].abs() < 1e-14);
            assert!((r.normal[2] - 1.0).abs() < 1e-12, "{:?}", r.normal);
        }
    }
    for (name, scheme, p, f, tags) in corpus() {
        let ev = Evaluator::new(&f, p.len(), &tags, &Options::new(scheme)).unwrap();
        let params = ev.random_params(50, 11);
        let base = ev.evaluate_batch(&p, &params).unwrap();
        for s in [1e-6, 1e6] {
            let ps: Vec<[f64; 3]> = p.iter().map(|x| [x[0] * s, x[1] * s, x[2] * s]).collect();
            let scaled = ev.evaluate_batch(&ps, &params).unwrap();
            for (a, b) in base.iter().zip(&scaled) {
                for k in 0..3 {
                    assert!(
                        (a.position[k] * s - b.position[k]).abs() <= 1e-13 * s,
                        "{name}"
                    );
                    assert!((a.normal[k] - b.normal[k]).abs() < 1e-12, "{name}");
                }
            }
        }
    }
}

#[test]
fn bad_parameters_are_typed_errors() {
    let (p, f) = bicone(5);
    let ev = Evaluator::new(&f, p.len(), &Tags::new(), &Options::new(Scheme::Loop)).unwrap();
    assert!(ev.evaluate(&p, SurfaceParam::new(999, 0.1, 0.1)).is_err());
    assert!(ev.evaluate(&p, SurfaceParam::new(0, 0.8, 0.8)).is_err());
    assert!(ev
        .evaluate(&p, SurfaceParam::new(0, f64::NAN, 0.1))
        .is_err());
    assert!(ev
        .evaluate(&p[..3], SurfaceParam::new(0, 0.1, 0.1))
        .is_err());
    let q = Polygons::from_quads(&[[0, 1, 2, 3]]);
    assert!(Evaluator::new(&q, 4, &Tags::new(), &Options::new(Scheme::Loop)).is_err());
}

/// The child face of a uniformly refined mesh (children in `refine`'s order) containing `(u, v)`
/// of face `f`, and the parameters there (all-triangle or all-quad meshes).
fn to_child(tri: bool, f: u32, u: f64, v: f64) -> (u32, f64, f64) {
    if tri {
        let (c, s, t) = if u + v <= 0.5 {
            (0, 2.0 * u, 2.0 * v)
        } else if u >= 0.5 {
            (1, 2.0 * v, 2.0 - 2.0 * u - 2.0 * v)
        } else if v >= 0.5 {
            (2, 2.0 - 2.0 * u - 2.0 * v, 2.0 * u)
        } else {
            (3, 2.0 * u + 2.0 * v - 1.0, 1.0 - 2.0 * u)
        };
        (4 * f + c, s.max(0.0), t.max(0.0))
    } else {
        let (c, s, t) = match (u >= 0.5, v >= 0.5) {
            (false, false) => (0, 2.0 * u, 2.0 * v),
            (true, false) => (1, 2.0 * v, 2.0 - 2.0 * u),
            (true, true) => (2, 2.0 - 2.0 * u, 2.0 - 2.0 * v),
            (false, true) => (3, 2.0 - 2.0 * v, 2.0 * u),
        };
        (4 * f + c, s.clamp(0.0, 1.0), t.clamp(0.0, 1.0))
    }
}

#[test]
fn evaluation_commutes_with_global_refinement() {
    for (name, scheme, p, f, tags) in corpus() {
        let tri = scheme == Scheme::Loop;
        if !tri && !f.is_quads() {
            continue;
        }
        let opts = Options::new(scheme);
        let ev = Evaluator::new(&f, p.len(), &tags, &opts).unwrap();
        let r1 = refine(&f, p.len(), &tags, &opts).unwrap();
        let p1 = r1.matrix.apply(&p);
        let r2 = refine(&r1.faces, p1.len(), &r1.tags, &opts).unwrap();
        let p2 = r2.matrix.apply(&p1);
        let ev2 = Evaluator::new(&r2.faces, p2.len(), &r2.tags, &opts).unwrap();
        let d = diag(&p);
        let mut params = ev.random_params(100, 5);
        // Points close to the corners (extraordinary vertices among them).
        params.extend(ev.random_params(100, 6).into_iter().map(|q| SurfaceParam {
            u: q.u * 1e-4,
            v: q.v * 1e-4,
            ..q
        }));
        let mut max_err = 0.0f64;
        for q in params {
            let (c1, s1, t1) = to_child(tri, q.face, q.u, q.v);
            let (c2, s2, t2) = to_child(tri, c1, s1, t1);
            let a = ev.evaluate(&p, q).unwrap();
            let b = ev2.evaluate(&p2, SurfaceParam::new(c2, s2, t2)).unwrap();
            max_err = max_err.max(dist(a.position, b.position) / d);
        }
        println!("{name}: eval vs eval on the twice-refined mesh: {max_err:.1e}");
        assert!(max_err < 1e-13, "{name}: {max_err:e}");
    }
}

/// The memoisation budget bounds the memory of an evaluator without changing its results:
/// budget 0 memoises nothing, a small budget stops near its limit, the default memoises
/// freely; all agree to round-off, and `clear_cache` gives the memory back.
#[test]
fn cache_budget_bounds_memory_without_changing_results() {
    for (scheme, (p, f)) in [
        (Scheme::Loop, bicone(7)),
        (Scheme::CatmullClark, cc_prism(5)),
    ] {
        let o = Options::new(scheme);
        let mut params = Evaluator::new(&f, p.len(), &Tags::new(), &o)
            .unwrap()
            .random_params(300, 11);
        // Points close to the extraordinary vertices, where local refinement is deep.
        params.extend(dyadic(
            &Evaluator::new(&f, p.len(), &Tags::new(), &o).unwrap(),
            3,
        ));
        let eval_all = |ev: &Evaluator| -> Vec<[f64; 3]> {
            params
                .iter()
                .map(|&q| ev.evaluate(&p, q).unwrap().position)
                .collect()
        };
        let mut free = Evaluator::new(&f, p.len(), &Tags::new(), &o).unwrap();
        let reference = eval_all(&free);
        let used = free.cache_bytes();
        assert!(used > 0, "{scheme:?}: nothing memoised");
        assert!(used <= subfit_subdiv::DEFAULT_CACHE_BYTES);
        let none = Evaluator::new(&f, p.len(), &Tags::new(), &o)
            .unwrap()
            .with_cache_budget(0);
        let small = Evaluator::new(&f, p.len(), &Tags::new(), &o)
            .unwrap()
            .with_cache_budget(used / 4);
        let tol = 1e-12 * diag(&p);
        for ev in [&none, &small] {
            for (a, b) in eval_all(ev).into_iter().zip(&reference) {
                assert!(dist(a, *b) <= tol, "{scheme:?}: {a:?} vs {b:?}");
            }
        }
        assert_eq!(none.cache_bytes(), 0, "{scheme:?}: budget 0 memoised");
        // The per-patch nodes and the shared shapes each stop at most one node or shape past
        // the budget (single-threaded here); both are far below `used`.
        assert!(
            small.cache_bytes() >= used / 4,
            "{scheme:?}: small budget not used"
        );
        assert!(
            small.cache_bytes() < 3 * used / 4,
            "{scheme:?}: small budget exceeded: {} of {used}",
            small.cache_bytes()
        );
        free.clear_cache();
        assert_eq!(free.cache_bytes(), 0);
        for (a, b) in eval_all(&free).into_iter().zip(&reference) {
            assert!(dist(a, *b) <= tol, "{scheme:?}: after clear_cache");
        }
        assert_eq!(
            free.cache_bytes(),
            used,
            "{scheme:?}: memoised again the same"
        );
    }
}

/// `area_weights` make statistics over `random_params` samples area-uniform: on a planar grid
/// whose columns grow as `t³` (patches of very different sizes), the weighted area and
/// centroid match those of the mesh refined five times (within 1 %), while the unweighted
/// centroid lies far off (patches are drawn uniformly).
#[test]
fn area_weights_make_random_samples_area_uniform() {
    for scheme in [Scheme::Loop, Scheme::CatmullClark] {
        let n = 8;
        let mut p = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let t = i as f64 / n as f64;
                p.push([t * t * t, j as f64 / n as f64, 0.0]);
            }
        }
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut f = Polygons::new();
        for j in 0..n {
            for i in 0..n {
                let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
                if scheme == Scheme::Loop {
                    f.push(&[q[0], q[1], q[2]]);
                    f.push(&[q[0], q[2], q[3]]);
                } else {
                    f.push(&q);
                }
            }
        }
        let tags = Tags::default();
        let opts = Options::new(scheme);
        // Reference: the mesh refined five times (its area and area centroid).
        let (mut fr, mut pr, mut tr) = (f.clone(), p.clone(), tags.clone());
        for _ in 0..5 {
            let r = refine(&fr, pr.len(), &tr, &opts).unwrap();
            pr = r.matrix.apply(&pr);
            (fr, tr) = (r.faces, r.tags);
        }
        let (mut area, mut cx) = (0.0, 0.0);
        for face in fr.iter() {
            for k in 1..face.len() - 1 {
                let [a, b, c] = [face[0], face[k], face[k + 1]].map(|v| pr[v as usize]);
                let s = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs();
                area += s;
                cx += s * (a[0] + b[0] + c[0]) / 3.0;
            }
        }
        cx /= area;
        let ev = Evaluator::new(&f, p.len(), &tags, &opts).unwrap();
        let samples = 40_000;
        let (params, points) = subfit_subdiv::random_samples(&ev, &p, samples, 3).unwrap();
        let w = subfit_subdiv::area_weights(&ev, &params, &points);
        let total: f64 = w.iter().sum();
        let est_area = total / samples as f64 * ev.num_patches() as f64;
        let est_cx = w
            .iter()
            .zip(&points)
            .map(|(w, q)| w * q.position[0])
            .sum::<f64>()
            / total;
        let plain_cx = points.iter().map(|q| q.position[0]).sum::<f64>() / samples as f64;
        println!("{scheme:?}: area {est_area:.5} vs {area:.5}; centroid x {est_cx:.5} vs {cx:.5} (unweighted {plain_cx:.5})");
        assert!((est_area / area - 1.0).abs() < 0.01, "{scheme:?}");
        assert!((est_cx / cx - 1.0).abs() < 0.01, "{scheme:?}");
        assert!(
            (plain_cx / cx - 1.0).abs() > 0.2,
            "{scheme:?}: the grid does not discriminate"
        );
    }
}
