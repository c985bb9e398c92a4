//! The adaptive octree's lattice and samples for [`crate::contour()`]: the [`Frame`] (finest
//! cell, band level, root), the band of cells around the data ([`Band`]), the octree points
//! and the leaves' corners and extra points ([`Points`], [`Sampled`]), the refinement of band
//! cells near the zero set and the IMLS evaluation (Xie et al. 2023, eq. 2–3) at the points.
//! See the parent module's documentation for the method.

use subfit_mesh::{Cancel, Cancelled};
use subfit_target::Target;

use crate::octree::{
    dilate3, face_centre, face_needs_steiner, pack, unpack, KeyMap, Leaf, Octree, CENTRE, CORNERS,
    CORNER_MASK, HANGING,
};

/// The lattice of one contour: finest cell, band level, padding, root.
pub(super) struct Frame {
    /// Position of finest-lattice point 0.
    pub(super) origin: [f64; 3],
    /// Finest cell size.
    pub(super) cell: f64,
    /// Finest cells along the data's longest side.
    pub(super) resolution: usize,
    pub(super) band_level: u32,
    /// Band half-width in band-level cells.
    pub(super) band: usize,
    pub(super) root_level: u32,
    /// Finest nodes of the padded box along x, y, z.
    pub(super) dims: [usize; 3],
    /// The cloud's boundary points ([`subfit_target::cloud_boundary_points`]): beyond them
    /// the IMLS values keep the nearest point's tangent plane ([`Target::imls_reaching`]).
    pub(super) rim: Vec<bool>,
}

impl Frame {
    /// Position of a packed finest-lattice point.
    pub(super) fn position(&self, key: u64) -> [f64; 3] {
        let c = unpack(key);
        [0, 1, 2].map(|k| self.origin[k] + c[k] as f64 * self.cell)
    }
}

/// The band on the band level (sorted packed band-level coordinates).
pub(super) struct Band {
    pub(super) level: u32,
    /// Cells within `band` cells (Chebyshev) of a data point's nearest band-level node.
    pub(super) cells: Vec<u64>,
    /// `cells` and the cells touching them (refined to the band level at least).
    pub(super) ring: Vec<u64>,
}

impl Band {
    /// Cost `O(m log m)`, `m` the band cells (points are first reduced to distinct nodes).
    pub(super) fn new(points: &[[f64; 3]], frame: &Frame) -> Self {
        let level = frame.band_level;
        let band_cell = frame.cell * f64::from(1u32 << level);
        let mut q: Vec<u64> = points
            .iter()
            .map(|p| pack([0, 1, 2].map(|k| ((p[k] - frame.origin[k]) / band_cell).round() as u64)))
            .collect();
        q.sort_unstable();
        q.dedup();
        let limit = 1u64 << (frame.root_level - level);
        let b = frame.band as i64;
        let cells = dilate3(&q, -b, b - 1, limit);
        let ring = dilate3(&cells, -1, 1, limit);
        Self { level, cells, ring }
    }

    /// Whether `leaf` lies in a band cell. Cost `O(log m)`.
    pub(super) fn holds(&self, leaf: &Leaf) -> bool {
        leaf.level <= self.level
            && self
                .cells
                .binary_search(&pack(unpack(leaf.min).map(|c| c >> self.level)))
                .is_ok()
    }
}

/// Which points lie in a closed band cell: the points (corners, hanging nodes, centres and
/// Steiner points) of the leaves inside band cells, which tile those cells.
pub(super) fn band_points(
    leaves: &[Leaf],
    sampled: &Sampled,
    points: &Points,
    band: &Band,
) -> Vec<bool> {
    let mut in_band = vec![false; points.len()];
    for (f, leaf) in leaves.iter().enumerate() {
        if !band.holds(leaf) {
            continue;
        }
        if sampled.masks[f] == CORNER_MASK {
            for &i in &sampled.corners[f] {
                in_band[i as usize] = true;
            }
        } else {
            for i in sampled.local_ids(f, leaf, points) {
                if i != u32::MAX {
                    in_band[i as usize] = true;
                }
            }
        }
    }
    in_band
}

