//! The starts of a fit (DESIGN.md §2 "Starts → fit → choose", §3.6): **the one place where
//! the kinds of initial cage are listed** ([`starts`]) and built ([`build_start`]). A new kind
//! of start (a CAD cage, a thin-part-aware octree, cross-field quads from `subfit_init`) is
//! added here: a variant of [`StartKind`], its builder in a `start_*.rs` file called from
//! [`build_start`], and the condition under which [`starts`] lists it. [`crate::fit_scan`]
//! fits every start listed from the one [`crate::Prepared`] input (`fit_start.rs`) and
//! keeps the best by [`crate::choose::Measurement`]; a later start of another kind is capped
//! to one control point fewer than a kept fit that met the tolerances (it can only win by
//! being more compact), so it stops early when it cannot win.
//!
//! The kinds today:
//!
//! * **given** ([`InitialCage::Given`], `--init FILE`): checked against the target's topology
//!   and the budget, optionally paired into quads;
//! * **QEM** (`--init qem`): [`subfit_init::initial_control_mesh`], the simplification of a mesh
//!   target or the trimmed IMLS contour of a point cloud;
//! * **curvature lines** (`--init curvature-lines`): [`subfit_init::curvature_lines`], the
//!   cage of Lavoué et al. 2007 §4 whose vertices are the control points of the boundary
//!   curves, joined along the target's lines of curvature, fitted with the quad/triangle scheme
//!   unless another is asked. Open mesh targets of genus 0 only.
//! * **CAD tessellation** (listed first under `--init auto` when the target's facets say it is
//!   a CAD export): [`crate::start_cad`], the tessellation's own creases and corners tagged,
//!   its planes emptied, judged by the tessellation's tolerances within its vertex count.
//!
//! `--init auto` (the default) fits from QEM, and for an open mesh target of genus 0 with at
//! most [`BOTH_INITS_POINTS`] points (CAD-like patches, not scans) from the curvature lines as
//! well, and keeps the better fit ([`crate::choose::Measurement::better_start_than`]: within the tolerances with fewer control
//! points). Which start a cage came from cannot be told from the cages before they are fitted:
//! the curvature-line cage of a saddle (12 control points) is 6 % of the diagonal off after 30
//! iterations at fixed connectivity, 22 times the RMS tolerance, yet the stages' refinement
//! takes it to the tolerance with fewer points than QEM's 169 when the tolerance is loose. The
//! report's `init.source` says which start was kept, `init.curvature_lines` what the other
//! gave.
//!
//! ## Cross-field starts
//!
//! A quad cage (`--scheme catmull-clark` or `quad-tri`, `--quad-dominant`, `--quads only`)
//! under `--quads field` (the default) or `only` is also laid along a cross field of the
//! surface ([`subfit_init::cross_field`]): edges that follow the shape, irregular vertices
//! where the field has its singularities. That cage is a variant of the QEM start, fitted
//! first, and the closer of the fits is kept ([`crate::choose::Measurement::closer_than`]):
//! on smooth shapes the field's cage fits as closely as the paired simplification and has
//! half its irregular vertices; on thin parts (the bunny's ears, the armadillo's limbs) a
//! lattice of even cells leaves too few control points where the simplification puts many,
//! and the paired cage is kept. `--quads paired` fits the paired cage alone.
//!
//! ## Budget starts
//!
//! Fits under a small budget from more than one start, the better cage kept.
//!
//! A Catmull-Clark or quad/triangle cage whose default start (from the target's size) exceeds
//! `--max-control-points` starts below the budget, so that the stages' refinement has points
//! to place where the error is: started at the budget, the Catmull-Clark fit of the artist
//! model of the CLI's `tests/artist_cage.rs` ended at a Hausdorff distance of 3.11e-3
//! of the diagonal, from 0.6 of it at 2.20e-3. Which start is best depends on the model: where
//! the largest error ends up is decided by which faces the first refinements split. So such a
//! fit is run from each fraction in [`BUDGET_STARTS`] and the better cage is written
//! ([`crate::choose::Measurement::closer_than`]); `report.json`'s `budget_starts` lists every start, `init.budget_start` the one
//! kept. Loop cages start at the budget (a CAD part's feature cage needs its points) and are
//! fitted once, as is every fit whose start the budget does not cap.
//!
//! Measured on six models made as `tests/artist_cage.rs` makes its model, the sculpted detail
//! drawn with six seeds (the artist's own cages: Hausdorff distance 1.64e-3–1.90e-3 of the
//! diagonal, RMS 4.9e-4–5.1e-4). One start each (`subfit fit MODEL --scheme S
//! --max-control-points 201 --control-points N`, then `subfit compare control.obj MODEL --scheme
//! S --samples 100000`), Hausdorff distance, worst over the six / range:
//!
//! | start (of 201) | Catmull-Clark | quad/tri |
//! |---|---|---|
//! | 0.45 | 5.44e-3 / 1.57e-3–5.44e-3 | 3.93e-3 / 1.70e-3–3.93e-3 |
//! | 0.6 | 2.20e-3 / 1.42e-3–2.20e-3 | 1.88e-3 / 1.49e-3–1.88e-3 |
//! | 0.75 | 2.74e-3 / 1.49e-3–2.74e-3 | 2.06e-3 / 1.42e-3–2.06e-3 |
//! | 0.9 | 1.85e-3 / 1.39e-3–1.85e-3 | 1.72e-3 / 1.41e-3–1.72e-3 |
//! | the defaults: the best of [`BUDGET_STARTS`] | **1.72e-3** / 1.30e-3–1.72e-3 | **1.57e-3** / 1.25e-3–1.57e-3 |
//!
//! The single-start rows were measured before left-over triangles were merged in hexagons
//! ([`subfit_init::hexagons`]); the last row is `subfit fit MODEL --scheme S
//! --max-control-points 201` with it, at RMS 3.7e-4–3.9e-4. No single start is best on every
//! model, and none beats every artist's cage with both schemes; with the three starts both
//! schemes beat all six (the CI test's model: Catmull-Clark 1.72e-3 against the artist's
//! 1.74e-3). Before the hexagons, the three starts gave 1.77e-3 / 1.52e-3 at worst, and the
//! better of 0.6 and 0.9 alone 1.78e-3 / 1.76e-3. On the Stanford bunny at 201 points
//! (Catmull-Clark) 0.9 alone is better than 0.6: RMS 1.45e-3 / Hausdorff 7.6e-3 against
//! 1.61e-3 / 9.7e-3. Cost: the fit three times from one prepared input (6–8 s in all on the 55k-point artist
//! models when each start read and analysed the input again); the default start never exceeds
//! 2,000 points (`subfit_init::default_control_points`), so neither does a fit that is
//! repeated.

