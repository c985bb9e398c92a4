//! Planar regions of a tessellation: faces grown across flat edges from the largest face
//! first, a face joining only when its three corners lie on the region's plane (refitted as
//! the region grows: the area-weighted mean normal through the area-weighted centroid), so a
//! finely tessellated cylinder whose neighbouring facets are nearly coplanar does not creep
//! into one "plane". Cost O(F log F) for the order, O(F) for the growth.

use subfit_mesh::vec3::{dot, norm, sub};

use super::elements::{FacetEdge, PlanarRegion};

/// The planar region of every face and the regions. `tol` is the flat tolerance of
/// [`super::Facets::new`].
pub(super) fn grow(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    normals: &[[f64; 3]],
    areas: &[f64],
    edges: &[FacetEdge],
    tol: f64,
) -> (Vec<u32>, Vec<PlanarRegion>) {
    let nf = triangles.len();
    // Flat neighbours of every face.
    let mut adjacency: Vec<Vec<u32>> = vec![Vec::new(); nf];
    for e in edges.iter().filter(|e| e.flat) {
        adjacency[e.faces[0] as usize].push(e.faces[1]);
        adjacency[e.faces[1] as usize].push(e.faces[0]);
    }
    let mut order: Vec<u32> = (0..nf as u32).collect();
    order.sort_by(|&a, &b| areas[b as usize].total_cmp(&areas[a as usize]));
    let mut region = vec![u32::MAX; nf];
    let mut regions = Vec::new();
    let mut stack = Vec::new();
    for &seed in &order {
        if region[seed as usize] != u32::MAX {
            continue;
        }
        let id = regions.len() as u32;
        let mut plane = Plane::default();
        plane.add(
            positions,
            triangles[seed as usize],
            normals[seed as usize],
            areas[seed as usize],
        );
        region[seed as usize] = id;
        let mut count = 1;
        stack.push(seed);
        while let Some(f) = stack.pop() {
            for &g in &adjacency[f as usize] {
                let gi = g as usize;
                if region[gi] != u32::MAX || !plane.holds(positions, triangles[gi], tol) {
                    continue;
                }
                region[gi] = id;
                count += 1;
                plane.add(positions, triangles[gi], normals[gi], areas[gi]);
                stack.push(g);
            }
        }
        regions.push(PlanarRegion {
            normal: plane.normal(),
            faces: count,
            area: plane.area,
        });
    }
    (region, regions)
}

/// A plane refitted as faces join it.
#[derive(Default)]
struct Plane {
    normal_sum: [f64; 3],
    centroid_sum: [f64; 3],
    area: f64,
}

impl Plane {
    fn add(&mut self, positions: &[[f64; 3]], t: [u32; 3], n: [f64; 3], area: f64) {
        let c = t.map(|v| positions[v as usize]);
        for k in 0..3 {
            self.normal_sum[k] += area * n[k];
            self.centroid_sum[k] += area * (c[0][k] + c[1][k] + c[2][k]) / 3.0;
        }
        self.area += area;
    }

    fn normal(&self) -> [f64; 3] {
        let l = norm(self.normal_sum);
        if l > 0.0 {
            self.normal_sum.map(|x| x / l)
        } else {
            [0.0; 3]
        }
    }

    /// Whether the three corners of `t` lie within `tol` of the plane (a region of no area
    /// yet takes any face its flat edge reached).
    fn holds(&self, positions: &[[f64; 3]], t: [u32; 3], tol: f64) -> bool {
        let n = self.normal();
        if n == [0.0; 3] || self.area <= 0.0 {
            return true;
        }
        let p = self.centroid_sum.map(|x| x / self.area);
        t.iter()
            .all(|&v| dot(sub(positions[v as usize], p), n).abs() <= tol)
    }
}
