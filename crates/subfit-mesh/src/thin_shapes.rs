//! Generated hard cases for coverage: closed shapes with thin parts, a thin handle and high
//! genus, each a fine triangle mesh that *is* the known surface (a fit is judged against it).
//!
//! The corpus shows where the defaults leave data uncovered (DESIGN.md decision 11: the
//! tolerance is two-sided): thin limbs and tentacles that the initial cage never reaches,
//! handles, lattices of many holes. These generators make such parts with a known thickness,
//! so a benchmark or a test can say how far off a fit is and at which thickness it breaks:
//!
//! * [`capsule`]: a thin cylinder with round caps (genus 0), radius a given fraction of its
//!   length;
//! * [`coin`]: a thin round plate with a round rim (genus 0), thickness a given fraction of
//!   its diameter;
//! * [`handle_torus`]: a body with a thin handle — a torus whose tube radius goes from thick
//!   on one side to thin on the other (genus 1);
//! * [`lattice`]: a plate with a grid of square holes, smoothed (genus = the number of holes;
//!   8 with the defaults of the benchmark);
//! * [`two_sided_lens`]: a closed lens whose middle is a sheet of no thickness written as both
//!   its sides (a repair's hard case).
//!
//! Surfaces of revolution are meshed on rings at uniform arc length along the meridian
//! profile (near-square triangles away from the poles); the lattice is the boundary of a
//! union of voxels, split into `k × k` quads per voxel face, triangulated and smoothed by
//! Taubin's λ|μ filter (Taubin 1995, "A signal processing approach to fair surface design",
//! §4), which rounds the voxel edges without shrinking the plate. All winding is outward.

use crate::vec3::{add, scale, sub};
use crate::{PolyMesh, Polygons};
use std::collections::HashMap;
use std::f64::consts::{PI, TAU};

/// A surface of revolution about the z axis of the meridian `profile` (`(ρ, z)` points from
/// the south pole, `ρ = 0`, to the north pole, `ρ = 0`; the inner points with `ρ > 0`), with
/// `nu ≥ 3` segments around the axis: `nu · (#profile − 2)` ring vertices and two poles,
/// triangles, outward winding (for a profile that runs from −z to +z on the `ρ ≥ 0` side).
/// Cost O(nu · #profile).
fn revolve(profile: &[(f64, f64)], nu: usize) -> PolyMesh {
    let nu = nu.max(3);
    let rings = profile.len().saturating_sub(2);
    let mut pos = Vec::with_capacity(nu * rings + 2);
    pos.push([0.0, 0.0, profile[0].1]);
    for &(rho, z) in &profile[1..=rings] {
        for i in 0..nu {
            let t = TAU * i as f64 / nu as f64;
            pos.push([rho * t.cos(), rho * t.sin(), z]);
        }
    }
    let north = pos.len() as u32;
    pos.push([0.0, 0.0, profile[profile.len() - 1].1]);
    let id = |j: usize, i: usize| (1 + j * nu + i % nu) as u32;
    let mut faces = Polygons::with_capacity(2 * nu * rings, 6 * nu * rings);
    for i in 0..nu {
        faces.push(&[0, id(0, i + 1), id(0, i)]);
        faces.push(&[id(rings - 1, i), id(rings - 1, i + 1), north]);
        for j in 0..rings.saturating_sub(1) {
            let (a, b, c, d) = (id(j, i), id(j, i + 1), id(j + 1, i + 1), id(j + 1, i));
            faces.push(&[a, b, c]);
            faces.push(&[a, c, d]);
        }
    }
    PolyMesh::new(pos, faces)
}

/// One piece of a meridian profile: its length and its `(ρ, z)` point at arc length `s`.
type Piece<'a> = (f64, &'a dyn Fn(f64) -> (f64, f64));

