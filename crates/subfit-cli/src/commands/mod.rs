//! One module per subcommand; `run` dispatches.

mod analyze;
mod bench;
mod bench_fit;
mod compare;
mod convert;
mod demo;
mod eval;
mod fit;
mod info;
mod init;
mod subdivide;

use std::process::ExitCode;

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
        Command::Bench(b) => bench::run(b),
    }
}
