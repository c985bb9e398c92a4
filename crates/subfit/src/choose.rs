//! Choosing between fits of different starts by a typed [`Measurement`] (DESIGN.md §2
//! "Starts → fit → choose", STYLE.md rule 12): a fit that meets the tolerances beats one that
//! does not; between variants of one start (the budget fractions of a capped quad scheme,
//! [`crate::starts::BUDGET_STARTS`]) the closer cage wins ([`Measurement::closer_than`]);
//! between different starts (QEM against the curvature lines) the more compact of two that
//! meet the tolerances wins ([`Measurement::better_start_than`]). The report's strings are
//! written after the choice and never read back.

/// What a fit is chosen by, measured both ways on its final cage (normalized units).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measurement {
    /// Whether the cage meets the tolerances it is judged by.
    pub reached: bool,
    /// Its control points.
    pub control_points: usize,
    /// Two-sided RMS distance (the larger direction's), unit cube.
    pub rms: f64,
    /// Two-sided maximum (Hausdorff) distance, unit cube.
    pub max: f64,
}

impl Measurement {
    /// Whether this cage is closer than `other`'s: one that meets the tolerances beats one
    /// that does not; otherwise the one whose two-sided RMS and Hausdorff distance are, at
    /// worst, nearer the better of the two figures (a cage best in both wins; a trade goes to
    /// the smaller loss). A tie is not closer.
    pub fn closer_than(&self, other: &Self) -> bool {
        if self.reached != other.reached {
            return self.reached;
        }
        let rms = self.rms.min(other.rms).max(f64::MIN_POSITIVE);
        let max = self.max.min(other.max).max(f64::MIN_POSITIVE);
        let score = |e: &Self| (e.rms / rms).max(e.max / max);
        score(self) < score(other)
    }

    /// Whether this cage is about as close as `other`'s: both or neither meet the tolerances
    /// and its worse figure, relative to the better of the two cages' (as in
    /// [`Self::closer_than`]), is at most `1 + slack` times `other`'s.
    pub fn about_as_close_as(&self, other: &Self, slack: f64) -> bool {
        if self.reached != other.reached {
            return self.reached;
        }
        let rms = self.rms.min(other.rms).max(f64::MIN_POSITIVE);
        let max = self.max.min(other.max).max(f64::MIN_POSITIVE);
        let score = |e: &Self| (e.rms / rms).max(e.max / max);
        score(self) <= (1.0 + slack) * score(other)
    }

    /// Whether this fit is better than `other`'s as a start of another kind: of two that meet
    /// the tolerances, the one with fewer control points (the point of a compact cage; equal
    /// counts go to [`Self::closer_than`]); otherwise [`Self::closer_than`].
    pub fn better_start_than(&self, other: &Self) -> bool {
        if self.reached && other.reached && self.control_points != other.control_points {
            return self.control_points < other.control_points;
        }
        self.closer_than(other)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(reached: bool, rms: f64, max: f64) -> Measurement {
        Measurement {
            reached,
            control_points: 100,
            rms,
            max,
        }
    }

    #[test]
    fn a_cage_within_the_tolerances_wins_then_the_smaller_loss() {
        // Meeting the tolerances decides first, whatever the figures.
        assert!(m(true, 2.0, 2.0).closer_than(&m(false, 1.0, 1.0)));
        assert!(!m(false, 1.0, 1.0).closer_than(&m(true, 2.0, 2.0)));
        // Best in both.
        assert!(m(false, 1.0, 1.0).closer_than(&m(false, 1.1, 1.2)));
        // A trade: 4 % more RMS for 14 % less Hausdorff wins, and the reverse loses.
        assert!(m(true, 4.16, 1.63).closer_than(&m(true, 4.01, 1.85)));
        assert!(!m(true, 4.01, 1.85).closer_than(&m(true, 4.16, 1.63)));
        // A tie keeps the first.
        assert!(!m(true, 1.0, 1.0).closer_than(&m(true, 1.0, 1.0)));
    }

    #[test]
    fn of_two_starts_within_the_tolerances_the_smaller_cage_wins() {
        let small = Measurement {
            control_points: 60,
            ..m(true, 2.0, 2.0)
        };
        let large = m(true, 1.0, 1.0);
        assert!(small.better_start_than(&large));
        assert!(!large.better_start_than(&small));
        // Outside the tolerances the count does not matter.
        let small_out = Measurement {
            reached: false,
            ..small
        };
        assert!(!small_out.better_start_than(&m(false, 1.0, 1.0)));
        // Equal counts: the closer one.
        assert!(m(true, 1.0, 1.0).better_start_than(&m(true, 1.0, 1.2)));
    }

    #[test]
    fn about_as_close_allows_the_slack_and_no_more() {
        // 18 % more Hausdorff against 14 % more RMS: within 10 % of each other's score.
        let field = m(true, 0.0175, 0.158);
        let paired = m(true, 0.0200, 0.134);
        assert!(!field.closer_than(&paired));
        assert!(field.about_as_close_as(&paired, 0.1));
        assert!(!field.about_as_close_as(&paired, 0.01));
        // Twice as far is not about as close; meeting the tolerances still decides first.
        assert!(!m(true, 2.0, 2.0).about_as_close_as(&m(true, 1.0, 1.0), 0.1));
        assert!(!m(false, 1.0, 1.0).about_as_close_as(&m(true, 2.0, 2.0), 0.1));
    }
}
