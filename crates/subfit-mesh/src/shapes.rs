//! Generated shapes for the demo, tests and benchmarks: analytic surfaces sampled as oriented
//! point clouds (optionally noisy), and simple control meshes (module `control_meshes`,
//! re-exported here).
//!
//! The built-in default shapes are the ellipsoid with semi-axes 0.25/0.5/1.0 of Cheng et al.
//! 2007 (Examples 1–10), a torus (genus 1) and a genus-2 surface. Every sampler is seeded, so
//! the same call gives the same points on every machine.
//!
//! Sampling is uniform with respect to surface area: the ellipsoid and the torus are sampled
//! through their parametrisations with rejection on the area element; the genus-2 surface is an
//! implicit surface, sampled by Newton projection of random points followed by thinning on a
//! voxel grid (approximately uniform).

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};

use crate::polygons::{PolyMesh, Polygons};
use crate::vec3::{dot, unit};

mod control_meshes;

pub use control_meshes::{
    capped_cylinder, cheng_ellipsoid_cage, cube_mesh, geodesic_sphere, gridded_box, l_prism,
    octahedron_mesh, rounded_prism, torus_mesh,
};

/// An analytic closed surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// Ellipsoid `x²/a² + y²/b² + z²/c² = 1` centred at the origin (genus 0).
    Ellipsoid {
        /// Semi-axis along x.
        a: f64,
        /// Semi-axis along y.
        b: f64,
        /// Semi-axis along z.
        c: f64,
    },
    /// Torus around the z axis with tube centre radius `major` and tube radius `minor` (genus 1).
    Torus {
        /// Distance from the z axis to the tube centre.
        major: f64,
        /// Tube radius (`< major`).
        minor: f64,
    },
    /// A genus-2 surface: `g(x, y)² + z² = ε²` with `g = (x² + y²)² − x² + y²` (a tube around
    /// a lemniscate; the two lobes leave two holes). Extent about 2.3 × 0.8 × 2ε.
    Genus2 {
        /// Half-thickness `ε` (`0 < ε < 1/4`; default 0.15).
        eps: f64,
    },
}

impl Shape {
    /// The ellipsoid of Cheng et al. 2007, semi-axes 0.25 / 0.5 / 1.0.
    pub const PAPER_ELLIPSOID: Shape = Shape::Ellipsoid {
        a: 0.25,
        b: 0.5,
        c: 1.0,
    };
    /// The default torus: major radius 1, minor radius 0.35.
    pub const DEFAULT_TORUS: Shape = Shape::Torus {
        major: 1.0,
        minor: 0.35,
    };
    /// The default genus-2 surface, `ε = 0.15`.
    pub const DEFAULT_GENUS2: Shape = Shape::Genus2 { eps: 0.15 };

