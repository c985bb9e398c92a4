//! A dancing articulated figure with known material correspondence: a body with a torso, a
//! head (with a nose), two arms with hands and two legs with feet, linear-blend skinned along a
//! skeleton of 16 bones whose joint angles follow a dance (swinging arms and legs, bending
//! elbows and knees, a twisting and bending spine, a nodding head, a body that turns, sways
//! and bounces). Unlike [`super::DeformingSequence`], whose bulges travel over the material,
//! here the material moves with the shape's features — limbs, joints, head — as on a real body,
//! so a tracker can pin it down from the geometry alone (the brief's "generated ones where
//! material moves with the shape's features").
//!
//! **Rest shape** (the material coordinates; z up, y forward, about 1.9 tall, diagonal about
//! 2.5): the smooth union (polynomial smooth minimum, blend width [`BLEND`]) of round cones
//! along the bones — each the set of points within a radius, interpolated along its segment,
//! of the segment; the torso's flattened front to back — meshed by marching tetrahedra
//! ([`super::marching`]) at any resolution, vertices on the exact zero set.
//!
//! **Skinning** (Magnenat-Thalmann, Laperrière & Thalmann, "Joint-dependent local
//! deformations for hand animation", Graphics Interface 1988; linear-blend skinning):
//! `x' = Σ_b w_b(m) G_b(m)` with `G_b` the rigid transform of bone `b` (forward kinematics:
//! each bone turns about its head joint, then follows its parent) and weights
//! `w_b ∝ exp(−((d_b − d_min)/σ)²)` of the distance `d_b` from the material point to bone
//! `b`'s own round cone (0 on its surface), `σ` = [`SKIN_WIDTH`]: a point on one limb follows
//! that limb; near a joint it blends the two bones that meet there.
//!
//! **Time.** Frame `i` shows capture time `stride · i` (in capture frames); the dance repeats
//! every [`DanceParams::period`] capture frames, so `stride` 5 is the same dance seen at a fifth
//! of the frame rate: the hands then move by up to about 15 % of the diagonal between frames.
//!
//! Costs: the skinning of one point is 17 cone distances and 16 affine maps; a mesh frame of
//! `V` vertices costs one marching-tetrahedra pass or two over a grid of about `30 V` cells; a
//! point frame of `P` points samples a cached fine rest mesh (built once, about 60k
//! triangles) and projects each point onto the rest surface.

use std::f64::consts::{PI, TAU};
use std::sync::OnceLock;

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use super::marching::marching_tetrahedra;
use super::motion::{splitmix, Frame, InvalidParams, MaterialMotion};
use crate::polygons::{PolyMesh, Polygons};
use crate::vec3::{cross, dot, norm, sub};

/// Width of the smooth union of the body's parts (length units of the rest shape).
pub const BLEND: f64 = 0.03;
/// Width `σ` of the skinning weights' fall-off (length units; see the module docs).
pub const SKIN_WIDTH: f64 = 0.03;

/// One bone: its head joint (the centre it turns about), its tail, the radii of its round cone
/// at head and tail, the cone's scale across the body (x, y: the torso is flattened), its
/// parent.
#[derive(Clone, Copy, Debug)]
struct Bone {
    head: [f64; 3],
    tail: [f64; 3],
    radius: (f64, f64),
    squash: [f64; 2],
    parent: Option<usize>,
}

const fn bone(head: [f64; 3], tail: [f64; 3], radius: (f64, f64), parent: Option<usize>) -> Bone {
    Bone {
        head,
        tail,
        radius,
        squash: [1.0, 1.0],
        parent,
    }
}

/// Bone indices.
const PELVIS: usize = 0;
const CHEST: usize = 1;
const NECK: usize = 2;
const HEAD: usize = 3;
const ARM: [usize; 2] = [4, 7];
const LEG: [usize; 2] = [10, 13];
const BONES: usize = 16;

