//! One module per subcommand; `run` dispatches.

mod analyze;
mod bench;
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

use subfit::mesh::{reorient_faces, PolyMesh};

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

/// Repairs a target mesh read from `file` as `subfit fit` does: splits non-manifold vertices
/// into one per fan of faces ([`subfit::mesh::split_bowties`]; holes that touch at a vertex)
/// and re-orients the faces consistently per component ([`reorient_faces`]; real scans often
/// have a few faces the wrong way round), with a warning on stderr for each repair. A mesh that
/// cannot be repaired (a non-manifold edge, a non-orientable component) is left as it is, for
/// the command's own checks to accept (e.g. `analyze`, `init --from-points`) or refuse with
/// their usual one-line error.
pub fn repair_target(mesh: &mut PolyMesh, file: &Path) {
    if mesh.faces.is_empty() {
        return;
    }
    let (split, r) = subfit::mesh::split_bowties(mesh);
    if r.vertices_split > 0 {
        eprintln!(
            "subfit: warning: split {} non-manifold vertices of {} (faces meeting only at a vertex, e.g. vertex {}) into one vertex per fan",
            r.vertices_split,
            file.display(),
            r.examples[0]
        );
        *mesh = split;
    }
    // Not repairable: the command's own checks accept or refuse the mesh as it is.
    let Ok((faces, r)) = reorient_faces(&mesh.faces, mesh.num_vertices(), Some(&mesh.positions))
    else {
        return;
    };
    if r.needed {
        eprintln!(
            "subfit: warning: re-oriented {} faces in {} components of {}",
            r.flipped_faces,
            r.repaired_components,
            file.display()
        );
        mesh.faces = faces;
    }
}
