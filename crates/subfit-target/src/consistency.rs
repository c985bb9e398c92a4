//! Whether the normals a point cloud brings are consistently oriented (DESIGN.md §3.2: the
//! target's normals are unit and consistently oriented).
//!
//! Input normals are kept as given (they usually come from the scanner or a better estimate
//! than ours), but some files carry normals whose *direction* is right and whose *sign* is not:
//! a range image's normals written without orienting them toward the scanner, half of them
//! pointing into the surface. The IMLS function of such a cloud changes sign between
//! neighbouring points, and its zero set is a foam of small closed pieces instead of the sheet
//! (a single range view of the Stanford dragon with such normals: a contour of genus 98 and
//! 139 boundary loops after trimming, against genus 0 with the same points and estimated
//! normals). Hoppe et al. 1992 §3.3 orient unsigned normals by propagation; [`crate::orient`]
//! does that, so when the input's signs disagree the points are handed to it as unoriented
//! (their directions kept, their signs free) instead of fixed.
//!
//! **The test.** Over the edges `(i, j)` of the k-nearest-neighbour graph whose two normals are
//! clearly (anti)parallel (`|n_i·n_j| ≥` [`PARALLEL_COS`]), the fraction with `n_i·n_j < 0`. On a
//! consistently oriented sampled surface neighbouring normals agree, and opposed pairs only
//! occur across a part thinner than the neighbourhood (the two sheets of a thin plate): a few
//! percent at most. With signs independent of the surface the fraction is near one half (0.45
//! on the dragon view above, whose signs are 65 % / 35 % along its mean view direction). The
//! threshold [`MAX_OPPOSED_FRACTION`] sits between the two. Point clouds only: a mesh is
//! oriented by its faces, and a coarse one has many neighbours across thin parts (20 % of the
//! pairs on a 398-vertex cat).

use subfit_mesh::vec3::dot;

/// Two neighbouring normals count in the test when `|n_i·n_j|` is at least this (cosine of
/// 60°): on a smooth surface sampled finely enough for a fit, neighbouring normals are within
/// a few degrees of each other; nearly perpendicular pairs (at a sharp edge, or a noisy
/// estimate) say nothing about the sign.
pub const PARALLEL_COS: f64 = 0.5;

/// Input normals are taken as unoriented when more than this fraction of the counted
/// neighbour pairs point opposite ways (a fraction of graph edges; see the module docs: a
/// consistently oriented sampled surface gives a few percent at most, random signs about 0.5).
pub const MAX_OPPOSED_FRACTION: f64 = 0.1;

/// The fraction of neighbour pairs among the points with `fixed` normals whose normals are
/// clearly opposed (see the module docs), over the nearest-neighbour `graph` (rows of `stride`
/// entries, padded with `u32::MAX`). 0 when no pair counts. Cost `O(#P · stride)`.
pub(crate) fn opposed_fraction(
    normals: &[[f64; 3]],
    fixed: &[bool],
    graph: &[u32],
    stride: usize,
) -> f64 {
    let (mut counted, mut opposed) = (0usize, 0usize);
    for (i, row) in graph.chunks(stride.max(1)).enumerate() {
        if !fixed[i] {
            continue;
        }
        for &j in row {
            let j = j as usize;
            if j >= normals.len() || j == i || !fixed[j] {
                continue;
            }
            let c = dot(normals[i], normals[j]);
            if c.abs() >= PARALLEL_COS {
                counted += 1;
                if c < 0.0 {
                    opposed += 1;
                }
            }
        }
    }
    if counted == 0 {
        0.0
    } else {
        opposed as f64 / counted as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A line of points whose neighbours are the next two: all agreeing, then every other sign
    /// flipped (half the pairs at distance one opposed, none at distance two).
    #[test]
    fn counts_opposed_pairs() {
        let n = 10;
        let graph: Vec<u32> = (0..n)
            .flat_map(|i| [(i + 1) % n, (i + 2) % n].map(|j| j as u32))
            .collect();
        let up = vec![[0.0, 0.0, 1.0]; n];
        let fixed = vec![true; n];
        assert_eq!(opposed_fraction(&up, &fixed, &graph, 2), 0.0);
        let alt: Vec<[f64; 3]> = (0..n)
            .map(|i| [0.0, 0.0, if i % 2 == 0 { 1.0 } else { -1.0 }])
            .collect();
        assert!((opposed_fraction(&alt, &fixed, &graph, 2) - 0.5).abs() < 1e-12);
        // Perpendicular neighbours do not count; unfixed points neither.
        let side: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                if i % 2 == 0 {
                    [0.0, 0.0, 1.0]
                } else {
                    [1.0, 0.0, 0.0]
                }
            })
            .collect();
        assert!((opposed_fraction(&side, &fixed, &graph, 2)).abs() < 1e-12);
        assert_eq!(opposed_fraction(&alt, &[false; 10], &graph, 2), 0.0);
    }
}
