//! `subfit demo`: the whole pipeline on the built-in shapes, with no input. Samples the paper
//! ellipsoid (semi-axes 0.25/0.5/1.0), a torus and a genus-2 surface as point clouds (binary
//! PLY with normals), fits each with [`subfit::fit_scan`]'s defaults (those of `subfit fit`) (automatic initial mesh of the
//! shape's genus, multi-stage SDM to `E_rms ≤ 5e-4`) into `DIR/fit-<shape>/`, and prints a
//! summary table.

use std::process::ExitCode;

use anyhow::{bail, Context};
use subfit::io::{Encoding, Format, WriteOptions};
use subfit::mesh::shapes::Shape;
use subfit::{FitScanOptions, Input};

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
    let mut rows = Vec::new();
    let mut reports = Vec::new();
    let mut all_reached = true;
    for (name, shape) in Shape::builtin() {
        let cloud = shape.sample(a.points as usize, a.noise, a.seed);
        let path = a.output.join(format!("{name}.ply"));
        crate::interrupt::watch_dir(&path);
        subfit::io::write_file(&path, &cloud, &opts)?;
        if a.no_fit {
            rows.push(format!(
                "{:<10} {:>5} {:>9} {:>8}  {}",
                name,
                shape.genus(),
                cloud.num_vertices(),
                a.noise,
                path.display()
            ));
            continue;
        }
        let dir = a.output.join(format!("fit-{name}"));
        let input = Input::Mesh {
            mesh: cloud.clone(),
            name: path.display().to_string(),
        };
        let options = FitScanOptions::default();
        let mut fitted = crate::commands::fit::run_with_progress(
            input,
            &options,
            options.stages.max_iterations as u64,
        )
        .with_context(|| format!("fitting the {name}"))?;
        crate::commands::fit::write_outputs(&mut fitted, &dir, &Default::default())?;
        all_reached &= fitted.reached();
        reports.push(dir.join("report.html"));
        let r = &fitted.report;
        rows.push(format!(
            "{:<10} {:>5} {:>5} {:>9} {:>6} → {:<6} {:>6} {:>10.2e} {:>10.2e} {:>10.2e} {:>10.2e} {:>7.1}  {}",
            name,
            shape.genus(),
            r.init.genus,
            cloud.num_vertices(),
            r.init.control_points,
            r.control_points,
            r.stages.len(),
            r.r#final.e_rms,
            r.r#final.e_max,
            r.r#final.two_sided.e_rms,
            r.r#final.two_sided.e_max,
            r.timings_s.total,
            dir.display()
        ));
    }
    if a.no_fit {
        out!(
            "{:<10} {:>5} {:>9} {:>8}  file",
            "shape",
            "genus",
            "points",
            "noise"
        );
    } else {
        out!(
            "{:<10} {:>5} {:>5} {:>9} {:>15} {:>6} {:>10} {:>10} {:>10} {:>10} {:>7}  output",
            "shape",
            "genus",
            "cage",
            "points",
            "control points",
            "stages",
            "E_rms",
            "E_max",
            "2s E_rms",
            "2s E_max",
            "time s"
        );
    }
    for r in rows {
        out!("{r}");
    }
    if !a.no_fit {
        out!("reports to look at (open in a browser; preview.png beside each):");
        for r in &reports {
            out!("  {}", r.display());
        }
        out!("(errors in unit-cube units: the shape scaled so that its longest side is 1; E_rms/E_max surface → data, 2s: the worse of both directions)");
    }
    Ok(if all_reached {
        ExitCode::SUCCESS
    } else {
        eprintln!("subfit: a demo fit did not reach its tolerance (outputs written)");
        ExitCode::from(1)
    })
}
