//! Distances from points to a tessellated surface: exact point–triangle distances through a
//! BVH ([`subfit_target::TriangleBvh`]), with the face of the tessellation each closest point
//! lies on.
//!
//! This is how the data → surface direction is measured during a fit: the limit surface is
//! tessellated by the limit points of a uniform refinement (the fitter's samples, or the
//! tessellation written as `limit.ply`), and a point's distance to it differs from its
//! distance to the limit surface by at most the tessellation's chordal error
//! ([`crate::tessellate`]), which is reported beside it. Exact closest points on the limit
//! surface ([`crate::LimitDistance`]) cost 50–100 µs a query, a BVH query about 1 µs.

use rayon::prelude::*;
use subfit_mesh::Polygons;
use subfit_target::TriangleBvh;

use crate::limit_distance::PointToLimit;

/// A tessellated surface to measure distances to.
pub struct MeshDistance {
    bvh: TriangleBvh,
    /// The polygon of every triangle (polygons are fan-triangulated).
    face_of: Vec<u32>,
}

impl MeshDistance {
    /// The surface of `faces` over `positions` (`#V by 3`; polygons fan-triangulated).
    /// Cost: O(T log T) for `T` triangles.
    pub fn new(positions: &[[f64; 3]], faces: &Polygons) -> Self {
        let mut triangles = Vec::with_capacity(faces.indices().len());
        let mut face_of = Vec::with_capacity(faces.indices().len());
        for (f, poly) in faces.iter().enumerate() {
            for i in 1..poly.len().saturating_sub(1) {
                triangles.push([poly[0], poly[i], poly[i + 1]]);
                face_of.push(f as u32);
            }
        }
        Self {
            bvh: TriangleBvh::new(positions.to_vec(), triangles),
            face_of,
        }
    }

    /// Distances from every point of `queries` to the surface, with the face (index into the
    /// `faces` given to [`Self::new`]) of each closest point; in parallel, in query order. An
    /// empty surface gives infinite distances at face 0.
    pub fn distances(&self, queries: &[[f64; 3]]) -> Vec<PointToLimit> {
        queries
            .par_iter()
            .map(|&q| match self.bvh.closest(q) {
                Some(c) => PointToLimit {
                    distance: c.distance,
                    face: self.face_of[c.triangle as usize],
                },
                None => PointToLimit {
                    distance: f64::INFINITY,
                    face: 0,
                },
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::LimitDistance;
    use subfit_mesh::shapes::torus_mesh;
    use subfit_mesh::Tags;
    use subfit_subdiv::{sampling_operator, Options, Scheme};

    /// The distance to a level-3 limit tessellation agrees with the exact distance to the limit
    /// surface within the tessellation's chordal error.
    #[test]
    fn tessellation_distance_is_within_the_chordal_error_of_the_exact_one() {
        let cage = torus_mesh(1.0, 0.4, 12, 8, true);
        let opts = Options::new(Scheme::Loop);
        let tags = Tags::new();
        let op = sampling_operator(&cage.faces, cage.num_vertices(), &tags, &opts, 3).unwrap();
        let s = op.evaluate(&cage.positions);
        let md = MeshDistance::new(&s.positions, &op.faces);
        let exact = LimitDistance::new(&cage.faces, cage.num_vertices(), &tags, &opts).unwrap();
        let t = crate::limit_tessellation(&cage.faces, &cage.positions, &tags, &opts, 1.0, 1.0)
            .unwrap();
        let chordal = t.chordal.max * 0.25f64.powi(3 - t.level as i32);
        let queries: Vec<[f64; 3]> = (0..400)
            .map(|i| {
                let a = i as f64 * 0.7;
                let r = 1.0 + 0.6 * (0.3 * a).cos();
                [r * a.cos(), r * a.sin(), 0.5 * (1.3 * a).sin()]
            })
            .collect();
        let d_tess = md.distances(&queries);
        let d_exact = exact.distances(&cage.positions, &queries).unwrap();
        for (a, b) in d_tess.iter().zip(&d_exact) {
            assert!(
                (a.distance - b.distance).abs() <= 2.0 * chordal + 1e-12,
                "{} vs {} (chordal {chordal})",
                a.distance,
                b.distance
            );
            assert!((a.face as usize) < op.faces.len());
        }
    }
}
