//! Which edges of a tessellation are creases, which belong to a smooth face, and the
//! exporter's chord height — read from the facets alone.
//!
//! A tessellator samples a curved face of the part with vertices on it and keeps each facet's
//! sag below its chord height `h`. Across an edge where the facets turn by `θ` and are `w`
//! wide (measured across the edge: the planar region's extent from the edge line), a circle
//! through the vertices lies `s = w θ / 8` off the facets (the sagitta `R(1 − cos(θ/2))` with
//! `w ≈ Rθ`); for two sides of widths `w1`, `w2` the curvature is `θ / ((w1 + w2)/2)` and the
//! wider side sags `s = θ max(w)² / (4 (w1 + w2))`. Smoothing an edge between two strips of a
//! cylinder moves the surface by about `s ≈ h`; smoothing the kink between a fillet strip and
//! a wide plane would bend the plane over its whole width, `s ≫ h`. So an edge is:
//!
//! * **flat** when its faces are coplanar (one planar region);
//! * a **crease** when it turns by [`MAX_SMOOTH_ANGLE_DEG`] or more (a designed edge; an
//!   exporter that lets a curved face turn that much per facet asks for a faceted part), or
//!   when its sag is above the threshold of the [`SmoothBudget`];
//! * **smooth** otherwise: the limit surface may round it.
//!
//! A smooth limit fitted to a strip's facets by least squares lies within `2s/3` of them with an
//! RMS of about `0.3 s` (the parabola `s(1 − u²)` less its mean over the strip), which is what
//! [`classify_edges`] budgets with: the threshold is the largest sag at most
//! [`SmoothBudget::max_sag`] whose smooth regions predict an RMS deviation from the facets,
//! over the whole surface, within [`SmoothBudget::max_rms`].

use super::facets::Facets;
use subfit_mesh::vec3::{cross, norm, sub};

/// Edges turning by at least this (degrees) are creases whatever their sag: a curved face
/// tessellated that coarsely is faceted on purpose; the box edges, chamfers and hole rims of a
/// part turn by 45–90° over facets of any width. 6-segment cylinders stay faceted.
pub const MAX_SMOOTH_ANGLE_DEG: f64 = 50.0;

/// How much smoothing the facets allow (units of the positions).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothBudget {
    /// Largest sag `s` of a smooth edge.
    pub max_sag: f64,
    /// Largest predicted RMS deviation of the smooth limit from the facets over the whole
    /// surface (`f64::INFINITY`: no bound).
    pub max_rms: f64,
}

impl SmoothBudget {
    /// No smoothing: every edge that turns is a crease (the facets reproduced exactly).
    pub const FACETED: Self = Self {
        max_sag: 0.0,
        max_rms: 0.0,
    };
}

/// Under the chordal tolerance, an edge of a curved face sags by about the exporter's chord
/// height; one that sags by more than this many chord heights is a designed edge (a chamfer
/// between wide planes, the kink between a fillet and its plane) and stays a crease.
pub const CHORDAL_SAGS: f64 = 3.0;

impl SmoothBudget {
    /// The chordal tolerance's budget for `facets` over `positions`: an edge that turns by
    /// less than [`MAX_SMOOTH_ANGLE_DEG`] is smooth when its sag is within [`CHORDAL_SAGS`]
    /// exporter's chord heights ([`chord_height`]), whatever the deviation from the facets
    /// adds up to: the limit aims at the curved part, not at the facets.
    pub fn chordal(positions: &[[f64; 3]], facets: &Facets) -> Self {
        let open = Self {
            max_sag: f64::INFINITY,
            max_rms: f64::INFINITY,
        };
        let h = classify_edges(positions, facets, &open).chord_height;
        Self {
            max_sag: CHORDAL_SAGS * h,
            max_rms: f64::INFINITY,
        }
    }
}

/// Under the chordal tolerance, an edge is smooth only between sides at most this many times
/// as wide across it as it is long: the facets of a curved face are strips along it (a
/// cylinder's) or about square (a sphere's), while two wide planes meeting at a shallow angle
/// (the walls of an embossed letter at a corner of 40°) are a designed edge, whatever their
/// sag says.
pub const CHORDAL_STRIP_RATIO: f64 = 2.0;

