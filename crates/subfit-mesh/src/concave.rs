//! Concave corners of a tagged cage split by a crease.
//!
//! At a corner (a vertex tagged as a corner, or where three or more sharp edges meet, boundary
//! edges counted) the limit surface of every sector between two consecutive sharp edges is, to
//! first order, an affine image of the sector's characteristic map. Under the standard rules
//! (Hoppe et al. 1994; OpenSubdiv's `Sdc` corner and crease rules) that map fills a *convex*
//! wedge, so the surface of a sector whose opening angle is above π — a concave corner, such as
//! the inside corner of an L-shaped bracket or the notches of fandisk — cannot follow the data:
//! it spans the convex wedge between the two crease tangents instead, and folds over its own
//! crease curves by a fraction of the corner's edge length (Biermann, Levin and Zorin 2000,
//! "Piecewise smooth subdivision surfaces with normal control", add a concave-corner rule for
//! this; OpenSubdiv, USD and Blender have no such rule). On fandisk at the default
//! tolerance that fold is the fit's largest error (3.2e-3 of the unit cube, near one notch).
//!
//! A cage that stays within OpenSubdiv's semantics avoids the fold by topology: an extra crease
//! tag on an interior edge of the concave sector, from the corner into the sector, splits it
//! into two sectors below π each. The crease ends at a vertex with no other sharp edge, a dart,
//! which the smooth rules subdivide, so the extra tag changes nothing away from the corner
//! where the sector is flat, and the fit keeps it (a split crease edge gives two crease edges).
//! Where every interior edge of the sector ends on another crease (a narrow strip between two
//! feature curves, common on CAD parts), the middle one is split at its midpoint to give the
//! crease its dart: one control point per such corner.
//!
//! The angles are those of the cage's faces, so this is done on a cage that lies on the data
//! (the initial cage); a fitted cage's control points are off the surface and their angles say
//! little about the surface's.

use crate::vec3::{dot, norm, sub};
use crate::{HalfEdgeMesh, PolyMesh, Polygons, Tags, VertexId, SHARPNESS_INFINITE};

/// Sectors whose opening angle at a corner is above this (radians, 175°: also the
/// T-junctions where a crease meets another one that runs straight on) are split.
pub const CONCAVE_ANGLE: f64 = 175.0 * std::f64::consts::PI / 180.0;

/// A concave sector's middle edge `d` and its creases `t1`, `t2` (unit vectors from the
/// corner) have `d · (t1 + t2)` below this; for a flat sector of opening θ it is `2 cos(θ/2)`,
/// 0.2 at θ ≈ 168°.
const REFLEX_COSINE: f64 = 0.2;

/// What [`split_concave_corners`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct ConcaveSplits {
    /// Concave sectors found.
    pub sectors: usize,
    /// Crease tags added (one per sector split).
    pub creases: usize,
    /// Control points inserted to give a crease its interior end.
    pub inserted: usize,
}

/// Splits every concave sector of `cage`'s corners by a crease (see the module docs). A sector
/// is concave when the angles of its faces at the corner add up to more than
/// [`CONCAVE_ANGLE`] and its middle edge points out of the convex wedge between its two
/// creases (not into it, as on a bumpy fan between creases less than π apart). The new crease
/// runs along the interior edge nearest the sector's angular middle among those whose other
/// end has no sharp or boundary edge (so that no crease curve through it gets a corner); when there is none, the interior edge nearest the middle is split
/// at its midpoint (its two faces must be triangles that no other split touches, and at most
/// `max_new_points` points are inserted) and the crease runs to the new point. The crease takes
/// the corner's sharpness (the largest of its creases when the corner is untagged). A cage
/// that is not an oriented manifold is left alone (the code that needs one says why). Cost
/// O(#half-edges).
pub fn split_concave_corners(
    cage: &mut PolyMesh,
    tags: &mut Tags,
    max_new_points: usize,
) -> ConcaveSplits {
    split_concave_corners_with(cage, tags, max_new_points, &|_| false)
}

