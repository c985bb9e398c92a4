//! Samples grouped by shared support, for a fast fill of the normal matrix of the quadratic
//! model (the error terms of Cheng 2007 §II-D summed over samples; DESIGN.md §3.3).
//!
//! `H = w_e Σ_k (c_k c_kᵀ) ⊗ Q_k` is a sum of small dense blocks. Most samples share their
//! support with many others (all level-`l` samples inside one control face depend on the same
//! control points, those on an edge or at a vertex on a subset of them), so the samples are
//! grouped under a *host* support that contains each of theirs. Per host the dense
//! `s × s` block (6 upper components per pair of points) is a product of a `K × s` matrix of
//! stencil weights with itself, weighted by the `Q_k`: contiguous dot products that vectorize.
//! Each block is then added once into a *part* buffer of its chunk of hosts; every entry of
//! `H` finally sums its parts in a fixed order. Nothing depends on the thread count, so the
//! fill is bitwise deterministic across thread counts; no locks.
//!
//! The grouping is generic: a sample's support becomes a host unless a host containing it
//! already exists (supports visited largest first), so no assumption on the scheme or the
//! topology is made — a worse grouping only costs time.

use std::collections::HashMap;

use rayon::prelude::*;
use subfit_subdiv::StencilMatrix;

use crate::term::Mat3;

/// Hosts larger than this fall back to the column-wise fill (dense blocks would grow as s²).
pub(crate) const MAX_HOST: usize = 48;
/// Samples per chunk of hosts (a unit of parallel work with its own part buffer).
const CHUNK_SAMPLES: usize = 2048;

/// Per-sample weighted residuals (`m by 3`) and the gradient parts to fill.
pub(crate) type GradientParts<'a> = (&'a [[f64; 3]], &'a mut [[f64; 3]]);

/// One chunk's index with its slices of the block parts and of the gradient parts.
type ChunkParts<'a> = (usize, &'a mut [[f64; 6]], &'a mut [[f64; 3]]);

/// Samples grouped under host supports, with the map from each host's pairs of points to the
/// block entries of `H`.
#[derive(Clone, Debug)]
pub(crate) struct Groups {
    /// Host `h` has `sup_ptr[h + 1] − sup_ptr[h]` control points (its support, increasing, is
    /// only needed while building).
    sup_ptr: Vec<usize>,
    /// Host `h`'s samples: `smp[smp_ptr[h]..smp_ptr[h + 1]]`.
    smp_ptr: Vec<usize>,
    smp: Vec<u32>,
    /// The nonzeros of the samples in host order (`smp`): sample `smp[x]` has the weights
    /// `wts[nz_ptr[x]..nz_ptr[x + 1]]` at the positions `local[..]` of its host's support.
    /// A copy of the operator's values, so that a host's samples are read contiguously.
    nz_ptr: Vec<usize>,
    wts: Vec<f64>,
    local: Vec<u8>,
    /// Per host, for its pairs `p ≤ q` (column-major over the upper triangle), the slot of the
    /// block entry in the host's chunk of parts: `pair_slot[pair_ptr[h]..pair_ptr[h + 1]]`.
    pair_ptr: Vec<usize>,
    pair_slot: Vec<u32>,
    /// Chunk `c` holds hosts `chunk_host[c]..chunk_host[c + 1]` and parts
    /// `part_ptr[c]..part_ptr[c + 1]`.
    chunk_host: Vec<usize>,
    part_ptr: Vec<usize>,
    /// Block entry `e` of `H` (index into the pattern's block rows) sums the parts
    /// `contrib[contrib_ptr[e]..contrib_ptr[e + 1]]` (in chunk order).
    contrib_ptr: Vec<usize>,
    contrib: Vec<u32>,
    /// Per host point (indexed like the supports, `sup_ptr`), the slot of its control point in
    /// the chunk's gradient parts; chunk `c` owns `vpart_ptr[c]..vpart_ptr[c + 1]`, and
    /// control point `j` sums `vcontrib[vcontrib_ptr[j]..vcontrib_ptr[j + 1]]`.
    vslot: Vec<u32>,
    vpart_ptr: Vec<usize>,
    vcontrib_ptr: Vec<usize>,
    vcontrib: Vec<u32>,
    /// Rows and nonzeros of the operator the groups were built for.
    nrows: usize,
    nnz: usize,
}

