//! One entry scored: run `subfit` on it as a user would (defaults; a cage pair at the given
//! cage's count (`--control-points` and `--max-control-points`) in its scheme; a sequence
//! through `subfit sequence`), then judge what it wrote
//! against the input with [`crate::judge`], and set the fit's own figures beside the judge's.

use std::path::Path;

use subfit::mesh::{PolyMesh, Tags};
use subfit::subdiv::Scheme;

use crate::cage_stats::{cage_stats, topology, Topology};
use crate::inputs::{
    disagreement, fans, read_cage, read_model, read_model_typed, reference_of, scheme_named,
};
use crate::judge::{judge, Candidate, JudgeOptions};
use crate::manifest::{Entry, Job};
use crate::row::{criteria, passes, Judged, ReadCheck, ReportFigures, Row};
use crate::Settings;

/// Scores `entry`, its runs and outputs under `work/<entry>/`.
pub fn score(entry: &Entry, settings: &Settings) -> Row {
    let dir = settings.work.join(&entry.name);
    let mut row = match &entry.job {
        Job::Fit { input } => fit_row(entry, input, &dir, settings),
        Job::CagePair { control, dense } => pair_row(entry, control, dense, &dir, settings),
        Job::Sequence { frames } => crate::sequence::sequence_row(entry, frames, &dir, settings),
        Job::Read { input } => read_row(entry, input),
    };
    row.pass = passes(&row, criteria(&entry.category));
    row
}

fn report_json(dir: &Path) -> Option<serde_json::Value> {
    let text = std::fs::read_to_string(dir.join("report.json")).ok()?;
    serde_json::from_str(&text).ok()
}

/// The figures of a fit's `report.json` (`final.two_sided`).
fn report_figures(r: &serde_json::Value) -> Option<ReportFigures> {
    let t = &r["final"]["two_sided"];
    Some(ReportFigures {
        rms_fraction: t["e_rms_fraction_of_diagonal"].as_f64()?,
        hausdorff_fraction: t["e_max_fraction_of_diagonal"].as_f64()?,
        tolerance_reached: r["tolerance_reached"].as_bool().unwrap_or(false),
    })
}

fn judge_options(settings: &Settings) -> JudgeOptions {
    settings.judge
}

fn input_topology(entry: &Entry, mesh: &PolyMesh) -> Option<Topology> {
    match (entry.genus, entry.boundary_loops) {
        (Some(genus), Some(boundary_loops)) => Some(Topology {
            genus,
            boundary_loops,
        }),
        _ if !mesh.faces.is_empty() => topology(mesh),
        _ => None,
    }
}

fn fit_row(entry: &Entry, input: &Path, dir: &Path, settings: &Settings) -> Row {
    let mesh = read_model(input);
    let kind = match &mesh {
        Ok(m) if m.faces.is_empty() => "points",
        _ => "mesh",
    };
    let mut row = Row::new(
        &entry.name,
        &entry.category,
        kind,
        input.display().to_string(),
    );
    let out = dir.join("fit");
    let mut args = vec![
        "fit".to_string(),
        input.display().to_string(),
        "-o".into(),
        out.display().to_string(),
    ];
    args.extend(settings.fit_args.iter().cloned());
    judge_fit(&mut row, entry, mesh, &args, &out, dir, settings);
    row
}

/// Runs `args` (a `subfit fit`), then judges `out/control.obj` against `mesh`.
fn judge_fit(
    row: &mut Row,
    entry: &Entry,
    mesh: Result<PolyMesh, String>,
    args: &[String],
    out: &Path,
    dir: &Path,
    settings: &Settings,
) {
    let run = match settings.runner.run(args, dir) {
        Ok(r) => r,
        Err(e) => {
            row.note = Some(format!(
                "could not run {}: {e}",
                settings.runner.exe.display()
            ));
            return;
        }
    };
    let wrote = run.exit.wrote();
    row.run = Some(run);
    let mesh = match mesh {
        Ok(m) => m,
        Err(e) => {
            row.note = Some(format!("the judge cannot read the input: {e}"));
            return;
        }
    };
    row.input_topology = input_topology(entry, &mesh);
    if !wrote {
        return;
    }
    let Some(report) = report_json(out) else {
        row.note = Some("no report.json".into());
        return;
    };
    row.report = report_figures(&report);
    let scheme = report["options"]["scheme"]
        .as_str()
        .and_then(scheme_named)
        .unwrap_or(Scheme::Loop);
    let candidate = match read_cage(&out.join("control.obj"), scheme) {
        Ok(c) => c,
        Err(e) => {
            row.note = Some(format!("cannot read the cage: {e}"));
            return;
        }
    };
    if let Candidate::Limit { cage, tags, .. } = &candidate {
        let stats = cage_stats(cage, tags);
        row.topology_kept = match (row.input_topology, stats.topology) {
            (Some(a), Some(b)) => Some(a == b),
            _ => None,
        };
        row.cage = Some(stats);
    }
    match judge(&reference_of(&mesh), &candidate, &judge_options(settings)) {
        Ok(j) => {
            row.disagreement = row
                .report
                .as_ref()
                .map(|r| disagreement(j.rms_fraction, j.hausdorff_fraction, r));
            row.judge = Some(j);
        }
        Err(e) => row.note = Some(format!("the judge failed: {e}")),
    }
}

