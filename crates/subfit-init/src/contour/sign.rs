//! The sign of the octree points off the band for [`crate::contour()`]: a flood fill from the
//! octree's boundary along leaf edges gives the outside; the regions it does not reach take
//! the side of most band points next to them, and the IMLS values are negated when the normals
//! point inward (see "Sign far from the data" in the parent module's documentation).

use crate::octree::{pack, unpack, CORNERS, CORNER_MASK};

use super::sampling::{Frame, Points, Sampled};

/// Union-find with path halving.
pub(super) struct Dsu(Vec<u32>);

impl Dsu {
    pub(super) fn find(&mut self, mut i: u32) -> u32 {
        while self.0[i as usize] != i {
            let g = self.0[self.0[i as usize] as usize];
            self.0[i as usize] = g;
            i = g;
        }
        i
    }
    pub(super) fn union(&mut self, a: u32, b: u32) {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            self.0[a.max(b) as usize] = a.min(b);
        }
    }
}

/// Values off the band: a flood fill from the root's corner along leaf edges (split at hanging
/// nodes) over the off-band points gives `+far` to the reached ones, `far = 2·band·band cell`;
/// the IMLS values are negated when most band points on an edge to the outside are negative;
/// each region it does not reach gets `+far` when most band points on an edge to it are
/// positive, else `−far`. Extra points off the band copy an off-band corner of their leaf
/// (or take the mean of its corners). Returns (flipped, enclosed off-band nodes).
pub(super) fn classify(
    frame: &Frame,
    sampled: &Sampled,
    points: &Points,
    in_band: &[bool],
    values: &mut [f64],
) -> (bool, usize) {
    let mut dsu = Dsu((0..points.len() as u32).collect());
    let mut rim = Vec::new();
    let leaves_of = |f: usize| (sampled.corners[f], sampled.masks[f]);
    for f in 0..sampled.corners.len() {
        let (ids, mask) = leaves_of(f);
        if mask == CORNER_MASK && ids.iter().all(|&i| in_band[i as usize]) {
            continue;
        }
        for k in 0..3 {
            for c in (0..8).filter(|c| c & (1 << k) == 0) {
                let (a, b) = (CORNERS[c], CORNERS[c | 1 << k]);
                let (ia, ib) = (ids[c], ids[c | 1 << k]);
                let mid = (a + b) / 2;
                let chain = if mask & (1 << mid) != 0 {
                    let key = mid_key(points, ia, ib);
                    let im = points.get(key).expect("hanging node is a point");
                    [ia, im, ib]
                } else {
                    [ia, ib, ib]
                };
                for w in chain.windows(2) {
                    match (in_band[w[0] as usize], in_band[w[1] as usize]) {
                        (false, false) => dsu.union(w[0], w[1]),
                        (true, false) => rim.push((w[0], w[1])),
                        (false, true) => rim.push((w[1], w[0])),
                        (true, true) => {}
                    }
                }
            }
        }
    }
    let far = 2.0 * frame.band as f64 * frame.cell * f64::from(1u32 << frame.band_level);
    let outside = dsu.find(points.get(0).expect("the root's corner is a node"));
    let root: Vec<u32> = (0..sampled.n_nodes as u32)
        .map(|i| {
            if in_band[i as usize] {
                u32::MAX
            } else {
                dsu.find(i)
            }
        })
        .collect();
    let root_of = |i: u32| root.get(i as usize).copied().unwrap_or(u32::MAX);
    // The band points next to each off-band region, each counted once per region.
    let mut rim: Vec<(u32, u32)> = rim
        .iter()
        .map(|&(b, o)| (root_of(o), b))
        .filter(|&(r, _)| r != u32::MAX)
        .collect();
    rim.sort_unstable();
    rim.dedup();
    let votes = |r: u32, values: &[f64]| {
        let lo = rim.partition_point(|&(q, _)| q < r);
        let hi = rim.partition_point(|&(q, _)| q <= r);
        rim[lo..hi]
            .iter()
            .fold((0usize, 0usize), |(p, n), &(_, b)| {
                if values[b as usize] < 0.0 {
                    (p, n + 1)
                } else {
                    (p + 1, n)
                }
            })
    };
    let (pos_rim, neg_rim) = votes(outside, values);
    let flipped = neg_rim > pos_rim;
    if flipped {
        for (v, &b) in values.iter_mut().zip(in_band) {
            if b {
                *v = -*v;
            }
        }
    }
    // An enclosed region is inside when most band points around it are (a pocket between
    // folds that the band closes off is outside).
    let mut enclosed = 0;
    let mut region_sign: Vec<(u32, f64)> = Vec::new();
    for i in 0..sampled.n_nodes {
        let r = root[i];
        if r == u32::MAX {
            continue;
        }
        values[i] = if r == outside {
            far
        } else {
            let sign = match region_sign.binary_search_by_key(&r, |&(q, _)| q) {
                Ok(k) => region_sign[k].1,
                Err(k) => {
                    let (p, n) = votes(r, values);
                    let sign = if p > n { far } else { -far };
                    region_sign.insert(k, (r, sign));
                    sign
                }
            };
            if sign < 0.0 {
                enclosed += 1;
            }
            sign
        };
    }
    for (e, &f) in sampled.owner.iter().enumerate() {
        let i = sampled.n_nodes + e;
        if in_band[i] {
            continue;
        }
        let ids = sampled.corners[f as usize];
        values[i] = match ids.iter().find(|&&c| !in_band[c as usize]) {
            Some(&c) => values[c as usize],
            None => ids.iter().map(|&c| values[c as usize]).sum::<f64>() / 8.0,
        };
    }
    (flipped, enclosed)
}

/// Packed key of the midpoint of two points.
pub(super) fn mid_key(points: &Points, a: u32, b: u32) -> u64 {
    let (pa, pb) = (
        unpack(points.keys[a as usize]),
        unpack(points.keys[b as usize]),
    );
    pack([0, 1, 2].map(|k| (pa[k] + pb[k]) / 2))
}
