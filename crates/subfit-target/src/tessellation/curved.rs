//! The curved interpolant of a tessellation: the part its facets stand for.
//!
//! A CAD exporter puts the vertices of its tessellation on the true surface and lets the facets
//! cut the curved faces by up to the chord height. The curved PN triangle of each facet
//! (Vlachos, Peters, Boyd & Mitchell 2001, "Curved PN Triangles", §3: a cubic Bézier triangle
//! from the three corners and their normals, the edge control points projected onto each
//! corner's tangent plane, the centre raised by half the distance of the edges' mean from the
//! corners' mean) interpolates the vertices with the surface's normals there, so it follows a
//! curved face to the fourth order of the facet size where the facets follow it to the second.
//! It is what a fit with the chordal tolerance aims at.
//!
//! What the facets say decides the corner normals (a PN triangle is only as good as they are):
//!
//! * the faces around a vertex fall into **fans** separated by its crease edges (the edges that
//!   turn and are not smooth under the chordal tolerance, [`classify_edges_chordal`]: a curved
//!   face's edges sag by about the exporter's chord height between strip-like facets, a
//!   chamfer's by far more, between wide ones) and its boundary edges; each fan has one normal, so that neighbouring PN triangles share their edge curve
//!   and the surface has no cracks;
//! * a fan that holds a face of a **planar region** of three faces or more takes the plane's
//!   normal (the largest such plane by area): a fillet meets its plane tangentially, and an
//!   averaged normal would bulge the plane's long facets; a facet of a plane then stays flat;
//! * any other fan takes the angle-weighted mean of its faces' normals (Thürmer & Wüthrich
//!   1998).
//!
//! A crease or boundary edge is not curved by its faces' normals, which disagree across it (a
//! curved edge per face would open a crack): it is the cubic that leaves each end along the
//! chain of crease edges through it (the chord of its two neighbours, as in Catmull–Rom
//! interpolation), the same for both faces, so a hole's rim and a cylinder's cap edge follow
//! their circles; it stays straight at a corner, where the chain turns or ends.

use subfit_mesh::vec3::{add, dot, norm, scale, sub};

use super::edges::{classify_edges_chordal, EdgeClass};
use super::facets::Facets;

/// Planar regions of at least this many faces give their normal to the fans they touch: a
/// strip of two triangles (a quad of a tessellated cylinder) is not a plane of the part.
pub const MIN_PLANE_FACES: usize = 3;

/// The curved interpolant of a tessellation ([`curved_interpolant`]).
#[derive(Clone, Debug, PartialEq)]
pub struct CurvedInterpolant {
    /// Its vertices: the input's first, at their indices, then the new ones.
    pub positions: Vec<[f64; 3]>,
    /// Its triangles, `levels²` per facet in facet order.
    pub triangles: Vec<[u32; 3]>,
    /// The largest distance of a facet from it over its vertices: what the facets cut off the
    /// part, the chord height the chordal tolerance allows (0 with `levels = 1`).
    pub facet_deviation: f64,
}

