//! Welding coincident vertices: a mesh exported with its vertices split along texture seams
//! (photogrammetry and game-asset PLY/glTF exports keep one vertex per UV chart corner) has
//! every seam as a pair of boundary edges and every chart as a component, though the surface
//! is one. Fitting it as it is keeps those seams as boundaries of the cage. Vertices at exactly
//! the same position (bitwise, after `-0.0` is read as `0.0`) are merged into the first of them,
//! as MeshLab's "merge close vertices" does at distance 0; faces that collapse (a repeated
//! vertex) are dropped.
//!
//! Only exact duplicates are merged: two parts that merely touch are not glued. A weld that
//! would make an edge non-manifold (three or more faces on it, two sheets glued along a line)
//! is not done: [`weld_coincident`] returns the mesh unchanged and says so. Cost `O(#V + #H)`
//! with a hash map over positions.

use std::collections::HashMap;

use crate::diagnose::diagnose;
use crate::polygons::{PolyMesh, Polygons};

/// What [`weld_coincident`] did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct WeldReport {
    /// Vertices merged into an earlier one at the same position.
    pub vertices_merged: usize,
    /// Faces dropped because two of their corners became one vertex.
    pub faces_dropped: usize,
    /// Whether a weld was found but not done because it made an edge non-manifold (the counts
    /// above are then those of the weld not done).
    pub refused: bool,
}

/// How many referenced vertices of `mesh` sit at exactly the same position as an earlier
/// referenced one: what [`weld_coincident`] would merge. Cost `O(#V + #H)`.
pub fn coincident_vertices(mesh: &PolyMesh) -> usize {
    let mut referenced = vec![false; mesh.positions.len()];
    for &v in mesh.faces.indices() {
        if let Some(r) = referenced.get_mut(v as usize) {
            *r = true;
        }
    }
    let mut seen = std::collections::HashSet::with_capacity(mesh.positions.len());
    mesh.positions
        .iter()
        .zip(&referenced)
        .filter(|(p, &r)| r && !seen.insert(key(p)))
        .count()
}

/// A position's hash key: its bits, with `-0.0` read as `0.0`.
fn key(p: &[f64; 3]) -> [u64; 3] {
    p.map(|c| if c == 0.0 { 0u64 } else { c.to_bits() })
}

/// Merges the vertices of `mesh` at the same position (see the module docs): each merged-away
/// vertex is removed (with its normal and colour), the others keep their order, the faces are
/// re-indexed. A merge that would make its vertex a bowtie (faces meeting only there) is not
/// done. A point cloud (no faces) is left alone. The mesh is unchanged when nothing is merged
/// or the weld is refused.
pub fn weld_coincident(mesh: &mut PolyMesh) -> WeldReport {
    let mut report = WeldReport::default();
    if mesh.faces.is_empty() {
        return report;
    }
    let mut first: HashMap<[u64; 3], u32> = HashMap::with_capacity(mesh.positions.len());
    let mut referenced = vec![false; mesh.positions.len()];
    for &v in mesh.faces.indices() {
        if let Some(r) = referenced.get_mut(v as usize) {
            *r = true;
        }
    }
    let mut map: Vec<u32> = (0..mesh.positions.len() as u32).collect();
    for (v, p) in mesh.positions.iter().enumerate() {
        if !referenced[v] {
            continue;
        }
        let id = *first.entry(key(p)).or_insert(v as u32);
        if id != v as u32 {
            map[v] = id;
            report.vertices_merged += 1;
        }
    }
    if report.vertices_merged == 0 {
        return report;
    }
    // A merge whose vertex would become a bowtie is undone: two sheets touching at a point (a
    // model's parts, or a split of our own) are not one surface there, and the bowtie split
    // would only take the merge back.
    let nv = mesh.positions.len();
    let (mapped, _) = remapped(&mesh.faces, |v| map.get(v as usize).copied().unwrap_or(v));
    let (was, now) = (
        crate::bowtie::bowtie_vertices(&mesh.faces, nv),
        crate::bowtie::bowtie_vertices(&mapped, nv),
    );
    for (v, m) in map.iter_mut().enumerate() {
        let r = *m as usize;
        if r != v && now[r] && !was[r] {
            *m = v as u32;
            report.vertices_merged -= 1;
        }
    }
    if report.vertices_merged == 0 {
        return report;
    }
    // Merged-away vertices are removed; the others keep their order.
    let mut new_id = vec![u32::MAX; map.len()];
    let mut kept = 0u32;
    for (v, &m) in map.iter().enumerate() {
        if m == v as u32 {
            new_id[v] = kept;
            kept += 1;
        }
    }
    let renumber = |v: u32| match map.get(v as usize) {
        Some(&m) => new_id[m as usize],
        None => v,
    };
    let (faces, dropped) = remapped(&mesh.faces, renumber);
    report.faces_dropped = dropped;
    let (before, after) = (
        diagnose(&mesh.faces, mesh.num_vertices(), None),
        diagnose(&faces, kept as usize, None),
    );
    if after.non_manifold_edges > before.non_manifold_edges {
        report.refused = true;
        return report;
    }
    mesh.faces = faces;
    let keep = |v: &usize| map[*v] == *v as u32;
    mesh.positions = (0..map.len())
        .filter(keep)
        .map(|v| mesh.positions[v])
        .collect();
    if let Some(n) = mesh.normals.as_mut() {
        *n = (0..map.len()).filter(keep).map(|v| n[v]).collect();
    }
    if let Some(c) = mesh.colors.as_mut() {
        *c = (0..map.len()).filter(keep).map(|v| c[v]).collect();
    }
    report
}