/// Whether the sorted list `a` is contained in the sorted list `b`.
fn is_subset(a: &[u32], b: &[u32]) -> bool {
    let mut it = b.iter();
    a.iter().all(|x| it.by_ref().any(|y| y == x))
}

/// What [`host_supports`] returns: the distinct support of every sample (`dist_of`), the host
/// of every distinct support (`host_of_dist`, `u32::MAX` for an empty one) and the hosts'
/// supports (`host_sup`).
type HostSupports<'c> = (Vec<u32>, Vec<u32>, Vec<&'c [u32]>);

/// The hosts of the samples of `c` (`m × n`): its distinct supports, then, largest first, each
/// support joins the first host containing it or becomes a host ([`HostSupports`]). `None`
/// when a host would exceed [`MAX_HOST`] points.
fn host_supports(c: &StencilMatrix) -> Option<HostSupports<'_>> {
    let (m, n) = (c.nrows(), c.ncols());
    // Distinct supports, then hosts: largest first, each joins the first host containing it.
    let mut distinct: HashMap<&[u32], u32> = HashMap::new();
    let mut dist_of = Vec::with_capacity(m);
    let mut supports: Vec<&[u32]> = Vec::new();
    for k in 0..m {
        let idx = c.row(k).0;
        let next = supports.len() as u32;
        let d = *distinct.entry(idx).or_insert(next);
        if d == next {
            supports.push(idx);
        }
        dist_of.push(d);
    }
    drop(distinct);
    let mut order: Vec<u32> = (0..supports.len() as u32).collect();
    order.sort_by(|&a, &b| {
        let (a, b) = (supports[a as usize], supports[b as usize]);
        b.len().cmp(&a.len()).then(a.cmp(b))
    });
    let mut host_of_dist = vec![u32::MAX; supports.len()];
    let mut host_sup: Vec<&[u32]> = Vec::new();
    let mut by_vertex: Vec<Vec<u32>> = vec![Vec::new(); n];
    for &d in &order {
        let s = supports[d as usize];
        let Some(&first) = s.first() else {
            continue;
        };
        let found = by_vertex[first as usize]
            .iter()
            .copied()
            .find(|&h| is_subset(s, host_sup[h as usize]));
        host_of_dist[d as usize] = match found {
            Some(h) => h,
            None => {
                if s.len() > MAX_HOST {
                    return None;
                }
                let h = host_sup.len() as u32;
                host_sup.push(s);
                for &v in s {
                    by_vertex[v as usize].push(h);
                }
                h
            }
        };
    }
    Some((dist_of, host_of_dist, host_sup))
}

/// The nonzeros of `c`'s samples in host order (`smp`, host `h`'s in
/// `smp[smp_ptr[h]..smp_ptr[h + 1]]`, its support `sup[sup_ptr[h]..sup_ptr[h + 1]]`): the
/// fields `nz_ptr`, `wts` and `local` of [`Groups`].
fn host_nonzeros(
    c: &StencilMatrix,
    sup: &[u32],
    sup_ptr: &[usize],
    smp: &[u32],
    smp_ptr: &[usize],
) -> (Vec<usize>, Vec<f64>, Vec<u8>) {
    let nh = sup_ptr.len() - 1;
    let mut nz_ptr = Vec::with_capacity(smp.len() + 1);
    let mut wts = Vec::with_capacity(c.nnz());
    let mut local = Vec::with_capacity(c.nnz());
    nz_ptr.push(0);
    for h in 0..nh {
        let hs = &sup[sup_ptr[h]..sup_ptr[h + 1]];
        for &k in &smp[smp_ptr[h]..smp_ptr[h + 1]] {
            let (idx, w) = c.row(k as usize);
            let mut p = 0;
            for &i in idx {
                while hs[p] != i {
                    p += 1;
                }
                local.push(p as u8);
            }
            wts.extend_from_slice(w);
            nz_ptr.push(wts.len());
        }
    }
    (nz_ptr, wts, local)
}

