//! What a cage is made of, counted the same way for ours, an artist's and a peer's: control
//! points, faces, the quad share, irregular vertices, tags, genus and boundary loops.

use serde::{Deserialize, Serialize};
use subfit::mesh::{HalfEdgeMesh, PolyMesh, Tags};

/// Counts of one cage.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CageStats {
    /// Control points (vertices used by a face).
    pub control_points: usize,
    /// Faces.
    pub faces: usize,
    /// Quads / faces.
    pub quad_fraction: f64,
    /// Irregular vertices: interior vertices whose valence is not the regular one (4 in a
    /// quad-dominant cage — quads at least half the faces —, 6 otherwise) and boundary vertices
    /// whose valence is neither the regular boundary one (3, resp. 4) nor 2 (a corner).
    pub irregular_vertices: usize,
    /// Edges tagged as creases (any sharpness > 0).
    pub crease_edges: usize,
    /// Vertices tagged as corners.
    pub corners: usize,
    /// Genus and boundary loops, when the cage is a manifold surface.
    pub topology: Option<Topology>,
}

/// Genus and boundary loops.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Topology {
    /// Genus.
    pub genus: u32,
    /// Boundary loops.
    pub boundary_loops: usize,
}

/// Genus and boundary loops of `mesh` when it is a manifold surface.
pub fn topology(mesh: &PolyMesh) -> Option<Topology> {
    let h = HalfEdgeMesh::from_mesh(mesh).ok()?;
    Some(Topology {
        genus: h.genus(),
        boundary_loops: h.boundary_loops().len(),
    })
}

/// Counts of `cage` with `tags`. Cost: O(#faces).
pub fn cage_stats(cage: &PolyMesh, tags: &Tags) -> CageStats {
    let faces = cage.faces.len();
    let quads = cage.faces.iter().filter(|f| f.len() == 4).count();
    let n = cage.num_vertices();
    let mut used = vec![false; n];
    // Valence = distinct neighbours over edges; boundary = an edge with one face.
    let mut edges: Vec<(u32, u32)> = Vec::new();
    for f in cage.faces.iter() {
        for i in 0..f.len() {
            let (a, b) = (f[i], f[(i + 1) % f.len()]);
            if (a as usize) < n && (b as usize) < n {
                used[a as usize] = true;
                edges.push((a.min(b), a.max(b)));
            }
        }
    }
    edges.sort_unstable();
    let mut valence = vec![0usize; n];
    let mut boundary = vec![false; n];
    let mut i = 0;
    while i < edges.len() {
        let mut j = i;
        while j < edges.len() && edges[j] == edges[i] {
            j += 1;
        }
        let (a, b) = edges[i];
        valence[a as usize] += 1;
        valence[b as usize] += 1;
        if j - i == 1 {
            boundary[a as usize] = true;
            boundary[b as usize] = true;
        }
        i = j;
    }
    let quad_dominant = faces > 0 && 2 * quads >= faces;
    let (inner, rim) = if quad_dominant { (4, 3) } else { (6, 4) };
    let irregular_vertices = (0..n)
        .filter(|&v| used[v])
        .filter(|&v| {
            if boundary[v] {
                valence[v] != rim && valence[v] != 2
            } else {
                valence[v] != inner
            }
        })
        .count();
    CageStats {
        control_points: used.iter().filter(|&&u| u).count(),
        faces,
        quad_fraction: if faces == 0 {
            0.0
        } else {
            quads as f64 / faces as f64
        },
        irregular_vertices,
        crease_edges: tags.creases().iter().filter(|(_, s)| *s > 0.0).count(),
        corners: tags.corners().iter().filter(|(_, s)| *s > 0.0).count(),
        topology: topology(cage),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfit::mesh::shapes;

    #[test]
    fn a_cube_has_eight_irregular_vertices_of_valence_three() {
        let cube = shapes::cube_mesh(1.0);
        let s = cage_stats(&cube, &Tags::new());
        assert_eq!((s.control_points, s.faces, s.quad_fraction), (8, 6, 1.0));
        assert_eq!(s.irregular_vertices, 8);
        assert_eq!(
            s.topology,
            Some(Topology {
                genus: 0,
                boundary_loops: 0
            })
        );
    }

    #[test]
    fn a_regular_quad_grid_has_none_and_counts_tags() {
        // A 4 × 4 grid of quads: interior valence 4, rim valence 3, four corners of valence 2.
        let n = 5u32;
        let pos = (0..n * n)
            .map(|i| [(i % n) as f64, (i / n) as f64, 0.0])
            .collect();
        let quads: Vec<[u32; 4]> = (0..n - 1)
            .flat_map(|j| {
                (0..n - 1).map(move |i| {
                    [
                        j * n + i,
                        j * n + i + 1,
                        (j + 1) * n + i + 1,
                        (j + 1) * n + i,
                    ]
                })
            })
            .collect();
        let g = PolyMesh::new(pos, subfit::mesh::Polygons::from_quads(&quads));
        let mut tags = Tags::new();
        tags.set_crease(0, 1, 10.0);
        tags.set_corner(0, 10.0);
        let s = cage_stats(&g, &tags);
        assert_eq!(s.irregular_vertices, 0);
        assert_eq!((s.crease_edges, s.corners), (1, 1));
        assert_eq!(s.topology.map(|t| t.boundary_loops), Some(1));
    }
}