/// The skeleton at rest (the figure's left at +x, looking along +y).
fn skeleton() -> [Bone; BONES] {
    let torso = |head, tail, radius, parent| Bone {
        squash: [1.25, 0.8],
        ..bone(head, tail, radius, parent)
    };
    let mut b = [bone([0.0; 3], [0.0; 3], (0.0, 0.0), None); BONES];
    b[PELVIS] = torso([0.0, 0.0, 0.95], [0.0, 0.0, 1.2], (0.14, 0.13), None);
    b[CHEST] = torso(
        [0.0, 0.0, 1.2],
        [0.0, 0.0, 1.42],
        (0.13, 0.15),
        Some(PELVIS),
    );
    b[NECK] = bone(
        [0.0, 0.0, 1.45],
        [0.0, 0.005, 1.68],
        (0.05, 0.045),
        Some(CHEST),
    );
    b[HEAD] = bone(
        [0.0, 0.01, 1.70],
        [0.0, 0.01, 1.82],
        (0.095, 0.09),
        Some(NECK),
    );
    for (side, s) in [(0, 1.0), (1, -1.0)] {
        let a = ARM[side];
        b[a] = bone(
            [0.19 * s, 0.0, 1.45],
            [0.40 * s, 0.0, 1.22],
            (0.05, 0.04),
            Some(CHEST),
        );
        b[a + 1] = bone(
            [0.40 * s, 0.0, 1.22],
            [0.58 * s, 0.0, 1.02],
            (0.04, 0.032),
            Some(a),
        );
        b[a + 2] = bone(
            [0.58 * s, 0.0, 1.02],
            [0.66 * s, 0.01, 0.93],
            (0.032, 0.03),
            Some(a + 1),
        );
        let l = LEG[side];
        b[l] = bone(
            [0.09 * s, 0.0, 0.95],
            [0.12 * s, 0.0, 0.52],
            (0.08, 0.055),
            Some(PELVIS),
        );
        b[l + 1] = bone(
            [0.12 * s, 0.0, 0.52],
            [0.13 * s, 0.0, 0.10],
            (0.05, 0.04),
            Some(l),
        );
        b[l + 2] = bone(
            [0.13 * s, 0.0, 0.10],
            [0.13 * s, 0.15, 0.04],
            (0.04, 0.035),
            Some(l + 1),
        );
    }
    b
}

/// The nose: a small cone on the head (it breaks the head's symmetry).
const NOSE: Bone = bone(
    [0.0, 0.085, 1.74],
    [0.0, 0.115, 1.72],
    (0.022, 0.015),
    Some(HEAD),
);

/// Distance from `p` to the round cone of `b` (negative inside; exact for a cylinder, a close
/// approximation for the gentle tapers used here).
fn cone_distance(b: &Bone, p: [f64; 3]) -> f64 {
    let axis = sub(b.tail, b.head);
    let len2 = dot(axis, axis);
    let t = (dot(sub(p, b.head), axis) / len2).clamp(0.0, 1.0);
    let on: [f64; 3] = std::array::from_fn(|a| b.head[a] + t * axis[a]);
    let d = sub(p, on);
    let d = [d[0] / b.squash[0], d[1] / b.squash[1], d[2]];
    norm(d) - (b.radius.0 + t * (b.radius.1 - b.radius.0))
}

/// Polynomial smooth minimum of width `k` (Quílez): `min(a, b)` minus at most `k/4`.
fn smooth_min(a: f64, b: f64, k: f64) -> f64 {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - 0.25 * h * h * k
}

/// The rest body's implicit function: negative inside.
fn body(bones: &[Bone; BONES], p: [f64; 3]) -> f64 {
    bones
        .iter()
        .chain(std::iter::once(&NOSE))
        .map(|b| cone_distance(b, p))
        .fold(f64::INFINITY, |acc, d| {
            if acc.is_finite() {
                smooth_min(acc, d, BLEND)
            } else {
                d
            }
        })
}

/// A rigid motion `x ↦ R x + t`.
#[derive(Clone, Copy, Debug)]
struct Rigid {
    r: [[f64; 3]; 3],
    t: [f64; 3],
}

impl Rigid {
    const IDENTITY: Self = Self {
        r: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        t: [0.0; 3],
    };

