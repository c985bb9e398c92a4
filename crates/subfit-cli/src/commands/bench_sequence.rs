//! `subfit bench sequence`: figures on generated sequences with known correspondence
//! (`subfit::mesh::deforming`): the tube whose bulges travel over its material (the moderate
//! and the large tangential motion) and the dancing articulated figure (`--motion dance`,
//! `--stride 5` for fast motion, `--points N` for frames of fresh random points without
//! normals, like a capture); every mesh frame has its own resolution. One cage is fitted to all
//! frames with [`subfit::fit_sequence`], once with the silhouette term and once without.
//! Prints per run the worst two-sided RMS, the drift of the tracked limit points (the control
//! vertices' limit points located on frame 0, compared in every frame with where their
//! material point went; RMS, 95th percentile and largest, fraction of the frame's diagonal)
//! and the seconds per frame, beside Xie et al. 2023's 12.9–17 s per frame on a GPU.

use std::process::ExitCode;

use anyhow::Context;
use subfit::mesh::deforming::{
    drift, DanceParams, DancingFigure, DeformingParams, DeformingSequence, Frame, MaterialLookup,
    MaterialMotion, SameConnectivity,
};
use subfit::{fit_sequence, FitScanOptions, Input, SequenceOptions, SilhouetteOptions};

use crate::cli::{BenchSequenceArgs, MotionArg};

/// One run's figures.
struct Row {
    motion: &'static str,
    views: usize,
    worst_rms: f64,
    worst_max: f64,
    drift_max: f64,
    drift_p95: f64,
    drift_rms: f64,
    seconds_per_frame: f64,
    cpu_seconds_per_frame: f64,
    template_seconds: f64,
}

/// CPU seconds (user + system, all threads) this process has used so far, from
/// `/proc/self/stat` (Linux; clock ticks of 1/100 s, the kernel's `USER_HZ`); `None`
/// elsewhere. On a machine shared with other work, wall-clock seconds per frame measure the
/// load as much as the code; CPU seconds do not, and on an idle 2-core machine the wall-clock
/// time is at most the CPU time (the process never waits on anything but the CPU).
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) in parentheses.
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

/// A generated sequence: the tube or the dancing figure.
enum Generated {
    Tube(DeformingSequence),
    Dance(Box<DancingFigure>),
    /// Frames read from files, their ground truth by shared connectivity.
    Files(SameConnectivity, Vec<std::path::PathBuf>),
}

impl Generated {
    fn len(&self) -> usize {
        match self {
            Self::Tube(s) => s.len(),
            Self::Dance(d) => d.len(),
            Self::Files(s, _) => s.len(),
        }
    }

    fn motion(&self) -> &dyn MaterialMotion {
        match self {
            Self::Tube(s) => s,
            Self::Dance(d) => d.as_ref(),
            Self::Files(s, _) => s,
        }
    }

    /// Frame `i` as a mesh of about `vertices` vertices, or as `points` points (if > 0).
    fn frame(&self, i: usize, vertices: usize, points: usize, seed: u64) -> Frame {
        match self {
            Self::Tube(s) => s.frame(i, vertices, seed),
            Self::Dance(d) if points > 0 => d.points(i, points, seed),
            Self::Dance(d) => d.frame(i, vertices, seed),
            Self::Files(s, _) => s.first_frame(),
        }
    }

    /// Frame `i` as the sequence's input.
    fn input(&self, i: usize, vertices: usize, points: usize, seed: u64, name: &str) -> Input {
        match self {
            Self::Files(_, paths) => Input::File(paths[i].clone()),
            _ => Input::Mesh {
                mesh: self.frame(i, vertices, points, seed).mesh,
                name: format!("{name} frame {i}"),
            },
        }
    }
}

