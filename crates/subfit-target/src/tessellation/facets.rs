//! What the facets of a triangle mesh say ([`Facets`]: normals, areas, interior edges with their
//! dihedral angles, flat edges, planar regions) and whether the mesh is a CAD tessellation
//! ([`TessellationStats`]); Hoppe et al. 1994, §2 on the piecewise-smooth model (see the
//! parent module's docs).

use std::collections::HashMap;

use subfit_mesh::vec3::{cross, dot, norm, sub};

use super::elements::{FacetEdge, PlanarRegion};
use super::planes;

/// A mesh is a tessellation when at least this share of its interior edges is flat (the two
/// faces coplanar, see [`Facets::new`]). A CAD export's quad strips alone give a third (one
/// diagonal per two triangles) and its planar faces nearly all: the corpus's CAD exports
/// measure 0.24–0.63 (`examples/tessellation_stats.rs`). Its scans and scanned meshes measure
/// below 0.05, a resampled bathymetry 0.13, and a gridded geological horizon 0.76 (it is a
/// tessellation of planar quads; without creases it is no CAD part, see `subfit-init`'s
/// CAD cage).
pub const FLAT_EDGE_SHARE: f64 = 0.2;

/// A mesh is also a tessellation when at least this share of its area lies in exact planar
/// regions of three faces or more, however few of its edges test flat: an export whose faces
/// are fans of extreme slivers (aspect 1e5 and more, where a corner's distance from the other
/// face's plane is dominated by rounding) measures 0.19. Scans and scanned meshes measure at
/// most 0.10 (a resampled bathymetry; `examples/tessellation_stats.rs`).
pub const PLANAR_AREA_SHARE: f64 = 0.15;

/// Triangles whose longest edge is more than this many times their height on it are slivers
/// (reported, not used to decide): exporters make them along every strip.
pub const SLIVER_ASPECT: f64 = 10.0;

/// What the facets of a triangle mesh say (see the module docs).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Facets {
    /// The triangles, `#F by 3`.
    pub triangles: Vec<[u32; 3]>,
    /// Unit normal per face (`[0; 3]` for a face of zero area).
    pub normals: Vec<[f64; 3]>,
    /// Area per face.
    pub areas: Vec<f64>,
    /// Interior manifold edges (two faces, consistently oriented).
    pub edges: Vec<FacetEdge>,
    /// Edges with one face, `[a, b]` with `a < b`.
    pub boundary: Vec<[u32; 2]>,
    /// Planar region of every face.
    pub region: Vec<u32>,
    /// The planar regions.
    pub regions: Vec<PlanarRegion>,
    /// Distance within which four corners count as coplanar (units of the positions).
    pub flat_tolerance: f64,
}

impl Facets {
    /// Measures the facets of `triangles` over `positions` (`#V by 3`); faces that repeat a
    /// vertex and edges of more than two faces are left out of the edge lists (a repaired mesh
    /// has neither). `flat_tolerance` is the largest distance of a corner from the other
    /// face's plane for a flat edge: a few units of the file's rounding
    /// ([`Facets::float32_tolerance`] for STL's single precision). Cost O(F log F).
    pub fn new(positions: &[[f64; 3]], triangles: &[[u32; 3]], flat_tolerance: f64) -> Self {
        let mut normals = Vec::with_capacity(triangles.len());
        let mut areas = Vec::with_capacity(triangles.len());
        for t in triangles {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            let n = cross(sub(b, a), sub(c, a));
            let l = norm(n);
            areas.push(0.5 * l);
            normals.push(if l > 0.0 { n.map(|x| x / l) } else { [0.0; 3] });
        }
        let (interior, boundary) = edge_faces(triangles);
        let mut edges: Vec<FacetEdge> = interior
            .into_iter()
            .map(|(ends, faces)| {
                let flat = coplanar(positions, triangles, &areas, ends, faces, flat_tolerance);
                FacetEdge {
                    ends,
                    faces,
                    angle: 0.0,
                    convex: true,
                    flat,
                }
            })
            .collect();
        let (region, regions) = planes::grow(
            positions,
            triangles,
            &normals,
            &areas,
            &edges,
            flat_tolerance,
        );
        for e in &mut edges {
            let [f, g] = e.faces.map(|f| f as usize);
            let nf = regions[region[f] as usize].normal;
            let ng = regions[region[g] as usize].normal;
            // One region, or a face without a plane (zero area, alone): nothing turns here.
            e.flat = region[f] == region[g] || nf == [0.0; 3] || ng == [0.0; 3];
            if e.flat {
                e.angle = 0.0;
                continue;
            }
            e.angle = dot(nf, ng).clamp(-1.0, 1.0).acos();
            // Convex when the far corner of g lies behind f's plane.
            let far = triangles[g]
                .iter()
                .copied()
                .find(|v| !e.ends.contains(v))
                .unwrap_or(e.ends[0]);
            let p = positions[e.ends[0] as usize];
            e.convex = dot(sub(positions[far as usize], p), nf) <= 0.0;
        }
        Self {
            triangles: triangles.to_vec(),
            normals,
            areas,
            edges,
            boundary,
            region,
            regions,
            flat_tolerance,
        }
    }