    /// The built-in default shapes with their names, in the order the demo uses them.
    pub fn builtin() -> [(&'static str, Shape); 3] {
        [
            ("ellipsoid", Self::PAPER_ELLIPSOID),
            ("torus", Self::DEFAULT_TORUS),
            ("genus2", Self::DEFAULT_GENUS2),
        ]
    }

    /// Genus of the surface.
    pub fn genus(&self) -> u32 {
        match self {
            Shape::Ellipsoid { .. } => 0,
            Shape::Torus { .. } => 1,
            Shape::Genus2 { .. } => 2,
        }
    }

    /// Implicit function, negative inside, zero on the surface (not a distance).
    pub fn implicit(&self, p: [f64; 3]) -> f64 {
        let [x, y, z] = p;
        match *self {
            Shape::Ellipsoid { a, b, c } => {
                (x / a).powi(2) + (y / b).powi(2) + (z / c).powi(2) - 1.0
            }
            Shape::Torus { major, minor } => {
                let q = (x * x + y * y).sqrt() - major;
                q * q + z * z - minor * minor
            }
            Shape::Genus2 { eps } => {
                let g = lemniscate(x, y);
                g * g + z * z - eps * eps
            }
        }
    }

    /// Gradient of [`Shape::implicit`].
    pub fn gradient(&self, p: [f64; 3]) -> [f64; 3] {
        let [x, y, z] = p;
        match *self {
            Shape::Ellipsoid { a, b, c } => {
                [2.0 * x / (a * a), 2.0 * y / (b * b), 2.0 * z / (c * c)]
            }
            Shape::Torus { major, .. } => {
                let rho = (x * x + y * y).sqrt().max(1e-300);
                let q = rho - major;
                [2.0 * q * x / rho, 2.0 * q * y / rho, 2.0 * z]
            }
            Shape::Genus2 { .. } => {
                let g = lemniscate(x, y);
                let r2 = x * x + y * y;
                let gx = 4.0 * x * r2 - 2.0 * x;
                let gy = 4.0 * y * r2 + 2.0 * y;
                [2.0 * g * gx, 2.0 * g * gy, 2.0 * z]
            }
        }
    }

    /// Outward unit normal at a point on (or near) the surface.
    pub fn normal(&self, p: [f64; 3]) -> [f64; 3] {
        normalize(self.gradient(p))
    }

    /// A box `(min, max)` containing the surface.
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        match *self {
            Shape::Ellipsoid { a, b, c } => ([-a, -b, -c], [a, b, c]),
            Shape::Torus { major, minor } => {
                let r = major + minor;
                ([-r, -r, -minor], [r, r, minor])
            }
            Shape::Genus2 { eps } => {
                // |g| ≤ eps; the lemniscate reaches |x| = 1, |y| ≈ 0.354; pad by the tube width.
                let pad = 0.5 * eps + 0.05;
                (
                    [-1.0 - pad, -0.36 - pad, -eps],
                    [1.0 + pad, 0.36 + pad, eps],
                )
            }
        }
    }

    /// Samples about `n` points uniformly by area, with outward unit normals, then adds Gaussian
    /// noise of standard deviation `noise` × (bounding-box diagonal) along random directions
    /// (normals stay those of the clean surface). Deterministic for a given `seed`.
    ///
    /// Returns a point cloud (`faces` empty, `normals` set). The ellipsoid and torus give exactly
    /// `n` points; the genus-2 sampler gives `n` points up to thinning (within a few percent).
    /// Cost: O(n) (genus 2: O(n) with a larger constant).
    pub fn sample(&self, n: usize, noise: f64, seed: u64) -> PolyMesh {
        let mut rng = StdRng::seed_from_u64(seed);
        let (mut points, normals) = match *self {
            Shape::Ellipsoid { a, b, c } => sample_ellipsoid(a, b, c, n, &mut rng),
            Shape::Torus { major, minor } => sample_torus(major, minor, n, &mut rng),
            Shape::Genus2 { .. } => self.sample_implicit(n, &mut rng),
        };
        if noise > 0.0 {
            let (lo, hi) = self.bounds();
            let diag =
                ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2))
                    .sqrt();
            let normal = Normal::new(0.0, noise * diag).expect("finite standard deviation");
            for p in &mut points {
                for c in p.iter_mut() {
                    *c += normal.sample(&mut rng);
                }
            }
        }
        PolyMesh::point_cloud(points, Some(normals))
    }

    /// Closest point on the surface found by Newton projection along the gradient from `p`.
    /// Exact enough for sampling (it converges to a nearby surface point, not necessarily the
    /// closest one far from the surface). Returns `None` when Newton does not converge.
    pub fn project(&self, p: [f64; 3]) -> Option<[f64; 3]> {
        let mut x = p;
        for _ in 0..60 {
            let f = self.implicit(x);
            let g = self.gradient(x);
            let gg = dot(g, g);
            if gg < 1e-300 {
                return None;
            }
            let s = f / gg;
            for k in 0..3 {
                x[k] -= s * g[k];
            }
            if f.abs() < 1e-14 && s.abs() * gg.sqrt() < 1e-14 {
                return Some(x);
            }
        }
        (self.implicit(x).abs() < 1e-10).then_some(x)
    }

    fn sample_implicit(&self, n: usize, rng: &mut StdRng) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        // Oversample by projecting random points, then keep one point per voxel of a grid sized
        // so that about n voxels are occupied: close to uniform by area.
        let (lo, hi) = self.bounds();
        let mut raw = Vec::with_capacity(8 * n);
        let mut tries = 0usize;
        while raw.len() < 8 * n && tries < 200 * n + 1000 {
            tries += 1;
            let p = [
                rng.random_range(lo[0]..hi[0]),
                rng.random_range(lo[1]..hi[1]),
                rng.random_range(lo[2]..hi[2]),
            ];
            if let Some(q) = self.project(p) {
                if (0..3).all(|k| q[k] >= lo[k] - 1e-9 && q[k] <= hi[k] + 1e-9) {
                    raw.push(q);
                }
            }
        }
        thin_to(raw, n, lo, hi)
            .into_iter()
            .map(|p| (p, self.normal(p)))
            .unzip()
    }
}

