//! The judge against analytic truth: concentric spheres, heights over a plane, a limit surface
//! offset along its exact normal (Loop, Catmull-Clark with n-gons, quad/triangle with both face
//! kinds, creases), a point cloud the surface overhangs, invariance to scale and threads, and
//! typed errors for bad input.
#![allow(
    clippy::print_stdout,
    reason = "the offset test reports the figures it checked"
)]

use subfit::mesh::shapes::{cheng_ellipsoid_cage, cube_mesh, geodesic_sphere};
use subfit::mesh::vec3::{add, cross, dist2, dot, norm, scale, sub};
use subfit::mesh::{PolyMesh, Polygons, Tags, SHARPNESS_INFINITE};
use subfit::subdiv::{EvalKind, Evaluator, Options, Scheme, SurfaceParam};
use subfit_bench::judge::{judge, Candidate, Direction, JudgeError, JudgeOptions, Reference};

/// Options small enough for a debug build: a few thousand samples, a 20k-triangle tessellation.
fn small() -> JudgeOptions {
    JudgeOptions {
        surface_samples: 4_000,
        data_samples: 4_000,
        tessellation_triangles: 20_000,
        polished_points: 300,
        seed: 3,
        threads: None,
    }
}

fn scaled(mesh: &PolyMesh, s: f64) -> PolyMesh {
    let mut m = mesh.clone();
    m.positions.iter_mut().for_each(|p| *p = scale(*p, s));
    m
}

/// How far inside the sphere of radius `r` about the origin the triangles of `mesh` (vertices on
/// that sphere) reach: `r` minus the least distance from the origin to a triangle's plane.
fn chord_error(mesh: &PolyMesh, r: f64) -> f64 {
    mesh.faces
        .triangulate_fan()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let n = cross(sub(b, a), sub(c, a));
            r - dot(n, a).abs() / norm(n)
        })
        .fold(0.0, f64::max)
}

fn assert_within(d: &Direction, lo: f64, hi: f64, what: &str) {
    for (name, x) in [
        ("mean", d.mean),
        ("rms", d.rms),
        ("p95", d.p95),
        ("max", d.max),
    ] {
        assert!(
            (lo..=hi).contains(&x),
            "{what} {name} {x} outside [{lo}, {hi}]"
        );
    }
}

#[test]
fn concentric_spheres_are_their_radii_apart() {
    // Unit sphere against radius r: every distance lies in [r(1 − ε_c) − 1, r − 1 + ε_r], the
    // chord errors ε of the two triangulations widening the exact |r − 1|.
    let reference = geodesic_sphere(4);
    let r = 1.05;
    let candidate = scaled(&geodesic_sphere(3), r);
    let (er, ec) = (chord_error(&reference, 1.0), chord_error(&candidate, r));
    let (lo, hi) = (r * (1.0 - ec) - 1.0, r - 1.0 + er);
    let j = judge(
        &Reference::from_polymesh(&reference),
        &Candidate::mesh_from_polymesh(&candidate),
        &small(),
    )
    .unwrap();
    assert_within(&j.data_to_surface, lo, hi, "data → surface");
    assert_within(&j.surface_to_data, lo, hi, "surface → data");
    assert_eq!(j.data_to_surface.samples, reference.positions.len() + 4_000);
    assert_eq!(j.surface_to_data.samples, 4_000);
    assert!((j.diagonal - 2.0 * 3f64.sqrt()).abs() < 0.2);
    assert!((j.hausdorff_fraction - j.hausdorff / j.diagonal).abs() < 1e-15);
    assert_eq!((j.point_spacing, j.tessellation_triangles), (None, 0));

    // The same points as a cloud: its discs (radius s, tangent to the sphere) lie between
    // radius 1 and √(1 + s²) ≤ 1 + s²/2, so surface → data widens by s².
    let cloud = Reference::Points {
        positions: reference.positions.clone(),
    };
    let j = judge(&cloud, &Candidate::mesh_from_polymesh(&candidate), &small()).unwrap();
    let s = j.point_spacing.unwrap();
    assert!(s > 0.0 && s < 0.2, "{s}");
    assert_within(&j.data_to_surface, lo, r - 1.0, "cloud → surface");
    assert_within(
        &j.surface_to_data,
        lo - s * s,
        hi + s * s,
        "surface → cloud",
    );
}