use subfit_init::default_control_points;
use subfit_subdiv::Scheme;

use crate::error::Error;
use crate::options::{FitScanOptions, InitialCage, QuadLayout};
use crate::prepare::Prepared;
pub use crate::start::{Start, StartKind};
use crate::start_cad::{cad_applies, cad_start, tessellation_budget};
use crate::start_curvature_lines::curvature_line_start;
use crate::start_given::given_start;
use crate::start_qem::{qem_start, start_control_points};

/// Under `--init auto`, open mesh targets of genus 0 with at most this many points are fitted
/// from both initializers (see the module docs): CAD-like patches are small; a scan is larger,
/// and its curvature-line cage (vertices on its boundary only) is no start for it (the camel
/// head, 11k points: 704 control points outside the tolerances where QEM met them with 706;
/// fitting both took 12.7 s instead of 3.0 s).
pub const BOTH_INITS_POINTS: usize = 10_000;

/// The fractions of the budget a capped quad-scheme fit starts from (see the module docs);
/// the first is fitted first and tells whether the start is capped at all.
pub const BUDGET_STARTS: [f64; 3] = [0.6, 0.75, 0.9];

/// The starts to fit for `prepared` under `options`, in the order they are fitted (the
/// choice keeps the first of equals): the given cage; or the QEM start — once, or once per
/// [`BUDGET_STARTS`] fraction when the budget caps a quad scheme's default size — and, under
/// `--init auto` for an open mesh target of genus 0 with at most [`BOTH_INITS_POINTS`] points
/// (no count asked, not Loop, not as points), the curvature-line start; or the curvature-line
/// start alone; a CAD tessellation ([`crate::start_cad::cad_applies`]) its CAD starts first.
/// Cost: O(1) but the CAD test, one edge classification (O(E)); nothing is built.
pub fn starts(prepared: &Prepared, options: &FitScanOptions) -> Vec<StartKind> {
    let budget = options.stages.max_control_points;
    match options.init {
        InitialCage::Given { .. } => vec![StartKind::Given],
        InitialCage::CurvatureLines => vec![StartKind::CurvatureLines],
        InitialCage::Auto | InitialCage::Qem => {
            let default = default_control_points(prepared.target.len());
            // An all-quad cage is not refined: it starts at its final size, once.
            let capped = options.control_points.is_none()
                && options.quads != QuadLayout::Only
                && start_control_points(default, budget, options.scheme, BUDGET_STARTS[0])
                    .1
                    .is_some();
            let mut kinds: Vec<StartKind> = if capped {
                BUDGET_STARTS
                    .iter()
                    .map(|&f| StartKind::Qem {
                        budget_fraction: Some(f),
                        cross_field: false,
                    })
                    .collect()
            } else {
                vec![StartKind::Qem {
                    budget_fraction: None,
                    cross_field: false,
                }]
            };
            // A quad cage is also laid along a cross field, at the first size: a variant of
            // the QEM start, the closer fit kept (see the module docs).
            if options.wants_quads() && options.quads != QuadLayout::Paired {
                kinds.insert(
                    0,
                    StartKind::Qem {
                        budget_fraction: capped.then_some(BUDGET_STARTS[0]),
                        cross_field: true,
                    },
                );
            }
            let both = matches!(options.init, InitialCage::Auto)
                && options.control_points.is_none()
                && options.scheme != Some(Scheme::Loop)
                && !options.as_points
                && prepared.is_open_disc()
                && prepared.target.len() <= BOTH_INITS_POINTS;
            if both {
                kinds.push(StartKind::CurvatureLines);
            }
            // A CAD tessellation's own cage first: the starts after it win only with fewer
            // control points (crate::start_cad).
            if cad_applies(prepared, options) {
                kinds.splice(0..0, [StartKind::Cad, StartKind::CadFaceted]);
            }
            kinds
        }
    }
}

