//! The prepared input (DESIGN.md §2 "Prepared input", STYLE.md rule 11): the scan read,
//! repaired (`repair.rs`, [`crate::repair_mesh`]) and analysed ([`subfit_target::Target`]: normalization to the
//! unit cube, kd-tree, normals, curvature, noise level, features of a mesh, boundaries) once,
//! and borrowed by every start ([`crate::starts`]) and every fit (`fit_start.rs`).
//!
//! What the input is — a point cloud or a mesh, open or closed, of which genus, how noisy — is
//! read off [`Prepared`] by the starts and the tolerance policy ([`crate::tolerance`]), never
//! off a file name.

use std::sync::Arc;
use std::time::Instant;

use subfit_init::InitOptions;
use subfit_mesh::{HalfEdgeMesh, PolyMesh, Polygons};
use subfit_target::{Target, TargetOptions};

use crate::chordal::{chordal_target, ChordalTarget};
use crate::error::Error;
use crate::options::{FitScanOptions, Input};
use crate::pipeline_report::{Reorientation, Topology};
use crate::progress::{Notify, Step};

/// The input read, repaired and analysed once (see the module docs). Cost of `prepare`:
/// reading, the repairs (about linear in the mesh) and [`Target::build`] (kd-tree, normals,
/// curvature by local quadrics: O(#points · k log #points)).
pub struct Prepared {
    /// The input's name for messages and the report (its file).
    pub name: String,
    /// The repaired input in its own coordinates; no faces for a point cloud or with
    /// [`FitScanOptions::as_points`].
    pub(crate) mesh: PolyMesh,
    /// Every vertex a face of the file uses, as read and before any repair, in the target's
    /// normalized units (empty for points): the final measure's largest data → surface
    /// distance is taken over them too, the figure a user measures against the file.
    pub(crate) file_vertices: Vec<[f64; 3]>,
    /// Faces turned to agree with their neighbours by the repair, if any.
    pub reoriented: Option<Reorientation>,
    /// Genus and boundary loops of a mesh target; `None` for a point cloud.
    pub topology: Option<Topology>,
    /// With [`FitScanOptions::as_points`], the dropped faces' topology: the initial cage aims at it.
    pub expected_topology: Option<Topology>,
    /// The analysed target (unit cube), shared by every fit and the [`crate::Fitted`] kept.
    pub target: Arc<Target>,
    /// The diagonal of the target's bounding box (unit cube; 1 when degenerate): what the
    /// tolerances and the reported fractions are relative to.
    pub diagonal: f64,
    /// What the repairs and the analysis told (also in every report).
    pub(crate) warnings: Vec<String>,
    /// Under the chordal tolerance, the curved interpolant of a tessellation: what the stages
    /// fit and the final measure measures ([`crate::chordal`]).
    pub(crate) chordal: Option<ChordalTarget>,
    /// Seconds spent reading the input.
    pub(crate) read_seconds: f64,
    /// Seconds spent analysing it ([`subfit_target::TargetStats`]'s total).
    pub(crate) preprocess_seconds: f64,
}

impl Prepared {
    /// Whether the target is a mesh (faces fitted) that is open, of genus 0: a disc-like patch.
    pub fn is_open_disc(&self) -> bool {
        self.topology
            .is_some_and(|t| t.genus == 0 && t.boundary_loops > 0)
    }

    /// The number of faces fitted (0 for a point cloud or with `as_points`).
    pub fn mesh_faces(&self) -> usize {
        self.mesh.faces.len()
    }

    /// Seconds spent reading and analysing the input.
    pub fn read_and_analyse_seconds(&self) -> f64 {
        self.read_seconds + self.preprocess_seconds
    }

    /// The target the stages fit and the final measure measures: the curved interpolant under
    /// the chordal tolerance, else the target.
    pub(crate) fn fit_target(&self) -> &Arc<Target> {
        self.chordal.as_ref().map_or(&self.target, |c| &c.target)
    }

    /// Whether the target is a mesh with boundary loops.
    pub fn is_open_mesh(&self) -> bool {
        self.topology.is_some_and(|t| t.boundary_loops > 0)
    }

    /// The options of [`subfit_init`] for this input: `options.init_options` with the run's
    /// cancel token, the count asked taken as given, quad pairing from the scheme, and the
    /// topology of dropped faces to aim at.
    pub(crate) fn init_options(&self, options: &FitScanOptions) -> InitOptions {
        let mut init = options.init_options.clone();
        init.cancel = options.cancel.clone();
        if options.control_points.is_some() {
            // The count asked for is the count given.
            init.simplify.exact_error = 0.0;
        }
        // Catmull-Clark and quad/triangle cages start quad-dominant; Loop needs triangles.
        init.quad_dominant = options.wants_quads();
        if let Some(t) = self.expected_topology {
            // A genus the caller gave (`subfit init --genus`) wins over the dropped faces'.
            init.expected_genus.get_or_insert(t.genus);
            init.expected_boundary_loops.get_or_insert(t.boundary_loops);
        }
        init
    }
}