/// The chunks of hosts (`chunk_host` of [`Groups`]): consecutive hosts until a chunk holds at
/// least [`CHUNK_SAMPLES`] samples (`smp_ptr`: the hosts' sample ranges).
fn chunks(smp_ptr: &[usize]) -> Vec<usize> {
    let nh = smp_ptr.len() - 1;
    let mut chunk_host = vec![0usize];
    let mut count = 0;
    for h in 0..nh {
        count += smp_ptr[h + 1] - smp_ptr[h];
        if count >= CHUNK_SAMPLES {
            chunk_host.push(h + 1);
            count = 0;
        }
    }
    if *chunk_host.last().unwrap_or(&0) != nh {
        chunk_host.push(nh);
    }
    chunk_host
}

/// What [`pair_slots`] returns: `pair_ptr`, `pair_slot`, `part_ptr` (of [`Groups`]) and the
/// block entry of `H` of every part.
type PairSlots = (Vec<usize>, Vec<u32>, Vec<usize>, Vec<u32>);

/// The part slot of every pair of a host's points, per chunk of hosts ([`PairSlots`]). `None`
/// when a pair misses the pattern (block rows `brow` per block column `bcol_ptr`).
fn pair_slots(
    chunk_host: &[usize],
    sup: &[u32],
    sup_ptr: &[usize],
    bcol_ptr: &[usize],
    brow: &[u32],
) -> Option<PairSlots> {
    let nh = sup_ptr.len() - 1;
    let nblocks = brow.len();
    let mut mark = vec![u32::MAX; nblocks];
    let mut pair_ptr = Vec::with_capacity(nh + 1);
    let mut pair_slot = Vec::new();
    let mut part_ptr = vec![0usize];
    let mut part_entry: Vec<u32> = Vec::new();
    pair_ptr.push(0);
    for w in chunk_host.windows(2) {
        let base = part_entry.len();
        for h in w[0]..w[1] {
            let hs = &sup[sup_ptr[h]..sup_ptr[h + 1]];
            for (qi, &j) in hs.iter().enumerate() {
                for &i in &hs[..=qi] {
                    let col = &brow[bcol_ptr[j as usize]..bcol_ptr[j as usize + 1]];
                    let e = bcol_ptr[j as usize] + col.binary_search(&i).ok()?;
                    if mark[e] == u32::MAX || (mark[e] as usize) < base {
                        mark[e] = part_entry.len() as u32;
                        part_entry.push(e as u32);
                    }
                    pair_slot.push(mark[e] - base as u32);
                }
            }
            pair_ptr.push(pair_slot.len());
        }
        part_ptr.push(part_entry.len());
    }
    Some((pair_ptr, pair_slot, part_ptr, part_entry))
}

/// The gradient's part slot of every host point, per chunk (`vslot`, `vpart_ptr` of
/// [`Groups`]), and the control point (of `n`) of every part.
fn vertex_slots(
    chunk_host: &[usize],
    sup: &[u32],
    sup_ptr: &[usize],
    n: usize,
) -> (Vec<u32>, Vec<usize>, Vec<u32>) {
    let mut vmark = vec![u32::MAX; n];
    let mut vslot = vec![0u32; sup.len()];
    let mut vpart_ptr = vec![0usize];
    let mut vpart_vertex: Vec<u32> = Vec::new();
    for w in chunk_host.windows(2) {
        let base = vpart_vertex.len();
        for x in sup_ptr[w[0]]..sup_ptr[w[1]] {
            let j = sup[x] as usize;
            if vmark[j] == u32::MAX || (vmark[j] as usize) < base {
                vmark[j] = vpart_vertex.len() as u32;
                vpart_vertex.push(j as u32);
            }
            vslot[x] = vmark[j] - base as u32;
        }
        vpart_ptr.push(vpart_vertex.len());
    }
    (vslot, vpart_ptr, vpart_vertex)
}

