//! Consistent normal orientation by minimum-spanning-tree propagation (Hoppe, DeRose, Duchamp,
//! McDonald, Stuetzle 1992, "Surface reconstruction from unorganized points", §3.3), with three
//! safeguards for sparse samplings of thin parts (where neighbourhoods cross sheets):
//!
//! 1. **Edge cost.** The Riemannian graph is the (symmetrized) k-nearest-neighbour graph; an edge
//!    `(i, j)` costs `1 − |n_i·n_j|` (Hoppe), plus `τ · (|n_i·ê| + |n_j·ê|)/2` with `ê` the unit
//!    edge direction (edges leaving the tangent plane, e.g. across a thin plate where the
//!    unoriented normals are parallel and Hoppe's cost is 0, become expensive), plus a penalty
//!    per endpoint whose normal is ambiguous (those points are attached last, as leaves, instead
//!    of relaying the orientation).
//! 2. **Global sign per component.** The tree (Kruskal on sorted `f32` costs, union–find) is
//!    traversed from an arbitrary seed; then the sign of each component is chosen so that
//!    `Σ_i a_i n_i·(p_i − c)` (divergence theorem: 3 × the enclosed volume for a closed surface
//!    with outward normals, `a_i` the area per point, `c` the centroid) is positive. When that sum
//!    is not decisive, or the component does not look closed (`|Σ_i a_i n_i|` not small, as it is
//!    for a closed surface), the point of largest `z` faces `+z` (ties `+x`, then `+y`).
//! 3. **Consensus pass.** A point whose normal disagrees with the weighted majority of its
//!    neighbours (weights `|n_i·n_j|` times the in-plane fraction of the edge, lower for
//!    ambiguous neighbours) is flipped; repeated until stable (a few sweeps).
//! 4. **Global check on closed components** ([`crate::winding`]; Barill et al. 2018): a normal
//!    pointing up the generalized winding number of the rest of the shape (its neighbourhood
//!    left out) points inward and is flipped; a few passes. This repairs whole regions that the
//!    tree oriented across a thin part, which no local rule sees.
//! 5. **Field refinement** ([`crate::regularize`]; WNNC, Lin et al. 2024, with the on-surface
//!    term of PGR, Lin et al. 2022): where a cheap check of the winding field finds suspicious
//!    points (`w` outside `[0, 1]` at a sample, or a normal more than 60° from `−∇w`), a monotone
//!    iteration makes the normals there follow the field's gradient with `w = ½` on the
//!    surface. This repairs both sheets of a thin part flipped together (consistent for step 4)
//!    and replaces directions the local fit got wrong; skipped when nothing is suspicious.
//!
//! Points with a prescribed (fixed) normal keep it and orient their components: they are merged
//! into one tree root before Kruskal's algorithm. Cost O(E log E) for E = #P·k edges (parallel
//! sort), the winding check O(P log P) per pass, the field refinement O(C log P) for its check
//! of `C` points and O(A log P) per iteration on `A` active points, the rest O(E).

use std::time::{Duration, Instant};

use rayon::prelude::*;
use subfit_mesh::{Cancel, Cancelled};

use crate::neighbors::morton_order;
use crate::regularize::{self, FieldInput};
use crate::winding::{self, DipoleTree, WindingInput};
use subfit_mesh::vec3::{add, dot, norm, normalize, scale, sub};

/// Outcome of [`orient_normals`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Orientation {
    /// Per point: whether its normal was negated.
    pub flipped: Vec<bool>,
    /// Number of connected components of the graph (each seeded separately).
    pub components: usize,
    /// Flips made by the global winding-number check on closed-looking components (after
    /// propagation and consensus; a point flipped twice counts twice).
    pub winding_flips: usize,
    /// Points failing the winding-field check of [`crate::regularize`] (0: the field
    /// refinement was skipped).
    pub field_suspicious: usize,
    /// Iterations of the field refinement.
    pub field_iterations: usize,
    /// Sign changes made by the field refinement.
    pub field_flips: usize,
    /// Per point: whether the field refinement replaced the normal's direction (`#P`; the
    /// caller refits what depends on it). Empty when nothing was replaced.
    pub redirected: Vec<bool>,
    /// Wall time of the spanning tree, propagation and consensus (steps 1–3).
    pub propagate_time: Duration,
    /// Wall time of the winding-number check (step 4).
    pub winding_time: Duration,
    /// Wall time of the field refinement (step 5).
    pub field_time: Duration,
}

