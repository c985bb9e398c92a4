//! Splitting non-manifold vertices ("bowties"): a vertex whose faces form several fans gets one
//! copy per fan, so the mesh becomes a manifold surface with the same faces and positions.
//!
//! A bowtie is common in real meshes and in meshes with holes cut into them: two holes (or a
//! hole and the rim) that touch at one vertex leave its faces in two fans joined only at that
//! point (`diagnose` counts them as non-manifold vertices). The half-edge structure, the
//! subdivision and the fit need a manifold; the usual repair (e.g. CGAL's
//! `duplicate_non_manifold_vertices`, OpenMesh's import) duplicates the vertex per fan, which
//! keeps every face and every position and only changes what touches what. The largest fan
//! keeps the original vertex id; the others get new ids appended after the existing vertices.
//!
//! Fans are found as in [`crate::diagnose`], by the same union-find over the corners at each
//! vertex, two corners joined when their faces share an edge at the vertex. Non-manifold edges (three or
//! more faces on one edge) are not touched. Cost `O(#H · α)`.

use crate::edges::{corner_fans, corner_next, group_edges, EdgeGroups};
use crate::polygons::{PolyMesh, Polygons};

/// What [`split_bowties`] did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BowtieReport {
    /// Vertices whose faces formed several fans.
    pub vertices_split: usize,
    /// Vertices added (one per fan beyond the first).
    pub vertices_added: usize,
    /// Up to [`crate::diagnose::MAX_EXAMPLES`] of the split vertices (input ids).
    pub examples: Vec<u32>,
}

/// Splits each non-manifold vertex of `mesh` into one vertex per fan of its faces (see the
/// module docs); returns what was split. Faces with an out-of-range or repeated vertex id are
/// left as they are and do not join fans. The mesh is unchanged when there is no bowtie.
pub fn split_bowties(mesh: &mut PolyMesh) -> BowtieReport {
    split_fans(mesh, |_, _, groups| groups)
}

/// [`split_bowties`] with the edge grouping changed by `regroup(faces, next, groups)` before
/// the fans are found: half-edges that `regroup` puts in separate groups do not join their
/// faces, so their vertices split as bowties (how [`crate::cut_nonmanifold_edges`] detaches
/// faces from an edge).
pub(crate) fn split_fans(
    mesh: &mut PolyMesh,
    regroup: impl FnOnce(&Polygons, &[u32], EdgeGroups) -> EdgeGroups,
) -> BowtieReport {
    let nv = mesh.num_vertices();
    let Fans {
        corners_of_valid,
        fan_size,
        mut roots_of,
    } = fans(&mesh.faces, nv, regroup);
    let mut report = BowtieReport::default();
    // New vertex id per fan root that is not its vertex's largest fan; the copies' source.
    let mut new_id = vec![u32::MAX; mesh.faces.indices().len()];
    let mut source: Vec<usize> = Vec::new();
    for (v, roots) in roots_of.iter_mut().enumerate() {
        if roots.len() < 2 {
            continue;
        }
        // The largest fan keeps the id (ties: the lowest corner), the rest in corner order.
        roots.sort_unstable_by_key(|&r| (std::cmp::Reverse(fan_size[r as usize]), r));
        for &r in &roots[1..] {
            new_id[r as usize] = (nv + source.len()) as u32;
            source.push(v);
            report.vertices_added += 1;
        }
        report.vertices_split += 1;
        if report.examples.len() < crate::diagnose::MAX_EXAMPLES {
            report.examples.push(v as u32);
        }
    }
    if report.vertices_split == 0 {
        return report;
    }
    let indices = mesh.faces.indices_mut();
    for &(c, root) in &corners_of_valid {
        let id = new_id[root as usize];
        if id != u32::MAX {
            indices[c as usize] = id;
        }
    }
    // The copies carry the vertex's attributes.
    let copies: Vec<[f64; 3]> = source.iter().map(|&v| mesh.positions[v]).collect();
    mesh.positions.extend(copies);
    if let Some(n) = mesh.normals.as_mut() {
        let copies: Vec<[f64; 3]> = source.iter().map(|&v| n[v]).collect();
        n.extend(copies);
    }
    if let Some(c) = mesh.colors.as_mut() {
        let copies: Vec<[u8; 3]> = source.iter().map(|&v| c[v]).collect();
        c.extend(copies);
    }
    report
}

