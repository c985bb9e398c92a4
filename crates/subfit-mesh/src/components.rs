//! Connected components, Euler characteristic and genus.
//!
//! For a compact orientable surface with `C` connected components, `b` boundary loops and total
//! genus `g`, the Euler characteristic is `χ = V − E + F = 2C − 2g − b` (the Euler–Poincaré
//! formula; see e.g. Botsch et al., *Polygon Mesh Processing*, 2010, §1.3.1), so
//! `g = (2C − χ − b) / 2`. The formula only holds for manifold, orientable surfaces: callers
//! check that first (see [`crate::diagnose()`]).

use crate::edges::UnionFind;
use crate::polygons::Polygons;

/// Connected components of the faces of a polygon list, where two faces are connected when they
/// share a vertex (topological connectedness: a bowtie is one component).
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Components {
    /// Number of components (unreferenced vertices form none).
    pub count: usize,
    /// Per face its component (`#F` entries), numbered `0..count` in order of each component's
    /// first face; `u32::MAX` for faces that were excluded (see [`face_components`]).
    pub face_labels: Vec<u32>,
    /// Per vertex its component (`#V` entries); `u32::MAX` for vertices no included face uses.
    pub vertex_labels: Vec<u32>,
}

impl Components {
    /// Number of faces in each component (`count` entries). Cost `O(#F)`.
    pub fn face_counts(&self) -> Vec<usize> {
        let mut out = vec![0; self.count];
        for &l in &self.face_labels {
            if l != u32::MAX {
                out[l as usize] += 1;
            }
        }
        out
    }

    /// Number of vertices in each component (`count` entries). Cost `O(#V)`.
    pub fn vertex_counts(&self) -> Vec<usize> {
        let mut out = vec![0; self.count];
        for &l in &self.vertex_labels {
            if l != u32::MAX {
                out[l as usize] += 1;
            }
        }
        out
    }
}

/// Connected components of `faces` over `num_vertices` vertices (faces sharing a vertex are
/// connected). Vertex ids `>= num_vertices` are ignored; a face with no in-range vertex gets
/// label `u32::MAX`. Cost: `O(#V + #H · α)` with a union-find over vertices.
pub fn face_components(faces: &Polygons, num_vertices: usize) -> Components {
    components_by(num_vertices, faces.len(), |f| {
        faces.face(crate::FaceId(f as u32)).iter().copied()
    })
}

/// [`face_components`] over faces given by a closure (`face(f)` yields the vertex ids of face `f`
/// for `f < num_faces`; an empty iterator excludes the face).
pub(crate) fn components_by<I: Iterator<Item = u32>>(
    num_vertices: usize,
    num_faces: usize,
    face: impl Fn(usize) -> I,
) -> Components {
    let mut uf = UnionFind::new(num_vertices);
    let mut used = vec![false; num_vertices];
    for f in 0..num_faces {
        let mut first = None;
        for v in face(f).filter(|&v| (v as usize) < num_vertices) {
            used[v as usize] = true;
            match first {
                None => first = Some(v),
                Some(a) => {
                    uf.union(a, v);
                }
            }
        }
    }
    let mut root_label = vec![u32::MAX; num_vertices];
    let mut face_labels = vec![u32::MAX; num_faces];
    let mut count = 0u32;
    for (f, label) in face_labels.iter_mut().enumerate() {
        if let Some(v) = face(f).find(|&v| (v as usize) < num_vertices) {
            let r = uf.find(v) as usize;
            if root_label[r] == u32::MAX {
                root_label[r] = count;
                count += 1;
            }
            *label = root_label[r];
        }
    }
    let vertex_labels = (0..num_vertices)
        .map(|v| {
            if used[v] {
                root_label[uf.find(v as u32) as usize]
            } else {
                u32::MAX
            }
        })
        .collect();
    Components {
        count: count as usize,
        face_labels,
        vertex_labels,
    }
}

/// Euler characteristic `χ = V − E + F`. Pass only the vertices used by faces as `V`.
#[inline]
pub fn euler_characteristic(vertices: usize, edges: usize, faces: usize) -> i64 {
    vertices as i64 - edges as i64 + faces as i64
}

/// Total genus `g = (2C − χ − b) / 2` of a manifold orientable surface with `components`
/// connected components, Euler characteristic `chi` and `boundary_loops` boundary loops.
///
/// Returns `None` when `2C − χ − b` is negative or odd, which no such surface produces (the input
/// is then not a manifold orientable surface, or the counts are wrong). Cost `O(1)`.
pub fn genus(chi: i64, components: usize, boundary_loops: usize) -> Option<u32> {
    let twice = 2 * components as i64 - chi - boundary_loops as i64;
    if twice < 0 || twice % 2 != 0 {
        return None;
    }
    u32::try_from(twice / 2).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn genus_formula() {
        assert_eq!(genus(2, 1, 0), Some(0));
        assert_eq!(genus(0, 1, 0), Some(1));
        assert_eq!(genus(-6, 1, 0), Some(4));
        assert_eq!(genus(-9, 1, 11), Some(0));
        assert_eq!(genus(1, 1, 0), None);
        assert_eq!(genus(4, 1, 0), None);
        assert_eq!(genus(4, 2, 0), Some(0));
    }

    #[test]
    fn components_of_two_triangles_and_a_bowtie() {
        let p = Polygons::from_triangles(&[[0, 1, 2], [3, 4, 5], [2, 6, 7]]);
        let c = face_components(&p, 9);
        assert_eq!(c.count, 2);
        assert_eq!(c.face_labels, vec![0, 1, 0]);
        assert_eq!(c.vertex_labels[8], u32::MAX);
        assert_eq!(c.face_counts(), vec![2, 1]);
        assert_eq!(c.vertex_counts(), vec![5, 3]);
    }
}
