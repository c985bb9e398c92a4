//! Where points land on a limit surface: the parameter `(face, u, v)` of each point's closest
//! point, found as the judge finds data → surface distances (the closest point on the exact
//! tessellation, then Newton steps on the exact surface). The sequence drift of the scoreboard
//! fixes material points on frame 0 with it.

use rayon::prelude::*;
use subfit::subdiv::{EvalError, Evaluator, Options, SurfaceParam};

use super::closest::Triangles;
use super::{polish, tessellate, Candidate, JudgeError, JudgeOptions};

/// The parameter of the closest point on `candidate`'s limit surface of each of `points`, in
/// order; the tessellation as [`super::judge`] builds it for `options`. Errors: a mesh
/// candidate (it has no parameters), or a cage the evaluator refuses. Cost: the judge's
/// tessellation, then per point one closest-point query and a few exact evaluations.
pub fn closest_params(
    candidate: &Candidate,
    points: &[[f64; 3]],
    options: &JudgeOptions,
) -> Result<Vec<SurfaceParam>, JudgeError> {
    let Candidate::Limit {
        cage,
        tags,
        scheme,
        boundary,
    } = candidate
    else {
        return Err(JudgeError::Empty {
            what: "the candidate",
            reason: "a flat mesh has no surface parameters",
        });
    };
    let subdiv = Options::new(*scheme).with_boundary(*boundary);
    let (level, _) = tessellate::level_for(&cage.faces, *scheme, options.tessellation_triangles);
    let tess = tessellate::tessellate(&cage.faces, &cage.positions, tags, &subdiv, level)
        .map_err(EvalError::from)?;
    let flat = Triangles::new(&tess.positions, &tess.triangles);
    let ev = Evaluator::new(&cage.faces, cage.positions.len(), tags, &subdiv)?;
    let params = points
        .par_iter()
        .map(|&x| {
            let c = flat.closest(x);
            let start = tess.levels.param(tess.face_of[c.triangle as usize], c.bary);
            Ok(match polish::polish(&ev, &cage.positions, x, start) {
                Ok(p) if p.distance <= c.distance => p.param,
                _ => start,
            })
        })
        .collect::<Result<Vec<_>, EvalError>>()?;
    Ok(params)
}
