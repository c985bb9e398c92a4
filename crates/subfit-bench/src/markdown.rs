//! The scoreboard as Markdown: the per-category summary, then one table per kind of row
//! (fits, cage pairs, sequences, read checks), then the regressions against the baseline.

use std::fmt::Write;

use crate::row::{Judged, Row, DISAGREEMENT_FLAG};
use crate::summary::CategorySummary;
use crate::Scoreboard;

/// A fraction of the diagonal as a percentage with three significant digits.
pub fn pct(x: Option<f64>) -> String {
    match x {
        Some(v) if v.is_finite() => {
            let p = v * 100.0;
            if p >= 10.0 {
                format!("{p:.1}%")
            } else if p >= 0.1 {
                format!("{p:.2}%")
            } else {
                format!("{p:.3}%")
            }
        }
        _ => "–".into(),
    }
}

fn num(x: Option<f64>, digits: usize) -> String {
    x.filter(|v| v.is_finite())
        .map_or("–".into(), |v| format!("{v:.digits$}"))
}

/// The per-category summary table (the README shows it).
pub fn summary_table(categories: &[CategorySummary]) -> String {
    let mut s = String::new();
    s.push_str("| category | rows | pass | exits | median RMS | worst RMS | median Hausdorff | worst Hausdorff | median s | median cps | best peer median RMS / Hausdorff | ours better than best peer |\n");
    s.push_str("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for c in categories {
        let exits: Vec<String> = c.exits.iter().map(|(k, v)| format!("{k}: {v}")).collect();
        let peers = if c.rows_with_peers == 0 {
            "–".to_string()
        } else {
            format!(
                "{} / {}",
                pct(c.peer_median_rms_fraction),
                pct(c.peer_median_hausdorff_fraction)
            )
        };
        let better = if c.rows_with_peers == 0 {
            "–".to_string()
        } else {
            format!("{} of {}", c.better_than_peers, c.rows_with_peers)
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} ({:.0}%) | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            c.category,
            c.rows,
            c.passed,
            100.0 * c.share_passed,
            exits.join(", "),
            pct(c.median_rms_fraction),
            pct(c.worst_rms_fraction),
            pct(c.median_hausdorff_fraction),
            pct(c.worst_hausdorff_fraction),
            num(c.median_seconds, 1),
            num(c.median_control_points, 0),
            peers,
            better,
        );
    }
    s
}

fn pass_mark(p: Option<bool>) -> &'static str {
    match p {
        Some(true) => "yes",
        Some(false) => "**no**",
        None => "–",
    }
}

fn peer_cell(p: Option<&Judged>) -> String {
    match p {
        Some(p) => match &p.judge {
            Some(j) => format!(
                "{}: {} / {} ({} v, {} s)",
                p.by,
                pct(Some(j.rms_fraction)),
                pct(Some(j.hausdorff_fraction)),
                p.stats.control_points,
                num(p.seconds, 1)
            ),
            None => format!("{}: failed", p.by),
        },
        None => "–".into(),
    }
}

