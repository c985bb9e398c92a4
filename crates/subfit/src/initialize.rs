//! The initial cage alone (`subfit init`, DESIGN.md §3.6): the same prepared input and the
//! same first start as [`crate::fit_scan`] ([`crate::starts`]), built and not fitted, so the
//! cage `init` writes is the one `fit` would start from, with the same defaults.

use subfit_mesh::{PolyMesh, Tags};

use crate::error::Error;
use crate::options::{validate, FitScanOptions, Input};
use crate::prepare::{prepare, Prepared};
use crate::progress::{Notify, Progress, Step};
use crate::start::Start;
use crate::starts::{build_start, starts};

/// An initial cage built by [`initialize`].
pub struct Initialized {
    /// The cage in the input's coordinates.
    pub cage: PolyMesh,
    /// Its crease and corner tags.
    pub tags: Tags,
    /// The start as built (normalized cage, summary, the builder's report).
    pub start: Start,
    /// The prepared input it was built from.
    pub prepared: Prepared,
}

/// Prepares `input` and builds the first start [`crate::starts::starts`] lists for it under
/// `options` (the QEM start under `--init auto`, the curvature lines or a given cage when
/// asked), within `options.stages.max_control_points`. Errors: as [`crate::fit_scan`]'s
/// before its fit.
pub fn initialize(
    input: Input,
    options: &FitScanOptions,
    progress: Option<&mut dyn FnMut(Progress<'_>)>,
) -> Result<Initialized, Error> {
    validate(options)?;
    let mut notify = Notify::new(progress);
    let prepared = prepare(input, options, &mut notify)?;
    let kind = starts(&prepared, options)[0];
    notify.step(Step::Init);
    let start = build_start(&prepared, kind, options, options.stages.max_control_points)?;
    let mut kept = Vec::new();
    for w in &start.warnings {
        notify.warn(&mut kept, w.clone());
    }
    let cage = PolyMesh::new(
        start
            .cage
            .positions
            .iter()
            .map(|&p| prepared.target.to_original(p))
            .collect(),
        start.cage.faces.clone(),
    );
    Ok(Initialized {
        cage,
        tags: start.tags.clone(),
        start,
        prepared,
    })
}