/// `faces` with every vertex id `v` replaced by `id(v)`, without the faces that then repeat a
/// vertex; and how many those were.
fn remapped(faces: &Polygons, id: impl Fn(u32) -> u32) -> (Polygons, usize) {
    let mut out = Polygons::with_capacity(faces.len(), faces.indices().len());
    let mut face = Vec::new();
    let mut dropped = 0;
    for f in faces.iter() {
        face.clear();
        face.extend(f.iter().map(|&v| id(v)));
        if (0..face.len()).any(|i| face[i + 1..].contains(&face[i])) {
            dropped += 1;
        } else {
            out.push(&face);
        }
    }
    (out, dropped)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::diagnose_mesh;

    /// Two unit squares side by side, each with its own copy of the shared edge's vertices.
    fn split_squares() -> PolyMesh {
        let p = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [1.0, 1.0, -0.0],
        ];
        let mut faces = Polygons::new();
        faces.push(&[0, 1, 2, 3]);
        faces.push(&[4, 5, 6, 7]);
        PolyMesh::new(p, faces)
    }

    #[test]
    fn a_seam_is_welded_into_one_sheet() {
        let m = split_squares();
        assert_eq!(diagnose_mesh(&m).num_components, 2);
        assert_eq!(coincident_vertices(&m), 2);
        let mut w = m.clone();
        let r = weld_coincident(&mut w);
        assert_eq!(coincident_vertices(&w), 0);
        assert_eq!(
            r,
            WeldReport {
                vertices_merged: 2,
                faces_dropped: 0,
                refused: false
            }
        );
        let d = diagnose_mesh(&w);
        assert_eq!(d.num_components, 1);
        assert_eq!(d.boundary_loops, 1);
        let f: Vec<Vec<u32>> = w.faces.iter().map(<[u32]>::to_vec).collect();
        assert_eq!(f, vec![vec![0, 1, 2, 3], vec![1, 4, 5, 2]]);
        assert_eq!(w.positions.len(), 6);
        assert_eq!(w.positions[4], [2.0, 0.0, 0.0]);
    }

    #[test]
    fn a_weld_that_makes_a_non_manifold_edge_is_refused() {
        // A third square on the same edge (a fin): welded, three faces would share it.
        let mut m = split_squares();
        m.positions.extend([
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [1.0, 1.0, 0.0],
        ]);
        m.faces.push(&[8, 9, 10, 11]);
        let mut w = m.clone();
        let r = weld_coincident(&mut w);
        assert!(r.refused, "{r:?}");
        assert_eq!(w, m);
    }

    #[test]
    fn two_sheets_touching_at_a_point_stay_apart() {
        // Two triangles whose corners 0 and 3 coincide: welded, they would meet only there.
        let p = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
        ];
        let mut faces = Polygons::new();
        faces.push(&[0, 1, 2]);
        faces.push(&[3, 4, 5]);
        let m = PolyMesh::new(p, faces);
        assert_eq!(coincident_vertices(&m), 1);
        let mut w = m.clone();
        assert_eq!(weld_coincident(&mut w), WeldReport::default());
        assert_eq!(w, m);
    }

    #[test]
    fn a_welded_mesh_is_returned_unchanged() {
        let m = crate::shapes::torus_mesh(1.0, 0.3, 12, 8, true);
        let mut w = m.clone();
        let r = weld_coincident(&mut w);
        assert_eq!(r, WeldReport::default());
        assert_eq!(w, m);
    }
}
