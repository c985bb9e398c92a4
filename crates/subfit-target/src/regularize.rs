//! Normal refinement by the winding-number field of the oriented points, where the local
//! estimate and the propagated signs cannot be trusted (sparse samplings of thin parts). Two
//! properties of a consistently oriented closed surface, in terms of the point-cloud winding
//! number `w` (Barill et al. 2018, §3.2):
//!
//! 1. **Winding number normal consistency** (Lin, Shi, Liu 2024, "Fast and globally consistent
//!    normal orientation based on the winding number normal consistency", the WNNC update): the
//!    normals sampled from the field, `−∇w(p_i)`, are codirectional with the normals `n_i` the
//!    field is computed from.
//! 2. **On-surface value ½** (Lin, Xiao, Shi, Wang 2022, "Surface reconstruction from point
//!    clouds without normals by parametrizing the Gauss formula", PGR): `w(p_i) = ½` at the
//!    samples. A thin part whose two sheets were flipped together keeps property 1 but has
//!    `w ≈ −½` on it; property 2 sees it.
//!
//! Both are stationarity conditions of
//! `F(n) = ½ Σ_i a_i n_i·(−∇w(p_i)) − (β/2) Σ_i (a_i/h_i) (w(p_i) − ½)²` over unit normals
//! (`a_i` area; `h_i` the larger of the sample spacing and the estimation radius; `w` is linear
//! in the dipoles `a_j n_j`, with the kernel regularized as `|p_i − p_j|² + (σ_i² + σ_j²)/2`,
//! `σ_i = SIGMA · h_i`, so that it is symmetric and `F` smooth). The gradient of `F` in `n_j` is
//! `a_j (−∇w(p_j) − β E(p_j))`, `E` the Coulomb field of the charges `a_i (w(p_i) − ½)/h_i`.
//! Each iteration moves every active normal towards its normalized gradient (a projected power
//! step: the WNNC update and the PGR gradient step in one), with the step length halved until
//! `F` does not decrease; without that control the iteration oscillates once `β` is a little
//! larger than needed. Measured on `lucy.ply` while choosing the constants: `β` from 3 to 5 and
//! `SIGMA` from 0.12 to 0.25 all give 99.55–99.65 % sign agreement; `β = 7` 99.47 %, 10 99.13 %.
//!
//! **Where.** A cheap check evaluates `w` and `∇w` of the others (the point itself left out) at
//! an even subsample of the eligible points and at every point with a graph neighbour more than
//! 60° away: a point is *suspicious* when `w` leaves `[0, 1]` (impossible at a sample of a
//! consistently oriented closed surface, up to sampling error) or its normal is more than 60°
//! from `−∇w`. With no suspicious point the step stops there (on the dense scans here). Otherwise
//! the iteration updates the suspicious points and [`RINGS`] rings of their graph neighbours,
//! adding the neighbours of points that turn by more than 30° in a step; the other normals are
//! held fixed but keep contributing to the field. A final normal keeps the local estimate's
//! direction (with the field's sign) where the two agree within 30°, else takes the field's.
//!
//! Cost: the check O(C log P) for `C` checked points (the dipole tree of [`crate::winding`]),
//! then per iteration O(A log P) for `A` active points plus O(P) to refresh the tree; at most
//! [`MAX_ITERATIONS`] iterations and `BUDGET_BASE + BUDGET_PER_POINT · P` point evaluations.

use rayon::prelude::*;
use subfit_mesh::{Cancel, Cancelled};

use crate::winding::DipoleTree;
use subfit_mesh::vec3::{add, dot, norm, normalize, scale, sub};