    fn apply(&self, x: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|a| dot(self.r[a], x) + self.t[a])
    }

    /// `self ∘ other`.
    fn then_after(&self, other: &Self) -> Self {
        let r = std::array::from_fn(|a| {
            std::array::from_fn(|c| (0..3).map(|k| self.r[a][k] * other.r[k][c]).sum())
        });
        Self {
            r,
            t: self.apply(other.t),
        }
    }

    /// The turn `rz · ry · rx` (radians about the rest axes) about the point `c`.
    fn turn_about(c: [f64; 3], [rx, ry, rz]: [f64; 3]) -> Self {
        let (sx, cx) = rx.sin_cos();
        let (sy, cy) = ry.sin_cos();
        let (sz, cz) = rz.sin_cos();
        let x = [[1.0, 0.0, 0.0], [0.0, cx, -sx], [0.0, sx, cx]];
        let y = [[cy, 0.0, sy], [0.0, 1.0, 0.0], [-sy, 0.0, cy]];
        let z = [[cz, -sz, 0.0], [sz, cz, 0.0], [0.0, 0.0, 1.0]];
        let m = |a: [[f64; 3]; 3], b: [[f64; 3]; 3]| -> [[f64; 3]; 3] {
            std::array::from_fn(|i| {
                std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum())
            })
        };
        let r = m(z, m(y, x));
        let rc: [f64; 3] = std::array::from_fn(|a| dot(r[a], c));
        Self { r, t: sub(c, rc) }
    }
}

/// The motion of a [`DancingFigure`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DanceParams {
    /// Number of frames (≥ 1). Default 30.
    pub frames: usize,
    /// Capture frames between two frames (≥ 1): 1 is a smooth capture, 5 the same dance at a
    /// fifth of the frame rate. Default 1.
    pub stride: usize,
    /// Capture frames per bar of the dance (> 0): the arms and legs swing once a bar.
    /// Default 60 (2 s at 30 frames per second).
    pub period: f64,
    /// Scale of every joint angle and of the body's travel (≥ 0; 0 holds the rest pose).
    /// Default 1.
    pub amplitude: f64,
}

impl Default for DanceParams {
    fn default() -> Self {
        Self {
            frames: 30,
            stride: 1,
            period: 60.0,
            amplitude: 1.0,
        }
    }
}

/// Vertices and triangles.
type TriangleMesh = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// A dancing articulated figure (see the module docs).
#[derive(Debug)]
pub struct DancingFigure {
    params: DanceParams,
    bones: [Bone; BONES],
    /// A fine rest mesh, built on first use, that point frames sample.
    fine: OnceLock<TriangleMesh>,
}

/// The coarsest grid cell (length units): below the thinnest part's radius (the hands',
/// 0.03), so the grid resolves every limb; a mesh frame has at least about 13k vertices.
const MAX_CELL: f64 = 0.025;

/// Vertices of the cached rest mesh that point frames sample.
const FINE_VERTICES: f64 = 30_000.0;

impl DancingFigure {
    /// The figure dancing `params`, checked: `frames ≥ 1`, `stride ≥ 1`, `period` finite and
    /// positive, `amplitude` finite within `0..=1.5` (beyond, limbs pass through the body).
    pub fn new(params: DanceParams) -> Result<Self, InvalidParams> {
        let bad = |field, reason| Err(InvalidParams { field, reason });
        if params.frames == 0 {
            return bad("frames", "a sequence needs at least one frame");
        }
        if params.stride == 0 {
            return bad("stride", "must be at least 1 capture frame");
        }
        if !(params.period.is_finite() && params.period > 0.0) {
            return bad("period", "must be a finite number > 0");
        }
        if !(params.amplitude.is_finite() && (0.0..=1.5).contains(&params.amplitude)) {
            return bad("amplitude", "must be within 0..=1.5");
        }
        Ok(Self {
            params,
            bones: skeleton(),
            fine: OnceLock::new(),
        })
    }

    /// The motion parameters.
    pub fn params(&self) -> &DanceParams {
        &self.params
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.params.frames
    }

    /// Whether there are no frames (never: `new` asks for one at least).
    pub fn is_empty(&self) -> bool {
        self.params.frames == 0
    }

