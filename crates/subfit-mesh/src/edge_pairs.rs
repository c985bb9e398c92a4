//! Pairing the faces around an edge shared by more than two faces, so that the surfaces
//! continue each other: the choice [`crate::cut_nonmanifold_edges`] makes before it cuts.
//!
//! Around an edge the faces are half-planes at angles `θ` about the edge's axis (Rossignac and
//! Cardoze, "Matchmaker: manifold BReps for non-manifold r-sets", ACM Symposium on Solid
//! Modeling and Applications 1999, §3: the faces around a non-manifold edge are paired by
//! their circular order, each pair bounding one cell, so that the result is an oriented
//! manifold; Guéziec et al., "Cutting and stitching: converting sets of polygons to manifold
//! surfaces", IEEE TVCG 7(2), 2001, §4, cut such edges into pairs). A face that runs along the
//! edge from its smaller to its larger vertex has its normal turned towards growing `θ`, one
//! that runs the other way towards falling `θ`. Two faces can continue each other with a
//! consistent orientation only when they run along the edge in opposite directions; the wedge
//! both normals face, from the first face's `θ` up to the second's, is then the space outside
//! both, and the pair continues most smoothly when that wedge is half a turn (a flat edge).
//!
//! Of the pairings of consistent faces (each face of the rarer direction with one of the
//! other), the one chosen has no two pairs whose wedges cross (two surfaces passing through
//! each other along the edge: Matchmaker's non-crossing rule) when there is one, and the
//! smallest sum of the pairs' departures from flat. So a sheet of no thickness written as two
//! coincident faces with opposite orientations (a thin part of a scan collapsed by the
//! reconstruction) is not paired with itself: each of its sides continues the side of the
//! surface it faces. Faces left over (more faces run one way than the other) are paired with
//! each other by flatness after turning one of them (the re-orientation turns it later), and a
//! last odd one is left alone.
//!
//! Pairings are enumerated up to [`MAX_PAIRINGS`] per edge (an edge of 12 faces, 6 each way);
//! beyond that the pairs are taken greedily, flattest first. Cost `O(k!)` per edge of `2k`
//! faces within that limit, `O(k³)` beyond.

use std::f64::consts::{PI, TAU};

use crate::edges::EdgeGroups;
use crate::polygons::Polygons;
use crate::vec3::{add, any_orthogonal, cross, dot, scale, sub, unit};

/// Pairings of one edge's faces enumerated at most; larger edges are paired greedily.
pub const MAX_PAIRINGS: usize = 720;

/// Angles (radians) closer than this are the same for [`crosses`]: coincident faces (the two
/// sides of a sheet of no thickness) get the same angle up to rounding, about `1e-16` rad.
const SAME_ANGLE: f64 = 1e-12;

/// A half-edge around the edge being paired: its id, its direction along the edge (`true`:
/// from the smaller vertex to the larger) and the angle of its face about the edge (`None`
/// for a face with no extent off the edge).
#[derive(Clone, Copy, Debug)]
struct Side {
    h: u32,
    forward: bool,
    theta: Option<f64>,
}

/// `groups` with every edge of more than two half-edges split into pairs (see the module docs)
/// and single half-edges for what is left. `next` is [`crate::edges::corner_next`] of `faces`,
/// whose vertex ids must index `positions`. Cost as the module docs say.
pub(crate) fn pair_up(
    faces: &Polygons,
    positions: &[[f64; 3]],
    next: &[u32],
    groups: &EdgeGroups,
) -> EdgeGroups {
    let mut order = Vec::with_capacity(groups.order.len());
    let mut starts = Vec::with_capacity(groups.starts.len());
    for e in 0..groups.len() {
        let g = groups.group(e);
        if g.len() <= 2 {
            starts.push(order.len() as u32);
            order.extend_from_slice(g);
            continue;
        }
        let sides = sides_of(faces, positions, next, g);
        let (pairs, singles) = pair_sides(&sides);
        for (a, b) in pairs {
            starts.push(order.len() as u32);
            order.extend([sides[a].h, sides[b].h]);
        }
        for a in singles {
            starts.push(order.len() as u32);
            order.push(sides[a].h);
        }
    }
    starts.push(order.len() as u32);
    EdgeGroups { order, starts }
}

