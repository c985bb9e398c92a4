//! One row of the scoreboard per corpus entry, and what a category must reach.

use serde::{Deserialize, Serialize};

use crate::cage_stats::{CageStats, Topology};
use crate::child::{Exit, Run};
use crate::judge::Judgement;

/// The figures `report.json` gives for its own fit (its measurer), next to the judge's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ReportFigures {
    /// Two-sided RMS / diagonal.
    pub rms_fraction: f64,
    /// Two-sided maximum / diagonal.
    pub hausdorff_fraction: f64,
    /// Whether the fit said it reached its tolerance.
    pub tolerance_reached: bool,
}

/// A cage judged the same way as ours: the given cage of a pair, or a peer's result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Judged {
    /// Who made it (`given`, `poisson-qem`, `instant-meshes`, `quadriflow`).
    pub by: String,
    /// Its counts (for a peer's plain mesh: its vertices and faces).
    pub stats: CageStats,
    /// The judge's figures; `None` when it could not be judged (see `error`).
    pub judge: Option<Judgement>,
    /// Wall time to make it (peers), seconds.
    pub seconds: Option<f64>,
    /// What went wrong.
    pub error: Option<String>,
}

/// One frame of a sequence entry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameRow {
    /// Frame index (0 the first).
    pub index: usize,
    /// The judge's figures for this frame's cage against the frame.
    pub judge: Option<Judgement>,
    /// The sequence report's own two-sided figures for the frame.
    pub report: Option<ReportFigures>,
    /// Drift of the limit points tracked from frame 0, when the frames share their
    /// connectivity (every data vertex a known material point): see [`crate::drift`].
    pub drift: Option<crate::drift::Drift>,
}

/// A read check (the `refused` category): what reading the file gave.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReadCheck {
    /// Whether it read.
    pub read: bool,
    /// Vertices (points) read.
    pub vertices: Option<usize>,
    /// Faces read.
    pub faces: Option<usize>,
    /// Whether the counts are the manifest's.
    pub counts_match: Option<bool>,
    /// The error, when refused.
    pub message: Option<String>,
    /// Refused because the file is cut short (its data ends before a point, a face or a count
    /// it announces is complete): a damaged copy, whose refusal with the place named is the
    /// right answer rather than a reader's gap.
    #[serde(default)]
    pub cut_short: bool,
}

/// One scoreboard row.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// The entry's name.
    pub entry: String,
    /// Its category.
    pub category: String,
    /// `mesh`, `points`, `cage-pair`, `sequence` or `read`.
    pub kind: String,
    /// The input file (a pair's dense mesh, a sequence's first frame).
    pub input: String,
    /// The `subfit` run.
    pub run: Option<Run>,
    /// Our cage's counts.
    #[serde(flatten)]
    pub cage: Option<CageStats>,
    /// The input's genus and boundary loops (the manifest's, else the mesh's own when manifold).
    pub input_topology: Option<Topology>,
    /// Whether our cage has the input's genus and boundary loops (when both are known).
    pub topology_kept: Option<bool>,
    /// The judge's figures for our cage (a sequence: its worst frame).
    pub judge: Option<Judgement>,
    /// The fit's own figures.
    pub report: Option<ReportFigures>,
    /// The larger relative difference between the report's and the judge's RMS and maximum.
    pub disagreement: Option<f64>,
    /// Whether the row meets its category's bar ([`Criteria`]).
    pub pass: Option<bool>,
    /// A cage pair's given cage, judged against the same dense mesh.
    pub given: Option<Judged>,
    /// A sequence's frames.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub frames: Vec<FrameRow>,
    /// A read check's result.
    pub read: Option<ReadCheck>,
    /// Peers at the same size.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub peers: Vec<Judged>,
    /// What went wrong outside the run (the judge, missing outputs).
    pub note: Option<String>,
}

impl Row {
    /// An empty row for an entry.
    pub fn new(entry: &str, category: &str, kind: &str, input: String) -> Self {
        Self {
            entry: entry.into(),
            category: category.into(),
            kind: kind.into(),
            input,
            run: None,
            cage: None,
            input_topology: None,
            topology_kept: None,
            judge: None,
            report: None,
            disagreement: None,
            pass: None,
            given: None,
            frames: Vec::new(),
            read: None,
            peers: Vec::new(),
            note: None,
        }
    }

    /// How the run ended (`None` for read checks).
    pub fn exit(&self) -> Option<Exit> {
        self.run.as_ref().map(|r| r.exit)
    }

