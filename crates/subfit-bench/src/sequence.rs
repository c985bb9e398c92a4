//! A sequence entry: `subfit sequence FRAME...` with defaults, then every frame's cage judged
//! against its frame, and the drift of tracked points where the frames share their
//! connectivity ([`crate::drift`]).

use std::path::{Path, PathBuf};

use crate::cage_stats::cage_stats;
use crate::drift::{locate, measure, same_connectivity};
use crate::inputs::{disagreement, read_cage, read_model, reference_of, scheme_named};
use crate::judge::{judge, Candidate};
use crate::manifest::Entry;
use crate::row::{FrameRow, ReportFigures, Row};
use crate::Settings;

/// Tracked points per sequence for the drift (evenly strided over frame 0's vertices).
pub const DRIFT_POINTS: usize = 5_000;

pub(crate) fn sequence_row(
    entry: &Entry,
    frames: &[PathBuf],
    dir: &Path,
    settings: &Settings,
) -> Row {
    let first = frames
        .first()
        .map_or(String::new(), |f| f.display().to_string());
    let mut row = Row::new(&entry.name, &entry.category, "sequence", first);
    let out = dir.join("sequence");
    let mut args = vec!["sequence".to_string()];
    args.extend(frames.iter().map(|f| f.display().to_string()));
    args.extend(["-o".to_string(), out.display().to_string()]);
    let run = match settings.runner.run(&args, dir) {
        Ok(r) => r,
        Err(e) => {
            row.note = Some(format!(
                "could not run {}: {e}",
                settings.runner.exe.display()
            ));
            return row;
        }
    };
    let wrote = run.exit.wrote();
    row.run = Some(run);
    if !wrote {
        return row;
    }
    let report: Option<serde_json::Value> = std::fs::read_to_string(out.join("report.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    let Some(report) = report else {
        row.note = Some("no report.json".into());
        return row;
    };
    let scheme = report["scheme"]
        .as_str()
        .and_then(scheme_named)
        .unwrap_or_default();
    let meshes: Vec<Result<_, String>> = frames.iter().map(|f| read_model(f)).collect();
    let mut tracked = None;
    for (i, mesh) in meshes.iter().enumerate() {
        let mut frame = FrameRow {
            index: i,
            judge: None,
            report: frame_figures(&report, i),
            drift: None,
        };
        let cage = read_cage(&out.join(subfit::frame_file_name(i)), scheme);
        match (mesh, cage) {
            (Ok(mesh), Ok(cage)) => {
                if i == 0 {
                    if let Candidate::Limit { cage: c, tags, .. } = &cage {
                        row.cage = Some(cage_stats(c, tags));
                    }
                    if meshes.iter().flatten().all(|m| same_connectivity(mesh, m)) {
                        tracked = locate(&cage, mesh, DRIFT_POINTS, &settings.judge).ok();
                    }
                }
                frame.judge = judge(&reference_of(mesh), &cage, &settings.judge).ok();
                frame.drift = tracked.as_ref().and_then(|t| measure(t, &cage, mesh).ok());
            }
            (Err(e), _) => {
                row.note.get_or_insert(format!("frame {i}: {e}"));
            }
            (_, Err(e)) => {
                row.note.get_or_insert(format!("frame {i}: {e}"));
            }
        }
        row.frames.push(frame);
    }
    worst_frame(&mut row);
    row
}

fn frame_figures(report: &serde_json::Value, i: usize) -> Option<ReportFigures> {
    let f = &report["frames"][i];
    let t = &f["two_sided"];
    Some(ReportFigures {
        rms_fraction: t["e_rms_fraction_of_diagonal"].as_f64()?,
        hausdorff_fraction: t["e_max_fraction_of_diagonal"].as_f64()?,
        tolerance_reached: f["tolerance_reached"].as_bool().unwrap_or(false),
    })
}

/// The row's judge and report are its worst frame's (by RMS).
fn worst_frame(row: &mut Row) {
    let worst = row
        .frames
        .iter()
        .filter(|f| f.judge.is_some())
        .max_by(|a, b| {
            let r = |f: &FrameRow| f.judge.as_ref().map_or(0.0, |j| j.rms_fraction);
            r(a).total_cmp(&r(b))
        });
    if let Some(w) = worst {
        row.judge = w.judge;
        row.report = w.report;
        row.disagreement = match (&w.judge, &w.report) {
            (Some(j), Some(r)) => Some(disagreement(j.rms_fraction, j.hausdorff_fraction, r)),
            _ => None,
        };
    }
}
