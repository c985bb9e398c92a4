//! The measurement of a cage between stages (Cheng et al. 2007 §II-B step 8; DESIGN.md
//! decisions 11 and 12): the fitter built for one topology ([`Topo`]), both-way distances of a
//! cage with its per-face errors and, for local enrichment, its error points
//! ([`Measurement`]), the judging of a boundary's distances by its own tolerance, and the best
//! cage so far ([`Best`]). The driver ([`crate::fit_stages`]) and the polish
//! ([`crate::polish`]) measure with it.

use subfit_measure::data_samples::DataSamples;
use subfit_measure::TwoSided;
use subfit_mesh::{PolyMesh, Polygons, Tags};
use subfit_target::Target;

use crate::any_term::AnyTerm;
use crate::enrich::error_points;
use crate::error::FitError;
use crate::fitter::Fitter;
use crate::options::FitOptions;
use crate::remesh::{face_errors, face_owners, FaceError};
use crate::report::ErrorStats;
use crate::stage_options::StageOptions;

/// The cage of one topology with what is built for it: the fitter (sampling operator, pattern,
/// symbolic factorization) and the control face of every face of the sample tessellation.
/// Rebuilt only when the topology changes (refinement, flips); a `λ` change keeps both.
pub(crate) struct Topo<'t> {
    pub(crate) fitter: Fitter<'t, AnyTerm<'t>>,
    pub(crate) owners: Vec<u32>,
}

impl<'t> Topo<'t> {
    pub(crate) fn new(
        target: &'t Target,
        mesh: &PolyMesh,
        opts: &FitOptions,
    ) -> Result<Self, FitError> {
        let term = AnyTerm::from_options(target, opts);
        let fitter = Fitter::with_term(term, &mesh.faces, mesh.num_vertices(), opts)?;
        let owners = face_owners(&mesh.faces, fitter.sampling_operator());
        Ok(Self { fitter, owners })
    }
}

/// Both-way distances of one cage, with per-face errors for refinement.
pub(crate) struct Measurement {
    pub(crate) two_sided: TwoSided,
    /// What the stopping rules judge: [`Self::two_sided`] with the data → surface maximum
    /// raised to the boundary vertices' largest distance scaled by
    /// `tolerance_max / tolerance_boundary` ([`StageOptions::tolerance_boundary`]), so one
    /// maximum tolerance holds both.
    pub(crate) judged: TwoSided,
    /// Surface → data, per control face.
    pub(crate) surface_faces: Vec<FaceError>,
    /// Data → surface, per control face (the face of each data point's closest point).
    pub(crate) data_faces: Vec<FaceError>,
    /// The error points of local enrichment ([`crate::enrich`]; empty when it is off): each
    /// level-`l` sub-face (its largest corner error) and each data point (its distance, a
    /// boundary vertex's scaled as in `data_faces`), with its control face.
    pub(crate) points: Vec<(u32, f32)>,
}

/// Measures `positions` both ways: the squared errors of every sample of the fitter's sampling
/// operator from fresh projections (its data term; RMS and mean weighted by the area each
/// sample stands for in the tessellation, as a measurement uniform by area would see them),
/// and the distance of every data sample to the tessellation of the samples (the
/// level-`l` limit points; within its chordal error of the limit surface).
pub(crate) fn measure(
    topo: &Topo<'_>,
    faces: &Polygons,
    positions: &[[f64; 3]],
    data: &DataSamples,
    stages: &StageOptions,
) -> Measurement {
    let op = topo.fitter.sampling_operator();
    let (two_sided, err2, to_surface) = topo.fitter.measure_two_sided(positions, data);
    let surface_faces = face_errors(faces, op, &err2);
    let mut data_faces = vec![FaceError::default(); faces.len()];
    let rim_from = to_surface.len() - data.boundary.min(to_surface.len());
    let uniform = data.uniform();
    let scale = rim_scale(stages);
    for (i, p) in to_surface.iter().enumerate() {
        let e = &mut data_faces[topo.owners[p.face as usize] as usize];
        // The mesh's vertices count for a face's maximum, not its RMS.
        if i < uniform || i >= rim_from {
            e.sum_sq += p.distance * p.distance;
            e.count += 1;
        }
        let d = if i >= rim_from {
            scale * p.distance
        } else {
            p.distance
        };
        e.max = e.max.max(d);
    }
    let rim: Vec<f64> = to_surface[rim_from..].iter().map(|p| p.distance).collect();
    let judged = judged_with_boundary(&two_sided, &rim, stages);
    // Only a missed maximum makes error fields (and local enrichment).
    let points = if stages.local_field_share > 0.0 && stages.refine && stages.tolerance_max > 0.0 {
        error_points(op, &topo.owners, &err2, &to_surface, rim_from, scale)
    } else {
        Vec::new()
    };
    Measurement {
        two_sided,
        judged,
        surface_faces,
        data_faces,
        points,
    }
}

/// The factor on a boundary vertex's distance that makes [`StageOptions::tolerance_max`]
/// judge it by [`StageOptions::tolerance_boundary`] (1 when either is unset or the boundary's
/// is the looser).
fn rim_scale(stages: &StageOptions) -> f64 {
    if stages.tolerance_boundary > 0.0 && stages.tolerance_max > 0.0 {
        (stages.tolerance_max / stages.tolerance_boundary).max(1.0)
    } else {
        1.0
    }
}

/// [`TwoSided`] `two` of data samples `data` with the boundary vertices' distances `rim`
/// (the tail of the data → surface distances) judged as [`measure`] does.
pub fn judged_with_boundary(two: &TwoSided, rim: &[f64], stages: &StageOptions) -> TwoSided {
    let scale = rim_scale(stages);
    let mut judged = *two;
    for &d in rim {
        judged.data_to_surface.max = judged.data_to_surface.max.max(scale * d);
    }
    judged
}

/// The best cage measured so far.
pub(crate) struct Best {
    pub(crate) stage: usize,
    pub(crate) badness: f64,
    pub(crate) mesh: PolyMesh,
    pub(crate) tags: Tags,
    pub(crate) errors: ErrorStats,
    pub(crate) two_sided: TwoSided,
    /// [`Measurement::judged`] of it.
    pub(crate) judged: TwoSided,
}
