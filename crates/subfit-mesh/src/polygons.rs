//! Polygon lists in compressed-row form, and the plain mesh container passed between crates.
//!
//! A [`Polygons`] list stores `F` faces of any sizes as two flat arrays: `offsets` (`F + 1`
//! entries, starting at 0) and `indices` (vertex ids of all faces, concatenated, each face in its
//! winding order). It knows nothing of positions. [`PolyMesh`] bundles a polygon list with
//! per-vertex positions and optional per-vertex normals and colours; a point cloud is a
//! `PolyMesh` without faces.

use crate::ids::{FaceId, VertexId};

/// Faces of any size as flat `u32` arrays (compressed rows).
///
/// Invariants (checked by [`Polygons::push`], not by field access, which is private):
/// `offsets[0] == 0`, offsets are non-decreasing, `offsets.last() == indices.len()`.
/// Faces with fewer than three vertices can be stored (readers report them as degenerate);
/// vertex ids are not checked against a vertex count here.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Polygons {
    offsets: Vec<u32>,
    indices: Vec<u32>,
}

impl Default for Polygons {
    fn default() -> Self {
        Self::new()
    }
}

impl Polygons {
    /// An empty list.
    pub fn new() -> Self {
        Self {
            offsets: vec![0],
            indices: Vec::new(),
        }
    }

    /// An empty list with room for `faces` faces holding `indices` vertex references in total.
    pub fn with_capacity(faces: usize, indices: usize) -> Self {
        let mut offsets = Vec::with_capacity(faces + 1);
        offsets.push(0);
        Self {
            offsets,
            indices: Vec::with_capacity(indices),
        }
    }

    /// Builds a list from triangles (`#F by 3`).
    pub fn from_triangles(tris: &[[u32; 3]]) -> Self {
        Self::from_fixed(tris)
    }

    /// Builds a list from quads (`#F by 4`).
    pub fn from_quads(quads: &[[u32; 4]]) -> Self {
        Self::from_fixed(quads)
    }

    fn from_fixed<const N: usize>(faces: &[[u32; N]]) -> Self {
        let mut p = Self::with_capacity(faces.len(), faces.len() * N);
        for f in faces {
            p.push(f);
        }
        p
    }

    /// Builds a list from raw compressed rows.
    ///
    /// Returns `None` when the invariants above do not hold.
    pub fn from_raw(offsets: Vec<u32>, indices: Vec<u32>) -> Option<Self> {
        if offsets.first() != Some(&0)
            || offsets.windows(2).any(|w| w[0] > w[1])
            || *offsets.last()? as usize != indices.len()
        {
            return None;
        }
        Some(Self { offsets, indices })
    }

    /// Appends one face given by its vertex ids in winding order.
    ///
    /// # Panics
    /// If the total index count would exceed `u32::MAX` (a broken invariant).
    #[track_caller]
    pub fn push(&mut self, face: &[u32]) {
        self.indices.extend_from_slice(face);
        let end = u32::try_from(self.indices.len()).expect("more than u32::MAX face indices");
        self.offsets.push(end);
    }

    /// Number of faces.
    #[inline]
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Whether there are no faces.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Vertex ids of face `f`, in winding order.
    ///
    /// # Panics
    /// If `f` is out of range.
    #[inline]
    #[track_caller]
    pub fn face(&self, f: FaceId) -> &[u32] {
        let (a, b) = (self.offsets[f.idx()], self.offsets[f.idx() + 1]);
        &self.indices[a as usize..b as usize]
    }

    /// Number of vertices of face `f`.
    #[inline]
    pub fn face_len(&self, f: FaceId) -> usize {
        (self.offsets[f.idx() + 1] - self.offsets[f.idx()]) as usize
    }

