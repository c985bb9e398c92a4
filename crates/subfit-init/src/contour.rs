//! A closed, manifold surface from an oriented point cloud: the IMLS function of Xie et al. 2023
//! (eq. 2–3, [`subfit_target::Target::imls`]) sampled on an adaptive octree and contoured by
//! marching tetrahedra on a conforming tetrahedralization of its leaves (the crate's `octree`
//! module).
//!
//! Cheng et al. 2004 §4.3 contour an octree by marching cubes and Cheng et al. 2007 §II-C by the
//! dual marching cubes of Schaefer & Warren 2004. Marching cubes on the leaves leaves cracks
//! where cells of different sizes meet, and the cube cases of both are ambiguous, so the
//! result can be non-manifold; this module contours a tetrahedralization of the leaves that is
//! conforming across level transitions instead (face triangles shared by both sides, hanging
//! nodes included; see the octree module), so the piecewise-linear zero set is always a closed
//! 2-manifold with no cracks. Leaves without hanging nodes, which
//! are all the leaves near the surface in practice, use the Kuhn triangulation of the cube,
//! so on a uniform region the result is exactly the uniform-grid marching tetrahedra.
//!
//! **Octree.** The finest level has [`ContourOptions::resolution`] cells along the longest side
//! of the data. The *band* is built on the **band level**, the coarsest level whose cells are no
//! larger than the automatic cell (`h / cells_per_radius`, `h` the IMLS radius): the band cells
//! are those within [`ContourOptions::band_cells`] cells (Chebyshev distance, on that level) of a
//! data point; those and the cells touching them are refined to the band level at least. Below
//! it (the automatic resolution is [`ContourOptions::refine_levels`] levels finer than the band
//! level; an explicit `resolution` sets the finest level itself), band cells are split further,
//! level by level, only where the IMLS values at their corners change sign or come within
//! [`ContourOptions::refine_margin`] cell edges of zero, so the finest cells hug the zero set
//! and a part thinner than a band cell keeps an inside. The tree is then 2:1 balanced. Memory and time grow with the area of the
//! surface over the square of the cell, not with the cube of the resolution.
//!
//! **Sign far from the data.** The IMLS value is used only at points in the closed band cells
//! (corners, hanging nodes, leaf centres). Band points with no data point within `h` take
//! [`Target::imls_reaching`]: the kernel grown to reach the data, so a patch of points votes on
//! the side (the nearest point's tangent plane alone lets one wrong normal decide: a torus
//! cloud with every third normal flipped got spurious sheets, genus 29, and now contours to
//! genus 1; the noisy armadillo's cage fits 1.36e-3 of the diagonal from the clean mesh
//! instead of 1.64e-3), except beyond the cloud's rim points, where a grown kernel would cap a
//! hole of the scan (and where Lucy's clean cloud, thin parts seen edge-on, still grows 11
//! stray components, removed as small).
//! Every other point is classified by a flood fill from
//! the octree's boundary over the points off the band, along leaf edges (split at hanging
//! nodes; on the band level this is the 6-neighbourhood of a uniform grid): reached points are
//! outside (`+2·band·cell`). So the surface cannot grow sheets away from the data, and a scan
//! with holes larger than the band leaks (its inside is taken as outside; the surface then hugs
//! the band's inner side). If most band points on an edge to the outside region are negative,
//! the normals point inward and the IMLS values are negated ([`ContourReport::flipped`]).
//! A region the fill does not reach, enclosed by the band, takes the side of most band points
//! next to it: the inside of a closed surface (`−2·band·cell`), or a pocket or cavity that the
//! band closes off (outside).
//!
//! Then small components are removed ([`ContourOptions::min_component_fraction`]), unless one
//! alone covers data (at least [`crate::islands::MIN_ISLAND_POINTS`] points farther than the
//! band width from every other kept component: an island of a range scan, [`crate::islands`]).
//! Cost:
//! `O(n log n)` for the `n` octree points (about the band's cells on the band level plus, with
//! a finer resolution, a few layers of finest cells around the zero set) plus one IMLS
//! evaluation per band point (parallel in `subfit-target`).

use subfit_mesh::{Cancel, Cancelled, HalfEdgeMesh, PolyMesh};
use subfit_target::Target;

use crate::islands::keep_components;
use crate::march::Marcher;
use crate::octree::{leaf_tets, pack, unpack, Leaf, Octree, CORNER_MASK, KUHN};

