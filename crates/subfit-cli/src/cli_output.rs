//! Flags on what `subfit fit` prints and how it writes the limit tessellation: `--quiet`,
//! `--json` (a machine-readable closing summary) and `--limit-quads`; `subfit completions`.

/// How `subfit fit` reports and writes.
#[derive(clap::Args, Debug, Clone, Copy, Default)]
pub struct OutputArgs {
    /// Print nothing on success: no progress, no closing summary, no hints (warnings and
    /// errors still go to stderr; the exit code says whether the tolerances were reached).
    #[arg(short, long)]
    pub quiet: bool,
    /// Print the closing summary as one JSON object on stdout (control points, the two-sided
    /// errors in the input's units and as fractions of its bounding-box diagonal, seconds,
    /// the files written); progress stays on stderr.
    #[arg(long)]
    pub json: bool,
    /// Keep the limit tessellation's quads in limit.ply and error.ply (Catmull-Clark and
    /// quad/tri cages) instead of splitting each into two triangles. Off by default: some
    /// readers (trimesh) refuse a PLY whose faces differ in size.
    #[arg(long)]
    pub limit_quads: bool,
}

/// `subfit completions`.
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct CompletionsArgs {
    /// The shell to complete in.
    #[arg(value_enum)]
    pub shell: clap_complete::Shell,
}
