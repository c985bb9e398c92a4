//! Command-line syntax of `subfit bench …` (clap derive): the benchmark subcommands and their
//! flags. Values are checked here or in each command's `validate` step before any work starts.

use std::path::PathBuf;

use clap::{Subcommand, ValueEnum};

/// `subfit bench …`.
#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// Reproduce Cheng et al. 2007 Examples 1–4 and 6–10 on the ellipsoid: error-curve CSVs and
    /// SVG plots of E_rms per iteration, one line per method.
    Convergence(ConvergenceArgs),
    /// Fit the models of `$SUBFIT_DATA` end to end and print a table per model (control
    /// points, iterations, E_max, E_rms, time per phase) next to the papers' figures.
    Fit(BenchFitArgs),
    /// Fit generated deforming sequences (known correspondence: drift measured exactly) with
    /// and without the silhouette term; print per-frame errors, drift and time.
    Sequence(BenchSequenceArgs),
    /// Fit every model of a corpus as a user would (defaults; its manifest.tsv, or every model
    /// file of a plain folder), judge each result independently (exact two-sided distances to
    /// the input) and print the scoreboard: per row exit, time, memory, control points, errors,
    /// topology; per category the share within tolerance; regressions against a baseline.
    Corpus(BenchCorpusArgs),
}

/// `subfit bench corpus`.
#[derive(clap::Args, Debug)]
pub struct BenchCorpusArgs {
    /// The corpus: a folder with a manifest.tsv (categories scan, open, range, cad, cage, seq,
    /// refused), or any folder of model files (each fitted with defaults) [default:
    /// $SUBFIT_CORPUS].
    pub dir: Option<PathBuf>,
    /// Only these categories (repeat the flag).
    #[arg(long = "category", value_name = "C")]
    pub categories: Vec<String>,
    /// Only these entries, by name (e.g. `scan-kitten`; repeat the flag).
    #[arg(long = "entry", value_name = "NAME")]
    pub entries: Vec<String>,
    /// Entries fitted at once (each fit then gets cores / N threads).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub jobs: u32,
    /// A fixed subset from every category, chosen by size: the two smallest inputs of each
    /// fitted category, the smallest cage pair, the smallest sequence's first frames, every
    /// read check.
    #[arg(long)]
    pub quick: bool,
    /// The scoreboard as JSON; the Markdown tables are written beside it (same name, `.md`).
    #[arg(long, default_value = "corpus-scoreboard.json")]
    pub out: PathBuf,
    /// Where each entry's runs and outputs are kept [default: beside --out, `NAME-runs/`].
    #[arg(long)]
    pub work: Option<PathBuf>,
    /// A committed scoreboard to compare with: rows whose error is more than 10 % worse, whose
    /// exit got worse or that no longer pass are error regressions; runs more than 25 % (and
    /// 1 s) slower are time regressions [default: bench/corpus-baseline.json when it exists].
    #[arg(long)]
    pub baseline: Option<PathBuf>,
    /// Exit with code 1 when an error regressed against the baseline (not on time).
    #[arg(long)]
    pub fail_on_regression: bool,
    /// A folder made by tools/peers/peers.py (its peers.json): each peer's result is judged the
    /// same way and set beside ours.
    #[arg(long)]
    pub peers: Option<PathBuf>,
    /// Take the rows of earlier scoreboards (their JSON) instead of fitting again: to add
    /// `--peers`, compare with another baseline, or refresh some rows of a scoreboard with a
    /// later run (repeat the flag: a later file's row replaces an earlier one's, and keeps the
    /// earlier row's peers, at the size they were run at, unless `--peers` judges them again).
    /// The entry filters apply; the scoreboard lists where its rows came from.
    #[arg(long, value_name = "FILE.json")]
    pub rows: Vec<PathBuf>,
    /// Seconds one run may take before it is stopped (a row `timeout`).
    #[arg(long, default_value_t = 900)]
    pub timeout: u64,
    /// Area-uniform samples of each limit surface the judge measures (at least 200,000 for
    /// the scoreboard's figures).
    #[arg(long, default_value_t = 200_000)]
    pub surface_samples: usize,
    /// The `subfit` executable to score [default: this one].
    #[arg(long)]
    pub subfit: Option<PathBuf>,
    /// A flag added to every `subfit fit` of the corpus, to score an option before it becomes
    /// a default (repeat it: `--fit-arg --no-facing`, `--fit-arg --coverage --fit-arg 0`); the
    /// scoreboard records them. Sequences are run as they are.
    #[arg(long = "fit-arg", value_name = "ARG", allow_hyphen_values = true)]
    pub fit_args: Vec<String>,
}