    /// Iterates over faces as slices of vertex ids.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = &[u32]> + '_ {
        self.offsets
            .windows(2)
            .map(move |w| &self.indices[w[0] as usize..w[1] as usize])
    }

    /// The offsets array (`#F + 1` entries).
    #[inline]
    pub fn offsets(&self) -> &[u32] {
        &self.offsets
    }

    /// All vertex ids, face after face.
    #[inline]
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }

    /// Mutable access to the vertex ids (the face structure stays fixed).
    #[inline]
    pub fn indices_mut(&mut self) -> &mut [u32] {
        &mut self.indices
    }

    /// Whether every face is a triangle.
    pub fn is_triangles(&self) -> bool {
        self.offsets.windows(2).all(|w| w[1] - w[0] == 3)
    }

    /// Whether every face is a quad.
    pub fn is_quads(&self) -> bool {
        self.offsets.windows(2).all(|w| w[1] - w[0] == 4)
    }

    /// Largest vertex id referenced plus one (0 when there are no indices).
    pub fn min_vertex_count(&self) -> usize {
        self.indices.iter().max().map_or(0, |&m| m as usize + 1)
    }

    /// Histogram of face sizes: `(size, count)` pairs sorted by size.
    pub fn size_histogram(&self) -> Vec<(usize, usize)> {
        let mut map = std::collections::BTreeMap::new();
        for w in self.offsets.windows(2) {
            *map.entry((w[1] - w[0]) as usize).or_insert(0usize) += 1;
        }
        map.into_iter().collect()
    }

    /// The triangles of a fan triangulation of every face (`(n - 2)` per `n`-gon; faces with
    /// fewer than three vertices give none).
    pub fn triangulate_fan(&self) -> Vec<[u32; 3]> {
        let mut out = Vec::with_capacity(self.indices.len().saturating_sub(2 * self.len()));
        for f in self.iter() {
            for i in 1..f.len().saturating_sub(1) {
                out.push([f[0], f[i], f[i + 1]]);
            }
        }
        out
    }

    /// The vertex ids of face `f` as typed ids.
    pub fn face_vertices(&self, f: FaceId) -> impl ExactSizeIterator<Item = VertexId> + '_ {
        self.face(f).iter().map(|&v| VertexId(v))
    }
}

/// A polygon mesh or point cloud as passed between crates: positions plus optional attributes and
/// a face list.
///
/// `positions` is `#V by 3` (f64, in the units of the source). `normals`, when present, has `#V`
/// rows (not necessarily unit length as read from a file); `colors`, when present, has `#V` rows
/// of 8-bit RGB. `faces` may be empty (a point cloud). Per-edge creases and per-vertex corners live
/// in [`crate::Tags`], beside the mesh, since only control meshes carry them.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PolyMesh {
    /// Vertex positions, `#V by 3`.
    pub positions: Vec<[f64; 3]>,
    /// Optional per-vertex normals, `#V by 3`.
    pub normals: Option<Vec<[f64; 3]>>,
    /// Optional per-vertex colours, `#V by 3`, 8-bit RGB.
    pub colors: Option<Vec<[u8; 3]>>,
    /// The faces; empty for a point cloud.
    pub faces: Polygons,
}

impl PolyMesh {
    /// A mesh from positions and faces, without attributes.
    pub fn new(positions: Vec<[f64; 3]>, faces: Polygons) -> Self {
        Self {
            positions,
            normals: None,
            colors: None,
            faces,
        }
    }

    /// A point cloud (no faces), with optional normals.
    pub fn point_cloud(positions: Vec<[f64; 3]>, normals: Option<Vec<[f64; 3]>>) -> Self {
        Self {
            positions,
            normals,
            colors: None,
            faces: Polygons::new(),
        }
    }

    /// Number of vertices (points).
    #[inline]
    pub fn num_vertices(&self) -> usize {
        self.positions.len()
    }

    /// Number of faces.
    #[inline]
    pub fn num_faces(&self) -> usize {
        self.faces.len()
    }

