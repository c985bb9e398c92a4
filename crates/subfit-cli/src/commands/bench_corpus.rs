//! `subfit bench corpus [DIR]`: translate the flags into [`subfit_bench::Settings`], score the
//! corpus with [`subfit_bench::score_all`] (a line per entry on stderr as it finishes), add the
//! peers, compare with the baseline, and write the scoreboard as JSON and Markdown.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{bail, Context};
use subfit_bench::markdown::{pct, render, summary_table};
use subfit_bench::{child::Runner, judge::JudgeOptions, manifest, Row, Scoreboard, Settings};

use crate::cli::BenchCorpusArgs;

/// The baseline looked for when `--baseline` is not given.
const DEFAULT_BASELINE: &str = "bench/corpus-baseline.json";

pub fn run(a: BenchCorpusArgs) -> anyhow::Result<ExitCode> {
    let dir = match &a.dir {
        Some(d) => d.clone(),
        None => std::env::var_os("SUBFIT_CORPUS")
            .map(PathBuf::from)
            .context("no corpus folder given and SUBFIT_CORPUS is not set")?,
    };
    let mut entries = manifest::load(&dir)?;
    if a.quick {
        entries = manifest::quick(&entries);
    }
    if !a.categories.is_empty() {
        entries.retain(|e| a.categories.contains(&e.category));
    }
    if !a.entries.is_empty() {
        for n in &a.entries {
            if !entries.iter().any(|e| &e.name == n) {
                bail!("{}: no entry named `{n}`", dir.display());
            }
        }
        entries.retain(|e| a.entries.contains(&e.name));
    }
    if entries.is_empty() {
        bail!("{}: no entry left to score", dir.display());
    }
    let baseline = baseline(&a)?;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let jobs = a.jobs as usize;
    let threads = (jobs > 1).then(|| (cores / jobs).max(1));
    let work = a.work.clone().unwrap_or_else(|| runs_dir(&a.out));
    let settings = Settings {
        runner: Runner {
            exe: match &a.subfit {
                Some(p) => p.clone(),
                None => std::env::current_exe().context("cannot locate the subfit executable")?,
            },
            timeout: Duration::from_secs(a.timeout),
            threads,
        },
        work,
        judge: JudgeOptions {
            surface_samples: a.surface_samples,
            ..JudgeOptions::default()
        },
        jobs,
        fit_args: a.fit_args.clone(),
    };
    eprintln!(
        "subfit: scoring {} entries of {} ({jobs} at once; runs under {})",
        entries.len(),
        dir.display(),
        settings.work.display()
    );
    let t0 = Instant::now();
    let (mut rows, sources, earlier_seconds) = if a.rows.is_empty() {
        let rows = subfit_bench::score_all(&entries, &settings, &|row, n, total| {
            eprintln!("[{n}/{total}] {}", line(row));
        });
        (rows, Vec::new(), None)
    } else {
        let (rows, sources, seconds) = earlier_rows(&a.rows, &entries, a.peers.is_none())?;
        (rows, sources, Some(seconds))
    };
    if let Some(p) = &a.peers {
        let peers = subfit_bench::peers::read_peers(p).map_err(anyhow::Error::msg)?;
        subfit_bench::peers::add_peers(&mut rows, &peers, p, &settings.judge);
    }
    let mut board = Scoreboard {
        corpus: dir.display().to_string(),
        quick: a.quick,
        jobs,
        threads_per_run: threads,
        cores,
        seconds: earlier_seconds.unwrap_or_else(|| t0.elapsed().as_secs_f64()),
        judge_surface_samples: a.surface_samples,
        fit_args: a.fit_args.clone(),
        rows,
        sources,
        ..Scoreboard::default()
    };
    board.finish(baseline.as_ref());
    write(&a.out, &board)?;
    out!("{}", summary_table(&board.categories));
    for r in &board.regressions {
        out!(
            "regression: {} {}: {:.4e} → {:.4e}{}",
            r.entry,
            r.what,
            r.baseline,
            r.now,
            if r.error { "" } else { " (time)" }
        );
    }
    out!(
        "wrote {} and {} ({:.0} s)",
        a.out.display(),
        a.out.with_extension("md").display(),
        board.seconds
    );
    Ok(if a.fail_on_regression && board.has_error_regression() {
        eprintln!("subfit: errors regressed against the baseline");
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

fn runs_dir(out: &Path) -> PathBuf {
    let stem = out
        .file_stem()
        .map_or("corpus".into(), |s| s.to_string_lossy().to_string());
    out.with_file_name(format!("{stem}-runs"))
}

/// The rows of earlier scoreboards `paths` for `entries`, in the entries' order (a later
/// file's row replaces an earlier one's), with their peers when `keep_peers` — a row without
/// any taking an earlier file's for the same entry, each peer shown at the size it was run at —
/// else without (they are judged again from `--peers`); one line per file saying which rows it gave; the wall seconds of the runs that
/// gave rows, added. Errors: an unreadable file, or an entry none of them holds.
fn earlier_rows(
    paths: &[PathBuf],
    entries: &[subfit_bench::Entry],
    keep_peers: bool,
) -> anyhow::Result<(Vec<Row>, Vec<String>, f64)> {
    let boards = paths
        .iter()
        .map(|p| Scoreboard::read(p).map_err(anyhow::Error::msg))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let mut given = vec![Vec::new(); boards.len()];
    let rows = entries
        .iter()
        .map(|e| {
            let (k, row) = boards
                .iter()
                .enumerate()
                .rev()
                .find_map(|(k, b)| b.rows.iter().find(|r| r.entry == e.name).map(|r| (k, r)))
                .with_context(|| format!("no row for entry `{}` in --rows", e.name))?;
            given[k].push(e.name.clone());
            let mut row = row.clone();
            if !keep_peers {
                row.peers.clear();
            } else if row.peers.is_empty() {
                // A row refreshed by a later run keeps the peers an earlier scoreboard judged.
                if let Some(earlier) = boards[..k].iter().rev().find_map(|b| {
                    b.rows
                        .iter()
                        .find(|r| r.entry == e.name && !r.peers.is_empty())
                }) {
                    row.peers = earlier.peers.clone();
                }
            }
            Ok(row)
        })
        .collect::<anyhow::Result<Vec<Row>>>()?;
    let sources = paths
        .iter()
        .zip(&given)
        .filter(|(_, g)| !g.is_empty())
        .map(|(p, g)| {
            let name = p
                .file_name()
                .map_or(p.display().to_string(), |n| n.to_string_lossy().into());
            format!("`{name}` ({} rows: {})", g.len(), g.join(", "))
        })
        .collect();
    let seconds = boards
        .iter()
        .zip(&given)
        .filter(|(_, g)| !g.is_empty())
        .map(|(b, _)| b.seconds)
        .sum();
    Ok((rows, sources, seconds))
}

fn baseline(a: &BenchCorpusArgs) -> anyhow::Result<Option<Scoreboard>> {
    match &a.baseline {
        Some(p) => Ok(Some(Scoreboard::read(p).map_err(anyhow::Error::msg)?)),
        None if Path::new(DEFAULT_BASELINE).is_file() => Ok(Some(
            Scoreboard::read(Path::new(DEFAULT_BASELINE)).map_err(anyhow::Error::msg)?,
        )),
        None => Ok(None),
    }
}

fn write(out: &Path, board: &Scoreboard) -> anyhow::Result<()> {
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).with_context(|| parent.display().to_string())?;
    }
    let json = serde_json::to_string_pretty(board)?;
    subfit::io::write_atomic(out, json.as_bytes())?;
    subfit::io::write_atomic(&out.with_extension("md"), render(board).as_bytes())?;
    Ok(())
}

/// The progress line of a finished row.
fn line(r: &Row) -> String {
    let mut s = format!("{} ({})", r.entry, r.category);
    if let Some(run) = &r.run {
        s += &format!(": exit {}, {:.1} s", run.exit.label(), run.seconds);
    }
    if let Some(c) = &r.cage {
        s += &format!(", {} control points", c.control_points);
    }
    if let Some(j) = &r.judge {
        s += &format!(
            ", RMS {}, Hausdorff {}",
            pct(Some(j.rms_fraction)),
            pct(Some(j.hausdorff_fraction))
        );
    }
    if let Some(read) = &r.read {
        s += &match (&read.message, read.vertices) {
            (Some(m), _) => format!(": refused: {m}"),
            (None, Some(v)) => format!(": read {v} vertices, {} faces", read.faces.unwrap_or(0)),
            _ => String::new(),
        };
    }
    s += match r.pass {
        Some(true) => " — pass",
        Some(false) => " — fail",
        None => "",
    };
    if let Some(n) = &r.note {
        s += &format!(" ({n})");
    }
    s
}