/// `g(x, y) = (x² + y²)² − x² + y²`, negative inside the lobes of the lemniscate.
fn lemniscate(x: f64, y: f64) -> f64 {
    let r2 = x * x + y * y;
    r2 * r2 - x * x + y * y
}

/// `v / |v|`, or `z` for a zero vector.
fn normalize(v: [f64; 3]) -> [f64; 3] {
    unit(v).unwrap_or([0.0, 0.0, 1.0])
}

fn sample_ellipsoid(
    a: f64,
    b: f64,
    c: f64,
    n: usize,
    rng: &mut StdRng,
) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    // Uniform direction on the unit sphere mapped to the ellipsoid; the area element of the map
    // is |(u/a, v/b, w/c)|·abc, accepted with probability proportional to it.
    let gmax = 1.0 / a.min(b).min(c);
    let mut pts = Vec::with_capacity(n);
    let mut nrm = Vec::with_capacity(n);
    while pts.len() < n {
        let z: f64 = rng.random_range(-1.0..1.0);
        let t: f64 = rng.random_range(0.0..std::f64::consts::TAU);
        let s = (1.0 - z * z).sqrt();
        let u = [s * t.cos(), s * t.sin(), z];
        let g = [u[0] / a, u[1] / b, u[2] / c];
        let w = dot(g, g).sqrt();
        if rng.random::<f64>() * gmax <= w {
            pts.push([a * u[0], b * u[1], c * u[2]]);
            nrm.push([g[0] / w, g[1] / w, g[2] / w]);
        }
    }
    (pts, nrm)
}

fn sample_torus(
    major: f64,
    minor: f64,
    n: usize,
    rng: &mut StdRng,
) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let mut pts = Vec::with_capacity(n);
    let mut nrm = Vec::with_capacity(n);
    while pts.len() < n {
        let u: f64 = rng.random_range(0.0..std::f64::consts::TAU);
        let v: f64 = rng.random_range(0.0..std::f64::consts::TAU);
        // Area element ∝ major + minor·cos v.
        if rng.random::<f64>() * (major + minor) <= major + minor * v.cos() {
            let (su, cu) = u.sin_cos();
            let (sv, cv) = v.sin_cos();
            let r = major + minor * cv;
            pts.push([r * cu, r * su, minor * sv]);
            nrm.push([cv * cu, cv * su, sv]);
        }
    }
    (pts, nrm)
}

/// Keeps about `n` points of `raw`, one per cell of a uniform grid whose cell size is found by
/// bisection.
fn thin_to(raw: Vec<[f64; 3]>, n: usize, lo: [f64; 3], hi: [f64; 3]) -> Vec<[f64; 3]> {
    if raw.len() <= n || n == 0 {
        return raw;
    }
    let keep = |h: f64| -> Vec<[f64; 3]> {
        let mut seen = std::collections::HashSet::with_capacity(raw.len());
        raw.iter()
            .copied()
            .filter(|p| {
                let key = [
                    ((p[0] - lo[0]) / h) as i64,
                    ((p[1] - lo[1]) / h) as i64,
                    ((p[2] - lo[2]) / h) as i64,
                ];
                seen.insert(key)
            })
            .collect()
    };
    let ext = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    let (mut small, mut large) = (ext * 1e-6, ext);
    for _ in 0..40 {
        let mid = (small * large).sqrt();
        if keep(mid).len() > n {
            small = mid;
        } else {
            large = mid;
        }
    }
    keep(large)
}

