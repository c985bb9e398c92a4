//! The CAD-exporter-like tessellation of an extruded profile: walls in vertical strips, caps as
//! fans (from the first vertex, or from an inner point when the sides are cut) or as rings
//! zipped between an outline and a hole by angle.

use std::collections::HashMap;
use std::f64::consts::TAU;

use super::profile::{arc_segments, circle, rounded_rectangle, split_sides, Profile};
use crate::{PolyMesh, Polygons};

/// Triangles with vertices welded on a grid of `quantum`.
struct Builder {
    quantum: f64,
    positions: Vec<[f64; 3]>,
    ids: HashMap<[i64; 3], u32>,
    triangles: Vec<[u32; 3]>,
}

impl Builder {
    fn vertex(&mut self, p: [f64; 2], z: f64) -> u32 {
        let q = [p[0], p[1], z];
        let key = q.map(|c| (c / self.quantum).round() as i64);
        let n = self.positions.len() as u32;
        *self.ids.entry(key).or_insert_with(|| {
            self.positions.push(q);
            n
        })
    }

    fn triangle(&mut self, t: [u32; 3]) {
        if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
            self.triangles.push(t);
        }
    }

    /// The walls of a closed loop (counter-clockwise for an outline, clockwise for a hole:
    /// faces to the right of the loop's direction face out), in `rows` rows.
    fn walls(&mut self, lp: &[[f64; 2]], height: f64, rows: usize) {
        let n = lp.len();
        for i in 0..n {
            let (a, b) = (lp[i], lp[(i + 1) % n]);
            for j in 0..rows {
                let (z0, z1) = (
                    height * j as f64 / rows as f64,
                    height * (j + 1) as f64 / rows as f64,
                );
                let q = [
                    self.vertex(a, z0),
                    self.vertex(b, z0),
                    self.vertex(b, z1),
                    self.vertex(a, z1),
                ];
                self.triangle([q[0], q[1], q[2]]);
                self.triangle([q[0], q[2], q[3]]);
            }
        }
    }

    /// Top (`z = height`, facing up) and bottom (facing down) caps of a counter-clockwise
    /// loop: fans from `centre` when given, else from the loop's first vertex.
    fn fan_caps(&mut self, lp: &[[f64; 2]], centre: Option<[f64; 2]>, height: f64) {
        let n = lp.len();
        for (z, up) in [(height, true), (0.0, false)] {
            let (start, hub) = match centre {
                Some(c) => (0, self.vertex(c, z)),
                None => (1, self.vertex(lp[0], z)),
            };
            let end = if centre.is_some() { n } else { n - 1 };
            for i in start..end {
                let a = self.vertex(lp[i], z);
                let b = self.vertex(lp[(i + 1) % n], z);
                self.triangle(if up { [hub, a, b] } else { [hub, b, a] });
            }
        }
    }

    /// Top and bottom caps of the ring between the counter-clockwise loops `outer` and `inner`
    /// around `centre`, zipped by angle.
    fn ring_caps(&mut self, outer: &[[f64; 2]], inner: &[[f64; 2]], centre: [f64; 2], h: f64) {
        let angle = |p: [f64; 2], from: f64| {
            ((p[1] - centre[1]).atan2(p[0] - centre[0]) - from).rem_euclid(TAU)
        };
        let from = angle(outer[0], 0.0);
        let (m, n) = (outer.len(), inner.len());
        let first = (0..n)
            .min_by(|&a, &b| angle(inner[a], from).total_cmp(&angle(inner[b], from)))
            .unwrap_or(0);
        // Unwrapped angles; the loops close at their first point plus a turn.
        let ao = |k: usize| {
            if k == m {
                TAU
            } else {
                angle(outer[k], from)
            }
        };
        let ai = |k: usize| angle(inner[(first + k) % n], from) + if k == n { TAU } else { 0.0 };
        for (z, up) in [(h, true), (0.0, false)] {
            let (mut a, mut b) = (0, 0);
            while a < m || b < n {
                let o0 = self.vertex(outer[a % m], z);
                let i0 = self.vertex(inner[(first + b) % n], z);
                let t = if b == n || (a < m && ao(a + 1) <= ai(b + 1)) {
                    a += 1;
                    [i0, o0, self.vertex(outer[a % m], z)]
                } else {
                    b += 1;
                    [i0, o0, self.vertex(inner[(first + b) % n], z)]
                };
                self.triangle(if up { t } else { [t[0], t[2], t[1]] });
            }
        }
    }
}

