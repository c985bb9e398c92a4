//! Ground truth for captured sequences whose frames share one connectivity (the same vertices
//! and faces in every frame, as deformation-transfer poses or a rigged animation's export):
//! vertex `i` of every frame is the same material point, and a point of frame 0's surface
//! is carried into frame `t` by its barycentric coordinates in its triangle. With frame 0 as
//! the material (rest) shape this is a [`MaterialMotion`], so [`super::drift`] measures a
//! tracker on real sequences as on the generated ones.

use crate::bvh::TriangleBvh;
use crate::polygons::PolyMesh;

use super::motion::{Frame, MaterialMotion};

/// Frames of one connectivity (see the module docs).
#[derive(Clone, Debug)]
pub struct SameConnectivity {
    first: TriangleBvh,
    frames: Vec<Vec<[f64; 3]>>,
}

/// Why frames cannot serve as ground truth: the frame and what differs.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("frame {frame}: {reason}")]
pub struct NotCorresponded {
    /// The frame (0 the first).
    pub frame: usize,
    /// What differs from frame 0.
    pub reason: String,
}

impl SameConnectivity {
    /// Checks that every mesh has frame 0's vertex count and faces, and keeps their positions.
    /// Faces are fan-triangulated. Cost: O(#frames · #V) plus a BVH over frame 0.
    pub fn new(meshes: &[PolyMesh]) -> Result<Self, NotCorresponded> {
        let Some(first) = meshes.first() else {
            return Err(NotCorresponded {
                frame: 0,
                reason: "no frames".into(),
            });
        };
        if first.faces.is_empty() {
            return Err(NotCorresponded {
                frame: 0,
                reason: "has no faces".into(),
            });
        }
        for (t, m) in meshes.iter().enumerate().skip(1) {
            if m.positions.len() != first.positions.len() {
                return Err(NotCorresponded {
                    frame: t,
                    reason: format!(
                        "{} vertices, frame 0 has {}",
                        m.positions.len(),
                        first.positions.len()
                    ),
                });
            }
            if m.faces != first.faces {
                return Err(NotCorresponded {
                    frame: t,
                    reason: "its faces differ from frame 0's".into(),
                });
            }
        }
        Ok(Self {
            first: TriangleBvh::new(first.positions.clone(), first.faces.triangulate_fan()),
            frames: meshes.iter().map(|m| m.positions.clone()).collect(),
        })
    }

    /// Frame 0 as a [`Frame`] whose material is its own positions (for a
    /// [`super::MaterialLookup`]).
    pub fn first_frame(&self) -> Frame {
        let mesh = PolyMesh::new(
            self.frames[0].clone(),
            crate::polygons::Polygons::from_triangles(self.first.triangles()),
        );
        Frame {
            material: mesh.positions.clone(),
            mesh,
        }
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Whether there are no frames (never: `new` asks for one).
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }
}

impl MaterialMotion for SameConnectivity {
    /// Each material point (a point on or near frame 0's surface) is located on frame 0's
    /// triangles and carried into frame `index` by its barycentric coordinates.
    fn deform_all(&self, index: usize, material: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let frame = &self.frames[index.min(self.frames.len() - 1)];
        material
            .iter()
            .map(|&m| {
                let hit = self.first.closest(m).expect("frame 0 has triangles");
                let tri = self.first.triangles()[hit.triangle as usize];
                let b = hit.barycentric;
                let [p, q, r] = tri.map(|v| frame[v as usize]);
                std::array::from_fn(|k| b[0] * p[k] + b[1] * q[k] + b[2] * r[k])
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::polygons::Polygons;

    #[test]
    fn points_follow_their_triangle() {
        let tri = Polygons::from_triangles(&[[0, 1, 2]]);
        let a = PolyMesh::new(
            vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            tri.clone(),
        );
        let b = PolyMesh::new(vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 0.0, 3.0]], tri);
        let s = SameConnectivity::new(&[a, b]).unwrap();
        let moved = s.deform_all(1, &[[0.25, 0.5, 0.0]]);
        assert!(crate::vec3::dist2(moved[0], [0.5, 0.0, 1.5]) < 1e-24);
        let c = PolyMesh::new(vec![[0.0; 3]; 2], Polygons::new());
        let err = SameConnectivity::new(&[s.first_frame().mesh, c]).unwrap_err();
        assert_eq!(err.frame, 1);
    }
}