fn pair_row(entry: &Entry, control: &Path, dense: &Path, dir: &Path, settings: &Settings) -> Row {
    let mut row = Row::new(
        &entry.name,
        &entry.category,
        "cage-pair",
        dense.display().to_string(),
    );
    let given = match read_model(control) {
        Ok(m) => m,
        Err(e) => {
            row.note = Some(format!("cannot read the given cage: {e}"));
            return row;
        }
    };
    // A cage whose faces disagree in orientation has no limit surface until they agree; the
    // fit's reader repairs the same on its inputs, so the given cage is repaired alike.
    let (given, reoriented) = match subfit::mesh::reorient_faces(
        &given.faces,
        given.num_vertices(),
        Some(&given.positions),
    ) {
        Ok((faces, report)) if report.needed => (
            PolyMesh { faces, ..given },
            Some(format!(
                "given cage: {} faces re-oriented to agree with their neighbours",
                report.flipped_faces
            )),
        ),
        _ => (given, None),
    };
    let tags =
        subfit::io::read_tags_file(control, given.num_vertices()).unwrap_or_else(|_| Tags::new());
    // The given cage's scheme: Loop for a triangle cage, Catmull-Clark otherwise.
    let scheme = if given.faces.is_triangles() {
        Scheme::Loop
    } else {
        Scheme::CatmullClark
    };
    let mesh = read_model(dense);
    let out = dir.join("fit");
    let mut args = vec![
        "fit".to_string(),
        dense.display().to_string(),
        "-o".into(),
        out.display().to_string(),
        "--max-control-points".into(),
        given.num_vertices().to_string(),
        // At the given cage's count: the comparison is per control point.
        "--control-points".into(),
        given.num_vertices().to_string(),
        "--scheme".into(),
        if scheme == Scheme::Loop {
            "loop".into()
        } else {
            "catmull-clark".into()
        },
    ];
    args.extend(settings.fit_args.iter().cloned());
    if let Ok(m) = &mesh {
        let stats = cage_stats(&given, &tags);
        let candidate = Candidate::limit(given.clone(), tags.clone(), scheme);
        let j = judge(&reference_of(m), &candidate, &judge_options(settings));
        row.given = Some(Judged {
            by: "given".into(),
            stats,
            error: j.as_ref().err().map(|e| e.to_string()),
            judge: j.ok(),
            seconds: None,
        });
    }
    judge_fit(&mut row, entry, mesh, &args, &out, dir, settings);
    if let Some(r) = reoriented {
        row.note = Some(match row.note.take() {
            Some(n) => format!("{n}; {r}"),
            None => r,
        });
    }
    row
}

fn read_row(entry: &Entry, input: &Path) -> Row {
    let mut row = Row::new(
        &entry.name,
        &entry.category,
        "read",
        input.display().to_string(),
    );
    row.read = Some(match read_model_typed(input) {
        Ok(m) => {
            let (v, f) = (m.num_vertices(), m.faces.len());
            let counts_match = match (entry.vertices, entry.faces) {
                (Some(ev), Some(ef)) => Some(ev == v && ef == f),
                (Some(ev), None) => Some(ev == v),
                _ => None,
            };
            ReadCheck {
                read: true,
                vertices: Some(v),
                faces: Some(f),
                counts_match,
                message: None,
                cut_short: false,
            }
        }
        Err(e) => ReadCheck {
            read: false,
            vertices: None,
            faces: None,
            counts_match: Some(false),
            cut_short: matches!(e.kind, subfit::io::ErrorKind::Truncated(_)),
            message: Some(e.to_string()),
        },
    });
    row
}