/// [`split_concave_corners`], where a sector may also take its crease to a vertex already on
/// a crease when `may_corner` says so for it: a vertex whose crease curves are polygons on
/// purpose (a faceted part's), which the new crease makes a corner (three sharp edges) without
/// changing its surface. A tessellation's decimated planar faces have no vertex off their
/// outlines, so a concave corner of one finds its crease this way without a new point.
pub fn split_concave_corners_with(
    cage: &mut PolyMesh,
    tags: &mut Tags,
    max_new_points: usize,
    may_corner: &dyn Fn(u32) -> bool,
) -> ConcaveSplits {
    let mut out = ConcaveSplits::default();
    if tags.is_empty() {
        return out;
    }
    let Ok(he) = HalfEdgeMesh::from_mesh(cage) else {
        return out;
    };
    let mut plans = Vec::new();
    for vi in 0..he.num_vertices() {
        plans.extend(concave_sectors(
            &he,
            cage,
            tags,
            VertexId(vi as u32),
            may_corner,
        ));
    }
    out.sectors = plans.len();
    // Edges to split at their midpoints, with the faces they touch (each face split once).
    let mut touched = vec![false; cage.faces.len()];
    let mut splits: Vec<(u32, u32, f64)> = Vec::new();
    for plan in plans {
        match plan.direct {
            Some(n) => {
                tags.set_crease(plan.corner, n, plan.sharpness);
                out.creases += 1;
            }
            None if splits.len() < max_new_points => {
                let Some(h) = he.find_half_edge(VertexId(plan.corner), VertexId(plan.middle))
                else {
                    continue;
                };
                let Some(t) = he.twin(h) else { continue };
                let faces = [he.face(h), he.face(t)];
                let triangles = faces.iter().all(|&f| cage.faces.face_len(f) == 3);
                let faces = faces.map(|f| f.idx());
                if !triangles || faces.iter().any(|&f| touched[f]) {
                    continue;
                }
                for f in faces {
                    touched[f] = true;
                }
                splits.push((plan.corner, plan.middle, plan.sharpness));
            }
            None => {}
        }
    }
    if splits.is_empty() {
        return out;
    }
    let mut faces = Polygons::default();
    let first_new = cage.positions.len() as u32;
    let new_of = |a: u32, b: u32| {
        splits
            .iter()
            .position(|&(c, m, _)| (c, m) == (a, b) || (c, m) == (b, a))
            .map(|i| first_new + i as u32)
    };
    for (f, face) in cage.faces.iter().enumerate() {
        if !touched[f] {
            faces.push(face);
            continue;
        }
        // A touched triangle has exactly one split edge: (a, b) → (a, m, c) and (m, b, c).
        let cut = (0..3).find_map(|i| {
            let (a, b, c) = (face[i], face[(i + 1) % 3], face[(i + 2) % 3]);
            new_of(a, b).map(|m| [[a, m, c], [m, b, c]])
        });
        match cut {
            Some([x, y]) => {
                faces.push(&x);
                faces.push(&y);
            }
            None => faces.push(face),
        }
    }
    for &(c, m, s) in &splits {
        let p = cage.positions[c as usize];
        let q = cage.positions[m as usize];
        cage.positions
            .push(std::array::from_fn(|k| 0.5 * (p[k] + q[k])));
        if let Some(normals) = cage.normals.as_mut() {
            let (a, b) = (normals[c as usize], normals[m as usize]);
            normals.push(std::array::from_fn(|k| 0.5 * (a[k] + b[k])));
        }
        if let Some(colors) = cage.colors.as_mut() {
            let a = colors[c as usize];
            colors.push(a);
        }
        let new = cage.positions.len() as u32 - 1;
        tags.set_crease(c, new, s);
        out.creases += 1;
        out.inserted += 1;
    }
    cage.faces = faces;
    out
}

/// A concave sector of a corner and how to split it.
struct Plan {
    corner: u32,
    /// The far end of the interior edge to tag, when one ends off every crease.
    direct: Option<u32>,
    /// The far end of the interior edge nearest the sector's angular middle.
    middle: u32,
    sharpness: f64,
}

