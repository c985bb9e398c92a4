//! Edge flips between stages (Cheng 2007 §III-D, DESIGN.md §3.5: "optional edge flips accepted
//! only if the error drops"): independent flips of the edges of faces that miss the tolerance,
//! each judged by the surface → data error over the faces whose limit it changes, with the
//! control points as they are (no re-fit).

use subfit_mesh::{PolyMesh, Polygons};
use subfit_subdiv::sampling_operator;

use crate::error::FitError;
use crate::options::FitOptions;
use crate::remesh::{apply_flips, face_errors, face_owners, independent_flips, FaceError};
use crate::stage_options::{face_score, StageOptions};
use crate::term::DataTerm;

/// Tries independent edge flips on faces scoring above the tolerance with the current
/// control points (no re-fit): a flip is kept when the squared surface → data error summed
/// over the faces whose limit it changes goes down; the scores of those faces are updated.
/// Returns (tried, kept).
pub(crate) fn flip_pass(
    term: &impl DataTerm,
    mesh: &mut PolyMesh,
    (surface, data): (&[FaceError], &[FaceError]),
    score: &mut [f64],
    stages: &StageOptions,
    unmet: (bool, bool),
    base: &FitOptions,
) -> Result<(usize, usize), FitError> {
    let mut flips = independent_flips(&mesh.faces, mesh.num_vertices(), score, 1.0);
    // A crease stays where the features put it.
    flips.retain(|f| base.tags.crease(f.a, f.b) == 0.0);
    if flips.is_empty() {
        return Ok((0, 0));
    }
    let flipped = apply_flips(&mesh.faces, &flips);
    let op = sampling_operator(
        &flipped,
        mesh.num_vertices(),
        &base.tags,
        &base.subdivision(),
        base.sample_level,
    )?;
    // Faces incident to each vertex of the old mesh (the same faces are incident to a, b, c,
    // d in both meshes).
    let mut vf: Vec<Vec<u32>> = vec![Vec::new(); mesh.num_vertices()];
    for (f, face) in mesh.faces.iter().enumerate() {
        for &v in face {
            vf[v as usize].push(f as u32);
        }
    }
    let regions: Vec<Vec<u32>> = flips
        .iter()
        .map(|fl| {
            let mut region: Vec<u32> = [fl.a, fl.b, fl.c, fl.d]
                .iter()
                .flat_map(|&v| vf[v as usize].iter().copied())
                .collect();
            region.sort_unstable();
            region.dedup();
            region
        })
        .collect();
    // Only the faces of the regions are compared: only their samples are projected.
    let new_errors = region_errors(term, &flipped, &op, &mesh.positions, &regions);
    let mut kept = Vec::new();
    for (fl, region) in flips.iter().zip(&regions) {
        let before: f64 = region.iter().map(|&f| surface[f as usize].sum_sq).sum();
        let after: f64 = region.iter().map(|&f| new_errors[f as usize].sum_sq).sum();
        if after < before {
            kept.push(*fl);
            for &f in region {
                let f = f as usize;
                score[f] = face_score(&new_errors[f], stages, unmet)
                    .max(face_score(&data[f], stages, unmet));
            }
        }
    }
    if !kept.is_empty() {
        mesh.faces = apply_flips(&mesh.faces, &kept);
    }
    Ok((flips.len(), kept.len()))
}

/// Per-face errors of the cage `faces` (sampled by `op`, control points `positions`) on the
/// faces of `regions` only: the samples of those faces are projected (fresh), every other
/// sample counts as error 0, so the other faces' entries mean nothing. Same values on the
/// regions' faces as [`face_errors`] over all samples; cost in proportion to the regions.
fn region_errors(
    term: &impl DataTerm,
    faces: &Polygons,
    op: &subfit_subdiv::SamplingOperator,
    positions: &[[f64; 3]],
    regions: &[Vec<u32>],
) -> Vec<FaceError> {
    let mut in_region = vec![false; faces.len()];
    for &f in regions.iter().flatten() {
        in_region[f as usize] = true;
    }
    let mut needed = vec![false; op.position.nrows()];
    for (f, &o) in op.faces.iter().zip(&face_owners(faces, op)) {
        if in_region[o as usize] {
            for &v in f {
                needed[v as usize] = true;
            }
        }
    }
    let rows: Vec<u32> = (0..needed.len() as u32)
        .filter(|&k| needed[k as usize])
        .collect();
    let samples = crate::active::sample_rows(&op.position, &rows, positions);
    let mut err2 = vec![0.0; needed.len()];
    for (&k, e) in rows.iter().zip(term.squared_errors(&samples)) {
        err2[k as usize] = e;
    }
    face_errors(faces, op, &err2)
}