/// Octree points (packed finest-lattice keys) numbered in insertion order.
#[derive(Default)]
pub(super) struct Points {
    pub(super) index: KeyMap<u64, u32>,
    pub(super) keys: Vec<u64>,
}

impl Points {
    pub(super) fn insert(&mut self, key: u64) -> (u32, bool) {
        let next = self.keys.len() as u32;
        let id = *self.index.entry(key).or_insert(next);
        if id == next {
            self.keys.push(key);
        }
        (id, id == next)
    }
    pub(super) fn get(&self, key: u64) -> Option<u32> {
        self.index.get(&key).copied()
    }
    pub(super) fn len(&self) -> usize {
        self.keys.len()
    }
}

/// Points per batch of IMLS evaluations (a few tens of milliseconds): `cancel` is polled
/// between batches.
pub(super) const EVALUATION_BATCH: usize = 1 << 14;

/// IMLS values ([`Target::imls_reaching`]: far from the data the kernel is grown to reach it)
/// at the points `ids` into `values` (grown with NaN as needed); exact zeros are
/// nudged to `1e-300` (outside). Polls `cancel` per [`EVALUATION_BATCH`] points.
pub(super) fn evaluate(
    target: &Target,
    frame: &Frame,
    points: &Points,
    ids: &[u32],
    values: &mut Vec<f64>,
    cancel: &Cancel,
) -> Result<(), Cancelled> {
    values.resize(points.len(), f64::NAN);
    for batch in ids.chunks(EVALUATION_BATCH) {
        cancel.check()?;
        let xs: Vec<[f64; 3]> = batch
            .iter()
            .map(|&i| frame.position(points.keys[i as usize]))
            .collect();
        let vs = target.imls_reaching_batch(&xs, &frame.rim);
        for (&i, v) in batch.iter().zip(vs) {
            values[i as usize] = if v == 0.0 { 1e-300 } else { v };
        }
    }
    Ok(())
}

/// Below the band level: splits band cells level by level where the zero set may pass
/// (corner values of both signs, or some `|f|` below `margin` edges), evaluating the IMLS
/// function at the corners of the cells it examines. Polls `cancel` per level and per batch of
/// evaluations.
#[allow(clippy::too_many_arguments)]
pub(super) fn refine_band(
    target: &Target,
    frame: &Frame,
    band: &Band,
    tree: &mut Octree,
    points: &mut Points,
    values: &mut Vec<f64>,
    margin: f64,
    cancel: &Cancel,
) -> Result<(), Cancelled> {
    let mut current = band.cells.clone();
    for l in (1..=frame.band_level).rev() {
        cancel.check()?;
        let mut fresh = Vec::new();
        let ids: Vec<[u32; 8]> = current
            .iter()
            .map(|&cell| {
                let leaf = Leaf {
                    min: pack(unpack(cell).map(|c| c << l)),
                    level: l,
                };
                CORNERS.map(|c| {
                    let (id, new) = points.insert(leaf.point_at(c));
                    if new {
                        fresh.push(id);
                    }
                    id
                })
            })
            .collect();
        evaluate(target, frame, points, &fresh, values, cancel)?;
        let edge = margin * frame.cell * f64::from(1u32 << l);
        let split: Vec<u64> = current
            .iter()
            .zip(&ids)
            .filter(|(_, ids)| {
                let v = ids.map(|i| values[i as usize]);
                let neg = v.iter().filter(|&&x| x < 0.0).count();
                (neg > 0 && neg < 8) || v.iter().any(|x| x.abs() < edge)
            })
            .map(|(&c, _)| c)
            .collect();
        tree.split(l, split.iter().copied());
        current = split
            .iter()
            .flat_map(|&p| {
                let pc = unpack(p);
                (0..8u64).map(move |c| pack([0, 1, 2].map(|k| 2 * pc[k] + (c >> k & 1))))
            })
            .collect();
        current.sort_unstable();
    }
    Ok(())
}

