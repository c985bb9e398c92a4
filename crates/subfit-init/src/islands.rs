//! Components of a contour that alone cover data: the rule that keeps a small piece of surface
//! when dropping it would leave data points with no surface near them.
//!
//! The contour ([`crate::contour()`]) and the trimming ([`crate::trim`]) drop small components:
//! the IMLS zero set grows little closed blobs around stray points, and trimming leaves islands
//! supported by a few of them. But a single-view range scan also holds real, small, separate
//! pieces — a one-pixel strip of a flat base seen edge-on, a patch of the far side seen through
//! a gap between the ears. Dropped, their points are 12–20 % of the diagonal from the surface
//! (measured on four simulated scans of `bunny.off`), and a fit that leaves data
//! uncovered has not reached its tolerance (DESIGN.md decision 11). A blob around stray points
//! sits next to data the kept surface already covers; an island is the only surface near its
//! points. So a component that would be dropped is kept when at least [`MIN_ISLAND_POINTS`] data
//! points lie farther than a gap (`island_gap`) from every kept component and nearest to it.
//! [`keep_components`] applies the size rule and this one to a contour's triangles.

use subfit_mesh::{face_components, PolyMesh, Polygons};
use subfit_target::PointIndex;

/// Data points an island must cover alone for it to be kept: more than a few stray points
/// that survived outlier removal, no more than the small real pieces of a range scan (18
/// points on a 33k-point view of the bunny; a claw or the rim of an ear seen through a gap of
/// the armadillo, 4–7 points on 20k-point views). With 8, two such pieces of the armadillo's
/// view along +x were dropped, their points 1.4–2.8 % of the diagonal from the surface; with 4
/// they are islands (surface → true-mesh RMS of that fit 1.40e-3 → 8.9e-4, along +z 1.16e-3
/// → 1.13e-3), while the bunny's views, the other armadillo views, the armadillo's vertices
/// read as a closed cloud and the noisy clouds with outliers (Igea, beetle, armadillo) give
/// the same cages as with 8.
pub const MIN_ISLAND_POINTS: usize = 4;

/// The distance beyond which a data point counts as uncovered by the kept components: the
/// contour's band half-width `band_width`, or on a clean cloud at most one point spacing
/// ([`subfit_target::TargetStats::point_spacing`], the median distance to the 16th neighbour).
/// The band is 2–4 % of the diagonal on a 400 × 400 range scan of the bunny, so a piece of
/// 15 points seen through a gap 2.6 % from the surface counted as covered and was dropped;
/// one spacing (0.7 % there) is about the fits' default largest error. On a noisy cloud the
/// noise's tail lies beyond a spacing, so the band stays. Used when trimming an open cloud
/// ([`crate::trim`]); the contour's own components keep the band (the IMLS surface of a closed
/// cloud misses points at thin parts by more than a spacing: the armadillo's vertices read as
/// points kept three blobs with the smaller gap).
pub(crate) fn island_gap(target: &subfit_target::Target, band_width: f64) -> f64 {
    let stats = target.stats();
    if stats.is_noisy() || stats.point_spacing <= 0.0 {
        band_width
    } else {
        band_width.min(stats.point_spacing)
    }
}

/// For every component (`vertex_labels` over `positions`, `u32::MAX` for unused vertices;
/// `count` components), the number of `points` farther than `gap` from every vertex of a
/// component with `kept[c]` and whose nearest vertex lies in component `c` (0 for kept
/// components). Cost: one nearest query per point over the kept vertices, one over all
/// vertices for the points found uncovered (parallel).
pub fn uncovered_by_component(
    points: &[[f64; 3]],
    positions: &[[f64; 3]],
    vertex_labels: &[u32],
    count: usize,
    kept: &[bool],
    gap: f64,
) -> Vec<usize> {
    let mut out = vec![0; count];
    let labelled = |keep: bool| -> Vec<usize> {
        (0..positions.len())
            .filter(|&v| {
                let l = vertex_labels[v];
                l != u32::MAX && kept[l as usize] == keep
            })
            .collect()
    };
    let (kept_v, dropped_v) = (labelled(true), labelled(false));
    if dropped_v.is_empty() {
        return out;
    }
    let at = |vs: &[usize]| vs.iter().map(|&v| positions[v]).collect::<Vec<_>>();
    let uncovered: Vec<[f64; 3]> = match PointIndex::new(&at(&kept_v)) {
        Some(index) => index
            .nearest_batch(points)
            .iter()
            .zip(points)
            .filter(|(n, _)| n.distance > gap)
            .map(|(_, &p)| p)
            .collect(),
        None => points.to_vec(),
    };
    let Some(index) = PointIndex::new(&at(&dropped_v)) else {
        return out;
    };
    for n in index.nearest_batch(&uncovered) {
        out[vertex_labels[dropped_v[n.index as usize]] as usize] += 1;
    }
    out
}

/// Keeps the components with at least `fraction` × (largest face count) faces; re-indexes.
/// Returns the mesh, the number of components found and kept.
pub(crate) fn keep_components(
    positions: Vec<[f64; 3]>,
    tris: &[[u32; 3]],
    fraction: f64,
    cover: Option<(&[[f64; 3]], f64)>,
) -> (PolyMesh, usize, usize) {
    let polys = Polygons::from_triangles(tris);
    let comps = face_components(&polys, positions.len());
    let counts = comps.face_counts();
    let largest = counts.iter().copied().max().unwrap_or(0);
    let mut keep: Vec<bool> = counts
        .iter()
        .map(|&c| c == largest || c as f64 >= fraction * largest as f64)
        .collect();
    if let Some((points, gap)) = cover {
        let alone = uncovered_by_component(
            points,
            &positions,
            &comps.vertex_labels,
            comps.count,
            &keep,
            gap,
        );
        for (k, &a) in keep.iter_mut().zip(&alone) {
            *k |= a >= MIN_ISLAND_POINTS;
        }
    }
    let mut map = vec![u32::MAX; positions.len()];
    let mut out_pos = Vec::new();
    let mut out = Vec::new();
    for (f, t) in tris.iter().enumerate() {
        if !keep[comps.face_labels[f] as usize] {
            continue;
        }
        out.push(t.map(|v| {
            let m = &mut map[v as usize];
            if *m == u32::MAX {
                *m = out_pos.len() as u32;
                out_pos.push(positions[v as usize]);
            }
            *m
        }));
    }
    let kept = keep.iter().filter(|&&k| k).count();
    (
        PolyMesh::new(out_pos, Polygons::from_triangles(&out)),
        comps.count,
        kept,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_components_that_alone_cover_data_count() {
        // Component 0 (kept) near the origin, 1 next to it (a blob), 2 far away (an island).
        let positions = vec![
            [0.0, 0.0, 0.0],
            [0.1, 0.0, 0.0],
            [0.12, 0.0, 0.0],
            [5.0, 0.0, 0.0],
            [9.0, 9.0, 9.0],
        ];
        let labels = vec![0, 0, 1, 2, u32::MAX];
        let kept = [true, false, false];
        let mut points = vec![[0.05, 0.0, 0.0], [0.12, 0.01, 0.0]];
        points.extend((0..10).map(|k| [5.0, 0.001 * k as f64, 0.0]));
        let counts = uncovered_by_component(&points, &positions, &labels, 3, &kept, 0.5);
        assert_eq!(counts, vec![0, 0, 10]);
        // With everything kept there is nothing to count.
        let all = uncovered_by_component(&points, &positions, &labels, 3, &[true; 3], 0.5);
        assert_eq!(all, vec![0, 0, 0]);
    }
}
