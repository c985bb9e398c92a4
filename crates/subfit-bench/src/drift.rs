//! Drift of a sequence's cage where the frames give the truth: when every frame is the same
//! mesh posed differently (the same vertex count and faces), each data vertex is a known
//! material point. Its closest point on frame 0's limit surface fixes a parameter `(face, u,
//! v)`; in frame `t` the same parameter of frame `t`'s cage (one connectivity for all frames)
//! should land on the same vertex of frame `t`. The drift is how far it lands from it, along
//! the surface: the gap with its part along the limit normal removed (the normal part is the
//! fit's error, which the two-sided figures already give).

use serde::{Deserialize, Serialize};
use subfit::mesh::PolyMesh;
use subfit::subdiv::{Evaluator, Options, SurfaceParam};

use crate::judge::{closest_params, Candidate, JudgeOptions};

/// Drift of the tracked points in one frame (the frame's units and as fractions of its
/// bounding-box diagonal).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Drift {
    /// Tracked points.
    pub points: usize,
    /// RMS of the tangential gap.
    pub rms: f64,
    /// Its 95th percentile.
    pub p95: f64,
    /// Its maximum.
    pub max: f64,
    /// `rms` / diagonal.
    pub rms_fraction: f64,
    /// `p95` / diagonal.
    pub p95_fraction: f64,
}

/// Points of frame 0 located on its limit surface.
#[derive(Clone, Debug)]
pub struct Tracked {
    /// Data vertices tracked (indices into every frame).
    pub vertices: Vec<usize>,
    /// Their parameters on the cage.
    pub params: Vec<SurfaceParam>,
}

/// Whether `a` and `b` are the same mesh posed differently (vertex count and faces equal).
pub fn same_connectivity(a: &PolyMesh, b: &PolyMesh) -> bool {
    a.num_vertices() == b.num_vertices()
        && !a.faces.is_empty()
        && a.faces.len() == b.faces.len()
        && a.faces.iter().zip(b.faces.iter()).all(|(x, y)| x == y)
}

/// Locates up to `max_points` vertices of `frame0` (evenly strided) on the limit surface of
/// `cage0`. Errors: the judge's, as text.
pub fn locate(
    cage0: &Candidate,
    frame0: &PolyMesh,
    max_points: usize,
    options: &JudgeOptions,
) -> Result<Tracked, String> {
    let n = frame0.num_vertices();
    let stride = n.div_ceil(max_points.max(1)).max(1);
    let vertices: Vec<usize> = (0..n).step_by(stride).collect();
    let points: Vec<[f64; 3]> = vertices.iter().map(|&v| frame0.positions[v]).collect();
    let params = closest_params(cage0, &points, options).map_err(|e| e.to_string())?;
    Ok(Tracked { vertices, params })
}

/// The drift in frame `t`: `cage` is frame `t`'s cage (the same connectivity as frame 0's),
/// `frame` frame `t`'s mesh. Errors: an evaluation failure, as text.
pub fn measure(tracked: &Tracked, cage: &Candidate, frame: &PolyMesh) -> Result<Drift, String> {
    let Candidate::Limit {
        cage,
        tags,
        scheme,
        boundary,
    } = cage
    else {
        return Err("drift needs a cage".into());
    };
    let options = Options {
        scheme: *scheme,
        boundary: *boundary,
        ..Options::default()
    };
    let eval = Evaluator::new(&cage.faces, cage.num_vertices(), tags, &options)
        .map_err(|e| e.to_string())?;
    let s = eval
        .evaluate_batch(&cage.positions, &tracked.params)
        .map_err(|e| e.to_string())?;
    let mut gaps: Vec<f64> = tracked
        .vertices
        .iter()
        .zip(&s)
        .map(|(&v, p)| {
            let t = frame.positions[v];
            let d = [
                t[0] - p.position[0],
                t[1] - p.position[1],
                t[2] - p.position[2],
            ];
            let n = p.normal;
            let dn = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
            let g = [d[0] - dn * n[0], d[1] - dn * n[1], d[2] - dn * n[2]];
            (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt()
        })
        .collect();
    let diagonal = subfit::mesh::bounding_box(&frame.positions).map_or(1.0, |(lo, hi)| {
        subfit::mesh::vec3::norm(subfit::mesh::vec3::sub(hi, lo))
    });
    gaps.sort_by(f64::total_cmp);
    let k = gaps.len();
    if k == 0 {
        return Err("no tracked point".into());
    }
    let rms = (gaps.iter().map(|g| g * g).sum::<f64>() / k as f64).sqrt();
    let p95 = gaps[((0.95 * k as f64).ceil() as usize).clamp(1, k) - 1];
    Ok(Drift {
        points: k,
        rms,
        p95,
        max: gaps[k - 1],
        rms_fraction: rms / diagonal,
        p95_fraction: p95 / diagonal,
    })
}
