//! The tracking step's robustness to large motion between frames:
//!
//! - **Data → model correspondences** (symmetric ICP; e.g. Li, Sumner & Pauly, "Global
//!   correspondence optimization for non-rigid registration of depth scans", SGP 2008, §4.1,
//!   use both directions for the same reason): each of an even subsample of the frame's points
//!   pulls the nearest moved sample whose normal agrees (within 60°), along the frame's normal.
//!   Model → data correspondences alone let a limb that moved farther than its width be
//!   matched to whatever body part now lies nearest; the frame's points of that limb still
//!   find the model's limb.
//! - **Stiffness annealing** (Amberg, Romdhani & Vetter, CVPR 2007, §3.2): stiff first (the
//!   graph moves nearly piece-wise rigidly, far correspondences allowed), then softer with a
//!   shorter correspondence radius, down to [`super::TrackOptions`]' own weights and radius.

use rayon::prelude::*;
use subfit_measure::data_samples::area_samples;
use subfit_mesh::vec3::dot;
use subfit_target::neighbors::PointIndex;
use subfit_target::Target;

use super::options::TrackOptions;

/// The frame points used by the data → model correspondences, with their unit normals.
pub(super) struct DataPoints {
    pub(super) points: Vec<[f64; 3]>,
    pub(super) normals: Vec<[f64; 3]>,
}

/// Seed of the area samples of a mesh frame (any fixed value: the step is deterministic).
const SEED: u64 = 0x5eed_7a2c;

/// `count` points of `target` with their normals: on a mesh, uniform by area over its
/// triangles with the normal of the triangle each lies on (a mesh's vertices crowd where its
/// triangles are small, and a low-poly frame has too few of them to stand for its faces);
/// on a point cloud every `⌈n / count⌉`-th point (all of them when `count ≥ n`).
pub(super) fn subsample(target: &Target, count: usize) -> DataPoints {
    let n = target.len();
    if count == 0 || n == 0 {
        return DataPoints {
            points: Vec::new(),
            normals: Vec::new(),
        };
    }
    if let Some(bvh) = target.mesh() {
        let points = area_samples(bvh.vertices(), bvh.triangles(), count, SEED);
        if !points.is_empty() {
            let normals = points
                .par_iter()
                .map(|&p| target.mesh_foot_point(p).normal)
                .collect();
            return DataPoints { points, normals };
        }
    }
    let step = n.div_ceil(count).max(1);
    DataPoints {
        points: target.points().iter().step_by(step).copied().collect(),
        normals: target.normals().iter().step_by(step).copied().collect(),
    }
}

/// Candidates examined per frame point: the nearest moved samples, the first whose normal
/// agrees is taken (the very nearest may be on a body part facing the other way, e.g. the
/// other leg).
const CANDIDATES: usize = 4;

/// Per frame point of `data`, the nearest of the `moved` samples within `reach` whose unit
/// normal (`moved_normals`) is within 60° of the point's: `(sample, point, point's normal)`.
/// Cost: O(S log S) for the index, O(P log S) for the queries.
pub(super) fn matches(
    moved: &[[f64; 3]],
    moved_normals: &[[f64; 3]],
    data: &DataPoints,
    reach: f64,
) -> Vec<(usize, [f64; 3], [f64; 3])> {
    let Some(index) = PointIndex::new(moved) else {
        return Vec::new();
    };
    (0..data.points.len())
        .into_par_iter()
        .filter_map(|j| {
            let (y, n) = (data.points[j], data.normals[j]);
            index
                .k_nearest(&y, CANDIDATES)
                .into_iter()
                .take_while(|c| c.distance <= reach)
                .find(|c| dot(moved_normals[c.index as usize], n) >= 0.5)
                .map(|c| (c.index as usize, y, n))
        })
        .collect()
}

/// One stiffness level of a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Level {
    /// Factor on the regularity and rigidity weights.
    pub stiffness: f64,
    /// Correspondence radius (normalized units).
    pub reach: f64,
    /// Whether this is the last level (where a stalled step ends the iterations).
    pub last: bool,
}

/// The stiffness levels of a step and the iteration each ends at.
pub(super) struct Schedule {
    levels: Vec<(Level, usize)>,
}

impl Schedule {
    /// Levels `stiffness_start, /10, …, 1`, each [`TrackOptions::level_iterations`] long but
    /// the last; the reach geometric from [`TrackOptions::reach_start`] to
    /// [`TrackOptions::max_distance`].
    pub(super) fn new(o: &TrackOptions) -> Self {
        let steps = if o.stiffness_start > 1.0 {
            o.stiffness_start.log10().ceil().max(0.0) as usize
        } else {
            0
        };
        let levels = (0..=steps)
            .map(|i| {
                let stiffness = if steps == 0 {
                    1.0
                } else {
                    (o.stiffness_start / 10f64.powi(i as i32)).max(1.0)
                };
                let reach = if steps == 0 {
                    o.max_distance
                } else {
                    let f = i as f64 / steps as f64;
                    o.reach_start.max(o.max_distance).powf(1.0 - f) * o.max_distance.powf(f)
                };
                let end = if i == steps {
                    usize::MAX
                } else {
                    (i + 1) * o.level_iterations
                };
                let last = i == steps;
                (
                    Level {
                        stiffness,
                        reach,
                        last,
                    },
                    end,
                )
            })
            .collect();
        Self { levels }
    }

    /// The level of iteration `it` (0-based).
    pub(super) fn level(&self, it: usize) -> Level {
        self.levels
            .iter()
            .find(|(_, end)| it < *end)
            .or(self.levels.last())
            .map(|(l, _)| *l)
            .expect("a schedule has a level")
    }
}

/// Residual of a match, for tests: `nᵀ(x − y)`.
#[cfg(test)]
fn residual(x: [f64; 3], (_, y, n): (usize, [f64; 3], [f64; 3])) -> f64 {
    dot(n, subfit_mesh::vec3::sub(x, y))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_schedule_anneals_down_to_the_options() {
        let o = TrackOptions::default();
        let s = Schedule::new(&o);
        let first = s.level(0);
        assert_eq!((first.stiffness, first.last), (100.0, false));
        assert!((first.reach - o.reach_start).abs() < 1e-12);
        assert_eq!(s.level(4).stiffness, 10.0);
        let last = s.level(8);
        assert_eq!((last.stiffness, last.last), (1.0, true));
        assert!((last.reach - o.max_distance).abs() < 1e-12);
        assert_eq!(s.level(1000), last);
        let flat = Schedule::new(&TrackOptions {
            stiffness_start: 1.0,
            ..o
        });
        assert!(flat.level(0).last);
    }

    #[test]
    fn a_frame_point_takes_the_nearest_sample_facing_its_way() {
        // Two sheets 0.02 apart facing away from each other; a point just above the upper
        // one facing up takes the upper sheet's sample, not the lower (nearer in index order).
        let moved = vec![[0.0, 0.0, 0.0], [0.0, 0.0, 0.02]];
        let normals = vec![[0.0, 0.0, -1.0], [0.0, 0.0, 1.0]];
        let data = DataPoints {
            points: vec![[0.0, 0.0, 0.011], [5.0, 0.0, 0.0]],
            normals: vec![[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]],
        };
        let m = matches(&moved, &normals, &data, 0.5);
        assert_eq!(m.len(), 1, "the far point is out of reach");
        assert_eq!(m[0].0, 1);
        assert!((residual(moved[1], m[0]) - 0.009).abs() < 1e-12);
    }
}
