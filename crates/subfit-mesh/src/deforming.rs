//! Deforming test sequences with known correspondence: a closed body that bends, twists and
//! changes thickness over `N` frames, every frame a triangle mesh of its own random resolution,
//! and the material point of every vertex known, so the drift of a tracked surface (points
//! sliding along the surface between frames) can be measured exactly. Meant for tests, the CLI's
//! sequence benchmark (`subfit bench sequence`) and the demo.
//!
//! **Rest shape.** A closed genus-0 body of length 2 along z (a capsule of radius 0.35 with an
//! elliptic cross-section of semi-axes 0.40/0.30 and three bumps of height 0.04–0.06), not
//! symmetric under any rotation or mirror, so a fit cannot spin about its axis unnoticed. The
//! *material coordinates* of a point are its position on the rest shape.
//!
//! **Deformation.** `Φ_t` maps material to frame `t`; it is smooth in space and time and the
//! identity at `t = 0`. In order, for a material point `(x, y, z)` with axial coordinate
//! `s = z` (the global deformations of Barr, "Global and local deformations of solid
//! primitives", SIGGRAPH 1984, §§ twisting, bending, with his tapering as a travelling wave):
//! 1. twist: `(x, y)` turns about the axis by `spin·t + τ(t)·s`;
//! 2. thickness: `(x, y)` is scaled by `1 + A(t) cos 2π(s/λ − t/(N−1))`;
//! 3. bend: the axis becomes a circular arc of curvature `κ(t)` in a plane that turns about
//!    the axis by `ψ(t)`, the middle `s = 0` fixed, cross-sections kept normal to the arc.
//!
//! See [`DeformingParams`] for the time laws. **Frames** ([`DeformingSequence::frame`]) are
//! geodesic subdivisions of an elongated icosahedron projected onto the rest shape, with a
//! random resolution, azimuth and jitter, so connectivity differs from frame to frame.
//! **Drift** ([`DeformingSequence::drift`]) locates tracked points on frame 0 with a
//! [`MaterialLookup`] and compares them in every frame with where their material went.
//!
//! Costs: `Φ_t` of one point is a few dozen flops and five trigonometric calls; a frame of 25k
//! vertices is O(#V) (a few milliseconds, `benches/deforming.rs`); a lookup is one BVH query
//! (O(log #T)) after an O(#T log #T) build.

mod corresponded;
mod figure;
mod marching;
mod motion;
mod tessellate;

pub use corresponded::{NotCorresponded, SameConnectivity};
pub use figure::{DanceParams, DancingFigure};
use motion::splitmix;
pub use motion::{Frame, InvalidParams, MaterialMotion};

use std::f64::consts::TAU;

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use crate::bvh::TriangleBvh;
use crate::polygons::{bounding_box, PolyMesh, Polygons};
use crate::vec3::{dist2, norm, sub};

/// The motion of a [`DeformingSequence`]. Times are in frames; `u = t / (frames − 1)` runs
/// from 0 to 1 over the sequence, so a longer sequence shows the same motion more finely.
/// Lengths are in the units of the rest shape (length 2). Every law is 0 at `t = 0`.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DeformingParams {
    /// Number of frames `N` (≥ 1). Default 30.
    pub frames: usize,
    /// Peak curvature of the bent axis (1/length): `κ(t) = bend · sin(2π · bend_periods · u)`.
    /// `|bend| · 0.47 · (1 + thickness)` must stay below 1 (the inner side would fold).
    /// Default 0.8: the ends turn by ±0.8 rad against the middle and move by about 0.4.
    pub bend: f64,
    /// Oscillations of the curvature over the sequence. Default 1.0 (bends one way, then the
    /// other).
    pub bend_periods: f64,
    /// Turn of the bending plane about the axis over the sequence, radians:
    /// `ψ(t) = bend_plane_turn · u`. Default π/2.
    pub bend_plane_turn: f64,
    /// Peak twist rate, radians per unit axial length (the ends, at `s = ±1`, turn by
    /// `±twist` against the middle): `τ(t) = twist · sin(2π · twist_periods · u)`. Default 0.6.
    pub twist: f64,
    /// Oscillations of the twist over the sequence. Default 0.75.
    pub twist_periods: f64,
    /// Peak relative change of thickness, in `[0, 1)`:
    /// `A(t) = thickness · sin(2π · thickness_periods · u)`. Default 0.2.
    pub thickness: f64,
    /// Oscillations of the thickness amplitude over the sequence. Default 1.0.
    pub thickness_periods: f64,
    /// Wavelength of the thickness wave along the axis (length units; the wave travels one
    /// wavelength over the sequence). Default 2.0.
    pub thickness_wavelength: f64,
    /// Rigid turn of the material about the axis added per frame, radians: a large tangential
    /// motion for drift tests (the surface moves little, its points much). Default 0.
    pub spin_per_frame: f64,
}

