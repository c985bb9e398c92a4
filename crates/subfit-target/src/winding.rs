//! Global orientation check by the generalized winding number of an oriented point set (Barill,
//! Dickson, Schmidt, Levin, Jacobson 2018, "Fast winding numbers for soups and clouds", §3.2
//! point-cloud winding number and §4 Barnes–Hut tree with a dipole far field).
//!
//! The winding number `w(q) = Σ_j a_j (p_j − q)·n_j / (4π |p_j − q|³)` of a closed, outward
//! oriented, sampled surface is ≈ 1 inside and ≈ 0 outside. With a small neighbourhood `S_i`
//! of point `i` left out, the field of the rest is smooth at `p_i` and decreases along the
//! outward normal (for a disk of radius `ρ` left out its gradient is `−n/(2ρ)`). So a normal
//! with `n_i·∇w_{P∖S_i}(p_i) > 0` points inward: it is flipped. Because the field sums over the
//! whole shape, this decides across thin parts where tree propagation relays a wrong sign
//! (the other sheet of a thin plate sits across the part, not in the neighbourhood).
//!
//! The field is approximated with a binary tree over contiguous ranges of the points (expected
//! in Morton order, so ranges are compact): a node far from `q` (distance `> r/θ`, `r` its
//! bounding radius) acts as one dipole `Σ a_j n_j` at its area-weighted centroid. Cost per
//! evaluation O(log P) for well-spread samples; building O(P log P), refreshing the dipoles after
//! flips O(P).

use rayon::prelude::*;
use subfit_mesh::{Cancel, Cancelled};

use subfit_mesh::vec3::{add, dot, scale, sub};

/// Points per leaf.
const LEAF: usize = 8;
/// Barnes–Hut opening ratio: a node of bounding radius `r` at distance `d > r / THETA` is
/// approximated by its dipole.
const THETA: f64 = 0.7;

#[derive(Clone, Copy, Debug)]
struct Node {
    /// Area-weighted centroid.
    center: [f64; 3],
    /// Dipole moment `Σ a_j n_j`.
    moment: [f64; 3],
    /// Squared opening distance `(r / θ)²`.
    open2: f64,
    /// Bounding radius `r` about the centroid.
    radius: f64,
    /// Point range `[lo, hi)`.
    lo: u32,
    hi: u32,
    /// Index of the first child (the second is `child + 1`), `u32::MAX` for a leaf.
    child: u32,
    /// Total charge `Σ c_j` (for [`DipoleTree::coulomb`]).
    charge: f64,
    /// Charge dipole `Σ c_j (p_j − center)`.
    charge_dipole: [f64; 3],
}

/// Barnes–Hut tree of dipoles `a_j n_j` at points `p_j` (indices into the arrays it was built
/// from).
pub(crate) struct DipoleTree {
    nodes: Vec<Node>,
}

impl DipoleTree {
    /// Builds the tree over `points` (`#P by 3`, ideally in Morton order) with weights `area`
    /// (`#P`, ≥ 0); moments from `normals`. O(P log P).
    pub(crate) fn new(points: &[[f64; 3]], normals: &[[f64; 3]], area: &[f64]) -> Self {
        let mut nodes = Vec::with_capacity(4 * points.len() / LEAF + 2);
        nodes.push(Node {
            center: [0.0; 3],
            moment: [0.0; 3],
            open2: 0.0,
            radius: 0.0,
            lo: 0,
            hi: 0,
            child: u32::MAX,
            charge: 0.0,
            charge_dipole: [0.0; 3],
        });
        build(points, area, 0, 0, points.len(), &mut nodes);
        let mut tree = Self { nodes };
        tree.refresh(normals, area);
        tree
    }

    /// Recomputes the dipole moments from `normals` (after flips). O(P).
    pub(crate) fn refresh(&mut self, normals: &[[f64; 3]], area: &[f64]) {
        // Children always follow their parent: a reverse sweep sees children first.
        for k in (0..self.nodes.len()).rev() {
            let nd = self.nodes[k];
            let m = if nd.child == u32::MAX {
                (nd.lo as usize..nd.hi as usize)
                    .fold([0.0; 3], |m, j| add(m, scale(normals[j], area[j])))
            } else {
                let c = nd.child as usize;
                add(self.nodes[c].moment, self.nodes[c + 1].moment)
            };
            self.nodes[k].moment = m;
        }
    }

