//! The quad/triangle scheme on mixed meshes: limits are invariant under refinement, plain
//! refinement converges to them, and normals are continuous across quad/triangle seams. The
//! reductions to Loop and Catmull-Clark are checked against OpenSubdiv in `golden.rs`.
//! Evaluation through the cached refinement steps agrees with plain local refinement.
#![allow(
    clippy::print_stdout,
    reason = "the tests report the figures they measured"
)]

use subfit_mesh::{Polygons, Tags};
use subfit_subdiv::{refine, sampling_operator, Evaluator, Options, Scheme, SurfaceParam};

/// A closed cylinder of `m` quads around, capped by triangle fans (ring vertices see two
/// quads and two triangles; the cap centres are Loop vertices of valence `m`).
fn capped_cylinder(m: u32) -> (Vec<[f64; 3]>, Polygons) {
    let mut p = Vec::new();
    for z in [0.0, 1.0] {
        for i in 0..m {
            let a = 2.0 * std::f64::consts::PI * i as f64 / m as f64;
            let r = 0.6 + 0.05 * (3.0 * a).sin();
            p.push([r * a.cos(), r * a.sin(), z + 0.03 * (2.0 * a).cos()]);
        }
    }
    p.push([0.0, 0.0, -0.1]);
    p.push([0.02, 0.0, 1.15]);
    let (bot, top) = (2 * m, 2 * m + 1);
    let mut f = Polygons::new();
    for i in 0..m {
        let j = (i + 1) % m;
        f.push(&[i, j, m + j, m + i]);
        f.push(&[bot, j, i]);
        f.push(&[top, m + i, m + j]);
    }
    (p, f)
}

/// An open 4 × 4 grid, quads on the left half and triangles on the right.
fn half_and_half() -> (Vec<[f64; 3]>, Polygons) {
    let n = 4u32;
    let id = |i: u32, j: u32| i * (n + 1) + j;
    let mut p = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            let (x, y) = (j as f64, i as f64);
            p.push([x, y, 0.1 * (x * 0.9).sin() * (y * 0.7).cos() + 0.02 * x * y]);
        }
    }
    let mut f = Polygons::new();
    for i in 0..n {
        for j in 0..n {
            let q = [id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)];
            if j < n / 2 {
                f.push(&q);
            } else {
                f.push(&[q[0], q[1], q[2]]);
                f.push(&[q[0], q[2], q[3]]);
            }
        }
    }
    (p, f)
}

/// A closed cube-like cage with a pentagon (a vertex added on one edge, joined to the opposite
/// corner of the next side), quads and triangles.
fn pentagon_cage() -> (Vec<[f64; 3]>, Polygons) {
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.05],
        [1.1, 1.0, 0.0],
        [0.0, 1.0, -0.05],
        [0.0, 0.0, 1.0],
        [1.0, 0.05, 1.0],
        [1.0, 1.0, 1.1],
        [0.0, 1.0, 1.0],
        [0.5, 1.05, 1.05],
    ];
    let mut f = Polygons::new();
    f.push(&[0, 3, 2, 1]);
    f.push(&[0, 1, 5]);
    f.push(&[0, 5, 4]);
    f.push(&[1, 2, 6, 5]);
    f.push(&[2, 3, 7, 8]);
    f.push(&[2, 8, 6]);
    f.push(&[3, 0, 4, 7]);
    f.push(&[4, 5, 6, 8, 7]);
    (p, f)
}

fn diag(p: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for q in p {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
}

fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d: f64 = (0..3).map(|k| a[k] * b[k]).sum();
    let c = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt().atan2(d)
}

const QT: Options = Options {
    scheme: Scheme::QuadTriangle,
    boundary: subfit_subdiv::BoundaryRule::EdgeOnly,
    triangles: subfit_subdiv::TriangleRule::Catmark,
};

fn meshes() -> Vec<(&'static str, Vec<[f64; 3]>, Polygons, bool)> {
    let (a, b) = capped_cylinder(6);
    let (c, d) = half_and_half();
    let (e, f) = pentagon_cage();
    vec![
        ("capped cylinder", a, b, true),
        ("half quads, half triangles", c, d, false),
        ("a pentagon, quads, triangles", e, f, true),
    ]
}

