//! Convex pieces of a planar contour, and their split into quads and triangles (Lavoué et al.
//! 2007, "Subdivision surface fitting with quad/triangle meshes" §4.4: a planar contour of
//! control points becomes a facet of the initial control polyhedron "if it is convex, … and if
//! not, we decompose it into convex parts, using the algorithm from Hertel and Mehlhorn").
//!
//! [`convex_pieces`] follows Hertel & Mehlhorn (1983, "Fast triangulation of simple polygons"):
//! triangulate (ear clipping, best-shaped ear first), then remove the diagonals one by one
//! whenever the two polygons they separate merge into a convex one, those between two convex
//! corners of the contour first (they always go): at most `2r + 1` pieces for `r` reflex
//! corners, at most four times the optimum. Then, where a convex piece is wedged between two
//! kept diagonals at a reflex corner, the three pieces become two when one diagonal from that
//! corner across the middle piece suffices. [`quads_and_triangles`] splits a convex piece into
//! quads and at most one triangle, maximizing the worst corner. Both work in the plane of the
//! contour's Newell normal; points on a straight line (zero turn) stay in the pieces.

use std::f64::consts::PI;
use std::iter::successors;

use subfit_mesh::vec3::{any_orthogonal, cross, dot, normalize, polygon_normal, sub};

/// A turn whose sine (relative to the two edge lengths) is within this of zero is straight.
const STRAIGHT_SINE: f64 = 1e-9;

/// [`quads_and_triangles`] splits pieces of up to this many vertices optimally (about `m⁴/24`
/// steps); from a larger piece, runs of this many vertices are cut off first.
const MAX_EXACT: usize = 64;

/// Cycles of point indices.
type Cycles = Vec<Vec<usize>>;

/// `(b − a) × (c − a)`: twice the signed area of the triangle `a b c`.
fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