/// `n + 1` points at uniform arc length along a profile made of pieces, each a function of
/// its own arc length `s ∈ [0, len]` (the pieces' lengths given).
fn arc_profile(pieces: &[Piece<'_>], n: usize) -> Vec<(f64, f64)> {
    let total: f64 = pieces.iter().map(|p| p.0).sum();
    (0..=n)
        .map(|k| {
            let mut s = total * k as f64 / n as f64;
            for (i, (len, f)) in pieces.iter().enumerate() {
                if s <= *len || i + 1 == pieces.len() {
                    let (rho, z) = f(s.min(*len));
                    return (rho.max(0.0), z);
                }
                s -= len;
            }
            unreachable!("a profile has at least one piece")
        })
        .collect()
}

/// A capsule along the z axis: a cylinder of radius `radius` and length `length` (of the
/// straight part) with hemispherical caps, centred at the origin; `nu ≥ 3` segments around,
/// rings about as far apart as the segments. Genus 0. Its thickness is `2 · radius` everywhere
/// but at the caps' tips. Cost O(nu² · (length / radius)).
pub fn capsule(radius: f64, length: f64, nu: usize) -> PolyMesh {
    let nu = nu.max(3);
    let (r, h) = (radius, 0.5 * length);
    let cap = 0.5 * PI * r;
    let south = move |s: f64| {
        let a = s / r;
        (r * a.sin(), -h - r * a.cos())
    };
    let side = move |s: f64| (r, -h + s);
    let north = move |s: f64| {
        let a = s / r;
        (r * a.cos(), h + r * a.sin())
    };
    let step = TAU * r / nu as f64;
    let n = ((2.0 * cap + length) / step).ceil().max(4.0) as usize;
    let profile = arc_profile(&[(cap, &south), (length, &side), (cap, &north)], n);
    revolve(&profile, nu)
}

/// A round plate ("coin") in the xy plane: two flat faces of radius `radius` at
/// `z = ±thickness / 2` joined by a half-torus rim of radius `thickness / 2` (so the plate's
/// full radius is `radius + thickness / 2`); `nu ≥ 3` segments around, meridian points about
/// as far apart as `rim_points` per half-circle of rim. Genus 0; thickness `thickness` over
/// the flat faces. Cost O(nu · (radius / thickness) · rim_points).
pub fn coin(radius: f64, thickness: f64, nu: usize, rim_points: usize) -> PolyMesh {
    let t = 0.5 * thickness;
    let bottom = move |s: f64| (s, -t);
    let rim = move |s: f64| {
        let a = s / t;
        (radius + t * a.sin(), -t * a.cos())
    };
    let top = move |s: f64| (radius - s, t);
    let rim_len = PI * t;
    let step = rim_len / rim_points.max(2) as f64;
    let n = ((2.0 * radius + rim_len) / step).ceil().max(6.0) as usize;
    let profile = arc_profile(&[(radius, &bottom), (rim_len, &rim), (radius, &top)], n);
    revolve(&profile, nu)
}

/// A body with a thin handle: a torus about the z axis of major radius `major` whose tube
/// radius varies around the axis, `thick` at angle 0 (the body) and `thin` at angle π (the
/// handle): `r(u) = thin + (thick − thin) · ((1 + cos u) / 2)²`. Needs `0 < thin ≤ thick <
/// major` (the tube never reaches the axis, so the surface does not cross itself). `nu`
/// segments around the axis, `nv` around the tube. Genus 1. Cost O(nu · nv).
pub fn handle_torus(major: f64, thick: f64, thin: f64, nu: usize, nv: usize) -> PolyMesh {
    let mut m = crate::shapes::torus_mesh(major, 1.0, nu, nv, true);
    let (nu, nv) = (nu.max(3), nv.max(3));
    for i in 0..nu {
        let u = TAU * i as f64 / nu as f64;
        let w = 0.5 * (1.0 + u.cos());
        let r = thin + (thick - thin) * w * w;
        for j in 0..nv {
            let v = TAU * j as f64 / nv as f64;
            let rho = major + r * v.cos();
            m.positions[i * nv + j] = [rho * u.cos(), rho * u.sin(), r * v.sin()];
        }
    }
    m
}

/// Options of [`lattice`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LatticeOptions {
    /// Holes per side of the grid (default 3); the plate has `2·holes + 1` voxels per side.
    pub holes: usize,
    /// Leave the middle hole solid (default true): with 3 holes per side, genus 8.
    pub skip_middle: bool,
    /// The plate's thickness in voxel sizes (default 1; the bars are one voxel wide).
    pub thickness: f64,
    /// Quads per voxel side (default 4).
    pub k: usize,
    /// Taubin λ|μ smoothing steps (default 30).
    pub smoothing: usize,
}