    /// Whether this is a point cloud (no faces).
    #[inline]
    pub fn is_point_cloud(&self) -> bool {
        self.faces.is_empty()
    }

    /// Axis-aligned bounding box `(min, max)` of the positions, or `None` when there are none.
    pub fn bounding_box(&self) -> Option<([f64; 3], [f64; 3])> {
        bounding_box(&self.positions)
    }

    /// Removes the vertices no face uses (with their normals and colours) and renumbers the
    /// faces; returns the removed vertices' former indices, ascending. A point cloud (no faces)
    /// is left alone. Cost: O(#V + #corners).
    pub fn remove_unreferenced(&mut self) -> Vec<u32> {
        if self.faces.is_empty() {
            return Vec::new();
        }
        let mut used = vec![false; self.positions.len()];
        for &v in self.faces.indices() {
            used[v as usize] = true;
        }
        let removed: Vec<u32> = (0..used.len() as u32)
            .filter(|&v| !used[v as usize])
            .collect();
        if removed.is_empty() {
            return removed;
        }
        let mut map = vec![u32::MAX; used.len()];
        let mut next = 0u32;
        for (v, &u) in used.iter().enumerate() {
            if u {
                map[v] = next;
                next += 1;
            }
        }
        fn keep<T: Copy>(values: &[T], used: &[bool]) -> Vec<T> {
            values
                .iter()
                .zip(used)
                .filter(|(_, &u)| u)
                .map(|(&x, _)| x)
                .collect()
        }
        self.positions = keep(&self.positions, &used);
        self.normals = self.normals.as_deref().map(|n| keep(n, &used));
        self.colors = self.colors.as_deref().map(|c| keep(c, &used));
        for v in self.faces.indices_mut() {
            *v = map[*v as usize];
        }
        removed
    }
}

/// Axis-aligned bounding box `(min, max)` of a point set, or `None` when it is empty.
/// Cost: O(#points).
pub fn bounding_box(points: &[[f64; 3]]) -> Option<([f64; 3], [f64; 3])> {
    let first = *points.first()?;
    let mut lo = first;
    let mut hi = first;
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    Some((lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compressed_rows_round_trip() {
        let mut p = Polygons::new();
        p.push(&[0, 1, 2]);
        p.push(&[0, 2, 3, 4]);
        assert_eq!(p.len(), 2);
        assert_eq!(p.face(FaceId(1)), &[0, 2, 3, 4]);
        assert_eq!(p.size_histogram(), vec![(3, 1), (4, 1)]);
        assert_eq!(p.triangulate_fan().len(), 3);
        assert_eq!(p.min_vertex_count(), 5);
        let q = Polygons::from_raw(p.offsets().to_vec(), p.indices().to_vec()).unwrap();
        assert_eq!(p, q);
        assert!(Polygons::from_raw(vec![0, 3, 2], vec![0, 1, 2]).is_none());
        assert!(Polygons::from_raw(vec![1], vec![]).is_none());
    }

    #[test]
    fn unreferenced_vertices_are_removed_with_their_attributes() {
        let mut m = PolyMesh::new(
            vec![
                [0.0; 3],
                [9.0; 3],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [7.0; 3],
            ],
            Polygons::from_triangles(&[[0, 2, 3]]),
        );
        m.colors = Some(vec![[0; 3], [1; 3], [2; 3], [3; 3], [4; 3]]);
        assert_eq!(m.remove_unreferenced(), vec![1, 4]);
        assert_eq!(
            m.positions,
            vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        );
        assert_eq!(m.colors, Some(vec![[0; 3], [2; 3], [3; 3]]));
        assert_eq!(m.faces.face(FaceId(0)), &[0, 1, 2]);
        assert!(m.remove_unreferenced().is_empty());
        let mut cloud = PolyMesh::point_cloud(vec![[0.0; 3]; 3], None);
        assert!(cloud.remove_unreferenced().is_empty());
        assert_eq!(cloud.num_vertices(), 3);
    }
}
