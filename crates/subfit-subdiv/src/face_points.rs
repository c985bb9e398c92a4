//! Which parent faces get a face point in one refinement step ([`FacePoints`]): none (Loop),
//! every face (Catmull-Clark) or the non-triangles (quad/triangle, Stam & Loop 2003). Shared by
//! the refinement matrix (module `refine`) and the refined adjacency (module `child`), which
//! both number face points `V + E + k` as the child vertex order of [`crate::refine`] states.

use crate::scheme::Scheme;
use crate::topology::Topology;

/// Which parent faces have a face point, and its index among the face points.
#[derive(Clone, Debug)]
pub(crate) enum FacePoints {
    /// Loop: none.
    None,
    /// Catmull-Clark: every face, face point `f` of face `f`.
    All(usize),
    /// Quad/triangle: the non-triangles; `index[f]` (`u32::MAX` for a triangle) and `face[k]`.
    Some {
        /// Face point index of each face.
        index: Vec<u32>,
        /// Face of each face point.
        face: Vec<u32>,
    },
}

impl FacePoints {
    /// The face points of `topo` under `scheme`. Cost O(#F).
    pub(crate) fn new(topo: &Topology, scheme: Scheme) -> Self {
        match scheme {
            Scheme::Loop => FacePoints::None,
            Scheme::CatmullClark => FacePoints::All(topo.num_faces()),
            Scheme::QuadTriangle => {
                let mut index = vec![u32::MAX; topo.num_faces()];
                let mut face = Vec::new();
                for (f, slot) in index.iter_mut().enumerate() {
                    if topo.face(f).len() != 3 {
                        *slot = face.len() as u32;
                        face.push(f as u32);
                    }
                }
                FacePoints::Some { index, face }
            }
        }
    }

    /// Number of face points.
    pub(crate) fn len(&self) -> usize {
        match self {
            FacePoints::None => 0,
            FacePoints::All(n) => *n,
            FacePoints::Some { face, .. } => face.len(),
        }
    }

    /// The face point index of face `f` (which must have one).
    #[inline]
    pub(crate) fn index(&self, f: usize) -> u32 {
        match self {
            FacePoints::Some { index, .. } => index[f],
            _ => f as u32,
        }
    }

    /// The face of face point `k`.
    #[inline]
    pub(crate) fn face(&self, k: usize) -> usize {
        match self {
            FacePoints::Some { face, .. } => face[k] as usize,
            _ => k,
        }
    }
}
