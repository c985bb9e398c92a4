//! The data of foot-point queries in Morton (Z-curve) order of the points, for memory
//! locality (the Z-order curve of Morton 1966).

use rayon::prelude::*;

use crate::estimate::DESCENT_K;
use crate::neighbors::{morton_order, NeighborGraph};
use crate::quadric::LocalQuadric;

/// The data read by foot-point queries, copied into Morton (Z-curve) order of the points: "slot"
/// `s` holds point `point[s]`, and `slot[i]` is the slot of point `i`. The target's public arrays
/// keep the input order; queries read these copies, so that spatially coherent queries (batches
/// are processed in Morton order) touch contiguous memory: on a million points in random input
/// order, cache misses otherwise dominate. Memory: `#P · (4·16 + 8 + 24 + 8 + 8 + 128)` bytes.
#[derive(Debug)]
pub(crate) struct QueryLayout {
    /// Slot of each point, `#P`.
    pub slot: Vec<u32>,
    /// Point of each slot, `#P`.
    pub point: Vec<u32>,
    /// Positions by slot.
    pub points: Vec<[f64; 3]>,
    /// Quadrics by slot.
    pub quadrics: Vec<LocalQuadric>,
    /// Foot-point shortcut diameters by slot (see [`crate::Target::foot_shortcut_diameters`]).
    pub shortcut: Vec<f64>,
    /// Neighbourhood radius of each slot's quadric fit.
    pub radius: Vec<f64>,
    /// Whether each slot's quadric disagrees with its neighbours' (see `blend::untrusted`);
    /// all `false` from [`Self::new`], set by `blend::mark_untrusted`.
    pub untrusted: Vec<bool>,
    /// The `DESCENT_K`-nearest-neighbour graph over slots.
    pub descent: NeighborGraph,
}

impl QueryLayout {
    /// `rows`: the `DESCENT_K` nearest neighbours of each point (point indices, `u32::MAX`
    /// padding), sorted by distance. O(P log P).
    pub(crate) fn new(
        points: &[[f64; 3]],
        quadrics: &[LocalQuadric],
        shortcut: &[f64],
        radius: &[f64],
        rows: &[u32],
    ) -> Self {
        let point = morton_order(points);
        let mut slot = vec![0u32; points.len()];
        for (s, &i) in point.iter().enumerate() {
            slot[i as usize] = s as u32;
        }
        let k = DESCENT_K;
        let targets: Vec<u32> = point
            .par_iter()
            .flat_map_iter(|&i| {
                rows[i as usize * k..(i as usize + 1) * k].iter().map(|&j| {
                    if j == u32::MAX {
                        j
                    } else {
                        slot[j as usize]
                    }
                })
            })
            .collect();
        let spoints: Vec<[f64; 3]> = point.par_iter().map(|&i| points[i as usize]).collect();
        let squadrics: Vec<LocalQuadric> =
            point.par_iter().map(|&i| quadrics[i as usize]).collect();
        let sradius: Vec<f64> = point.par_iter().map(|&i| radius[i as usize]).collect();
        let untrusted = vec![false; point.len()];
        let descent = NeighborGraph::new(&spoints, targets, k);
        Self {
            quadrics: squadrics,
            shortcut: point.par_iter().map(|&i| shortcut[i as usize]).collect(),
            radius: sradius,
            untrusted,
            points: spoints,
            slot,
            point,
            descent,
        }
    }
}
