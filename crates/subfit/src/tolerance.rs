//! The tolerances a fit is judged by when the user gives none, and the noise floor of a noisy
//! scan's RMS tolerance.
//!
//! **Defaults relative to the target** ([`crate::FitScanOptions::target_tolerances`]): a fixed
//! tolerance in the unit cube (Cheng et al. 2007's Table IV works at `E_rms` 5e-4) is 2–3.5e-4
//! of a typical model's diagonal — far stricter than a scan needs, and paid for in control
//! points: an armadillo with 27 holes took 4,698 of them. Users judge a cage by its distance to
//! the data as a fraction of the model's size, both the RMS and the largest (Hausdorff), so the
//! defaults are stated that way:
//!
//! - a **scan** (any target without sharp features): two-sided RMS ≤ [`SCAN_RMS`] and
//!   Hausdorff ≤ [`SCAN_MAX`] of the bounding-box diagonal, a mesh's boundary vertices within
//!   [`SCAN_BOUNDARY`] of the limit surface;
//! - a **CAD part** (a fifth or more of the cage's edges are sharp creases, from detected
//!   feature curves or a given tagged cage): RMS ≤ [`CAD_RMS`] and Hausdorff ≤ [`CAD_MAX`] —
//!   a rounded sharp edge is what a CAD user sees first;
//! - a **noisy scan** ([`subfit_target::TargetStats::is_noisy`]): the scan's RMS, no maximum
//!   (an outlier or the noise's tail sets it), then raised to the noise floor
//!   (`noise_floored`).
//!
//! Measured with `subfit fit MODEL` on the shared models and the hard cases of
//! `examples/hard_cases.rs` (two-sided, from report.json, fractions of the diagonal; control
//! points before → after): armadillo with 27 holes 4,698 → 1,381 (RMS 6.9e-4, Hausdorff
//! 0.58 %, boundary vertices within 0.39 % by `subfit compare`), Igea cut open at its base
//! 1,845 → 674 (6.1e-4, 0.36 %), Igea 1,725 → 595, bunny.off 4,936 → 484, armadillo 3,451 →
//! 1,110, Stanford bunny 1,559 → 500, camel head 657 → 459 (4.9e-4, 0.67 %), face 362 → 291,
//! beetle 315 → 329, rocker arm 495 → 320 (6.1e-4, 0.38 %); fandisk, a CAD part, 323 → 343
//! (8.9e-5, 0.15 %).

use subfit_fit::StageOptions;
use subfit_mesh::{Polygons, Tags, SHARPNESS_INFINITE};
use subfit_target::TargetStats;

/// Default two-sided RMS tolerance of a scan, as a fraction of the bounding-box diagonal.
pub const SCAN_RMS: f64 = 7.5e-4;
/// Default two-sided maximum (Hausdorff) tolerance of a scan, fraction of the diagonal.
pub const SCAN_MAX: f64 = 7e-3;
/// Default largest distance of a scan's boundary vertices to the limit surface, fraction of
/// the diagonal ([`StageOptions::tolerance_boundary`]): an open rim is judged tighter.
pub const SCAN_BOUNDARY: f64 = 4e-3;
/// Default two-sided RMS tolerance of a CAD part (sharp creases), fraction of the diagonal.
pub const CAD_RMS: f64 = 4e-4;
/// Default two-sided maximum tolerance of a CAD part, fraction of the diagonal.
pub const CAD_MAX: f64 = 2e-3;

/// The share of a cage's edges that are sharp creases from which its target is a CAD part:
/// fandisk's automatic cage has 32 % (198 of 610 edges), the filleted prism of
/// `shapes::rounded_prism` 60 %; the scanned car of `beetle.off` 13 % (85 of 636, the creases
/// of its wheel arches and windows), and a smooth scan none.
pub const CAD_CREASE_SHARE: f64 = 0.2;

/// The dihedral angle (degrees) from which a CAD part's edges are sharp features
/// ([`crate::FitScanOptions::cad_feature_angle`]), below the default 40° that keeps scans free of
/// spurious creases. A fillet tessellated with two facets meets its flat sides at 22.5° kinks;
/// with them left to the smooth surface, the rounded prism's rims stayed 0.34 % of the diagonal
/// off at 124 control points (the CAD tolerance is 0.2 %); with them creased its 24-point cage
/// is exact, and fandisk needs 259 control points instead of 343 at the same Hausdorff distance
/// (0.15 %). At 20° the bunny has four crease curves, hence not for scans.
pub const CAD_FEATURE_ANGLE: f64 = 20.0;