/// The fans of faces at every vertex: per corner of a valid face its fan's root corner, per
/// root the corners in its fan, per vertex the roots of its fans.
struct Fans {
    corners_of_valid: Vec<(u32, u32)>,
    fan_size: Vec<u32>,
    roots_of: Vec<Vec<u32>>,
}

/// Per vertex whether its faces form more than one fan (a bowtie), for `faces` over `nv`
/// vertices. Cost `O(#H · α)`.
pub(crate) fn bowtie_vertices(faces: &Polygons, nv: usize) -> Vec<bool> {
    fans(faces, nv, |_, _, groups| groups)
        .roots_of
        .iter()
        .map(|r| r.len() > 1)
        .collect()
}

/// The fans of `faces` (see [`Fans`]): a union-find over corners, two corners at a vertex
/// joined when their faces share an edge at it (an edge as grouped by `regroup`).
fn fans(
    faces: &Polygons,
    nv: usize,
    regroup: impl FnOnce(&Polygons, &[u32], EdgeGroups) -> EdgeGroups,
) -> Fans {
    let idx = faces.indices();
    let valid: Vec<bool> = faces
        .iter()
        .map(|f| {
            f.len() >= 3
                && f.iter().all(|&v| (v as usize) < nv)
                && (0..f.len()).all(|i| !f[i + 1..].contains(&f[i]))
        })
        .collect();
    let next = corner_next(faces);
    let groups = regroup(faces, &next, group_edges(faces, &next, nv, |f| valid[f]));
    let mut fans = corner_fans(faces, &groups, &next);
    // Corners of valid faces per fan root, and the fans of each vertex.
    let mut fan_size = vec![0u32; idx.len()];
    let mut corners_of_valid = Vec::with_capacity(idx.len());
    for (f, w) in faces.offsets().windows(2).enumerate() {
        if valid[f] {
            for c in w[0]..w[1] {
                let root = fans.find(c);
                fan_size[root as usize] += 1;
                corners_of_valid.push((c, root));
            }
        }
    }
    let mut roots_of: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for &(c, root) in &corners_of_valid {
        if c == root {
            roots_of[idx[c as usize] as usize].push(root);
        }
    }
    Fans {
        corners_of_valid,
        fan_size,
        roots_of,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::diagnose_mesh;

    /// Two triangles meeting only at vertex 0, and a quad strip sharing an edge with one.
    fn bowtie() -> PolyMesh {
        let p = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [-1.0, -1.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
        ];
        let mut faces = Polygons::new();
        for f in [&[0, 1, 2][..], &[0, 3, 4], &[1, 5, 6, 2]] {
            faces.push(f);
        }
        PolyMesh::new(p, faces)
    }

    #[test]
    fn a_bowtie_vertex_gets_one_copy_per_fan() {
        let m = bowtie();
        assert_eq!(diagnose_mesh(&m).non_manifold_vertices, 1);
        let mut out = m.clone();
        let r = split_bowties(&mut out);
        assert_eq!(
            r,
            BowtieReport {
                vertices_split: 1,
                vertices_added: 1,
                examples: vec![0],
            }
        );
        assert_eq!(out.num_vertices(), 8);
        assert_eq!(out.positions[7], m.positions[0]);
        let d = diagnose_mesh(&out);
        assert_eq!(d.non_manifold_vertices, 0);
        assert!(d.is_manifold, "{d:?}");
        // Each fan has one corner at vertex 0: the tie goes to the lower corner, so the first
        // triangle keeps id 0.
        let f: Vec<Vec<u32>> = out.faces.iter().map(<[u32]>::to_vec).collect();
        assert_eq!(f, vec![vec![0, 1, 2], vec![7, 3, 4], vec![1, 5, 6, 2]]);
    }

    #[test]
    fn a_manifold_mesh_is_returned_unchanged() {
        let m = crate::shapes::torus_mesh(1.0, 0.3, 12, 8, true);
        let mut out = m.clone();
        let r = split_bowties(&mut out);
        assert_eq!(r, BowtieReport::default());
        assert_eq!(out, m);
    }
}