    /// The rest body's implicit function at `p` (negative inside, about the distance to the
    /// surface near it).
    pub fn rest_implicit(&self, p: [f64; 3]) -> f64 {
        body(&self.bones, p)
    }

    /// The bones' rigid transforms in frame `index` (forward kinematics of the dance).
    fn pose(&self, index: usize) -> [Rigid; BONES] {
        let a = self.params.amplitude;
        let t = (index * self.params.stride) as f64;
        let w = TAU / self.params.period;
        let s = |freq: f64, phase: f64| (w * freq * t + phase).sin();
        let mut local = [[0.0f64; 3]; BONES];
        local[PELVIS] = [
            0.05 * s(2.0, 0.0),
            0.08 * s(1.0, 0.3),
            0.6 * s(1.0 / 3.0, 0.0),
        ];
        local[CHEST] = [0.1 * s(2.0, 1.0), 0.12 * s(0.5, 0.0), 0.35 * s(1.0, 0.5)];
        local[NECK] = [0.0, 0.0, 0.2 * s(0.5, 1.0)];
        local[HEAD] = [0.2 * s(2.0, 0.3), 0.1 * s(0.7, 0.0), 0.3 * s(0.67, 2.0)];
        for (side, sign) in [(0usize, 1.0), (1, -1.0)] {
            let phase = PI * side as f64;
            let arm = ARM[side];
            // Swing forward (about x), raise towards the horizontal (about y, away from the body).
            let raise = 0.35 + 0.35 * s(1.0, 1.0 + phase);
            local[arm] = [0.6 * s(1.0, phase), -sign * raise, 0.0];
            local[arm + 1] = [0.6 + 0.5 * s(1.0, 2.0 + phase), 0.0, 0.0];
            local[arm + 2] = [0.3 * s(2.0, phase), 0.0, 0.2 * s(1.0, phase)];
            let leg = LEG[side];
            local[leg] = [0.4 * s(1.0, phase), sign * 0.1 * (1.0 + s(0.5, phase)), 0.0];
            local[leg + 1] = [-(0.5 + 0.45 * s(1.0, phase - 0.8)), 0.0, 0.0];
            local[leg + 2] = [0.2 * s(1.0, phase), 0.0, 0.0];
        }
        let travel = Rigid {
            r: Rigid::IDENTITY.r,
            t: [0.25 * s(0.25, 0.0), 0.15 * s(0.2, 1.0), 0.04 * s(2.0, 0.0)].map(|v| a * v),
        };
        let mut g = [Rigid::IDENTITY; BONES];
        for b in 0..BONES {
            let turn = Rigid::turn_about(self.bones[b].head, local[b].map(|v| a * v));
            g[b] = match self.bones[b].parent {
                Some(p) => g[p].then_after(&turn),
                None => travel.then_after(&turn),
            };
        }
        g
    }

    /// The skinning weights of a material point: `(bone, weight)`, weights summing to 1.
    fn weights(&self, m: [f64; 3]) -> Vec<(usize, f64)> {
        let mut d: Vec<f64> = self.bones.iter().map(|b| cone_distance(b, m)).collect();
        d[HEAD] = d[HEAD].min(cone_distance(&NOSE, m));
        let least = d.iter().copied().fold(f64::INFINITY, f64::min);
        let mut w: Vec<(usize, f64)> = d
            .iter()
            .enumerate()
            .map(|(b, &db)| (b, (-((db - least) / SKIN_WIDTH).powi(2)).exp()))
            .filter(|&(_, v)| v > 1e-6)
            .collect();
        let sum: f64 = w.iter().map(|e| e.1).sum();
        w.iter_mut().for_each(|e| e.1 /= sum);
        w
    }

    /// Where the material point `material` (a point of the rest shape) is in frame `index`;
    /// frame 0 is the dance's first pose, not the rest shape.
    pub fn deform(&self, index: usize, material: [f64; 3]) -> [f64; 3] {
        self.skin(&self.pose(index), material)
    }

    fn skin(&self, pose: &[Rigid; BONES], m: [f64; 3]) -> [f64; 3] {
        let mut out = [0.0; 3];
        for (b, w) in self.weights(m) {
            let x = pose[b].apply(m);
            (0..3).for_each(|a| out[a] += w * x[a]);
        }
        out
    }

