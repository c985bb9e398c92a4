//! Writes the CAD start of a tessellation (`subfit::cad_start`) without fitting it: the cage
//! with its crease and corner tags (`OUT.obj`, OpenSubdiv `t` lines, in the input's
//! coordinates) and its summary, to look at what the facets gave before the fit moves it.
//! With the default (CAD tessellation) tolerances.
//!
//! `cargo run --release -p subfit --example cad_cage -- MESH OUT.obj`
#![allow(clippy::print_stdout)]

use subfit::target::{Target, TargetOptions};
use subfit::{cad_start::cad_start, repair_mesh, FitScanOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, input, output] = &args[..] else {
        return Err("usage: cad_cage MESH OUT.obj".into());
    };
    let (mut mesh, _) = subfit::io::read_file(input.as_ref(), &Default::default())?;
    repair_mesh(&mut mesh, input, &mut |w| println!("repair: {w}"))?;
    let target = Target::build(&mesh, &TargetOptions::default(), None)?;
    let options = FitScanOptions {
        target_tolerances: true,
        ..FitScanOptions::default()
    };
    let Some(start) = cad_start(&target, &mesh, input, &options)? else {
        println!("{input}: not a CAD tessellation with creases (no CAD start)");
        return Ok(());
    };
    let cage = subfit::mesh::PolyMesh::new(
        start
            .cage
            .positions
            .iter()
            .map(|&p| target.to_original(p))
            .collect(),
        start.cage.faces.clone(),
    );
    subfit::io::write_obj_with_tags_file(output.as_ref(), &cage, &start.tags)?;
    println!(
        "{input}: {} control points, {} creases, {} corners\n{}",
        cage.num_vertices(),
        start.tags.creases().len(),
        start.tags.corners().len(),
        serde_json::to_string_pretty(&start.init.cad)?
    );
    Ok(())
}
