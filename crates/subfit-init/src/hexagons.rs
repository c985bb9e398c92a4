//! Two left-over triangles on either side of a quad become two quads.
//!
//! Pairing ([`crate::quads`]) leaves a triangle alone when no neighbour makes a good quad with
//! it: on a CAD part's feature cage the triangles between crease lines are long and thin, and
//! most of their pairs are non-convex or have a corner near 180° (fandisk: 106 of 256 faces
//! stay triangles, 24 of their pairs reflex, 14 near-straight, 13 across a crease). But a
//! quad `Q` with a left-over triangle on each of two of its sides makes a hexagon `T₁ ∪ Q ∪
//! T₂`, and a hexagon splits into two quads along one of its three long diagonals, through
//! edges the triangles never had. [`merge_hexagons`] does that wherever both quads are good
//! (the shape test of pairing: convex, corners below [`crate::PairOptions::max_corner_deg`],
//! no fold), best first by the worse quad's shape score: three faces become two quads, two
//! triangles fewer. The removed edges are interior and untagged, the diagonal is new, every
//! interior vertex keeps at least three edges, and hexagons touching the boundary are left
//! alone (the small-hole rule of pairing is about corners there), so genus, boundary loops,
//! tags and winding are kept; positions do not change.
//!
//! On fandisk's initial cage for `--scheme quad-tri` (205 points) the quads go from 150 of
//! 256 faces (59 %) to 170 of 236 (72 %) in four rounds ([`crate::quads`] runs them); fitted
//! with the defaults, the cage ends at 80 % quads (68 % before), Catmull-Clark at 78 % (73 %).
//!
//! Cost: `O(F)` to index the edges, `O(T)` candidates of constant work (`T` left-over
//! triangles), a sort; deterministic.

use std::collections::HashMap;

use subfit_mesh::{Polygons, Tags};

use crate::quad_shape::{shape_score, PairOptions};

/// Splits hexagons made of a quad and two left-over triangles into two quads (see the module
/// docs). Returns the new faces (merged faces in place of the first of their three faces, in
/// the input's face order otherwise) and the number of hexagons split.
pub(crate) fn merge_hexagons(
    faces: &Polygons,
    pos: &[[f64; 3]],
    tags: &Tags,
    options: &PairOptions,
) -> (Polygons, usize) {
    let list: Vec<Vec<u32>> = faces.iter().map(<[u32]>::to_vec).collect();
    let mut edge_faces: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    let mut valence: HashMap<u32, u32> = HashMap::new();
    for (f, face) in list.iter().enumerate() {
        for i in 0..face.len() {
            let e = key(face[i], face[(i + 1) % face.len()]);
            let owners = edge_faces.entry(e).or_default();
            if owners.is_empty() {
                *valence.entry(e.0).or_default() += 1;
                *valence.entry(e.1).or_default() += 1;
            }
            owners.push(f as u32);
        }
    }
    let on_boundary = boundary_vertices(&edge_faces);
    let interior_edge = |a: u32, b: u32| {
        edge_faces.get(&key(a, b)).is_some_and(|o| o.len() == 2) && tags.crease(a, b) == 0.0
    };
    let across = |f: usize, a: u32, b: u32| -> Option<usize> {
        let o = edge_faces.get(&key(a, b))?;
        (o.len() == 2).then(|| o.iter().map(|&g| g as usize).find(|&g| g != f))?
    };
    let mut candidates: Vec<Candidate> = Vec::new();
    for (t1, tri) in list.iter().enumerate() {
        if tri.len() != 3 {
            continue;
        }
        for i in 0..3 {
            let (a, b) = (tri[i], tri[(i + 1) % 3]);
            if !interior_edge(a, b) {
                continue;
            }
            let Some(q) = across(t1, a, b).filter(|&q| list[q].len() == 4) else {
                continue;
            };
            let quad = &list[q];
            for j in 0..4 {
                let (c, d) = (quad[j], quad[(j + 1) % 4]);
                if key(c, d) == key(a, b) || !interior_edge(c, d) {
                    continue;
                }
                // Each hexagon once: from its lower-numbered triangle.
                let Some(t2) = across(q, c, d).filter(|&t| t > t1 && list[t].len() == 3) else {
                    continue;
                };
                let Some(hex) = hexagon(&list[t1], quad, &list[t2]) else {
                    continue;
                };
                if hex.iter().any(|v| on_boundary.contains(v)) {
                    continue;
                }
                let removed = [a, b, c, d];
                if let Some(best) = best_split(&hex, pos, options, &edge_faces, |v, gain| {
                    keeps_edges(&valence, &removed, v, gain)
                }) {
                    candidates.push((best.0, [t1, q, t2], best.1, removed));
                }
            }
        }
    }
    candidates.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    let mut used = vec![false; list.len()];
    let mut replaced: Vec<Option<[[u32; 4]; 2]>> = vec![None; list.len()];
    let mut merged = 0;
    for (_, [t1, q, t2], quads, removed) in candidates {
        if used[t1] || used[q] || used[t2] {
            continue;
        }
        // An earlier merge may have added this diagonal, or taken edges from its vertices.
        let (a, b) = (quads[0][0], quads[0][3]);
        if edge_faces.contains_key(&key(a, b))
            || !quads[0]
                .iter()
                .chain(&quads[1])
                .all(|&v| keeps_edges(&valence, &removed, v, u32::from(v == a || v == b)))
        {
            continue;
        }
        for v in removed {
            *valence.get_mut(&v).expect("an edge's end point") -= 1;
        }
        for v in [a, b] {
            *valence.entry(v).or_default() += 1;
        }
        edge_faces.insert(key(a, b), Vec::new());
        for f in [t1, q, t2] {
            used[f] = true;
        }
        replaced[t1.min(q).min(t2)] = Some(quads);
        merged += 1;
    }
    let mut out = Polygons::new();
    for (f, face) in list.iter().enumerate() {
        match &replaced[f] {
            Some(quads) => {
                for quad in quads {
                    out.push(quad);
                }
            }
            None if used[f] => {}
            None => out.push(face),
        }
    }
    (out, merged)
}

