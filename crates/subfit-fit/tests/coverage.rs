//! The data → surface part of the objective ([`subfit_fit::Coverage`], `FitOptions::coverage`):
//! its model is the Gauss-Newton model of what it adds to the objective, and on an open patch
//! it pulls the limit boundary out to the data's edge, which Cheng's one-sided terms leave
//! shrunk inside it.

use subfit_fit::{
    fit_stages, Coverage, DataTerm, FitOptions, Fitter, FootPointTerm, FootSample, StageOptions,
};
use subfit_measure::MeshDistance;
use subfit_mesh::{PolyMesh, Polygons};
use subfit_subdiv::{sampling_operator, Options, Scheme};
use subfit_target::{Target, TargetOptions};

/// The saddle `z = 0.3 (x² − y²)` over the unit disc: a centre and `n` rings of `6i` vertices,
/// rings joined by triangle strips that advance by angle (open, one round boundary loop, no
/// corner).
fn saddle(n: usize) -> PolyMesh {
    let mut p = vec![[0.0, 0.0, 0.0]];
    let mut rings: Vec<Vec<u32>> = vec![vec![0]];
    for i in 1..=n {
        let r = i as f64 / n as f64;
        let k = 6 * i;
        let ring: Vec<u32> = (0..k)
            .map(|j| {
                let t = std::f64::consts::TAU * j as f64 / k as f64;
                let (x, y) = (r * t.cos(), r * t.sin());
                p.push([x, y, 0.3 * (x * x - y * y)]);
                (p.len() - 1) as u32
            })
            .collect();
        rings.push(ring);
    }
    let mut tris = Vec::new();
    for i in 1..=n {
        let (inner, outer) = (&rings[i - 1], &rings[i]);
        if inner.len() == 1 {
            for j in 0..outer.len() {
                tris.push([inner[0], outer[j], outer[(j + 1) % outer.len()]]);
            }
            continue;
        }
        // Merge the two rings by angle: each step advances the ring whose next vertex comes
        // first.
        let (a, b) = (inner.len(), outer.len());
        let (mut ia, mut ib) = (0, 0);
        while ia < a || ib < b {
            let ta = (ia + 1) as f64 / a as f64;
            let tb = (ib + 1) as f64 / b as f64;
            if ib < b && (ia >= a || tb <= ta) {
                tris.push([inner[ia % a], outer[ib], outer[(ib + 1) % b]]);
                ib += 1;
            } else {
                tris.push([inner[ia], outer[ib % b], inner[(ia + 1) % a]]);
                ia += 1;
            }
        }
    }
    PolyMesh::new(p, Polygons::from_triangles(&tris))
}

