//! `subfit sequence FRAME... [-o DIR]`: translate the flags into [`subfit::SequenceOptions`],
//! run [`subfit::fit_sequence`] with a bar over the frames, and write its outputs
//! ([`subfit::Sequence::write_into`]: every frame's cage `frame_0000.obj` …, the animated
//! `sequence.usda`, `report.json`) into a staging directory moved into place together (an
//! error or an interruption leaves none).

use std::process::ExitCode;

use anyhow::Context;
use subfit::fit::FitOptions;
use subfit::subdiv::Scheme;
use subfit::{fit_sequence, FitScanOptions, InitialCage, Input, SequenceOptions};

use crate::cli::{MethodArg, SchemeArg, SequenceArgs};
use crate::commands::fit::method_of;

pub fn run(a: SequenceArgs) -> anyhow::Result<ExitCode> {
    if a.output.exists() && !a.output.is_dir() {
        anyhow::bail!("{}: exists and is not a directory", a.output.display());
    }
    if !(a.fps.is_finite() && a.fps > 0.0) {
        anyhow::bail!("--fps must be a positive number, got {}", a.fps);
    }
    let options = options(&a)?;
    let stage = crate::interrupt::Staging::new(&a.output)
        .with_context(|| format!("{}: cannot create directory", a.output.display()))?;
    let bar = crate::progress::bar(a.frames.len() as u64, "fitting frames");
    let mut on_frame = |f: subfit::SequenceFrame<'_>| -> Result<(), subfit::Error> {
        let e = &f.report.two_sided;
        bar.set_message(format!(
            "frame {}: two-sided E_rms {:.2e} ({:.3}% of its diagonal), {:.2} s",
            f.report.index,
            e.e_rms_original_units,
            100.0 * e.e_rms_fraction_of_diagonal,
            f.report.timings_s.total
        ));
        bar.inc(1);
        Ok(())
    };
    let mut warn = |m: &str| bar.suspend(|| eprintln!("subfit: warning: {m}"));
    let frames = a.frames.iter().map(|p| Input::File(p.clone()));
    let result = fit_sequence(frames, &options, &mut on_frame, &mut warn);
    bar.finish_and_clear();
    let sequence = result?;
    sequence.write_into(&stage.path(""), a.fps)?;
    let names = sequence.output_names();
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    stage
        .commit(&refs)
        .with_context(|| format!("{}: cannot move the outputs into place", a.output.display()))?;
    let r = &sequence.report;
    let reached = r.frames.iter().filter(|f| f.tolerance_reached).count();
    out!(
        "{} frames, {} control points ({:?}): worst two-sided E_rms {:.3}% and E_max {:.3}% of a frame's diagonal, {reached}/{} frames within the tolerance, {:.2} s per frame after the first; wrote {}",
        r.frames_fitted,
        r.control_points,
        sequence.scheme,
        100.0 * r.worst_rms_fraction_of_diagonal,
        100.0 * r.worst_max_fraction_of_diagonal,
        r.frames_fitted,
        r.mean_seconds_per_frame,
        a.output.display()
    );
    Ok(if reached == r.frames_fitted {
        ExitCode::SUCCESS
    } else {
        eprintln!("subfit: some frames did not reach the tolerance both ways (outputs written)");
        ExitCode::from(1)
    })
}

/// The library's options for the flags of `subfit sequence`.
fn options(a: &SequenceArgs) -> anyhow::Result<SequenceOptions> {
    let template = match &a.template {
        None => InitialCage::Auto,
        Some(path) => subfit::read_cage(path)?,
    };
    let scheme = match a.scheme {
        SchemeArg::Auto => None,
        SchemeArg::Loop => Some(Scheme::Loop),
        SchemeArg::CatmullClark => Some(Scheme::CatmullClark),
        SchemeArg::QuadTri => Some(Scheme::QuadTriangle),
    };
    let method = method_of(a.method);
    if matches!(a.method, MethodArg::Pdm | MethodArg::Tdm) {
        anyhow::bail!("--method: a sequence fits with sdm or imls");
    }
    let fit = FitOptions {
        sample_level: a.sample_level as usize,
        method,
        coverage: 1.0,
        ..FitOptions::default()
    };
    // The template is fitted as `subfit fit` would (sample level 3); the frames at
    // --sample-level.
    let mut template_fit = FitScanOptions {
        control_points: a.control_points.map(|n| n as usize),
        scheme,
        fit: FitOptions {
            sample_level: 3,
            ..fit.clone()
        },
        ..FitScanOptions::default()
    };
    template_fit.stages.tolerance_rms = a.tolerance;
    if let Some(n) = a.control_points {
        template_fit.stages.max_control_points = n as usize;
    }
    Ok(SequenceOptions {
        template,
        template_fit,
        fit,
        lambda: a.lambda,
        arap: a.arap,
        iterations: a.iterations as usize,
        tolerance_rms: a.tolerance,
        silhouette: subfit::SilhouetteOptions {
            views: a.silhouette_views as usize,
            resolution: a.silhouette_resolution as usize,
            weight: a.silhouette_weight,
            ..subfit::SilhouetteOptions::default()
        },
        tracking: match (tracking(a.track_nodes), &a.markers) {
            (t, None) => t,
            (None, Some(_)) => {
                anyhow::bail!("--markers needs the tracking step (--track-nodes > 0)")
            }
            (Some(t), Some(path)) => Some(subfit::TrackingOptions {
                markers: markers(path, a.frames.len())?,
                ..t
            }),
        },
        cancel: crate::interrupt::token(),
        ..SequenceOptions::default()
    })
}

/// The markers of `path`, each in one of the `frames` frames given.
fn markers(
    path: &std::path::Path,
    frames: usize,
) -> anyhow::Result<Vec<subfit::MarkerObservation>> {
    let markers = subfit::read_markers(path)?;
    if let Some(m) = markers.iter().find(|m| m.frame >= frames) {
        anyhow::bail!(
            "{}: marker {:?} is given in frame {}, but only {frames} frames (0..={}) are given",
            path.display(),
            m.marker,
            m.frame,
            frames.saturating_sub(1)
        );
    }
    Ok(markers)
}

/// The tracking step with `nodes` nodes (0: off).
pub fn tracking(nodes: u32) -> Option<subfit::TrackingOptions> {
    (nodes > 0).then(|| subfit::TrackingOptions {
        nodes: nodes as usize,
        ..subfit::TrackingOptions::default()
    })
}