/// The [`Side`]s of the half-edges `g` of one edge.
fn sides_of(faces: &Polygons, positions: &[[f64; 3]], next: &[u32], g: &[u32]) -> Vec<Side> {
    let idx = faces.indices();
    let (a, b) = (idx[g[0] as usize], idx[next[g[0] as usize] as usize]);
    let (lo, hi) = (a.min(b), a.max(b));
    let (plo, phi) = (positions[lo as usize], positions[hi as usize]);
    let axis = unit(sub(phi, plo));
    let basis = axis.and_then(|u| unit(any_orthogonal(u)).map(|x| (u, x, cross(u, x))));
    g.iter()
        .map(|&h| {
            let forward = idx[h as usize] == lo;
            let theta = basis.and_then(|(u, x, y)| {
                // The face's other corners, averaged: its direction off the edge.
                let (mut c, mut n) = ([0.0; 3], 0.0);
                let mut k = next[next[h as usize] as usize];
                while k != h {
                    c = add(c, positions[idx[k as usize] as usize]);
                    n += 1.0;
                    k = next[k as usize];
                }
                let d = sub(scale(c, 1.0 / n), plo);
                let w = sub(d, scale(u, dot(d, u)));
                unit(w).map(|w| dot(w, y).atan2(dot(w, x)))
            });
            Side { h, forward, theta }
        })
        .collect()
}

/// The wedge of a consistent pair: from the forward face's angle up to the backward face's
/// (where both normals point), as `(start, length)`; `None` when an angle is unknown.
fn wedge(fwd: Side, bwd: Side) -> Option<(f64, f64)> {
    let (s, t) = (fwd.theta?, bwd.theta?);
    Some((s, (t - s).rem_euclid(TAU)))
}

/// How far a consistent pair is from continuing flat (radians, `0..=π`); a face of unknown
/// angle counts as a quarter turn off.
fn departure(fwd: Side, bwd: Side) -> f64 {
    wedge(fwd, bwd).map_or(PI / 2.0, |(_, w)| (w - PI).abs())
}

/// Whether the wedges of two consistent pairs cross: exactly one face of the second lies
/// strictly inside the first's wedge. A face at the same angle as an end of the wedge (up to
/// [`SAME_ANGLE`]: the two sides of a sheet of no thickness) is not inside it.
fn crosses(p: (Side, Side), q: (Side, Side)) -> bool {
    let Some((s, w)) = wedge(p.0, p.1) else {
        return false;
    };
    let inside = |t: Option<f64>| {
        t.is_some_and(|t| {
            let r = (t - s).rem_euclid(TAU);
            r > SAME_ANGLE && r < w - SAME_ANGLE
        })
    };
    inside(q.0.theta) != inside(q.1.theta)
}

/// Pairs of indices into `sides` (consistent pairs first, then turned ones) and the indices
/// left single.
fn pair_sides(sides: &[Side]) -> (Vec<(usize, usize)>, Vec<usize>) {
    let fwd: Vec<usize> = (0..sides.len()).filter(|&i| sides[i].forward).collect();
    let bwd: Vec<usize> = (0..sides.len()).filter(|&i| !sides[i].forward).collect();
    let mut pairs = consistent_pairs(sides, &fwd, &bwd);
    let mut left: Vec<usize> = (0..sides.len())
        .filter(|i| !pairs.iter().any(|&(a, b)| a == *i || b == *i))
        .collect();
    // Left over: all run one way; pair them flattest first, one to be turned.
    while left.len() >= 2 {
        let mut best = (f64::INFINITY, 0, 1);
        for i in 0..left.len() {
            for j in i + 1..left.len() {
                let d = match (sides[left[i]].theta, sides[left[j]].theta) {
                    (Some(s), Some(t)) => {
                        let a = (t - s).rem_euclid(TAU);
                        PI - a.min(TAU - a)
                    }
                    _ => PI / 2.0,
                };
                if d < best.0 {
                    best = (d, i, j);
                }
            }
        }
        let (_, i, j) = best;
        pairs.push((left[i], left[j]));
        left.remove(j);
        left.remove(i);
    }
    (pairs, left)
}

