//! The rest shape of [`super`] and its random-resolution tessellation.
//!
//! The rest shape is a body of length 2 along z: a capsule (spine `z ∈ [−H, H]`, radius `R`)
//! whose radius is modulated by an elliptic cross-section and three Gaussian bumps, so that no
//! rotation or mirror maps it onto itself. Every point is `a + ρ(d)·d`, with `a` the spine point
//! nearest the point and `d` the unit direction from it ([`rest_point`] projects any point off
//! the spine this way), so the body is star-shaped about its spine and the projection of a
//! polyhedron wrapped around the spine is a bijection.
//!
//! The polyhedron is an *elongated icosahedron*: the two caps of an icosahedron of radius `R`
//! centred at the spine ends, with `k` pentagonal antiprism layers between their rings (the
//! icosahedron itself is `k = 1`; `k` is chosen so the layers are near-equilateral). Each face
//! is split into `n²` triangles (class I geodesic subdivision, Kenner, *Geodesic Math and How
//! to Use It*, 1976, ch. 6), the points are jittered and projected. The result has
//! `V = 5(k + 1)n² + 2` vertices, `2(V − 2)` triangles, no sliver (the base faces are
//! near-equilateral and the projection stretches them by at most about 1.2), and faces wound
//! counter-clockwise seen from outside.

use std::collections::HashMap;
use std::f64::consts::{PI, TAU};

use rand::rngs::StdRng;
use rand::Rng;

use crate::vec3::{add, dist2, scale, sub, unit};

/// Capsule radius (before the elliptic and bump modulation).
pub(super) const RADIUS: f64 = 0.35;
/// Half length of the spine; the body spans `z ∈ [−(H + R), H + R] = [−1, 1]`.
pub(super) const HALF_SPINE: f64 = 0.65;
/// Relative radius change of the elliptic cross-section: `ρ = R(1 + E cos 2φ)` along the
/// cylinder, semi-axes `R(1 ± E)` (0.4025 along x, 0.2975 along y).
const ELLIPTICITY: f64 = 0.15;
/// Gaussian bumps `(axial position, azimuth, height, width)` on the base capsule.
const BUMPS: [(f64, f64, f64, f64); 3] = [
    (0.35, 0.7, 0.06, 0.18),
    (-0.25, 3.6, 0.05, 0.22),
    (0.6, 2.2, 0.04, 0.15),
];
/// Largest distance of the rest surface from its spine (`R(1 + E)` plus the highest bump),
/// rounded up: bounds how far the bend may go before the body folds.
pub(super) const MAX_OFFSET: f64 = 0.47;
/// Vertex jitter, as a fraction of the subdivided edge length, per coordinate.
const JITTER: f64 = 0.12;

/// The point of the rest surface on the ray from the spine through `p` (see the module doc).
/// `p` must not lie on the spine itself.
pub(super) fn rest_point(p: [f64; 3]) -> [f64; 3] {
    let a = [0.0, 0.0, p[2].clamp(-HALF_SPINE, HALF_SPINE)];
    let d = unit(sub(p, a)).unwrap_or([1.0, 0.0, 0.0]);
    let base = add(a, scale(d, RADIUS));
    let mut rho = RADIUS * (1.0 + ELLIPTICITY * (d[0] * d[0] - d[1] * d[1]));
    for (z, phi, height, width) in BUMPS {
        let c = [RADIUS * phi.cos(), RADIUS * phi.sin(), z];
        rho += height * (-dist2(base, c) / (width * width)).exp();
    }
    add(a, scale(d, rho))
}