/// `subfit bench sequence`.
#[derive(clap::Args, Debug)]
pub struct BenchSequenceArgs {
    /// Frames per sequence.
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(2..=1000))]
    pub frames: u32,
    /// Vertices per frame (each frame's resolution varies ±30% around it).
    #[arg(long, default_value_t = 25_000, value_parser = clap::value_parser!(u32).range(500..=5_000_000))]
    pub vertices: u32,
    /// Control points of the template [default: 1000; with --meshes, `subfit sequence`'s].
    #[arg(long, value_parser = clap::value_parser!(u32).range(20..=100_000))]
    pub control_points: Option<u32>,
    /// Silhouette views of the run with the term (the other run has none).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub silhouette_views: u32,
    /// Which motion: the tube's moderate default, its large tangential one, both, or the
    /// dancing articulated figure (material moves with its limbs, as on a real body).
    #[arg(long, value_enum, default_value_t = MotionArg::Both)]
    pub motion: MotionArg,
    /// Capture frames between two frames of the dance (1: a smooth capture; 5: the same dance
    /// at a fifth of the frame rate, fast motion between frames).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub stride: u32,
    /// Give each frame of the dance as this many fresh random surface points without normals
    /// (like a capture) instead of a mesh; 0: meshes.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=10_000_000))]
    pub points: u32,
    /// Only the run with the silhouette term, or only the one without (`0`); both by default.
    #[arg(long)]
    pub only_views: Option<u32>,
    /// Instead of a generated sequence, fit these frames (files, in order) as `subfit
    /// sequence` does with its defaults (the template's control points by `subfit fit`'s
    /// rule unless --control-points is given), and measure the drift by the frames' own
    /// correspondence: they must share one connectivity (vertex i is the same material point
    /// in every frame), as the corpus's seq-* frames do.
    #[arg(long, num_args = 2.., value_name = "FRAME")]
    pub meshes: Vec<PathBuf>,
    /// Seed of the frames' tessellations.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Nodes of the tracking step (0: off) [default: `subfit sequence`'s].
    #[arg(long)]
    pub track_nodes: Option<u32>,
    /// Markers at their true places in every frame, spread over frame 0 (as `subfit sequence
    /// --markers` takes them from motion capture); 0: none.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=10_000))]
    pub markers: u32,
    /// ARAP weight α towards the template [default: `subfit sequence`'s].
    #[arg(long)]
    pub arap: Option<f64>,
    /// ARAP weight at the start of each frame's annealing [default: `subfit sequence`'s].
    #[arg(long)]
    pub arap_start: Option<f64>,
    /// LM iterations per frame at most [default: `subfit sequence`'s].
    #[arg(long)]
    pub iterations: Option<u32>,
    /// Silhouette weight [default: `subfit sequence`'s].
    #[arg(long)]
    pub silhouette_weight: Option<f64>,
    /// Peak twist of the generated motion, radians per unit length (0: none) [default: the
    /// motion's].
    #[arg(long)]
    pub twist: Option<f64>,
    /// Peak curvature of the generated bend (0: none) [default: the motion's].
    #[arg(long)]
    pub bend: Option<f64>,
    /// Peak relative thickness change of the generated motion (0: none) [default: the motion's].
    #[arg(long)]
    pub thickness: Option<f64>,
    /// Also write each run's outputs (frames, sequence.usda, report.json) under this directory.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// The motion of a generated sequence.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MotionArg {
    /// Bending, twisting, thickness waves (subfit_mesh::deforming defaults).
    Moderate,
    /// The same with a large spin about the axis: points slide far between frames.
    Large,
    /// Both.
    Both,
    /// The dancing articulated figure (subfit_mesh::deforming::DancingFigure).
    Dance,
}

/// `subfit bench fit`.
#[derive(clap::Args, Debug)]
pub struct BenchFitArgs {
    /// Directory of the models [default: $SUBFIT_DATA].
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// Output directory: one fit directory per model and `summary.json`.
    #[arg(short, long, default_value = "subfit-bench-fit")]
    pub output: PathBuf,
    /// Run only these models (e.g. `--models igea,rocker-arm`).
    #[arg(long, value_delimiter = ',')]
    pub models: Vec<String>,
    /// Judge the tolerances surface → data only, as the papers do (both directions are
    /// printed either way).
    #[arg(long)]
    pub one_sided: bool,
}

/// `subfit bench convergence`.
#[derive(clap::Args, Debug)]
pub struct ConvergenceArgs {
    /// Output directory for `exampleN.csv`, `exampleN.svg` and `summary.json`.
    #[arg(short, long, default_value = "subfit-convergence")]
    pub output: PathBuf,
    /// Points sampled on each target ellipsoid.
    #[arg(long, default_value_t = 30_000, value_parser = clap::value_parser!(u32).range(1000..=10_000_000))]
    pub points: u32,
    /// Iterations per run.
    #[arg(long, default_value_t = 50, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub iterations: u32,
    /// Run only these examples (e.g. `--examples 1,2`).
    #[arg(long, value_delimiter = ',')]
    pub examples: Vec<u32>,
}
