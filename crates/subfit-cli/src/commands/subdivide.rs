//! `subfit subdivide CONTROL --levels k [--limit] -o OUT`: uniform refinement or limit
//! positions and normals of a control mesh.

use std::process::ExitCode;

use anyhow::{bail, Context};
use subfit::io::{Encoding, Format, WriteOptions};
use subfit::mesh::PolyMesh;
use subfit::subdiv::{refine, sampling_operator, BoundaryRule, Options, Scheme};

use crate::cli::{BoundaryArg, SchemeArg, SubdivideArgs};

/// The scheme named on the command line, or Loop for all-triangle meshes and Catmull-Clark
/// otherwise.
pub fn pick_scheme(arg: SchemeArg, control: &PolyMesh) -> Scheme {
    match arg {
        SchemeArg::Loop => Scheme::Loop,
        SchemeArg::CatmullClark => Scheme::CatmullClark,
        SchemeArg::QuadTri => Scheme::QuadTriangle,
        SchemeArg::Auto if control.faces.is_triangles() => Scheme::Loop,
        SchemeArg::Auto => Scheme::CatmullClark,
    }
}

/// The boundary rule named on the command line.
pub fn boundary_rule(arg: BoundaryArg) -> BoundaryRule {
    match arg {
        BoundaryArg::EdgeOnly => BoundaryRule::EdgeOnly,
        BoundaryArg::EdgeAndCorner => BoundaryRule::EdgeAndCorner,
    }
}

pub fn run(a: SubdivideArgs) -> anyhow::Result<ExitCode> {
    let Some(out_format) = Format::from_path(&a.output) else {
        bail!(
            "{}: cannot tell the output format from the extension",
            a.output.display()
        );
    };
    let (control, _) = crate::progress::load(&a.control)?;
    if control.faces.is_empty() {
        bail!(
            "{}: has no faces; a control mesh is needed",
            a.control.display()
        );
    }
    let scheme = pick_scheme(a.scheme, &control);
    let options = Options::new(scheme).with_boundary(boundary_rule(a.boundary));
    // The cage's own creases and corners (an OBJ's `t` lines, as control.obj has them).
    let tags = subfit::io::read_tags_file(&a.control, control.num_vertices())?;
    let ctx = || format!("{}: cannot subdivide", a.control.display());

    let sp = crate::progress::spinner("subdividing");
    let result = if a.limit {
        let op = sampling_operator(
            &control.faces,
            control.num_vertices(),
            &tags,
            &options,
            a.levels as usize,
        )
        .with_context(ctx)?;
        let samples = op.evaluate(&control.positions);
        PolyMesh {
            positions: samples.positions,
            normals: Some(samples.normals),
            colors: None,
            faces: op.faces,
        }
    } else {
        let mut faces = control.faces.clone();
        let mut positions = control.positions.clone();
        let mut level_tags = tags;
        for _ in 0..a.levels {
            let r = refine(&faces, positions.len(), &level_tags, &options).with_context(ctx)?;
            positions = r.matrix.apply(&positions);
            faces = r.faces;
            level_tags = r.tags;
        }
        PolyMesh::new(positions, faces)
    };
    sp.finish_and_clear();

    let encoding = match out_format {
        Format::Ply | Format::Stl => Encoding::BinaryLittleEndian,
        _ => Encoding::Ascii,
    };
    let opts = WriteOptions {
        format: Some(out_format),
        encoding,
        single_precision: false,
    };
    crate::interrupt::watch_dir(&a.output);
    subfit::io::write_file(&a.output, &result, &opts)?;
    eprintln!(
        "{} ({:?}, {} level(s){}) -> {}: {} vertices, {} faces",
        a.control.display(),
        scheme,
        a.levels,
        if a.limit { ", limit" } else { "" },
        a.output.display(),
        result.num_vertices(),
        result.num_faces()
    );
    Ok(ExitCode::SUCCESS)
}