mod sampling;
mod sign;

use sampling::{band_points, evaluate, refine_band, Band, Frame, Points, Sampled};
use sign::classify;

/// Largest accepted [`ContourOptions::resolution`] and [`ContourOptions::max_resolution`].
pub const MAX_RESOLUTION: usize = 4096;

/// Options of [`contour`]. Lengths in the target's normalized units (unit cube).
#[derive(Clone, Debug, PartialEq)]
pub struct ContourOptions {
    /// Cells of the octree's finest level along the longest side of the data's bounding box
    /// (`2..=`[`MAX_RESOLUTION`]). Default `None`: from the target's IMLS radius `h` (itself from
    /// the point spacing), band cell size `h / cells_per_radius`, clamped to
    /// `16..=max_resolution`, and [`Self::refine_levels`] levels finer (at most
    /// `max_resolution`; see the module docs).
    pub resolution: Option<usize>,
    /// Cells of the band level per IMLS radius `h` (the automatic resolution is this, refined
    /// [`Self::refine_levels`] times near the zero set). Default 1.25 (cell `0.8 h`): the IMLS function has no detail finer than `h`, and
    /// on the real models a finer grid (2.5 cells per `h`) was 4× larger and slower to contour
    /// and simplify, and created a spurious handle on the armadillo. Valid: finite, `> 0`.
    pub cells_per_radius: f64,
    /// Levels of adaptive refinement below the band level with the automatic resolution: the
    /// finest cells are `2^refine_levels` times smaller than the band cells, and exist only
    /// where the zero set passes (see [`Self::refine_margin`]). On thin parts (plates, tubes,
    /// the rims of flat shapes thinner than about a band cell) the band level alone misses the
    /// inside between two sheets and breaks the surface into pieces or opens spurious
    /// handles; one level halves the cell there at about 4× the contour's vertices (generated
    /// thin tori and genus-2 tubes get their genus and one component back; the noisy 150k
    /// clouds of bunny, igea, rocker-arm, fertility and armadillo fit 3–20 % closer to their
    /// clean meshes). Default 0 all the same: on a clean cloud with holes (the Stanford
    /// bunny's points) the finer contour closes the handles but its trimmed cage fits 2× worse
    /// at 4,667 control points (1.8e-3 against 8.3e-4 unit cube two-sided). Valid `0..=4`.
    pub refine_levels: usize,
    /// Upper bound of the automatic resolution (`2..=`[`MAX_RESOLUTION`]). Default 1024.
    pub max_resolution: usize,
    /// Half-width of the band where the IMLS sign is trusted, in cells of the band level.
    /// Default `None`: `max(2, ⌈h / band cell⌉)`.
    pub band_cells: Option<usize>,
    /// Below the band level, a band cell is split when its corner values change sign or the
    /// smallest `|f|` at its corners is below this many of its edges. Default 0.5. Valid:
    /// finite, `≥ 0`.
    pub refine_margin: f64,
    /// Components with fewer faces than this fraction of the largest one are removed.
    /// Default 0.05 (valid `[0, 1]`; 1 keeps only the largest).
    pub min_component_fraction: f64,
    /// Cancellation token, polled per octree level, per batch of IMLS evaluations and per
    /// batch of leaves marched; once cancelled, [`contour`] returns
    /// [`ContourError::Interrupted`]. Default: a fresh token, never cancelled.
    /// ([`crate::initial_control_mesh`] uses [`crate::InitOptions::cancel`] instead.)
    pub cancel: Cancel,
}

impl Default for ContourOptions {
    fn default() -> Self {
        Self {
            resolution: None,
            cells_per_radius: 1.25,
            max_resolution: 1024,
            refine_levels: 0,
            band_cells: None,
            refine_margin: 0.5,
            min_component_fraction: 0.05,
            cancel: Cancel::default(),
        }
    }
}

