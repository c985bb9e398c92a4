//! The limit tessellation written with a fit (`limit.ply`, `error.ply`): the limit points of a
//! uniform refinement, at the coarsest level whose chordal error is a tenth of the fitting
//! error in the same norm, so that what a user measures on the file is the fit's error, not
//! the tessellation's.

use std::collections::HashMap;

use subfit_mesh::{PolyMesh, Polygons, Tags};
use subfit_subdiv::{sampling_operator, Options, SubdivError};

/// Finest tessellation level tried.
pub const MAX_TESSELLATION_LEVEL: usize = 6;
/// Largest tessellation (vertices).
pub const MAX_TESSELLATION_VERTICES: usize = 1_000_000;

/// Chordal error of a tessellation (units of the control points): the largest and the RMS,
/// over its edges, of the distance from the limit point of the edge's midpoint to the chord.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chordal {
    /// Largest over the edges.
    pub max: f64,
    /// Root mean square over the edges.
    pub rms: f64,
}

impl Chordal {
    fn scaled(self, s: f64) -> Self {
        Self {
            max: self.max * s,
            rms: self.rms * s,
        }
    }
}

/// A limit tessellation and how fine it is.
#[derive(Clone, Debug)]
pub struct LimitTessellation {
    /// Limit positions and normals of the level's vertices, and its faces.
    pub mesh: PolyMesh,
    /// The refinement level.
    pub level: usize,
    /// Its predicted chordal error.
    pub chordal: Chordal,
}

/// The limit surface of `faces`/`control` (with `tags` and `options`) tessellated at the
/// coarsest level whose chordal error is below a tenth of the fitting error in the same norm —
/// RMS chordal error ≤ `e_rms / 10` and largest ≤ `e_max / 10` — or the finest level with at
/// most [`MAX_TESSELLATION_VERTICES`] vertices (up to [`MAX_TESSELLATION_LEVEL`]).
///
/// The chordal error of level 1 is measured (between the level-2 limit point of each edge and
/// the midpoint of the limit points of its ends) and divided by 4 per level, as it shrinks with
/// the square of the edge length on a smooth surface; so only levels 1, 2 and the chosen one
/// are built.
pub fn limit_tessellation(
    faces: &Polygons,
    control: &[[f64; 3]],
    tags: &Tags,
    options: &Options,
    e_rms: f64,
    e_max: f64,
) -> Result<LimitTessellation, SubdivError> {
    let one = sampling_operator(faces, control.len(), tags, options, 1)?;
    let two = sampling_operator(faces, control.len(), tags, options, 2)?;
    let chord1 = chordal_estimate(&one.faces, one.num_vertices, &two.position.apply(control));
    let at = |level: usize| chord1.scaled(0.25f64.powi(level as i32 - 1));
    let fine_enough = |c: Chordal| c.rms <= 0.1 * e_rms && c.max <= 0.1 * e_max;
    let mut level = 1;
    let mut vertices = one.num_vertices;
    while level < MAX_TESSELLATION_LEVEL
        && !fine_enough(at(level))
        && vertices.saturating_mul(4) <= MAX_TESSELLATION_VERTICES
    {
        level += 1;
        vertices = vertices.saturating_mul(4);
    }
    let op = match level {
        1 => one,
        2 => two,
        l => sampling_operator(faces, control.len(), tags, options, l)?,
    };
    let s = op.evaluate(control);
    Ok(LimitTessellation {
        mesh: PolyMesh {
            positions: s.positions,
            normals: Some(s.normals),
            colors: None,
            faces: op.faces,
        },
        level,
        chordal: at(level),
    })
}

/// Largest and RMS `|fine[V + e] − (fine[a] + fine[b]) / 2|` over the edges `e = (a, b)` of
/// the coarse faces, numbered in order of first appearance (the refinement's child order:
/// vertex points keep their ids, then one edge point per edge).
fn chordal_estimate(faces: &Polygons, nv: usize, fine: &[[f64; 3]]) -> Chordal {
    let mut ids: HashMap<(u32, u32), usize> = HashMap::with_capacity(faces.indices().len());
    let (mut worst, mut sum2): (f64, f64) = (0.0, 0.0);
    for f in faces.iter() {
        for i in 0..f.len() {
            let (a, b) = (f[i], f[(i + 1) % f.len()]);
            let key = (a.min(b), a.max(b));
            let next = ids.len();
            let e = *ids.entry(key).or_insert(next);
            if e != next {
                continue; // seen from the other side
            }
            let (pa, pb, pe) = (fine[a as usize], fine[b as usize], fine[nv + e]);
            let d2: f64 = (0..3)
                .map(|k| (pe[k] - 0.5 * (pa[k] + pb[k])).powi(2))
                .sum();
            worst = worst.max(d2.sqrt());
            sum2 += d2;
        }
    }
    Chordal {
        max: worst,
        rms: (sum2 / ids.len().max(1) as f64).sqrt(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfit_mesh::shapes::torus_mesh;
    use subfit_subdiv::Scheme;

    /// The chordal error predicted from level 1 (÷ 4 per level) against the one measured at
    /// level 3 (level-3 chords against level-4 limit points), on a torus cage.
    #[test]
    fn predicted_chordal_error_matches_the_measured_one() {
        let cage = torus_mesh(1.0, 0.4, 12, 8, true);
        let (faces, p) = (&cage.faces, &cage.positions);
        let opts = Options::new(Scheme::Loop);
        let tags = Tags::new();
        let op = |l| sampling_operator(faces, p.len(), &tags, &opts, l).unwrap();
        let (one, two, three, four) = (op(1), op(2), op(3), op(4));
        let c1 = chordal_estimate(&one.faces, one.num_vertices, &two.position.apply(p));
        let c3 = chordal_estimate(&three.faces, three.num_vertices, &four.position.apply(p));
        let predicted = c1.scaled(1.0 / 16.0);
        for (m, q) in [(c3.max, predicted.max), (c3.rms, predicted.rms)] {
            assert!(
                m > 0.0 && (m / q - 1.0).abs() < 0.25,
                "measured {m}, predicted {q}"
            );
        }
        // RMS below max; the tessellation goal picks the first level meeting both norms.
        assert!(c1.rms < c1.max);
        let t = limit_tessellation(faces, p, &tags, &opts, c1.rms, c1.max).unwrap();
        assert_eq!(t.level, 3);
        assert!(t.chordal.rms <= 0.1 * c1.rms && t.chordal.max <= 0.1 * c1.max);
    }
}
