//! The zero set of an implicit function as a closed triangle mesh: marching tetrahedra over a
//! regular grid cut into Kuhn (Freudenthal) tetrahedra — the six of a cube that share its main
//! diagonal, a triangulation of space that is consistent across cube faces, so the surface has
//! no cracks and is a closed 2-manifold wherever no grid value is exactly zero (Doi & Koide,
//! "An efficient method of triangulating equi-valued surfaces by using tetrahedral cells",
//! IEICE 1991). Each vertex is then moved onto the zero set by a few Newton steps along the
//! function's gradient (central differences), so the mesh's vertices lie on the surface
//! itself, not on its linear interpolant.
//!
//! Used by the articulated figure ([`super::figure`]) for its rest surface at any resolution.

use std::collections::HashMap;

use crate::vec3::{cross, dot, sub};

/// Where an edge crossing may sit along its edge, as a fraction from either end: crossings
/// closer to a grid vertex are moved in to this, which keeps every triangle's area away from
/// zero (the Newton projection then puts the vertex on the surface all the same).
const END_CLEARANCE: f64 = 0.15;

/// The six Kuhn tetrahedra of a unit cube, as corners `0..8` (`bit 0` = x, `bit 1` = y,
/// `bit 2` = z): the paths from corner 0 to corner 7 along one axis at a time.
const TETS: [[usize; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 1, 5, 7],
    [0, 2, 3, 7],
    [0, 2, 6, 7],
    [0, 4, 5, 7],
    [0, 4, 6, 7],
];

/// Triangulates `{f = 0}` inside the box `lo..hi` with cubes of side `h` (the grid starts at
/// `lo` shifted by `offset`, a fraction of a cell per axis, so different offsets give
/// different tessellations of one surface). `f` must be negative inside, positive outside and
/// positive on the box's border (the surface closed inside the box). Returns vertices on the
/// surface and triangles wound counter-clockwise seen from outside (from where `f > 0`).
/// Cost: O(#cells) evaluations of `f`, plus O(#V) Newton projections.
pub(super) fn marching_tetrahedra(
    f: &(dyn Fn([f64; 3]) -> f64 + Sync),
    lo: [f64; 3],
    hi: [f64; 3],
    h: f64,
    offset: [f64; 3],
) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let start: [f64; 3] = std::array::from_fn(|a| lo[a] - (1.0 + offset[a]) * h);
    let n: [usize; 3] = std::array::from_fn(|a| ((hi[a] - start[a]) / h).ceil() as usize + 2);
    let point = |i: usize, j: usize, k: usize| {
        [
            start[0] + i as f64 * h,
            start[1] + j as f64 * h,
            start[2] + k as f64 * h,
        ]
    };
    let index = |i: usize, j: usize, k: usize| (k * n[1] + j) * n[0] + i;
    let mut values = vec![0.0; n[0] * n[1] * n[2]];
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let v = f(point(i, j, k));
                // A zero would put a surface vertex on a grid vertex, shared by many edges.
                values[index(i, j, k)] = if v == 0.0 { 1e-12 } else { v };
            }
        }
    }
    let mut vertices: Vec<[f64; 3]> = Vec::new();
    let mut on_edge: HashMap<(usize, usize), u32> = HashMap::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    for k in 0..n[2] - 1 {
        for j in 0..n[1] - 1 {
            for i in 0..n[0] - 1 {
                let corner = |c: usize| (i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
                let ids: [usize; 8] = std::array::from_fn(|c| {
                    let (a, b, d) = corner(c);
                    index(a, b, d)
                });
                if ids.iter().all(|&g| values[g] > 0.0) || ids.iter().all(|&g| values[g] < 0.0) {
                    continue;
                }
                for tet in TETS {
                    let g = tet.map(|c| ids[c]);
                    let mut crossing = |a: usize, b: usize| -> u32 {
                        let key = (g[a].min(g[b]), g[a].max(g[b]));
                        *on_edge.entry(key).or_insert_with(|| {
                            let (pa, pb) = (corner(tet[a]), corner(tet[b]));
                            let (pa, pb) = (point(pa.0, pa.1, pa.2), point(pb.0, pb.1, pb.2));
                            let (va, vb) = (values[g[a]], values[g[b]]);
                            let t = (va / (va - vb)).clamp(END_CLEARANCE, 1.0 - END_CLEARANCE);
                            vertices.push(std::array::from_fn(|x| pa[x] + t * (pb[x] - pa[x])));
                            (vertices.len() - 1) as u32
                        })
                    };
                    let inside: Vec<usize> = (0..4).filter(|&c| values[g[c]] < 0.0).collect();
                    let outside: Vec<usize> = (0..4).filter(|&c| values[g[c]] > 0.0).collect();
                    let corner_point = |c: usize| {
                        let (a, b, d) = corner(tet[c]);
                        point(a, b, d)
                    };
                    let mean = |cs: &[usize]| -> [f64; 3] {
                        let mut m = [0.0; 3];
                        for &c in cs {
                            let p = corner_point(c);
                            (0..3).for_each(|x| m[x] += p[x] / cs.len() as f64);
                        }
                        m
                    };
                    // Outward: from the inside corners towards the outside ones.
                    let out_dir = sub(mean(&outside), mean(&inside));
                    let mut emit = |tri: [u32; 3], vertices: &[[f64; 3]]| {
                        let [a, b, c] = tri.map(|i| vertices[i as usize]);
                        let n = cross(sub(b, a), sub(c, a));
                        triangles.push(if dot(n, out_dir) < 0.0 {
                            [tri[0], tri[2], tri[1]]
                        } else {
                            tri
                        });
                    };
                    match inside.len() {
                        1 | 3 => {
                            let (lone, others) = if inside.len() == 1 {
                                (inside[0], &outside)
                            } else {
                                (outside[0], &inside)
                            };
                            let tri = [
                                crossing(lone, others[0]),
                                crossing(lone, others[1]),
                                crossing(lone, others[2]),
                            ];
                            emit(tri, &vertices);
                        }
                        2 => {
                            let (a, b, c, d) = (inside[0], inside[1], outside[0], outside[1]);
                            let (ac, ad, bc, bd) = (
                                crossing(a, c),
                                crossing(a, d),
                                crossing(b, c),
                                crossing(b, d),
                            );
                            // The quad ac-ad-bd-bc, split along ac-bd.
                            emit([ac, ad, bd], &vertices);
                            emit([ac, bd, bc], &vertices);
                        }
                        _ => {}
                    }
                }
            }
        }
    }
    for p in &mut vertices {
        *p = project_onto(f, *p, h);
    }
    (vertices, triangles)
}

