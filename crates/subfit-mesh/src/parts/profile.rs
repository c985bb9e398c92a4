//! The planar cross-sections of [`super::Part`]: exact signed distances and outlines cut at a
//! chord height.

use std::f64::consts::{FRAC_PI_2, TAU};

/// A cross-section in the `xy` plane.
#[derive(Clone, Debug, PartialEq)]
pub enum Profile {
    /// A counter-clockwise simple polygon, star-shaped from the point halfway between its
    /// first vertex and its centroid (the caps of a finer tessellation are fans from there).
    Polygon(Vec<[f64; 2]>),
    /// A disc of this radius around the origin.
    Disc {
        /// Radius.
        radius: f64,
    },
    /// An annulus around the origin.
    Annulus {
        /// Outer radius.
        outer: f64,
        /// Inner radius, below `outer`.
        inner: f64,
    },
    /// The rectangle `[0, size[0]] × [0, size[1]]` with its corners rounded.
    RoundedRectangle {
        /// Side lengths.
        size: [f64; 2],
        /// Corner radius, below half of each side.
        radius: f64,
    },
    /// `cells[0] × cells[1]` squares of side `cell` from the origin, each with a hole of
    /// radius `hole_radius` at its centre.
    DrilledPlate {
        /// Cells along `x` and `y`.
        cells: [usize; 2],
        /// Side of a cell.
        cell: f64,
        /// Hole radius, below `cell / 2`.
        hole_radius: f64,
    },
}

impl Profile {
    /// Exact signed distance of `p` to the outline: negative inside.
    pub fn signed_distance(&self, p: [f64; 2]) -> f64 {
        match self {
            Self::Polygon(points) => polygon_distance(points, p),
            Self::Disc { radius } => p[0].hypot(p[1]) - radius,
            Self::Annulus { outer, inner } => {
                let r = p[0].hypot(p[1]);
                (r - outer).max(inner - r)
            }
            Self::RoundedRectangle { size, radius } => {
                let q = [0, 1].map(|k| (p[k] - 0.5 * size[k]).abs() - (0.5 * size[k] - radius));
                q[0].max(0.0).hypot(q[1].max(0.0)) + q[0].max(q[1]).min(0.0) - radius
            }
            Self::DrilledPlate {
                cells,
                cell,
                hole_radius,
            } => {
                let size = [cells[0] as f64 * cell, cells[1] as f64 * cell];
                let q = [0, 1].map(|k| (p[k] - 0.5 * size[k]).abs() - 0.5 * size[k]);
                let outer = q[0].max(0.0).hypot(q[1].max(0.0)) + q[0].max(q[1]).min(0.0);
                // The holes lie inside their cells: the nearest hole is in the nearest cell.
                let i = (p[0] / cell).floor().clamp(0.0, cells[0] as f64 - 1.0);
                let j = (p[1] / cell).floor().clamp(0.0, cells[1] as f64 - 1.0);
                let c = [(i + 0.5) * cell, (j + 0.5) * cell];
                let hole = hole_radius - (p[0] - c[0]).hypot(p[1] - c[1]);
                outer.max(hole)
            }
        }
    }

    /// Bounding box `(min, max)`.
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        match self {
            Self::Polygon(points) => points.iter().fold(
                ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
                |(lo, hi), q| {
                    (
                        [lo[0].min(q[0]), lo[1].min(q[1])],
                        [hi[0].max(q[0]), hi[1].max(q[1])],
                    )
                },
            ),
            Self::Disc { radius: r } | Self::Annulus { outer: r, .. } => ([-r, -r], [*r, *r]),
            Self::RoundedRectangle { size, .. } => ([0.0; 2], *size),
            Self::DrilledPlate { cells, cell, .. } => {
                ([0.0; 2], [cells[0] as f64 * cell, cells[1] as f64 * cell])
            }
        }
    }
}

/// Segments an arc of `angle` (radians) and `radius` needs so that no chord sags more than
/// `chord`; at least 1.
pub(super) fn arc_segments(radius: f64, angle: f64, chord: f64) -> usize {
    let half = (1.0 - chord / radius).clamp(-1.0, 1.0).acos();
    ((angle / (2.0 * half)).ceil() as usize).max(1)
}

/// The circle of `radius` around `centre` cut into `n` chords, from angle `start`,
/// counter-clockwise.
pub(super) fn circle(centre: [f64; 2], radius: f64, n: usize, start: f64) -> Vec<[f64; 2]> {
    (0..n)
        .map(|k| {
            let a = start + TAU * k as f64 / n as f64;
            [centre[0] + radius * a.cos(), centre[1] + radius * a.sin()]
        })
        .collect()
}

/// Segments of a straight side of length `len` (1 without `max_edge`).
pub(super) fn pieces(len: f64, max_edge: Option<f64>) -> usize {
    max_edge.map_or(1, |e| ((len / e).ceil() as usize).max(1))
}

/// The counter-clockwise outline of a rounded rectangle: per corner its arc, then the
/// straight side to the next corner.
pub(super) fn rounded_rectangle(
    size: [f64; 2],
    r: f64,
    chord: f64,
    max_edge: Option<f64>,
) -> Vec<[f64; 2]> {
    let m = arc_segments(r, FRAC_PI_2, chord);
    let centres = [
        [size[0] - r, r],
        [size[0] - r, size[1] - r],
        [r, size[1] - r],
        [r, r],
    ];
    let mut out = Vec::new();
    for (c, centre) in centres.iter().enumerate() {
        // Corner c's arc runs from angle (c − 1)·π/2 to c·π/2.
        let a0 = (c as f64 - 1.0) * FRAC_PI_2;
        for k in 0..=m {
            let a = a0 + FRAC_PI_2 * k as f64 / m as f64;
            out.push([centre[0] + r * a.cos(), centre[1] + r * a.sin()]);
        }
        let end = out[out.len() - 1];
        let next = centres[(c + 1) % 4];
        let a1 = a0 + FRAC_PI_2;
        let start = [next[0] + r * a1.cos(), next[1] + r * a1.sin()];
        let len = (start[0] - end[0]).hypot(start[1] - end[1]);
        let k = pieces(len, max_edge);
        for s in 1..k {
            let t = s as f64 / k as f64;
            out.push([
                end[0] + t * (start[0] - end[0]),
                end[1] + t * (start[1] - end[1]),
            ]);
        }
    }
    out
}

/// A polygon with every side cut into pieces no longer than `max_edge`.
pub(super) fn split_sides(points: &[[f64; 2]], max_edge: Option<f64>) -> Vec<[f64; 2]> {
    let n = points.len();
    let mut out = Vec::new();
    for i in 0..n {
        let (a, b) = (points[i], points[(i + 1) % n]);
        let k = pieces((b[0] - a[0]).hypot(b[1] - a[1]), max_edge);
        for s in 0..k {
            let t = s as f64 / k as f64;
            out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
        }
    }
    out
}

/// Exact signed distance to a simple polygon (negative inside, by the crossing rule).
fn polygon_distance(points: &[[f64; 2]], p: [f64; 2]) -> f64 {
    let n = points.len();
    let mut best = f64::INFINITY;
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (points[i], points[(i + 1) % n]);
        let d = [b[0] - a[0], b[1] - a[1]];
        let w = [p[0] - a[0], p[1] - a[1]];
        let t = ((w[0] * d[0] + w[1] * d[1]) / (d[0] * d[0] + d[1] * d[1])).clamp(0.0, 1.0);
        best = best.min((w[0] - t * d[0]).hypot(w[1] - t * d[1]));
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * d[0];
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    if inside {
        -best
    } else {
        best
    }
}
