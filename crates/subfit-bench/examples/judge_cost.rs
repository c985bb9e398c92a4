//! What the judge costs and says on real files: `judge_cost REFERENCE CAGE [loop|catmull-clark|quad-tri]`
//! judges the cage's limit surface against the reference with the default options and prints the
//! judgement (JSON) and its wall-clock time. Build with `--release`.
#![allow(
    clippy::print_stdout,
    reason = "a benchmark program prints its figures"
)]

use std::path::Path;
use subfit::io::{read_file, ReadOptions};
use subfit::mesh::Tags;
use subfit::subdiv::Scheme;
use subfit_bench::judge::{judge, Candidate, JudgeOptions, Reference};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        return Err("usage: judge_cost REFERENCE CAGE [loop|catmull-clark|quad-tri]".into());
    }
    let (reference, _) = read_file(Path::new(&args[1]), &ReadOptions::default())?;
    let (cage, _) = read_file(Path::new(&args[2]), &ReadOptions::default())?;
    let scheme = match args.get(3).map(String::as_str) {
        None | Some("loop") => Scheme::Loop,
        Some("catmull-clark") => Scheme::CatmullClark,
        Some("quad-tri") => Scheme::QuadTriangle,
        Some(other) => return Err(format!("unknown scheme {other}").into()),
    };
    let j = judge(
        &Reference::from_polymesh(&reference),
        &Candidate::limit(cage, Tags::new(), scheme),
        &JudgeOptions::default(),
    )?;
    println!("{}", serde_json::to_string_pretty(&j)?);
    println!("judged in {:.2} s", j.seconds);
    Ok(())
}