/// Reads, repairs and analyses `input` once (see the module docs), telling `notify` the steps
/// and warnings. Errors: an unreadable or unusable input naming the element, or
/// [`Error::Interrupted`].
pub(crate) fn prepare(
    input: Input,
    options: &FitScanOptions,
    notify: &mut Notify<'_>,
) -> Result<Prepared, Error> {
    let mut warnings = Vec::new();
    let t0 = Instant::now();
    notify.step(Step::Read);
    let crate::repair::ReadInput {
        mut mesh,
        name,
        reoriented,
        vertices: file_vertices,
    } = crate::repair::read_input(input, options.as_points, &mut |m| {
        notify.warn(&mut warnings, m)
    })?;
    let read_seconds = t0.elapsed().as_secs_f64();
    options.cancel.check().map_err(|_| Error::Interrupted)?;

    // With `as_points` the faces are dropped, but their genus still tells the initial mesh
    // what topology to aim for.
    let mut expected_topology = None;
    if options.as_points && !mesh.faces.is_empty() {
        expected_topology = topology(&mesh).ok();
        mesh.faces = Polygons::new();
    }
    let target_topology = if mesh.faces.is_empty() {
        None
    } else {
        Some(topology(&mesh).map_err(|e| Error::input(&name, e))?)
    };

    notify.step(Step::Analyse);
    let target_options = TargetOptions {
        cancel: options.cancel.clone(),
        ..options.target.clone()
    };
    let target =
        Target::build(&mesh, &target_options, None).map_err(|e| Error::target(&name, e))?;
    let preprocess_seconds = target.stats().timings.total.as_secs_f64();
    let outliers = target.stats().outliers_removed;
    if outliers > 0 {
        let msg = format!(
            "dropped {outliers} of {} points of {name} as outliers (not fitted, not measured)",
            target.stats().input_points
        );
        notify.warn(&mut warnings, msg);
    }
    if target.stats().reoriented_input_normals {
        let msg = format!(
            "the normals of {name} are not consistently oriented ({:.0}% of neighbouring normals point opposite ways): their directions kept, their signs chosen again",
            100.0 * target.stats().opposed_input_normals
        );
        notify.warn(&mut warnings, msg);
    }
    let diagonal = bbox_diagonal(target.points());
    let chordal = if options.chordal && mesh.faces.is_empty() {
        let msg = format!(
            "{name} is fitted as points: the chordal tolerance, for a tessellation's facets, does not apply"
        );
        notify.warn(&mut warnings, msg);
        None
    } else if options.chordal {
        let c = chordal_target(&target, &target_options).map_err(|e| Error::target(&name, e))?;
        let msg = match &c {
            Some(c) => format!(
                "{name}: the chordal tolerance: fitted and measured against the curved interpolant of the facets (PN triangles, {}² per facet), from which the facets lie up to {:.3e} ({:.3}% of the diagonal)",
                c.levels,
                target.normalization().length_to_original(c.facet_deviation),
                100.0 * c.facet_deviation / diagonal
            ),
            None => format!(
                "{name} is not recognised as a CAD tessellation (or has too many faces to cut): the chordal tolerance does not apply, its facets are fitted"
            ),
        };
        notify.warn(&mut warnings, msg);
        c
    } else {
        None
    };
    let file_vertices = file_vertices
        .into_iter()
        .map(|p| target.to_normalized(p))
        .collect();
    Ok(Prepared {
        name,
        mesh,
        file_vertices,
        reoriented,
        topology: target_topology,
        expected_topology,
        target: Arc::new(target),
        diagonal,
        warnings,
        chordal,
        read_seconds,
        preprocess_seconds,
    })
}

/// Genus and boundary loops of a mesh with faces; the error names the element that makes it
/// unusable.
pub(crate) fn topology(m: &PolyMesh) -> Result<Topology, subfit_mesh::TopologyError> {
    let h = HalfEdgeMesh::from_mesh(m)?;
    Ok(Topology {
        genus: h.genus(),
        boundary_loops: h.boundary_loops().len(),
    })
}

/// The diagonal of the bounding box of `p` (1 when empty or degenerate), as the fitter's data
/// terms compute it (`subfit_fit`'s `DataTerm::bbox_diagonal`), so the tolerances and the
/// reported fractions agree with the stages'.
fn bbox_diagonal(p: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for x in p {
        for a in 0..3 {
            lo[a] = lo[a].min(x[a]);
            hi[a] = hi[a].max(x[a]);
        }
    }
    let d = (0..3).map(|a| (hi[a] - lo[a]).powi(2)).sum::<f64>().sqrt();
    if d.is_finite() && d > 0.0 {
        d
    } else {
        1.0
    }
}
