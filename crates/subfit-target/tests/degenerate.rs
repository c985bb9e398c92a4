//! Degenerate and invalid inputs: typed errors or documented results, never panics or NaN.
//! Also: sign conventions with inward normals, duplicate merging, scale invariance, IMLS,
//! mesh targets.
mod common;

use common::*;
use subfit_mesh::{PolyMesh, Polygons};
use subfit_target::{Neighborhood, NormalOrigin, Target, TargetError, TargetOptions, MIN_POINTS};

fn grid(n: usize, f: impl Fn(f64, f64) -> [f64; 3]) -> Vec<[f64; 3]> {
    let mut v = Vec::new();
    for i in 0..n {
        for j in 0..n {
            v.push(f(i as f64 / (n - 1) as f64, j as f64 / (n - 1) as f64));
        }
    }
    v
}

fn all_finite(t: &Target) {
    let a = t.point_attributes();
    for i in 0..a.points.len() {
        for v in [a.normals[i], a.t1[i], a.t2[i]] {
            assert!(v.iter().all(|c| c.is_finite()));
        }
        assert!(a.k1[i].is_finite() && a.k2[i].is_finite());
    }
}

#[test]
fn plane_is_valid_flat_target() {
    let pts = grid(30, |x, y| [x * 2.0, y * 2.0, 0.5]);
    let t = Target::from_points(&pts, None, &TargetOptions::default()).unwrap();
    all_finite(&t);
    let a = t.point_attributes();
    assert!(a.normals.iter().all(|n| n[2] > 0.999_999), "oriented +z");
    assert!(a.k1.iter().chain(&a.k2).all(|k| k.abs() < 1e-6));
    // Foot points of points above and below; far away too.
    for (x, d) in [
        ([0.3, 0.4, 0.1], 0.1),
        ([0.5, 0.5, -0.2], -0.2),
        ([5.0, -3.0, 7.0], 7.0),
    ] {
        let f = t.foot_point(x);
        assert!((f.distance - d).abs() < 1e-9, "{f:?}");
        assert!(f.rho1.is_infinite() && f.alpha1 == 0.0 && f.alpha2 == 0.0);
        assert!(f.point.iter().all(|c| c.is_finite()));
    }
    // Vertical plane: normal ±x oriented +x (documented tie rule).
    let pts = grid(30, |y, z| [0.25, y, z]);
    let t = Target::from_points(&pts, None, &TargetOptions::default()).unwrap();
    all_finite(&t);
    assert!(t.normals().iter().all(|n| n[0] > 0.999_999));
}

#[test]
fn line_is_rejected() {
    let pts: Vec<[f64; 3]> = (0..50)
        .map(|i| [i as f64, 2.0 * i as f64, -(i as f64)])
        .collect();
    let e = Target::from_points(&pts, None, &TargetOptions::default()).unwrap_err();
    assert!(
        matches!(e, TargetError::Collinear { points: 50, .. }),
        "{e}"
    );
}

#[test]
fn too_few_points() {
    let pts = grid(3, |x, y| [x, y, x * y]);
    let e = Target::from_points(&pts, None, &TargetOptions::default()).unwrap_err();
    assert_eq!(
        e,
        TargetError::TooFewPoints {
            found: 9,
            required: MIN_POINTS
        }
    );
    let e = Target::from_points(&[], None, &TargetOptions::default()).unwrap_err();
    assert!(matches!(e, TargetError::TooFewPoints { found: 0, .. }));
}

#[test]
fn duplicates_only_and_merging() {
    let e =
        Target::from_points(&[[1.0, 2.0, 3.0]; 100], None, &TargetOptions::default()).unwrap_err();
    assert!(
        matches!(
            e,
            TargetError::TooFewDistinctPoints {
                distinct: 1,
                input: 100,
                ..
            }
        ),
        "{e}"
    );
    let mut pts = grid(5, |x, y| [x, y, 0.3 * x * x]);
    pts.extend_from_slice(&pts.clone()[..3]);
    let mut few = pts[..8].to_vec();
    few.extend_from_slice(&pts[..8]);
    let e = Target::from_points(&few, None, &TargetOptions::default()).unwrap_err();
    assert!(matches!(
        e,
        TargetError::TooFewDistinctPoints {
            distinct: 8,
            merged: 8,
            ..
        }
    ));
    let t = Target::from_points(&pts, None, &TargetOptions::default()).unwrap();
    assert_eq!(t.stats().merged_duplicates, 3);
    assert_eq!(t.len(), 25);
    assert_eq!(&t.input_to_point()[25..], &[0, 1, 2]);
}