/// Kernel regularization `σ_i = SIGMA · h_i`.
const SIGMA: f64 = 0.2;
/// Weight `β` of the on-surface term (dimensionless: both terms of `F` scale like a length).
const BETA: f64 = 4.0;
/// Suspicious: `n·(−∇w)/|∇w|` below this (60°); also the neighbour angle that gets a point
/// checked.
const SUSPICIOUS_COS: f64 = 0.5;
/// Subsample of the check: every `⌈P / CHECK_POINTS⌉`-th point in Morton order.
const CHECK_POINTS: usize = 32_768;
/// Graph rings around the suspicious points updated from the start.
const RINGS: usize = 2;
/// A normal turning by more than this (cos 30°) in one step activates its neighbours; a final
/// normal keeps the estimate's direction when within this of the field's.
const TURN_COS: f64 = 0.866;
/// Iterations at most.
const MAX_ITERATIONS: usize = 200;
/// Converged when no active normal turns by more than this (cos ≈ 0.5°) in a step.
const CONVERGED_COS: f64 = 0.999_96;
/// Budget of the iteration: it stops once it has evaluated the field at
/// [`BUDGET_BASE`] + this many × `#P` points, whatever the iteration count, so that a scan where
/// most points look suspicious (heavy noise with small neighbourhoods) costs a bounded number of
/// passes over the cloud (measured: about 3 µs per evaluation on this machine's cores).
const BUDGET_PER_POINT: usize = 8;
/// Evaluations always allowed: enough for the slowest clean case of the tests (a flipped
/// hemisphere of 3000 points, 125 iterations, about 0.8 M evaluations) several times over.
const BUDGET_BASE: usize = 3_000_000;
/// Shortest step tried before the iteration stops.
const MIN_STEP: f64 = 1.0 / 64.0;

/// Inputs of [`refine`], all in the same (Morton) order, `#P` rows.
pub(crate) struct FieldInput<'a> {
    /// Points.
    pub points: &'a [[f64; 3]],
    /// Area weights `a_i` (≥ 0).
    pub area: &'a [f64],
    /// Sample spacing `h_i` (≥ 0), e.g. the distance to the farthest graph neighbour.
    pub spacing: &'a [f64],
    /// Length scale `r_i` (≥ 0): the radius of the neighbourhood the normal was estimated from.
    /// The kernel regularization is `σ_i = SIGMA · max(h_i, r_i)` and `max(h_i, r_i)` is the
    /// `h_i` of `F` (the field should not resolve finer detail than the estimate did).
    pub scale: &'a [f64],
    /// The k-nearest-neighbour rows (stride `k`, padding `u32::MAX`).
    pub targets: &'a [u32],
    /// Entries per row.
    pub stride: usize,
    /// Whether a point's normal may change (free, in a closed-looking component).
    pub eligible: &'a [bool],
}

/// What [`refine`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct FieldOutcome {
    /// Points evaluated by the check.
    pub checked: usize,
    /// Points failing the check (0: nothing else was done).
    pub suspicious: usize,
    /// Points updated by the iteration (at the end).
    pub active: usize,
    /// Iterations run.
    pub iterations: usize,
    /// Normals whose sign changed.
    pub flips: usize,
    /// Normals whose direction was replaced by the field's (more than 30° from the estimate).
    pub redirected: usize,
}

/// Shared per-call data.
struct Ctx<'a> {
    inp: &'a FieldInput<'a>,
    sigma: Vec<f64>,
    /// Polled per point evaluated; the loops return [`Cancelled`] after their parallel part.
    cancel: &'a Cancel,
}

/// The field at the points of an evaluation set.
struct Eval {
    /// `4π w`.
    w: Vec<f64>,
    /// `4π ∇w` (the point's own dipole included).
    g: Vec<[f64; 3]>,
}

const FOUR_PI: f64 = 4.0 * std::f64::consts::PI;