/// The curved interpolant of `facets` over `positions`, each facet cut into `levels²`
/// triangles whose vertices lie on its PN triangle (see the module docs); `levels = 1` gives
/// the facets back. The vertices of the input keep their indices (the first `#V`); the new
/// vertices of an edge are shared by its faces. Cost O(F · levels²).
///
/// # Panics
/// If `levels` is 0.
pub fn curved_interpolant(
    positions: &[[f64; 3]],
    facets: &Facets,
    levels: usize,
) -> CurvedInterpolant {
    assert!(levels > 0, "curved_interpolant: levels must be at least 1");
    let tris = &facets.triangles;
    let lines = Lines::new(positions, facets);
    let normals = corner_normals(positions, facets, &lines.straight);
    let mut out = positions.to_vec();
    let mut edge_points: std::collections::HashMap<(u32, u32), Vec<u32>> =
        std::collections::HashMap::new();
    let mut faces = Vec::with_capacity(tris.len() * levels * levels);
    let n = levels;
    let mut facet_deviation: f64 = 0.0;
    for (f, t) in tris.iter().enumerate() {
        let patch = PnTriangle::of_face(positions, *t, normals[f], &lines);
        let corner = t.map(|v| positions[v as usize]);
        // Grid index (i, j) with i + j ≤ n: barycentric (n − i − j, i, j) / n.
        let mut grid = vec![u32::MAX; (n + 1) * (n + 2) / 2];
        let at = |i: usize, j: usize| i * (n + 1) - i * (i.saturating_sub(1)) / 2 + j;
        for i in 0..=n {
            for j in 0..=n - i {
                let k = n - i - j;
                grid[at(i, j)] = match (i, j, k) {
                    (0, 0, _) => t[0],
                    (_, 0, 0) => t[1],
                    (0, _, 0) => t[2],
                    _ => {
                        // On an edge: shared with the face across it, ordered from its
                        // smaller vertex.
                        let side = if j == 0 {
                            Some((t[0], t[1], i))
                        } else if k == 0 {
                            Some((t[1], t[2], j))
                        } else if i == 0 {
                            Some((t[2], t[0], k))
                        } else {
                            None
                        };
                        let w = [k as f64, i as f64, j as f64].map(|w| w / n as f64);
                        let x = patch.at(w);
                        let flat = (0..3).fold([0.0; 3], |s, c| add(s, scale(corner[c], w[c])));
                        facet_deviation = facet_deviation.max(norm(sub(x, flat)));
                        match side {
                            None => push(&mut out, x),
                            Some((a, b, s)) => {
                                let key = (a.min(b), a.max(b));
                                let from_small = if a < b { s } else { n - s };
                                let list = edge_points
                                    .entry(key)
                                    .or_insert_with(|| vec![u32::MAX; n + 1]);
                                if list[from_small] == u32::MAX {
                                    list[from_small] = push(&mut out, x);
                                }
                                list[from_small]
                            }
                        }
                    }
                };
            }
        }
        for i in 0..n {
            for j in 0..n - i {
                faces.push([grid[at(i, j)], grid[at(i + 1, j)], grid[at(i, j + 1)]]);
                if i + j + 1 < n {
                    faces.push([
                        grid[at(i + 1, j)],
                        grid[at(i + 1, j + 1)],
                        grid[at(i, j + 1)],
                    ]);
                }
            }
        }
    }
    CurvedInterpolant {
        positions: out,
        triangles: faces,
        facet_deviation,
    }
}

fn push(out: &mut Vec<[f64; 3]>, x: [f64; 3]) -> u32 {
    out.push(x);
    (out.len() - 1) as u32
}

/// The crease and boundary edges of a tessellation, and the curves their chains follow.
struct Lines {
    /// The crease and boundary edges (`(a, b)`, `a < b`): each face takes them as they are,
    /// not from its corner normals.
    straight: std::collections::HashSet<(u32, u32)>,
    /// At a vertex where exactly two of them meet (a chain goes on through it), the chain's
    /// unit tangent (along its neighbours, as Catmull–Rom would): a crease's edges are the
    /// cubic with these end tangents, shared by both faces; elsewhere they stay straight.
    tangent: std::collections::HashMap<u32, [f64; 3]>,
}

impl Lines {
    fn new(positions: &[[f64; 3]], facets: &Facets) -> Self {
        let straight = straight_edges(positions, facets);
        let mut ends: std::collections::HashMap<u32, Vec<u32>> = Default::default();
        for &(a, b) in &straight {
            ends.entry(a).or_default().push(b);
            ends.entry(b).or_default().push(a);
        }
        let tangent = ends
            .into_iter()
            .filter(|(_, w)| w.len() == 2)
            .filter_map(|(v, w)| {
                let d = sub(positions[w[1] as usize], positions[w[0] as usize]);
                let l = norm(d);
                (l > 0.0).then(|| (v, scale(d, 1.0 / l)))
            })
            .collect();
        Self { straight, tangent }
    }
}

