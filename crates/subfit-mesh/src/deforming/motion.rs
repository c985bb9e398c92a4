//! What every generated motion shares ([`super`]): a frame with its material points, the
//! ground-truth motion trait [`super::drift`] measures against, the parameter error, and the
//! seed mixer. Kept apart so the motions' own files import it, not one another.

use crate::polygons::PolyMesh;

/// Parameters rejected by [`super::DeformingSequence::new`]: the field and what is wrong.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("invalid deforming-sequence parameter `{field}`: {reason}")]
pub struct InvalidParams {
    /// The field of [`super::DeformingParams`].
    pub field: &'static str,
    /// What is wrong with it.
    pub reason: &'static str,
}

/// One frame: a closed triangle mesh of the deformed body and the material point of each
/// vertex.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Positions `Φ_t(material)` (`#V by 3`) and triangles (counter-clockwise seen from
    /// outside); a closed genus-0 2-manifold.
    pub mesh: PolyMesh,
    /// Material coordinates of the vertices (`#V by 3`): their positions on the rest shape.
    pub material: Vec<[f64; 3]>,
}

/// A motion of material points whose image in every frame is known: the ground truth that
/// [`super::drift`] measures a tracker against.
pub trait MaterialMotion {
    /// Where the material points (points of the rest shape) are in frame `index`.
    fn deform_all(&self, index: usize, material: &[[f64; 3]]) -> Vec<[f64; 3]>;
}

/// SplitMix64 finaliser (Steele, Lea & Flood, OOPSLA 2014): decorrelates nearby seeds.
pub(super) fn splitmix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
