//! The final measurement of a fitted cage (DESIGN.md decision 11): both ways, on the limit
//! tessellation written with it (chordal error a tenth of the fitting error, reported), with
//! the one measurer ([`subfit_measure`]): surface → data by the fitter's foot points (for a
//! point cloud, to the data's local surface bounded where the data ends,
//! [`subfit_target::Target::to_local_surface`]), uniform by area over the tessellation
//! ([`DistanceStats::over_surface`]); data → surface from the target's data samples to the
//! tessellation, its maximum over every input vertex too. What a user measures on limit.ply. A quad/triangle cage also gets the distance to the surface USD declares for it.

use subfit_fit::{DataTerm, FitOptions, FootPointTerm, StagesResult};
use subfit_measure::{
    data_samples, limit_tessellation, mesh_vertices, DistanceStats, LimitTessellation,
    MeshDistance, TwoSided,
};
use subfit_mesh::{PolyMesh, Tags};
use subfit_subdiv::Scheme;
use subfit_target::Target;

use crate::error::Error;
use crate::pipeline_report::{LargestErrorAt, UsdDifference};

/// A fitted cage measured both ways on its limit tessellation.
pub(crate) struct FinalMeasure {
    /// The tessellation (normalized units) with its level and chordal error.
    pub(crate) tessellation: LimitTessellation,
    /// Distance of each tessellation vertex to the data (surface → data).
    pub(crate) local: Vec<f64>,
    /// Distance of each data sample to the tessellation (data → surface); the boundary
    /// samples are the last `rim_samples`.
    pub(crate) to_surface: Vec<f64>,
    /// Data samples on the data's boundary, at the end of `to_surface`.
    pub(crate) rim_samples: usize,
    /// Both directions' statistics.
    pub(crate) two_sided: TwoSided,
    /// Where each direction's largest distance is (normalized units): the tessellation
    /// vertex farthest from the data, and the data sample or file vertex farthest from the
    /// tessellation.
    pub(crate) largest_at: LargestErrorAt,
}

/// The point of `points` whose `distance` is largest (the origin when there is none) with it.
fn farthest(points: &[[f64; 3]], distance: impl Fn(usize) -> f64) -> ([f64; 3], f64) {
    (0..points.len()).map(|i| (points[i], distance(i))).fold(
        ([0.0; 3], f64::NEG_INFINITY),
        |a, b| if b.1 > a.1 { b } else { a },
    )
}

impl FinalMeasure {
    /// The data → surface distances of the data's boundary samples.
    pub(crate) fn rim(&self) -> &[f64] {
        &self.to_surface[self.to_surface.len() - self.rim_samples.min(self.to_surface.len())..]
    }
}

/// Measures the cage `result` of a fit of `target` with `fit`, `samples` data samples and the
/// file's vertices `file_vertices` (normalized units) the way
/// (see the module docs). Cost: the tessellation, one foot point per tessellation vertex, one
/// BVH query per data sample.
pub(crate) fn measure_final(
    target: &Target,
    file_vertices: &[[f64; 3]],
    result: &StagesResult,
    fit: &FitOptions,
    samples: usize,
) -> Result<FinalMeasure, Error> {
    let last = result.report.last;
    let term = FootPointTerm::from_options(target, fit);
    let tessellation = limit_tessellation(
        &result.mesh.faces,
        &result.mesh.positions,
        &result.tags,
        &fit.subdivision(),
        last.e_rms,
        last.e_max,
    )
    .map_err(|e| Error::Output(e.to_string()))?;
    let mut err2 = term.squared_errors(&tessellation.mesh.positions);
    term.measured_errors(&tessellation.mesh.positions, &mut err2);
    let local: Vec<f64> = err2.into_iter().map(f64::sqrt).collect();
    let data = data_samples(target, samples);
    let surface = MeshDistance::new(&tessellation.mesh.positions, &tessellation.mesh.faces);
    let to_surface: Vec<f64> = surface
        .distances(&data.points)
        .iter()
        .map(|p| p.distance)
        .collect();
    // The RMS is the area samples' (not the rim's); the largest distance is also taken over
    // the rim and every vertex: the file's as read (the target's are among them, at the same
    // places, but for the midpoints of edges the repair split), else the target's.
    let mut data_to_surface = DistanceStats::of_samples(&to_surface, data.boundary);
    let vertices = if file_vertices.is_empty() {
        mesh_vertices(target)
    } else {
        file_vertices
    };
    let from_vertices = surface.distances(vertices);
    let at_vertex = farthest(vertices, |i| from_vertices[i].distance);
    let at_sample = farthest(&data.points, |i| to_surface[i]);
    let data_far = if at_vertex.1 > at_sample.1 {
        at_vertex
    } else {
        at_sample
    };
    data_to_surface.max = data_to_surface.max.max(data_far.1);
    let largest_at = LargestErrorAt {
        surface_to_data: farthest(&tessellation.mesh.positions, |i| local[i]).0,
        data_to_surface: data_far.0,
    };
    let two_sided = TwoSided {
        surface_to_data: DistanceStats::over_surface(
            &local,
            &tessellation.mesh.positions,
            &tessellation.mesh.faces,
        ),
        data_to_surface,
    };
    Ok(FinalMeasure {
        tessellation,
        local,
        to_surface,
        rim_samples: data.boundary,
        two_sided,
        largest_at,
    })
}

/// Both-way distances between the quad/triangle limit of `cage` and the Catmull-Clark limit
/// (smooth triangle rule, what control.usda declares) at refinement `level`.
pub(crate) fn usd_difference(
    cage: &PolyMesh,
    tags: &Tags,
    options: &subfit_subdiv::Options,
    level: usize,
    diagonal: f64,
    unit: f64,
) -> Result<UsdDifference, Error> {
    use subfit_subdiv::{sampling_operator, TriangleRule};
    let cc = options
        .with_triangles(TriangleRule::Smooth)
        .with_scheme(Scheme::CatmullClark);
    let surface = |o: &subfit_subdiv::Options| {
        sampling_operator(&cage.faces, cage.num_vertices(), tags, o, level)
            .map(|op| (op.position.apply(&cage.positions), op.faces))
            .map_err(|e| Error::Output(e.to_string()))
    };
    let (pa, fa) = surface(options)?;
    let (pb, fb) = surface(&cc)?;
    let ab = MeshDistance::new(&pb, &fb).distances(&pa);
    let ba = MeshDistance::new(&pa, &fa).distances(&pb);
    let d: Vec<f64> = ab.iter().chain(&ba).map(|p| p.distance).collect();
    let stats = DistanceStats::of(&d);
    Ok(UsdDifference {
        written_as: "catmullClark, triangleSubdivisionRule = smooth".into(),
        rms_fraction_of_diagonal: stats.rms / diagonal,
        max_fraction_of_diagonal: stats.max / diagonal,
        max_original_units: stats.max * unit,
    })
}