fn fit_table(s: &mut String, rows: &[&Row]) {
    s.push_str("| entry | cat | exit | s | MB | cps | quads | irregular | RMS | Hausdorff | report RMS / H | genus, loops | creases | pass | best peer (RMS / H) | note |\n");
    s.push_str("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for r in rows {
        let run = r.run.as_ref();
        let c = r.cage.as_ref();
        let j = r.judge.as_ref();
        let report = r.report.as_ref().map_or("–".into(), |f| {
            let flag = if r.disagreement.is_some_and(|d| d > DISAGREEMENT_FLAG) {
                " ⚑"
            } else {
                ""
            };
            format!(
                "{} / {}{flag}",
                pct(Some(f.rms_fraction)),
                pct(Some(f.hausdorff_fraction))
            )
        });
        let topo = match (r.input_topology, c.and_then(|c| c.topology)) {
            (Some(a), Some(b)) => format!(
                "{},{} → {},{}{}",
                a.genus,
                a.boundary_loops,
                b.genus,
                b.boundary_loops,
                if a == b { "" } else { " ✗" }
            ),
            (None, Some(b)) => format!("? → {},{}", b.genus, b.boundary_loops),
            _ => "–".into(),
        };
        let note = r
            .note
            .clone()
            .or_else(|| {
                run.filter(|x| !x.exit.wrote())
                    .map(|x| x.stderr_tail.lines().last().unwrap_or("").to_string())
            })
            .unwrap_or_default()
            .replace('|', "/");
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.entry,
            r.category,
            run.map_or("–".into(), |x| x.exit.label()),
            num(run.map(|x| x.seconds), 1),
            num(run.and_then(|x| x.peak_memory_mb), 0),
            c.map_or("–".into(), |c| c.control_points.to_string()),
            c.map_or("–".into(), |c| format!("{:.0}%", 100.0 * c.quad_fraction)),
            c.map_or("–".into(), |c| c.irregular_vertices.to_string()),
            pct(j.map(|j| j.rms_fraction)),
            pct(j.map(|j| j.hausdorff_fraction)),
            report,
            topo,
            c.map_or("–".into(), |c| format!(
                "{}+{}",
                c.crease_edges, c.corners
            )),
            pass_mark(r.pass),
            peer_cell(r.best_peer()),
            truncate(&note, 120),
        );
    }
}

fn truncate(s: &str, n: usize) -> String {
    if s.chars().count() <= n {
        s.to_string()
    } else {
        format!("{}…", s.chars().take(n).collect::<String>())
    }
}

fn pair_table(s: &mut String, rows: &[&Row]) {
    s.push_str("| pair | exit | ours: cps / quads / irregular | ours RMS / H | given: cps / quads / irregular | given RMS / H | QuadriFlow + fit: cps / quads / irregular, RMS / H | pass |\n");
    s.push_str("|---|---|---|---|---|---|---|---|\n");
    for r in rows {
        let g = r.given.as_ref();
        let stats = |c: Option<&crate::cage_stats::CageStats>| {
            c.map_or("–".into(), |c| {
                format!(
                    "{} / {:.0}% / {}",
                    c.control_points,
                    100.0 * c.quad_fraction,
                    c.irregular_vertices
                )
            })
        };
        let errs = |j: Option<&crate::judge::Judgement>| {
            format!(
                "{} / {}",
                pct(j.map(|j| j.rms_fraction)),
                pct(j.map(|j| j.hausdorff_fraction))
            )
        };
        // The remesher a user would try for a quad cage, fitted at about the same count.
        let quadriflow = r
            .peers
            .iter()
            .find(|p| p.by == "quadriflow")
            .map_or("–".into(), |p| match &p.judge {
                Some(j) => format!("{}, {}", stats(Some(&p.stats)), errs(Some(j))),
                None => "failed".into(),
            });
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            r.entry,
            r.exit().map_or("–".into(), |e| e.label()),
            stats(r.cage.as_ref()),
            errs(r.judge.as_ref()),
            stats(g.map(|g| &g.stats)),
            errs(g.and_then(|g| g.judge.as_ref())),
            quadriflow,
            pass_mark(r.pass),
        );
    }
}

fn sequence_table(s: &mut String, rows: &[&Row]) {
    s.push_str("| sequence | exit | frames | s | cps | worst frame RMS / H | drift RMS (worst frame) | drift p95 (worst frame) | pass |\n");
    s.push_str("|---|---|---|---|---|---|---|---|---|\n");
    for r in rows {
        let drift = |f: fn(&crate::drift::Drift) -> f64| {
            r.frames
                .iter()
                .filter_map(|x| x.drift.as_ref().map(f))
                .reduce(f64::max)
        };
        let j = r.judge.as_ref();
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} / {} | {} | {} | {} |",
            r.entry,
            r.exit().map_or("–".into(), |e| e.label()),
            r.frames.len(),
            num(r.run.as_ref().map(|x| x.seconds), 1),
            r.cage
                .as_ref()
                .map_or("–".into(), |c| c.control_points.to_string()),
            pct(j.map(|j| j.rms_fraction)),
            pct(j.map(|j| j.hausdorff_fraction)),
            pct(drift(|d| d.rms_fraction)),
            pct(drift(|d| d.p95_fraction)),
            pass_mark(r.pass),
        );
    }
}