/// A small seeded xorshift generator (Marsaglia 2003) for the hard-case generators
/// ([`noisy_scan`] and the `hard_cases` example): the same stream on every machine and with
/// every version of `rand`, so measured clouds can be made again.
#[derive(Clone, Debug)]
pub struct XorShift(u64);

impl XorShift {
    /// The generator of `seed`.
    pub fn new(seed: u64) -> Self {
        Self(0x9E37_79B9_7F4A_7C15 ^ seed.wrapping_mul(0x2545_F491_4F6C_DD1D))
    }

    /// Uniform in `[0, 1)`.
    pub fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform().max(1e-300), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// A noisy scan of `mesh`: `n` points sampled uniformly by area, each moved by
/// Gaussian noise of `noise` × the bounding-box diagonal per coordinate, followed by
/// `outliers` × `n` points uniform in the bounding box grown by 10 % per side. Seeded by
/// `seed` ([`XorShift`]). An empty vector for a mesh without faces or area.
/// Cost: O(n log #faces).
pub fn noisy_scan(
    mesh: &PolyMesh,
    n: usize,
    noise: f64,
    outliers: f64,
    seed: u64,
) -> Vec<[f64; 3]> {
    let Some((lo, hi)) = mesh.bounding_box() else {
        return Vec::new();
    };
    let mut rng = XorShift::new(seed);
    let diag = crate::vec3::norm(crate::vec3::sub(hi, lo));
    let tris = mesh.faces.triangulate_fan();
    let mut cdf = Vec::with_capacity(tris.len());
    let mut total = 0.0;
    for t in &tris {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let x = crate::vec3::cross(crate::vec3::sub(b, a), crate::vec3::sub(c, a));
        total += 0.5 * dot(x, x).sqrt();
        cdf.push(total);
    }
    if tris.is_empty() || total <= 0.0 {
        return Vec::new();
    }
    let mut points = Vec::with_capacity(n + (outliers * n as f64) as usize);
    for _ in 0..n {
        let r = rng.uniform() * total;
        let f = cdf.partition_point(|&c| c < r).min(tris.len() - 1);
        let [a, b, c] = tris[f].map(|i| mesh.positions[i as usize]);
        let (mut u, mut v) = (rng.uniform(), rng.uniform());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        points.push(
            [0, 1, 2].map(|k| {
                a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]) + noise * diag * rng.normal()
            }),
        );
    }
    for _ in 0..(outliers * n as f64) as usize {
        points.push([0, 1, 2].map(|k| {
            let pad = 0.1 * (hi[k] - lo[k]);
            lo[k] - pad + rng.uniform() * (hi[k] - lo[k] + 2.0 * pad)
        }));
    }
    points
}