/// A random-resolution triangulation of the rest surface: vertex positions on it (the material
/// coordinates, `#V by 3`) and triangles (`#T by 3`, counter-clockwise seen from outside).
///
/// `target` is the wanted vertex count; the layer count `k` (one of the two nearest the
/// equilateral spacing), the azimuth of the polyhedron and the jitter are drawn from `rng`;
/// the subdivision `n` gives the count nearest `target` among those within ±30% of `approx`
/// (or nearest `target` if none is). Cost: O(#V).
pub(super) fn tessellate(
    target: f64,
    approx: f64,
    rng: &mut StdRng,
) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    // Icosahedron of radius R: rings at height R/√5 from the centre, of radius 2R/√5.
    let ring_radius = 2.0 * RADIUS / 5f64.sqrt();
    let end_ring = HALF_SPINE + RADIUS / 5f64.sqrt();
    let layers_exact = 2.0 * end_ring / ring_radius;
    let layers = (layers_exact.floor() as usize).max(1) + usize::from(rng.random_bool(0.5));
    let rings = layers + 1;
    let count = |n: usize| (5 * rings * n * n + 2) as f64;
    let guess = (((target - 2.0) / (5 * rings) as f64).sqrt().round() as usize).max(1);
    let n = (guess.saturating_sub(1).max(1)..=guess + 1)
        .min_by_key(|&n| {
            let outside = (count(n) - approx).abs() > 0.3 * approx;
            (outside, (count(n) - target).abs() as u64)
        })
        .unwrap_or(guess);
    let azimuth = rng.random_range(0.0..TAU);

    let mut base = vec![
        [0.0, 0.0, -HALF_SPINE - RADIUS],
        [0.0, 0.0, HALF_SPINE + RADIUS],
    ];
    for j in 0..rings {
        let z = -end_ring + 2.0 * end_ring * j as f64 / layers as f64;
        for i in 0..5 {
            let phi = azimuth + PI * (j as f64 + 2.0 * i as f64) / 5.0;
            base.push([ring_radius * phi.cos(), ring_radius * phi.sin(), z]);
        }
    }
    let ring = |j: usize, i: usize| (2 + 5 * j + i % 5) as u32;
    let mut faces = Vec::with_capacity(10 * rings);
    for i in 0..5 {
        faces.push([0, ring(0, i + 1), ring(0, i)]);
        faces.push([1, ring(rings - 1, i), ring(rings - 1, i + 1)]);
        for j in 0..layers {
            // Ring j + 1 is turned by 36° from ring j: its vertex i sits above the gap i, i + 1.
            faces.push([ring(j, i), ring(j, i + 1), ring(j + 1, i)]);
            faces.push([ring(j + 1, i), ring(j, i + 1), ring(j + 1, i + 1)]);
        }
    }
    let (mut points, triangles) = subdivide(&base, &faces, n);
    let step = JITTER * 2.0 * ring_radius * (PI / 5.0).sin() / n as f64;
    for p in &mut points {
        let jitter = [0; 3].map(|_| rng.random_range(-step..=step));
        *p = rest_point(add(*p, jitter));
    }
    (points, triangles)
}

/// Class I geodesic subdivision: every triangle of `faces` (over `base`) split into `n²`
/// triangles of the same orientation, points on shared edges created once. Returns the points
/// (the base vertices first) and the triangles. Cost: O(#faces · n²).
fn subdivide(base: &[[f64; 3]], faces: &[[u32; 3]], n: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut points = base.to_vec();
    let mut triangles = Vec::with_capacity(faces.len() * n * n);
    // First of the n − 1 points of each edge, listed from its smaller to its larger vertex.
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    let lerp = |a: [f64; 3], b: [f64; 3], t: f64| add(a, scale(sub(b, a), t));
    let row = |j: usize| j * (n + 1) - j * j.saturating_sub(1) / 2;
    let mut local = Vec::with_capacity((n + 1) * (n + 2) / 2);
    for &[a, b, c] in faces {
        let mut edge_point = |x: u32, y: u32, t: usize, points: &mut Vec<[f64; 3]>| -> u32 {
            let (lo, hi, t) = if x < y { (x, y, t) } else { (y, x, n - t) };
            let first = *edges.entry((lo, hi)).or_insert_with(|| {
                let first = points.len() as u32;
                let (p, q) = (points[lo as usize], points[hi as usize]);
                points.extend((1..n).map(|s| lerp(p, q, s as f64 / n as f64)));
                first
            });
            first + t as u32 - 1
        };
        let [pa, pb, pc] = [a, b, c].map(|v| points[v as usize]);
        local.clear();
        for j in 0..=n {
            for i in 0..=n - j {
                let id = match (i, j) {
                    (0, 0) => a,
                    _ if i == n => b,
                    _ if j == n => c,
                    (_, 0) => edge_point(a, b, i, &mut points),
                    (0, _) => edge_point(a, c, j, &mut points),
                    _ if i + j == n => edge_point(b, c, j, &mut points),
                    _ => {
                        let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                        points.push(add(pa, add(scale(sub(pb, pa), u), scale(sub(pc, pa), v))));
                        (points.len() - 1) as u32
                    }
                };
                local.push(id);
            }
        }
        debug_assert_eq!(local.len(), row(n + 1));
        let at = |i: usize, j: usize| local[row(j) + i];
        for j in 0..n {
            for i in 0..n - j {
                triangles.push([at(i, j), at(i + 1, j), at(i, j + 1)]);
                if i + j + 2 <= n {
                    triangles.push([at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
    }
    (points, triangles)
}