/// Which default set the tolerances ([`target_tolerances`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ToleranceKind {
    /// [`SCAN_RMS`], [`SCAN_MAX`].
    Scan,
    /// [`CAD_RMS`], [`CAD_MAX`]: the cage has sharp creases, or the target is a CAD
    /// tessellation ([`crate::start_cad`]).
    CadPart,
    /// [`SCAN_RMS`] without a maximum: a noisy scan.
    NoisyScan,
}

impl ToleranceKind {
    /// The kind for a target with `stats` whose cage (with `edges` edges) carries `tags`: a
    /// noisy scan, a CAD part when at least [`CAD_CREASE_SHARE`] of the edges are infinitely
    /// sharp creases, a scan otherwise.
    pub fn of(stats: &TargetStats, tags: &Tags, edges: usize) -> Self {
        let sharp = tags
            .creases()
            .iter()
            .filter(|&&(_, s)| s >= SHARPNESS_INFINITE)
            .count();
        if stats.is_noisy() {
            Self::NoisyScan
        } else if sharp > 0 && sharp as f64 >= CAD_CREASE_SHARE * edges as f64 {
            Self::CadPart
        } else {
            Self::Scan
        }
    }

    /// What the defaults are, for a message: "tolerances for a scan: two-sided RMS 0.075 %,
    /// Hausdorff 0.70 % of the diagonal".
    pub fn describe(self) -> String {
        let (rms, max) = self.fractions();
        let what = match self {
            Self::Scan => "a scan",
            Self::CadPart => "a CAD part (sharp creases)",
            Self::NoisyScan => "a noisy scan",
        };
        let max = match self {
            Self::Scan => format!(
                ", Hausdorff {:.2} % (boundary vertices {:.2} %)",
                100.0 * max,
                100.0 * SCAN_BOUNDARY
            ),
            _ if max > 0.0 => format!(", Hausdorff {:.2} %", 100.0 * max),
            _ => String::new(),
        };
        format!(
            "tolerances for {what}: two-sided RMS {:.3} %{max} of the diagonal",
            100.0 * rms
        )
    }

    /// `(RMS, max)` as fractions of the diagonal; a max of 0 is none.
    pub fn fractions(self) -> (f64, f64) {
        match self {
            Self::Scan => (SCAN_RMS, SCAN_MAX),
            Self::CadPart => (CAD_RMS, CAD_MAX),
            Self::NoisyScan => (SCAN_RMS, 0.0),
        }
    }
}

/// `stages` with its tolerances set by `kind` for a target whose bounding-box diagonal is
/// `diagonal` (unit cube).
pub fn target_tolerances(
    stages: &StageOptions,
    kind: ToleranceKind,
    diagonal: f64,
) -> StageOptions {
    let (rms, max) = kind.fractions();
    StageOptions {
        tolerance_rms: rms * diagonal,
        tolerance_max: max * diagonal,
        tolerance_boundary: if kind == ToleranceKind::Scan {
            SCAN_BOUNDARY * diagonal
        } else {
            0.0
        },
        ..stages.clone()
    }
}

/// The share of the target's maximum tolerance the fitting stages aim at: they
/// judge the limit surface at the fitter's samples (level 3), and the tessellation the fit is
/// finally measured on (finer, by chordal error) finds peaks between them — on a torus with
/// holes, a surface → data maximum of 6.3e-3 at the last stage's samples, 7.1e-3 on the final
/// tessellation, against a tolerance of 7e-3.
pub const SAMPLING_MARGIN: f64 = 0.85;

/// `stages` with the maximum tolerance scaled by [`SAMPLING_MARGIN`] (what the stages of a fit
/// with the target's tolerances aim at; the fit is judged at the full one). The boundary
/// tolerance is left: a boundary vertex's distance to the stages' tessellation and to the
/// final one differ little (the rim is sampled densely by both), and [`SCAN_BOUNDARY`] already
/// has a margin to the 0.5 % a user asks.
pub fn with_sampling_margin(stages: &StageOptions) -> StageOptions {
    StageOptions {
        tolerance_max: SAMPLING_MARGIN * stages.tolerance_max,
        ..stages.clone()
    }
}

