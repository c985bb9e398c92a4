//! One module per subcommand; `run` dispatches.

mod analyze;
mod bench;
mod bench_corpus;
mod bench_fit;
mod bench_sequence;
mod compare;
mod compare_html;
mod convert;
mod demo;
mod eval;
mod fit;
mod info;
mod init;
mod sequence;
mod subdivide;

use std::path::Path;
use std::process::ExitCode;

use subfit::mesh::PolyMesh;

use crate::cli::{Args, Command};

/// Runs a parsed command. `Err` means bad input or usage (exit code 2).
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    match args.command {
        Command::Info(a) => info::run(a),
        Command::Convert(a) => convert::run(a),
        Command::Demo(a) => demo::run(a),
        Command::Subdivide(a) => subdivide::run(a),
        Command::Analyze(a) => analyze::run(a),
        Command::Eval(a) => eval::run(a),
        Command::Fit(a) => fit::run(a),
        Command::Init(a) => init::run(a),
        Command::Compare(a) => compare::run(a),
        Command::Sequence(a) => sequence::run(a),
        Command::Bench(b) => bench::run(b),
    }
}

/// Repairs a target mesh read from `file` as `subfit fit` does ([`subfit::repair_mesh`]: welds
/// vertices split along seams, drops collapsed and repeated faces, cuts edges with more than two
/// faces, splits non-manifold vertices, re-orients faces), with a warning on stderr for each
/// repair. A mesh that cannot be repaired (a non-orientable component) is left as it is, for the command's own checks to accept (e.g.
/// `analyze`, `init --from-points`) or refuse with their usual one-line error.
pub fn repair_target(mesh: &mut PolyMesh, file: &Path) {
    let name = file.display().to_string();
    let mut copy = mesh.clone();
    let mut warnings = Vec::new();
    // Not repairable: the command's own checks accept or refuse the mesh as it is.
    if subfit::repair_mesh(&mut copy, &name, &mut |w| warnings.push(w)).is_ok() {
        for w in warnings {
            eprintln!("subfit: warning: {w}");
        }
        *mesh = copy;
    }
}