    /// `4π ∇w(q)` of the dipoles farther than `exclude` from `q` (`exclude ≥ 0`; the points
    /// closer are left out exactly, nodes reaching into that ball are opened). `points`,
    /// `normals`, `area` as given to [`Self::new`] (normals as of the last [`Self::refresh`]).
    pub(crate) fn gradient(
        &self,
        points: &[[f64; 3]],
        normals: &[[f64; 3]],
        area: &[f64],
        q: [f64; 3],
        exclude: f64,
    ) -> [f64; 3] {
        let ex2 = exclude * exclude;
        let mut g = [0.0; 3];
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let nd = &self.nodes[stack[top] as usize];
            let d = sub(nd.center, q);
            let d2 = dot(d, d);
            // Far (opening criterion) and clear of the excluded ball: (r + exclude)² < d².
            let reach = nd.radius + exclude;
            if d2 > nd.open2 && d2 > reach * reach {
                g = add(g, dipole_gradient(d, nd.moment));
            } else if nd.child == u32::MAX || top + 2 > stack.len() {
                for j in nd.lo as usize..nd.hi as usize {
                    let r = sub(points[j], q);
                    if dot(r, r) > ex2 {
                        g = add(g, dipole_gradient(r, scale(normals[j], area[j])));
                    }
                }
            } else {
                stack[top] = nd.child;
                stack[top + 1] = nd.child + 1;
                top += 2;
            }
        }
        g
    }

    /// Recomputes the charges `c` (`#P`, any sign) of [`Self::coulomb`]. O(P).
    pub(crate) fn refresh_charges(&mut self, points: &[[f64; 3]], charges: &[f64]) {
        for k in (0..self.nodes.len()).rev() {
            let nd = self.nodes[k];
            let (q, d) = if nd.child == u32::MAX {
                (nd.lo as usize..nd.hi as usize).fold((0.0, [0.0; 3]), |(q, d), j| {
                    (
                        q + charges[j],
                        add(d, scale(sub(points[j], nd.center), charges[j])),
                    )
                })
            } else {
                // Shift the children's dipoles to this node's centre.
                let mut q = 0.0;
                let mut d = [0.0; 3];
                for c in [nd.child as usize, nd.child as usize + 1] {
                    let ch = &self.nodes[c];
                    q += ch.charge;
                    d = add(
                        d,
                        add(
                            ch.charge_dipole,
                            scale(sub(ch.center, nd.center), ch.charge),
                        ),
                    );
                }
                (q, d)
            };
            self.nodes[k].charge = q;
            self.nodes[k].charge_dipole = d;
        }
    }

    /// `4π w(q)` and `4π ∇w(q)` of all the dipoles, with the kernel regularized near the
    /// samples: a point `j` closer than the opening distance contributes with `|p_j − q|²`
    /// replaced by `|p_j − q|² + (σ_q² + σ_j²)/2` (`sigma`: `#P`, ≥ 0; `sigma_q` that of the
    /// evaluation point). Far nodes act as plain dipoles. Point `skip` (an index, or
    /// `usize::MAX`) is left out. O(log P) per call for well-spread samples.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn field(
        &self,
        points: &[[f64; 3]],
        normals: &[[f64; 3]],
        area: &[f64],
        sigma: &[f64],
        q: [f64; 3],
        sigma_q: f64,
        skip: usize,
    ) -> (f64, [f64; 3]) {
        let (mut w, mut g) = (0.0, [0.0; 3]);
        let s2q = 0.5 * sigma_q * sigma_q;
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let nd = &self.nodes[stack[top] as usize];
            let d = sub(nd.center, q);
            let d2 = dot(d, d);
            if d2 > nd.open2 && d2 > nd.radius * nd.radius {
                let inv = 1.0 / d2.sqrt();
                w += dot(d, nd.moment) * inv * inv * inv;
                g = add(g, dipole_gradient(d, nd.moment));
            } else if nd.child == u32::MAX || top + 2 > stack.len() {
                for j in nd.lo as usize..nd.hi as usize {
                    if j == skip {
                        continue;
                    }
                    let r = sub(points[j], q);
                    let m = scale(normals[j], area[j]);
                    let e2 = dot(r, r) + s2q + 0.5 * sigma[j] * sigma[j];
                    if !(e2 > 0.0) {
                        continue;
                    }
                    let inv = 1.0 / e2.sqrt();
                    let inv3 = inv * inv * inv;
                    let rm = dot(r, m);
                    w += rm * inv3;
                    g = add(
                        g,
                        add(scale(m, -inv3), scale(r, 3.0 * rm * inv3 * inv * inv)),
                    );
                }
            } else {
                stack[top] = nd.child;
                stack[top + 1] = nd.child + 1;
                top += 2;
            }
        }
        (w, g)
    }

    /// `4π E(q)`, the field `Σ_j c_j (q − p_j)/|q − p_j|³` of the charges of the last
    /// [`Self::refresh_charges`], regularized near the samples as in [`Self::field`]; far nodes
    /// act as a charge plus a dipole at their centre. O(log P) per call.
    pub(crate) fn coulomb(
        &self,
        points: &[[f64; 3]],
        charges: &[f64],
        sigma: &[f64],
        q: [f64; 3],
        sigma_q: f64,
    ) -> [f64; 3] {
        let mut e = [0.0; 3];
        let s2q = 0.5 * sigma_q * sigma_q;
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let nd = &self.nodes[stack[top] as usize];
            let d = sub(nd.center, q);
            let d2 = dot(d, d);
            if d2 > nd.open2 && d2 > nd.radius * nd.radius {
                let inv = 1.0 / d2.sqrt();
                // Charge at the centre, field (q − c) Q/|q − c|³; the dipole D gives
                // ∇ of −D·(c − q)/|c − q|³ negated, i.e. `dipole_gradient(c − q, D)`.
                e = add(e, scale(d, -nd.charge * inv * inv * inv));
                e = add(e, dipole_gradient(d, nd.charge_dipole));
            } else if nd.child == u32::MAX || top + 2 > stack.len() {
                for j in nd.lo as usize..nd.hi as usize {
                    let c = charges[j];
                    if c == 0.0 {
                        continue;
                    }
                    let r = sub(q, points[j]);
                    let e2 = dot(r, r) + s2q + 0.5 * sigma[j] * sigma[j];
                    if !(e2 > 0.0) {
                        continue;
                    }
                    let inv = 1.0 / e2.sqrt();
                    e = add(e, scale(r, c * inv * inv * inv));
                }
            } else {
                stack[top] = nd.child;
                stack[top + 1] = nd.child + 1;
                top += 2;
            }
        }
        e
    }
}