pub fn run(a: BenchSequenceArgs) -> anyhow::Result<ExitCode> {
    let tube = |p: DeformingParams| -> anyhow::Result<Generated> {
        let mut params = DeformingParams {
            frames: a.frames as usize,
            ..p
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
        Ok(Generated::Tube(
            DeformingSequence::new(params).context("sequence parameters")?,
        ))
    };
    let motions: Vec<(&'static str, Generated)> = if !a.meshes.is_empty() {
        vec![("files", read_meshes(&a.meshes)?)]
    } else {
        match a.motion {
            MotionArg::Moderate => vec![("moderate", tube(DeformingParams::default())?)],
            MotionArg::Large => vec![("large", tube(DeformingParams::large_tangential_motion())?)],
            MotionArg::Both => vec![
                ("moderate", tube(DeformingParams::default())?),
                ("large", tube(DeformingParams::large_tangential_motion())?),
            ],
            MotionArg::Dance => vec![(
                "dance",
                Generated::Dance(Box::new(
                    DancingFigure::new(DanceParams {
                        frames: a.frames as usize,
                        stride: a.stride as usize,
                        ..DanceParams::default()
                    })
                    .context("dance parameters")?,
                )),
            )],
        }
    };
    if a.points > 0 && (a.motion != MotionArg::Dance || !a.meshes.is_empty()) {
        anyhow::bail!("--points: point frames are generated for --motion dance only");
    }
    let frames_as = if !a.meshes.is_empty() {
        "files".to_string()
    } else if a.points > 0 {
        format!("{} points without normals", a.points)
    } else {
        format!("~{} vertices", a.vertices)
    };
    out!(
        "subfit bench sequence: {} frames of {frames_as}, stride {}, {} control points, {} markers",
        motions.first().map_or(0, |m| m.1.len()),
        a.stride,
        a.control_points
            .map_or("default".to_string(), |n| n.to_string()),
        a.markers
    );
    let views: Vec<usize> = match a.only_views {
        Some(v) => vec![v as usize],
        None => vec![a.silhouette_views as usize, 0],
    };
    let mut rows = Vec::new();
    for (name, seq) in &motions {
        for &v in &views {
            rows.push(run_one(&a, name, seq, v)?);
        }
    }
    out!();
    out!(
        "{:<9} {:>5} {:>10} {:>10} {:>10} {:>10} {:>10} {:>8} {:>9} {:>10}",
        "motion",
        "views",
        "worst RMS",
        "worst max",
        "drift RMS",
        "drift p95",
        "drift max",
        "s/frame",
        "CPU s/fr",
        "template s"
    );
    for r in &rows {
        out!(
            "{:<9} {:>5} {:>9.4}% {:>9.4}% {:>9.3}% {:>9.3}% {:>9.3}% {:>8.2} {:>9.2} {:>10.2}",
            r.motion,
            r.views,
            100.0 * r.worst_rms,
            100.0 * r.worst_max,
            100.0 * r.drift_rms,
            100.0 * r.drift_p95,
            100.0 * r.drift_max,
            r.seconds_per_frame,
            r.cpu_seconds_per_frame,
            r.template_seconds
        );
    }
    out!(
        "(fractions of each frame's bounding-box diagonal, worst frame; s/frame: wall clock, CPU s/fr: CPU seconds of all threads, both after the first frame; goals: RMS ≤ 0.1%, drift RMS ≤ 1% and p95 ≤ 2%, ≤ 2 s per frame; Xie et al. 2023: 12.9–17 s per frame on a GPU)"
    );
    Ok(ExitCode::SUCCESS)
}

/// The frames of `paths`, which must share one connectivity (checked).
fn read_meshes(paths: &[std::path::PathBuf]) -> anyhow::Result<Generated> {
    let meshes = paths
        .iter()
        .map(|p| {
            subfit::io::read_file(p, &subfit::io::ReadOptions::default())
                .map(|(m, _)| m)
                .with_context(|| format!("{}", p.display()))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let truth = SameConnectivity::new(&meshes).map_err(|e| {
        anyhow::anyhow!(
            "{}: the frames cannot give the drift: {e}",
            paths[e.frame].display()
        )
    })?;
    Ok(Generated::Files(truth, paths.to_vec()))
}

/// `count` markers spread over `frame0`, at their true places in every frame of `seq`.
fn markers(seq: &Generated, frame0: &Frame, count: usize) -> Vec<subfit::MarkerObservation> {
    let mut out = Vec::new();
    let picks = frame0.spread_vertices(count);
    let material: Vec<[f64; 3]> = picks.iter().map(|&i| frame0.material[i]).collect();
    for t in 0..seq.len() {
        let moved = seq.motion().deform_all(t, &material);
        for (&i, position) in picks.iter().zip(moved) {
            out.push(subfit::MarkerObservation {
                frame: t,
                marker: format!("v{i}"),
                position,
            });
        }
    }
    out
}

fn run_one(
    a: &BenchSequenceArgs,
    motion: &'static str,
    seq: &Generated,
    views: usize,
) -> anyhow::Result<Row> {
    let points = a.points as usize;
    let frame0 = seq.frame(0, a.vertices as usize, points, a.seed);
    // The drift's material lookup needs faces: for point frames, a fine mesh of frame 0.
    let lookup = if points > 0 {
        MaterialLookup::new(&seq.frame(0, points.max(a.vertices as usize), 0, a.seed))
    } else {
        MaterialLookup::new(&frame0)
    };
    let n = match seq {
        Generated::Files(..) => a.control_points.map(|n| n as usize),
        _ => Some(a.control_points.unwrap_or(1000) as usize),
    };
    let mut template_fit = FitScanOptions {
        control_points: n,
        ..FitScanOptions::default()
    };
    if let Some(n) = n {
        template_fit.stages.max_control_points = n;
    }
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
    // Generated before the run, so that neither clock counts the generator.
    let frames: Vec<Input> = (0..seq.len())
        .map(|i| {
            if i == 0 && !matches!(seq, Generated::Files(..)) {
                Input::Mesh {
                    mesh: frame0.mesh.clone(),
                    name: format!("{motion} frame 0"),
                }
            } else {
                seq.input(
                    i,
                    a.vertices as usize,
                    points,
                    a.seed.wrapping_add(i as u64),
                    motion,
                )
            }
        })
        .collect();
    let bar = crate::progress::bar(seq.len() as u64, &format!("{motion}, {views} views"));
    let mut cpu = Vec::new();
    let mut on_frame = |f: subfit::SequenceFrame<'_>| -> Result<(), subfit::Error> {
        cpu.push(cpu_seconds().unwrap_or(f64::NAN));
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
    let drift = drift(seq.motion(), &tracked, &lookup);
    let r = &fitted.report;
    for f in &r.frames {
        let d = &drift.frames[f.index];
        out!(
            "{motion:<9} views {views:>2} frame {:>3}: two-sided E_rms {:.4}% E_max {:.4}%, drift RMS {:.3}% p95 {:.3}% max {:.3}%, tangential motion {:.3}%, {} iterations, {:.2} s",
            f.index,
            100.0 * f.two_sided.e_rms_fraction_of_diagonal,
            100.0 * f.two_sided.e_max_fraction_of_diagonal,
            100.0 * d.rms_relative,
            100.0 * d.p95_relative,
            100.0 * d.max_relative,
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
    let cpu_seconds_per_frame = match (cpu.first(), cpu.last()) {
        (Some(a), Some(b)) if cpu.len() > 1 => (b - a) / (cpu.len() - 1) as f64,
        _ => 0.0,
    };
    Ok(Row {
        motion,
        views,
        worst_rms: r.worst_rms_fraction_of_diagonal,
        worst_max: r.worst_max_fraction_of_diagonal,
        drift_max: drift.max_relative(),
        drift_p95: drift.max_p95_relative(),
        drift_rms: drift.max_rms_relative(),
        seconds_per_frame: r.mean_seconds_per_frame,
        cpu_seconds_per_frame,
        template_seconds,
    })
}
