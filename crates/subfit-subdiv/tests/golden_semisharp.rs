//! Semi-sharp creases and corners against OpenSubdiv 3.5 (`tests/golden_semisharp`, made by
//! `tools/osd-golden`): limit positions and normals of the tagged meshes refined 0–3 levels
//! match as point sets to 1e-12 of the diagonal and 1e-9 rad, through the sampling operator, the
//! limit stencils and exact evaluation; and the limit of a vertex is the limit of its vertex
//! point one level down.
#![allow(
    clippy::print_stdout,
    reason = "the test reports the errors it measured"
)]

mod common;

use common::{angle, compare, diag, dist, read_lim, read_obj, ANGLE_TOL, POS_TOL};
use std::path::{Path, PathBuf};
use subfit_mesh::{Polygons, Tags};
use subfit_subdiv::{
    limit_stencils, normals_from_tangents, random_samples, refine, sampling_operator,
    ClosestOptions, ClosestPointFinder, Evaluator, Options, Scheme, SurfaceParam,
};

const MESHES: [&str; 3] = [
    "quad_cube_semisharp",
    "tri_icosahedron_semisharp",
    "tri_open_patch_semisharp",
];
/// Catmull-Clark with pentagons: OpenSubdiv's level-0 `Limit` applies quad masks to `n`-gons
/// (see `tests/golden.rs`), so its level-0 reference is not the limit where no semi-sharpness
/// is left; levels 1–3 are compared.
const NGON_MESHES: [&str; 1] = ["ngon_prism_semisharp"];

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden_semisharp")
}

/// The control mesh, its `t` tags and its native scheme.
fn load(name: &str) -> (Vec<[f64; 3]>, Polygons, Tags, Scheme) {
    let path = dir().join(format!("{name}.obj"));
    let (pts, faces) = read_obj(&path);
    let tags = subfit_io::read_tags_file(&path, pts.len()).unwrap_or_else(|e| panic!("{e}"));
    assert!(!tags.is_empty(), "{name}: no tags");
    let scheme = if name.starts_with("tri_") {
        Scheme::Loop
    } else {
        Scheme::CatmullClark
    };
    (pts, faces, tags, scheme)
}

fn reference(name: &str, level: usize) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    read_lim(Path::new(&dir().join(format!("{name}.L{level}.lim"))))
}

#[test]
fn sampling_operator_matches_opensubdiv_on_semi_sharp_meshes() {
    let mut failures = Vec::new();
    println!("{:<28} lvl  max |dp|/diag   max angle (rad)", "mesh");
    for name in MESHES.into_iter().chain(NGON_MESHES) {
        let (pts, faces, tags, native) = load(name);
        let scale = diag(&pts);
        let first = usize::from(NGON_MESHES.contains(&name));
        // Quad/triangle is Loop on triangles only and Catmull-Clark without triangles.
        for scheme in [native, Scheme::QuadTriangle] {
            let options = Options::new(scheme);
            for level in first..=3 {
                let what = format!("{name} L{level} ({})", scheme.name());
                let (refp, ref_n) = reference(name, level);
                let s = sampling_operator(&faces, pts.len(), &tags, &options, level)
                    .unwrap()
                    .evaluate(&pts);
                let (d, a) = compare(&s.positions, &s.normals, &refp, &ref_n, scale, &what);
                println!(
                    "{name:<28} L{level}   {d:.3e}      {a:.3e}   {}",
                    scheme.name()
                );
                if d > POS_TOL || a > ANGLE_TOL {
                    failures.push(what);
                }
            }
        }
    }
    assert!(failures.is_empty(), "beyond tolerance: {failures:?}");
}

#[test]
fn limit_stencils_match_opensubdiv_at_level_0() {
    for name in MESHES {
        let (pts, faces, tags, scheme) = load(name);
        let l = limit_stencils(&faces, pts.len(), &tags, &Options::new(scheme)).unwrap();
        let p = l.position.apply(&pts);
        let n = normals_from_tangents(&l.tangent1.apply(&pts), &l.tangent2.apply(&pts));
        let (refp, ref_n) = reference(name, 0);
        let (d, a) = compare(&p, &n, &refp, &ref_n, diag(&pts), name);
        assert!(d <= POS_TOL && a <= ANGLE_TOL, "{name}: {d:e} {a:e}");
    }
}