/// The k-nearest-neighbour graph: row `i` is `targets[i * stride .. (i + 1) * stride]`, padded
/// with `u32::MAX` when a point has fewer neighbours. Self-loops are ignored.
#[derive(Clone, Copy, Debug)]
pub struct KnnGraph<'a> {
    /// Neighbour indices, `#P · stride`.
    pub targets: &'a [u32],
    /// Entries per row (≥ 1).
    pub stride: usize,
}

/// Per-point inputs of [`orient_normals`] besides positions and normals.
#[derive(Clone, Copy, Debug)]
pub struct OrientInput<'a> {
    /// Whether the point's normal is ambiguous (`#P`).
    pub ambiguous: &'a [bool],
    /// Whether the point's normal is prescribed and must be kept (`#P`).
    pub fixed: &'a [bool],
    /// Area weight of each point for the global sign (e.g. squared neighbourhood radius), `#P`.
    pub area: &'a [f64],
    /// Tangent penalty `τ ≥ 0` of the edge cost.
    pub tangent_penalty: f64,
    /// Whether the point's normal was estimated from a large neighbourhood (more than
    /// [`FIELD_MAX_NEIGHBORS`] samples, as chosen for noisy data), `#P`. The field refinement
    /// (step 5) leaves such points alone: their estimate averages many samples, while the
    /// winding field at the sample spacing mostly sees the noise (measured: on the noisy
    /// analytic shapes it flipped 2–13 correct normals). Empty: none.
    pub trusted: &'a [bool],
    /// Polled between the steps and inside the long loops of every step; once cancelled,
    /// [`orient_normals`] returns [`Cancelled`] (the normals are then partly oriented).
    pub cancel: &'a Cancel,
}

/// Estimation neighbourhoods larger than this make a normal trusted (see
/// [`OrientInput::trusted`]); the defaults use at most 24.
pub const FIELD_MAX_NEIGHBORS: usize = 48;

/// Cost added per ambiguous endpoint of an edge.
const AMBIGUOUS_PENALTY: f64 = 1.0;
/// A component is treated as closed when `|Σ a n| ≤ this · Σ a`.
const MAX_FLUX: f64 = 0.25;
/// The ball left out of a point's winding-number field: this × the distance to its farthest
/// graph neighbour.
const EXCLUDE_WIDEN: f64 = 1.0 + 1e-9;
/// Maximum number of consensus sweeps.
const CONSENSUS_SWEEPS: usize = 8;
/// The volume sum decides a component's sign when `|Σ a n·(p−c)| ≥ this · Σ a |n·(p−c)|`.
const VOLUME_DECISIVE: f64 = 0.2;

