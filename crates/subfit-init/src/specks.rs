//! Specks: a small disc of surface for a few lone data points that no piece of the trimmed
//! contour covers.
//!
//! A single-view range scan of a closed shape sees parts of it through gaps: a claw between two
//! legs, the tip of a toe behind another. When such a part returns one to a few points, the
//! contour has no component there (the IMLS zero set of one point is not a surface) or one too
//! small to keep as an island ([`crate::islands::MIN_ISLAND_POINTS`]). Left alone, those
//! points end 1–4 % of the diagonal from the fitted surface (measured on five simulated
//! 400 × 400 views of the armadillo, `hard_cases range-scan`), and a fit that leaves
//! data uncovered has not reached its tolerance (DESIGN.md decision 11).
//!
//! So the points farther than the island gap from the trimmed contour are linked into clusters
//! at [`LINK_SPACINGS`] point spacings ([`subfit_target::TargetStats::point_spacing`]); a
//! cluster with no other data point within that distance (lone returns, not the fringe of a
//! piece of surface, which is the trimming's business) and spread at most [`MAX_EXTENT`]
//! spacings from its centre gets a speck: a flat hexagonal fan (seven vertices, six
//! triangles) centred on it, of radius one spacing or [`RIM_MARGIN`] × its spread, normal to
//! its points' plane (or to their estimated normals), a separate open component that the fit
//! then moves onto its points. Its limit surface is a disc of about 5/6 of that radius (a
//! boundary vertex of a regular hexagon has its limit at `(4v + v₋ + v₊)/6 = 5v/6`), so it
//! adds a negligible area of surface away from the true one. Specks are added to the
//! simplified cage (simplification would collapse them), within the control-point budget.
//!
//! Only clean open clouds get specks (on a noisy cloud, points a spacing off the surface are
//! its noise tail), and none when more than [`MAX_SPECKS`] clusters qualify. The points
//! themselves reach the fit because a clean scan whose outlier rules flag only a handful of
//! points keeps them (`subfit_target` outliers, rule 5).
//! Cost: one nearest-vertex query per point, a triangle query and a radius query for the few
//! beyond the gap.

use rayon::prelude::*;
use subfit_mesh::bvh::TriangleBvh;
use subfit_mesh::vec3::{add, cross, norm, normalize, scale, sub};
use subfit_mesh::{PolyMesh, UnionFind};
use subfit_target::estimate::pca;
use subfit_target::{PointIndex, Target};

/// Specks added to one surface at most: more separate clusters than this are not a few parts
/// seen through gaps but a sampling the contour did not follow, for the fit to report.
pub const MAX_SPECKS: usize = 16;

/// Data points of one cluster lie within this many point spacings of another of its points.
const LINK_SPACINGS: f64 = 2.0;
/// A cluster whose points lie farther than this many point spacings from its centre gets no
/// speck.
const MAX_EXTENT: f64 = 2.0;
/// A speck reaches this factor beyond its farthest point (its limit surface, about 5/6 of
/// the fan, then still covers it).
const RIM_MARGIN: f64 = 1.3;
/// Eigenvalue ratio under which a cluster's points span a plane (the middle covariance
/// eigenvalue above this × the largest, the smallest below this × the middle).
const PLANAR: f64 = 0.1;

/// Vertices of one speck: the centre and six on the rim.
pub const SPECK_VERTICES: usize = 7;

/// One speck: the centre and the six rim vertices of a hexagonal fan (normalized units).
#[derive(Clone, Debug, PartialEq)]
pub struct Speck(pub [[f64; 3]; SPECK_VERTICES]);

