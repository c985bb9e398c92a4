//! The inputs of a scored entry as the judge sees them: models and cages read with subfit's
//! readers, references as triangles or points, schemes by the names reports use, and how far a
//! fit's own figures are from the judge's.

use std::path::Path;

use subfit::mesh::PolyMesh;
use subfit::subdiv::Scheme;

use crate::judge::{Candidate, Reference};
use crate::row::ReportFigures;

/// Reads a model file. Errors: the reader's message.
pub fn read_model(path: &Path) -> Result<PolyMesh, String> {
    read_model_typed(path).map_err(|e| e.to_string())
}

/// Reads a model file. Errors: the reader's typed error.
pub fn read_model_typed(path: &Path) -> Result<PolyMesh, subfit::io::Error> {
    subfit::io::read_file(path, &subfit::io::ReadOptions::default()).map(|(m, _)| m)
}

/// The judge's reference for a model: its triangles (polygons split into fans), or its points.
pub fn reference_of(mesh: &PolyMesh) -> Reference {
    if mesh.faces.is_empty() {
        return Reference::Points {
            positions: mesh.positions.clone(),
        };
    }
    Reference::Mesh {
        positions: mesh.positions.clone(),
        triangles: fans(mesh),
    }
}

/// Polygons split into triangle fans.
pub fn fans(mesh: &PolyMesh) -> Vec<[u32; 3]> {
    let mut t = Vec::with_capacity(mesh.faces.len() * 2);
    for f in mesh.faces.iter() {
        for i in 1..f.len().saturating_sub(1) {
            t.push([f[0], f[i], f[i + 1]]);
        }
    }
    t
}

/// A cage as written by `subfit fit` (control.obj with its OpenSubdiv `t` lines, or its
/// tags file) with its scheme.
pub fn read_cage(path: &Path, scheme: Scheme) -> Result<Candidate, String> {
    let cage = read_model(path)?;
    let tags = subfit::io::read_tags_file(path, cage.num_vertices()).map_err(|e| e.to_string())?;
    Ok(Candidate::limit(cage, tags, scheme))
}

/// The scheme named in a report (`Loop`, `CatmullClark`, `QuadTriangle` or the CLI's names).
pub fn scheme_named(name: &str) -> Option<Scheme> {
    let n: String = name
        .chars()
        .filter(|c| c.is_ascii_alphanumeric())
        .collect::<String>()
        .to_ascii_lowercase();
    match n.as_str() {
        "loop" => Some(Scheme::Loop),
        "catmullclark" | "catmark" => Some(Scheme::CatmullClark),
        "quadtriangle" | "quadtri" => Some(Scheme::QuadTriangle),
        _ => None,
    }
}

/// Fractions of the diagonal below this are the same to the scoreboard: its tables show errors
/// to 0.001 % of the diagonal, and two fits at 2e-8 and 1e-8 (exact, up to round-off) do not
/// disagree.
pub const DISAGREEMENT_RESOLUTION: f64 = 1e-5;

/// The larger relative difference of the report's figures from the judge's (relative to the
/// judge's figure, or to [`DISAGREEMENT_RESOLUTION`] when that is smaller).
pub fn disagreement(judge_rms: f64, judge_max: f64, r: &ReportFigures) -> f64 {
    let rel = |j: f64, r: f64| (j - r).abs() / j.max(DISAGREEMENT_RESOLUTION);
    rel(judge_rms, r.rms_fraction).max(rel(judge_max, r.hausdorff_fraction))
}