#[test]
fn non_finite_rejected_with_index() {
    let mut pts = grid(5, |x, y| [x, y, 0.0]);
    pts[7][1] = f64::NAN;
    let e = Target::from_points(&pts, None, &TargetOptions::default()).unwrap_err();
    assert!(matches!(e, TargetError::NonFinitePoint { index: 7, .. }));
    pts[7][1] = 0.5;
    pts[3][2] = f64::INFINITY;
    let e = Target::from_points(&pts, None, &TargetOptions::default()).unwrap_err();
    assert!(matches!(e, TargetError::NonFinitePoint { index: 3, .. }));
    let pts = grid(5, |x, y| [x, y, 0.0]);
    let mut n = vec![[0.0, 0.0, 1.0]; 25];
    n[11] = [f64::NAN, 0.0, 1.0];
    let e = Target::from_points(&pts, Some(&n), &TargetOptions::default()).unwrap_err();
    assert!(matches!(e, TargetError::NonFiniteNormal { index: 11, .. }));
    let e = Target::from_points(&pts, Some(&n[..3]), &TargetOptions::default()).unwrap_err();
    assert!(matches!(
        e,
        TargetError::NormalCountMismatch {
            points: 25,
            normals: 3
        }
    ));
}

#[test]
fn invalid_options_and_faces() {
    let pts = grid(5, |x, y| [x, y, 0.0]);
    for o in [
        TargetOptions {
            neighborhood: Neighborhood::Knn(3),
            ..Default::default()
        },
        TargetOptions {
            neighborhood: Neighborhood::Radius(f64::NAN),
            ..Default::default()
        },
        TargetOptions {
            jet_degree: 4,
            ..Default::default()
        },
        TargetOptions {
            ambiguity_ratio: 0.0,
            ..Default::default()
        },
        TargetOptions {
            imls_radius: Some(-1.0),
            ..Default::default()
        },
    ] {
        assert!(matches!(
            Target::from_points(&pts, None, &o).unwrap_err(),
            TargetError::InvalidOption { .. }
        ));
    }
    let mesh = PolyMesh::new(pts, Polygons::from_triangles(&[[0, 1, 5], [1, 6, 99]]));
    let e = Target::from_mesh(&mesh, &TargetOptions::default()).unwrap_err();
    assert!(matches!(
        e,
        TargetError::FaceIndexOutOfRange {
            face: 1,
            vertex: 99,
            vertices: 25
        }
    ));
}

/// Cheng 2007 §II-D3 signs with outward and with inward normals on a sphere.
#[test]
fn sign_convention_follows_normals() {
    let sh = Sphere {
        c: [0.0; 3],
        r: 1.0,
    };
    let s = sh.samples(20_000, 11);
    let p = positions(&s);
    let out: Vec<[f64; 3]> = s.iter().map(|s| s.n).collect();
    let inw: Vec<[f64; 3]> = out.iter().map(|n| scale(*n, -1.0)).collect();
    let x_out = [1.03, 0.5, 0.5]; // outside by 0.03, normalized (centre ≈ 0.5, r ≈ 0.5)
    let x_in = [0.5 + 0.5 - 0.1, 0.5, 0.5];
    for (normals, sign) in [(&out, 1.0), (&inw, -1.0)] {
        let t = Target::from_points(&p, Some(normals), &TargetOptions::default()).unwrap();
        assert_eq!(t.stats().normal_origin, NormalOrigin::Input);
        let f = t.foot_point(x_out);
        // Outside: d > 0 with outward N; centre opposite N ⇒ ρ < 0 (ρ ≈ −0.5); α = d/(d−ρ).
        assert_eq!(f.distance > 0.0, sign > 0.0);
        assert!((f.rho1 - (-0.5 * sign)).abs() < 1e-3 && (f.rho2 - (-0.5 * sign)).abs() < 1e-3);
        let alpha = f.distance / (f.distance - f.rho1);
        assert!(alpha > 0.0 && (f.alpha1 - alpha).abs() < 1e-12);
        let f = t.foot_point(x_in);
        // Inside: d and ρ have the same sign ⇒ α < 0 ⇒ [α]₊ = 0.
        assert_eq!(f.distance < 0.0, sign > 0.0);
        assert_eq!(f.alpha1, 0.0);
        assert_eq!(f.alpha2, 0.0);
        // IMLS follows the normals' side too.
        let v = t.imls(x_out);
        assert!(!v.fallback && (v.value - sign * 0.03).abs() < 2e-3, "{v:?}");
    }
}

#[test]
fn scale_invariance() {
    let sh = Torus {
        big: 0.35,
        small: 0.15,
    };
    let p = positions(&sh.samples(8_000, 12));
    let base = Target::from_points(&p, None, &TargetOptions::default())
        .unwrap()
        .point_attributes();
    for f in [1e-6, 1e6] {
        let q: Vec<[f64; 3]> = p
            .iter()
            .map(|x| scale(add(*x, [3.0, -2.0, 1.0]), f))
            .collect();
        let a = Target::from_points(&q, None, &TargetOptions::default())
            .unwrap()
            .point_attributes();
        for i in 0..p.len() {
            assert!(norm(sub(a.points[i], base.points[i])) < 1e-9);
            assert!(dot(a.normals[i], base.normals[i]) > 1.0 - 1e-9);
            assert!((a.k2[i] - base.k2[i]).abs() < 1e-5 * base.k2[i].abs().max(1.0));
        }
    }
}

