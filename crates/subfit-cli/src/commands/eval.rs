//! `subfit eval CONTROL --samples N -o OUT`: exact limit points and normals at random
//! `(face, u, v)` parameters (Stam-style local refinement down to regular patches; see
//! `subfit_subdiv::eval`).

use std::process::ExitCode;

use anyhow::{bail, Context};
use subfit::io::ply::VertexProperty;
use subfit::io::{Encoding, Format, WriteOptions};
use subfit::mesh::PolyMesh;
use subfit::subdiv::{random_samples, Evaluator, Options};

use crate::cli::EvalArgs;
use crate::commands::subdivide::{boundary_rule, pick_scheme};

pub fn run(a: EvalArgs) -> anyhow::Result<ExitCode> {
    let Some(format) = Format::from_path(&a.output) else {
        bail!(
            "{}: cannot tell the output format from the extension",
            a.output.display()
        );
    };
    if format == Format::Stl {
        bail!(
            "{}: STL holds triangles, not sample points",
            a.output.display()
        );
    }
    let (control, _) = crate::progress::load(&a.control)?;
    if control.faces.is_empty() {
        bail!(
            "{}: has no faces; a control mesh is needed",
            a.control.display()
        );
    }
    let options =
        Options::new(pick_scheme(a.scheme, &control)).with_boundary(boundary_rule(a.boundary));
    let ctx = || format!("{}: cannot evaluate", a.control.display());
    let sp = crate::progress::spinner("evaluating the limit surface");
    // The cage's own creases and corners (an OBJ's `t` lines, as control.obj has them).
    let tags = subfit::io::read_tags_file(&a.control, control.num_vertices())?;
    let evaluator = Evaluator::new(&control.faces, control.num_vertices(), &tags, &options)
        .with_context(ctx)?;
    let (params, points) =
        random_samples(&evaluator, &control.positions, a.samples as usize, a.seed)
            .with_context(ctx)?;
    sp.finish_and_clear();

    let cloud = PolyMesh::point_cloud(
        points.iter().map(|p| p.position).collect(),
        Some(points.iter().map(|p| p.normal).collect()),
    );
    if format == Format::Ply {
        let face: Vec<f64> = params.iter().map(|p| p.face as f64).collect();
        let sub: Vec<f64> = params.iter().map(|p| p.sub as f64).collect();
        let u: Vec<f64> = params.iter().map(|p| p.u).collect();
        let v: Vec<f64> = params.iter().map(|p| p.v).collect();
        let props = [("face", &face), ("sub", &sub), ("u", &u), ("v", &v)]
            .map(|(name, values)| VertexProperty { name, values });
        let opts = WriteOptions {
            format: None,
            encoding: Encoding::BinaryLittleEndian,
            single_precision: false,
        };
        crate::interrupt::watch_dir(&a.output);
        subfit::io::write_ply_with_properties(&a.output, &cloud, &props, &opts)?;
    } else {
        let opts = WriteOptions {
            format: Some(format),
            ..WriteOptions::default()
        };
        crate::interrupt::watch_dir(&a.output);
        subfit::io::write_file(&a.output, &cloud, &opts)?;
    }
    eprintln!(
        "{} ({:?}): {} exact limit samples -> {}",
        a.control.display(),
        options.scheme,
        cloud.num_vertices(),
        a.output.display()
    );
    Ok(ExitCode::SUCCESS)
}