fn dist2(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// A contour in 2D coordinates of its Newell plane, and its orientation there (±1).
struct Flat {
    p: Vec<[f64; 2]>,
    sign: f64,
}

impl Flat {
    /// `None` when the normal or the area is zero or not finite.
    fn new(points: &[[f64; 3]]) -> Option<Flat> {
        let ids: Vec<u32> = (0..points.len()).map(|i| i as u32).collect();
        let n = normalize(polygon_normal(points, &ids))?;
        let (u, v) = (any_orthogonal(n), cross(n, any_orthogonal(n)));
        let at = |p: [f64; 3]| [dot(sub(p, points[0]), u), dot(sub(p, points[0]), v)];
        let p: Vec<[f64; 2]> = points.iter().map(|&q| at(q)).collect();
        let edge = |i: usize| orient([0.0; 2], p[i], p[(i + 1) % p.len()]);
        let area: f64 = (0..p.len()).map(edge).sum();
        let sign = area.signum();
        (area != 0.0 && area.is_finite()).then_some(Flat { p, sign })
    }

    /// The turn at `b` of the path `a b c`: 1 convex, 0 straight (or a zero-length edge), −1
    /// reflex or back on itself.
    fn turn(&self, a: usize, b: usize, c: usize) -> i8 {
        let (a, b, c) = (self.p[a], self.p[b], self.p[c]);
        let cr = self.sign * orient(a, b, c);
        let tol = STRAIGHT_SINE * (dist2(a, b) * dist2(b, c)).sqrt();
        let back = (b[0] - a[0]) * (c[0] - b[0]) + (b[1] - a[1]) * (c[1] - b[1]) < 0.0;
        i8::from(cr > tol) - i8::from(cr <= tol && (cr < -tol || back))
    }

    /// Whether the cycle never turns reflex.
    fn convex(&self, cycle: &[usize]) -> bool {
        let (k, at) = (cycle.len(), |s: usize| cycle[s % cycle.len()]);
        (0..k).all(|t| self.turn(at(t), at(t + 1), at(t + 2)) >= 0)
    }
}

/// Splits the closed contour `points` (3D, roughly planar, in order, last not repeated, ≥ 3
/// points, simple when projected onto its best plane) into convex pieces: lists of indices into
/// `points`, each in the contour's order (same orientation). A convex contour gives one piece
/// (all indices).
///
/// Projection plane: Newell's normal of the contour. Collinear consecutive points (zero turn)
/// are kept in the pieces (they are control points) and do not make a polygon non-convex.
/// Never panics on degenerate input (repeated points, all collinear, tiny area): falls back to
/// a fan or ear-clipped triangles. Each piece starts at its smallest index (so its indices
/// increase) and the pieces are sorted; fewer than 3 points make one piece (none if empty).
///
/// Cost: O(n²) for n points (n is small, ≤ a few hundred), up to O(n³) for degenerate input
/// or many diagonals at one reflex corner.
pub fn convex_pieces(points: &[[f64; 3]]) -> Vec<Vec<usize>> {
    let n = points.len();
    let all: Vec<usize> = (0..n).collect();
    if n <= 3 {
        return if n == 0 { Vec::new() } else { vec![all] };
    }
    let Some(f) = Flat::new(points) else {
        return (1..n - 1).map(|i| vec![0, i, i + 1]).collect();
    };
    if f.convex(&all) {
        return vec![all];
    }
    let turn_at = |i: usize| f.turn((i + n - 1) % n, i, (i + 1) % n);
    let reflex: Vec<bool> = (0..n).map(|i| turn_at(i) < 0).collect();
    let (mut pieces, mut diagonals) = ear_clip(&f);
    diagonals.sort_by_key(|&(a, b)| reflex[a] || reflex[b]);
    for (a, b) in diagonals {
        if let Some((i, j, m)) = join(&pieces, a, b).filter(|(_, _, m)| f.convex(m)) {
            (pieces[i], pieces[j]) = (m, Vec::new());
        }
    }
    for v in (0..n).filter(|&v| reflex[v]) {
        let better = |p: &Cycles| p.iter().find_map(|mid| one_diagonal(&f, p, mid, v));
        while let Some(b) = better(&pieces) {
            pieces = b;
        }
    }
    pieces.retain(|p| !p.is_empty());
    for p in &mut pieces {
        let first = (0..p.len()).min_by_key(|&k| p[k]).unwrap_or(0);
        p.rotate_left(first);
    }
    pieces.sort();
    pieces
}

/// Ear quality of vertex `i` of the linked polygon: twice the triangle's area over the sum of
/// its squared edges when `prev[i] i next[i]` turns strictly convex and its closed triangle
/// (within a tolerance) holds no other remaining point but copies of its corners; else `None`.
fn ear(f: &Flat, prev: &[usize], next: &[usize], i: usize) -> Option<f64> {
    if f.turn(prev[i], i, next[i]) <= 0 {
        return None;
    }
    let (a, b, c) = (f.p[prev[i]], f.p[i], f.p[next[i]]);
    let mut v = next[next[i]];
    while v != prev[i] {
        let r = f.p[v];
        let on = |(x, y)| f.sign * orient(x, y, r) >= -STRAIGHT_SINE * dist2(x, y);
        if [(a, b), (b, c), (c, a)].into_iter().all(on) && r != a && r != b && r != c {
            return None;
        }
        v = next[v];
    }
    Some(f.sign * orient(a, b, c) / (dist2(a, b) + dist2(b, c) + dist2(c, a)))
}

/// Ear-clipping triangulation (triangles in the polygon's orientation) and its diagonals. After
/// a clip only the neighbours are re-tested; with no ear known all are, and with still none a
/// non-reflex vertex (else any) is clipped anyway.
fn ear_clip(f: &Flat) -> (Cycles, Vec<(usize, usize)>) {
    let n = f.p.len();
    let mut next: Vec<usize> = (0..n).map(|i| (i + 1) % n).collect();
    let mut prev: Vec<usize> = (0..n).map(|i| (i + n - 1) % n).collect();
    let mut quality: Vec<Option<f64>> = (0..n).map(|i| ear(f, &prev, &next, i)).collect();
    let best = |quality: &[Option<f64>]| {
        let ears = (0..n).filter_map(|i| Some((quality[i]?, i)));
        ears.min_by(|x, y| y.0.total_cmp(&x.0)).map(|(_, i)| i)
    };
    let (mut triangles, mut diagonals, mut start) = (Vec::new(), Vec::new(), 0);
    for remaining in (4..=n).rev() {
        let ring = successors(Some(start), |&v| Some(next[v])).take(remaining);
        let ring: Vec<usize> = ring.collect();
        if best(&quality).is_none() {
            ring.iter()
                .for_each(|&v| quality[v] = ear(f, &prev, &next, v));
        }
        let i = best(&quality).unwrap_or_else(|| {
            let flat = |&v: &usize| f.turn(prev[v], v, next[v]) >= 0;
            ring.iter().copied().find(flat).unwrap_or(start)
        });
        let (p, q) = (prev[i], next[i]);
        triangles.push(vec![p, i, q]);
        diagonals.push((p, q));
        (next[p], prev[q], quality[i]) = (q, p, None);
        quality[p] = ear(f, &prev, &next, p);
        quality[q] = ear(f, &prev, &next, q);
        start = q;
    }
    triangles.push(vec![prev[start], start, next[start]]);
    (triangles, diagonals)
}

/// The piece holding the directed edge `a → b`, and the edge's position in it.
fn find_edge(pieces: &[Vec<usize>], a: usize, b: usize) -> Option<(usize, usize)> {
    pieces.iter().enumerate().find_map(|(id, p)| {
        let k = (0..p.len()).find(|&k| p[k] == a && p[(k + 1) % p.len()] == b)?;
        Some((id, k))
    })
}

/// The pieces `i` (holding `a → b`) and `j` (holding `b → a`), and the two joined into one cycle
/// in the same orientation (starting at `b`).
fn join(pieces: &[Vec<usize>], a: usize, b: usize) -> Option<(usize, usize, Vec<usize>)> {
    let ((i, k), (j, l)) = (find_edge(pieces, a, b)?, find_edge(pieces, b, a)?);
    let (p, q) = (&pieces[i], &pieces[j]);
    let mut joined: Vec<usize> = (1..=p.len()).map(|t| p[(k + t) % p.len()]).collect();
    joined.extend((2..q.len()).map(|t| q[(l + t) % q.len()]));
    (i != j).then_some((i, j, joined))
}

/// When the piece `mid` (`… u v x …`) lies between the kept diagonals `u v` and `v x` at the
/// reflex corner `v`: the pieces with one diagonal `v w` (`w` a corner of `mid`) instead of
/// both, if one leaves both sides convex.
fn one_diagonal(f: &Flat, pieces: &[Vec<usize>], mid: &[usize], v: usize) -> Option<Cycles> {
    let (t, k) = (mid.iter().position(|&y| y == v)?, mid.len());
    let (u, x) = (mid[(t + k - 1) % k], mid[(t + 1) % k]);
    let (i, j, m) = join(pieces, u, v)?;
    let mut work = pieces.to_vec();
    (work[i], work[j]) = (m, Vec::new());
    let (i2, j2, un) = join(&work, v, x)?;
    let (k, pv) = (un.len(), un.iter().position(|&y| y == v)?);
    let mut seen = vec![false; f.p.len()];
    let at = |s: usize| un[s % k];
    // The union must be simple, and convex but at `v`.
    if un.iter().any(|&y| std::mem::replace(&mut seen[y], true))
        || (0..k).any(|s| s != pv && f.turn(at(s + k - 1), at(s), at(s + 1)) < 0)
    {
        return None;
    }
    let ok = |a: usize, b: usize, c: usize| f.turn(a, b, c) >= 0;
    let pw = (0..k).find(|&s| {
        let w = un[s];
        let at_v = ok(w, v, at(pv + 1)) && ok(at(pv + k - 1), v, w);
        let at_w = ok(at(s + k - 1), w, v) && ok(v, w, at(s + 1));
        at_v && at_w && mid.contains(&w) && ![u, v, x].contains(&w)
    })?;
    let arc = |s: usize, e: usize| (0..=(e + k - s) % k).map(|d| at(s + d)).collect();
    (work[i2], work[j], work[j2]) = (arc(pv, pw), arc(pw, pv), Vec::new());
    Some(work)
}

/// Splits one convex piece (indices in order) with more than 4 vertices into quads and at most
/// one triangle (for a quad/triangle cage), with no new vertices, choosing the diagonals so that
/// the pieces are as well shaped as possible. Pieces with 3 or 4 vertices (or fewer) are
/// returned as they are. Each output piece keeps the input orientation.
///
/// Shape: the split whose worst corner is best, a corner scoring its angle, or for a quad at
/// most `(180° − angle) / 2 + 15°`: a flat corner (collinear control points) counts as 15°, a
/// right angle as 60° like an equilateral triangle's. Exact (dynamic programming over the
/// sub-polygons cut off by diagonals, angles in the piece's Newell plane) up to 64 vertices,
/// O(m⁴); a larger piece first has runs of 64 consecutive vertices cut off.
pub fn quads_and_triangles(points: &[[f64; 3]], piece: &[usize]) -> Vec<Vec<usize>> {
    if piece.len() <= 4 {
        return vec![piece.to_vec()];
    }
    let (mut cells, mut rest) = (Vec::new(), piece.to_vec());
    while rest.len() > MAX_EXACT {
        cells.extend(split_exact(points, &rest[..MAX_EXACT]));
        rest.drain(1..MAX_EXACT - 1);
    }
    cells.extend(split_exact(points, &rest));
    cells
}

/// The best split of `piece` (≥ 3 vertices) into quads and at most one triangle.
fn split_exact(points: &[[f64; 3]], piece: &[usize]) -> Cycles {
    let m = piece.len();
    let pts: Vec<[f64; 3]> = piece.iter().map(|&i| points[i]).collect();
    let q = Flat::new(&pts).map_or(vec![[0.0; 2]; m], |f| f.p);
    let towards = |a: [f64; 2]| q.iter().map(|b| (b[1] - a[1]).atan2(b[0] - a[0])).collect();
    let dir: Vec<Vec<f64>> = q.iter().map(|&a| towards(a)).collect();
    let angle = |a: usize, b: usize, c: usize| {
        let d = (dir[b][a] - dir[b][c]).abs();
        d.min(2.0 * PI - d)
    };
    // The worst corner of a cell: its angle, for a quad at most (π − angle) / 2 + π / 12.
    let worst = |c: &[usize]| {
        let k = c.len();
        let slack = |x: f64| (PI - x) / 2.0 + PI / 12.0;
        let score = |x: f64| if k == 4 { x.min(slack(x)) } else { x };
        let corner = |t: usize| score(angle(c[(t + k - 1) % k], c[t], c[(t + 1) % k]));
        (0..k).map(corner).fold(PI, f64::min)
    };
    // best[i][j]: the score of the sub-polygon i..=j (closed by j → i, with one triangle when
    // it has an odd number of vertices, else none) and its cell on j → i: the quad (i, a, b, j),
    // or the triangle (i, a, j) when a == b.
    let mut best = vec![vec![(f64::INFINITY, 0, 0); m]; m];
    for size in 3..=m {
        for i in 0..=m - size {
            let j = i + size - 1;
            let mut cell = (f64::NEG_INFINITY, i + 1, i + 1 + usize::from(size > 3));
            for a in i + 1..j {
                if best[i][a].0 <= cell.0 {
                    continue; // no cell with this corner can do better
                }
                if (a - i) % 2 == 1 && (j - a) % 2 == 1 {
                    let s = best[i][a].0.min(best[a][j].0).min(worst(&[i, a, j]));
                    if s > cell.0 {
                        cell = (s, a, a);
                    }
                }
                for b in (a + 1..j).filter(|&b| (a - i) % 2 + (b - a) % 2 + (j - b) % 2 >= 2) {
                    let s = best[i][a].0.min(best[a][b].0).min(best[b][j].0);
                    let s = s.min(worst(&[i, a, b, j]));
                    if s > cell.0 {
                        cell = (s, a, b);
                    }
                }
            }
            best[i][j] = cell;
        }
    }
    let (mut cells, mut stack) = (Vec::new(), vec![(0, m - 1)]);
    while let Some((i, j)) = stack.pop() {
        if j - i >= 2 {
            let (_, a, b) = best[i][j];
            let mut cell = vec![piece[i], piece[a], piece[j]];
            if a != b {
                cell.insert(2, piece[b]);
            }
            cells.push(cell);
            stack.extend([(i, a), (a, b), (b, j)]);
        }
    }
    cells
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;
    use subfit_mesh::vec3::{add, norm, scale};

    /// The polygon with the flat coordinates `xy` on a tilted plane.
    fn tilt(xy: &[f64]) -> Vec<[f64; 3]> {
        let (e1, e2) = ([0.8, 0.0, 0.6], [0.36, 0.8, -0.48]);
        let at = |p: &[f64]| add([1.0, 0.0, 0.0], add(scale(e1, p[0]), scale(e2, p[1])));
        xy.chunks(2).map(at).collect()
    }

    fn regular(m: usize, r: f64) -> Vec<f64> {
        let a = |k: usize| 2.0 * PI * k as f64 / m as f64;
        let p = |k: usize| [r * a(k).cos(), r * a(k).sin()];
        (0..m).flat_map(p).collect()
    }

    fn area(points: &[[f64; 3]], cycle: &[usize]) -> [f64; 3] {
        polygon_normal(points, &cycle.iter().map(|&i| i as u32).collect::<Vec<_>>())
    }

    /// The corners of `cell` turning less than `sine` (relative) about the normal `n`.
    fn flat(points: &[[f64; 3]], cell: &[usize], n: [f64; 3], sine: f64) -> usize {
        let [x, y, z] = [0, 1, 2].map(|d| move |t: usize| points[cell[(t + d) % cell.len()]]);
        let turn = |e: [f64; 3], f: [f64; 3]| dot(cross(e, f), n) / (norm(e) * norm(f));
        let bent = |t: usize| turn(sub(y(t), x(t)), sub(z(t), y(t))) < sine;
        (0..cell.len()).filter(|&t| bent(t)).count()
    }

    /// `cells` tile the polygon `outer`: each convex with its orientation and a positive area,
    /// areas summing up, outer edges used once, diagonals once each way.
    fn check(points: &[[f64; 3]], outer: &[usize], cells: &[Vec<usize>]) {
        let total = area(points, outer);
        let n = normalize(total).unwrap();
        let (mut edges, mut sum) = (BTreeMap::new(), 0.0);
        for c in cells {
            let a = area(points, c);
            assert!(dot(a, n) > 1e-9 * norm(total), "{c:?} flipped or flat");
            assert_eq!(flat(points, c, n, -1e-9), 0, "{c:?} not convex");
            sum += norm(a);
            for t in 0..c.len() {
                *edges.entry((c[t], c[(t + 1) % c.len()])).or_insert(0) += 1;
            }
        }
        let error = (sum - norm(total)).abs();
        assert!(error <= 1e-9 * norm(total), "{sum} vs {total:?}");
        let k = outer.len();
        let boundary: Vec<_> = (0..k).map(|t| (outer[t], outer[(t + 1) % k])).collect();
        assert!(boundary.iter().all(|e| edges.contains_key(e)), "{cells:?}");
        for (&(a, b), &c) in &edges {
            assert_eq!(c, 1, "edge {a}-{b} used {c} times");
            let twin = edges.get(&(b, a)) == Some(&1);
            assert!(twin || boundary.contains(&(a, b)), "{a}-{b}");
        }
    }

    /// [`check`] for [`convex_pieces`], each piece in increasing index order; the piece count.
    fn check_pieces(points: &[[f64; 3]]) -> usize {
        let pieces = convex_pieces(points);
        check(points, &(0..points.len()).collect::<Vec<_>>(), &pieces);
        let sorted = pieces.iter().all(|p| p.windows(2).all(|w| w[0] < w[1]));
        assert!(sorted, "{pieces:?}");
        pieces.len()
    }

    const L: [f64; 12] = [0., 0., 2., 0., 2., 1., 1., 1., 1., 2., 0., 2.];

    #[test]
    fn convex_and_l_shaped_contours() {
        let hexagon = tilt(&regular(6, 1.5));
        assert_eq!(convex_pieces(&hexagon), vec![(0..6).collect::<Vec<_>>()]);
        assert_eq!(check_pieces(&tilt(&L)), 2);
        // Clockwise (and sheared) in the xy plane: pieces stay clockwise.
        let mut cw = tilt(&L);
        cw.reverse();
        cw.iter_mut().for_each(|p| p[2] = 0.0);
        assert_eq!(check_pieces(&cw), 2);
        assert!(convex_pieces(&cw).iter().all(|p| area(&cw, p)[2] < 0.0));
    }

    #[test]
    fn star_and_comb() {
        let mut star = regular(24, 1.0);
        for k in (0..48).filter(|k| k % 4 < 2) {
            star[k] *= 2.0;
        }
        let mut comb = vec![0., 0., 3., 0., 9., 0.];
        for t in (0..5).rev().map(f64::from) {
            comb.extend([2. * t + 1., 2., 2. * t + 1., 3., 2. * t, 3.]);
            if t > 0.0 {
                comb.extend([2. * t, 1., 2. * t - 0.5, 1., 2. * t - 1., 1.]);
            }
        }
        for (poly, reflex) in [(star, 12), (comb, 8)] {
            let count = check_pieces(&tilt(&poly));
            assert!(count <= (2 * reflex + 1).min(4 * (reflex + 1)), "{count}");
        }
    }

    #[test]
    fn collinear_points_stay_in_pieces() {
        let sq = tilt(&[0., 0., 1., 0., 1., 0.5, 1., 1., 0., 1.]);
        assert_eq!(convex_pieces(&sq), vec![vec![0, 1, 2, 3, 4]]);
        let l = [
            0., 0., 1., 0., 2., 0., 2., 1., 1.5, 1., 1., 1., 1., 1.5, 1., 2., 0., 2., 0., 1.,
        ];
        assert_eq!(check_pieces(&tilt(&l)), 2);
    }

    #[test]
    fn degenerate_input_does_not_panic() {
        let line = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0]];
        assert_eq!(convex_pieces(&line), vec![vec![0, 1, 2]]);
        let back = [line[0], line[1], line[2], line[1]];
        assert_eq!(convex_pieces(&back).len(), 2);
        assert_eq!(convex_pieces(&[[0.0; 3]; 5]).len(), 3);
        assert_eq!(convex_pieces(&[[f64::NAN; 3]; 4]).len(), 2);
        assert!(convex_pieces(&[]).is_empty());
        assert_eq!(convex_pieces(&line[..2]), vec![vec![0, 1]]);
        let sq = tilt(&[0., 0., 1., 0., 1., 0., 1., 1., 0., 1.]);
        assert_eq!(convex_pieces(&sq), vec![vec![0, 1, 2, 3, 4]]);
        let mut l = L.to_vec();
        l.splice(6..6, [1., 1.]); // the reflex corner twice
        let pieces = convex_pieces(&tilt(&l));
        let total: usize = pieces.iter().map(Vec::len).sum();
        assert_eq!(total, 7 + 2 * (pieces.len() - 1), "{pieces:?}");
        let tiny: Vec<f64> = L.iter().map(|x| x * 1e-150).collect();
        assert!(!convex_pieces(&tilt(&tiny)).is_empty());
        let nan = [[f64::NAN; 3]; 7];
        assert_eq!(quads_and_triangles(&nan, &[0, 1, 2, 3, 4, 5, 6]).len(), 3);
    }

    #[test]
    fn quads_and_triangles_of_convex_pieces() {
        for m in [5, 6, 8, 9, 101] {
            let (pts, piece) = (tilt(&regular(m, 1.0)), (0..m).collect::<Vec<_>>());
            let cells = quads_and_triangles(&pts, &piece);
            let count = |k: usize| cells.iter().filter(|c| c.len() == k).count();
            assert_eq!([count(3), count(4)], [m % 2, (m - 2) / 2], "{cells:?}");
            check(&pts, &piece, &cells);
        }
        // Indices into a larger array, clockwise in the xy plane.
        let (mut pts, piece) = (vec![[9.0; 3]; 12], [2, 5, 7, 9, 11, 0]);
        for (k, p) in regular(6, 2.0).chunks(2).rev().enumerate() {
            pts[piece[k]] = [p[0], p[1], 0.0];
        }
        let cells = quads_and_triangles(&pts, &piece);
        assert_eq!(cells.len(), 2);
        check(&pts, &piece, &cells);
        let quad = &piece[..4];
        assert_eq!(quads_and_triangles(&pts, quad), vec![quad.to_vec()]);
        // A rectangle with points on three sides: no flat corner (one can be avoided).
        let pts = tilt(&[0., 0., 1., 0., 2., 0., 2., 1., 2., 3., 1., 3., 0., 3.]);
        let piece: Vec<usize> = (0..7).collect();
        let cells = quads_and_triangles(&pts, &piece);
        check(&pts, &piece, &cells);
        let n = normalize(area(&pts, &piece)).unwrap();
        let sharp = cells.iter().all(|c| flat(&pts, c, n, 0.1) == 0);
        assert!(sharp, "{cells:?}");
    }
}