/// Refines `normals` (unit, Morton order) in place, see the module doc. `tree` is built over
/// `inp.points` and `inp.area` with moments from `normals`; it is left refreshed with the result.
/// Returns what was done and, per point, whether its direction was replaced (`#P`), or
/// [`Cancelled`] once `cancel` is (polled per point evaluated; `normals` are then partly
/// refined).
pub(crate) fn refine(
    normals: &mut [[f64; 3]],
    inp: &FieldInput<'_>,
    tree: &mut DipoleTree,
    cancel: &Cancel,
) -> Result<(FieldOutcome, Vec<bool>), Cancelled> {
    let n = inp.points.len();
    let mut out = FieldOutcome::default();
    let mut redirected = vec![false; n];
    let ctx = Ctx {
        inp,
        sigma: inp
            .spacing
            .par_iter()
            .zip(inp.scale)
            .map(|(&h, &r)| SIGMA * h.max(r))
            .collect(),
        cancel,
    };
    let checked = check_set(normals, inp);
    out.checked = checked.len();
    let mut active = vec![false; n];
    for i in suspicious(&ctx, tree, normals, &checked)? {
        active[i as usize] = true;
        out.suspicious += 1;
    }
    if out.suspicious == 0 {
        return Ok((out, redirected));
    }
    for _ in 0..RINGS {
        let marked = members(&active);
        add_neighbours(&mut active, &marked, inp);
    }
    let original = normals.to_vec();
    let act = iterate(&ctx, tree, normals, &mut active, &mut out)?;
    out.active = act.len();
    // Final normals: the estimate's direction with the field's sign where they agree within
    // 30°, else the field's.
    for &i in &act {
        let i = i as usize;
        let (o, f) = (original[i], normals[i]);
        let c = dot(o, f);
        if c.abs() >= TURN_COS {
            normals[i] = if c < 0.0 { scale(o, -1.0) } else { o };
        } else {
            redirected[i] = true;
            out.redirected += 1;
        }
        if dot(normals[i], o) < 0.0 {
            out.flips += 1;
        }
    }
    tree.refresh(normals, inp.area);
    Ok((out, redirected))
}

/// The points the check evaluates: an even subsample of the eligible points (every
/// `⌈P / CHECK_POINTS⌉`-th in Morton order, spread over the shape) and every eligible point with
/// a graph neighbour more than 60° away (sign or direction). Sorted.
fn check_set(normals: &[[f64; 3]], inp: &FieldInput<'_>) -> Vec<u32> {
    let n = inp.points.len();
    let k = inp.stride;
    let step = n.div_ceil(CHECK_POINTS).max(1);
    (0..n as u32)
        .into_par_iter()
        .filter(|&i| {
            let i = i as usize;
            inp.eligible[i]
                && (i % step == 0
                    || inp.targets[i * k..(i + 1) * k].iter().any(|&j| {
                        (j as usize) < n && dot(normals[i], normals[j as usize]) < SUSPICIOUS_COS
                    }))
        })
        .collect()
}

/// The points of `set` failing the check (see the module doc).
fn suspicious(
    ctx: &Ctx<'_>,
    tree: &DipoleTree,
    normals: &[[f64; 3]],
    set: &[u32],
) -> Result<Vec<u32>, Cancelled> {
    let inp = ctx.inp;
    let out = set
        .par_iter()
        .copied()
        .filter(|&i| {
            if ctx.cancel.is_cancelled() {
                return false;
            }
            let i = i as usize;
            let (w4, g4) = tree.field(
                inp.points,
                normals,
                inp.area,
                &ctx.sigma,
                inp.points[i],
                ctx.sigma[i],
                i,
            );
            let w = w4 / FOUR_PI;
            let c = -dot(normals[i], g4) / norm(g4).max(f64::MIN_POSITIVE);
            !(0.0..=1.0).contains(&w) || c < SUSPICIOUS_COS
        })
        .collect();
    ctx.cancel.check()?;
    Ok(out)
}