/// Builds the start `kind` of `prepared` within `budget` control points. Errors: the
/// builder's (a budget too small, a topology that does not match, an input a kind cannot
/// start from), or [`Error::Interrupted`].
pub fn build_start(
    prepared: &Prepared,
    kind: StartKind,
    options: &FitScanOptions,
    budget: usize,
) -> Result<Start, Error> {
    options.cancel.check().map_err(|_| Error::Interrupted)?;
    let t = std::time::Instant::now();
    let mut start = match kind {
        StartKind::Given => {
            let InitialCage::Given { mesh, tags, name } = &options.init else {
                return Err(Error::Options(
                    "a given start needs --init FILE (InitialCage::Given)".into(),
                ));
            };
            given_start(prepared, mesh, tags, name, budget, options)
        }
        StartKind::Qem {
            budget_fraction,
            cross_field,
        } => qem_start(
            prepared,
            options,
            budget,
            budget_fraction.unwrap_or(BUDGET_STARTS[0]),
            cross_field,
        ),
        StartKind::CurvatureLines => curvature_line_start(prepared, options, budget),
        StartKind::Cad => cad_start(
            prepared,
            options,
            tessellation_budget(prepared, options, budget),
            false,
        ),
        StartKind::CadFaceted => cad_start(
            prepared,
            options,
            tessellation_budget(prepared, options, budget),
            true,
        ),
    }?;
    start.seconds = t.elapsed().as_secs_f64();
    Ok(start)
}

/// Whether `kind` is a variant of `other` (the budget fractions of the QEM start): variants
/// are compared by closeness, different kinds by compactness ([`crate::choose`]).
pub fn same_kind(kind: StartKind, other: StartKind) -> bool {
    std::mem::discriminant(&kind) == std::mem::discriminant(&other)
}