/// Vertices of `mesh` on edges of one face.
fn boundary_vertices(mesh: &PolyMesh) -> Vec<usize> {
    let mut count = std::collections::HashMap::new();
    for f in mesh.faces.iter() {
        for i in 0..f.len() {
            let (a, b) = (f[i], f[(i + 1) % f.len()]);
            *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let mut v: Vec<usize> = count
        .iter()
        .filter(|(_, &c)| c == 1)
        .flat_map(|(&(a, b), _)| [a as usize, b as usize])
        .collect();
    v.sort_unstable();
    v.dedup();
    v
}

/// The dense target and a coarse cage on it (normalized coordinates).
fn setup() -> (Target, PolyMesh) {
    let data = saddle(40);
    let target = Target::from_mesh(&data, &TargetOptions::default()).unwrap();
    let mut cage = saddle(3);
    for p in &mut cage.positions {
        *p = target.to_normalized(*p);
    }
    (target, cage)
}

/// Largest distance of the target's boundary vertices to the level-3 limit tessellation of
/// `control` (normalized units).
fn boundary_gap(target: &Target, cage: &PolyMesh, control: &[[f64; 3]]) -> f64 {
    let op = sampling_operator(
        &cage.faces,
        cage.num_vertices(),
        &Default::default(),
        &Options::new(Scheme::Loop),
        3,
    )
    .unwrap();
    let samples = op.position.apply(control);
    let rim: Vec<[f64; 3]> = boundary_vertices(&saddle(40))
        .into_iter()
        .map(|i| target.points()[i])
        .collect();
    MeshDistance::new(&samples, &op.faces)
        .distances(&rim)
        .iter()
        .fold(0.0f64, |m, d| m.max(d.distance))
}

fn diagonal(target: &Target) -> f64 {
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in target.points() {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    (0..3).map(|a| (hi[a] - lo[a]).powi(2)).sum::<f64>().sqrt()
}

#[test]
fn target_boundary_vertices_are_found() {
    let (target, _) = setup();
    let term =
        FootPointTerm::new(&target, Default::default(), Default::default()).with_coverage(1.0);
    assert_eq!(term.coverage().unwrap().num_boundary_points(), 6 * 40);
}

#[test]
fn the_model_is_the_gauss_newton_model_of_the_objective_share() {
    let (target, cage) = setup();
    let opts = FitOptions {
        coverage: 1.0,
        ..FitOptions::default()
    };
    let mut term = FootPointTerm::from_options(&target, &opts);
    let op = sampling_operator(
        &cage.faces,
        cage.num_vertices(),
        &Default::default(),
        &Options::new(Scheme::Loop),
        3,
    )
    .unwrap();
    term.prepare(&op);
    // The coarse cage's limit lies inside the rim: the boundary samples collect data.
    let xs = op.position.apply(&cage.positions);
    let state = term.project(None, &xs);
    let covered = state.iter().filter(|s| s.cover.is_some()).count();
    assert!(covered >= 10, "{covered} of {}", xs.len());
    // The data part of the model's residual is half the gradient of the data part of the
    // objective share (assignment frozen), by central differences; the foot-point part is
    // the term's own model (checked in tests/term.rs).
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    for (s, &x) in state.iter().zip(&xs) {
        let (_, r) = term.model(s, x);
        let bare = FootSample {
            foot: s.foot,
            cover: None,
            weight: 1.0,
        };
        let (_, r_foot) = term.model(&bare, x);
        let half = |y: [f64; 3]| 0.5 * s.cover.as_ref().map_or(0.0, |c| c.energy(y));
        for a in 0..3 {
            let h = 1e-7;
            let (mut xp, mut xm) = (x, x);
            xp[a] += h;
            xm[a] -= h;
            let fd = (half(xp) - half(xm)) / (2.0 * h);
            worst = worst.max((fd - (r[a] - r_foot[a])).abs());
            scale = scale.max(r[a].abs());
        }
        let e2 = term.squared_error(s, x);
        let obj = term.objective_error(s, x);
        assert!(obj >= e2);
        if s.cover.is_none() {
            assert_eq!(obj, e2);
        }
    }
    assert!(worst <= 1e-6 * scale, "{worst:e} vs {scale:e}");
    // Fresh projections (measurements) carry no data part.
    assert!(term.project_fresh(&xs).iter().all(|s| s.cover.is_none()));
}

#[test]
fn coverage_pulls_the_boundary_out_to_the_data() {
    let (target, cage) = setup();
    let diag = diagonal(&target);
    let mut gaps = Vec::new();
    for coverage in [0.0, 1.0] {
        let opts = FitOptions {
            coverage,
            lambda: 1e-4,
            max_iterations: 30,
            ..FitOptions::default()
        };
        let mut fitter = Fitter::new(&target, &cage.faces, cage.num_vertices(), &opts).unwrap();
        let mut p = cage.positions.clone();
        fitter.run(&mut p, None).unwrap();
        gaps.push(boundary_gap(&target, &cage, &p) / diag);
    }
    // One-sided, the B-spline rim stays inside the data's edge; both ways it reaches it.
    assert!(gaps[0] > 0.01, "one-sided rim gap {:.2e}", gaps[0]);
    assert!(gaps[1] < 0.005, "two-sided rim gap {:.2e}", gaps[1]);
}

#[test]
fn stages_reach_the_two_sided_tolerance_on_an_open_patch() {
    let (target, cage) = setup();
    let base = FitOptions {
        coverage: 1.0,
        ..FitOptions::default()
    };
    let stages = StageOptions {
        tolerance_rms: 5e-4,
        ..StageOptions::default()
    };
    let r = fit_stages(&target, &cage, &base, &stages, None).unwrap();
    let two = r.report.two_sided;
    assert!(
        two.within(5e-4, 0.0),
        "two-sided rms {:.2e} / {:.2e}",
        two.surface_to_data.rms,
        two.data_to_surface.rms
    );
    let diag = diagonal(&target);
    assert!(
        two.max() / diag < 0.01,
        "Hausdorff {:.2e}",
        two.max() / diag
    );
    let gap = boundary_gap_of(&target, &r.mesh) / diag;
    assert!(gap < 0.005, "rim gap {gap:.2e}");
}

fn boundary_gap_of(target: &Target, mesh: &PolyMesh) -> f64 {
    boundary_gap(target, mesh, &mesh.positions)
}

/// The feature-curve part ([`subfit_fit::Coverage::with_features`], through
/// `FitOptions::feature_segments`): on a creased cube cage, whose limit is the cube itself, data
/// feature curves offset by `δ` from its edges add `FEATURE_WEIGHT · m · δ²` to the objective
/// share (each curve point `δ` from the crease line it pulls), all of it on crease samples.
#[test]
fn feature_curves_pull_the_creases_perpendicular_to_them() {
    use std::sync::Arc;
    use subfit_fit::FEATURE_WEIGHT;
    use subfit_mesh::shapes::{cube_mesh, gridded_box};
    use subfit_mesh::{Tags, SHARPNESS_INFINITE};

    let target = Target::from_mesh(&gridded_box(8, false), &TargetOptions::default()).unwrap();
    let cube = cube_mesh(0.5);
    let positions: Vec<[f64; 3]> = cube
        .positions
        .iter()
        .map(|p| target.to_normalized(p.map(|c| c + 0.5)))
        .collect();
    let faces = Polygons::from_triangles(&cube.faces.triangulate_fan());
    let mut tags = Tags::new();
    let mut segments = Vec::new();
    let delta = 0.01;
    for a in 0..8u32 {
        tags.set_corner(a, SHARPNESS_INFINITE);
        for bit in [1u32, 2, 4] {
            let b = a | bit;
            if b != a {
                tags.set_crease(a, b, SHARPNESS_INFINITE);
                // The edge moved by δ along an axis across it.
                let off = if bit == 1 { 1 } else { 0 };
                let shift = |p: [f64; 3]| {
                    let mut q = p;
                    q[off] += delta;
                    q
                };
                segments.push([shift(positions[a as usize]), shift(positions[b as usize])]);
            }
        }
    }
    let opts = FitOptions {
        coverage: 1.0,
        feature_segments: Some(Arc::new(segments)),
        tags: tags.clone(),
        ..FitOptions::default()
    };
    let mut term = FootPointTerm::from_options(&target, &opts);
    assert_eq!(term.coverage().unwrap().num_feature_points(), 12);
    let op = sampling_operator(&faces, 8, &tags, &Options::new(Scheme::Loop), 2).unwrap();
    term.prepare(&op);
    let crease_rows = term.coverage().unwrap().num_crease_samples();
    assert_eq!(
        crease_rows,
        12 * 3 + 8,
        "level 2: 3 new samples per cube edge"
    );
    let xs = op.position.apply(&positions);
    let state = term.project(None, &xs);
    let mut energy = 0.0;
    let mut crease_sample = vec![false; xs.len()];
    for ((a, b), _) in op.tags.creases() {
        crease_sample[a as usize] = true;
        crease_sample[b as usize] = true;
    }
    for (k, (s, &x)) in state.iter().zip(&xs).enumerate() {
        if let Some(c) = &s.cover {
            assert!(crease_sample[k], "sample {k} off the creases has a pair");
            energy += c.energy(x);
        }
    }
    let expected = FEATURE_WEIGHT * xs.len() as f64 * delta * delta;
    assert!(
        (energy - expected).abs() < 1e-9 * expected,
        "{energy} vs {expected}"
    );
}

/// On a noisy cloud every data point pulls its nearest sample along the surface's normal, not
/// only uncovered data: Cheng et al.'s one-sided term is small for any surface inside the band
/// of noisy points, so only this data → surface least squares puts the surface in the band's
/// middle. A plane of 3,600 points with Gaussian noise σ = 0.05 across it, and a flat cage
/// one σ above it: the pulls, summed over the samples, move the cage to the band's middle
/// (the old rule counted no pair here, every point being within a sample spacing).
#[test]
fn a_noisy_cloud_pulls_the_surface_to_the_middle_of_its_band() {
    let (n, sigma) = (60, 0.05);
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut points = Vec::new();
    for i in 0..n {
        for j in 0..n {
            // Box–Muller.
            let (u, v) = (uniform().max(1e-300), uniform());
            let z = sigma * (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos();
            let at = |k: usize| -1.0 + 2.0 * (k as f64 + 0.5) / n as f64;
            points.push([at(i), at(j), z]);
        }
    }
    let target = Target::from_points(&points, None, &TargetOptions::default()).unwrap();
    assert!(target.stats().is_noisy(), "{:?}", target.stats());
    // A 6 × 6 grid of triangles over the square, one σ above the plane (normalized units).
    let k = 6;
    let mut cage = Vec::new();
    for i in 0..=k {
        for j in 0..=k {
            let at = |k2: usize| -1.0 + 2.0 * k2 as f64 / k as f64;
            cage.push(target.to_normalized([at(i), at(j), sigma]));
        }
    }
    let id = |i: usize, j: usize| (i * (k + 1) + j) as u32;
    let mut tris = Vec::new();
    for i in 0..k {
        for j in 0..k {
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let faces = Polygons::from_triangles(&tris);
    let op = sampling_operator(
        &faces,
        cage.len(),
        &Default::default(),
        &Options::new(Scheme::Loop),
        3,
    )
    .unwrap();
    let mut coverage = Coverage::new(&target, 1.0);
    coverage.prepare(&op);
    let xs = op.position.apply(&cage);
    let sums = coverage.assign(&xs);
    let pairs: u32 = sums.iter().flatten().map(|s| s.count()).sum();
    assert!(pairs as usize >= points.len() / 2, "{pairs} pairs");
    // The common shift t of all samples along z minimizing the summed quadratics:
    // t = −Σ r_z / Σ Q_zz with (Q, r) the models at the samples.
    let (mut q, mut r) = (0.0, 0.0);
    for (s, &x) in sums.iter().zip(&xs) {
        if let Some(s) = s {
            let (qs, rs) = s.model(x);
            q += qs[2][2];
            r += rs[2];
        }
    }
    let t = -r / q;
    // Normalized units: the plane is at z = 0 and the cage at σ·scale.
    let scale = target.to_normalized([0.0, 0.0, sigma])[2] - target.to_normalized([0.0; 3])[2];
    let plane = target.to_normalized([0.0; 3])[2];
    let lands = xs[0][2] + t - plane;
    assert!(
        lands.abs() < 0.15 * scale,
        "the cage lands {:.3} σ from the plane",
        lands / scale
    );
}
