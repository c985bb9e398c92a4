//! The real-data scoreboard: `subfit bench corpus` runs the fit on a corpus of real models as
//! a user runs it (the `subfit` executable, defaults) and measures every result with an
//! independent judge ([`mod@judge`]), a code path of its own (parry's closest points on triangles,
//! the limit surface evaluated exactly and sampled by area) that shares nothing with the fit's
//! foot points or the report's distances, so that it can catch their mistakes.
//!
//! One [`Row`] per entry of the corpus ([`manifest`]): exit, time, peak memory, the cage's
//! counts, the judge's two-sided RMS and Hausdorff distance next to the fit's own, genus and
//! boundary loops kept, whether the category's bar is met ([`row::criteria`]), and the peers a
//! user would run instead at the same size ([`peers`]). [`summary`] gives the per-category
//! figures and the regressions against a committed baseline; [`markdown`] the tables.

pub mod cage_stats;
pub mod child;
pub mod drift;
pub mod inputs;
pub mod judge;
pub mod manifest;
pub mod markdown;
pub mod peers;
pub mod row;
pub mod score;
mod sequence;
pub mod summary;

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use serde::{Deserialize, Serialize};

pub use judge::{judge, Candidate, Direction, JudgeError, JudgeOptions, Judgement, Reference};
pub use manifest::{Entry, Job};
pub use row::Row;
pub use summary::{CategorySummary, Regression};

/// How a corpus is scored.
#[derive(Clone, Debug)]
pub struct Settings {
    /// How `subfit` is run.
    pub runner: child::Runner,
    /// Where each entry's runs and outputs go (`WORK/<entry>/`).
    pub work: PathBuf,
    /// How the judge samples.
    pub judge: judge::JudgeOptions,
    /// Entries scored at once.
    pub jobs: usize,
    /// Flags added to every `subfit fit` (e.g. `--no-facing`), to score an option before it
    /// becomes a default; empty: the defaults.
    pub fit_args: Vec<String>,
}

/// A scored corpus: what `--out` writes as JSON and what a baseline is.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Scoreboard {
    /// The corpus folder.
    pub corpus: String,
    /// Whether only the quick subset ran.
    pub quick: bool,
    /// Entries scored at once.
    pub jobs: usize,
    /// Threads of each run.
    pub threads_per_run: Option<usize>,
    /// Cores of the machine.
    pub cores: usize,
    /// Wall time of the whole run, seconds.
    pub seconds: f64,
    /// The judge's samples of each limit surface.
    pub judge_surface_samples: usize,
    /// Flags added to every `subfit fit` ([`Settings::fit_args`]); empty: the defaults.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fit_args: Vec<String>,
    /// One row per entry, in corpus order.
    pub rows: Vec<Row>,
    /// Per category.
    pub categories: Vec<CategorySummary>,
    /// Against the baseline, when one was given.
    #[serde(default)]
    pub regressions: Vec<Regression>,
    /// Where the rows came from when they were taken from earlier scoreboards rather than
    /// fitted in this run: one line per source (its file and the rows it gave).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sources: Vec<String>,
}

impl Scoreboard {
    /// Reads a scoreboard (a baseline) from JSON. Errors: unreadable or not a scoreboard.
    pub fn read(path: &Path) -> Result<Self, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        serde_json::from_str(&text)
            .map_err(|e| format!("{}: not a scoreboard: {e}", path.display()))
    }

    /// Sets the per-category figures from the rows, and the regressions against `baseline`.
    pub fn finish(&mut self, baseline: Option<&Scoreboard>) {
        self.categories = summary::summarize(&self.rows);
        self.regressions =
            baseline.map_or_else(Vec::new, |b| summary::regressions(&self.rows, &b.rows));
    }

    /// Whether an error (not a time) got worse than the baseline.
    pub fn has_error_regression(&self) -> bool {
        self.regressions.iter().any(|r| r.error)
    }
}

/// Scores `entries` with `settings.jobs` at once; `done(row, finished, total)` is called as each
/// row is ready (from the worker threads, one at a time). Rows come back in entry order.
pub fn score_all(
    entries: &[Entry],
    settings: &Settings,
    done: &(dyn Fn(&Row, usize, usize) + Sync),
) -> Vec<Row> {
    let next = AtomicUsize::new(0);
    let finished = AtomicUsize::new(0);
    let rows: Mutex<Vec<Option<Row>>> = Mutex::new(vec![None; entries.len()]);
    let report = Mutex::new(());
    std::thread::scope(|s| {
        for _ in 0..settings.jobs.max(1) {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(entry) = entries.get(i) else {
                    break;
                };
                let row = score::score(entry, settings);
                let n = finished.fetch_add(1, Ordering::SeqCst) + 1;
                {
                    let _one_at_a_time = report.lock().unwrap_or_else(|e| e.into_inner());
                    done(&row, n, entries.len());
                }
                rows.lock().unwrap_or_else(|e| e.into_inner())[i] = Some(row);
            });
        }
    });
    rows.into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .into_iter()
        .flatten()
        .collect()
}