/// The reduction map of parts onto their targets: part `x` adds to target `targets[x]` (of
/// `len`); returns (`ptr`, `parts`) with target `t` summing `parts[ptr[t]..ptr[t + 1]]`, in
/// part order (the `contrib` and `vcontrib` maps of [`Groups`]).
fn gather_map(targets: &[u32], len: usize) -> (Vec<usize>, Vec<u32>) {
    let mut ptr = vec![0usize; len + 1];
    for &e in targets {
        ptr[e as usize + 1] += 1;
    }
    for e in 0..len {
        ptr[e + 1] += ptr[e];
    }
    let mut fill = ptr.clone();
    let mut parts = vec![0u32; targets.len()];
    for (x, &e) in targets.iter().enumerate() {
        parts[fill[e as usize]] = x as u32;
        fill[e as usize] += 1;
    }
    (ptr, parts)
}

impl Groups {
    /// Groups the samples of `c` (`m × n`) for the pattern with block rows `brow` per block
    /// column (`bcol_ptr`, `n + 1`). `None` when a host would exceed [`MAX_HOST`] points or a
    /// pair misses the pattern (then the caller keeps the column-wise fill).
    /// Cost: O(nnz(C) + Σ_hosts s² log) time, O(nnz(C) + Σ_hosts s²) memory.
    pub fn new(c: &StencilMatrix, bcol_ptr: &[usize], brow: &[u32]) -> Option<Self> {
        let (m, n) = (c.nrows(), c.ncols());
        let (dist_of, host_of_dist, host_sup) = host_supports(c)?;
        // Hosts ordered by their first control point (locality of the touched columns).
        let mut hosts: Vec<u32> = (0..host_sup.len() as u32).collect();
        hosts.sort_by_key(|&h| (host_sup[h as usize][0], h));
        let mut rank = vec![0u32; hosts.len()];
        for (r, &h) in hosts.iter().enumerate() {
            rank[h as usize] = r as u32;
        }
        let nh = hosts.len();
        let mut sup_ptr = Vec::with_capacity(nh + 1);
        let mut sup = Vec::new();
        sup_ptr.push(0);
        for &h in &hosts {
            sup.extend_from_slice(host_sup[h as usize]);
            sup_ptr.push(sup.len());
        }
        // Samples per host (increasing k); empty rows belong to no host.
        let host_of = |k: usize| -> Option<usize> {
            let h = host_of_dist[dist_of[k] as usize];
            (h != u32::MAX).then(|| rank[h as usize] as usize)
        };
        let mut smp_ptr = vec![0usize; nh + 1];
        for k in 0..m {
            if let Some(h) = host_of(k) {
                smp_ptr[h + 1] += 1;
            }
        }
        for h in 0..nh {
            smp_ptr[h + 1] += smp_ptr[h];
        }
        let mut next = smp_ptr.clone();
        let mut smp = vec![0u32; smp_ptr[nh]];
        for k in 0..m {
            let Some(h) = host_of(k) else { continue };
            smp[next[h]] = k as u32;
            next[h] += 1;
        }
        let (nz_ptr, wts, local) = host_nonzeros(c, &sup, &sup_ptr, &smp, &smp_ptr);
        // Chunks, part slots of the pairs, and the reduction map.
        let chunk_host = chunks(&smp_ptr);
        let (pair_ptr, pair_slot, part_ptr, part_entry) =
            pair_slots(&chunk_host, &sup, &sup_ptr, bcol_ptr, brow)?;
        // The same for the gradient's parts, one per control point touched by a chunk.
        let (vslot, vpart_ptr, vpart_vertex) = vertex_slots(&chunk_host, &sup, &sup_ptr, n);
        let (vcontrib_ptr, vcontrib) = gather_map(&vpart_vertex, n);
        let (contrib_ptr, contrib) = gather_map(&part_entry, brow.len());
        Some(Self {
            sup_ptr,
            smp_ptr,
            smp,
            nz_ptr,
            wts,
            local,
            pair_ptr,
            pair_slot,
            chunk_host,
            part_ptr,
            contrib_ptr,
            contrib,
            vslot,
            vpart_ptr,
            vcontrib_ptr,
            vcontrib,
            nrows: m,
            nnz: c.nnz(),
        })
    }

    /// Whether `c` has the shape and nonzero count the groups were built for.
    pub fn fits(&self, c: &StencilMatrix) -> bool {
        c.nrows() == self.nrows && c.nnz() == self.nnz
    }