/// The crease and boundary edges (`(a, b)`, `a < b`): the edges that turn and are not
/// smooth under the chordal tolerance ([`classify_edges_chordal`]).
fn straight_edges(
    positions: &[[f64; 3]],
    facets: &Facets,
) -> std::collections::HashSet<(u32, u32)> {
    let class = classify_edges_chordal(positions, facets).class;
    let mut s: std::collections::HashSet<(u32, u32)> = facets
        .edges
        .iter()
        .zip(&class)
        .filter(|(_, &c)| c == EdgeClass::Crease)
        .map(|(e, _)| (e.ends[0], e.ends[1]))
        .collect();
    s.extend(
        facets
            .boundary
            .iter()
            .map(|b| (b[0].min(b[1]), b[0].max(b[1]))),
    );
    // Edges of more than two faces are in neither list: straight as well.
    let mut count: std::collections::HashMap<(u32, u32), usize> = Default::default();
    for t in &facets.triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    s.extend(count.into_iter().filter(|&(_, c)| c > 2).map(|(e, _)| e));
    s
}

/// The normal of every face corner (see the module docs).
fn corner_normals(
    positions: &[[f64; 3]],
    facets: &Facets,
    straight: &std::collections::HashSet<(u32, u32)>,
) -> Vec<[[f64; 3]; 3]> {
    let tris = &facets.triangles;
    let mut vertex_faces: Vec<Vec<u32>> = vec![Vec::new(); positions.len()];
    for (f, t) in tris.iter().enumerate() {
        for &v in t {
            vertex_faces[v as usize].push(f as u32);
        }
    }
    let mut out = vec![[[0.0; 3]; 3]; tris.len()];
    for (v, around) in vertex_faces.iter().enumerate() {
        let v = v as u32;
        // Fans: faces around v joined across their shared non-straight edges (union-find).
        let mut parent: Vec<usize> = (0..around.len()).collect();
        fn root(p: &mut [usize], mut i: usize) -> usize {
            while p[i] != i {
                p[i] = p[p[i]];
                i = p[i];
            }
            i
        }
        for a in 0..around.len() {
            for b in a + 1..around.len() {
                let (ta, tb) = (tris[around[a] as usize], tris[around[b] as usize]);
                let shared = ta.iter().find(|&&w| w != v && tb.contains(&w));
                if let Some(&w) = shared {
                    if !straight.contains(&(v.min(w), v.max(w))) {
                        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                        parent[ra] = rb;
                    }
                }
            }
        }
        let roots: Vec<usize> = (0..around.len()).map(|a| root(&mut parent, a)).collect();
        for fan in 0..around.len() {
            if roots[fan] != fan {
                continue;
            }
            let members: Vec<u32> = (0..around.len())
                .filter(|&a| roots[a] == fan)
                .map(|a| around[a])
                .collect();
            let n = fan_normal(positions, facets, v, &members);
            for &f in &members {
                let c = tris[f as usize].iter().position(|&w| w == v).unwrap_or(0);
                out[f as usize][c] = n;
            }
        }
    }
    out
}

/// The normal of the fan `members` around vertex `v`: its largest plane's, else the
/// angle-weighted mean of its faces' normals.
fn fan_normal(positions: &[[f64; 3]], facets: &Facets, v: u32, members: &[u32]) -> [f64; 3] {
    let plane = members
        .iter()
        .map(|&f| facets.region[f as usize] as usize)
        .filter(|&r| facets.regions[r].faces >= MIN_PLANE_FACES)
        .max_by(|&a, &b| facets.regions[a].area.total_cmp(&facets.regions[b].area));
    if let Some(r) = plane {
        return facets.regions[r].normal;
    }
    let mut sum = [0.0; 3];
    for &f in members {
        let t = facets.triangles[f as usize];
        let c = t.iter().position(|&w| w == v).unwrap_or(0);
        let p = positions[v as usize];
        let (a, b) = (
            sub(positions[t[(c + 1) % 3] as usize], p),
            sub(positions[t[(c + 2) % 3] as usize], p),
        );
        let (la, lb) = (norm(a), norm(b));
        if la == 0.0 || lb == 0.0 {
            continue;
        }
        let angle = (dot(a, b) / (la * lb)).clamp(-1.0, 1.0).acos();
        sum = add(sum, scale(facets.normals[f as usize], angle));
    }
    let l = norm(sum);
    if l > 0.0 {
        scale(sum, 1.0 / l)
    } else {
        [0.0; 3]
    }
}

