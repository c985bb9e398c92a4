//! Exact distances from points to a limit surface: for each query the closest point on the
//! limit surface ([`subfit_subdiv::ClosestPointFinder`]: a BVH over an exact tessellation for
//! the start, then Newton's method on the exact surface, across patches and onto boundary
//! curves), with the control face it lies on.
//!
//! The data → surface half of [`crate::TwoSided`]: a point of the data whose closest point is
//! far away, or on the surface's boundary curve, is data the surface does not cover, and the
//! face it lands on is the one to refine.

use subfit_mesh::{Polygons, Tags};
use subfit_subdiv::{ClosestOptions, ClosestPointFinder, EvalError, Evaluator, Options};

/// Why distances to a limit surface could not be measured.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LimitDistanceError {
    /// The control mesh cannot be evaluated (topology, or a failed evaluation).
    #[error("cannot evaluate the limit surface: {0}")]
    Eval(#[from] EvalError),
}

/// The distance of one query point to the limit surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointToLimit {
    /// `|q − S(face, u, v)|` at the closest point (units of the control points).
    pub distance: f64,
    /// The control face of the closest point.
    pub face: u32,
}

/// Distances to the limit surface of one control-mesh topology; the control points are given
/// per call, so one value serves every set of positions of that topology.
pub struct LimitDistance {
    evaluator: Evaluator,
    options: ClosestOptions,
}

impl LimitDistance {
    /// Prepares `faces` over `num_vertices` control points with `tags` and subdivision
    /// `options`.
    ///
    /// Errors: a control mesh the evaluator refuses. Cost: O(#faces).
    pub fn new(
        faces: &Polygons,
        num_vertices: usize,
        tags: &Tags,
        options: &Options,
    ) -> Result<Self, LimitDistanceError> {
        Ok(Self {
            evaluator: Evaluator::new(faces, num_vertices, tags, options)?,
            options: ClosestOptions::default(),
        })
    }

    /// Distances from every point of `queries` (`#Q by 3`) to the limit surface of
    /// `positions` (`#V by 3`), in query order, in parallel.
    ///
    /// Errors: a wrong number of positions, or a failed evaluation. Cost: an exact tessellation
    /// of every patch (4 × 4 per patch) and its BVH, then per query one BVH descent and a few
    /// Newton steps of exact evaluations.
    pub fn distances(
        &self,
        positions: &[[f64; 3]],
        queries: &[[f64; 3]],
    ) -> Result<Vec<PointToLimit>, LimitDistanceError> {
        let finder = ClosestPointFinder::new(&self.evaluator, positions, self.options)?;
        Ok(finder
            .closest_batch(queries)?
            .into_iter()
            .map(|c| PointToLimit {
                distance: c.distance,
                face: c.param.face,
            })
            .collect())
    }

    /// The evaluator in use.
    pub fn evaluator(&self) -> &Evaluator {
        &self.evaluator
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfit_mesh::shapes::torus_mesh;
    use subfit_subdiv::{sampling_operator, Scheme};

    /// Points on the limit surface are at distance 0; points pushed off along the limit normal
    /// by `h` (less than the tube's radius of curvature) are at distance `h`.
    #[test]
    fn distances_to_limit_points_pushed_along_the_normal() {
        let cage = torus_mesh(1.0, 0.4, 12, 8, true);
        let opts = Options::new(Scheme::Loop);
        let op =
            sampling_operator(&cage.faces, cage.num_vertices(), &Tags::new(), &opts, 2).unwrap();
        let s = op.evaluate(&cage.positions);
        let ld = LimitDistance::new(&cage.faces, cage.num_vertices(), &Tags::new(), &opts).unwrap();
        let h = 0.01;
        let queries: Vec<[f64; 3]> = s
            .positions
            .iter()
            .zip(&s.normals)
            .step_by(7)
            .map(|(p, n)| std::array::from_fn(|k| p[k] + h * n[k]))
            .collect();
        let d = ld.distances(&cage.positions, &queries).unwrap();
        for x in &d {
            assert!((x.distance - h).abs() < 1e-8, "{}", x.distance);
            assert!((x.face as usize) < cage.faces.len());
        }
        let on = ld.distances(&cage.positions, &s.positions[..50]).unwrap();
        assert!(on.iter().all(|x| x.distance < 1e-9));
    }
}