/// The best pairing of each face of the smaller of `fwd`, `bwd` with one of the other (see
/// the module docs), as `(forward, backward)` index pairs.
fn consistent_pairs(sides: &[Side], fwd: &[usize], bwd: &[usize]) -> Vec<(usize, usize)> {
    let (few, many, few_fwd) = if fwd.len() <= bwd.len() {
        (fwd, bwd, true)
    } else {
        (bwd, fwd, false)
    };
    let pair = |i: usize, j: usize| {
        if few_fwd {
            (few[i], many[j])
        } else {
            (many[j], few[i])
        }
    };
    if injections(few.len(), many.len()) > MAX_PAIRINGS {
        return greedy_pairs(sides, fwd, bwd);
    }
    // Depth-first over the injections few → many; cost (crossings, departure).
    let mut best: Option<((usize, f64), Vec<usize>)> = None;
    let mut chosen: Vec<usize> = Vec::with_capacity(few.len());
    let mut used = vec![false; many.len()];
    let mut visit = |chosen: &[usize]| {
        let pairs: Vec<(usize, usize)> = chosen
            .iter()
            .enumerate()
            .map(|(i, &j)| pair(i, j))
            .collect();
        let mut crossings = 0;
        let mut dep = 0.0;
        for (k, &(a, b)) in pairs.iter().enumerate() {
            dep += departure(sides[a], sides[b]);
            for &(c, d) in &pairs[k + 1..] {
                crossings += usize::from(crosses((sides[a], sides[b]), (sides[c], sides[d])));
            }
        }
        let better = best
            .as_ref()
            .is_none_or(|((c, d), _)| crossings < *c || (crossings == *c && dep < *d - 1e-12));
        if better {
            best = Some(((crossings, dep), chosen.to_vec()));
        }
    };
    enumerate(few.len(), &mut used, &mut chosen, &mut visit);
    best.map(|(_, c)| c.iter().enumerate().map(|(i, &j)| pair(i, j)).collect())
        .unwrap_or_default()
}

/// Calls `visit` with every injection `0..k → 0..used.len()` (as the image of each element),
/// in lexicographic order.
fn enumerate(
    k: usize,
    used: &mut [bool],
    chosen: &mut Vec<usize>,
    visit: &mut dyn FnMut(&[usize]),
) {
    if chosen.len() == k {
        visit(chosen);
        return;
    }
    for j in 0..used.len() {
        if !used[j] {
            used[j] = true;
            chosen.push(j);
            enumerate(k, used, chosen, visit);
            chosen.pop();
            used[j] = false;
        }
    }
}

/// Number of injections of `k` elements into `n`, saturating past [`MAX_PAIRINGS`].
fn injections(k: usize, n: usize) -> usize {
    let mut count = 1usize;
    for i in 0..k {
        count = count.saturating_mul(n - i);
        if count > MAX_PAIRINGS {
            return usize::MAX;
        }
    }
    count
}