/// The monotone iteration on the `active` points (grown as normals turn). Updates `normals` to
/// the field's normals at the active points; returns them (sorted). Polls `ctx.cancel` per
/// point evaluated, and returns [`Cancelled`] after the parallel loop that saw it.
fn iterate(
    ctx: &Ctx<'_>,
    tree: &mut DipoleTree,
    normals: &mut [[f64; 3]],
    active: &mut [bool],
    out: &mut FieldOutcome,
) -> Result<Vec<u32>, Cancelled> {
    let inp = ctx.inp;
    let n = inp.points.len();
    let mut act = members(active);
    // The evaluation set (active points and their neighbours: their `w` and `∇w` change most;
    // `F` and the charges are restricted to it) and each point's position in it.
    let mut set = with_neighbours(active, inp);
    let mut pos = positions(&set, n);
    let mut ev = evaluate(ctx, tree, normals, &set)?;
    let mut f = objective(ctx, normals, &ev, &set);
    let mut charges = vec![0.0; n];
    let mut backup: Vec<[f64; 3]> = Vec::with_capacity(act.len());
    let mut step = 1.0;
    let budget = BUDGET_PER_POINT * n + BUDGET_BASE;
    let mut spent = set.len();
    while out.iterations < MAX_ITERATIONS && spent < budget {
        ctx.cancel.check()?;
        out.iterations += 1;
        for (e, &i) in set.iter().enumerate() {
            let i = i as usize;
            charges[i] = area_per_spacing(inp, i) * (ev.w[e] / FOUR_PI - 0.5);
        }
        tree.refresh_charges(inp.points, &charges);
        let dirs: Vec<[f64; 3]> = {
            let (tree, normals, charges, ev, pos) = (&*tree, &*normals, &charges, &ev, &pos);
            act.par_iter()
                .map(|&i| {
                    let i = i as usize;
                    if ctx.cancel.is_cancelled() {
                        return normals[i];
                    }
                    let e =
                        tree.coulomb(inp.points, charges, &ctx.sigma, inp.points[i], ctx.sigma[i]);
                    let g = ev.g[pos[i] as usize];
                    normalize(sub(scale(g, -1.0), scale(e, BETA))).unwrap_or(normals[i])
                })
                .collect()
        };
        ctx.cancel.check()?;
        for &i in &set {
            charges[i as usize] = 0.0;
        }
        backup.clear();
        backup.extend(act.iter().map(|&i| normals[i as usize]));
        // Step control: the longest step (1, ½, ¼, …) that does not decrease F.
        let accepted = loop {
            for ((&i, d), &old) in act.iter().zip(&dirs).zip(&backup) {
                normals[i as usize] = normalize(add(old, scale(sub(*d, old), step))).unwrap_or(old);
            }
            tree.refresh(normals, inp.area);
            spent += set.len() + act.len();
            let ev2 = evaluate(ctx, tree, normals, &set)?;
            let f2 = objective(ctx, normals, &ev2, &set);
            if f2 >= f {
                break Some((ev2, f2));
            }
            if step <= MIN_STEP {
                break None;
            }
            step *= 0.5;
        };
        let Some((ev2, f2)) = accepted else {
            for (&i, &old) in act.iter().zip(&backup) {
                normals[i as usize] = old;
            }
            tree.refresh(normals, inp.area);
            break;
        };
        (ev, f) = (ev2, f2);
        step = (2.0 * step).min(1.0);
        let mut settled = true;
        let mut turned: Vec<u32> = Vec::new();
        for (&i, &old) in act.iter().zip(&backup) {
            let c = dot(normals[i as usize], old);
            settled &= c >= CONVERGED_COS;
            if c < TURN_COS {
                turned.push(i);
            }
        }
        let before = act.len();
        add_neighbours(active, &turned, inp);
        act = members(active);
        if act.len() != before {
            set = with_neighbours(active, inp);
            pos = positions(&set, n);
            spent += set.len();
            ev = evaluate(ctx, tree, normals, &set)?;
            f = objective(ctx, normals, &ev, &set);
        } else if settled {
            break;
        }
    }
    Ok(act)
}

/// Marks the eligible graph neighbours of the points `of`.
fn add_neighbours(mark: &mut [bool], of: &[u32], inp: &FieldInput<'_>) {
    let n = mark.len();
    let k = inp.stride;
    for &i in of {
        let i = i as usize;
        for &j in &inp.targets[i * k..(i + 1) * k] {
            let j = j as usize;
            if j < n && inp.eligible[j] {
                mark[j] = true;
            }
        }
    }
}

/// Indices of the marked points, sorted.
fn members(mark: &[bool]) -> Vec<u32> {
    (0..mark.len() as u32)
        .filter(|&i| mark[i as usize])
        .collect()
}

