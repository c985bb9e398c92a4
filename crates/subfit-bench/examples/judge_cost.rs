//! What the judge costs and says on real files:
//! `judge_cost REFERENCE CANDIDATE [loop|catmull-clark|quad-tri|mesh]` judges the candidate — a
//! cage's limit surface under the scheme (default Loop), or with `mesh` the file's polygons as
//! they are — against the reference with the default options, and prints the judgement (JSON)
//! and its wall-clock time. Build with `--release`.
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
        return Err(
            "usage: judge_cost REFERENCE CANDIDATE [loop|catmull-clark|quad-tri|mesh]".into(),
        );
    }
    let (reference, _) = read_file(Path::new(&args[1]), &ReadOptions::default())?;
    let (mesh, _) = read_file(Path::new(&args[2]), &ReadOptions::default())?;
    let scheme = |s| match s {
        "loop" => Ok(Scheme::Loop),
        "catmull-clark" => Ok(Scheme::CatmullClark),
        "quad-tri" => Ok(Scheme::QuadTriangle),
        other => Err(format!("unknown scheme {other}")),
    };
    let candidate = match args.get(3).map(String::as_str) {
        Some("mesh") => Candidate::mesh_from_polymesh(&mesh),
        s => Candidate::limit(mesh, Tags::new(), scheme(s.unwrap_or("loop"))?),
    };
    let j = judge(
        &Reference::from_polymesh(&reference),
        &candidate,
        &JudgeOptions::default(),
    )?;
    println!("{}", serde_json::to_string_pretty(&j)?);
    println!("judged in {:.2} s", j.seconds);
    Ok(())
}