/// See [`super::Part::tessellate`].
pub(super) fn extrude(
    profile: &Profile,
    height: f64,
    chord: f64,
    max_edge: Option<f64>,
) -> PolyMesh {
    let (lo, hi) = profile.bounds();
    let size = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(height);
    let mut b = Builder {
        quantum: 1e-9 * size,
        positions: Vec::new(),
        ids: HashMap::new(),
        triangles: Vec::new(),
    };
    let rows = super::profile::pieces(height, max_edge);
    let round = |r: f64| {
        let by_edge = max_edge.map_or(3, |e| (TAU * r / e).ceil() as usize);
        arc_segments(r, TAU, chord).max(by_edge).max(3)
    };
    match profile {
        Profile::Polygon(points) => {
            let lp = split_sides(points, max_edge);
            b.walls(&lp, height, rows);
            let centre = (lp.len() > points.len()).then(|| kernel_point(points));
            b.fan_caps(&lp, centre, height);
        }
        Profile::Disc { radius } => {
            let lp = circle([0.0; 2], *radius, round(*radius), 0.0);
            b.walls(&lp, height, rows);
            b.fan_caps(&lp, None, height);
        }
        Profile::RoundedRectangle { size, radius } => {
            let lp = rounded_rectangle(*size, *radius, chord, max_edge);
            b.walls(&lp, height, rows);
            let centre = max_edge.map(|_| [0.5 * size[0], 0.5 * size[1]]);
            b.fan_caps(&lp, centre, height);
        }
        Profile::Annulus { outer, inner } => {
            let n = round(*outer).max(round(*inner));
            let o = circle([0.0; 2], *outer, n, 0.0);
            let i = circle([0.0; 2], *inner, n, 0.0);
            b.walls(&o, height, rows);
            b.walls(&reversed(&i), height, rows);
            b.ring_caps(&o, &i, [0.0; 2], height);
        }
        Profile::DrilledPlate {
            cells,
            cell,
            hole_radius,
        } => drilled_plate(&mut b, *cells, *cell, *hole_radius, height, rows, &round),
    }
    PolyMesh::new(b.positions, Polygons::from_triangles(&b.triangles))
}

/// Halfway between a polygon's first vertex and its centroid (see [`Profile::Polygon`]).
fn kernel_point(points: &[[f64; 2]]) -> [f64; 2] {
    let n = points.len() as f64;
    let c = points
        .iter()
        .fold([0.0; 2], |s, p| [s[0] + p[0] / n, s[1] + p[1] / n]);
    [0.5 * (points[0][0] + c[0]), 0.5 * (points[0][1] + c[1])]
}

fn reversed(lp: &[[f64; 2]]) -> Vec<[f64; 2]> {
    lp.iter().rev().copied().collect()
}

/// A drilled plate: per cell, the hole's polygon (a multiple of 4 chords, offset by half a
/// chord so that it is symmetric about both axes) and the cell's outline through the points
/// where the hole's rays meet it (and its corners), so that neighbouring cells share their
/// points; the caps are rings between them, the outer walls run along the plate's outline.
fn drilled_plate(
    b: &mut Builder,
    cells: [usize; 2],
    cell: f64,
    r: f64,
    height: f64,
    rows: usize,
    round: &dyn Fn(f64) -> usize,
) {
    let n = round(r).div_ceil(4) * 4;
    let half = 0.5 * cell;
    let size = [cells[0] as f64 * cell, cells[1] as f64 * cell];
    let mut perimeter: [Vec<[f64; 2]>; 4] = Default::default();
    for i in 0..cells[0] {
        for j in 0..cells[1] {
            let c = [(i as f64 + 0.5) * cell, (j as f64 + 0.5) * cell];
            let hole = circle(c, r, n, std::f64::consts::PI / n as f64);
            let mut outline: Vec<(f64, [f64; 2])> = (0..n)
                .map(|k| {
                    let a = TAU * (k as f64 + 0.5) / n as f64;
                    let (s, co) = a.sin_cos();
                    let t = half / co.abs().max(s.abs());
                    (a, [c[0] + t * co, c[1] + t * s])
                })
                .collect();
            for k in 0..4 {
                let a = std::f64::consts::FRAC_PI_4 * (2 * k + 1) as f64;
                let (s, co) = a.sin_cos();
                outline.push((a, [c[0] + half * co.signum(), c[1] + half * s.signum()]));
            }
            outline.sort_by(|x, y| x.0.total_cmp(&y.0));
            let outline: Vec<[f64; 2]> = outline.into_iter().map(|x| x.1).collect();
            for p in &outline {
                let eps = 1e-9 * cell;
                for (side, on) in [
                    p[1] < eps,
                    p[0] > size[0] - eps,
                    p[1] > size[1] - eps,
                    p[0] < eps,
                ]
                .into_iter()
                .enumerate()
                {
                    if on {
                        perimeter[side].push(*p);
                    }
                }
            }
            b.walls(&reversed(&hole), height, rows);
            b.ring_caps(&outline, &hole, c, height);
        }
    }
    // The outline counter-clockwise: bottom by x, right by y, top by −x, left by −y.
    let keys: [fn(&[f64; 2]) -> f64; 4] = [|p| p[0], |p| p[1], |p| -p[0], |p| -p[1]];
    let mut lp: Vec<[f64; 2]> = Vec::new();
    for (side, key) in perimeter.iter_mut().zip(keys) {
        side.sort_by(|x, y| key(x).total_cmp(&key(y)));
        for p in side.iter() {
            let same = |q: &[f64; 2]| (q[0] - p[0]).abs() + (q[1] - p[1]).abs() < 1e-9 * cell;
            if !lp.last().is_some_and(same) && !lp.first().is_some_and(same) {
                lp.push(*p);
            }
        }
    }
    b.walls(&lp, height, rows);
}
