//! The whole pipeline behind every front end (DESIGN.md §1, §2 `subfit`), as a list of named
//! steps:
//!
//! 1. [`crate::prepare`]: read, repair and analyse the input once (Cheng 2007 §II-C);
//! 2. [`crate::starts`]: the candidate initial cages with the target's topology (§II-A; QEM
//!    simplification or IMLS contouring, the curvature lines of Lavoué et al. 2007 §4, a
//!    given cage, budget variants);
//! 3. [`crate::fit_start`]: each start fitted in stages (Cheng 2004 §4.4–4.6, Cheng 2007
//!    §II-F) and measured both ways (DESIGN.md decision 11) from the one prepared input;
//! 4. [`crate::choose`]: the best fit kept by its typed measurement (decision 12), returned in
//!    the input's coordinates with a typed [`Report`].
//!
//! The CLI's `fit`, `demo` and `bench fit`, the tests and the Python package call
//! [`fit_scan`]; none re-implements a step. Nothing here prints: progress and warnings go to the
//! callback.

use std::path::Path;
use std::time::Instant;

use subfit_mesh::Tags;

use crate::error::Error;
use crate::fit_start::fit_start;
use crate::fitted::Fitted;
use crate::options::{validate, FitScanOptions, InitialCage, Input};
use crate::pipeline_report::{BudgetStart, CurvatureLineSummary, InitAlternative, Report};
use crate::prepare::{prepare, Prepared};
use crate::progress::{Notify, Progress, Step};
use crate::starts::{build_start, same_kind, starts, StartKind};

/// Fits a subdivision surface to `input`: the whole pipeline (see the module docs).
///
/// Errors: invalid options ([`Error::Options`]), an unreadable or unusable input
/// ([`Error::Io`], [`Error::Input`] naming the element), a budget that cannot be honoured
/// ([`Error::Budget`]), a failed initial mesh or fit. On error nothing is returned; nothing
/// is written in any case (see [`Fitted::write_into`]).
///
/// A quad scheme whose default start exceeds the budget (`--max-control-points` below the
/// target's default size) is fitted from each of [`crate::BUDGET_STARTS`] and the better cage
/// kept; see [`crate::starts`] for every start.
///
/// ```
/// use subfit::mesh::shapes::Shape;
/// use subfit::{fit_scan, FitScanOptions, Input, OutputOptions};
///
/// // 2,000 points on the papers' ellipsoid (semi-axes 0.25, 0.5, 1), a small budget.
/// let mesh = Shape::PAPER_ELLIPSOID.sample(2_000, 0.0, 1);
/// let mut options = FitScanOptions {
///     control_points: Some(40),
///     ..FitScanOptions::default()
/// };
/// options.stages.max_iterations = 5;
/// options.fit.sample_level = 2;
/// let input = Input::Mesh { mesh, name: "ellipsoid".into() };
/// let mut fitted = fit_scan(input, &options, None)?;
/// let two = &fitted.report.r#final.two_sided; // errors both ways
/// assert!(two.e_rms_fraction_of_diagonal < 0.01);
/// assert!(fitted.cage.num_vertices() >= 4);
///
/// let dir = std::env::temp_dir().join(format!("subfit-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// fitted.write_into_with(&dir, &OutputOptions::default())?; // limit.ply as triangles
/// let summary = fitted.closing_summary(&dir); // what `subfit fit` prints last
/// assert_eq!(summary.control_points, fitted.cage.num_vertices());
/// assert!(summary.files.iter().all(|f| f.is_file()));
/// # std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn fit_scan(
    input: Input,
    options: &FitScanOptions,
    progress: Option<&mut dyn FnMut(Progress<'_>)>,
) -> Result<Fitted, Error> {
    validate(options)?;
    let t0 = Instant::now();
    let mut notify = Notify::new(progress);
    let prepared = prepare(input, options, &mut notify)?;
    let mut kept: Option<Fitted> = None;
    let mut first_error = None;
    let groups = kinds_in_groups(starts(&prepared, options));
    let last = groups.len().saturating_sub(1);
    for (g, group) in groups.into_iter().enumerate() {
        let budget = budget_against(kept.as_ref(), options);
        // A start after a kept fit that met the tolerances can win only by meeting them with
        // fewer points: it stops as soon as it cannot.
        let must_reach = kept.as_ref().is_some_and(|k| k.measurement.reached);
        let reaching;
        let options = if must_reach {
            let mut o = options.clone();
            o.stages.must_reach = true;
            reaching = o;
            &reaching
        } else {
            options
        };
        let fitted = match fit_group(&prepared, &group, options, budget, &mut notify) {
            Ok(f) => f,
            Err(Error::Interrupted) => return Err(Error::Interrupted),
            Err(e) => match kept.as_mut() {
                // A later start of another kind that cannot be built or fitted leaves the
                // kept fit, which says why.
                Some(k) => {
                    note_failed(&mut k.report, group[0], &e);
                    continue;
                }
                // A start that cannot be built leaves the next one (a CAD start over the
                // budget, the QEM start); the first error is returned when none is left.
                None if g < last => {
                    first_error.get_or_insert(e);
                    continue;
                }
                None => return Err(first_error.unwrap_or(e)),
            },
        };
        kept = Some(match kept {
            None => fitted,
            Some(k) => keep_better(k, fitted),
        });
    }
    let mut kept = kept.ok_or_else(|| Error::Options("no start to fit".into()))?;
    kept.report.timings_s.total = t0.elapsed().as_secs_f64();
    Ok(kept)
}