    /// The flat tolerance for coordinates stored in single precision (STL) that spanned
    /// `magnitude` in the file (the largest absolute coordinate) and were scaled by `scale`
    /// into the units used: 8 units in the last place of an f32 of that magnitude, at least
    /// 1e-9 (double-precision files).
    pub fn float32_tolerance(magnitude: f64, scale: f64) -> f64 {
        (8.0 * f64::from(f32::EPSILON) * magnitude * scale).max(1e-9)
    }

    /// The figures that tell a tessellation from a scan. Cost O(F + E).
    pub fn stats(&self, positions: &[[f64; 3]]) -> TessellationStats {
        let flat = self.edges.iter().filter(|e| e.flat).count();
        let share = flat as f64 / self.edges.len().max(1) as f64;
        let total: f64 = self.areas.iter().sum();
        let planar: f64 = self
            .regions
            .iter()
            .filter(|r| r.faces >= 3)
            .map(|r| r.area)
            .sum();
        let slivers = self
            .triangles
            .iter()
            .filter(|t| {
                let [a, b, c] = t.map(|v| positions[v as usize]);
                let long = norm(sub(b, a)).max(norm(sub(c, b))).max(norm(sub(a, c)));
                let area = 0.5 * norm(cross(sub(b, a), sub(c, a)));
                long * long > SLIVER_ASPECT * 2.0 * area
            })
            .count();
        let mut used = vec![false; positions.len()];
        for t in &self.triangles {
            for &v in t {
                used[v as usize] = true;
            }
        }
        TessellationStats {
            is_tessellation: !self.edges.is_empty()
                && (share >= FLAT_EDGE_SHARE
                    || (total > 0.0 && planar / total >= PLANAR_AREA_SHARE)),
            vertices: used.iter().filter(|&&u| u).count(),
            faces: self.triangles.len(),
            flat_edge_share: share,
            planar_regions: self.regions.iter().filter(|r| r.faces >= 3).count(),
            planar_area_share: if total > 0.0 { planar / total } else { 0.0 },
            sliver_share: slivers as f64 / self.triangles.len().max(1) as f64,
        }
    }
}

/// Whether a mesh is a CAD tessellation, and the figures that say so.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TessellationStats {
    /// At least [`FLAT_EDGE_SHARE`] of the interior edges are flat.
    pub is_tessellation: bool,
    /// Vertices used by the faces.
    pub vertices: usize,
    /// Triangles.
    pub faces: usize,
    /// Share of the interior edges that are flat.
    pub flat_edge_share: f64,
    /// Planar regions of three faces or more.
    pub planar_regions: usize,
    /// Share of the area in those regions.
    pub planar_area_share: f64,
    /// Share of the triangles that are slivers ([`SLIVER_ASPECT`]).
    pub sliver_share: f64,
}

/// Interior manifold edges `(ends, faces)` (consistently oriented, two faces) and boundary
/// edges of `triangles`, sorted by their ends.
type EdgeLists = (Vec<([u32; 2], [u32; 2])>, Vec<[u32; 2]>);

fn edge_faces(triangles: &[[u32; 3]]) -> EdgeLists {
    let mut map: HashMap<[u32; 2], Vec<(u32, bool)>> = HashMap::with_capacity(triangles.len() * 2);
    for (f, t) in triangles.iter().enumerate() {
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            continue;
        }
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            map.entry([a.min(b), a.max(b)])
                .or_default()
                .push((f as u32, a < b));
        }
    }
    let mut interior = Vec::new();
    let mut boundary = Vec::new();
    for (ends, faces) in map {
        match faces.as_slice() {
            [_] => boundary.push(ends),
            [(f, df), (g, dg)] if df != dg => {
                let pair = if *df { [*f, *g] } else { [*g, *f] };
                interior.push((ends, pair));
            }
            _ => {}
        }
    }
    interior.sort_unstable();
    boundary.sort_unstable();
    (interior, boundary)
}

/// Whether the two faces of an edge are coplanar: the height of the tetrahedron of their four
/// corners over the larger face is at most `tol` (the smaller face's own normal is the less
/// accurate one for a sliver).
fn coplanar(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    areas: &[f64],
    ends: [u32; 2],
    faces: [u32; 2],
    tol: f64,
) -> bool {
    let far = |f: u32| {
        triangles[f as usize]
            .iter()
            .copied()
            .find(|v| !ends.contains(v))
    };
    let (Some(c), Some(d)) = (far(faces[0]), far(faces[1])) else {
        return false;
    };
    let [a, b, c, d] = [ends[0], ends[1], c, d].map(|v| positions[v as usize]);
    let volume6 = dot(sub(d, a), cross(sub(b, a), sub(c, a))).abs();
    let base = areas[faces[0] as usize].max(areas[faces[1] as usize]);
    // height = 3 V / base area = volume6 / (2 base).
    base > 0.0 && volume6 <= 2.0 * base * tol
}
