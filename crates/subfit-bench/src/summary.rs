//! Per-category figures of a scoreboard, and its regressions against a baseline.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::row::Row;

/// The figures of one category.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CategorySummary {
    /// The category.
    pub category: String,
    /// Rows.
    pub rows: usize,
    /// Rows that meet the category's bar.
    pub passed: usize,
    /// `passed / rows`.
    pub share_passed: f64,
    /// Rows by how the run ended (`0`, `1`, `2`, `timeout`, `crash`; `read` / `refused` for
    /// read checks).
    pub exits: BTreeMap<String, usize>,
    /// Median of the judged two-sided RMS / diagonal.
    pub median_rms_fraction: Option<f64>,
    /// Worst judged two-sided RMS / diagonal.
    pub worst_rms_fraction: Option<f64>,
    /// Median judged Hausdorff / diagonal.
    pub median_hausdorff_fraction: Option<f64>,
    /// Worst judged Hausdorff / diagonal.
    pub worst_hausdorff_fraction: Option<f64>,
    /// Median seconds of the runs.
    pub median_seconds: Option<f64>,
    /// Median control points.
    pub median_control_points: Option<f64>,
    /// Rows whose judge and report disagree by more than [`crate::row::DISAGREEMENT_FLAG`].
    pub disagreements: usize,
    /// Median RMS / diagonal of the best peer of each row that has one.
    pub peer_median_rms_fraction: Option<f64>,
    /// Median Hausdorff / diagonal of those best peers.
    pub peer_median_hausdorff_fraction: Option<f64>,
    /// Rows with a judged peer.
    pub rows_with_peers: usize,
    /// Rows where ours is closer than the best peer on both RMS and Hausdorff.
    pub better_than_peers: usize,
}

/// The median of `v` (`None` when empty).
pub fn median(mut v: Vec<f64>) -> Option<f64> {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

fn worst(v: &[f64]) -> Option<f64> {
    v.iter().copied().filter(|x| x.is_finite()).reduce(f64::max)
}

/// The summary of every category present in `rows`, in name order.
pub fn summarize(rows: &[Row]) -> Vec<CategorySummary> {
    let mut by: BTreeMap<&str, Vec<&Row>> = BTreeMap::new();
    for r in rows {
        by.entry(&r.category).or_default().push(r);
    }
    by.into_iter()
        .map(|(category, rows)| summarize_category(category, &rows))
        .collect()
}

fn summarize_category(category: &str, rows: &[&Row]) -> CategorySummary {
    let judged: Vec<_> = rows.iter().filter_map(|r| r.judge.as_ref()).collect();
    let rms: Vec<f64> = judged.iter().map(|j| j.rms_fraction).collect();
    let haus: Vec<f64> = judged.iter().map(|j| j.hausdorff_fraction).collect();
    let mut exits = BTreeMap::new();
    for r in rows {
        let label = match (&r.run, &r.read) {
            (Some(run), _) => run.exit.label(),
            (None, Some(read)) if read.read => "read".into(),
            (None, Some(read)) if read.cut_short => "refused: cut short".into(),
            (None, Some(_)) => "refused".into(),
            (None, None) => "not run".into(),
        };
        *exits.entry(label).or_insert(0) += 1;
    }
    let peers: Vec<(&Row, &crate::row::Judged)> = rows
        .iter()
        .filter_map(|r| r.best_peer().map(|p| (*r, p)))
        .collect();
    let peer_j: Vec<_> = peers.iter().filter_map(|(_, p)| p.judge.as_ref()).collect();
    let better = peers
        .iter()
        .filter(|(r, p)| match (r.judge.as_ref(), p.judge.as_ref()) {
            (Some(o), Some(q)) => {
                o.rms_fraction < q.rms_fraction && o.hausdorff_fraction < q.hausdorff_fraction
            }
            _ => false,
        })
        .count();
    let passed = rows.iter().filter(|r| r.pass == Some(true)).count();
    CategorySummary {
        category: category.into(),
        rows: rows.len(),
        passed,
        share_passed: passed as f64 / rows.len().max(1) as f64,
        exits,
        median_rms_fraction: median(rms.clone()),
        worst_rms_fraction: worst(&rms),
        median_hausdorff_fraction: median(haus.clone()),
        worst_hausdorff_fraction: worst(&haus),
        median_seconds: median(
            rows.iter()
                .filter_map(|r| r.run.as_ref().map(|x| x.seconds))
                .collect(),
        ),
        median_control_points: median(
            rows.iter()
                .filter_map(|r| r.cage.as_ref().map(|c| c.control_points as f64))
                .collect(),
        ),
        disagreements: rows
            .iter()
            .filter(|r| {
                r.disagreement
                    .is_some_and(|d| d > crate::row::DISAGREEMENT_FLAG)
            })
            .count(),
        peer_median_rms_fraction: median(peer_j.iter().map(|j| j.rms_fraction).collect()),
        peer_median_hausdorff_fraction: median(
            peer_j.iter().map(|j| j.hausdorff_fraction).collect(),
        ),
        rows_with_peers: peers.len(),
        better_than_peers: better,
    }
}

/// A row that got worse than the baseline's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Regression {
    /// The entry.
    pub entry: String,
    /// What got worse: `rms`, `hausdorff`, `exit`, `pass` (errors) or `seconds` (time).
    pub what: String,
    /// The baseline's figure (exit: its code; pass: 1).
    pub baseline: f64,
    /// This run's.
    pub now: f64,
    /// An error regression (fails `--fail-on-regression`); time regressions only inform.
    pub error: bool,
}