/// The number of edges of the polygon mesh `faces`.
pub(crate) fn edge_count(faces: &Polygons) -> usize {
    let mut edges: Vec<(u32, u32)> = faces
        .iter()
        .flat_map(|f| {
            (0..f.len()).map(move |i| {
                (
                    f[i].min(f[(i + 1) % f.len()]),
                    f[i].max(f[(i + 1) % f.len()]),
                )
            })
        })
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges.len()
}

/// Factor on a noisy scan's noise level in its RMS tolerance (`noise_floored`).
pub const NOISE_FLOOR_FACTOR: f64 = 1.25;

/// `stages` with the RMS tolerance raised to `√(tol² + (1.25 σ)²)` when the target is a noisy
/// point cloud ([`subfit_target::TargetStats::is_noisy`], σ its estimated noise level): the
/// data's own noise keeps the data → surface RMS of the true surface near σ, so a tolerance below
/// it can be met only by fitting the noise — refinement to the budget, a rougher surface, no
/// closer to the scanned object (Cheng et al. 2007 §V name noisy data as SDM's limit). 0.3 %
/// noise and 3 % outliers on 150k points of Igea: σ = 3.6e-3 and data → surface 3.85e-3 unit
/// cube at every stage from 578 to 5,000 control points, 77 s, while the distance to the clean
/// mesh stayed near 8e-4 of its diagonal. Returns the options and the raised tolerance (unit
/// cube), if it was raised.
pub(crate) fn noise_floored(
    stages: &StageOptions,
    stats: &TargetStats,
) -> (StageOptions, Option<f64>) {
    let mut options = stages.clone();
    if !stats.is_noisy() || stages.tolerance_rms <= 0.0 {
        return (options, None);
    }
    let sigma = NOISE_FLOOR_FACTOR * stats.noise_level;
    options.tolerance_rms = stages.tolerance_rms.hypot(sigma);
    options.noise_rms = sigma;
    let floor = options.tolerance_rms;
    (options, Some(floor))
}

/// The tolerances one fit works to and is judged by.
pub(crate) struct Tolerances {
    /// The default set chosen for the target, when the target's defaults are asked.
    pub(crate) kind: Option<ToleranceKind>,
    /// The tolerances before the noise floor (the report's options).
    pub(crate) judged: StageOptions,
    /// The tolerances the cage is judged by (noise floor applied).
    pub(crate) stages: StageOptions,
    /// The raised RMS tolerance of a noisy scan, if it was raised.
    pub(crate) noise_floor: Option<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_kind_follows_the_noise_and_the_sharp_creases() {
        let clean = TargetStats::default();
        let mut tags = Tags::new();
        assert_eq!(ToleranceKind::of(&clean, &tags, 10), ToleranceKind::Scan);
        tags.set_crease(0, 1, 2.0);
        tags.set_crease(3, 4, 2.0);
        assert_eq!(
            ToleranceKind::of(&clean, &tags, 10),
            ToleranceKind::Scan,
            "semi-sharp only"
        );
        tags.set_crease(1, 2, SHARPNESS_INFINITE);
        assert_eq!(
            ToleranceKind::of(&clean, &tags, 10),
            ToleranceKind::Scan,
            "1 of 10"
        );
        tags.set_crease(2, 3, SHARPNESS_INFINITE);
        assert_eq!(
            ToleranceKind::of(&clean, &tags, 10),
            ToleranceKind::CadPart,
            "2 of 10"
        );
        let st = target_tolerances(&StageOptions::default(), ToleranceKind::CadPart, 1.5);
        assert!((st.tolerance_rms - CAD_RMS * 1.5).abs() < 1e-15);
        assert!((st.tolerance_max - CAD_MAX * 1.5).abs() < 1e-15);
        assert_eq!(st.tolerance_boundary, 0.0);
        let st = target_tolerances(&StageOptions::default(), ToleranceKind::Scan, 1.5);
        assert!((st.tolerance_boundary - SCAN_BOUNDARY * 1.5).abs() < 1e-15);
        let st = target_tolerances(&StageOptions::default(), ToleranceKind::NoisyScan, 1.5);
        assert_eq!(st.tolerance_max, 0.0);
    }
}
