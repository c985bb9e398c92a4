//! The options of the stage driver ([`crate::fit_stages`]; Cheng et al. 2007 §II-B step 8,
//! §II-E, Table IV; Cheng et al. 2004 §4.4–4.6; DESIGN.md §3.5): the `λ` schedule,
//! tolerances, budgets and refinement switches, how a measured cage is judged against them,
//! and the score of a face for refinement. The driver and its phases (flips, refinement,
//! enrichment, polish) all read them, so they live here, below all of them.

use subfit_measure::TwoSided;

use crate::error::FitError;
use crate::error_field::FIELD_THRESHOLD;
use crate::remesh::FaceError;
use crate::report::ErrorStats;

/// Options of the stage driver; the per-iteration options (method, step control, sample
/// level, scheme) come from a [`crate::FitOptions`].
#[derive(Clone, Debug, PartialEq)]
pub struct StageOptions {
    /// `λ` of the first stage (the papers: 1e-3).
    pub lambda_start: f64,
    /// Smallest `λ` (the papers: 1e-4 to 1e-5).
    pub lambda_end: f64,
    /// Factor applied to `λ` after each stage, in (0, 1].
    pub lambda_factor: f64,
    /// Iterations of one stage at most.
    pub iterations_per_stage: usize,
    /// A stage ends when an accepted iteration lowers the objective by less than this
    /// fraction.
    pub stall: f64,
    /// Stop when `E_rms ≤` this (normalized units; 0 = not used).
    pub tolerance_rms: f64,
    /// Stop when `E_max ≤` this (normalized units; 0 = not used). With both tolerances set,
    /// both must hold.
    pub tolerance_max: f64,
    /// The largest distance (normalized units) of a mesh target's boundary vertices to the
    /// limit surface, judged with [`Self::tolerance_max`] (0 = none; needs a max tolerance):
    /// an open surface's rim is judged tighter than the rest (every boundary vertex
    /// within 0.5 % of the diagonal). Default 0.
    pub tolerance_boundary: f64,
    /// The part of the data → surface RMS that is the data's own noise (normalized units;
    /// a noisy scan's noise floor): a refinement sizes its growth by the RMS above it,
    /// `√(rms² − noise²)` against `√(tol² − noise²)`. Default 0.
    pub noise_rms: f64,
    /// Never refine beyond this many control points.
    pub max_control_points: usize,
    /// Stages at most.
    pub max_stages: usize,
    /// Iterations over all stages at most.
    pub max_iterations: usize,
    /// Local 1-to-4 refinement of high-error faces between stages.
    pub refine: bool,
    /// At most this fraction of the current control points is added by one refinement.
    pub growth: f64,
    /// Edge flips in high-error regions, kept only where they lower the error.
    pub edge_flips: bool,
    /// A face that descends from this many splits of an initial face is not split again:
    /// where refinement does not lower the error (a foot point on the wrong side of a thin
    /// part, a sharp crease), it would otherwise only pile up control points. Default 5: at
    /// 4 the camel head's quad/tri fit stalled at 551 control points with a data → surface
    /// maximum of 0.85 % of the diagonal in a fold whose faces were 4 splits deep (tolerance
    /// 0.7 %); at 5 it reaches it at 663. On 22 other fits (Loop and quad/tri; open, closed,
    /// noisy, range scans) the depth changed nothing or little (holed armadillo quad/tri 1,672
    /// → 1,650 points; camel head Loop 459 → 493).
    pub max_depth: u8,
    /// After a stage changed the mesh (refinement, flips), optimize only the control points
    /// near the change in the next stage — the new points, the points of every face touching
    /// one or changed by a flip, and `local_rings` rings of faces around them — holding the
    /// rest, which already fit, fixed (Cheng 2004 §4.6). Such a stage samples, projects and
    /// solves only that region ([`crate::Fitter::set_active`]); its reported errors are still over
    /// the whole surface. A stage whose `λ` changed with nothing else, or whose region would
    /// hold more than half of the points, is global.
    pub local: bool,
    /// Rings of faces added around the changed region by [`Self::local`].
    pub local_rings: usize,
    /// Judge the tolerances both ways: surface → data and data → surface (default true).
    /// False keeps Cheng et al.'s one-sided measure (surface → data) for stopping; both are
    /// measured and reported either way.
    pub two_sided: bool,
    /// Data → surface samples of a mesh target, uniform by area (0 = as many as it has
    /// points, at least [`subfit_measure::data_samples::MIN_AREA_SAMPLES`]; a point cloud
    /// always uses its points). Default 0.
    pub data_samples: usize,
    /// The error power of the last step, a polish of the best cage towards a lower maximum
    /// error ([`crate::polish`]; [`crate::FitOptions::error_power`]); kept only when it lowers the
    /// maximum without costing RMS. Default 3; 2 or less turns it off. Valid: `≤ 8`.
    pub polish_power: f64,
    /// The rate below which a refinement does not pay: [`crate::UNPAID_REFINEMENTS`] refinements in a
    /// row that lower the judged RMS by less than `n^−refine_payoff` in the control points `n`,
    /// while it misses its tolerance, end the stages ([`crate::StageStop::Diminishing`]). Default
    /// [`REFINE_PAYOFF`]; 0 turns the rule off.
    pub refine_payoff: f64,
    /// The fit is of use only if it meets its tolerances within
    /// [`Self::max_control_points`] (a later start that can win only so): once `λ` is at
    /// its end, a stage from which even the best rate of approximation
    /// ([`Self::points_to_reach`]) needs more control points than the budget ends the
    /// stages ([`crate::StageStop::Hopeless`]). Default off.
    pub must_reach: bool,
    /// Local enrichment ([`crate::enrich`], Lavoué et al. 2005 §5.2): an error field of which
    /// fewer than [`Self::local_field_share`] of the error points are at least this fraction
    /// of its maximum is local. Default [`LOCAL_FIELD_PEAK`] (0.8).
    pub local_field_peak: f64,
    /// The share below which an error field is local: its faces are merged into one with one
    /// new control point, where a diffuse field has every face split. Default
    /// [`LOCAL_FIELD_SHARE`] (0.5); 0 turns local enrichment off.
    pub local_field_share: f64,
}