fn read_table(s: &mut String, rows: &[&Row]) {
    s.push_str("| file | read | vertices | faces | counts as the manifest | message |\n");
    s.push_str("|---|---|---|---|---|---|\n");
    for r in rows {
        let Some(c) = &r.read else { continue };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} |",
            r.entry,
            match (c.read, c.cut_short) {
                (true, _) => "yes",
                (false, true) => "refused: cut short",
                (false, false) => "refused",
            },
            c.vertices.map_or("–".into(), |v| v.to_string()),
            c.faces.map_or("–".into(), |v| v.to_string()),
            if c.cut_short {
                "– (right to refuse)"
            } else {
                pass_mark(c.counts_match)
            },
            truncate(
                &c.message.clone().unwrap_or_default().replace('|', "/"),
                160
            ),
        );
    }
}

/// The whole scoreboard as Markdown.
pub fn render(board: &Scoreboard) -> String {
    let mut s = String::new();
    let how = if board.sources.is_empty() {
        format!(
            "{} at once ({} thread(s) per run, {} cores), {:.0} s",
            board.jobs,
            board
                .threads_per_run
                .map_or("all".into(), |t| t.to_string()),
            board.cores,
            board.seconds
        )
    } else {
        format!(
            "rows taken from the runs listed below, whose wall times add up to {:.0} s",
            board.seconds
        )
    };
    let _ = writeln!(
        s,
        "# Corpus scoreboard\n\n`{}`{}: {} entries, {how}. Errors are two-sided (the worse direction), judged independently, as % of the input's bounding-box diagonal; `report` is the fit's own measure (⚑: more than {:.0}% apart).\n",
        board.corpus,
        if board.quick { " (quick subset)" } else { "" },
        board.rows.len(),
        100.0 * DISAGREEMENT_FLAG,
    );
    if !board.fit_args.is_empty() {
        let _ = writeln!(
            s,
            "Every `subfit fit` ran with `{}` added (not the defaults).\n",
            board.fit_args.join(" ")
        );
    }
    for source in &board.sources {
        let _ = writeln!(s, "- rows from {source}");
    }
    if !board.sources.is_empty() {
        s.push('\n');
    }
    s.push_str("## Per category\n\n");
    s.push_str(&summary_table(&board.categories));
    let of = |k: &[&str]| -> Vec<&Row> {
        board
            .rows
            .iter()
            .filter(|r| k.contains(&r.kind.as_str()))
            .collect()
    };
    let fits = of(&["mesh", "points"]);
    if !fits.is_empty() {
        s.push_str("\n## Meshes and point clouds\n\n");
        fit_table(&mut s, &fits);
    }
    let pairs = of(&["cage-pair"]);
    if !pairs.is_empty() {
        s.push_str("\n## Cage pairs: ours at the given cage's count against the given cage\n\n");
        pair_table(&mut s, &pairs);
    }
    let seqs = of(&["sequence"]);
    if !seqs.is_empty() {
        s.push_str("\n## Sequences\n\n");
        sequence_table(&mut s, &seqs);
    }
    let reads = of(&["read"]);
    if !reads.is_empty() {
        s.push_str("\n## File variants\n\n");
        read_table(&mut s, &reads);
    }
    if !board.regressions.is_empty() {
        s.push_str("\n## Regressions against the baseline\n\n| entry | what | baseline | now | fails CI |\n|---|---|---|---|---|\n");
        for r in &board.regressions {
            let _ = writeln!(
                s,
                "| {} | {} | {:.4e} | {:.4e} | {} |",
                r.entry,
                r.what,
                r.baseline,
                r.now,
                if r.error { "yes" } else { "no (time)" }
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentages_keep_three_digits() {
        assert_eq!(pct(Some(0.0123)), "1.23%");
        assert_eq!(pct(Some(0.129)), "12.9%");
        assert_eq!(pct(Some(4.2e-4)), "0.042%");
        assert_eq!(pct(None), "–");
    }
}