/// Judges a peer's output `file` (`kind` `mesh`: its triangles as they are; `limit`: a cage
/// whose `scheme` limit surface is the result) against the entry's input.
pub fn judge_peer(
    input: &Path,
    by: &str,
    file: &Path,
    kind: &str,
    scheme: Option<Scheme>,
    seconds: Option<f64>,
    options: &JudgeOptions,
) -> Judged {
    let fail = |error: String| Judged {
        by: by.into(),
        stats: Default::default(),
        judge: None,
        seconds,
        error: Some(error),
    };
    let reference = match read_model(input) {
        Ok(m) => reference_of(&m),
        Err(e) => return fail(e),
    };
    let mesh = match read_model(file) {
        Ok(m) => m,
        Err(e) => return fail(e),
    };
    let tags =
        subfit::io::read_tags_file(file, mesh.num_vertices()).unwrap_or_else(|_| Tags::new());
    let stats = cage_stats(&mesh, &tags);
    let candidate = if kind == "limit" {
        Candidate::limit(mesh, tags, scheme.unwrap_or(Scheme::CatmullClark))
    } else {
        Candidate::Mesh {
            triangles: fans(&mesh),
            positions: mesh.positions,
        }
    };
    match judge(&reference, &candidate, options) {
        Ok(j) => Judged {
            by: by.into(),
            stats,
            judge: Some(j),
            seconds,
            error: None,
        },
        Err(e) => Judged {
            stats,
            ..fail(e.to_string())
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schemes_are_named_as_reports_and_the_cli_name_them() {
        assert_eq!(scheme_named("Loop"), Some(Scheme::Loop));
        assert_eq!(scheme_named("CatmullClark"), Some(Scheme::CatmullClark));
        assert_eq!(scheme_named("catmull-clark"), Some(Scheme::CatmullClark));
        assert_eq!(scheme_named("QuadTriangle"), Some(Scheme::QuadTriangle));
        assert_eq!(scheme_named("quad-tri"), Some(Scheme::QuadTriangle));
        assert_eq!(scheme_named("bilinear"), None);
    }

    #[test]
    fn disagreement_is_relative_to_the_judge() {
        let r = ReportFigures {
            rms_fraction: 1.1e-3,
            hausdorff_fraction: 0.9e-2,
            tolerance_reached: true,
        };
        assert!((disagreement(1e-3, 1e-2, &r) - 0.1).abs() < 1e-12);
        // Two exact fits (round-off apart) agree.
        let exact = ReportFigures {
            rms_fraction: 2e-9,
            hausdorff_fraction: 1e-8,
            tolerance_reached: true,
        };
        assert!(disagreement(1e-9, 3e-8, &exact) < 0.01);
    }

    /// A file variant passes when it reads with the manifest's counts, or when it is cut short
    /// and refused for it; any other refusal fails.
    #[test]
    fn a_cut_short_file_is_rightly_refused_and_a_syntax_error_is_not() {
        let d = tempfile::tempdir().unwrap();
        let entry = |name: &str| Entry {
            name: name.into(),
            category: "refused".into(),
            job: Job::Read {
                input: d.path().join(name),
            },
            vertices: Some(2),
            faces: None,
            genus: None,
            boundary_loops: None,
            bytes: 0,
        };
        let cases = [
            ("whole.xyz", "0 0 0\n1 0 0\n", true, false),
            ("cut.xyz", "0 0 0\n1 0 0\n0.5 0.", true, true),
            ("words.xyz", "0 0 0\nx y z\n", false, false),
        ];
        for (name, text, pass, cut) in cases {
            std::fs::write(d.path().join(name), text).unwrap();
            let e = entry(name);
            let Job::Read { input } = &e.job else {
                unreachable!()
            };
            let row = read_row(&e, input);
            let read = row.read.as_ref().unwrap();
            assert_eq!(read.cut_short, cut, "{name}: {read:?}");
            assert_eq!(
                passes(&row, criteria("refused")),
                Some(pass),
                "{name}: {read:?}"
            );
        }
    }

    #[test]
    fn fans_split_polygons() {
        let m = subfit::mesh::shapes::cube_mesh(1.0);
        assert_eq!(fans(&m).len(), 12);
    }
}