impl Default for DeformingParams {
    fn default() -> Self {
        Self {
            frames: 30,
            bend: 0.8,
            bend_periods: 1.0,
            bend_plane_turn: TAU / 4.0,
            twist: 0.6,
            twist_periods: 0.75,
            thickness: 0.2,
            thickness_periods: 1.0,
            thickness_wavelength: 2.0,
            spin_per_frame: 0.0,
        }
    }
}

impl DeformingParams {
    /// The default motion plus a large tangential one: a spin of 0.25 rad (14°) per frame
    /// about the axis (points of the widest cross-section slide by 0.1 a frame) and twice the
    /// twist. A tracker that follows only the surface drifts along it.
    pub fn large_tangential_motion() -> Self {
        Self {
            twist: 1.2,
            spin_per_frame: 0.25,
            ..Self::default()
        }
    }
}

/// A deforming sequence: the rest shape and the motion `Φ_t` of [`DeformingParams`]
/// (`Default`: the default motion).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DeformingSequence {
    params: DeformingParams,
}

impl Frame {
    /// `count` vertices spread over the frame (farthest-point sampling from vertex 0, by
    /// straight-line distance): places for markers whose true position in every frame is
    /// [`DeformingSequence::deform`] of their material. Cost: O(#V · count).
    pub fn spread_vertices(&self, count: usize) -> Vec<usize> {
        let p = &self.mesh.positions;
        let mut picks = Vec::with_capacity(count.min(p.len()));
        let mut d2 = vec![f64::INFINITY; p.len()];
        let mut next = 0;
        while picks.len() < count.min(p.len()) {
            picks.push(next);
            for (d, &q) in d2.iter_mut().zip(p) {
                *d = d.min(dist2(q, p[next]));
            }
            next = (0..p.len())
                .max_by(|&a, &b| d2[a].total_cmp(&d2[b]))
                .unwrap_or(0);
        }
        picks
    }
}

/// The per-frame constants of `Φ_t`.
#[derive(Clone, Copy, Debug)]
struct Motion {
    spin: f64,
    twist_rate: f64,
    thickness: f64,
    wave_phase: f64,
    wave_number: f64,
    curvature: f64,
    plane: (f64, f64),
}

impl Motion {
    fn apply(&self, m: [f64; 3]) -> [f64; 3] {
        let s = m[2];
        let (sin_a, cos_a) = (self.spin + self.twist_rate * s).sin_cos();
        let sigma = 1.0 + self.thickness * (self.wave_number * s - self.wave_phase).cos();
        let x = sigma * (cos_a * m[0] - sin_a * m[1]);
        let y = sigma * (sin_a * m[0] + cos_a * m[1]);
        // Offset along the bend direction (u) and across the bending plane (v).
        let (sin_p, cos_p) = self.plane;
        let u = cos_p * x + sin_p * y;
        let v = cos_p * y - sin_p * x;
        let k = self.curvature;
        let theta = k * s;
        let (sin_t, cos_t) = theta.sin_cos();
        // The arc through the origin, tangent to z: (1 − cos θ)/κ along the bend, sin θ/κ up.
        let (out, up) = if k.abs() > 1e-9 {
            (2.0 * (0.5 * theta).sin().powi(2) / k, sin_t / k)
        } else {
            (0.5 * k * s * s, s)
        };
        let w = out + u * cos_t;
        [cos_p * w - sin_p * v, sin_p * w + cos_p * v, up - u * sin_t]
    }
}

