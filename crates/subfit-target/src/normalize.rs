//! Uniform normalization into the unit cube (Cheng 2004 §3 step 1: "normalization of the target
//! shape"; DESIGN.md §1): the bounding box's longest side becomes 1 and its minimum corner the
//! origin. The map is `x ↦ (x − min) / scale` with `scale` the longest side, so every length is
//! divided by `scale` and every curvature multiplied by it.

/// The uniform map between original and normalized coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Normalization {
    /// Minimum corner of the original bounding box (original units).
    pub min: [f64; 3],
    /// Longest side of the original bounding box (original units), > 0.
    pub scale: f64,
}

impl Normalization {
    /// The identity map.
    pub const IDENTITY: Self = Self {
        min: [0.0; 3],
        scale: 1.0,
    };

    /// The map for the bounding box `(lo, hi)`. Returns `None` when the box is a single point
    /// (all sides 0) or not finite.
    pub fn from_bounds(lo: [f64; 3], hi: [f64; 3]) -> Option<Self> {
        let scale = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
        (scale > 0.0 && scale.is_finite() && lo.iter().all(|c| c.is_finite()))
            .then_some(Self { min: lo, scale })
    }

    /// Original → normalized coordinates of a point.
    #[inline]
    pub fn to_normalized(&self, p: [f64; 3]) -> [f64; 3] {
        let s = 1.0 / self.scale;
        [
            (p[0] - self.min[0]) * s,
            (p[1] - self.min[1]) * s,
            (p[2] - self.min[2]) * s,
        ]
    }

    /// Normalized → original coordinates of a point.
    #[inline]
    pub fn to_original(&self, p: [f64; 3]) -> [f64; 3] {
        [
            p[0] * self.scale + self.min[0],
            p[1] * self.scale + self.min[1],
            p[2] * self.scale + self.min[2],
        ]
    }

    /// Original → normalized length (distance, radius). Curvatures transform by the inverse.
    #[inline]
    pub fn length_to_normalized(&self, l: f64) -> f64 {
        l / self.scale
    }

    /// Normalized → original length.
    #[inline]
    pub fn length_to_original(&self, l: f64) -> f64 {
        l * self.scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let n = Normalization::from_bounds([-1.0, 2.0, 3.0], [1.0, 3.0, 7.0]).unwrap();
        assert_eq!(n.scale, 4.0);
        let p = [0.5, 2.5, 5.0];
        let q = n.to_normalized(p);
        assert_eq!(q, [0.375, 0.125, 0.5]);
        assert_eq!(n.to_original(q), p);
        assert_eq!(n.length_to_original(n.length_to_normalized(3.0)), 3.0);
        assert!(Normalization::from_bounds([1.0; 3], [1.0; 3]).is_none());
    }
}