/// Whether `v` keeps at least three edges once the `removed` edges' end points (two edges,
/// `[a, b, c, d]` for `a–b` and `c–d`) lose them and it gains `gain`.
fn keeps_edges(valence: &HashMap<u32, u32>, removed: &[u32; 4], v: u32, gain: u32) -> bool {
    let lost = removed.iter().filter(|&&w| w == v).count() as u32;
    valence.get(&v).copied().unwrap_or(0) + gain >= 3 + lost
}

/// A hexagon split: the worse quad's shape score, the faces (triangle, quad, triangle), the
/// two quads, and the end points of the two edges removed.
type Candidate = (f64, [usize; 3], [[u32; 4]; 2], [u32; 4]);

fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

fn boundary_vertices(edge_faces: &HashMap<(u32, u32), Vec<u32>>) -> std::collections::HashSet<u32> {
    edge_faces
        .iter()
        .filter(|(_, o)| o.len() == 1)
        .flat_map(|(&(a, b), _)| [a, b])
        .collect()
}

/// The boundary cycle of `t1 ∪ quad ∪ t2` in their winding, when it is a simple hexagon: the
/// triangles on two different sides of the quad, sharing no vertex outside it.
fn hexagon(t1: &[u32], quad: &[u32], t2: &[u32]) -> Option<[u32; 6]> {
    let h = merge(t1, quad)?;
    let h = merge(&h, t2)?;
    let mut sorted = h.clone();
    sorted.sort_unstable();
    sorted.dedup();
    (h.len() == 6 && sorted.len() == 6).then(|| std::array::from_fn(|i| h[i]))
}

/// The boundary cycle of two faces that share one edge, in their winding.
fn merge(f: &[u32], g: &[u32]) -> Option<Vec<u32>> {
    let (nf, ng) = (f.len(), g.len());
    // The shared edge runs x → y in f (and y → x in g).
    let i = (0..nf).find(|&i| {
        let (x, y) = (f[i], f[(i + 1) % nf]);
        (0..ng).any(|j| g[j] == y && g[(j + 1) % ng] == x)
    })?;
    let (x, y) = (f[i], f[(i + 1) % nf]);
    let j = (0..ng).find(|&j| g[j] == x)?;
    // f from y round to x, then g from x round to y (its end points left out).
    let mut out: Vec<u32> = (1..=nf).map(|k| f[(i + k) % nf]).collect();
    debug_assert_eq!((out[0], out[nf - 1]), (y, x));
    out.extend((1..ng - 1).map(|k| g[(j + k) % ng]));
    debug_assert_eq!(g[(j + ng - 1) % ng], y, "g runs y → x");
    Some(out)
}