/// `p` moved onto `{f = 0}` by Newton steps along the gradient (central differences of step
/// `h / 100`), at most 8, each at most `h` long.
pub(super) fn project_onto(
    f: &(dyn Fn([f64; 3]) -> f64 + Sync),
    mut p: [f64; 3],
    h: f64,
) -> [f64; 3] {
    for _ in 0..8 {
        let v = f(p);
        let g = gradient(f, p, h);
        let g2 = dot(g, g);
        if g2 <= 0.0 {
            break;
        }
        let mut step = v / g2;
        let len = step.abs() * g2.sqrt();
        if len > h {
            step *= h / len;
        }
        p = std::array::from_fn(|a| p[a] - step * g[a]);
        if len < 1e-12 * h {
            break;
        }
    }
    p
}

fn gradient(f: &(dyn Fn([f64; 3]) -> f64 + Sync), p: [f64; 3], h: f64) -> [f64; 3] {
    let e = 0.01 * h;
    std::array::from_fn(|a| {
        let mut hi = p;
        let mut lo = p;
        hi[a] += e;
        lo[a] -= e;
        (f(hi) - f(lo)) / (2.0 * e)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::polygons::{PolyMesh, Polygons};

    #[test]
    fn a_sphere_is_closed_on_its_surface_and_wound_outward() {
        let f = |p: [f64; 3]| dot(p, p).sqrt() - 0.7;
        let (v, t) = marching_tetrahedra(&f, [-1.0; 3], [1.0; 3], 0.1, [0.3, 0.1, 0.6]);
        for p in &v {
            assert!(f(*p).abs() < 1e-9, "vertex off the sphere by {}", f(*p));
        }
        let mesh = PolyMesh::new(v.clone(), Polygons::from_triangles(&t));
        let topo = crate::diagnose::diagnose_mesh(&mesh);
        assert!(topo.is_closed && topo.is_manifold && topo.is_consistently_oriented);
        assert_eq!(topo.euler_characteristic, 2);
        assert_eq!(topo.zero_area_faces, Some(0));
        // Enclosed volume by the divergence theorem: positive when wound outward, and near
        // the sphere's (4/3)π 0.7³ = 1.4368.
        let volume: f64 = t
            .iter()
            .map(|tri| {
                let [a, b, c] = tri.map(|i| v[i as usize]);
                dot(a, cross(b, c)) / 6.0
            })
            .sum();
        assert!((volume - 1.4368).abs() < 0.03, "volume {volume}");
    }
}