impl DeformingSequence {
    /// A sequence with the motion `params`, checked: `frames ≥ 1`, every field finite,
    /// `0 ≤ thickness < 1`, `thickness_wavelength > 0`, and the bend gentle enough that the
    /// inner side does not fold (`|bend| · 0.47 · (1 + thickness) < 1`).
    pub fn new(params: DeformingParams) -> Result<Self, InvalidParams> {
        let bad = |field, reason| Err(InvalidParams { field, reason });
        let p = &params;
        let fields = [
            ("bend", p.bend),
            ("bend_periods", p.bend_periods),
            ("bend_plane_turn", p.bend_plane_turn),
            ("twist", p.twist),
            ("twist_periods", p.twist_periods),
            ("thickness", p.thickness),
            ("thickness_periods", p.thickness_periods),
            ("thickness_wavelength", p.thickness_wavelength),
            ("spin_per_frame", p.spin_per_frame),
        ];
        if let Some((field, _)) = fields.iter().find(|(_, v)| !v.is_finite()) {
            return bad(*field, "not a finite number");
        }
        if p.frames == 0 {
            return bad("frames", "a sequence needs at least one frame");
        }
        if !(0.0..1.0).contains(&p.thickness) {
            return bad("thickness", "must be in [0, 1)");
        }
        if p.thickness_wavelength <= 0.0 {
            return bad("thickness_wavelength", "must be positive");
        }
        if p.bend.abs() * tessellate::MAX_OFFSET * (1.0 + p.thickness) >= 1.0 {
            return bad("bend", "so strong a bend folds the inner side of the body");
        }
        Ok(Self { params })
    }

    /// The motion parameters.
    pub fn params(&self) -> &DeformingParams {
        &self.params
    }

    /// Number of frames `N`.
    pub fn len(&self) -> usize {
        self.params.frames
    }

    /// Whether the sequence has no frames (never: `new` asks for one at least).
    pub fn is_empty(&self) -> bool {
        self.params.frames == 0
    }

    fn motion(&self, index: usize) -> Motion {
        let p = &self.params;
        let t = index as f64;
        let u = t / (p.frames.max(2) - 1) as f64;
        let wave = |periods: f64| (TAU * periods * u).sin();
        let psi = p.bend_plane_turn * u;
        Motion {
            spin: p.spin_per_frame * t,
            twist_rate: p.twist * wave(p.twist_periods),
            thickness: p.thickness * wave(p.thickness_periods),
            wave_phase: TAU * u,
            wave_number: TAU / p.thickness_wavelength,
            curvature: p.bend * wave(p.bend_periods),
            plane: psi.sin_cos(),
        }
    }

    /// `Φ_t(material)`: where the material point (a point of the rest shape) is in frame
    /// `index`. Frame 0 is the rest shape itself (`Φ_0` is exactly the identity). Indices past
    /// `N − 1` continue the motion smoothly.
    pub fn deform(&self, index: usize, material: [f64; 3]) -> [f64; 3] {
        self.motion(index).apply(material)
    }

    /// [`Self::deform`] of many points (`#P by 3` in and out). Cost: O(#P).
    pub fn deform_all(&self, index: usize, material: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let motion = self.motion(index);
        material.iter().map(|&m| motion.apply(m)).collect()
    }