/// `kinds` in runs of one kind (the budget variants of the QEM start form one run).
fn kinds_in_groups(kinds: Vec<StartKind>) -> Vec<Vec<StartKind>> {
    let mut groups: Vec<Vec<StartKind>> = Vec::new();
    for k in kinds {
        match groups.last_mut() {
            Some(g) if same_kind(g[0], k) => g.push(k),
            _ => groups.push(vec![k]),
        }
    }
    groups
}

/// The budget of a start fitted after `kept`: the options', and one control point fewer than
/// a kept fit that met the tolerances (a start of another kind wins only with fewer control
/// points, [`crate::choose::Measurement::better_start_than`]: it stops where it cannot win).
fn budget_against(kept: Option<&Fitted>, options: &FitScanOptions) -> usize {
    let budget = options.stages.max_control_points;
    match kept {
        Some(k) if k.measurement.reached => {
            budget.min(k.measurement.control_points.saturating_sub(1))
        }
        _ => budget,
    }
}

/// Builds and fits each variant of one kind of start; the closest kept
/// ([`crate::choose::Measurement::closer_than`]), with the list of variants in its report's
/// `budget_starts` when there were several.
fn fit_group(
    prepared: &Prepared,
    group: &[StartKind],
    options: &FitScanOptions,
    budget: usize,
    notify: &mut Notify<'_>,
) -> Result<Fitted, Error> {
    let mut runs: Vec<(Fitted, f64)> = Vec::with_capacity(group.len());
    let mut field_failure = None;
    for &kind in group {
        let t = Instant::now();
        notify.step(Step::Init);
        let start = build_start(prepared, kind, options, budget)?;
        // A cross-field variant whose field gave no cage is the paired cage of the next
        // variant again: not fitted twice.
        let unlaid = matches!(
            kind,
            StartKind::Qem {
                cross_field: true,
                ..
            }
        ) && start
            .init_report
            .as_ref()
            .is_some_and(|r| r.cross_field.is_none())
            && group.len() > 1;
        if unlaid {
            field_failure = start.summary.cross_field.clone();
            continue;
        }
        let fitted = fit_start(prepared, start, options, budget, notify)?;
        runs.push((fitted, t.elapsed().as_secs_f64()));
    }
    let closest = (1..runs.len()).fold(0, |b, i| {
        if runs[i].0.measurement.closer_than(&runs[b].0.measurement) {
            i
        } else {
            b
        }
    });
    let best = with_fewer_irregular(&runs, closest);
    let listed: Vec<BudgetStart> = if runs.len() > 1 {
        runs.iter()
            .enumerate()
            .map(|(i, (f, seconds))| budget_start(&f.report, *seconds, i == best))
            .collect()
    } else {
        Vec::new()
    };
    let (mut kept, _) = runs.swap_remove(best);
    kept.report.budget_starts = listed;
    if kept.report.init.cross_field.is_none() {
        kept.report.init.cross_field = field_failure;
    }
    Ok(kept)
}

/// Of the variants `runs`, a cross-field cage about as close as the closest one
/// ([`QUAD_LAYOUT_SLACK`]) with fewer irregular vertices, if there is one; else `closest`.
fn with_fewer_irregular(runs: &[(Fitted, f64)], closest: usize) -> usize {
    let irregular = |f: &Fitted| subfit_init::cross_field::irregular_vertices(&f.cage);
    let field = |f: &Fitted| f.report.init.cross_field.as_ref().is_some_and(|c| c.used);
    let best = &runs[closest].0;
    if field(best) {
        return closest;
    }
    (0..runs.len())
        .filter(|&i| field(&runs[i].0))
        .filter(|&i| {
            runs[i]
                .0
                .measurement
                .about_as_close_as(&best.measurement, QUAD_LAYOUT_SLACK)
        })
        .filter(|&i| irregular(&runs[i].0) < irregular(best))
        .min_by_key(|&i| irregular(&runs[i].0))
        .unwrap_or(closest)
}