/// `4π ∇_q` of the dipole field `(p − q)·m / |p − q|³`, with `r = p − q`; 0 at `r = 0`.
pub(crate) fn dipole_gradient(r: [f64; 3], m: [f64; 3]) -> [f64; 3] {
    let d2 = dot(r, r);
    if !(d2 > 0.0) {
        return [0.0; 3];
    }
    let inv = 1.0 / d2.sqrt();
    let inv3 = inv * inv * inv;
    add(
        scale(m, -inv3),
        scale(r, 3.0 * dot(r, m) * inv3 * inv * inv),
    )
}

/// Fills node `k` with the range `[lo, hi)`; splits it into two adjacent child slots.
fn build(points: &[[f64; 3]], area: &[f64], k: usize, lo: usize, hi: usize, nodes: &mut Vec<Node>) {
    let (mut c, mut w) = ([0.0; 3], 0.0);
    for j in lo..hi {
        c = add(c, scale(points[j], area[j]));
        w += area[j];
    }
    let center = if w > 0.0 {
        scale(c, 1.0 / w)
    } else {
        let s = (lo..hi).fold([0.0; 3], |s, j| add(s, points[j]));
        scale(s, 1.0 / (hi - lo).max(1) as f64)
    };
    let r2 = (lo..hi)
        .map(|j| {
            let d = sub(points[j], center);
            dot(d, d)
        })
        .fold(0.0, f64::max);
    nodes[k] = Node {
        center,
        moment: [0.0; 3],
        open2: r2 / (THETA * THETA),
        radius: r2.sqrt(),
        lo: lo as u32,
        hi: hi as u32,
        child: u32::MAX,
        charge: 0.0,
        charge_dipole: [0.0; 3],
    };
    if hi - lo > LEAF {
        let mid = lo + (hi - lo) / 2;
        let first = nodes.len();
        nodes.push(nodes[k]);
        nodes.push(nodes[k]);
        nodes[k].child = first as u32;
        build(points, area, first, lo, mid, nodes);
        build(points, area, first + 1, mid, hi, nodes);
    }
}

