//! `subfit demo`: generate the built-in shapes into a directory.
//!
//! For now this writes the sampled point clouds (binary PLY with normals) of the paper
//! ellipsoid (semi-axes 0.25/0.5/1.0), a torus and a genus-2 surface; fitting them end to end
//! comes with the fitting pipeline.

use std::process::ExitCode;

use anyhow::{bail, Context};
use subfit::io::{Encoding, Format, WriteOptions};
use subfit::mesh::shapes::Shape;

use crate::cli::DemoArgs;

pub fn run(a: DemoArgs) -> anyhow::Result<ExitCode> {
    if !(a.noise.is_finite() && (0.0..0.1).contains(&a.noise)) {
        bail!(
            "--noise must be in [0, 0.1) (a fraction of the bounding-box diagonal), got {}",
            a.noise
        );
    }
    if a.output.exists() && !a.output.is_dir() {
        bail!("{}: exists and is not a directory", a.output.display());
    }
    std::fs::create_dir_all(&a.output)
        .with_context(|| format!("{}: cannot create directory", a.output.display()))?;
    let opts = WriteOptions {
        format: Some(Format::Ply),
        encoding: Encoding::BinaryLittleEndian,
        single_precision: false,
    };
    println!(
        "{:<10} {:>6} {:>10} {:>8}  file",
        "shape", "genus", "points", "noise"
    );
    let pb = crate::progress::bar(3, "sampling");
    for (name, shape) in Shape::builtin() {
        let cloud = shape.sample(a.points as usize, a.noise, a.seed);
        let path = a.output.join(format!("{name}.ply"));
        subfit::io::write_file(&path, &cloud, &opts)?;
        pb.inc(1);
        pb.suspend(|| {
            println!(
                "{:<10} {:>6} {:>10} {:>8}  {}",
                name,
                shape.genus(),
                cloud.num_vertices(),
                a.noise,
                path.display()
            )
        });
    }
    pb.finish_and_clear();
    Ok(ExitCode::SUCCESS)
}