#[test]
fn refinement_splits_triangles_into_triangles_and_quads_into_quads() {
    let (p, f) = capped_cylinder(6);
    let r = refine(&f, p.len(), &Tags::new(), &QT).unwrap();
    let tris = r.faces.iter().filter(|x| x.len() == 3).count();
    let quads = r.faces.iter().filter(|x| x.len() == 4).count();
    assert_eq!((tris, quads), (4 * 12, 4 * 6));
    // V + E + #non-triangles.
    assert_eq!(r.num_vertices, p.len() + 30 + 6);
    for row in 0..r.matrix.nrows() {
        let (_, w) = r.matrix.row(row);
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-14);
    }
}

#[test]
fn limits_are_invariant_under_one_more_refinement() {
    for (name, p, f, closed) in meshes() {
        let scale = diag(&p);
        let mut prev = sampling_operator(&f, p.len(), &Tags::new(), &QT, 0)
            .unwrap()
            .evaluate(&p);
        for level in 1..=3 {
            let s = sampling_operator(&f, p.len(), &Tags::new(), &QT, level)
                .unwrap()
                .evaluate(&p);
            let (mut dmax, mut amax) = (0.0f64, 0.0f64);
            // Vertex ids persist: the first vertices of level k are those of level k − 1.
            for (i, (a, b)) in prev.positions.iter().zip(&s.positions).enumerate() {
                dmax = dmax.max(dist(*a, *b) / scale);
                amax = amax.max(angle(prev.normals[i], s.normals[i]));
            }
            println!(
                "{name}: level {} → {level}: |dp|/diag {dmax:.2e}, angle {amax:.2e}",
                level - 1
            );
            assert!(dmax < 1e-10, "{name} level {level}: {dmax:e}");
            if closed {
                assert!(
                    amax < 1e-6,
                    "{name} level {level}: normals differ by {amax:e} rad"
                );
            }
            prev = s;
        }
    }
}

#[test]
fn plain_refinement_converges_to_the_limit() {
    for (name, p, f, _) in meshes() {
        let scale = diag(&p);
        let limit = sampling_operator(&f, p.len(), &Tags::new(), &QT, 0)
            .unwrap()
            .evaluate(&p)
            .positions;
        let (mut faces, mut pos, mut tags) = (f.clone(), p.clone(), Tags::new());
        let mut errors = Vec::new();
        let levels = if name.starts_with("capped") { 8 } else { 7 };
        for _ in 0..levels {
            let r = refine(&faces, pos.len(), &tags, &QT).unwrap();
            pos = r.matrix.apply(&pos);
            faces = r.faces;
            tags = r.tags;
            let e = (0..p.len())
                .map(|v| dist(pos[v], limit[v]) / scale)
                .fold(0.0, f64::max);
            errors.push(e);
        }
        println!("{name}: max |refined − limit| / diag per level {errors:?}");
        for k in 1..errors.len() {
            if errors[k] < 1e-13 {
                break;
            }
            assert!(
                errors[k - 1] / errors[k] >= 1.5,
                "{name}: level {} error {:e}, level {} error {:e}",
                k,
                errors[k - 1],
                k + 1,
                errors[k]
            );
        }
        assert!(*errors.last().unwrap() < 1e-4, "{name}: {errors:?}");
    }
}

#[test]
fn normals_are_continuous_across_quad_triangle_seams() {
    // The largest angle between a mixed vertex's limit normal and those of its neighbours at
    // level l shrinks as l grows (the limit surface has a tangent plane there).
    for (name, p, f, _) in meshes() {
        let mut spreads = Vec::new();
        for level in 1..=5 {
            let op = sampling_operator(&f, p.len(), &Tags::new(), &QT, level).unwrap();
            let s = op.evaluate(&p);
            let topo = subfit_subdiv::Topology::new(&op.faces, op.num_vertices).unwrap();
            let mut spread = 0.0f64;
            for v in 0..p.len() as u32 {
                if topo.is_boundary_vertex(v) {
                    continue;
                }
                for &u in topo.vertex_ring(v) {
                    spread = spread.max(angle(s.normals[v as usize], s.normals[u as usize]));
                }
            }
            spreads.push(spread);
        }
        println!("{name}: max normal angle to level-l neighbours {spreads:?}");
        for k in 1..spreads.len() {
            assert!(spreads[k] < 0.8 * spreads[k - 1], "{name}: {spreads:?}");
        }
    }
}