    /// Number of part buffers' entries (`[f64; 6]` each).
    pub fn num_parts(&self) -> usize {
        self.contrib.len()
    }

    /// Number of gradient parts (`[f64; 3]` each).
    pub fn num_vparts(&self) -> usize {
        self.vcontrib.len()
    }

    /// Gradient parts of control point `j`.
    pub fn vcontribs(&self, j: usize) -> &[u32] {
        &self.vcontrib[self.vcontrib_ptr[j]..self.vcontrib_ptr[j + 1]]
    }

    /// Parts of block entry `e`.
    pub fn contribs(&self, e: usize) -> &[u32] {
        &self.contrib[self.contrib_ptr[e]..self.contrib_ptr[e + 1]]
    }

    /// Fills `parts` (`num_parts`) with `w_e Σ_k c_ki c_kj Q_k` (6 upper components) per host
    /// pair, summed per chunk. Parallel over chunks; deterministic.
    ///
    /// With `grad = Some((r, vparts))` also fills `vparts` (`num_vparts`) with the gradient's
    /// `w_e Σ_k c_kj r_k` per host point, summed per chunk (`r`: per-sample weighted residuals,
    /// `m by 3`).
    pub fn fill_parts(
        &self,
        q: &[Mat3],
        w_e: f64,
        parts: &mut [[f64; 6]],
        grad: Option<GradientParts<'_>>,
    ) {
        let nc = self.chunk_host.len() - 1;
        let mut chunks: Vec<ChunkParts<'_>> = Vec::with_capacity(nc);
        let (r, mut vrest): (Option<&[[f64; 3]]>, &mut [[f64; 3]]) = match grad {
            Some((r, v)) => (Some(r), v),
            None => (None, &mut []),
        };
        let mut rest = parts;
        for ci in 0..nc {
            let (head, tail) = rest.split_at_mut(self.part_ptr[ci + 1] - self.part_ptr[ci]);
            rest = tail;
            let vlen = if r.is_some() {
                self.vpart_ptr[ci + 1] - self.vpart_ptr[ci]
            } else {
                0
            };
            let (vhead, vtail) = std::mem::take(&mut vrest).split_at_mut(vlen);
            vrest = vtail;
            chunks.push((ci, head, vhead));
        }
        chunks.into_par_iter().for_each_init(
            || [Vec::new(), Vec::new(), Vec::new()],
            |scratch, (ci, part, vpart)| {
                part.fill([0.0; 6]);
                vpart.fill([0.0; 3]);
                for h in self.chunk_host[ci]..self.chunk_host[ci + 1] {
                    self.host_block(q, w_e, h, scratch, part);
                    if let Some(r) = r {
                        self.host_gradient(r, w_e, h, &scratch[0], vpart);
                    }
                }
            },
        );
    }

    /// Adds host `h`'s gradient `w_e Σ_k c_kp r_k` into its chunk's `vpart`, with `bt` the
    /// host's weights as left by [`Self::host_block`].
    fn host_gradient(
        &self,
        r: &[[f64; 3]],
        w_e: f64,
        h: usize,
        bt: &[f64],
        vpart: &mut [[f64; 3]],
    ) {
        let s = self.sup_ptr[h + 1] - self.sup_ptr[h];
        let samples = &self.smp[self.smp_ptr[h]..self.smp_ptr[h + 1]];
        let mut gl = [[0.0; 3]; MAX_HOST];
        let gl = &mut gl[..s];
        for (&k, btcol) in samples.iter().zip(bt.chunks_exact(s)) {
            let rk = r[k as usize];
            for (g, &c) in gl.iter_mut().zip(btcol) {
                for a in 0..3 {
                    g[a] += c * rk[a];
                }
            }
        }
        let slots = &self.vslot[self.sup_ptr[h]..self.sup_ptr[h + 1]];
        for (g, &x) in gl.iter().zip(slots) {
            let d = &mut vpart[x as usize];
            for a in 0..3 {
                d[a] += w_e * g[a];
            }
        }
    }