impl Default for LatticeOptions {
    fn default() -> Self {
        Self {
            holes: 3,
            skip_middle: true,
            thickness: 1.0,
            k: 4,
            smoothing: 30,
        }
    }
}

/// A plate with a grid of square holes (see [`LatticeOptions`]), voxel size 1, smoothed:
/// genus = the number of holes, closed, triangles, outward winding. The voxel set has no two
/// solid voxels that meet at an edge or corner only, so its boundary is a manifold surface.
/// Cost O(holes² · k² · smoothing).
pub fn lattice(opts: &LatticeOptions) -> PolyMesh {
    let n = 2 * opts.holes + 1;
    let mid = opts.holes / 2 * 2 + 1;
    let solid = |x: i64, y: i64| {
        if x < 0 || y < 0 || x >= n as i64 || y >= n as i64 {
            return false;
        }
        let hole = x % 2 == 1 && y % 2 == 1;
        let kept = opts.skip_middle && opts.holes % 2 == 1 && x == mid as i64 && y == mid as i64;
        !hole || kept
    };
    let k = opts.k.max(1) as i64;
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut pos: Vec<[f64; 3]> = Vec::new();
    let mut tris: Vec<[u32; 3]> = Vec::new();
    let zs = opts.thickness;
    let mut vertex = |g: [i64; 3]| {
        *index.entry(g).or_insert_with(|| {
            pos.push([
                g[0] as f64 / k as f64,
                g[1] as f64 / k as f64,
                g[2] as f64 / k as f64 * zs,
            ]);
            (pos.len() - 1) as u32
        })
    };
    // Every face of a solid voxel whose neighbour across it is empty (z: always, one layer).
    for x in 0..n as i64 {
        for y in 0..n as i64 {
            if !solid(x, y) {
                continue;
            }
            let base = [x * k, y * k, 0];
            let sides: [([i64; 3], bool); 6] = [
                ([1, 0, 0], !solid(x + 1, y)),
                ([-1, 0, 0], !solid(x - 1, y)),
                ([0, 1, 0], !solid(x, y + 1)),
                ([0, -1, 0], !solid(x, y - 1)),
                ([0, 0, 1], true),
                ([0, 0, -1], true),
            ];
            for (dir, open) in sides {
                if open {
                    voxel_face(base, dir, k, &mut vertex, &mut tris);
                }
            }
        }
    }
    let faces = Polygons::from_triangles(&tris);
    let mut mesh = PolyMesh::new(pos, faces);
    taubin(&mut mesh, opts.smoothing);
    mesh
}

/// The `k × k` grid of one voxel face (the face of the voxel at grid corner `base`, size `k`,
/// on the side `dir`), two outward triangles per quad.
fn voxel_face(
    base: [i64; 3],
    dir: [i64; 3],
    k: i64,
    vertex: &mut impl FnMut([i64; 3]) -> u32,
    tris: &mut Vec<[u32; 3]>,
) {
    let axis = dir.iter().position(|&d| d != 0).unwrap_or(0);
    let positive = dir[axis] > 0;
    // The two in-face axes, ordered so (a, b, outward) is right-handed.
    let (mut a, mut b) = ((axis + 1) % 3, (axis + 2) % 3);
    if !positive {
        std::mem::swap(&mut a, &mut b);
    }
    let at = |i: i64, j: i64| {
        let mut g = base;
        if positive {
            g[axis] += k;
        }
        g[a] += i;
        g[b] += j;
        g
    };
    for i in 0..k {
        for j in 0..k {
            let p = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)].map(&mut *vertex);
            tris.push([p[0], p[1], p[2]]);
            tris.push([p[0], p[2], p[3]]);
        }
    }
}