impl Default for StageOptions {
    fn default() -> Self {
        Self {
            lambda_start: 1e-3,
            lambda_end: 1e-5,
            lambda_factor: 0.1,
            iterations_per_stage: 6,
            stall: 0.02,
            tolerance_rms: 5e-4,
            tolerance_max: 0.0,
            tolerance_boundary: 0.0,
            noise_rms: 0.0,
            max_control_points: 5_000,
            max_stages: 16,
            max_iterations: 100,
            refine: true,
            growth: 0.6,
            edge_flips: true,
            max_depth: 5,
            local: false,
            local_rings: 2,
            two_sided: true,
            data_samples: 0,
            polish_power: 3.0,
            refine_payoff: REFINE_PAYOFF,
            must_reach: false,
            local_field_peak: LOCAL_FIELD_PEAK,
            local_field_share: LOCAL_FIELD_SHARE,
        }
    }
}

impl StageOptions {
    pub(crate) fn validate(&self) -> Result<(), FitError> {
        let bad = |name: &'static str, value: f64| Err(FitError::BadOption { name, value });
        if !(self.lambda_start >= 0.0 && self.lambda_start.is_finite()) {
            return bad("lambda_start", self.lambda_start);
        }
        if !(self.lambda_end >= 0.0 && self.lambda_end <= self.lambda_start) {
            return bad("lambda_end", self.lambda_end);
        }
        if !(self.lambda_factor > 0.0 && self.lambda_factor <= 1.0) {
            return bad("lambda_factor", self.lambda_factor);
        }
        if !(self.stall >= 0.0 && self.stall < 1.0) {
            return bad("stall", self.stall);
        }
        if !(self.tolerance_rms >= 0.0 && self.tolerance_rms.is_finite()) {
            return bad("tolerance_rms", self.tolerance_rms);
        }
        if !(self.tolerance_max >= 0.0 && self.tolerance_max.is_finite()) {
            return bad("tolerance_max", self.tolerance_max);
        }
        if !(self.tolerance_boundary >= 0.0 && self.tolerance_boundary.is_finite()) {
            return bad("tolerance_boundary", self.tolerance_boundary);
        }
        if !(self.noise_rms >= 0.0 && self.noise_rms.is_finite()) {
            return bad("noise_rms", self.noise_rms);
        }
        if self.polish_power.is_nan() || self.polish_power > 8.0 {
            return bad("polish_power", self.polish_power);
        }
        if !(self.refine_payoff >= 0.0 && self.refine_payoff.is_finite()) {
            return bad("refine_payoff", self.refine_payoff);
        }
        if !(self.growth > 0.0 && self.growth.is_finite()) {
            return bad("growth", self.growth);
        }
        if !(self.local_field_peak > FIELD_THRESHOLD && self.local_field_peak <= 1.0) {
            return bad("local_field_peak", self.local_field_peak);
        }
        if !(0.0..=1.0).contains(&self.local_field_share) {
            return bad("local_field_share", self.local_field_share);
        }
        for (name, v) in [
            ("iterations_per_stage", self.iterations_per_stage),
            ("max_stages", self.max_stages),
            ("max_iterations", self.max_iterations),
        ] {
            if v == 0 {
                return bad(name, 0.0);
            }
        }
        Ok(())
    }

