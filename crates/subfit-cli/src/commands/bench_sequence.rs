//! `subfit bench sequence`: issue 17's figures on generated sequences with known
//! correspondence (`subfit::mesh::deforming`): every frame a mesh of its own resolution, one
//! cage fitted to all of them with [`subfit::fit_sequence`], once with the silhouette term and
//! once without. Prints per run the worst two-sided RMS, the drift of the tracked limit points
//! (the control vertices' limit points located on frame 0, compared in every frame with where
//! their material point went; fraction of the frame's diagonal) and the seconds per frame,
//! beside Xie et al. 2023's 12.9–17 s per frame on a GPU.

use std::process::ExitCode;

use anyhow::Context;
use subfit::mesh::deforming::{DeformingParams, DeformingSequence, Frame, MaterialLookup};
use subfit::{fit_sequence, FitScanOptions, Input, SequenceOptions, SilhouetteOptions};

use crate::cli::{BenchSequenceArgs, MotionArg};

/// One run's figures.
struct Row {
    motion: &'static str,
    views: usize,
    worst_rms: f64,
    worst_max: f64,
    drift_max: f64,
    drift_rms: f64,
    seconds_per_frame: f64,
    template_seconds: f64,
}

pub fn run(a: BenchSequenceArgs) -> anyhow::Result<ExitCode> {
    let motions: Vec<(&'static str, DeformingParams)> = match a.motion {
        MotionArg::Moderate => vec![("moderate", DeformingParams::default())],
        MotionArg::Large => vec![("large", DeformingParams::large_tangential_motion())],
        MotionArg::Both => vec![
            ("moderate", DeformingParams::default()),
            ("large", DeformingParams::large_tangential_motion()),
        ],
    };
    out!(
        "subfit bench sequence: {} frames of ~{} vertices, {} control points, {} markers",
        a.frames,
        a.vertices,
        a.control_points,
        a.markers
    );
    let mut rows = Vec::new();
    for (name, params) in motions {
        let mut params = DeformingParams {
            frames: a.frames as usize,
            ..params
        };
        if let Some(v) = a.twist {
            params.twist = v;
        }
        if let Some(v) = a.bend {
            params.bend = v;
        }
        if let Some(v) = a.thickness {
            params.thickness = v;
        }
        let seq = DeformingSequence::new(params).context("sequence parameters")?;
        for views in [a.silhouette_views as usize, 0] {
            rows.push(run_one(&a, name, &seq, views)?);
        }
    }
    out!();
    out!(
        "{:<9} {:>5} {:>12} {:>12} {:>11} {:>11} {:>9} {:>10}",
        "motion",
        "views",
        "worst RMS",
        "worst max",
        "drift max",
        "drift RMS",
        "s/frame",
        "template s"
    );
    for r in &rows {
        out!(
            "{:<9} {:>5} {:>11.4}% {:>11.4}% {:>10.3}% {:>10.3}% {:>9.2} {:>10.2}",
            r.motion,
            r.views,
            100.0 * r.worst_rms,
            100.0 * r.worst_max,
            100.0 * r.drift_max,
            100.0 * r.drift_rms,
            r.seconds_per_frame,
            r.template_seconds
        );
    }
    out!(
        "(fractions of each frame's bounding-box diagonal; goals: RMS ≤ 0.1%, drift ≤ 1%, ≤ 2 s per frame; Xie et al. 2023: 12.9–17 s per frame on a GPU)"
    );
    Ok(ExitCode::SUCCESS)
}

/// `count` markers spread over `frame0`, at their true places in every frame of `seq`.
fn markers(
    seq: &DeformingSequence,
    frame0: &Frame,
    count: usize,
) -> Vec<subfit::MarkerObservation> {
    let mut out = Vec::new();
    for i in frame0.spread_vertices(count) {
        for t in 0..seq.len() {
            out.push(subfit::MarkerObservation {
                frame: t,
                marker: format!("v{i}"),
                position: seq.deform(t, frame0.material[i]),
            });
        }
    }
    out
}