/// Taubin's λ|μ smoothing (λ = 0.5, μ = −0.53, umbrella weights), `steps` pairs of passes.
fn taubin(mesh: &mut PolyMesh, steps: usize) {
    let nv = mesh.num_vertices();
    let mut nbrs: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for f in mesh.faces.iter() {
        for (i, &v) in f.iter().enumerate() {
            let w = f[(i + 1) % f.len()];
            nbrs[v as usize].push(w);
            nbrs[w as usize].push(v);
        }
    }
    for l in &mut nbrs {
        l.sort_unstable();
        l.dedup();
    }
    for _ in 0..steps {
        for factor in [0.5, -0.53] {
            let old = mesh.positions.clone();
            for (v, l) in nbrs.iter().enumerate() {
                if l.is_empty() {
                    continue;
                }
                let mut mean = [0.0; 3];
                for &w in l {
                    mean = add(mean, old[w as usize]);
                }
                let mean = scale(mean, 1.0 / l.len() as f64);
                mesh.positions[v] = add(old[v], scale(sub(mean, old[v]), factor));
            }
        }
    }
}

/// A lens over `[−1, 1]²` (a `12 × 12` grid): a top sheet `z = h`, a bottom sheet `z = −h`,
/// joined at the rim and in the middle square `|x|, |y| ≤ 0.4`, where `h = 0`: there the top
/// and the bottom faces are the same triangles turned — a sheet of no thickness, as a thin part
/// of a scan collapsed by its reconstruction. `top_first(i, j)` says which copy of the middle
/// cell `(i, j)` is written first. Genus 0, closed; a repair's hard case, not a fit's truth.
pub fn two_sided_lens(top_first: impl Fn(usize, usize) -> bool) -> PolyMesh {
    let n = 12usize;
    let coord = |i: usize| -1.0 + 2.0 * i as f64 / n as f64;
    let height = |i: usize, j: usize| {
        let r = coord(i).abs().max(coord(j).abs());
        if r <= 0.4 + 1e-9 || r >= 1.0 - 1e-9 {
            0.0
        } else {
            0.3 * (PI * (r - 0.4) / 0.6).sin()
        }
    };
    let mut p = Vec::new();
    let mut top = vec![vec![0u32; n + 1]; n + 1];
    let mut bottom = top.clone();
    for i in 0..=n {
        for j in 0..=n {
            let h = height(i, j);
            top[i][j] = p.len() as u32;
            p.push([coord(i), coord(j), h]);
            bottom[i][j] = if h == 0.0 {
                top[i][j]
            } else {
                p.push([coord(i), coord(j), -h]);
                (p.len() - 1) as u32
            };
        }
    }
    let mut f = Polygons::new();
    for i in 0..n {
        for j in 0..n {
            let cell = |g: &Vec<Vec<u32>>| [g[i][j], g[i + 1][j], g[i + 1][j + 1], g[i][j + 1]];
            let (t, b) = (cell(&top), cell(&bottom));
            let up = [[t[0], t[1], t[2]], [t[0], t[2], t[3]]];
            let down = [[b[0], b[2], b[1]], [b[0], b[3], b[2]]];
            let order = if top_first(i, j) {
                [up, down]
            } else {
                [down, up]
            };
            for tri in order.iter().flatten() {
                f.push(tri);
            }
        }
    }
    PolyMesh::new(p, f)
}

#[cfg(test)]
#[path = "thin_shapes_tests.rs"]
mod tests;