/// The limit of vertex `v` at level `k` is the limit of its vertex point (the same id) at level
/// `k + 1`: positions and normals to round-off. (Normals would not be invariant at infinitely
/// sharp irregular creases and corners, where OpenSubdiv's tangent masks are approximations;
/// these meshes have none, their sharp features are semi-sharp or regular boundaries.)
#[test]
fn limit_of_a_vertex_is_the_limit_of_its_vertex_point() {
    for name in MESHES.into_iter().chain(NGON_MESHES) {
        let (pts, faces, tags, scheme) = load(name);
        let options = Options::new(scheme);
        let scale = diag(&pts);
        let ops: Vec<_> = (0..=3)
            .map(|l| {
                sampling_operator(&faces, pts.len(), &tags, &options, l)
                    .unwrap()
                    .evaluate(&pts)
            })
            .collect();
        let (mut max_d, mut max_a) = (0.0f64, 0.0f64);
        for k in 0..3 {
            let (a, b) = (&ops[k], &ops[k + 1]);
            for v in 0..a.positions.len() {
                let d = dist(&a.positions[v], &b.positions[v]) / scale;
                assert!(d < 1e-13, "{name} level {k} vertex {v}: {d:e}");
                let ang = angle(&a.normals[v], &b.normals[v]);
                assert!(ang < 1e-12, "{name} level {k} vertex {v}: normal {ang:e}");
                (max_d, max_a) = (max_d.max(d), max_a.max(ang));
            }
        }
        println!("{name:<28} level k vs k + 1: {max_d:.3e} {max_a:.3e}");
    }
}