/// A curved PN triangle: the cubic Bézier triangle of three corners and their normals.
struct PnTriangle {
    /// Control points b300, b030, b003, b210, b120, b021, b012, b102, b201, b111.
    b: [[f64; 3]; 10],
}

impl PnTriangle {
    /// The PN triangle over corners `p` with normals `n`; sides `i → i+1` marked in
    /// `straight` get the straight edge's control points. A zero normal leaves its corner's
    /// edges straight.
    fn new(
        p: [[f64; 3]; 3],
        n: [[f64; 3]; 3],
        straight: [bool; 3],
        tangent: [Option<[f64; 3]>; 3],
    ) -> Self {
        // The control point of side i → j next to corner i.
        let near = |i: usize, j: usize, side: usize| {
            let d = sub(p[j], p[i]);
            let lin = add(p[i], scale(d, 1.0 / 3.0));
            if straight[side] {
                // A crease or rim: along the curve its chain of edges follows at i.
                return match tangent[i] {
                    Some(t) => {
                        let t = if dot(t, d) < 0.0 { scale(t, -1.0) } else { t };
                        add(p[i], scale(t, norm(d) / 3.0))
                    }
                    None => lin,
                };
            }
            if n[i] == [0.0; 3] || n[j] == [0.0; 3] {
                return lin;
            }
            sub(lin, scale(n[i], dot(d, n[i]) / 3.0))
        };
        let b210 = near(0, 1, 0);
        let b120 = near(1, 0, 0);
        let b021 = near(1, 2, 1);
        let b012 = near(2, 1, 1);
        let b102 = near(2, 0, 2);
        let b201 = near(0, 2, 2);
        let e = scale(
            [b210, b120, b021, b012, b102, b201]
                .into_iter()
                .fold([0.0; 3], add),
            1.0 / 6.0,
        );
        let c = scale(add(add(p[0], p[1]), p[2]), 1.0 / 3.0);
        let b111 = add(e, scale(sub(e, c), 0.5));
        Self {
            b: [p[0], p[1], p[2], b210, b120, b021, b012, b102, b201, b111],
        }
    }

    /// The PN triangle of face `t` with corner normals `n`, its `straight` sides kept straight.
    fn of_face(positions: &[[f64; 3]], t: [u32; 3], n: [[f64; 3]; 3], lines: &Lines) -> Self {
        let sides = [0, 1, 2].map(|i| {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            lines.straight.contains(&(a.min(b), a.max(b)))
        });
        let tangent = t.map(|v| lines.tangent.get(&v).copied());
        Self::new(t.map(|v| positions[v as usize]), n, sides, tangent)
    }

    /// The point at barycentric coordinates `w` (of corners 0, 1, 2).
    fn at(&self, w: [f64; 3]) -> [f64; 3] {
        let [u, v, t] = w;
        let b = &self.b;
        let terms = [
            (b[0], u * u * u),
            (b[1], v * v * v),
            (b[2], t * t * t),
            (b[3], 3.0 * u * u * v),
            (b[4], 3.0 * u * v * v),
            (b[5], 3.0 * v * v * t),
            (b[6], 3.0 * v * t * t),
            (b[7], 3.0 * u * t * t),
            (b[8], 3.0 * u * u * t),
            (b[9], 6.0 * u * v * t),
        ];
        terms
            .iter()
            .fold([0.0; 3], |s, &(p, c)| add(s, scale(p, c)))
    }
}