/// Inputs of [`refine`], all in the same (Morton) order, `#P` rows.
pub(crate) struct WindingInput<'a> {
    /// Points.
    pub points: &'a [[f64; 3]],
    /// Area weights (≥ 0).
    pub area: &'a [f64],
    /// Per point: the radius of the ball left out of its field (its own neighbourhood, the point
    /// itself included), > 0.
    pub exclude: &'a [f64],
    /// The k-nearest-neighbour rows (stride `k`, padding `u32::MAX`), to grow the later passes.
    pub targets: &'a [u32],
    /// Entries per row.
    pub stride: usize,
    /// Whether a point's normal may be flipped (free, in a closed-looking component).
    pub eligible: &'a [bool],
}

/// Maximum number of flip passes.
const PASSES: usize = 8;
/// Points evaluated in the first pass (at most; an even subsample of larger sets).
const FIRST_PASS_POINTS: usize = 32_768;

/// Flips normals that point into the winding-number field of the rest of the shape (see the
/// module doc), in Jacobi passes: the first over all eligible points, later ones over the
/// points flipped in the previous pass and their neighbours. `tree` is built over `inp.points`
/// and `inp.area` with moments from `normals`, and is left refreshed with the result. Returns
/// the number of flips (a point flipped twice counts twice), or [`Cancelled`] once `cancel` is
/// (polled per point evaluated).
pub(crate) fn refine(
    normals: &mut [[f64; 3]],
    inp: &WindingInput<'_>,
    tree: &mut DipoleTree,
    cancel: &Cancel,
) -> Result<usize, Cancelled> {
    let n = inp.points.len();
    let k = inp.stride;
    // First pass on a subsample (every `step`-th point in Morton order: spread over the shape),
    // later passes around the flips.
    let step = n.div_ceil(FIRST_PASS_POINTS).max(1);
    let mut active: Vec<u32> = (0..n as u32)
        .step_by(step)
        .filter(|&i| inp.eligible[i as usize])
        .collect();
    if active.is_empty() {
        return Ok(0);
    }
    let mut total = 0;
    let mut mark = vec![false; n];
    for _ in 0..PASSES {
        let flips: Vec<u32> = {
            let normals = &*normals;
            let tree = &*tree;
            active
                .par_iter()
                .copied()
                .filter(|&i| {
                    if cancel.is_cancelled() {
                        return false;
                    }
                    let i = i as usize;
                    let p = inp.points[i];
                    let g = tree.gradient(inp.points, normals, inp.area, p, inp.exclude[i]);
                    dot(normals[i], g) > 0.0
                })
                .collect()
        };
        cancel.check()?;
        if flips.is_empty() {
            break;
        }
        total += flips.len();
        for &i in &flips {
            normals[i as usize] = scale(normals[i as usize], -1.0);
        }
        tree.refresh(normals, inp.area);
        // Next pass: the flipped points and their neighbours.
        active.clear();
        for &i in &flips {
            let i = i as usize;
            let row = &inp.targets[i * k..(i + 1) * k];
            for j in std::iter::once(i).chain(row.iter().map(|&j| j as usize)) {
                if j < n && inp.eligible[j] && !mark[j] {
                    mark[j] = true;
                    active.push(j as u32);
                }
            }
        }
        for &i in &active {
            mark[i as usize] = false;
        }
        active.sort_unstable();
    }
    Ok(total)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::neighbors::{morton_order, PointIndex};
    use subfit_mesh::vec3::norm;

    /// Fibonacci sphere of radius 0.4 about (0.5, 0.5, 0.5), Morton-ordered, outward normals.
    fn sphere(n: usize) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        let nrm: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let t = golden * i as f64;
                [r * t.cos(), r * t.sin(), z]
            })
            .collect();
        let pts: Vec<[f64; 3]> = nrm.iter().map(|&u| add([0.5; 3], scale(u, 0.4))).collect();
        let order = morton_order(&pts);
        (
            order.iter().map(|&i| pts[i as usize]).collect(),
            order.iter().map(|&i| nrm[i as usize]).collect(),
        )
    }

    fn winding(points: &[[f64; 3]], normals: &[[f64; 3]], area: &[f64], q: [f64; 3]) -> f64 {
        let mut w = 0.0;
        for ((p, n), a) in points.iter().zip(normals).zip(area) {
            let r = sub(*p, q);
            let d = dot(r, r).sqrt();
            w += a * dot(r, *n) / (d * d * d);
        }
        w / (4.0 * std::f64::consts::PI)
    }

    #[test]
    fn winding_number_and_gradient_match_direct_sums() {
        let n = 1500;
        let (pts, nrm) = sphere(n);
        let area = vec![4.0 * std::f64::consts::PI * 0.16 / n as f64; n];
        // Inside, w ≈ 1; outside ≈ 0.
        assert!((winding(&pts, &nrm, &area, [0.5; 3]) - 1.0).abs() < 0.01);
        assert!(winding(&pts, &nrm, &area, [1.5, 0.5, 0.5]).abs() < 0.01);
        // The direct gradient matches finite differences of w off the surface.
        let q = [0.55, 0.6, 0.98];
        let g = scale(
            direct_gradient(&pts, &nrm, &area, q, 0.0),
            0.25 / std::f64::consts::PI,
        );
        for (c, gc) in g.iter().enumerate() {
            let (mut a, mut b) = (q, q);
            a[c] += 1e-6;
            b[c] -= 1e-6;
            let fd = (winding(&pts, &nrm, &area, a) - winding(&pts, &nrm, &area, b)) / 2e-6;
            assert!(
                (gc - fd).abs() < 1e-5 * (1.0 + fd.abs()),
                "{c}: {gc} vs {fd}"
            );
        }
        // At the samples, with a neighbourhood left out: the tree is close to the direct sum and
        // the gradient points inward.
        let tree = DipoleTree::new(&pts, &nrm, &area);
        let ex = 0.08;
        for (i, (&p, &u)) in pts.iter().zip(&nrm).enumerate().step_by(7) {
            let t = tree.gradient(&pts, &nrm, &area, p, ex);
            let d = direct_gradient(&pts, &nrm, &area, p, ex);
            let e = norm(sub(t, d));
            assert!(e < 0.2 * norm(d), "{i}: tree {t:?} direct {d:?}");
            assert!(dot(t, u) < 0.0 && dot(d, u) < 0.0, "{i}: {t:?} {d:?}");
        }
    }

    fn direct_gradient(
        points: &[[f64; 3]],
        normals: &[[f64; 3]],
        area: &[f64],
        q: [f64; 3],
        ex: f64,
    ) -> [f64; 3] {
        let mut g = [0.0; 3];
        for ((p, n), a) in points.iter().zip(normals).zip(area) {
            let r = sub(*p, q);
            if norm(r) > ex {
                g = add(g, dipole_gradient(r, scale(*n, *a)));
            }
        }
        g
    }

    #[test]
    fn refine_restores_a_flipped_cap_and_keeps_a_correct_sphere() {
        let n = 3000;
        let (pts, truth) = sphere(n);
        let index = PointIndex::new(&pts).unwrap();
        let k = 10;
        let mut targets = vec![u32::MAX; n * k];
        let mut exclude = vec![0.0; n];
        for i in 0..n {
            let nb = index.k_nearest(&pts[i], k + 1);
            for (t, b) in targets[i * k..]
                .iter_mut()
                .zip(nb.iter().filter(|b| b.index as usize != i))
            {
                *t = b.index;
            }
            exclude[i] = nb.last().map_or(0.0, |b| b.distance) * 1.000_001;
        }
        let area = vec![4.0 * std::f64::consts::PI * 0.16 / n as f64; n];
        let eligible = vec![true; n];
        let inp = WindingInput {
            points: &pts,
            area: &area,
            exclude: &exclude,
            targets: &targets,
            stride: k,
            eligible: &eligible,
        };
        let mut normals = truth.clone();
        let mut tree = DipoleTree::new(&pts, &normals, &area);
        assert_eq!(
            refine(&mut normals, &inp, &mut tree, &Cancel::default()),
            Ok(0)
        );
        assert_eq!(normals, truth);
        // Flip a cap (about 10 % of the points): all of it comes back.
        let cap = |p: &[f64; 3]| p[2] > 0.5 + 0.4 * 0.8;
        for (nrm, p) in normals.iter_mut().zip(&pts) {
            if cap(p) {
                *nrm = scale(*nrm, -1.0);
            }
        }
        let flipped = pts.iter().filter(|p| cap(p)).count();
        assert!(flipped > n / 20);
        tree.refresh(&normals, &area);
        let (messy, cancel) = (normals.clone(), Cancel::new());
        cancel.cancel();
        assert_eq!(
            refine(&mut normals, &inp, &mut tree, &cancel),
            Err(Cancelled)
        );
        assert_eq!(normals, messy);
        assert!(refine(&mut normals, &inp, &mut tree, &Cancel::default()).unwrap() >= flipped);
        assert_eq!(normals, truth);
    }
}