/// A speck for every cluster of target points farther than `gap` from `surface` (a mesh in the
/// target's normalized units; clusters linked at [`LINK_SPACINGS`] point spacings) that
/// has no other data point within that distance and spreads at most [`MAX_EXTENT`] spacings;
/// none when there are more than [`MAX_SPECKS`].
pub(crate) fn find_specks(target: &Target, surface: &PolyMesh, gap: f64) -> Vec<Speck> {
    let spacing = target.stats().point_spacing;
    let points = target.points();
    if spacing <= 0.0 || surface.num_faces() == 0 || points.is_empty() {
        return Vec::new();
    }
    let Some(vertices) = PointIndex::new(&surface.positions) else {
        return Vec::new();
    };
    let beyond: Vec<usize> = vertices
        .nearest_batch(points)
        .iter()
        .enumerate()
        .filter(|(_, n)| n.distance > gap)
        .map(|(i, _)| i)
        .collect();
    if beyond.is_empty() {
        return Vec::new();
    }
    let bvh = TriangleBvh::new(surface.positions.clone(), surface.faces.triangulate_fan());
    let uncovered: Vec<usize> = beyond
        .into_par_iter()
        .filter(|&i| bvh.closest(points[i]).is_some_and(|c| c.distance > gap))
        .collect();
    if uncovered.is_empty() {
        return Vec::new();
    }
    let link = LINK_SPACINGS * spacing;
    let index = target.index();
    let alone = |c: &Vec<usize>| {
        c.iter().all(|&i| {
            index
                .within(&points[i], link)
                .iter()
                .all(|n| c.binary_search(&(n.index as usize)).is_ok())
        })
    };
    let specks: Vec<Speck> = clusters(points, &uncovered, link)
        .iter()
        .filter_map(|c| speck(target, c, spacing).filter(|_| alone(c)))
        .collect();
    if specks.len() > MAX_SPECKS {
        return Vec::new();
    }
    specks
}

/// Appends `specks` to `mesh` as separate components of six triangles each, wound
/// counter-clockwise about their normal.
pub(crate) fn push_specks(mesh: &mut PolyMesh, specks: &[Speck]) {
    for Speck(vertices) in specks {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(vertices);
        for j in 0..6u32 {
            mesh.faces
                .push(&[base, base + 1 + j, base + 1 + (j + 1) % 6]);
        }
    }
}

/// Groups `members` (indices into `points`, ascending) into clusters linked at distance `link`
/// (union-find over pairs within it), each ascending.
fn clusters(points: &[[f64; 3]], members: &[usize], link: f64) -> Vec<Vec<usize>> {
    let at: Vec<[f64; 3]> = members.iter().map(|&i| points[i]).collect();
    let Some(index) = PointIndex::new(&at) else {
        return Vec::new();
    };
    let mut sets = UnionFind::new(at.len());
    for (a, p) in at.iter().enumerate() {
        for n in index.within(p, link) {
            sets.union(a as u32, n.index);
        }
    }
    let mut groups: Vec<Vec<usize>> = vec![Vec::new(); at.len()];
    for (a, &m) in members.iter().enumerate() {
        groups[sets.find(a as u32) as usize].push(m);
    }
    groups.retain(|g| !g.is_empty());
    groups
}