/// Orients `normals` (unit, `#P by 3`) in place; see the module doc. The work is done on a copy
/// renumbered in Morton order of the points (memory locality; points are expected in the unit
/// cube, others still work, with less locality), so `normals` is only written at the end.
///
/// Errors: [`Cancelled`] when [`OrientInput::cancel`] is cancelled (`normals` unchanged).
pub fn orient_normals(
    points: &[[f64; 3]],
    normals: &mut [[f64; 3]],
    graph: KnnGraph<'_>,
    input: &OrientInput<'_>,
) -> Result<Orientation, Cancelled> {
    let cancel = input.cancel;
    let n = points.len();
    let k = graph.stride;
    let order = morton_order(points);
    let mut rank = vec![0u32; n];
    for (r, &i) in order.iter().enumerate() {
        rank[i as usize] = r as u32;
    }
    let gather = |v: &[bool]| -> Vec<bool> { order.par_iter().map(|&i| v[i as usize]).collect() };
    let pts: Vec<[f64; 3]> = order.par_iter().map(|&i| points[i as usize]).collect();
    let mut nrm: Vec<[f64; 3]> = order.par_iter().map(|&i| normals[i as usize]).collect();
    let area: Vec<f64> = order.par_iter().map(|&i| input.area[i as usize]).collect();
    let (ambiguous, fixed) = (gather(input.ambiguous), gather(input.fixed));
    let trusted = if input.trusted.is_empty() {
        vec![false; n]
    } else {
        gather(input.trusted)
    };
    cancel.check()?;
    let mut targets = vec![u32::MAX; n * k];
    targets
        .par_chunks_mut(k)
        .zip(order.par_iter())
        .for_each(|(row, &i)| {
            let i = i as usize;
            for (t, &j) in row.iter_mut().zip(&graph.targets[i * k..(i + 1) * k]) {
                if j != u32::MAX {
                    *t = rank[j as usize];
                }
            }
        });
    let graph = KnnGraph {
        targets: &targets,
        stride: k,
    };
    let input = OrientInput {
        ambiguous: &ambiguous,
        fixed: &fixed,
        area: &area,
        tangent_penalty: input.tangent_penalty,
        trusted: &trusted,
        cancel,
    };
    let clock = Instant::now();
    let tree = spanning_tree(&pts, &nrm, graph, &input)?;
    let mut closed = vec![false; n];
    let components = propagate(&pts, &mut nrm, &tree, &input, &mut closed);
    consensus(&pts, &mut nrm, graph, &input)?;
    let eligible: Vec<bool> = closed
        .iter()
        .zip(input.fixed)
        .map(|(&c, &f)| c && !f)
        .collect();
    // Per point, from its k graph neighbours (d_k the distance to the farthest): the area
    // π d_k² / k for the winding number, and d_k (slightly widened) as the radius left out.
    let (wn_area, exclude): (Vec<f64>, Vec<f64>) = targets
        .par_chunks(k)
        .zip(pts.par_iter())
        .map(|(row, &p)| {
            let (cnt, d2) =
                row.iter()
                    .filter(|&&j| j != u32::MAX)
                    .fold((0usize, 0.0f64), |(c, m), &j| {
                        let d = sub(pts[j as usize], p);
                        (c + 1, m.max(dot(d, d)))
                    });
            let a = std::f64::consts::PI * d2 / cnt.max(1) as f64;
            (a, d2.sqrt() * EXCLUDE_WIDEN)
        })
        .unzip();
    cancel.check()?;
    let propagate_time = clock.elapsed();
    let clock = Instant::now();
    let mut dipoles = DipoleTree::new(&pts, &nrm, &wn_area);
    let winding_flips = winding::refine(
        &mut nrm,
        &WindingInput {
            points: &pts,
            area: &wn_area,
            exclude: &exclude,
            targets: &targets,
            stride: k,
            eligible: &eligible,
        },
        &mut dipoles,
        cancel,
    )?;
    let winding_time = clock.elapsed();
    let clock = Instant::now();
    let spacing: Vec<f64> = exclude.par_iter().map(|&e| e / EXCLUDE_WIDEN).collect();
    let scale: Vec<f64> = area.par_iter().map(|&a| a.max(0.0).sqrt()).collect();
    let field_eligible: Vec<bool> = eligible
        .iter()
        .zip(&trusted)
        .map(|(&e, &t)| e && !t)
        .collect();
    let (field, redirected_sorted) = regularize::refine(
        &mut nrm,
        &FieldInput {
            points: &pts,
            area: &wn_area,
            spacing: &spacing,
            scale: &scale,
            targets: &targets,
            stride: k,
            eligible: &field_eligible,
        },
        &mut dipoles,
        cancel,
    )?;
    let field_time = clock.elapsed();
    let redirected = if field.redirected > 0 {
        rank.iter()
            .map(|&r| redirected_sorted[r as usize])
            .collect()
    } else {
        Vec::new()
    };
    let flipped = normals
        .par_iter_mut()
        .zip(rank.par_iter())
        .map(|(o, &r)| {
            let new = nrm[r as usize];
            let f = dot(*o, new) < 0.0;
            *o = new;
            f
        })
        .collect();
    Ok(Orientation {
        flipped,
        components,
        winding_flips,
        field_suspicious: field.suspicious,
        field_iterations: field.iterations,
        field_flips: field.flips,
        redirected,
        propagate_time,
        winding_time,
        field_time,
    })
}

/// Edge cost (see the module doc), as an `f32` whose bits order like its value.
fn edge_key(
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    a: usize,
    b: usize,
    inp: &OrientInput<'_>,
) -> u32 {
    let mut c = 1.0 - dot(normals[a], normals[b]).abs();
    if inp.tangent_penalty > 0.0 {
        if let Some(e) = normalize(sub(points[b], points[a])) {
            c += inp.tangent_penalty * 0.5 * (dot(normals[a], e).abs() + dot(normals[b], e).abs());
        }
    }
    if inp.ambiguous[a] {
        c += AMBIGUOUS_PENALTY;
    }
    if inp.ambiguous[b] {
        c += AMBIGUOUS_PENALTY;
    }
    (c.max(0.0) as f32).to_bits()
}