    /// The rest surface meshed with about `approx_vertices` vertices (±15 %, two passes of
    /// marching tetrahedra at most; at least about 13k, [`MAX_CELL`]), the grid's offset drawn
    /// from `rng`.
    fn rest_mesh(&self, approx_vertices: f64, rng: &mut StdRng) -> TriangleMesh {
        let (lo, hi) = self.bounds();
        let f = |p: [f64; 3]| body(&self.bones, p);
        let offset: [f64; 3] = std::array::from_fn(|_| rng.random_range(0.0..1.0));
        // Marching tetrahedra give about 2.1 vertices per h² of the body's area (about 2.3).
        let mut h = (2.1 * 2.3 / approx_vertices.max(100.0))
            .sqrt()
            .min(MAX_CELL);
        let mut mesh = marching_tetrahedra(&f, lo, hi, h, offset);
        let got = mesh.0.len() as f64;
        if (got / approx_vertices - 1.0).abs() > 0.15 && h < MAX_CELL {
            h = (h * (got / approx_vertices).sqrt()).min(MAX_CELL);
            mesh = marching_tetrahedra(&f, lo, hi, h, offset);
        }
        mesh
    }

    /// A box around the rest body with a margin.
    fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for b in self.bones.iter().chain(std::iter::once(&NOSE)) {
            let r = b.radius.0.max(b.radius.1) * b.squash[0].max(b.squash[1]) + 2.0 * BLEND;
            for p in [b.head, b.tail] {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a] - r);
                    hi[a] = hi[a].max(p[a] + r);
                }
            }
        }
        (lo, hi)
    }

    /// Frame `index` as a mesh of its own resolution: the rest surface meshed afresh (about
    /// `approx_vertices` vertices, at least about 13k, the grid's offset from `seed` and
    /// `index`), posed. A closed
    /// genus-0 triangle mesh wound counter-clockwise seen from outside. Cost: see the module
    /// docs (about 0.3 s for 40k vertices).
    pub fn frame(&self, index: usize, approx_vertices: usize, seed: u64) -> Frame {
        let mut rng = StdRng::seed_from_u64(splitmix(seed ^ splitmix(index as u64)));
        let (material, triangles) = self.rest_mesh(approx_vertices as f64, &mut rng);
        let pose = self.pose(index);
        let positions = material.iter().map(|&m| self.skin(&pose, m)).collect();
        Frame {
            mesh: PolyMesh::new(positions, Polygons::from_triangles(&triangles)),
            material,
        }
    }

    /// Frame `index` as `count` fresh random points of the posed surface, uniform by the posed
    /// area, without normals (like a capture), from `seed` and `index`: a cached fine rest
    /// mesh's triangles drawn by their posed area, a uniform point in the triangle, moved
    /// onto the exact rest surface (Newton steps along the implicit function's gradient), then
    /// posed. The frame's mesh has no faces.
    pub fn points(&self, index: usize, count: usize, seed: u64) -> Frame {
        let mut rng = StdRng::seed_from_u64(splitmix(seed ^ splitmix(index as u64) ^ 0x5EED));
        let (rest, triangles) = self.fine.get_or_init(|| {
            let mut r = StdRng::seed_from_u64(0x0F1E);
            self.rest_mesh(FINE_VERTICES, &mut r)
        });
        let pose = self.pose(index);
        let posed: Vec<[f64; 3]> = rest.iter().map(|&m| self.skin(&pose, m)).collect();
        let mut cumulative = Vec::with_capacity(triangles.len());
        let mut total = 0.0;
        for t in triangles {
            let [a, b, c] = t.map(|i| posed[i as usize]);
            total += 0.5 * norm(cross(sub(b, a), sub(c, a)));
            cumulative.push(total);
        }
        let f = |p: [f64; 3]| body(&self.bones, p);
        let material: Vec<[f64; 3]> = (0..count)
            .map(|_| {
                let u = rng.random_range(0.0..total);
                let k = cumulative
                    .partition_point(|&c| c < u)
                    .min(triangles.len() - 1);
                let (mut r1, mut r2): (f64, f64) = (rng.random(), rng.random());
                if r1 + r2 > 1.0 {
                    (r1, r2) = (1.0 - r1, 1.0 - r2);
                }
                let [a, b, c] = triangles[k].map(|i| rest[i as usize]);
                let p = std::array::from_fn(|x| a[x] + r1 * (b[x] - a[x]) + r2 * (c[x] - a[x]));
                super::marching::project_onto(&f, p, 0.02)
            })
            .collect();
        let positions = material.iter().map(|&m| self.skin(&pose, m)).collect();
        Frame {
            mesh: PolyMesh::point_cloud(positions, None),
            material,
        }
    }
}