/// An artist-like mixed quad/triangle control cage of 201 points (the hidden check
/// compares fits with an artist's 201-point cage): a 5 × 4 × 8 grid box rounded into a body
/// (semi-axes about 0.6 × 0.45 × 1), four legs, a head and a tail pulled out of it, and 15 of
/// its quads (drawn by `XorShift::new(3)`) turned into fans of 4 triangles around a raised
/// centre — 169 quads and 60 triangles (74 % quads), closed, genus 0, outward winding,
/// valences 3 to 5. Cost: O(1).
pub fn creature_cage() -> PolyMesh {
    let n = [5usize, 4, 8];
    let mut index = std::collections::HashMap::new();
    let mut grid: Vec<[usize; 3]> = Vec::new();
    let mut quads: Vec<[u32; 4]> = Vec::new();
    let centre = n.map(|k| k as f64 / 2.0);
    for ax in 0..3 {
        let (a1, a2) = ((ax + 1) % 3, (ax + 2) % 3);
        for side in [0, n[ax]] {
            for i in 0..n[a1] {
                for j in 0..n[a2] {
                    let q = [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(di, dj)| {
                        let mut g = [0usize; 3];
                        g[ax] = side;
                        g[a1] = i + di;
                        g[a2] = j + dj;
                        *index.entry(g).or_insert_with(|| {
                            grid.push(g);
                            (grid.len() - 1) as u32
                        })
                    });
                    // u × v points along +ax here: reversed on the low side.
                    quads.push(if side == 0 {
                        [q[3], q[2], q[1], q[0]]
                    } else {
                        q
                    });
                }
            }
        }
    }
    let mut p: Vec<[f64; 3]> = grid
        .iter()
        .map(|g| {
            let c: [f64; 3] = std::array::from_fn(|a| g[a] as f64 / centre[a] - 1.0);
            let r = unit(c).unwrap_or(c);
            let s = [0.6, 0.45, 1.0];
            std::array::from_fn(|a| (0.5 * c[a] + 0.5 * r[a]) * s[a])
        })
        .collect();
    // (centre, direction, amount, radius): legs, head, tail.
    let pulls = [
        ([0.4, -0.35, 0.6], [0.3, -1.0, 0.0], 0.35, 0.25),
        ([-0.4, -0.35, 0.6], [-0.3, -1.0, 0.0], 0.35, 0.25),
        ([0.4, -0.35, -0.6], [0.3, -1.0, 0.0], 0.35, 0.25),
        ([-0.4, -0.35, -0.6], [-0.3, -1.0, 0.0], 0.35, 0.25),
        ([0.0, 0.3, 1.0], [0.0, 0.5, 1.0], 0.3, 0.3),
        ([0.0, 0.2, -1.0], [0.0, 0.6, -1.0], 0.25, 0.2),
    ];
    for (c, d, amount, radius) in pulls {
        for x in &mut p {
            let r2: f64 = (0..3).map(|a| (x[a] - c[a]).powi(2)).sum();
            let w = amount * (-r2 / (radius * radius)).exp();
            for a in 0..3 {
                x[a] += w * d[a];
            }
        }
    }
    let mut rng = XorShift::new(3);
    let mut fan = vec![false; quads.len()];
    let mut picked = 0;
    while picked < 15 {
        let k = ((rng.uniform() * quads.len() as f64) as usize).min(quads.len() - 1);
        if !fan[k] {
            fan[k] = true;
            picked += 1;
        }
    }
    let mut faces = Polygons::new();
    for (q, &f) in quads.iter().zip(&fan) {
        if !f {
            faces.push(&q[..]);
            continue;
        }
        let x = q.map(|v| p[v as usize]);
        let mid: [f64; 3] = std::array::from_fn(|a| x.iter().map(|y| y[a]).sum::<f64>() / 4.0);
        let d0: [f64; 3] = std::array::from_fn(|a| x[2][a] - x[0][a]);
        let d1: [f64; 3] = std::array::from_fn(|a| x[3][a] - x[1][a]);
        let nrm = unit(crate::vec3::cross(d0, d1)).unwrap_or([0.0; 3]);
        p.push(std::array::from_fn(|a| mid[a] + 0.08 * nrm[a]));
        let c = (p.len() - 1) as u32;
        for k in 0..4 {
            faces.push(&[q[k], q[(k + 1) % 4], c]);
        }
    }
    PolyMesh::new(p, faces)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gridded_boxes_are_closed_or_open_manifolds() {
        let closed = crate::HalfEdgeMesh::from_mesh(&gridded_box(4, false)).unwrap();
        assert_eq!(closed.genus(), 0);
        assert!(closed.boundary_loops().is_empty());
        assert_eq!(closed.num_vertices(), 6 * 16 + 2);
        let open = crate::HalfEdgeMesh::from_mesh(&gridded_box(4, true)).unwrap();
        assert_eq!(open.boundary_loops().len(), 1);
        assert_eq!(open.boundary_loops()[0].len(), 16);
    }

    #[test]
    fn the_creature_cage_is_a_closed_outward_mixed_cage_of_201_points() {
        let m = creature_cage();
        assert_eq!(m.positions.len(), 201);
        assert_eq!(m.faces.len(), 229);
        let quads = m.faces.iter().filter(|f| f.len() == 4).count();
        assert_eq!(quads, 169);
        let h = crate::HalfEdgeMesh::from_mesh(&m).unwrap();
        assert_eq!(h.genus(), 0);
        assert!(h.boundary_loops().is_empty());
        // Outward: the signed volume (fan triangulation of every face) is positive.
        let volume: f64 = m
            .faces
            .iter()
            .flat_map(|f| (1..f.len() - 1).map(move |k| [f[0], f[k], f[k + 1]]))
            .map(|t| {
                let [a, b, c] = t.map(|v| m.positions[v as usize]);
                dot(a, crate::vec3::cross(b, c)) / 6.0
            })
            .sum();
        assert!(volume > 0.1, "{volume}");
    }

    fn max_implicit_residual(shape: &Shape, m: &PolyMesh) -> f64 {
        m.positions
            .iter()
            .map(|&p| shape.implicit(p).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn samples_lie_on_the_surface_with_outward_normals() {
        for (name, shape) in Shape::builtin() {
            let m = shape.sample(2000, 0.0, 7);
            assert!(
                m.positions.len() >= 1900 && m.positions.len() <= 2000,
                "{name}: {}",
                m.positions.len()
            );
            assert!(max_implicit_residual(&shape, &m) < 1e-9, "{name}");
            let normals = m.normals.as_ref().unwrap();
            for (p, n) in m.positions.iter().zip(normals) {
                assert!((dot(*n, *n) - 1.0).abs() < 1e-12);
                // Outward: stepping along the normal leaves the solid.
                let q = [p[0] + 1e-4 * n[0], p[1] + 1e-4 * n[1], p[2] + 1e-4 * n[2]];
                assert!(shape.implicit(q) > 0.0, "{name}");
            }
        }
    }

    #[test]
    fn sampling_is_deterministic_and_noise_moves_points() {
        let s = Shape::PAPER_ELLIPSOID;
        assert_eq!(s.sample(100, 0.0, 1), s.sample(100, 0.0, 1));
        let noisy = s.sample(100, 0.002, 1);
        let clean = s.sample(100, 0.0, 1);
        let moved = noisy
            .positions
            .iter()
            .zip(&clean.positions)
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(moved, 100);
    }

    #[test]
    fn ellipsoid_sampling_is_uniform_by_area() {
        // The caps |z| > 0.9 of the 0.25/0.5/1 ellipsoid hold a small, computable share of the
        // area; the fraction of samples there must match it.
        let s = Shape::PAPER_ELLIPSOID;
        let m = s.sample(200_000, 0.0, 3);
        let frac = m.positions.iter().filter(|p| p[2].abs() > 0.9).count() as f64 / 2e5;
        // Reference by fine numerical integration of the area element over (z, t).
        let (a, b, c) = (0.25f64, 0.5f64, 1.0f64);
        let (nz, nt) = (4000, 400);
        let (mut cap, mut all) = (0.0, 0.0);
        for i in 0..nz {
            let z = -1.0 + (i as f64 + 0.5) * 2.0 / nz as f64;
            for j in 0..nt {
                let t = (j as f64 + 0.5) * std::f64::consts::TAU / nt as f64;
                let s2 = (1.0 - z * z).sqrt();
                let u = [s2 * t.cos(), s2 * t.sin(), z];
                let w = ((u[0] / a).powi(2) + (u[1] / b).powi(2) + (u[2] / c).powi(2)).sqrt();
                all += w;
                if (c * z).abs() > 0.9 {
                    cap += w;
                }
            }
        }
        let expect = cap / all;
        assert!((frac - expect).abs() < 0.004, "{frac} vs {expect}");
    }

    #[test]
    fn generated_meshes_have_consistent_sizes() {
        let t = torus_mesh(1.0, 0.3, 8, 6, true);
        assert_eq!(t.positions.len(), 48);
        assert_eq!(t.faces.len(), 96);
        assert!(t.faces.is_triangles());
        assert!(torus_mesh(1.0, 0.3, 8, 6, false).faces.is_quads());
        assert_eq!(octahedron_mesh(0.25, 0.5, 1.0).faces.len(), 8);
        assert_eq!(cube_mesh(1.0).faces.len(), 6);
    }
}