/// A flat Catmull-Clark cage: a 10 × 10 grid of unit quads in z = 0 whose outer ring of control
/// points is lifted to z = 0.7. Bicubic patches depend on their face's one-ring, so the limit
/// over [2, 8]² is exactly the plane z = 0.
fn dished_grid() -> PolyMesh {
    let m = 10;
    let mut p = Vec::new();
    for j in 0..=m {
        for i in 0..=m {
            let ring = i == 0 || j == 0 || i == m || j == m;
            p.push([i as f64, j as f64, if ring { 0.7 } else { 0.0 }]);
        }
    }
    let at = |i: usize, j: usize| (j * (m + 1) + i) as u32;
    let mut f = Polygons::new();
    for j in 0..m {
        for i in 0..m {
            f.push(&[at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    PolyMesh::new(p, f)
}

#[test]
fn heights_over_a_plane_are_exact() {
    let mut points = Vec::new();
    let mut heights = Vec::new();
    for j in 0..6 {
        for i in 0..6 {
            let h = 0.05 + 0.01 * (i + 6 * j) as f64;
            points.push([2.5 + i as f64, 2.5 + j as f64 * 0.9, h]);
            heights.push(h);
        }
    }
    let n = heights.len() as f64;
    let rms = (heights.iter().map(|h| h * h).sum::<f64>() / n).sqrt();
    let mean = heights.iter().sum::<f64>() / n;
    let max = heights.iter().cloned().fold(0.0, f64::max);
    let cage = Candidate::limit(dished_grid(), Tags::new(), Scheme::CatmullClark);
    for polished in [0, 10, 100] {
        let options = JudgeOptions {
            polished_points: polished,
            ..small()
        };
        let reference = Reference::Points {
            positions: points.clone(),
        };
        let j = judge(&reference, &cage, &options).unwrap();
        let d = j.data_to_surface;
        assert_eq!((d.samples, j.polished_points), (36, polished.min(36)));
        for (got, want) in [(d.rms, rms), (d.mean, mean), (d.max, max)] {
            assert!((got - want).abs() < 1e-9 * want, "{got} vs {want}");
        }
    }
}

/// A ramp z = a·(x − 2.5) over [2.5, 7.5]² above the dished grid's plane, tessellated with most
/// of its vertices in a strip at its high end: the data → surface RMS is uniform by area
/// (a·5/√3, as Metro measures), not pulled up by where the vertices crowd; the maximum (5a) is
/// at those vertices.
#[test]
fn the_data_to_surface_rms_is_uniform_by_area_wherever_the_vertices_crowd() {
    let a = 0.02;
    let mut xs = vec![2.5, 3.75, 5.0, 6.25, 7.0];
    xs.extend((1..=40).map(|i| 7.0 + 0.5 * i as f64 / 40.0));
    let ys: Vec<f64> = (0..=10).map(|j| 2.5 + 0.5 * j as f64).collect();
    let mut positions = Vec::new();
    for &y in &ys {
        for &x in &xs {
            positions.push([x, y, a * (x - 2.5)]);
        }
    }
    let at = |i: usize, j: usize| (j * xs.len() + i) as u32;
    let mut triangles = Vec::new();
    for j in 0..ys.len() - 1 {
        for i in 0..xs.len() - 1 {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    let reference = Reference::Mesh {
        positions,
        triangles,
    };
    let cage = Candidate::limit(dished_grid(), Tags::new(), Scheme::CatmullClark);
    let j = judge(&reference, &cage, &small()).unwrap();
    let d = j.data_to_surface;
    let (rms, max) = (a * 5.0 / 3f64.sqrt(), a * 5.0);
    assert!((d.rms - rms).abs() < 0.03 * rms, "RMS {} vs {rms}", d.rms);
    assert!((d.max - max).abs() < 1e-9, "max {} vs {max}", d.max);
}

/// Corner parameters of the grid of resolution `n` on a triangle or unit-square patch, and its
/// triangles.
fn grid(n: usize, triangle: bool) -> (Vec<(f64, f64)>, Vec<[u32; 3]>) {
    let f = |i: usize| i as f64 / n as f64;
    let (mut uv, mut tris) = (Vec::new(), Vec::new());
    let at = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    for j in 0..=n {
        for i in 0..=n {
            uv.push((f(i), f(j)));
        }
    }
    for j in 0..n {
        for i in 0..n {
            if !triangle || i + j < n {
                tris.push([at(i, j), at(i + 1, j), at(i, j + 1)]);
            }
            if !triangle || i + j + 1 < n {
                tris.push([at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }
    // Unused vertices of a triangle grid (i + j > n) stay: the judge ignores them.
    (uv, tris)
}

/// The exact limit surface of a cage offset by `delta` along its exact unit normal, as a mesh:
/// an `n`-grid per patch of exact evaluations (Stam 1998, the evaluator checked against
/// OpenSubdiv). Also returns a bound on how far its flat triangles lie from the offset surface:
/// `4/3 ·` the largest gap at edge midpoints (or the centroid gap if larger), measured at every
/// triangle — the reference's own chord error, which widens every expectation.
fn offset_limit(
    cage: &PolyMesh,
    tags: &Tags,
    scheme: Scheme,
    n: usize,
    delta: f64,
) -> (Reference, f64) {
    let ev = Evaluator::new(
        &cage.faces,
        cage.positions.len(),
        tags,
        &Options::new(scheme),
    )
    .unwrap();
    let at = |face, sub, (u, v): (f64, f64)| {
        let q = SurfaceParam { face, sub, u, v };
        let s = ev.evaluate(&cage.positions, q).unwrap();
        // Where the evaluator answers with a vertex's limit masks (exactly at an irregular
        // vertex, or at its depth limit on a quad/triangle seam, whose tangent masks can come
        // out turned: a normal of (0, 0.05) on the triangular prism's cap points away from its
        // neighbours'), the normal is taken 1e-7 inside the patch, toward its centre.
        let normal = if s.kind == EvalKind::Vertex {
            let c = if ev.triangle_patch(face) {
                1.0 / 3.0
            } else {
                0.5
            };
            let inside = SurfaceParam {
                u: u + 1e-7 * (c - u),
                v: v + 1e-7 * (c - v),
                ..q
            };
            ev.evaluate(&cage.positions, inside).unwrap().normal
        } else {
            s.normal
        };
        add(s.position, scale(normal, delta))
    };
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    let (mut mid, mut centre) = (0.0f64, 0.0f64);
    for p in 0..ev.num_patches() {
        let (face, sub) = ev.patch(p);
        let triangle = ev.triangle_patch(face);
        let (uv, tris) = grid(n, triangle);
        let base = positions.len() as u32;
        // Points past a triangle patch's hypotenuse are used by no triangle: any point will do.
        positions.extend(uv.iter().map(|&(u, v)| {
            at(
                face,
                sub,
                if triangle && u + v > 1.0 {
                    (0.0, 0.0)
                } else {
                    (u, v)
                },
            )
        }));
        for t in &tris {
            let gap = |w: [f64; 3]| {
                let q = (0..3).fold((0.0, 0.0), |(u, v), k| {
                    let c = uv[t[k] as usize];
                    (u + w[k] * c.0, v + w[k] * c.1)
                });
                let flat = (0..3).fold([0.0; 3], |a, k| {
                    add(a, scale(positions[(base + t[k]) as usize], w[k]))
                });
                dist2(at(face, sub, q), flat).sqrt()
            };
            centre = centre.max(gap([1.0 / 3.0; 3]));
            for w in [[0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]] {
                mid = mid.max(gap(w));
            }
            triangles.push(t.map(|i| base + i));
        }
    }
    (
        Reference::Mesh {
            positions,
            triangles,
        },
        (4.0 / 3.0 * mid).max(centre),
    )
}

/// A prism over a regular `n`-gon, slightly wavy (two `n`-gon caps, `n` quad sides).
fn prism(n: usize) -> PolyMesh {
    let mut p = Vec::new();
    for z in [0.0, 1.0] {
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            p.push([a.cos(), a.sin(), z + 0.1 * (2.0 * a).sin()]);
        }
    }
    let k = n as u32;
    let mut f = Polygons::new();
    f.push(&(0..k).rev().collect::<Vec<_>>());
    f.push(&(k..2 * k).collect::<Vec<_>>());
    for i in 0..k {
        f.push(&[i, (i + 1) % k, k + (i + 1) % k, k + i]);
    }
    PolyMesh::new(p, f)
}

/// The cube cage with its top face's four edges creased.
fn creased_cube() -> (PolyMesh, Tags) {
    let cube = cube_mesh(0.5);
    let top = cube
        .faces
        .iter()
        .find(|f| f.iter().all(|&v| cube.positions[v as usize][2] > 0.0))
        .unwrap()
        .to_vec();
    let mut tags = Tags::new();
    for k in 0..4 {
        tags.set_crease(top[k], top[(k + 1) % 4], SHARPNESS_INFINITE);
    }
    (cube, tags)
}

#[test]
fn an_offset_limit_surface_is_delta_away_both_ways() {
    let delta = 0.01;
    let (cube, creases) = creased_cube();
    let cases = [
        (
            "Loop",
            cheng_ellipsoid_cage(0.5, 0.8, 1.0, false),
            Tags::new(),
            Scheme::Loop,
        ),
        (
            "Catmull-Clark n-gons",
            prism(5),
            Tags::new(),
            Scheme::CatmullClark,
        ),
        ("quad/triangle", prism(3), Tags::new(), Scheme::QuadTriangle),
        ("creased Catmull-Clark", cube, creases, Scheme::CatmullClark),
    ];
    for (name, cage, tags, scheme) in cases {
        let (reference, chord) = offset_limit(&cage, &tags, scheme, 20, delta);
        let j = judge(&reference, &Candidate::limit(cage, tags, scheme), &small()).unwrap();
        // Reference vertices lie exactly δ off; samples of its flat triangles and the judge's
        // tessellation each move a distance by at most their chord errors.
        let tol = j.tessellation_deviation + chord + 1e-12;
        println!(
            "{name}: deviation {:.2e}, reference chord {chord:.2e}, d→s {:?}, s→d {:?}",
            j.tessellation_deviation, j.data_to_surface, j.surface_to_data
        );
        assert!(j.tessellation_deviation < 0.01, "{name}");
        assert_within(&j.data_to_surface, delta - tol, delta + tol, name);
        assert_within(&j.surface_to_data, delta - tol, delta + tol, name);
        assert!((j.hausdorff - delta).abs() <= tol && (j.rms - delta).abs() <= tol);
        // The reference's vertices are exactly δ off, and the farthest are polished on the
        // exact surface: the maximum is δ to rounding, whatever the chord errors.
        assert!(j.data_to_surface.max >= delta - 1e-9, "{name}");
    }
}

#[test]
fn a_cage_against_its_own_limit_is_near_zero() {
    let cage = cheng_ellipsoid_cage(0.5, 0.8, 1.0, true);
    let (reference, chord) = offset_limit(&cage, &Tags::new(), Scheme::Loop, 16, 0.0);
    let all = JudgeOptions {
        polished_points: usize::MAX,
        ..small()
    };
    let j = judge(
        &reference,
        &Candidate::limit(cage, Tags::new(), Scheme::Loop),
        &all,
    )
    .unwrap();
    assert!(j.hausdorff <= j.tessellation_deviation + chord, "{j:?}");
    // Polished, every reference vertex is on the surface: only the flat triangles' samples
    // (within the reference's chord error) are off.
    assert!(j.data_to_surface.max <= chord + 1e-9, "{j:?}");
    assert!(
        j.tessellation_deviation < 5e-3,
        "{}",
        j.tessellation_deviation
    );
}

#[test]
fn a_surface_overhanging_a_cloud_is_seen() {
    // Points on [0, 1]² (spacing 0.025), a flat limit surface over about [−1, 2]².
    let mut points = Vec::new();
    for j in 0..=40 {
        for i in 0..=40 {
            points.push([0.025 * i as f64, 0.025 * j as f64, 0.0]);
        }
    }
    let m = 12;
    let mut p = Vec::new();
    for j in 0..=m {
        for i in 0..=m {
            p.push([-1.0 + 0.25 * i as f64, -1.0 + 0.25 * j as f64, 0.0]);
        }
    }
    let at = |i: usize, j: usize| (j * (m + 1) + i) as u32;
    let mut f = Polygons::new();
    for j in 0..m {
        for i in 0..m {
            f.push(&[at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    let cage = Candidate::limit(PolyMesh::new(p, f), Tags::new(), Scheme::CatmullClark);
    let j = judge(
        &Reference::Points {
            positions: points.clone(),
        },
        &cage,
        &small(),
    )
    .unwrap();
    // The 12th neighbour of an interior grid point is two spacings away.
    assert!((j.point_spacing.unwrap() - 0.05).abs() < 1e-12);
    assert!(j.data_to_surface.max < 1e-12, "{:?}", j.data_to_surface);
    // Far from the data (corners of the limit, ~1.3 from the square): far, less the radius.
    assert!(j.surface_to_data.max > 1.0, "{:?}", j.surface_to_data);
    assert!(j.surface_to_data.mean > 0.3, "{:?}", j.surface_to_data);
    assert_eq!(j.isolated_points, 0);

    // Two clusters of three stray returns, 0.5 and 0.8 above the square (a range scan's), are
    // left out of data → surface; a patch of 16 points floating as far is data and is measured.
    let mut strays = points.clone();
    for (i, h) in [
        (0.0, 0.5),
        (0.002, 0.5),
        (0.004, 0.5),
        (0.5, 0.8),
        (0.502, 0.8),
        (0.5, 0.802),
    ] {
        strays.push([0.3 + i, 0.3, h]);
    }
    let j = judge(
        &Reference::Points {
            positions: strays.clone(),
        },
        &cage,
        &small(),
    )
    .unwrap();
    assert_eq!(j.isolated_points, 6);
    assert!(j.data_to_surface.max < 1e-12, "{:?}", j.data_to_surface);
    for a in 0..4 {
        for b in 0..4 {
            strays.push([0.9 + 0.025 * a as f64, 0.9 + 0.025 * b as f64, 0.6]);
        }
    }
    let j = judge(&Reference::Points { positions: strays }, &cage, &small()).unwrap();
    assert_eq!(j.isolated_points, 6);
    assert!(
        (j.data_to_surface.max - 0.6).abs() < 1e-9,
        "{:?}",
        j.data_to_surface
    );
}

#[test]
fn figures_scale_with_the_input_and_ignore_threads() {
    let cage = cheng_ellipsoid_cage(0.5, 0.8, 1.0, true);
    let (reference, _) = offset_limit(&cage, &Tags::new(), Scheme::Loop, 8, 0.02);
    let Reference::Mesh {
        positions,
        triangles,
    } = &reference
    else {
        unreachable!()
    };
    // The cloud of the reference's vertices, once each (patches share their borders).
    let mut used: Vec<[f64; 3]> = triangles
        .iter()
        .flatten()
        .map(|&i| positions[i as usize])
        .collect();
    used.sort_by(|a, b| {
        a.iter()
            .zip(b)
            .fold(std::cmp::Ordering::Equal, |o, (x, y)| {
                o.then(x.total_cmp(y))
            })
    });
    used.dedup();
    let cloud = Reference::Points { positions: used };
    let s = 1e3;
    let grow = |r: &Reference| match r {
        Reference::Mesh {
            positions,
            triangles,
        } => Reference::Mesh {
            positions: positions.iter().map(|&p| scale(p, s)).collect(),
            triangles: triangles.clone(),
        },
        Reference::Points { positions } => Reference::Points {
            positions: positions.iter().map(|&p| scale(p, s)).collect(),
        },
    };
    let candidate = Candidate::limit(cage.clone(), Tags::new(), Scheme::Loop);
    let big = Candidate::limit(scaled(&cage, s), Tags::new(), Scheme::Loop);
    for r in [reference, cloud] {
        let a = judge(&r, &candidate, &small()).unwrap();
        let b = judge(&grow(&r), &big, &small()).unwrap();
        let pairs = [
            (a.data_to_surface.rms, b.data_to_surface.rms),
            (a.data_to_surface.mean, b.data_to_surface.mean),
            (a.data_to_surface.max, b.data_to_surface.max),
            (a.data_to_surface.p95, b.data_to_surface.p95),
            (a.surface_to_data.rms, b.surface_to_data.rms),
            (a.surface_to_data.mean, b.surface_to_data.mean),
            (a.surface_to_data.max, b.surface_to_data.max),
            (a.surface_to_data.p95, b.surface_to_data.p95),
            (a.rms, b.rms),
            (a.hausdorff, b.hausdorff),
            (a.diagonal, b.diagonal),
            (a.tessellation_deviation, b.tessellation_deviation),
            (
                a.point_spacing.unwrap_or(1.0),
                b.point_spacing.map_or(s, |x| x),
            ),
        ];
        for (k, (x, y)) in pairs.into_iter().enumerate() {
            assert!(
                (y - s * x).abs() <= 1e-9 * s * x,
                "figure {k}: {x} × 1e3 vs {y}\n{a:?}\n{b:?}"
            );
        }
        assert!((a.rms_fraction - b.rms_fraction).abs() <= 1e-9 * a.rms_fraction);
        assert_eq!(a.data_to_surface.samples, b.data_to_surface.samples);

        let one = judge(
            &r,
            &candidate,
            &JudgeOptions {
                threads: Some(1),
                ..small()
            },
        )
        .unwrap();
        let two = judge(
            &r,
            &candidate,
            &JudgeOptions {
                threads: Some(2),
                ..small()
            },
        )
        .unwrap();
        assert_eq!(
            (
                one.data_to_surface,
                one.surface_to_data,
                one.tessellation_deviation
            ),
            (
                two.data_to_surface,
                two.surface_to_data,
                two.tessellation_deviation
            )
        );
        assert_eq!(
            (one.data_to_surface, one.surface_to_data),
            (a.data_to_surface, a.surface_to_data)
        );
    }
}

#[test]
fn bad_input_is_a_typed_error() {
    let sphere = geodesic_sphere(1);
    let good = Reference::from_polymesh(&sphere);
    let candidate = Candidate::mesh_from_polymesh(&sphere);
    let o = small();
    let mut nan = sphere.clone();
    nan.positions[7][1] = f64::NAN;
    let err = judge(&Reference::from_polymesh(&nan), &candidate, &o).unwrap_err();
    assert!(
        matches!(err, JudgeError::NonFinite { index: 7, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("reference vertex 7"), "{err}");
    let bad = Reference::Mesh {
        positions: sphere.positions.clone(),
        triangles: vec![[0, 1, 2], [0, 1, 999]],
    };
    let err = judge(&bad, &candidate, &o).unwrap_err();
    assert!(
        matches!(
            err,
            JudgeError::BadIndex {
                face: 1,
                vertex: 999,
                ..
            }
        ),
        "{err}"
    );
    let few = Reference::Points {
        positions: sphere.positions[..5].to_vec(),
    };
    assert!(matches!(
        judge(&few, &candidate, &o),
        Err(JudgeError::TooFewPoints { got: 5, .. })
    ));
    let flat = Reference::Points {
        positions: vec![[1.0, 2.0, 3.0]; 20],
    };
    assert!(matches!(
        judge(&flat, &candidate, &o),
        Err(JudgeError::Degenerate)
    ));
    // A quad cage under Loop: the subdivision refuses it.
    let quads = Candidate::limit(cube_mesh(1.0), Tags::new(), Scheme::Loop);
    let err = judge(&good, &quads, &o).unwrap_err();
    assert!(matches!(err, JudgeError::Cage(_)), "{err}");
    let empty = Candidate::Mesh {
        positions: sphere.positions.clone(),
        triangles: Vec::new(),
    };
    assert!(matches!(
        judge(&good, &empty, &o),
        Err(JudgeError::Empty { .. })
    ));
    let zero = JudgeOptions {
        tessellation_triangles: 0,
        ..o
    };
    assert!(matches!(
        judge(&good, &candidate, &zero),
        Err(JudgeError::BadOption {
            name: "tessellation_triangles",
            ..
        })
    ));
}
