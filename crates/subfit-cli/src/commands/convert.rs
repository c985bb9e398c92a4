//! `subfit convert IN OUT`: read any supported format, write another.

use std::process::ExitCode;

use anyhow::bail;
use subfit::io::{Encoding, Format, ReadOptions, WriteOptions};

use crate::cli::{ConvertArgs, EncodingArg};

pub fn run(a: ConvertArgs) -> anyhow::Result<ExitCode> {
    // Validate everything before reading.
    let out_format = match a
        .to
        .map(Format::from)
        .or_else(|| Format::from_path(&a.output))
    {
        Some(f) => f,
        None => bail!(
            "{}: cannot tell the output format from the extension; use --to",
            a.output.display()
        ),
    };
    let encoding = match (a.encoding, out_format) {
        (EncodingArg::Auto, Format::Ply | Format::Stl) => Encoding::BinaryLittleEndian,
        (EncodingArg::Auto | EncodingArg::Ascii, _) => Encoding::Ascii,
        (EncodingArg::Binary, Format::Ply | Format::Stl) => Encoding::BinaryLittleEndian,
        (EncodingArg::BinaryBe, Format::Ply) => Encoding::BinaryBigEndian,
        (e, f) => bail!("--encoding {e:?} is not available for {}", f.name()),
    };
    if a.single && !(out_format == Format::Ply && encoding != Encoding::Ascii) {
        bail!("--single applies only to binary PLY output");
    }
    if a.input
        .canonicalize()
        .ok()
        .is_some_and(|p| Some(p) == a.output.canonicalize().ok())
    {
        bail!("{}: input and output are the same file", a.output.display());
    }

    let bytes = crate::progress::read_with_progress(&a.input)?;
    let ropts = ReadOptions {
        format: a.from.map(Format::from),
        weld_stl: !a.no_weld,
    };
    let (mesh, info) = subfit::io::read_bytes(&bytes, &a.input, &ropts)?;
    for loss in out_format.losses(&mesh) {
        eprintln!("subfit: warning: {} drops {loss}", out_format.name());
    }
    let wopts = WriteOptions {
        format: Some(out_format),
        encoding,
        single_precision: a.single,
    };
    crate::interrupt::watch_dir(&a.output);
    subfit::io::write_file(&a.output, &mesh, &wopts)?;
    eprintln!(
        "{} ({} {:?}) -> {} ({} {:?}): {} vertices, {} faces",
        a.input.display(),
        info.format.name(),
        info.encoding,
        a.output.display(),
        out_format.name(),
        encoding,
        mesh.num_vertices(),
        mesh.num_faces()
    );
    Ok(ExitCode::SUCCESS)
}