/// Minimum spanning forest in compressed rows: `(offsets, neighbours)`.
struct Tree {
    off: Vec<usize>,
    adj: Vec<u32>,
}

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let p = parent[x as usize];
        parent[x as usize] = parent[p as usize];
        x = p;
    }
    x
}

/// Kruskal's algorithm on the kNN graph, fixed points pre-merged into one root. Polls
/// `inp.cancel` after the sort and every 2^16 edges.
fn spanning_tree(
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    graph: KnnGraph<'_>,
    inp: &OrientInput<'_>,
) -> Result<Tree, Cancelled> {
    let n = points.len();
    let k = graph.stride;
    // key = cost bits << 32 | slot (i * k + s).
    let mut keys: Vec<u64> = (0..n)
        .into_par_iter()
        .flat_map_iter(|i| {
            // Cancelled: no more keys (the caller checks after the loop).
            let row = if inp.cancel.is_cancelled() {
                &[][..]
            } else {
                &graph.targets[i * k..(i + 1) * k]
            };
            row.iter().enumerate().filter_map(move |(s, &j)| {
                let j = j as usize;
                // Keep one direction of mutual edges.
                if j == u32::MAX as usize || j == i {
                    return None;
                }
                if j < i && graph.targets[j * k..(j + 1) * k].contains(&(i as u32)) {
                    return None;
                }
                let key = edge_key(points, normals, i, j, inp);
                Some((u64::from(key) << 32) | (i * k + s) as u64)
            })
        })
        .collect();
    inp.cancel.check()?;
    keys.par_sort_unstable();
    inp.cancel.check()?;
    let mut parent: Vec<u32> = (0..n as u32).collect();
    let mut size = vec![1u32; n];
    if let Some(f0) = inp.fixed.iter().position(|&f| f) {
        for (i, _) in inp.fixed.iter().enumerate().filter(|(_, &f)| f) {
            parent[i] = f0 as u32;
        }
    }
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(n);
    for (e, key) in keys.into_iter().enumerate() {
        if e % (1 << 16) == 0 {
            inp.cancel.check()?;
        }
        let slot = (key & 0xffff_ffff) as usize;
        let (a, b) = ((slot / k) as u32, graph.targets[slot]);
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        if ra == rb {
            continue;
        }
        let (big, small) = if size[ra as usize] >= size[rb as usize] {
            (ra, rb)
        } else {
            (rb, ra)
        };
        parent[small as usize] = big;
        size[big as usize] += size[small as usize];
        edges.push((a, b));
        if edges.len() + 1 >= n {
            break;
        }
    }
    let mut off = vec![0usize; n + 1];
    for &(a, b) in &edges {
        off[a as usize + 1] += 1;
        off[b as usize + 1] += 1;
    }
    for i in 0..n {
        off[i + 1] += off[i];
    }
    let mut fill = off.clone();
    let mut adj = vec![0u32; off[n]];
    for &(a, b) in &edges {
        adj[fill[a as usize]] = b;
        fill[a as usize] += 1;
        adj[fill[b as usize]] = a;
        fill[b as usize] += 1;
    }
    Ok(Tree { off, adj })
}

/// Traverses the forest: components holding fixed points from those, the others from their
/// highest point, then fixes each free component's global sign. Returns the component count.
fn propagate(
    points: &[[f64; 3]],
    normals: &mut [[f64; 3]],
    tree: &Tree,
    inp: &OrientInput<'_>,
    closed: &mut [bool],
) -> usize {
    let n = points.len();
    let mut visited = vec![false; n];
    let mut stack: Vec<u32> = Vec::new();
    let mut members: Vec<u32> = Vec::new();
    let walk = |stack: &mut Vec<u32>,
                members: &mut Vec<u32>,
                visited: &mut [bool],
                normals: &mut [[f64; 3]]| {
        while let Some(a) = stack.pop() {
            members.push(a);
            let na = normals[a as usize];
            for &b in &tree.adj[tree.off[a as usize]..tree.off[a as usize + 1]] {
                let b = b as usize;
                if visited[b] {
                    continue;
                }
                visited[b] = true;
                if dot(na, normals[b]) < 0.0 {
                    normals[b] = scale(normals[b], -1.0);
                }
                stack.push(b as u32);
            }
        }
    };
    let mut components = 0;
    if inp.fixed.iter().any(|&f| f) {
        components += 1;
        for (i, _) in inp.fixed.iter().enumerate().filter(|(_, &f)| f) {
            visited[i] = true;
            stack.push(i as u32);
        }
        walk(&mut stack, &mut members, &mut visited, normals);
    }
    for start in 0..n as u32 {
        if visited[start as usize] {
            continue;
        }
        // Tree propagation fixes signs relative to the start; the component's global sign is
        // decided afterwards (volume, or its highest point as the seed).
        components += 1;
        visited[start as usize] = true;
        members.clear();
        stack.push(start);
        walk(&mut stack, &mut members, &mut visited, normals);
        let seed = members
            .iter()
            .copied()
            .max_by(|&a, &b| {
                points[a as usize][2]
                    .total_cmp(&points[b as usize][2])
                    .then(b.cmp(&a))
            })
            .unwrap_or(start);
        let (keep, is_closed) = component_sign(points, normals, &members, seed as usize, inp);
        for &m in &members {
            closed[m as usize] = is_closed;
            if !keep {
                normals[m as usize] = scale(normals[m as usize], -1.0);
            }
        }
    }
    components
}

