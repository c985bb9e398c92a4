//! The `subfit` command-line tool.
//!
//! Argument parsing (clap) turns argv into a typed [`cli::Command`]; every flag is validated
//! before any file is touched. Exit codes: 0 success, 1 failure to fit within the budget,
//! 2 bad input or usage (one line on stderr), 130 interrupted (no partial output left).

#![allow(clippy::print_stdout, clippy::print_stderr)]

/// `println!` for the commands' results: when the reader has gone away (`subfit compare A B |
/// head -3`) the process ends quietly with exit 0, as Unix tools do, instead of panicking on
/// the broken pipe; another write error is a one-line error with exit 2.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = writeln!(std::io::stdout().lock(), $($arg)*) {
            $crate::stdout_failed(e);
        }
    }};
}

mod cli;
mod cli_bench;
mod cli_output;
mod commands;
mod hints;
mod interrupt;
mod progress;

use std::process::ExitCode;

use clap::Parser;

/// Exit code for bad input or usage.
const EXIT_BAD_INPUT: u8 = 2;

fn main() -> ExitCode {
    let args = match cli::Args::try_parse() {
        Ok(a) => a,
        Err(e) => {
            // Help and version go to stdout with code 0; usage errors keep clap's message.
            let code = if e.use_stderr() { EXIT_BAD_INPUT } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    interrupt::install();
    // An interrupted run exits 130 inside `conclude`, after removing what it had begun to write.
    match interrupt::conclude(commands::run(args)) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("subfit: error: {}", one_line(&e));
            ExitCode::from(EXIT_BAD_INPUT)
        }
    }
}

/// Ends the process after a failed write to stdout (see `out!`).
fn stdout_failed(e: std::io::Error) -> ! {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        std::process::exit(0);
    }
    eprintln!("subfit: error: cannot write to stdout: {e}");
    std::process::exit(EXIT_BAD_INPUT.into());
}

/// The error and its causes on one line.
fn one_line(e: &anyhow::Error) -> String {
    let mut s = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if !s.contains(&c) {
            s.push_str(": ");
            s.push_str(&c);
        }
    }
    s.replace('\n', " ")
}