/// An error figure counts as worse past this factor of the baseline's.
pub const ERROR_REGRESSION: f64 = 1.10;
/// A time counts as slower past this factor of the baseline's …
pub const TIME_REGRESSION: f64 = 1.25;
/// … and by at least this many seconds (shorter differences are the noise of a shared
/// machine, not of the fit).
pub const TIME_NOISE_SECONDS: f64 = 1.0;
/// Errors below this fraction of the diagonal are equal (far below any tolerance we judge by;
/// the noise of sampling at that level is not a regression).
pub const ERROR_FLOOR: f64 = 1e-5;

/// The worst judged (RMS, Hausdorff) of a row over the frames it shares with `other` (a
/// sequence cut to fewer frames in a quick run compares on those), else its own judge.
fn errors_on_common_frames(row: &Row, other: &Row) -> Option<(f64, f64)> {
    if row.frames.is_empty() || other.frames.is_empty() {
        return row
            .judge
            .as_ref()
            .map(|j| (j.rms_fraction, j.hausdorff_fraction));
    }
    let n = row.frames.len().min(other.frames.len());
    row.frames[..n]
        .iter()
        .filter_map(|f| f.judge.as_ref())
        .map(|j| (j.rms_fraction, j.hausdorff_fraction))
        .reduce(|a, b| (a.0.max(b.0), a.1.max(b.1)))
}

fn exit_rank(r: &Row) -> Option<i32> {
    r.run.as_ref().map(|run| match run.exit {
        crate::child::Exit::Code(c) if (0..=2).contains(&c) => c,
        _ => 3,
    })
}

/// The regressions of `rows` against `baseline` (entries in both).
pub fn regressions(rows: &[Row], baseline: &[Row]) -> Vec<Regression> {
    let base: BTreeMap<&str, &Row> = baseline.iter().map(|r| (r.entry.as_str(), r)).collect();
    let mut out = Vec::new();
    for r in rows {
        let Some(b) = base.get(r.entry.as_str()) else {
            continue;
        };
        let mut push = |what: &str, baseline: f64, now: f64, error: bool| {
            out.push(Regression {
                entry: r.entry.clone(),
                what: what.into(),
                baseline,
                now,
                error,
            })
        };
        if let (Some(now), Some(was)) = (exit_rank(r), exit_rank(b)) {
            if now > was {
                push("exit", was as f64, now as f64, true);
            }
        }
        if b.pass == Some(true) && r.pass == Some(false) {
            push("pass", 1.0, 0.0, true);
        }
        if let (Some(now), Some(was)) =
            (errors_on_common_frames(r, b), errors_on_common_frames(b, r))
        {
            let worse = |n: f64, w: f64| n > w.max(ERROR_FLOOR) * ERROR_REGRESSION;
            if worse(now.0, was.0) {
                push("rms", was.0, now.0, true);
            }
            if worse(now.1, was.1) {
                push("hausdorff", was.1, now.1, true);
            }
        }
        if let (Some(now), Some(was)) = (&r.run, &b.run) {
            if now.seconds > was.seconds * TIME_REGRESSION
                && now.seconds - was.seconds > TIME_NOISE_SECONDS
                && r.frames.len() >= b.frames.len()
            {
                push("seconds", was.seconds, now.seconds, false);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::child::{Exit, Run};
    use crate::judge::Judgement;

    fn row(entry: &str, rms: f64, haus: f64, seconds: f64, exit: i32) -> Row {
        let mut r = Row::new(entry, "scan", "mesh", String::new());
        r.run = Some(Run {
            exit: Exit::Code(exit),
            seconds,
            peak_memory_mb: None,
            stderr_tail: String::new(),
        });
        r.judge = Some(Judgement {
            rms_fraction: rms,
            hausdorff_fraction: haus,
            ..Judgement::default()
        });
        r
    }

    #[test]
    fn medians() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(vec![]), None);
    }

    #[test]
    fn errors_ten_percent_worse_and_slower_runs_are_flagged() {
        let base = [row("a", 1e-3, 1e-2, 10.0, 0), row("b", 1e-3, 1e-2, 10.0, 0)];
        let now = [
            row("a", 1.05e-3, 1.2e-2, 13.0, 1),
            row("b", 1e-3, 1e-2, 10.5, 0),
        ];
        let r = regressions(&now, &base);
        let what: Vec<(&str, &str, bool)> = r
            .iter()
            .map(|x| (x.entry.as_str(), x.what.as_str(), x.error))
            .collect();
        assert_eq!(
            what,
            [
                ("a", "exit", true),
                ("a", "hausdorff", true),
                ("a", "seconds", false)
            ]
        );
    }

    #[test]
    fn categories_count_passes_and_exits() {
        let mut a = row("a", 1e-3, 1e-2, 1.0, 0);
        a.pass = Some(true);
        let b = row("b", 3e-3, 3e-2, 3.0, 1);
        let s = summarize(&[a, b]);
        assert_eq!(s.len(), 1);
        assert_eq!((s[0].rows, s[0].passed), (2, 1));
        assert_eq!(s[0].exits.get("1"), Some(&1));
        assert_eq!(s[0].median_seconds, Some(2.0));
        assert_eq!(s[0].worst_rms_fraction, Some(3e-3));
    }
}