/// Whether a free component's current orientation is to be kept (see the module doc), and
/// whether it looks closed (sign decided by the enclosed volume).
fn component_sign(
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    members: &[u32],
    seed: usize,
    inp: &OrientInput<'_>,
) -> (bool, bool) {
    let mut c = [0.0; 3];
    let mut wsum = 0.0;
    for &m in members {
        let w = inp.area[m as usize];
        for k in 0..3 {
            c[k] += w * points[m as usize][k];
        }
        wsum += w;
    }
    if wsum > 0.0 && members.len() >= 4 {
        let c = scale(c, 1.0 / wsum);
        let (mut s, mut a, mut spread, mut flux) = (0.0, 0.0, 0.0, [0.0; 3]);
        for &m in members {
            let m = m as usize;
            let d = sub(points[m], c);
            let t = inp.area[m] * dot(normals[m], d);
            s += t;
            a += t.abs();
            spread += inp.area[m] * dot(d, d).sqrt();
            flux = add(flux, scale(normals[m], inp.area[m]));
        }
        // Closed-looking (the area-weighted normals nearly cancel, as ∮ n dA = 0 for a closed
        // surface), not flat, and one sign dominating. Open patches use the seed rule.
        let closed = norm(flux) <= MAX_FLUX * wsum;
        if closed && a > 1e-3 * spread && s.abs() >= VOLUME_DECISIVE * a {
            return (s > 0.0, true);
        }
    }
    let nz = normals[seed];
    let key = if nz[2] != 0.0 {
        nz[2]
    } else if nz[0] != 0.0 {
        nz[0]
    } else {
        nz[1]
    };
    (key >= 0.0, false)
}

/// Flips points that disagree with the weighted majority of their neighbours, until stable.
/// Polls `inp.cancel` before each sweep.
fn consensus(
    points: &[[f64; 3]],
    normals: &mut [[f64; 3]],
    graph: KnnGraph<'_>,
    inp: &OrientInput<'_>,
) -> Result<(), Cancelled> {
    let n = points.len();
    let k = graph.stride;
    // Edge weights do not depend on the signs: computed once, in parallel.
    let weights: Vec<f32> = {
        let normals = &*normals;
        (0..n * k)
            .into_par_iter()
            .map(|slot| {
                let (i, j) = (slot / k, graph.targets[slot] as usize);
                if j == u32::MAX as usize || j == i {
                    return 0.0;
                }
                let (ni, nj) = (normals[i], normals[j]);
                let mut w = dot(ni, nj).abs();
                if let Some(e) = normalize(sub(points[j], points[i])) {
                    let off_plane = 0.5 * (dot(ni, e).abs() + dot(nj, e).abs());
                    w *= (1.0 - off_plane).max(0.0);
                }
                if inp.ambiguous[j] {
                    w *= 0.25;
                }
                w as f32
            })
            .collect()
    };
    for _ in 0..CONSENSUS_SWEEPS {
        inp.cancel.check()?;
        let mut changed = 0usize;
        for i in 0..n {
            if inp.fixed[i] {
                continue;
            }
            let ni = normals[i];
            let mut s = 0.0f32;
            for (&j, &w) in graph.targets[i * k..(i + 1) * k]
                .iter()
                .zip(&weights[i * k..(i + 1) * k])
            {
                if w > 0.0 && dot(ni, normals[j as usize]) < 0.0 {
                    s -= w;
                } else {
                    s += w;
                }
            }
            if s < 0.0 {
                normals[i] = scale(ni, -1.0);
                changed += 1;
            }
        }
        if changed == 0 {
            break;
        }
    }
    Ok(())
}