/// How much farther (relative, [`crate::choose::Measurement::about_as_close_as`]) a
/// cross-field cage may be than the closest variant and still be kept for its fewer irregular
/// vertices: edge flow is what a quad cage is asked for (an artist edits and animates it),
/// and a tenth on the worse of the two errors is the trade an artist's own cage makes (on
/// Keenan Crane's Bob, 334 control points: the field's cage RMS 0.0175 % and Hausdorff
/// 0.158 % of the diagonal with 37–50 irregular vertices, the paired simplification's 0.0200 %
/// and 0.134 % with 99).
pub const QUAD_LAYOUT_SLACK: f64 = 0.1;

/// One line of report.json's `budget_starts`.
fn budget_start(r: &Report, seconds: f64, kept: bool) -> BudgetStart {
    BudgetStart {
        fraction: r.init.budget_start.unwrap_or(0.0),
        initial_control_points: r.init.control_points,
        control_points: r.control_points,
        rms_fraction_of_diagonal: r.r#final.two_sided.e_rms_fraction_of_diagonal,
        max_fraction_of_diagonal: r.r#final.two_sided.e_max_fraction_of_diagonal,
        tolerance_reached: r.tolerance_reached,
        seconds,
        kept,
        cross_field: r.init.cross_field.as_ref().is_some_and(|c| c.used),
    }
}

/// The better of the fit `kept` so far and `new` of another kind
/// ([`crate::choose::Measurement::better_start_than`]), its report saying what the other gave.
fn keep_better(kept: Fitted, new: Fitted) -> Fitted {
    let new_wins = new.measurement.better_start_than(&kept.measurement);
    let (mut winner, loser) = if new_wins { (new, kept) } else { (kept, new) };
    describe_alternative(&mut winner.report, &loser.report);
    winner
}

/// Writes into the kept report what the other start gave: today the curvature-line start's
/// `init.curvature_lines` (used, or why not, and the other fit's figures).
fn describe_alternative(kept: &mut Report, other: &Report) {
    let brief = |r: &Report| InitAlternative {
        initial_control_points: r.init.control_points,
        control_points: r.control_points,
        rms_fraction_of_diagonal: r.r#final.two_sided.e_rms_fraction_of_diagonal,
        max_fraction_of_diagonal: r.r#final.two_sided.e_max_fraction_of_diagonal,
        tolerance_reached: r.tolerance_reached,
    };
    if let Some(s) = kept.init.curvature_lines.as_mut() {
        // The curvature-line start was kept.
        s.alternative = Some(brief(other));
    } else if let Some(mut summary) = other.init.curvature_lines.clone() {
        let (qem, cl) = (brief(kept), brief(other));
        summary.used = false;
        summary.reason = Some(format!(
            "the QEM start gave {} control points ({}), the curvature-line start {} ({})",
            qem.control_points,
            reached(qem.tolerance_reached),
            cl.control_points,
            reached(cl.tolerance_reached)
        ));
        summary.alternative = Some(cl);
        kept.init.curvature_lines = Some(summary);
    }
}

/// Writes into the kept report why a start of `kind` gave no fit.
fn note_failed(kept: &mut Report, kind: StartKind, e: &Error) {
    if kind == StartKind::CurvatureLines {
        kept.init.curvature_lines = Some(CurvatureLineSummary {
            used: false,
            reason: Some(e.to_string()),
            ..CurvatureLineSummary::default()
        });
    }
}

fn reached(r: bool) -> &'static str {
    if r {
        "within the tolerances"
    } else {
        "outside the tolerances"
    }
}

/// Reads `path` as a cage for [`InitialCage::Given`].
///
/// ```
/// use subfit::mesh::shapes::octahedron_mesh;
/// use subfit::{read_cage, InitialCage};
///
/// let path = std::env::temp_dir().join(format!("subfit-doc-cage-{}.obj", std::process::id()));
/// subfit::io::write_file(&path, &octahedron_mesh(1.0, 1.0, 1.0), &Default::default())?;
/// let InitialCage::Given { mesh, .. } = read_cage(&path)? else { unreachable!() };
/// assert_eq!((mesh.num_vertices(), mesh.num_faces()), (6, 8));
/// # std::fs::remove_file(&path)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn read_cage(path: &Path) -> Result<InitialCage, Error> {
    let (mesh, _) = subfit_io::read_file(path, &subfit_io::ReadOptions::default())?;
    if mesh.faces.is_empty() {
        return Err(Error::input(
            &path.display().to_string(),
            "has no faces; an initial control mesh is needed",
        ));
    }
    Ok(InitialCage::Given {
        mesh,
        tags: Tags::new(),
        name: path.display().to_string(),
    })
}