/// What [`contour`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContourReport {
    /// Finest-level lattice nodes along x, y, z of the padded bounding box of the data (the
    /// octree's root is the cube of `2^(leaves_per_level.len() − 1)` finest cells containing it).
    pub nodes: [usize; 3],
    /// Cells of the finest level along the longest side of the data's bounding box.
    pub resolution: usize,
    /// Finest cell size (normalized units).
    pub cell_size: f64,
    /// Band half-width in cells of the band level.
    pub band_cells: usize,
    /// Level of the band (0 = finest; cells `2^band_level` finest cells wide).
    pub band_level: usize,
    /// Points where the IMLS function was evaluated.
    pub band_nodes: usize,
    /// Points off the band classified inside by the flood fill.
    pub enclosed_nodes: usize,
    /// All octree points: leaf corners (hanging nodes included), leaf centres and face Steiner
    /// points of leaves next to finer ones.
    pub octree_nodes: usize,
    /// Leaves per level, finest first (`leaves_per_level[l]`: leaves `2^l` finest cells wide).
    pub leaves_per_level: Vec<usize>,
    /// Leaves crossed by the zero set per level, finest first (before small components are
    /// removed).
    pub cut_leaves_per_level: Vec<usize>,
    /// Whether the IMLS sign was flipped because most band points next to the outside were
    /// negative (inward-pointing normals).
    pub flipped: bool,
    /// Components of the raw contour.
    pub components_found: usize,
    /// Components kept.
    pub components_kept: usize,
    /// Vertices of the output.
    pub vertices: usize,
    /// Triangles of the output.
    pub faces: usize,
    /// Genus of the output (sum over components).
    pub genus: u32,
}

/// Why [`contour`] failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ContourError {
    /// An option is out of range.
    #[error("invalid contour option: {0}")]
    InvalidOption(&'static str),
    /// The zero set is empty (e.g. all normals point inward, or the resolution is too coarse).
    #[error("the implicit function has no zero crossing at resolution {0}")]
    Empty(usize),
    /// Internal error: the contour is not manifold (a bug).
    #[error("internal error: the contour is not manifold: {0}")]
    NotManifold(String),
    /// The cancellation token ([`ContourOptions::cancel`]) was cancelled.
    #[error("interrupted")]
    Interrupted,
}

impl From<Cancelled> for ContourError {
    fn from(_: Cancelled) -> Self {
        ContourError::Interrupted
    }
}

/// Contours the target's IMLS function on an adaptive octree (see the module docs). Returns a
/// closed, manifold, outward-oriented triangle mesh in normalized units (vertices within about
/// a finest cell of the zero set) and a report.
///
/// Errors: [`ContourError::InvalidOption`] for an option out of its documented range,
/// [`ContourError::Empty`] when the function has no zero crossing, [`ContourError::NotManifold`]
/// (a bug), [`ContourError::Interrupted`]. Cost: see the module docs.
pub fn contour(
    target: &Target,
    options: &ContourOptions,
) -> Result<(PolyMesh, ContourReport), ContourError> {
    validate(options)?;
    let cancel = &options.cancel;
    let frame = Frame::new(target, options)?;
    cancel.check()?;
    let band = Band::new(target.points(), &frame);
    let mut tree = Octree::new(frame.root_level);
    let mut points = Points::default();
    let mut values = Vec::new();
    refine_band(
        target,
        &frame,
        &band,
        &mut tree,
        &mut points,
        &mut values,
        options.refine_margin,
        cancel,
    )?;
    cancel.check()?;
    let parents = band.ring.iter().map(|&k| pack(unpack(k).map(|c| c >> 1)));
    tree.split(frame.band_level + 1, parents);
    tree.balance();
    cancel.check()?;
    let leaves = tree.leaves();
    let sampled = Sampled::new(&leaves, &mut points);
    cancel.check()?;

    let in_band = band_points(&leaves, &sampled, &points, &band);
    values.resize(points.len(), f64::NAN);
    let fresh: Vec<u32> = (0..points.len() as u32)
        .filter(|&i| in_band[i as usize] && values[i as usize].is_nan())
        .collect();
    evaluate(target, &frame, &points, &fresh, &mut values, cancel)?;
    let (flipped, enclosed) = classify(&frame, &sampled, &points, &in_band, &mut values);
    cancel.check()?;

    let pos = |i: usize| frame.position(points.keys[i]);
    let (positions, tris, cut_leaves_per_level) = march_octree(
        &leaves,
        &sampled,
        &points,
        &values,
        &pos,
        frame.root_level,
        cancel,
    )?;
    if tris.is_empty() {
        return Err(ContourError::Empty(frame.resolution));
    }

    let band_width = frame.band as f64 * frame.cell * (1u64 << frame.band_level) as f64;
    let (mesh, found, kept) = keep_components(
        positions,
        &tris,
        options.min_component_fraction,
        Some((target.points(), band_width)),
    );
    let he =
        HalfEdgeMesh::from_mesh(&mesh).map_err(|e| ContourError::NotManifold(e.to_string()))?;
    let mut leaves_per_level = vec![0; cut_leaves_per_level.len()];
    for f in &leaves {
        leaves_per_level[f.level as usize] += 1;
    }
    let report = ContourReport {
        nodes: frame.dims,
        resolution: frame.resolution,
        cell_size: frame.cell,
        band_cells: frame.band,
        band_level: frame.band_level as usize,
        band_nodes: in_band.iter().filter(|&&b| b).count(),
        enclosed_nodes: enclosed,
        octree_nodes: points.len(),
        leaves_per_level,
        cut_leaves_per_level,
        flipped,
        components_found: found,
        components_kept: kept,
        vertices: mesh.num_vertices(),
        faces: mesh.num_faces(),
        genus: he.genus(),
    };
    Ok((mesh, report))
}