    /// Adds host `h`'s dense block into its chunk's `part`. With `Bᵀ` (`s × K`) the host's
    /// samples' stencil weights (a column per sample) and `Y` (`K` columns of `6s`, point-major:
    /// `Y[6p + t, k] = Bᵀ[p, k] w_e Q_k[t]`, `t` over the 6 upper components), the sums of the
    /// pairs `p ≤ q` are the first `6(q + 1)` entries of `Y Bᵀ[q, :]ᵀ`: contiguous
    /// multiply-adds over `K`, in 8 accumulators that vectorize (plain Rust: a dense-product
    /// library's wide-vector kernels were measured to slow the scalar code that follows, the
    /// projection, by 1.5–2× on this machine). Scratch: `bt`, `y`, `r` (grown, never shrunk).
    fn host_block(
        &self,
        q: &[Mat3],
        w_e: f64,
        h: usize,
        scratch: &mut [Vec<f64>; 3],
        part: &mut [[f64; 6]],
    ) {
        const W: usize = 8;
        let [bt, y, r] = scratch;
        let s = self.sup_ptr[h + 1] - self.sup_ptr[h];
        let samples = &self.smp[self.smp_ptr[h]..self.smp_ptr[h + 1]];
        let kk = samples.len();
        // Columns of Y padded so that every 8-wide window starting below 6s is in bounds.
        let rows = 6 * s + W;
        for (v, len) in [
            (&mut *bt, s * kk),
            (&mut *y, rows * kk),
            (&mut *r, 2 * rows),
        ] {
            if v.len() < len {
                v.resize(len, 0.0);
            }
        }
        let bt = &mut bt[..s * kk];
        bt.fill(0.0);
        let y = &mut y[..rows * kk];
        let r = &mut r[..2 * rows];
        let x0 = self.smp_ptr[h];
        for (col, ((&k, btcol), ycol)) in samples
            .iter()
            .zip(bt.chunks_exact_mut(s))
            .zip(y.chunks_exact_mut(rows))
            .enumerate()
        {
            let nz = self.nz_ptr[x0 + col]..self.nz_ptr[x0 + col + 1];
            for (&p, &w) in self.local[nz.clone()].iter().zip(&self.wts[nz]) {
                btcol[p as usize] = w;
            }
            let qk = &q[k as usize];
            let wq = [qk[0][0], qk[0][1], qk[0][2], qk[1][1], qk[1][2], qk[2][2]].map(|v| w_e * v);
            for (yp, &b) in ycol.chunks_exact_mut(6).zip(btcol.iter()) {
                for (yv, &v) in yp.iter_mut().zip(&wq) {
                    *yv = b * v;
                }
            }
            ycol[6 * s..].fill(0.0);
        }
        let slots = &self.pair_slot[self.pair_ptr[h]..self.pair_ptr[h + 1]];
        let mut pair = 0;
        // Two columns q at a time share the loads of Y (the second is absent for odd s).
        let (r0, r1) = r.split_at_mut(rows);
        for q0 in (0..s).step_by(2) {
            let q1 = (q0 + 1 < s).then_some(q0 + 1);
            let len = 6 * (q1.unwrap_or(q0) + 1);
            for c0 in (0..len).step_by(W) {
                let (mut a0, mut a1) = ([0.0f64; W], [0.0f64; W]);
                for (ycol, btcol) in y.chunks_exact(rows).zip(bt.chunks_exact(s)) {
                    let c = btcol[q0];
                    let d = q1.map_or(0.0, |q1| btcol[q1]);
                    if c == 0.0 && d == 0.0 {
                        continue;
                    }
                    let yw: &[f64; W] = ycol[c0..c0 + W].try_into().expect("8-wide window");
                    for ((a, b), &v) in a0.iter_mut().zip(a1.iter_mut()).zip(yw) {
                        *a += c * v;
                        *b += d * v;
                    }
                }
                r0[c0..c0 + W].copy_from_slice(&a0);
                r1[c0..c0 + W].copy_from_slice(&a1);
            }
            for (qi, rq) in [(Some(q0), &*r0), (q1, &*r1)] {
                let Some(qi) = qi else { continue };
                for p in 0..=qi {
                    let dst = &mut part[slots[pair] as usize];
                    for (d, &v) in dst.iter_mut().zip(&rq[6 * p..6 * p + 6]) {
                        *d += v;
                    }
                    pair += 1;
                }
            }
        }
    }
}