/// The concave sectors at `v` (none when `v` is no corner).
fn concave_sectors(
    he: &HalfEdgeMesh,
    cage: &PolyMesh,
    tags: &Tags,
    v: VertexId,
    may_corner: &dyn Fn(u32) -> bool,
) -> Vec<Plan> {
    let mut plans = Vec::new();
    let k = he.outgoing(v).count();
    if k < 2 {
        return plans;
    }
    let boundary = he.is_boundary_vertex(v);
    let sharp = |a: VertexId, b: VertexId| tags.crease(a.0, b.0) > 0.0;
    // Ring edge i is v → ring[i]; face i lies between ring edges i and i + 1 (a boundary
    // vertex's ring ends with the incoming boundary edge).
    let ring: Vec<VertexId> = he.vertex_neighbors(v).collect();
    let is_sharp: Vec<bool> = (0..ring.len())
        .map(|i| sharp(v, ring[i]) || (boundary && (i == 0 || i + 1 == ring.len())))
        .collect();
    let sharp_count = is_sharp.iter().filter(|&&s| s).count();
    let corner_sharpness = tags.corner(v.0);
    if sharp_count == 0 || (corner_sharpness <= 0.0 && sharp_count < 3) {
        return plans;
    }
    let on_crease = |n: VertexId| {
        (he.is_boundary_vertex(n) || he.vertex_neighbors(n).any(|w| sharp(n, w)))
            && !may_corner(n.0)
    };
    let p = cage.positions[v.idx()];
    let angle = |i: usize| {
        let a = sub(cage.positions[ring[i].idx()], p);
        let b = sub(cage.positions[ring[(i + 1) % ring.len()].idx()], p);
        let c = dot(a, b) / (norm(a) * norm(b));
        if c.is_finite() {
            c.clamp(-1.0, 1.0).acos()
        } else {
            0.0
        }
    };
    let sharpness = if corner_sharpness > 0.0 {
        corner_sharpness
    } else {
        ring.iter()
            .map(|&n| tags.crease(v.0, n.0))
            .fold(0.0, f64::max)
            .min(SHARPNESS_INFINITE)
    };
    // Walk the faces from a sharp edge on; a sector is the run of faces up to the next one.
    let Some(first) = (0..ring.len()).find(|&i| is_sharp[i]) else {
        return plans;
    };
    let direction = |i: usize| {
        let d = sub(cage.positions[ring[i].idx()], p);
        let l = norm(d);
        d.map(|c| if l > 0.0 { c / l } else { 0.0 })
    };
    let mut sector: Vec<(usize, f64)> = Vec::new(); // (ring edge ending the face, cumulative angle)
    let (mut total, mut start) = (0.0, first);
    for step in 0..k {
        let f = (first + step) % ring.len();
        total += angle(f);
        let end = (f + 1) % ring.len();
        if !is_sharp[end] {
            sector.push((end, total));
            continue;
        }
        let off_middle = |&&(_, a): &&(usize, f64)| (a - 0.5 * total).abs();
        let nearest = |it: &mut dyn Iterator<Item = &(usize, f64)>| {
            it.min_by(|x, y| off_middle(x).total_cmp(&off_middle(y)))
                .map(|&(e, _)| e)
        };
        if let (true, Some(middle)) = (total > CONCAVE_ANGLE, nearest(&mut sector.iter())) {
            // A bumpy fan's angles add up to more than its opening: the sector is concave
            // only if its middle edge does not point into the convex wedge of its creases
            // (for a flat sector of angle θ this is θ > 168°).
            let wedge: [f64; 3] = std::array::from_fn(|c| direction(start)[c] + direction(end)[c]);
            if dot(direction(middle), wedge) < REFLEX_COSINE {
                let direct = nearest(&mut sector.iter().filter(|&&(e, _)| !on_crease(ring[e])));
                plans.push(Plan {
                    corner: v.0,
                    direct: direct.map(|e| ring[e].0),
                    middle: ring[middle].0,
                    sharpness,
                });
            }
        }
        sector.clear();
        (total, start) = (0.0, end);
    }
    plans
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::{gridded_box, l_prism};
    use crate::vec3::cross;

    /// Every edge whose faces' normals are more than 45° apart tagged infinitely sharp (the
    /// prisms' 90° edges), as a feature-aligned cage would be.
    fn sharp_edges(m: &PolyMesh) -> Tags {
        let he = HalfEdgeMesh::from_mesh(m).unwrap();
        let normal = |f| {
            let v = he.face_vertices(f);
            let p = |i: usize| m.positions[v[i].idx()];
            let n = cross(sub(p(1), p(0)), sub(p(2), p(0)));
            n.map(|c| c / norm(n))
        };
        let mut tags = Tags::new();
        for e in 0..he.num_edges() {
            let e = crate::EdgeId(e as u32);
            if let (f, Some(g)) = he.edge_faces(e) {
                if dot(normal(f), normal(g)) < 0.7 {
                    let [a, b] = he.edge_vertices(e);
                    tags.set_crease(a.0, b.0, SHARPNESS_INFINITE);
                }
            }
        }
        tags
    }

    #[test]
    fn the_concave_corners_of_an_l_prism_get_a_crease_into_their_sector() {
        let mut m = l_prism(2);
        let mut tags = sharp_edges(&m);
        // 18 curves, 22 units long, at two edges per unit.
        assert_eq!(tags.creases().len(), 44);
        let n = m.num_vertices();
        let done = split_concave_corners(&mut m, &mut tags, usize::MAX);
        // The top and bottom faces' 270° sectors at the ends of the concave edge.
        assert_eq!(
            done,
            ConcaveSplits {
                sectors: 2,
                creases: 2,
                inserted: 0
            }
        );
        assert_eq!(m.num_vertices(), n);
        // Each new crease runs from (1, 1, h) into the face's interior, near the sector's middle.
        for ((a, b), s) in tags.creases() {
            let (p, q) = (m.positions[a as usize], m.positions[b as usize]);
            if p[0] == q[0] || p[1] == q[1] {
                continue; // an axis-aligned edge: one of the 90° ones
            }
            assert_eq!(s, SHARPNESS_INFINITE);
            let corner = if p[..2] == [1.0, 1.0] { p } else { q };
            assert_eq!(corner[..2], [1.0, 1.0]);
            assert!(p[2] == q[2], "the crease stays in its face: {p:?} {q:?}");
        }
        // Nothing concave is left.
        let again = split_concave_corners(&mut m, &mut tags, usize::MAX);
        assert_eq!(again, ConcaveSplits::default());
    }

    #[test]
    fn a_sector_without_interior_vertices_gets_one_inserted_within_the_budget() {
        let coarse = l_prism(1);
        let tags = sharp_edges(&coarse);
        let (n, f) = (coarse.num_vertices(), coarse.faces.len());
        let (mut m, mut t) = (coarse.clone(), tags.clone());
        let done = split_concave_corners(&mut m, &mut t, usize::MAX);
        assert_eq!(
            done,
            ConcaveSplits {
                sectors: 2,
                creases: 2,
                inserted: 2
            }
        );
        assert_eq!(m.num_vertices(), n + 2);
        assert_eq!(m.faces.len(), f + 4);
        let he = HalfEdgeMesh::from_mesh(&m).unwrap();
        assert_eq!((he.genus(), he.boundary_loops().len()), (0, 0));
        // The new points lie on their face, in the middle of an edge from the concave corner.
        for v in n..n + 2 {
            let p = m.positions[v];
            assert!(p[2] == 0.0 || p[2] == 1.0, "{p:?}");
            assert!(he.vertex_neighbors(VertexId(v as u32)).any(|w| {
                let q = m.positions[w.idx()];
                q[..2] == [1.0, 1.0] && t.is_sharp_edge(v as u32, w.0)
            }));
        }
        assert_eq!(
            split_concave_corners(&mut m, &mut t, usize::MAX),
            ConcaveSplits::default()
        );
        // A budget of one point: one sector split, the other left.
        let (mut m, mut t) = (coarse.clone(), tags.clone());
        let done = split_concave_corners(&mut m, &mut t, 1);
        assert_eq!((done.sectors, done.creases, done.inserted), (2, 1, 1));
        assert_eq!(m.num_vertices(), n + 1);
    }

    #[test]
    fn convex_corners_and_untagged_cages_are_left_alone() {
        for open in [false, true] {
            let mut m = gridded_box(3, open);
            let mut tags = sharp_edges(&m);
            let before = (m.clone(), tags.clone());
            assert_eq!(
                split_concave_corners(&mut m, &mut tags, usize::MAX),
                ConcaveSplits::default()
            );
            assert_eq!((m, tags), before);
        }
        let mut m = l_prism(2);
        let mut tags = Tags::new();
        assert_eq!(
            split_concave_corners(&mut m, &mut tags, usize::MAX),
            ConcaveSplits::default()
        );
        assert!(tags.is_empty());
    }
}