/// The classes of [`classify_edges`] under the chordal tolerance: the budget of
/// [`SmoothBudget::chordal`], and a smooth edge between sides wider than
/// [`CHORDAL_STRIP_RATIO`] times its length a crease.
pub fn classify_edges_chordal(positions: &[[f64; 3]], facets: &Facets) -> FacetFeatures {
    let mut features = classify_edges(positions, facets, &SmoothBudget::chordal(positions, facets));
    let widths = side_widths(positions, facets);
    for (i, e) in facets.edges.iter().enumerate() {
        if features.class[i] != EdgeClass::Smooth {
            continue;
        }
        let len = norm(sub(
            positions[e.ends[1] as usize],
            positions[e.ends[0] as usize],
        ));
        if widths[i][0].max(widths[i][1]) > CHORDAL_STRIP_RATIO * len {
            features.class[i] = EdgeClass::Crease;
        }
    }
    features
}

/// The class of an interior edge of a tessellation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeClass {
    /// Its faces are coplanar.
    Flat,
    /// A curved face's facets turn here; the limit may round it.
    Smooth,
    /// A sharp feature: tagged as an infinitely sharp crease.
    Crease,
}

/// The features of a tessellation (see the module docs).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FacetFeatures {
    /// Class of every edge of [`Facets::edges`], in order.
    pub class: Vec<EdgeClass>,
    /// Sag `s` of every edge (0 for flat ones; units of the positions).
    pub sag: Vec<f64>,
    /// The sag threshold used: edges below [`MAX_SMOOTH_ANGLE_DEG`] up to it are smooth.
    pub threshold: f64,
    /// The predicted RMS deviation of the smooth limit from the facets.
    pub predicted_rms: f64,
    /// The exporter's chord height estimated from the curved faces ([`chord_height`]).
    pub chord_height: f64,
}

impl FacetFeatures {
    /// Number of edges of `class`.
    pub fn count(&self, class: EdgeClass) -> usize {
        self.class.iter().filter(|&&c| c == class).count()
    }
}

/// Classifies the edges of `facets` over `positions` within `budget` (see the module docs).
/// Cost O(E log E) plus, per turning edge, the vertices of its two planar regions (capped
/// at [`WIDTH_SAMPLES`] each).
pub fn classify_edges(
    positions: &[[f64; 3]],
    facets: &Facets,
    budget: &SmoothBudget,
) -> FacetFeatures {
    let widths = side_widths(positions, facets);
    let max_angle = MAX_SMOOTH_ANGLE_DEG.to_radians();
    let sag: Vec<f64> = facets
        .edges
        .iter()
        .zip(&widths)
        .map(|(e, &[w1, w2])| {
            if e.flat {
                0.0
            } else {
                e.angle * w1.max(w2).powi(2) / (4.0 * (w1 + w2)).max(f64::MIN_POSITIVE)
            }
        })
        .collect();
    let candidate = |i: usize| !facets.edges[i].flat && facets.edges[i].angle < max_angle;
    let mut sorted: Vec<f64> = (0..sag.len())
        .filter(|&i| candidate(i) && sag[i] <= budget.max_sag)
        .map(|i| sag[i])
        .collect();
    sorted.sort_by(f64::total_cmp);
    let rms = |t: f64| predicted_rms(facets, &sag, &|i| candidate(i) && sag[i] <= t);
    // The largest threshold within the RMS budget (the predicted RMS grows with it).
    let (mut lo, mut hi) = (0usize, sorted.len());
    while lo < hi {
        let mid = (lo + hi).div_ceil(2);
        if rms(sorted[mid - 1]) <= budget.max_rms {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    let threshold = if lo == 0 { -1.0 } else { sorted[lo - 1] };
    let class = (0..sag.len())
        .map(|i| {
            if facets.edges[i].flat {
                EdgeClass::Flat
            } else if candidate(i) && sag[i] <= threshold {
                EdgeClass::Smooth
            } else {
                EdgeClass::Crease
            }
        })
        .collect();
    FacetFeatures {
        class,
        predicted_rms: rms(threshold),
        threshold: threshold.max(0.0),
        chord_height: chord_height(facets, &sag, &widths),
        sag,
    }
}

/// Most vertices of a planar region measured for its width across an edge (an evenly spread
/// subset beyond it: the width of a large face is only compared with small sags).
pub const WIDTH_SAMPLES: usize = 256;

/// Per edge, the width of each side: the largest distance of its planar region's vertices
/// from the edge's line, in the region's plane.
fn side_widths(positions: &[[f64; 3]], facets: &Facets) -> Vec<[f64; 2]> {
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); facets.regions.len()];
    for (f, t) in facets.triangles.iter().enumerate() {
        members[facets.region[f] as usize].extend_from_slice(t);
    }
    for m in &mut members {
        m.sort_unstable();
        m.dedup();
        if m.len() > WIDTH_SAMPLES {
            let step = m.len().div_ceil(WIDTH_SAMPLES);
            *m = m.iter().step_by(step).copied().collect();
        }
    }
    facets
        .edges
        .iter()
        .map(|e| {
            if e.flat {
                return [0.0; 2];
            }
            let a = positions[e.ends[0] as usize];
            let d = sub(positions[e.ends[1] as usize], a);
            let len = norm(d).max(f64::MIN_POSITIVE);
            e.faces.map(|f| {
                members[facets.region[f as usize] as usize]
                    .iter()
                    .map(|&v| norm(cross(sub(positions[v as usize], a), d)) / len)
                    .fold(0.0, f64::max)
            })
        })
        .collect()
}