#[test]
fn imls_gradient_matches_finite_differences_and_fallback() {
    let sh = Sphere {
        c: [0.0; 3],
        r: 1.0,
    };
    let p = positions(&sh.samples(20_000, 13));
    let t = Target::from_points(&p, None, &TargetOptions::default()).unwrap();
    let x = [0.52, 0.61, 0.93];
    let v = t.imls(x);
    assert!(!v.fallback && v.neighbors > 0);
    let h = 1e-6;
    for k in 0..3 {
        let (mut a, mut b) = (x, x);
        a[k] += h;
        b[k] -= h;
        let fd = (t.imls(a).value - t.imls(b).value) / (2.0 * h);
        assert!(
            (fd - v.gradient[k]).abs() < 1e-5,
            "{k}: {fd} vs {}",
            v.gradient[k]
        );
    }
    // Far away: no neighbours within h → nearest point's tangent plane.
    let far = t.imls([3.0, 0.5, 0.5]);
    assert!(far.fallback && far.value > 1.9 && far.value.is_finite());
}

#[test]
fn mesh_target_uses_face_normals_and_closest_points() {
    // Octahedron subdivided into a fine grid is overkill: use a 40×40 height-field mesh.
    let n = 40;
    let pts = grid(n, |x, y| [x, y, 0.2 * (x - 0.5) * (x - 0.5)]);
    let mut tris = Vec::new();
    for i in 0..n - 1 {
        for j in 0..n - 1 {
            let a = (i * n + j) as u32;
            let b = a + n as u32;
            tris.push([a, b, a + 1]);
            tris.push([a + 1, b, b + 1]);
        }
    }
    let mesh = PolyMesh::new(pts, Polygons::from_triangles(&tris));
    let t = Target::from_mesh(&mesh, &TargetOptions::default()).unwrap();
    assert_eq!(t.stats().normal_origin, NormalOrigin::Faces);
    // Winding (a, b, a+1) with b = +x: normal = x̂ × ŷ... check consistency with the face normal.
    let c = t.mesh_closest_point([0.5, 0.5, 0.5]).unwrap();
    assert!(dot(c.face_normal, t.normals()[0]) > 0.9);
    assert!((c.distance - (0.5 - 0.0)).abs() < 0.01);
    all_finite(&t);
    assert!(
        Target::from_points(mesh.positions.as_slice(), None, &TargetOptions::default())
            .unwrap()
            .mesh_closest_point([0.0; 3])
            .is_none()
    );
}

#[test]
fn progress_is_reported() {
    let pts = grid(20, |x, y| [x, y, x * y]);
    let seen = std::sync::Mutex::new(Vec::new());
    let cb = |p: subfit_target::Progress| seen.lock().unwrap().push(p.phase);
    let mesh = PolyMesh::point_cloud(pts, None);
    Target::build(&mesh, &TargetOptions::default(), Some(&cb)).unwrap();
    let seen = seen.into_inner().unwrap();
    assert!(seen.contains(&subfit_target::Phase::Estimate));
    assert!(seen.contains(&subfit_target::Phase::Orient));
}

/// Far from the data, [`Target::imls_reaching`] lets a patch of points vote on the side: above
/// a plane of points with upward normals, one of them flipped right under the query, the
/// nearest point's tangent plane puts the query inside, the grown kernel outside (unless that
/// point is flagged as the cloud's rim). Where points lie within `h` it is the IMLS value
/// itself.
#[test]
fn imls_reaching_outvotes_one_wrong_normal() {
    let n = 41;
    let pts = grid(n, |x, y| [x, y, 0.0]);
    let mut normals = vec![[0.0, 0.0, 1.0]; pts.len()];
    let centre = (n / 2) * n + n / 2;
    normals[centre] = [0.0, 0.0, -1.0];
    let options = TargetOptions {
        imls_radius: Some(0.05),
        ..TargetOptions::default()
    };
    let t = Target::from_points(&pts, Some(&normals), &options).unwrap();
    let above = t.to_normalized(add(pts[centre], [0.0, 0.0, 0.2]));
    let h = t.imls_radius();
    assert!(t.normalization().length_to_normalized(0.2) > 2.0 * h, "{h}");
    let nearest = t.imls(above);
    assert!(nearest.fallback && nearest.value < 0.0, "{nearest:?}");
    let reaching = t.imls_reaching(above, &[]);
    assert!(reaching > 0.0, "{reaching}");
    // Beyond a point of the cloud's rim the tangent plane is kept.
    let mut rim = vec![false; t.len()];
    rim[t.index().nearest(&above).index as usize] = true;
    assert_eq!(t.imls_reaching(above, &rim), nearest.value);
    let near = t.to_normalized(add(pts[centre + 3], [0.0, 0.0, 0.005]));
    assert!(!t.imls(near).fallback);
    assert_eq!(t.imls_reaching(near, &rim), t.imls(near).value);
    assert_eq!(
        t.imls_reaching_batch(&[above, near], &[]),
        vec![reaching, t.imls(near).value]
    );
}