/// Exact evaluation at the corners of every face gives the limit points of the control
/// vertices, and inside faces it lies on the limit surface of the refined mesh (the evaluation
/// at a face's centre equals the limit of the level-1 face point, Catmull-Clark).
#[test]
fn exact_evaluation_matches_opensubdiv_at_vertices() {
    for name in MESHES {
        let (pts, faces, tags, scheme) = load(name);
        let scale = diag(&pts);
        let ev = Evaluator::new(&faces, pts.len(), &tags, &Options::new(scheme)).unwrap();
        let (refp, ref_n) = reference(name, 0);
        let tri = scheme == Scheme::Loop;
        let corners: &[(f64, f64)] = if tri {
            &[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]
        } else {
            &[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
        };
        let (mut pos, mut nrm) = (vec![[f64::NAN; 3]; pts.len()], vec![[0.0; 3]; pts.len()]);
        for (f, face) in faces.iter().enumerate() {
            for (k, &(u, v)) in corners.iter().enumerate() {
                let p = ev
                    .evaluate(&pts, SurfaceParam::new(f as u32, u, v))
                    .unwrap_or_else(|e| panic!("{name} face {f} corner {k}: {e}"));
                let x = face[k] as usize;
                if !pos[x][0].is_nan() {
                    let d = dist(&pos[x], &p.position) / scale;
                    assert!(d < 1e-13, "{name} vertex {x} from two faces: {d:e}");
                }
                pos[x] = p.position;
                nrm[x] = p.normal;
            }
        }
        let (d, a) = compare(&pos, &nrm, &refp, &ref_n, scale, name);
        println!("{name:<28} eval at vertices {d:.3e} {a:.3e}");
        assert!(d <= POS_TOL && a <= ANGLE_TOL, "{name}: {d:e} {a:e}");
        if !tri {
            // Face centres: the limit of the level-1 face points (Catmull-Clark ids V + E + f).
            let s1 = sampling_operator(&faces, pts.len(), &tags, &Options::new(scheme), 1)
                .unwrap()
                .evaluate(&pts);
            let ne = s1.positions.len() - pts.len() - faces.len();
            for f in 0..faces.len() {
                let p = ev
                    .evaluate(&pts, SurfaceParam::new(f as u32, 0.5, 0.5))
                    .unwrap();
                let q = s1.positions[pts.len() + ne + f];
                let d = dist(&p.position, &q) / scale;
                assert!(d < 1e-12, "{name} face {f} centre: {d:e}");
            }
        }
    }
}

/// Exact evaluation at the dyadic parameters `(i/2^l, j/2^l)` of every control face lands on
/// OpenSubdiv's limit points of the level-`l` vertices (nearest reference point, not
/// one-to-one: vertices shared by faces are evaluated from each), with matching normals. Away
/// from the control vertices these points are inside patches that become regular only after the
/// sharpness around them has decayed, so this checks the blended local refinement and the
/// patches below it.
#[test]
fn exact_evaluation_at_dyadic_parameters_matches_opensubdiv() {
    for name in MESHES.into_iter().chain(NGON_MESHES) {
        let (pts, faces, tags, scheme) = load(name);
        let scale = diag(&pts);
        let ev = Evaluator::new(&faces, pts.len(), &tags, &Options::new(scheme)).unwrap();
        for level in [2usize, 3] {
            let (refp, ref_n) = reference(name, level);
            let (mut max_d, mut max_a) = (0.0f64, 0.0f64);
            for patch in 0..ev.num_patches() {
                let (face, sub) = ev.patch(patch);
                let tri = ev.triangle_patch(face);
                // The sub-quads of an n-gon are level-1 faces.
                let n = 1usize << (level - usize::from(ev.num_subpatches(face) > 1));
                for i in 0..=n {
                    for j in 0..=n {
                        if tri && i + j > n {
                            continue;
                        }
                        let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                        let p = ev
                            .evaluate(&pts, SurfaceParam { face, sub, u, v })
                            .unwrap_or_else(|e| panic!("{name} face {face} ({u}, {v}): {e}"));
                        let k = (0..refp.len())
                            .min_by(|&a, &b| {
                                dist(&p.position, &refp[a]).total_cmp(&dist(&p.position, &refp[b]))
                            })
                            .unwrap();
                        max_d = max_d.max(dist(&p.position, &refp[k]) / scale);
                        max_a = max_a.max(angle(&p.normal, &ref_n[k]));
                    }
                }
            }
            println!("{name:<28} eval L{level} dyadic {max_d:.3e} {max_a:.3e}");
            assert!(
                max_d <= POS_TOL && max_a <= ANGLE_TOL,
                "{name} L{level}: {max_d:e} {max_a:e}"
            );
        }
    }
}

/// Closest points: a query offset from an OpenSubdiv limit point along its normal (by 1e-4 of
/// the diagonal, well inside the radius of curvature of the rounded creases) has that limit
/// point as its closest point on our limit surface, at the offset distance.
#[test]
fn closest_points_find_opensubdiv_limit_points() {
    for name in MESHES.into_iter().chain(NGON_MESHES) {
        let (pts, faces, tags, scheme) = load(name);
        let scale = diag(&pts);
        let ev = Evaluator::new(&faces, pts.len(), &tags, &Options::new(scheme)).unwrap();
        let finder = ClosestPointFinder::new(&ev, &pts, ClosestOptions::default()).unwrap();
        let (refp, ref_n) = reference(name, 3);
        let h = 1e-4 * scale;
        let (mut max_d, mut max_h) = (0.0f64, 0.0f64);
        // Every 7th point: a few hundred queries per mesh, spread over the surface.
        for k in (0..refp.len()).step_by(7) {
            let q = [0, 1, 2].map(|c| refp[k][c] + h * ref_n[k][c]);
            let c = finder.closest(q).unwrap();
            max_d = max_d.max(dist(&c.position, &refp[k]) / scale);
            max_h = max_h.max((c.distance - h).abs() / scale);
        }
        println!("{name:<28} closest {max_d:.3e} {max_h:.3e}");
        assert!(max_d < 1e-9 && max_h < 1e-12, "{name}: {max_d:e} {max_h:e}");
    }
}

/// Derivatives of exact evaluation at seeded random parameters agree with central differences
/// of the positions (semi-sharp regions included: every patch touches a tag or is near one).
#[test]
fn derivatives_match_finite_differences_on_semi_sharp_meshes() {
    for name in MESHES.into_iter().chain(NGON_MESHES) {
        let (pts, faces, tags, scheme) = load(name);
        let scale = diag(&pts);
        let ev = Evaluator::new(&faces, pts.len(), &tags, &Options::new(scheme)).unwrap();
        let (params, points) = random_samples(&ev, &pts, 300, 7).unwrap();
        let h = 1e-6;
        let mut worst = 0.0f64;
        for (p, s) in params.iter().zip(&points) {
            // Keep the stencil inside the patch.
            let tri = ev.triangle_patch(p.face);
            let inside = |u: f64, v: f64| {
                u >= 0.0
                    && v >= 0.0
                    && if tri {
                        u + v <= 1.0
                    } else {
                        u <= 1.0 && v <= 1.0
                    }
            };
            if !inside(p.u - h, p.v - h) || !inside(p.u + h, p.v + h) {
                continue;
            }
            let at = |u: f64, v: f64| {
                ev.evaluate(&pts, SurfaceParam { u, v, ..*p })
                    .unwrap()
                    .position
            };
            for (d, (a, b)) in [
                (s.du, (at(p.u + h, p.v), at(p.u - h, p.v))),
                (s.dv, (at(p.u, p.v + h), at(p.u, p.v - h))),
            ] {
                let fd = [0, 1, 2].map(|c| (a[c] - b[c]) / (2.0 * h));
                worst = worst.max(dist(&fd, &d) / scale);
            }
        }
        println!("{name:<28} derivatives vs differences {worst:.3e}");
        assert!(worst < 1e-6, "{name}: {worst:e}");
    }
}

/// A crease of integer sharpness `k` is subdivided exactly as an infinitely sharp one for `k`
/// levels (the last one blends with weight 1): the refinement matrices are bit for bit equal.
#[test]
fn integer_sharpness_refines_as_infinite_for_that_many_levels() {
    for name in MESHES {
        let (pts, faces, tags, scheme) = load(name);
        let options = Options::new(scheme);
        let with = |s: f64| {
            let mut t = Tags::new();
            for ((a, b), _) in tags.creases() {
                t.set_crease(a, b, s);
            }
            t
        };
        let (mut fa, mut ta, mut na) = (faces.clone(), with(3.0), pts.len());
        let mut tb = with(subfit_mesh::SHARPNESS_INFINITE);
        for level in 0..3 {
            let a = refine(&fa, na, &ta, &options).unwrap();
            let b = refine(&fa, na, &tb, &options).unwrap();
            assert_eq!(a.matrix, b.matrix, "{name} level {level}");
            (fa, ta, tb, na) = (a.faces, a.tags, b.tags, a.num_vertices);
        }
        // Sharpness 3 has decayed: the next level differs (smooth there).
        let a = refine(&fa, na, &ta, &options).unwrap();
        let b = refine(&fa, na, &tb, &options).unwrap();
        assert!(ta.is_empty() && a.matrix != b.matrix, "{name}");
    }
}

/// Quad/triangle meshes with semi-sharp tags (mixed vertices on the creases): the limit of a
/// vertex equals the limit of its vertex point one level down (positions to round-off), and
/// exact evaluation at the control vertices gives the level-0 limit points.
#[test]
fn mixed_quad_triangle_semi_sharp_limits_are_consistent() {
    // A cube with one side split into two triangles.
    let (pts, _, _, _) = load("quad_cube_semisharp");
    let mut faces = Polygons::new();
    for f in [
        [0, 3, 2, 1],
        [4, 5, 6, 7],
        [1, 2, 6, 5],
        [2, 3, 7, 6],
        [3, 0, 4, 7],
    ] {
        faces.push(&f);
    }
    faces.push(&[0, 1, 5]);
    faces.push(&[0, 5, 4]);
    let mut tags = Tags::new();
    tags.set_crease(0, 1, 0.5);
    tags.set_crease(1, 5, 2.3);
    tags.set_crease(0, 5, 1.5);
    tags.set_crease(2, 6, 1.0);
    tags.set_corner(5, 0.7);
    let options = Options::new(Scheme::QuadTriangle);
    let scale = diag(&pts);
    let ops: Vec<_> = (0..=3)
        .map(|l| {
            sampling_operator(&faces, pts.len(), &tags, &options, l)
                .unwrap()
                .evaluate(&pts)
        })
        .collect();
    for k in 0..3 {
        for v in 0..ops[k].positions.len() {
            let d = dist(&ops[k].positions[v], &ops[k + 1].positions[v]) / scale;
            assert!(d < 1e-13, "level {k} vertex {v}: {d:e}");
        }
    }
    let ev = Evaluator::new(&faces, pts.len(), &tags, &options).unwrap();
    for (f, face) in faces.iter().enumerate() {
        let corners: &[(f64, f64)] = if face.len() == 3 {
            &[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]
        } else {
            &[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
        };
        for (k, &(u, v)) in corners.iter().enumerate() {
            let p = ev
                .evaluate(&pts, SurfaceParam::new(f as u32, u, v))
                .unwrap();
            let x = face[k] as usize;
            let d = dist(&p.position, &ops[0].positions[x]) / scale;
            assert!(d < 1e-13, "face {f} corner {k}: {d:e}");
            let a = angle(&p.normal, &ops[0].normals[x]);
            assert!(a < 1e-9, "face {f} corner {k}: normal {a:e}");
        }
    }
}