/// The RMS deviation from the facets predicted for the edges `smooth` being smooth: each
/// planar region with a smooth edge deviates by `0.3 s` RMS over its area, `s` its largest
/// smooth edge's sag.
fn predicted_rms(facets: &Facets, sag: &[f64], smooth: &dyn Fn(usize) -> bool) -> f64 {
    let mut region_sag = vec![0.0f64; facets.regions.len()];
    for (i, e) in facets.edges.iter().enumerate() {
        if smooth(i) {
            for f in e.faces {
                let r = facets.region[f as usize] as usize;
                region_sag[r] = region_sag[r].max(sag[i]);
            }
        }
    }
    let total: f64 = facets.regions.iter().map(|r| r.area).sum();
    let sum: f64 = facets
        .regions
        .iter()
        .zip(&region_sag)
        .map(|(r, &s)| r.area * (0.3 * s).powi(2))
        .sum();
    if total > 0.0 {
        (sum / total).sqrt()
    } else {
        0.0
    }
}

/// The exporter's chord height: the median sag, weighted by the area of the two faces, of the edges inside
/// curved faces — turning by less than [`MAX_SMOOTH_ANGLE_DEG`] between sides whose widths
/// differ by at most a factor of 3 (strips of one curved face; the kink between a fillet and
/// a wide plane is not one). 0 for a part with no such edge (all planes).
pub fn chord_height(facets: &Facets, sag: &[f64], widths: &[[f64; 2]]) -> f64 {
    let max_angle = MAX_SMOOTH_ANGLE_DEG.to_radians();
    let mut samples: Vec<(f64, f64)> = Vec::new();
    for (i, e) in facets.edges.iter().enumerate() {
        let [w1, w2] = widths[i];
        if e.flat || e.angle >= max_angle || w1.max(w2) > 3.0 * w1.min(w2) {
            continue;
        }
        samples.push((sag[i], edge_weight(facets, i)));
    }
    weighted_median(&mut samples)
}

/// An edge's weight in the chord height: the area of its two faces (a long strip counts for
/// its length).
fn edge_weight(facets: &Facets, i: usize) -> f64 {
    let e = &facets.edges[i];
    e.faces
        .iter()
        .map(|&f| facets.areas[f as usize])
        .sum::<f64>()
        + f64::MIN_POSITIVE
}

/// The weighted median of `(value, weight)` pairs; 0 for none.
fn weighted_median(samples: &mut [(f64, f64)]) -> f64 {
    samples.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = samples.iter().map(|s| s.1).sum();
    let mut acc = 0.0;
    for &(v, w) in samples.iter() {
        acc += w;
        if acc >= 0.5 * total {
            return v;
        }
    }
    0.0
}