/// Random parameters of every patch of `ev`, points at distances `1e-2 … 1e-13` from each patch
/// corner (towards the patch centre, jittered), and points on the patch edges (which never
/// reach a regular patch next to a seam and descend the deepest).
fn probe_params(ev: &Evaluator) -> Vec<SurfaceParam> {
    let mut params = ev.random_params(400, 17);
    let jitter = ev.random_params(ev.num_patches() * 4, 23);
    for pi in 0..ev.num_patches() {
        let (face, sub) = ev.patch(pi);
        let (corners, centre): (&[[f64; 2]], [f64; 2]) = if ev.triangle_patch(face) {
            (
                &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
                [1.0 / 3.0, 1.0 / 3.0],
            )
        } else {
            (
                &[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
                [0.5, 0.5],
            )
        };
        for (ci, c) in corners.iter().enumerate() {
            let j = jitter[(pi * 4 + ci) % jitter.len()];
            for s in [1e-2, 1e-5, 1e-9, 1e-13] {
                let (du, dv) = (centre[0] - c[0], centre[1] - c[1]);
                params.push(SurfaceParam {
                    face,
                    sub,
                    u: c[0] + s * du * (0.5 + j.u),
                    v: c[1] + s * dv * (0.5 + j.u),
                });
            }
        }
        let t = jitter[pi % jitter.len()].u * 0.5;
        params.push(SurfaceParam {
            face,
            sub,
            u: t,
            v: 0.0,
        });
        params.push(SurfaceParam {
            face,
            sub,
            u: 0.0,
            v: t,
        });
    }
    params
}

/// The cached descent (shapes and sparse refinement steps, memoised levels) gives what plain
/// local refinement from level 0 gives (budget 0: nothing cached), positions and first
/// derivatives, near mixed and extraordinary vertices and on seams too, on the first (cold)
/// and the second (warm) evaluation. Positions agree to 1e-14 of the mesh size. Derivatives
/// are the patch's scaled by `2^depth` (the chain rule to the original parameters), so their
/// rounding grows as `2^depth · eps` on either path; they are compared to that.
#[test]
fn cached_descent_matches_plain_local_refinement() {
    for (name, p, f, _) in meshes() {
        let cached = Evaluator::new(&f, p.len(), &Tags::new(), &QT).unwrap();
        let plain = Evaluator::new(&f, p.len(), &Tags::new(), &QT)
            .unwrap()
            .with_cache_budget(0);
        let params = probe_params(&plain);
        let scale = diag(&p);
        let (mut worst_p, mut worst_d, mut deepest) = (0.0f64, 0.0f64, 0);
        for pass in ["cold", "warm"] {
            for &q in &params {
                let a = cached.evaluate(&p, q).unwrap();
                let b = plain.evaluate(&p, q).unwrap();
                assert_eq!((a.kind, a.depth), (b.kind, b.depth), "{name} {pass} {q:?}");
                deepest = deepest.max(a.depth);
                let err = dist(a.position, b.position) / scale;
                worst_p = worst_p.max(err);
                assert!(err < 1e-14, "{name} {pass} {q:?}: position {err:e}");
                for (x, y) in [(a.du, b.du), (a.dv, b.dv)] {
                    let size = (0..3).map(|k| y[k] * y[k]).sum::<f64>().sqrt();
                    let err = dist(x, y) / size.max(scale) / 2f64.powi(a.depth as i32);
                    worst_d = worst_d.max(err);
                    assert!(err < 1e-14, "{name} {pass} {q:?}: {x:?} vs {y:?}");
                }
            }
        }
        assert_eq!(plain.cache_bytes(), 0);
        println!(
            "{name}: {} parameters (depth ≤ {deepest}), cached vs plain refinement: position \
             {worst_p:.1e} of the size, derivatives {worst_d:.1e} · 2^depth (relative)",
            params.len()
        );
    }
}
