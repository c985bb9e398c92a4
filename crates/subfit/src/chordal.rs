//! The chordal tolerance ([`FitScanOptions::chordal`]): a CAD export's vertices lie on the part
//! and its facets cut the curved faces by up to the chord height, so the fit aims at the part
//! the facets stand for — their curved interpolant (PN triangles, Vlachos et al. 2001;
//! [`subfit_target::tessellation::curved_interpolant`]) — rather than at the facets.
//!
//! The prepared target keeps the facets (the starts read their planes, creases and vertex
//! count from them); a second target, built from the interpolant in the same normalized units,
//! is what the stages fit and what the final measure measures (both ways). The report says so,
//! with how far the facets lie from it.

use std::sync::Arc;

use subfit_mesh::{PolyMesh, Polygons};
use subfit_target::tessellation::curved_interpolant;
use subfit_target::{Target, TargetOptions};

#[cfg(doc)]
use crate::options::FitScanOptions;

/// The interpolant has at most about this many triangles: each facet is cut into `levels²`
/// with the largest `levels` (1–[`MAX_LEVELS`]) that stays within it.
pub const MAX_CURVED_TRIANGLES: usize = 400_000;

/// Each facet is cut into at most `MAX_LEVELS²` triangles: at 4, a facet's interpolant lies
/// within a sixteenth of its own sag from its pieces.
pub const MAX_LEVELS: usize = 4;

/// The target the stages fit under the chordal tolerance.
pub(crate) struct ChordalTarget {
    /// The curved interpolant, analysed (the prepared target's normalization).
    pub(crate) target: Arc<Target>,
    /// Each facet was cut into `levels²` triangles.
    pub(crate) levels: usize,
    /// The largest distance of a facet from the interpolant (normalized units).
    pub(crate) facet_deviation: f64,
}

/// The chordal target of `target` (see the module docs); `None` when `target` is not a
/// recognised tessellation or is too large to cut. Errors: the interpolant cannot be analysed
/// (as the input could, this is not expected; the message says what failed).
pub(crate) fn chordal_target(
    target: &Target,
    options: &TargetOptions,
) -> Result<Option<ChordalTarget>, subfit_target::TargetError> {
    let Some(facets) = target.facets() else {
        return Ok(None);
    };
    let faces = facets.triangles.len().max(1);
    let levels = (1..=MAX_LEVELS)
        .rev()
        .find(|l| l * l * faces <= MAX_CURVED_TRIANGLES)
        .unwrap_or(1);
    if levels < 2 {
        return Ok(None);
    }
    let curved = curved_interpolant(target.points(), facets, levels);
    let mesh = PolyMesh::new(
        curved
            .positions
            .iter()
            .map(|&p| target.to_original(p))
            .collect(),
        Polygons::from_triangles(&curved.triangles),
    );
    let options = TargetOptions {
        normalization: Some(*target.normalization()),
        ..options.clone()
    };
    Ok(Some(ChordalTarget {
        target: Arc::new(Target::build(&mesh, &options, None)?),
        levels,
        facet_deviation: curved.facet_deviation,
    }))
}