fn validate(options: &ContourOptions) -> Result<(), ContourError> {
    if !(0.0..=1.0).contains(&options.min_component_fraction) {
        return Err(ContourError::InvalidOption(
            "min_component_fraction must be in [0, 1]",
        ));
    }
    let ok = |r: usize| (2..=MAX_RESOLUTION).contains(&r);
    if !options.resolution.is_none_or(ok) || !ok(options.max_resolution) {
        return Err(ContourError::InvalidOption(
            "resolution and max_resolution must be in 2..=4096",
        ));
    }
    if options.refine_levels > 4 {
        return Err(ContourError::InvalidOption(
            "refine_levels must be in 0..=4",
        ));
    }
    if !(options.cells_per_radius.is_finite() && options.cells_per_radius > 0.0) {
        return Err(ContourError::InvalidOption(
            "cells_per_radius must be finite and > 0",
        ));
    }
    if !(options.refine_margin.is_finite() && options.refine_margin >= 0.0) {
        return Err(ContourError::InvalidOption(
            "refine_margin must be finite and ≥ 0",
        ));
    }
    Ok(())
}

pub(crate) fn bounds(pts: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in pts {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

impl Frame {
    fn new(target: &Target, options: &ContourOptions) -> Result<Self, ContourError> {
        let (lo, hi) = bounds(target.points());
        let ext = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max).max(1e-12);
        let h = target.imls_radius();
        let auto = ((ext * options.cells_per_radius / h).ceil() as usize)
            .clamp(16.min(options.max_resolution), options.max_resolution);
        let resolution = options
            .resolution
            .unwrap_or((auto << options.refine_levels).min(options.max_resolution));
        let mut band_level = 0;
        while resolution >> (band_level + 1) >= auto {
            band_level += 1;
        }
        let cell = ext / resolution as f64;
        let band_cell = cell * f64::from(1u32 << band_level);
        let band = options
            .band_cells
            .unwrap_or_else(|| ((h / band_cell).ceil() as usize).max(2));
        let pad = (band + 2) << band_level;
        let origin = [0, 1, 2].map(|k| lo[k] - pad as f64 * cell);
        let dims = [0, 1, 2].map(|k| ((hi[k] - lo[k]) / cell).ceil() as usize + 2 * pad + 1);
        let cells = dims.iter().max().map_or(1, |&d| d - 1);
        let root_level = (band_level + 1).max(cells.next_power_of_two().trailing_zeros());
        if root_level > 20 {
            return Err(ContourError::InvalidOption(
                "band_cells too large for the resolution",
            ));
        }
        Ok(Self {
            origin,
            cell,
            resolution,
            band_level,
            band,
            root_level,
            dims,
            rim: target.cloud_rim().to_vec(),
        })
    }
}

/// Vertices, triangles and cut leaves per level of [`march_octree`].
type Marched = (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<usize>);

/// Marching tetrahedra over the conforming tetrahedralization of the leaves (see the octree
/// module), skipping leaves whose points all have one sign. `values` and `pos` are indexed by
/// point id. Returns the vertices, the outward triangles and the cut leaves per level
/// (`0..=root_level`). Polls `cancel` every 2^16 leaves.
fn march_octree(
    leaves: &[Leaf],
    sampled: &Sampled,
    points: &Points,
    values: &[f64],
    pos: &dyn Fn(usize) -> [f64; 3],
    root_level: u32,
    cancel: &Cancel,
) -> Result<Marched, Cancelled> {
    let order = |i: usize| points.keys[i];
    let mut marcher = Marcher::new(values, pos, &order);
    let mut cut = vec![0; root_level as usize + 1];
    let mut tets = Vec::new();
    for (f, leaf) in leaves.iter().enumerate() {
        if f % (1 << 16) == 0 {
            cancel.check()?;
        }
        let ids = &sampled.corners[f];
        if sampled.masks[f] == CORNER_MASK {
            let neg = ids.iter().filter(|&&i| values[i as usize] < 0.0).count();
            if neg > 0 && neg < 8 {
                cut[leaf.level as usize] += 1;
                for t in &KUHN {
                    marcher.tet(t.map(|c| ids[c] as usize));
                }
            }
            continue;
        }
        let loc = sampled.local_ids(f, leaf, points);
        let present = || loc.iter().filter(|&&i| i != u32::MAX);
        let neg = present().filter(|&&i| values[i as usize] < 0.0).count();
        if neg == 0 || neg == present().count() {
            continue;
        }
        cut[leaf.level as usize] += 1;
        tets.clear();
        leaf_tets(sampled.masks[f], &mut tets);
        for t in &tets {
            marcher.tet(t.map(|i| loc[i] as usize));
        }
    }
    Ok((marcher.positions, marcher.tris, cut))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::octree::KeyMap;

    /// The exact signed distance to a sphere (radius 20 finest cells) on an octree of 64³
    /// cells refined around it to level 0 where `x < 32` and only to level 2 elsewhere: the
    /// zero set crosses leaves of three levels, leaves with hanging nodes among them, and is
    /// still a closed, manifold sphere with every edge in exactly two triangles.
    #[test]
    fn the_zero_set_is_crack_free_across_level_transitions() {
        let root = 6;
        let sdf = |p: [f64; 3]| {
            let d = [p[0] - 32.3, p[1] - 31.7, p[2] - 32.1];
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - 20.0
        };
        let mut tree = Octree::new(root);
        for l in (1..=root).rev() {
            let n = 1u64 << (root - l);
            let s = f64::from(1u32 << l);
            let near = (0..n * n * n).filter_map(|i| {
                let c = [i % n, i / n % n, i / (n * n)];
                let centre = c.map(|v| (v as f64 + 0.5) * s);
                let deep_enough = l >= 3 || centre[0] < 32.0;
                (deep_enough && sdf(centre).abs() < s).then(|| pack(c))
            });
            let near: Vec<u64> = near.collect();
            tree.split(l, near);
        }
        tree.balance();
        let leaves = tree.leaves();
        let mut points = Points::default();
        let sampled = Sampled::new(&leaves, &mut points);
        let values: Vec<f64> = points
            .keys
            .iter()
            .map(|&k| sdf(unpack(k).map(|c| c as f64)))
            .map(|v| if v == 0.0 { 1e-300 } else { v })
            .collect();
        let pos = |i: usize| unpack(points.keys[i]).map(|c| c as f64);
        let (positions, tris, cut) = march_octree(
            &leaves,
            &sampled,
            &points,
            &values,
            &pos,
            root,
            &Cancel::default(),
        )
        .unwrap();
        assert!(cut[0] > 0 && cut[1] > 0 && cut[2] > 0, "{cut:?}");
        let cut_transitions = leaves
            .iter()
            .zip(&sampled.masks)
            .enumerate()
            .filter(|(f, (leaf, &mask))| {
                let loc = sampled.local_ids(*f, leaf, &points);
                let neg = loc
                    .iter()
                    .filter(|&&i| i != u32::MAX && values[i as usize] < 0.0)
                    .count();
                mask != CORNER_MASK && neg > 0
            })
            .count();
        assert!(cut_transitions > 0);
        let mut edges = KeyMap::<(u32, u32), u32>::default();
        for t in &tris {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        assert!(edges.values().all(|&n| n == 2));
        for p in &positions {
            assert!(sdf(*p).abs() < 0.5, "{p:?}");
        }
        let mesh = PolyMesh::new(positions, subfit_mesh::Polygons::from_triangles(&tris));
        let he = HalfEdgeMesh::from_mesh(&mesh).expect("manifold");
        assert_eq!(
            (he.genus(), he.boundary_loops().len(), he.components().count),
            (0, 0, 1)
        );
    }
}