fn run_one(
    a: &BenchSequenceArgs,
    motion: &'static str,
    seq: &DeformingSequence,
    views: usize,
) -> anyhow::Result<Row> {
    let frame0 = seq.frame(0, a.vertices as usize, a.seed);
    let lookup = MaterialLookup::new(&frame0);
    let n = a.control_points as usize;
    let mut template_fit = FitScanOptions {
        control_points: Some(n),
        ..FitScanOptions::default()
    };
    template_fit.stages.max_control_points = n;
    let d = SequenceOptions::default();
    let options = SequenceOptions {
        template_fit,
        silhouette: SilhouetteOptions {
            views,
            weight: a.silhouette_weight.unwrap_or(d.silhouette.weight),
            ..SilhouetteOptions::default()
        },
        arap: a.arap.unwrap_or(d.arap),
        arap_start: a.arap_start.unwrap_or(d.arap_start),
        iterations: a.iterations.map_or(d.iterations, |k| k as usize),
        tracking: a
            .track_nodes
            .map_or(d.tracking.clone(), crate::commands::sequence::tracking)
            .map(|t| subfit::TrackingOptions {
                markers: markers(seq, &frame0, a.markers as usize),
                ..t
            }),
        cancel: crate::interrupt::token(),
        ..d
    };
    let frames = (0..seq.len()).map(|i| {
        let mesh = if i == 0 {
            frame0.mesh.clone()
        } else {
            seq.frame(i, a.vertices as usize, a.seed.wrapping_add(i as u64))
                .mesh
        };
        Input::Mesh {
            mesh,
            name: format!("{motion} frame {i}"),
        }
    });
    let bar = crate::progress::bar(seq.len() as u64, &format!("{motion}, {views} views"));
    let mut on_frame = |f: subfit::SequenceFrame<'_>| -> Result<(), subfit::Error> {
        bar.set_message(format!(
            "frame {}: E_rms {:.3}% ({:.2} s)",
            f.report.index,
            100.0 * f.report.two_sided.e_rms_fraction_of_diagonal,
            f.report.timings_s.total
        ));
        bar.inc(1);
        Ok(())
    };
    let mut warn = |m: &str| bar.suspend(|| eprintln!("subfit: warning: {m}"));
    let result = fit_sequence(frames, &options, &mut on_frame, &mut warn);
    bar.finish_and_clear();
    let fitted = result?;
    let tracked = fitted.limit_points(0)?;
    let drift = seq.drift(&tracked, &lookup);
    let r = &fitted.report;
    for f in &r.frames {
        let d = &drift.frames[f.index];
        out!(
            "{motion:<9} views {views:>2} frame {:>3}: two-sided E_rms {:.4}% E_max {:.4}%, drift max {:.3}% RMS {:.3}%, tangential motion {:.3}%, {} iterations, {:.2} s",
            f.index,
            100.0 * f.two_sided.e_rms_fraction_of_diagonal,
            100.0 * f.two_sided.e_max_fraction_of_diagonal,
            100.0 * d.max_relative,
            100.0 * d.rms_relative,
            100.0 * f.drift.tangential_motion_rms,
            f.iterations,
            f.timings_s.total
        );
    }
    if let Some(dir) = &a.output {
        let d = dir.join(format!("{motion}-{views}-views"));
        std::fs::create_dir_all(&d).with_context(|| format!("{}", d.display()))?;
        fitted.write_into(&d, 24.0)?;
    }
    let template_seconds = r.frames.first().map_or(0.0, |f| f.timings_s.total);
    Ok(Row {
        motion,
        views,
        worst_rms: r.worst_rms_fraction_of_diagonal,
        worst_max: r.worst_max_fraction_of_diagonal,
        drift_max: drift.max_relative(),
        drift_rms: drift
            .frames
            .iter()
            .map(|f| f.rms_relative)
            .fold(0.0, f64::max),
        seconds_per_frame: r.mean_seconds_per_frame,
        template_seconds,
    })
}