/// The marked points and all their graph neighbours, sorted.
fn with_neighbours(mark: &[bool], inp: &FieldInput<'_>) -> Vec<u32> {
    let n = mark.len();
    let k = inp.stride;
    let mut r = mark.to_vec();
    for i in (0..n).filter(|&i| mark[i]) {
        for &j in &inp.targets[i * k..(i + 1) * k] {
            if (j as usize) < n {
                r[j as usize] = true;
            }
        }
    }
    members(&r)
}

/// Position of each point in `set` (`u32::MAX` if absent), `#P`.
fn positions(set: &[u32], n: usize) -> Vec<u32> {
    let mut pos = vec![u32::MAX; n];
    for (e, &i) in set.iter().enumerate() {
        pos[i as usize] = e as u32;
    }
    pos
}

/// `4π w` and `4π ∇w` (own dipole included) at the points of `set`; `tree` refreshed from
/// `normals`. [`Cancelled`] once `ctx.cancel` is (polled per point).
fn evaluate(
    ctx: &Ctx<'_>,
    tree: &DipoleTree,
    normals: &[[f64; 3]],
    set: &[u32],
) -> Result<Eval, Cancelled> {
    let inp = ctx.inp;
    let (w, g) = set
        .par_iter()
        .map(|&i| {
            if ctx.cancel.is_cancelled() {
                return (0.0, [0.0; 3]);
            }
            let i = i as usize;
            let p = inp.points[i];
            tree.field(
                inp.points,
                normals,
                inp.area,
                &ctx.sigma,
                p,
                ctx.sigma[i],
                usize::MAX,
            )
        })
        .unzip();
    ctx.cancel.check()?;
    Ok(Eval { w, g })
}

/// `4π F` restricted to the points of `set` (see the module doc).
fn objective(ctx: &Ctx<'_>, normals: &[[f64; 3]], ev: &Eval, set: &[u32]) -> f64 {
    let inp = ctx.inp;
    set.iter()
        .zip(ev.w.iter().zip(&ev.g))
        .map(|(&i, (&w, &g))| {
            let i = i as usize;
            let r = w / FOUR_PI - 0.5;
            -0.5 * inp.area[i] * dot(normals[i], g)
                - 0.5 * BETA * FOUR_PI * area_per_spacing(inp, i) * r * r
        })
        .sum()
}