/// The leaves' points: corner ids, which hanging nodes each leaf has, and the extra points
/// (leaf centres and face Steiner points) of leaves with hanging nodes.
pub(super) struct Sampled {
    pub(super) corners: Vec<[u32; 8]>,
    /// Bit `i` set when local lattice point `i` of the leaf is a node ([`CORNER_MASK`] = none
    /// hanging).
    pub(super) masks: Vec<u32>,
    /// Points `0..n_nodes` are leaf corners; the others are extra points.
    pub(super) n_nodes: usize,
    /// The leaf that created each extra point.
    pub(super) owner: Vec<u32>,
}

impl Sampled {
    pub(super) fn new(leaves: &[Leaf], points: &mut Points) -> Self {
        // A level-0 leaf shares its low-x corners with the previous leaf when that is its
        // neighbour along x (leaves are sorted z-major): half the lookups on the band.
        let mut corners: Vec<[u32; 8]> = Vec::with_capacity(leaves.len());
        for (i, f) in leaves.iter().enumerate() {
            let prev = i.checked_sub(1).map(|p| (&leaves[p], corners[p]));
            let ids = match prev {
                Some((g, ids)) if f.level == 0 && g.level == 0 && g.min + 1 == f.min => {
                    let mut own = [0; 8];
                    for c in 0..8 {
                        own[c] = if c & 1 == 0 {
                            ids[c | 1]
                        } else {
                            points.insert(f.point_at(CORNERS[c])).0
                        };
                    }
                    own
                }
                _ => CORNERS.map(|c| points.insert(f.point_at(c)).0),
            };
            corners.push(ids);
        }
        let n_nodes = points.len();
        let is_node =
            |points: &Points, key| points.get(key).is_some_and(|i| (i as usize) < n_nodes);
        let masks: Vec<u32> = leaves
            .iter()
            .map(|f| {
                let mut mask = CORNER_MASK;
                if f.level > 0 {
                    for &h in &HANGING {
                        if is_node(points, f.point_at(h)) {
                            mask |= 1 << h;
                        }
                    }
                }
                mask
            })
            .collect();
        let mut owner = Vec::new();
        for (i, (f, &mask)) in leaves.iter().zip(&masks).enumerate() {
            if mask == CORNER_MASK {
                continue;
            }
            let steiner = (0..6)
                .filter(|&face| face_needs_steiner(mask, face))
                .map(face_centre);
            for l in std::iter::once(CENTRE).chain(steiner) {
                if points.insert(f.point_at(l)).1 {
                    owner.push(i as u32);
                }
            }
        }
        Self {
            corners,
            masks,
            n_nodes,
            owner,
        }
    }

    /// Point ids of leaf `f`'s 27 local lattice points (`u32::MAX` where there is none).
    pub(super) fn local_ids(&self, f: usize, leaf: &Leaf, points: &Points) -> [u32; 27] {
        let mut loc = [u32::MAX; 27];
        for (c, &id) in self.corners[f].iter().enumerate() {
            loc[CORNERS[c]] = id;
        }
        let mask = self.masks[f];
        if mask != CORNER_MASK {
            for (i, slot) in loc.iter_mut().enumerate() {
                if *slot == u32::MAX && (mask & (1 << i) != 0 || i == CENTRE) {
                    *slot = points.get(leaf.point_at(i)).unwrap_or(u32::MAX);
                }
            }
            for face in (0..6).filter(|&face| face_needs_steiner(mask, face)) {
                let i = face_centre(face);
                loc[i] = points.get(leaf.point_at(i)).unwrap_or(u32::MAX);
            }
        }
        loc
    }
}