    /// Frame `index`: the rest shape tessellated afresh and deformed by `Φ_index`.
    ///
    /// The vertex count is drawn around `approx_vertices` (uniformly within ±30%, then rounded
    /// to the nearest count the tessellation offers, `5(k + 1)n² + 2` with `k ∈ {5, 6}`, kept
    /// within ±30% when one such count is); below about 60 vertices the coarsest mesh (32 or 37
    /// vertices) is given. The resolution, the azimuth of the tessellation and a jitter of the
    /// vertices (12% of an edge) come from a generator seeded by `seed` and `index`: the same
    /// arguments give the same frame on every machine, different indices different meshes.
    /// Triangles are wound counter-clockwise seen from outside; none is a sliver: the
    /// tessellation's angles stay above about 25° (frame 0), the deformation shears them to
    /// about 12° at the strongest bend of the default motion. Cost: O(#V), a few milliseconds
    /// for 25k vertices.
    pub fn frame(&self, index: usize, approx_vertices: usize, seed: u64) -> Frame {
        let mut rng = StdRng::seed_from_u64(splitmix(seed ^ splitmix(index as u64)));
        let approx = approx_vertices as f64;
        let target = approx * rng.random_range(0.7..1.3);
        let (material, triangles) = tessellate::tessellate(target, approx, &mut rng);
        let positions = self.deform_all(index, &material);
        Frame {
            mesh: PolyMesh::new(positions, Polygons::from_triangles(&triangles)),
            material,
        }
    }

    /// Drift of tracked points over the sequence: see [`drift`]. Frames past `N − 1` use the
    /// continued motion.
    ///
    /// # Panics
    /// If a frame lists a different number of points than `tracked[0]`.
    #[track_caller]
    pub fn drift(&self, tracked: &[Vec<[f64; 3]>], lookup: &MaterialLookup) -> DriftStats {
        drift(self, tracked, lookup)
    }
}

impl MaterialMotion for DeformingSequence {
    fn deform_all(&self, index: usize, material: &[[f64; 3]]) -> Vec<[f64; 3]> {
        DeformingSequence::deform_all(self, index, material)
    }
}

/// Drift of tracked points over a sequence of `motion`: `tracked[t][i]` is the position of
/// point `i` in frame `t` (every frame listing the same points in the same order). Point `i`'s
/// material `m_i` is found by locating `tracked[0][i]` on frame 0 with `lookup` (built from
/// frame 0, so `tracked[0]` must lie on or near frame 0's surface); its drift in frame `t` is
/// `|tracked[t][i] − Φ_t(m_i)|`, summarized per frame by its RMS, 95th percentile and largest
/// value.
///
/// Each frame's error is also given relative to the bounding-box diagonal of the deformed
/// body, taken over `lookup`'s vertices moved by `Φ_t`. Cost: O(#P log #T) for the lookups
/// plus O((#P log #P + #V₀) · #frames).
///
/// # Panics
/// If a frame lists a different number of points than `tracked[0]`.
#[track_caller]
pub fn drift(
    motion: &dyn MaterialMotion,
    tracked: &[Vec<[f64; 3]>],
    lookup: &MaterialLookup,
) -> DriftStats {
    let Some(first) = tracked.first() else {
        return DriftStats { frames: Vec::new() };
    };
    let material: Vec<[f64; 3]> = first.iter().map(|&q| lookup.material(q)).collect();
    let frames = tracked
        .iter()
        .enumerate()
        .map(|(t, points)| {
            assert_eq!(
                points.len(),
                material.len(),
                "frame {t} tracks {} points, frame 0 tracks {}",
                points.len(),
                material.len()
            );
            let truth = motion.deform_all(t, &material);
            let mut d2: Vec<f64> = points
                .iter()
                .zip(&truth)
                .map(|(&q, &m)| dist2(q, m))
                .collect();
            d2.sort_unstable_by(f64::total_cmp);
            let max2 = d2.last().copied().unwrap_or(0.0);
            let sum2: f64 = d2.iter().sum();
            let p95 = d2
                .get((0.95 * d2.len() as f64).ceil() as usize)
                .or(d2.last())
                .map_or(0.0, |v| v.sqrt());
            let moved = motion.deform_all(t, lookup.vertex_material());
            let diagonal = bounding_box(&moved).map_or(0.0, |(lo, hi)| norm(sub(hi, lo)));
            let rms = (sum2 / material.len().max(1) as f64).sqrt();
            FrameDrift {
                max: max2.sqrt(),
                rms,
                p95,
                diagonal,
                max_relative: max2.sqrt() / diagonal,
                rms_relative: rms / diagonal,
                p95_relative: p95 / diagonal,
            }
        })
        .collect();
    DriftStats { frames }
}