/// The speck of the points `cluster` of a cloud with point spacing `spacing`: a hexagonal fan
/// centred on them, of radius the larger of `spacing` and [`RIM_MARGIN`] × their largest
/// distance from the centre, perpendicular to their plane (three or more points that span
/// one) or else to the sum of their estimated normals, its rim counter-clockwise about that
/// normal. `None` when the points spread farther than [`MAX_EXTENT`] spacings from their
/// centre (a piece of surface, not a few returns).
fn speck(target: &Target, cluster: &[usize], spacing: f64) -> Option<Speck> {
    let points = target.points();
    let normals = target.normals();
    let k = cluster.len() as f64;
    let centre = cluster
        .iter()
        .fold([0.0; 3], |s, &i| add(s, scale(points[i], 1.0 / k)));
    let extent = cluster
        .iter()
        .map(|&i| norm(sub(points[i], centre)))
        .fold(0.0, f64::max);
    if extent > MAX_EXTENT * spacing {
        return None;
    }
    let radius = spacing.max(RIM_MARGIN * extent);
    let rel: Vec<[f64; 3]> = cluster.iter().map(|&i| sub(points[i], centre)).collect();
    let (_, eig, frame) = pca(&rel);
    let planar = cluster.len() >= 3 && eig[1] > PLANAR * eig[2] && eig[0] < PLANAR * eig[1];
    let summed = cluster.iter().fold([0.0; 3], |s, &i| add(s, normals[i]));
    let n = if planar {
        frame[0]
    } else {
        normalize(summed).unwrap_or([0.0, 0.0, 1.0])
    };
    let helper = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let u = normalize(cross(n, helper)).unwrap_or([1.0, 0.0, 0.0]);
    let v = cross(n, u);
    let mut out = [centre; 7];
    for (j, p) in out[1..].iter_mut().enumerate() {
        let a = j as f64 * std::f64::consts::FRAC_PI_3;
        *p = add(
            centre,
            scale(add(scale(u, a.cos()), scale(v, a.sin())), radius),
        );
    }
    Some(Speck(out))
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfit_mesh::Polygons;
    use subfit_target::TargetOptions;

    const N: usize = 40;

    /// A target of an `N × N` grid on the unit square plus `extra` points (kept: outlier
    /// removal off), and the grid's triangulation in the target's normalized units.
    fn grid_and(extra: &[[f64; 3]]) -> (Target, PolyMesh) {
        let h = 1.0 / (N - 1) as f64;
        let mut points: Vec<[f64; 3]> = (0..N * N)
            .map(|i| [(i % N) as f64 * h, (i / N) as f64 * h, 0.0])
            .collect();
        points.extend_from_slice(extra);
        let options = TargetOptions {
            remove_outliers: false,
            ..TargetOptions::default()
        };
        let t = Target::from_points(&points, None, &options).unwrap();
        let mut tris = Vec::new();
        for y in 0..N - 1 {
            for x in 0..N - 1 {
                let v = (y * N + x) as u32;
                let n = N as u32;
                tris.push([v, v + 1, v + n + 1]);
                tris.push([v, v + n + 1, v + n]);
            }
        }
        let surface = PolyMesh::new(
            t.points()[..N * N].to_vec(),
            Polygons::from_triangles(&tris),
        );
        (t, surface)
    }

    #[test]
    fn a_lone_pair_gets_a_speck_and_the_fringe_of_the_data_does_not() {
        let h = 1.0 / (N - 1) as f64;
        // A pair 0.3 above the middle, and one point just past the grid's edge.
        let pair = [[0.5, 0.5, 0.3], [0.5 + 0.3 * h, 0.5, 0.3]];
        let fringe = [1.0 + 1.5 * h, 0.5, 0.0];
        let (t, surface) = grid_and(&[pair[0], pair[1], fringe]);
        let spacing = t.stats().point_spacing;
        let specks = find_specks(&t, &surface, 0.5 * spacing);
        assert_eq!(specks.len(), 1, "{specks:?}");
        let Speck(v) = &specks[0];
        let mid = t.to_normalized([0.5 + 0.15 * h, 0.5, 0.3]);
        assert!(norm(sub(v[0], mid)) < 1e-12, "{:?} {mid:?}", v[0]);
        for r in &v[1..] {
            assert!((norm(sub(*r, v[0])) - spacing).abs() < 1e-12);
        }
        // Pushed, it is a seven-vertex, six-triangle component.
        let mut m = surface.clone();
        push_specks(&mut m, &specks);
        assert_eq!(m.num_vertices(), surface.num_vertices() + 7);
        assert_eq!(m.num_faces(), surface.num_faces() + 6);
    }

    #[test]
    fn more_than_max_specks_lone_returns_get_none() {
        // Sixteen 0.3 apart at height 0.3 (many spacings from each other), one more above.
        assert_eq!(MAX_SPECKS, 16);
        let mut lone: Vec<[f64; 3]> = (0..16)
            .map(|i| {
                [
                    0.05 + 0.3 * (i % 4) as f64,
                    0.05 + 0.3 * (i / 4) as f64,
                    0.3,
                ]
            })
            .collect();
        lone.push([0.5, 0.5, 0.6]);
        let (t, surface) = grid_and(&lone[..MAX_SPECKS]);
        let gap = 0.5 * t.stats().point_spacing;
        assert_eq!(find_specks(&t, &surface, gap).len(), MAX_SPECKS);
        let (t, surface) = grid_and(&lone);
        assert!(find_specks(&t, &surface, gap).is_empty());
    }
}