/// Consistent pairs taken flattest first (for edges with too many faces to enumerate).
fn greedy_pairs(sides: &[Side], fwd: &[usize], bwd: &[usize]) -> Vec<(usize, usize)> {
    let mut fwd = fwd.to_vec();
    let mut bwd = bwd.to_vec();
    let mut pairs = Vec::new();
    while !fwd.is_empty() && !bwd.is_empty() {
        let mut best = (f64::INFINITY, 0, 0);
        for (i, &a) in fwd.iter().enumerate() {
            for (j, &b) in bwd.iter().enumerate() {
                let d = departure(sides[a], sides[b]);
                if d < best.0 {
                    best = (d, i, j);
                }
            }
        }
        let (_, i, j) = best;
        pairs.push((fwd.remove(i), bwd.remove(j)));
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edges::{corner_faces, corner_next, group_edges};

    /// Triangles on the edge from vertex 0 `(0, 0, 0)` to vertex 1 `(1, 0, 0)`, one per
    /// `(angle in degrees about +x from +y, forward)`: forward ones run 0 → 1. Returns the
    /// pairs of faces [`pair_up`] makes there, each sorted, in order, and the faces left single.
    fn pairs_around(faces: &[(f64, bool)]) -> (Vec<[u32; 2]>, Vec<u32>) {
        let mut p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
        let mut polys = Polygons::new();
        for (i, &(deg, forward)) in faces.iter().enumerate() {
            let t = deg.to_radians();
            p.push([0.5, t.cos(), t.sin()]);
            let c = i as u32 + 2;
            polys.push(&if forward { [0, 1, c] } else { [1, 0, c] });
        }
        let next = corner_next(&polys);
        let groups = group_edges(&polys, &next, p.len(), |_| true);
        let paired = pair_up(&polys, &p, &next, &groups);
        let face_of = corner_faces(&polys);
        let (mut pairs, mut singles) = (Vec::new(), Vec::new());
        for e in 0..paired.len() {
            let g: Vec<u32> = paired
                .group(e)
                .iter()
                .map(|&h| face_of[h as usize])
                .collect();
            let shared = g.iter().all(|&f| polys.face(crate::FaceId(f)).len() == 3)
                && paired
                    .group(e)
                    .iter()
                    .all(|&h| polys.indices()[h as usize] < 2)
                && paired
                    .group(e)
                    .iter()
                    .all(|&h| polys.indices()[next[h as usize] as usize] < 2);
            match g[..] {
                [a, b] if shared => pairs.push([a.min(b), a.max(b)]),
                [a] if shared => singles.push(a),
                _ => {}
            }
        }
        pairs.sort_unstable();
        (pairs, singles)
    }

    #[test]
    fn each_side_of_a_sheet_of_no_thickness_continues_the_side_it_faces() {
        // A sheet along +y written on both sides (faces 0 and 1, the same triangle turned),
        // meeting a thick part along −y whose top (face 2, rising) and bottom (face 3) part.
        let (pairs, singles) = pairs_around(&[
            (0.0, true),    // top side of the sheet, normal +z
            (0.0, false),   // bottom side, normal −z
            (160.0, false), // the thick part's top, normal up
            (200.0, true),  // its bottom, normal down
        ]);
        assert_eq!(pairs, vec![[0, 2], [1, 3]]);
        assert!(singles.is_empty());
    }

    #[test]
    fn surfaces_are_not_paired_through_each_other() {
        // Three forward faces a third of a turn apart, each with a backward face just past
        // its opposite: the flattest pairs (0, 3), (1, 4), (2, 5) cross each other's wedges.
        // Of the pairings without a crossing the flattest keeps one of them, (0, 3), and nests
        // the others inside its wedge (120° and 70°) and outside it (240° and 310°).
        let (pairs, _) = pairs_around(&[
            (0.0, true),
            (120.0, true),
            (240.0, true),
            (190.0, false),
            (310.0, false),
            (70.0, false),
        ]);
        assert_eq!(pairs, vec![[0, 3], [1, 5], [2, 4]]);
    }

    #[test]
    fn a_fin_is_left_single_and_two_leftovers_pair_turned() {
        // A flat surface (0 and 1) and a fin standing up (2): the fin is left alone.
        let (pairs, singles) = pairs_around(&[(0.0, true), (180.0, false), (90.0, true)]);
        assert_eq!((pairs, singles), (vec![[0, 1]], vec![2]));
        // Four faces all running one way: two pairs, each flattest after turning one face.
        let (pairs, singles) =
            pairs_around(&[(0.0, true), (90.0, true), (175.0, true), (265.0, true)]);
        assert_eq!((pairs, singles), (vec![[0, 2], [1, 3]], vec![]));
    }
}