    /// Whether `e` (surface → data) meets every tolerance that is set (false when none is
    /// set): Cheng et al.'s one-sided test.
    pub fn reached(&self, e: &ErrorStats) -> bool {
        let any = self.tolerance_rms > 0.0 || self.tolerance_max > 0.0;
        any && (self.tolerance_rms <= 0.0 || e.e_rms <= self.tolerance_rms)
            && (self.tolerance_max <= 0.0 || e.e_max <= self.tolerance_max)
    }

    /// Whether a cage measured `e` (surface → data, as the fitter measures it: a mean over its
    /// samples) and `two` (both ways, surface → data weighted by area) meets the tolerances:
    /// `two` when [`Self::two_sided`], else `e` (Cheng's one-sided test).
    pub fn met(&self, e: &ErrorStats, two: &TwoSided) -> bool {
        if self.two_sided {
            two.within(self.tolerance_rms, self.tolerance_max)
        } else {
            self.reached(e)
        }
    }

    /// The judged RMS and maximum: the worse direction of `two` when two-sided, else `e`.
    pub(crate) fn judged(&self, e: &ErrorStats, two: &TwoSided) -> (f64, f64) {
        if self.two_sided {
            (two.rms(), two.max())
        } else {
            (e.e_rms, e.e_max)
        }
    }

    /// Which tolerances (RMS, max) the cage still misses.
    pub(crate) fn unmet(&self, e: &ErrorStats, two: &TwoSided) -> (bool, bool) {
        let (rms, max) = self.judged(e, two);
        (
            self.tolerance_rms > 0.0 && rms > self.tolerance_rms,
            self.tolerance_max > 0.0 && max > self.tolerance_max,
        )
    }