/// The best of the three ways to split `hex` into two quads by a long diagonal: the lower of
/// the two quads' shape scores and the quads; `None` when no way gives two good quads, the
/// diagonal exists already, or an end point would keep too few edges (`keeps(v, gain)`).
fn best_split(
    hex: &[u32; 6],
    pos: &[[f64; 3]],
    options: &PairOptions,
    edge_faces: &HashMap<(u32, u32), Vec<u32>>,
    keeps: impl Fn(u32, u32) -> bool,
) -> Option<(f64, [[u32; 4]; 2])> {
    let mut best: Option<(f64, [[u32; 4]; 2])> = None;
    for k in 0..3 {
        let (a, b) = (hex[k], hex[k + 3]);
        if edge_faces.contains_key(&key(a, b)) {
            continue;
        }
        let q1 = [hex[k], hex[k + 1], hex[k + 2], hex[k + 3]];
        let q2 = [hex[k + 3], hex[(k + 4) % 6], hex[(k + 5) % 6], hex[k]];
        // Every hexagon vertex but the diagonal's loses the removed edges only.
        if !hex.iter().all(|&v| keeps(v, u32::from(v == a || v == b))) {
            continue;
        }
        let score = |q: [u32; 4]| shape_score(q.map(|v| pos[v as usize]), options).ok();
        let (Some(s1), Some(s2)) = (score(q1), score(q2)) else {
            continue;
        };
        let s = s1.min(s2);
        if best.as_ref().is_none_or(|b| s > b.0) {
            best = Some((s, [q1, q2]));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 5 × 3 grid of unit quads; cells (1, 1) and (3, 1) cut into two triangles each, so
    /// that one triangle of each borders the quad (2, 1) between them. The hexagon they make
    /// splits into two parallelograms along (2,1)–(3,2) only (the other diagonals leave a
    /// straight corner).
    fn grid() -> (Vec<[f64; 3]>, Polygons) {
        let id = |x: u32, y: u32| y * 6 + x;
        let pos = (0..4)
            .flat_map(|y| (0..6).map(move |x| [f64::from(x), f64::from(y), 0.0]))
            .collect();
        let mut faces = Polygons::new();
        for y in 0..3 {
            for x in 0..5 {
                let (a, b, c, d) = (id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1));
                match (x, y) {
                    // Diagonals (1,1)–(2,2) and (3,1)–(4,2): the triangles (1,1) (2,1) (2,2)
                    // and (3,1) (4,2) (3,2) border the quad (2, 1).
                    (1 | 3, 1) => {
                        faces.push(&[a, b, c]);
                        faces.push(&[a, c, d]);
                    }
                    _ => faces.push(&[a, b, c, d]),
                }
            }
        }
        (pos, faces)
    }

    fn counts(faces: &Polygons) -> (usize, usize) {
        let q = faces.iter().filter(|f| f.len() == 4).count();
        (q, faces.len() - q)
    }

    fn edges(faces: &Polygons) -> HashMap<(u32, u32), usize> {
        let mut e = HashMap::new();
        for f in faces.iter() {
            for i in 0..f.len() {
                *e.entry(key(f[i], f[(i + 1) % f.len()])).or_default() += 1;
            }
        }
        e
    }

    #[test]
    fn two_triangles_beside_a_quad_become_two_quads() {
        let (pos, faces) = grid();
        assert_eq!(counts(&faces), (13, 4));
        let (out, n) = merge_hexagons(&faces, &pos, &Tags::new(), &PairOptions::default());
        assert_eq!(n, 1);
        assert_eq!(counts(&out), (14, 2));
        // Same vertices, a manifold disk still: every edge on one or two faces, one edge
        // fewer (two removed, one added), V − E + F unchanged.
        let (before, after) = (edges(&faces), edges(&out));
        assert!(after.values().all(|&k| k == 1 || k == 2));
        assert_eq!(after.len() + 1, before.len());
        let euler = |e: usize, f: usize| 24 - e as i64 + f as i64;
        assert_eq!(
            euler(after.len(), out.len()),
            euler(before.len(), faces.len())
        );
        // Both new quads are convex, counter-clockwise like the rest (positive area).
        for f in out.iter().filter(|f| f.len() == 4) {
            let area: f64 = (0..4)
                .map(|i| {
                    let (p, q) = (pos[f[i] as usize], pos[f[(i + 1) % 4] as usize]);
                    p[0] * q[1] - q[0] * p[1]
                })
                .sum();
            assert!(area > 0.0, "{f:?}");
        }
    }

    #[test]
    fn a_crease_between_them_keeps_the_triangles() {
        let (pos, faces) = grid();
        let mut tags = Tags::new();
        // The edge between the left triangle and the quad: (2, 1)–(2, 2).
        tags.set_crease(8, 14, 2.0);
        let (out, n) = merge_hexagons(&faces, &pos, &tags, &PairOptions::default());
        assert_eq!(n, 0);
        assert_eq!(out, faces);
    }
}