/// `a_i / max(h_i, r_i)`, 0 for a point without neighbours.
fn area_per_spacing(inp: &FieldInput<'_>, i: usize) -> f64 {
    let h = inp.spacing[i].max(inp.scale[i]);
    if h > 0.0 {
        inp.area[i] / h
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::neighbors::{morton_order, PointIndex};

    const K: usize = 10;

    /// Refines `normals` (`truth` with some flipped) over `points` with the orientation's inputs
    /// (k = 10 graph, area π d_k²/k, spacing d_k); returns the outcome and the fraction agreeing
    /// in sign with `truth`.
    fn run(
        points: &[[f64; 3]],
        truth: &[[f64; 3]],
        normals: &mut [[f64; 3]],
    ) -> (FieldOutcome, f64) {
        run_with(points, truth, normals, &Cancel::default()).unwrap()
    }

    /// [`run`] with a cancellation token.
    fn run_with(
        points: &[[f64; 3]],
        truth: &[[f64; 3]],
        normals: &mut [[f64; 3]],
        cancel: &Cancel,
    ) -> Result<(FieldOutcome, f64), Cancelled> {
        let order = morton_order(points);
        let pts: Vec<[f64; 3]> = order.iter().map(|&i| points[i as usize]).collect();
        let mut nrm: Vec<[f64; 3]> = order.iter().map(|&i| normals[i as usize]).collect();
        let n = pts.len();
        let index = PointIndex::new(&pts).unwrap();
        let mut targets = vec![u32::MAX; n * K];
        let mut spacing = vec![0.0; n];
        for i in 0..n {
            let nb = index.k_nearest(&pts[i], K + 1);
            for (t, b) in targets[i * K..]
                .iter_mut()
                .zip(nb.iter().filter(|b| b.index as usize != i))
            {
                *t = b.index;
            }
            spacing[i] = nb.last().map_or(0.0, |b| b.distance);
        }
        let area: Vec<f64> = spacing
            .iter()
            .map(|h| std::f64::consts::PI * h * h / K as f64)
            .collect();
        let eligible = vec![true; n];
        let inp = FieldInput {
            points: &pts,
            area: &area,
            spacing: &spacing,
            scale: &spacing,
            targets: &targets,
            stride: K,
            eligible: &eligible,
        };
        let mut tree = DipoleTree::new(&pts, &nrm, &area);
        let (out, redirected) = refine(&mut nrm, &inp, &mut tree, cancel)?;
        assert_eq!(redirected.iter().filter(|&&r| r).count(), out.redirected);
        for (r, &i) in order.iter().enumerate() {
            normals[i as usize] = nrm[r];
        }
        let agree = normals
            .iter()
            .zip(truth)
            .filter(|(a, b)| dot(**a, **b) > 0.0)
            .count();
        assert!(normals.iter().all(|v| (norm(*v) - 1.0).abs() < 1e-9));
        Ok((out, agree as f64 / n as f64))
    }

    /// Fibonacci points on the ellipsoid with semi-axes `a` about (0.5, 0.5, 0.5), with exact
    /// outward normals.
    fn ellipsoid(n: usize, a: [f64; 3]) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let t = golden * i as f64;
                let u = [r * t.cos(), r * t.sin(), z];
                let p = [0.5 + a[0] * u[0], 0.5 + a[1] * u[1], 0.5 + a[2] * u[2]];
                let g = normalize([u[0] / a[0], u[1] / a[1], u[2] / a[2]]).unwrap();
                (p, g)
            })
            .unzip()
    }

    #[test]
    fn a_consistent_sphere_is_left_alone() {
        let (pts, truth) = ellipsoid(3000, [0.4; 3]);
        let mut nrm = truth.clone();
        let (out, agree) = run(&pts, &truth, &mut nrm);
        assert_eq!(out.suspicious, 0, "{out:?}");
        assert_eq!(out.iterations, 0);
        assert_eq!(agree, 1.0);
        assert_eq!(nrm, truth);
    }

    /// The slowest case for the iteration (the correct orientation spreads from the equator to
    /// the pole: 125 iterations); the winding check of [`crate::winding`] runs first in the
    /// pipeline and fixes such caps itself.
    #[test]
    fn a_flipped_hemisphere_comes_back() {
        let (pts, truth) = ellipsoid(3000, [0.4; 3]);
        let mut nrm = truth.clone();
        for (v, p) in nrm.iter_mut().zip(&pts) {
            if p[2] > 0.5 {
                *v = scale(*v, -1.0);
            }
        }
        let messy = nrm.clone();
        let cancel = Cancel::new();
        cancel.cancel();
        assert_eq!(run_with(&pts, &truth, &mut nrm, &cancel), Err(Cancelled));
        assert_eq!(nrm, messy);
        let (out, agree) = run(&pts, &truth, &mut nrm);
        assert!(out.flips >= 1400, "{out:?}");
        assert!(agree >= 0.995, "{agree} {out:?}");
    }

    #[test]
    fn both_sheets_of_a_thin_plate_flipped_together_come_back() {
        // A plate 0.8 wide and 0.03 thick (about two sample spacings): neighbourhoods reach
        // across it. Flip one end of it, both sheets and the rim, as the tree propagation does
        // across a thin part.
        let (pts, truth) = ellipsoid(6000, [0.4, 0.4, 0.015]);
        let mut nrm = truth.clone();
        let region = |p: &[f64; 3]| p[0] > 0.65;
        let mut flipped = 0;
        for (v, p) in nrm.iter_mut().zip(&pts) {
            if region(p) {
                *v = scale(*v, -1.0);
                flipped += 1;
            }
        }
        assert!(flipped > 600);
        let (out, agree) = run(&pts, &truth, &mut nrm);
        assert!(out.suspicious > 0, "{out:?}");
        assert!(agree >= 0.99, "{agree} {out:?}");
    }
}