    /// How far a cage is from its tolerances; lower is better. With one tolerance set, the
    /// ratio of judged error to it (the judged RMS when none is). With both: the larger ratio
    /// while both are met, else the geometric mean of the two ratios, each floored at 1, so that
    /// progress on either miss counts. With the larger ratio alone, a maximum that no cage of
    /// the topology reaches (the rim of a single-view range scan) made every stage equal but
    /// for it: the best cage and the stall rule ignored the RMS, and a simulated scan of the
    /// bunny ended at its initial 271 control points with a two-sided RMS of 1.3e-3 of the
    /// diagonal where refinement reached 9.8e-4 two stages later.
    /// The control points a cage of `n` with errors `e`, `two` would need to meet the
    /// tolerances set at the best rate a subdivision surface approximates a smooth shape: the
    /// error falls as `h⁴` in the spacing `h ∝ n^−½` (Loop and Catmull-Clark surfaces are
    /// cubic box splines away from extraordinary vertices, whose approximation order is 4),
    /// so `n · ratio^½` for the larger ratio of error over tolerance. Creases, noise and detail only slow it down, so fewer points
    /// than this never suffice. `n` when the tolerances are met or none is set.
    pub fn points_to_reach(&self, e: &ErrorStats, two: &TwoSided, n: usize) -> f64 {
        let (rms, max) = self.judged(e, two);
        let ratio = |x: f64, t: f64| if t > 0.0 { x / t } else { 0.0 };
        let r = ratio(rms, self.tolerance_rms).max(ratio(max, self.tolerance_max));
        n as f64 * r.max(1.0).sqrt()
    }

    pub(crate) fn badness(&self, e: &ErrorStats, two: &TwoSided) -> f64 {
        let (rms, max) = self.judged(e, two);
        let r = (self.tolerance_rms > 0.0).then(|| rms / self.tolerance_rms);
        let m = (self.tolerance_max > 0.0).then(|| max / self.tolerance_max);
        match (r, m) {
            (Some(r), Some(m)) if r > 1.0 || m > 1.0 => (r.max(1.0) * m.max(1.0)).sqrt(),
            (Some(r), Some(m)) => r.max(m),
            (Some(r), None) => r,
            (None, Some(m)) => m,
            (None, None) => rms,
        }
    }
}

/// The default [`StageOptions::refine_payoff`]: a refinement pays when the judged RMS falls at
/// least as `n^−REFINE_PAYOFF` in the control points `n` (1.5 times the points for 6 % less).
/// A smooth surface's error falls as `n^−1`
/// and local refinement does better: over 22 fits of the shared models with defaults no two
/// refinements in a row were slower than `n^−0.2` while their RMS missed (the camel head's
/// slowest, 0.32 then 0.20). Fitting noise is slower: the Igea cut with Gaussian vertex noise of
/// 1e-3 of its diagonal went 1,155 → 4,804 control points at rates 0.19, 0.13, 0.08, … 0.06
/// for an RMS of 8.9e-4 → 7.6e-4 of the diagonal (tolerance 7.5e-4).
pub const REFINE_PAYOFF: f64 = 0.15;

/// The default [`StageOptions::local_field_peak`] (local enrichment, Lavoué et al. 2005 §5.2):
/// Lavoué et al.'s "close to `d_max`", the error points at or above this fraction of the
/// field's maximum count towards its peak share.
pub const LOCAL_FIELD_PEAK: f64 = 0.8;
/// The default [`StageOptions::local_field_share`] (local enrichment, Lavoué et al. 2005 §5.2):
/// Lavoué et al.'s threshold on the share of a field's error points close to its maximum:
/// below it the field is local (one control point), else diffuse.
pub const LOCAL_FIELD_SHARE: f64 = 0.5;

/// How far above the tolerance a face is (`> 1`: too large), counting only the tolerances the
/// whole surface does not meet yet (`unmet`: RMS, max): once `E_rms` is within its tolerance,
/// a face whose own RMS is above it needs no refinement for it (the budget goes where `E_max`
/// is still missed).
pub(crate) fn face_score(e: &FaceError, stages: &StageOptions, unmet: (bool, bool)) -> f64 {
    let mut s: f64 = 0.0;
    if unmet.0 {
        s = s.max(e.rms() / stages.tolerance_rms);
    }
    if unmet.1 {
        s = s.max(e.max / stages.tolerance_max);
    }
    s
}