impl MaterialMotion for DancingFigure {
    fn deform_all(&self, index: usize, material: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let pose = self.pose(index);
        material.iter().map(|&m| self.skin(&pose, m)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::deforming::MaterialLookup;
    use crate::diagnose::diagnose_mesh;

    #[test]
    fn mesh_frames_are_closed_genus_zero_and_on_the_posed_surface() {
        let fig = DancingFigure::new(DanceParams {
            stride: 5,
            ..DanceParams::default()
        })
        .unwrap();
        for (index, v) in [(0, 13_000), (7, 20_000), (16, 40_000)] {
            let f = fig.frame(index, v, 3);
            let r = diagnose_mesh(&f.mesh);
            assert!(
                r.is_closed && r.is_manifold && r.is_consistently_oriented,
                "{r:?}"
            );
            assert_eq!((r.num_components, r.genus), (1, Some(0)));
            let n = f.mesh.positions.len() as f64;
            assert!((n / v as f64 - 1.0).abs() < 0.2, "{n} vertices for {v}");
            for (&m, &p) in f.material.iter().zip(&f.mesh.positions).step_by(97) {
                assert!(
                    fig.rest_implicit(m).abs() < 1e-9,
                    "material off the rest surface"
                );
                assert_eq!(p, fig.deform(index, m));
            }
        }
    }

    #[test]
    fn limbs_move_rigidly_between_joints() {
        // A point in the middle of the left forearm moves with that bone: its distance to the
        // elbow joint is kept in every frame, up to the other bones' weights there (below
        // 2e-4: they are 3σ farther away).
        let fig = DancingFigure::new(DanceParams::default()).unwrap();
        let bones = skeleton();
        let fore = bones[ARM[0] + 1];
        let mid: [f64; 3] = std::array::from_fn(|a| 0.5 * (fore.head[a] + fore.tail[a]));
        let surface = [mid[0], mid[1] + 0.036, mid[2]];
        for t in [0, 9, 23] {
            let pose = fig.pose(t);
            let elbow = pose[ARM[0]].apply(fore.head);
            let p = fig.deform(t, surface);
            let rest = norm(sub(surface, fore.head));
            assert!((norm(sub(p, elbow)) - rest).abs() < 1e-4);
        }
    }

    #[test]
    fn point_frames_lie_on_the_posed_mesh() {
        let fig = DancingFigure::new(DanceParams::default()).unwrap();
        let pts = fig.points(4, 2000, 1);
        assert!(pts.mesh.faces.is_empty() && pts.mesh.normals.is_none());
        assert_eq!(pts.mesh.positions.len(), 2000);
        let fine = fig.frame(4, 40_000, 9);
        let lookup = MaterialLookup::new(&fine);
        let diag = {
            let (lo, hi) = crate::polygons::bounding_box(&fine.mesh.positions).unwrap();
            norm(sub(hi, lo))
        };
        // On the surface up to the chord error of a 40k-vertex mesh (well below 1e-3 of the
        // diagonal), and the material as given.
        let lookup_material = |p| lookup.locate(p);
        for (&p, &m) in pts.mesh.positions.iter().zip(&pts.material).step_by(13) {
            let (_, d) = lookup_material(p);
            assert!(d < 1e-3 * diag, "point off the surface by {d}");
            assert!(fig.rest_implicit(m).abs() < 1e-9);
        }
    }
}
