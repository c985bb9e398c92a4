//! Exact closest points on a triangle set, by parry3d-f64 (its BVH and point-triangle
//! projection: a code path of its own, independent of subfit's BVH and projections).

use parry3d_f64::math::Vector;
use parry3d_f64::query::{PointQuery, PointQueryWithLocation};
use parry3d_f64::shape::TriMesh;

/// A triangle set ready for closest-point queries.
pub(super) struct Triangles {
    mesh: TriMesh,
}

/// The closest point of a triangle set to a query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Closest {
    /// Distance to the query.
    pub distance: f64,
    /// The triangle it lies on.
    pub triangle: u32,
    /// Its barycentric weights over that triangle's corners 0, 1, 2.
    pub bary: [f64; 3],
}

impl Triangles {
    /// The triangles `triangles` over `positions` (indices checked by the caller, at least one
    /// triangle). Cost O(#T log #T) for the BVH.
    pub fn new(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Self {
        let vertices = positions
            .iter()
            .map(|p| Vector::new(p[0], p[1], p[2]))
            .collect();
        let mesh = TriMesh::new(vertices, triangles.to_vec())
            .expect("the caller passes at least one triangle with valid indices");
        Self { mesh }
    }

    /// Distance from `q` to the nearest triangle. Cost O(log #T) typical.
    pub fn distance(&self, q: [f64; 3]) -> f64 {
        let x = Vector::new(q[0], q[1], q[2]);
        (self.mesh.project_local_point(x, false).point - x).length()
    }

    /// The closest point to `q`: distance, triangle and barycentric weights.
    pub fn closest(&self, q: [f64; 3]) -> Closest {
        let x = Vector::new(q[0], q[1], q[2]);
        let (proj, (triangle, location)) = self.mesh.project_local_point_and_get_location(x, false);
        // `OnSolid` is reported only for solid queries; fall back to the first corner.
        let bary = location
            .barycentric_coordinates()
            .unwrap_or([1.0, 0.0, 0.0]);
        Closest {
            distance: (proj.point - x).length(),
            triangle,
            bary,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_points_on_two_triangles() {
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ];
        let t = Triangles::new(&p, &[[0, 1, 2], [1, 3, 2]]);
        let c = t.closest([0.2, 0.3, 0.5]);
        assert!((c.distance - 0.5).abs() < 1e-15);
        assert_eq!(c.triangle, 0);
        let back: [f64; 3] =
            std::array::from_fn(|k| (0..3).map(|i| c.bary[i] * p[[0, 1, 2][i]][k]).sum());
        assert!((back[0] - 0.2).abs() < 1e-15 && (back[1] - 0.3).abs() < 1e-15);
        // Past the far corner: the distance to the corner.
        assert!((t.distance([2.0, 1.0, 0.0]) - 1.0).abs() < 1e-15);
        let c = t.closest([1.5, 1.5, 0.0]);
        assert_eq!(c.triangle, 1);
        assert!((c.bary[1] - 1.0).abs() < 1e-15, "{:?}", c.bary);
    }
}