    /// The best peer (lowest two-sided RMS among those judged).
    pub fn best_peer(&self) -> Option<&Judged> {
        self.peers
            .iter()
            .filter(|p| p.judge.is_some())
            .min_by(|a, b| {
                let r = |p: &Judged| p.judge.as_ref().map_or(f64::INFINITY, |j| j.rms_fraction);
                r(a).total_cmp(&r(b))
            })
    }
}

/// The relative disagreement above which a row is flagged: the report's measurer and the judge
/// are two exact measurements of the same distances, with sampling of their own.
pub const DISAGREEMENT_FLAG: f64 = 0.10;

/// What a category must reach (fractions of the input's bounding-box diagonal, two-sided).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Criteria {
    /// Exit 0, two-sided RMS and Hausdorff within these, genus and loops kept where known.
    Within {
        /// Two-sided RMS / diagonal.
        rms_fraction: f64,
        /// Hausdorff / diagonal.
        hausdorff_fraction: f64,
    },
    /// A cage pair: ours closer to the dense mesh than the given cage on both RMS and
    /// Hausdorff, with no more irregular vertices.
    BeatGiven,
    /// A sequence: every frame within the RMS, tracked points' drift RMS and 95th percentile
    /// within theirs (where the drift is known).
    Sequence {
        /// Per-frame two-sided RMS / diagonal.
        rms_fraction: f64,
        /// Drift RMS / diagonal.
        drift_rms_fraction: f64,
        /// Drift 95th percentile / diagonal.
        drift_p95_fraction: f64,
    },
    /// A file variant: it reads with the manifest's counts, or, when the file is cut short, is
    /// refused with the line where its data ends.
    Reads,
}

/// The bar of `category`: scans, open surfaces, range clouds and plain folders 1e-3 RMS and
/// 1 % Hausdorff; CAD parts the tolerances of CAD exports, 4e-4 and 0.2 %; cage pairs beat the
/// given cage; sequences 1e-3 RMS per frame, drift RMS 1 % and 95th percentile 2 %.
pub fn criteria(category: &str) -> Criteria {
    match category {
        "cad" => Criteria::Within {
            rms_fraction: 4e-4,
            hausdorff_fraction: 2e-3,
        },
        "cage" => Criteria::BeatGiven,
        "seq" => Criteria::Sequence {
            rms_fraction: 1e-3,
            drift_rms_fraction: 1e-2,
            drift_p95_fraction: 2e-2,
        },
        "refused" => Criteria::Reads,
        _ => Criteria::Within {
            rms_fraction: 1e-3,
            hausdorff_fraction: 1e-2,
        },
    }
}

/// Whether `row` meets `criteria`; `None` when it cannot be told (nothing judged).
pub fn passes(row: &Row, criteria: Criteria) -> Option<bool> {
    let ok_exit = row.exit() == Some(Exit::Code(0));
    match criteria {
        Criteria::Within {
            rms_fraction,
            hausdorff_fraction,
        } => {
            let j = row.judge.as_ref()?;
            Some(
                ok_exit
                    && j.rms_fraction <= rms_fraction
                    && j.hausdorff_fraction <= hausdorff_fraction
                    && row.topology_kept != Some(false),
            )
        }
        Criteria::BeatGiven => {
            let (j, g) = (row.judge.as_ref()?, row.given.as_ref()?);
            let gj = g.judge.as_ref()?;
            let irregular = row.cage.as_ref()?.irregular_vertices;
            Some(
                row.exit().is_some_and(Exit::wrote)
                    && j.rms_fraction < gj.rms_fraction
                    && j.hausdorff_fraction < gj.hausdorff_fraction
                    && irregular <= g.stats.irregular_vertices,
            )
        }
        Criteria::Sequence {
            rms_fraction,
            drift_rms_fraction,
            drift_p95_fraction,
        } => {
            if row.frames.is_empty() {
                return None;
            }
            Some(
                row.exit().is_some_and(Exit::wrote)
                    && row.frames.iter().all(|f| {
                        f.judge
                            .as_ref()
                            .is_some_and(|j| j.rms_fraction <= rms_fraction)
                            && f.drift.as_ref().is_none_or(|d| {
                                d.rms_fraction <= drift_rms_fraction
                                    && d.p95_fraction <= drift_p95_fraction
                            })
                    }),
            )
        }
        Criteria::Reads => row
            .read
            .as_ref()
            .map(|r| r.counts_match == Some(true) || r.cut_short),
    }
}