/// Maps points near one frame's surface to material coordinates: the closest point on the
/// frame's triangles, then the barycentric interpolation of its corners' material
/// coordinates. For drift, build it from frame 0. Memory: the frame's positions, triangles and
/// material plus a BVH (about 150 bytes a triangle).
#[derive(Clone, Debug)]
pub struct MaterialLookup {
    bvh: TriangleBvh,
    material: Vec<[f64; 3]>,
}

impl MaterialLookup {
    /// Builds the lookup over `frame` (faces fan-triangulated). Cost: O(#T log #T).
    ///
    /// # Panics
    /// If the frame has no faces, or `material` and the positions differ in length.
    #[track_caller]
    pub fn new(frame: &Frame) -> Self {
        assert!(
            !frame.mesh.faces.is_empty(),
            "a material lookup needs faces"
        );
        assert_eq!(
            frame.material.len(),
            frame.mesh.positions.len(),
            "one material point per vertex"
        );
        let bvh = TriangleBvh::new(
            frame.mesh.positions.clone(),
            frame.mesh.faces.triangulate_fan(),
        );
        Self {
            bvh,
            material: frame.material.clone(),
        }
    }

    /// The material coordinates of the point of the frame's surface closest to `p`, and the
    /// distance from `p` to it. Cost: one BVH query, O(log #T).
    pub fn locate(&self, p: [f64; 3]) -> ([f64; 3], f64) {
        let hit = self.bvh.closest(p).expect("the lookup has triangles");
        let tri = self.bvh.triangles()[hit.triangle as usize];
        let b = hit.barycentric;
        let [m0, m1, m2] = tri.map(|v| self.material[v as usize]);
        let m = std::array::from_fn(|k| b[0] * m0[k] + b[1] * m1[k] + b[2] * m2[k]);
        (m, hit.distance)
    }

    /// The material coordinates of the point of the frame's surface closest to `p`.
    pub fn material(&self, p: [f64; 3]) -> [f64; 3] {
        self.locate(p).0
    }

    /// The material coordinates of the frame's vertices (`#V by 3`).
    pub fn vertex_material(&self) -> &[[f64; 3]] {
        &self.material
    }
}

/// Drift of tracked points in one frame (lengths in the units of the shape).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct FrameDrift {
    /// Largest distance of a tracked point from where its material went.
    pub max: f64,
    /// Root mean square of those distances.
    pub rms: f64,
    /// Their 95th percentile.
    pub p95: f64,
    /// Bounding-box diagonal of the deformed body in this frame.
    pub diagonal: f64,
    /// `max / diagonal`.
    pub max_relative: f64,
    /// `rms / diagonal`.
    pub rms_relative: f64,
    /// `p95 / diagonal`.
    pub p95_relative: f64,
}

/// Drift of tracked points over a sequence, one entry per frame.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct DriftStats {
    /// Per-frame figures, frame 0 first.
    pub frames: Vec<FrameDrift>,
}

impl DriftStats {
    /// The largest relative drift over all frames (0 without frames).
    pub fn max_relative(&self) -> f64 {
        self.frames
            .iter()
            .map(|f| f.max_relative)
            .fold(0.0, f64::max)
    }

    /// The largest relative RMS drift over all frames (0 without frames).
    pub fn max_rms_relative(&self) -> f64 {
        self.frames
            .iter()
            .map(|f| f.rms_relative)
            .fold(0.0, f64::max)
    }

    /// The largest relative 95th-percentile drift over all frames (0 without frames).
    pub fn max_p95_relative(&self) -> f64 {
        self.frames
            .iter()
            .map(|f| f.p95_relative)
            .fold(0.0, f64::max)
    }
}
