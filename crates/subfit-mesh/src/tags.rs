//! Per-edge crease and per-vertex corner tags of a control mesh.
//!
//! Tags are stored independently of any mesh storage, as vertex-id pairs and vertex ids, so they
//! survive conversion between face lists and half-edge views. Sharpness follows OpenSubdiv's
//! vocabulary: `0` is smooth, [`SHARPNESS_INFINITE`] is an infinitely sharp crease (Hoppe et al.
//! 1994 rules); finite values in between are semi-sharp (stored, but subdivision code may treat
//! them as smooth or sharp as it documents).

use std::collections::HashMap;

/// Sharpness of an infinitely sharp crease or corner (OpenSubdiv uses 10).
pub const SHARPNESS_INFINITE: f64 = 10.0;

/// Crease and corner tags.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Tags {
    creases: HashMap<(u32, u32), f64>,
    corners: HashMap<u32, f64>,
}

fn key(a: u32, b: u32) -> (u32, u32) {
    if a < b {
        (a, b)
    } else {
        (b, a)
    }
}

impl Tags {
    /// No tags.
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether there are no crease or corner tags.
    pub fn is_empty(&self) -> bool {
        self.creases.is_empty() && self.corners.is_empty()
    }

    /// Tags the edge between vertices `a` and `b` (either order) with `sharpness`; a sharpness
    /// of 0 removes the tag.
    pub fn set_crease(&mut self, a: u32, b: u32, sharpness: f64) {
        if sharpness > 0.0 {
            self.creases.insert(key(a, b), sharpness);
        } else {
            self.creases.remove(&key(a, b));
        }
    }

    /// Sharpness of the edge `a`–`b` (0 when untagged).
    pub fn crease(&self, a: u32, b: u32) -> f64 {
        self.creases.get(&key(a, b)).copied().unwrap_or(0.0)
    }

    /// Whether edge `a`–`b` is tagged infinitely sharp (sharpness ≥ [`SHARPNESS_INFINITE`]).
    pub fn is_sharp_edge(&self, a: u32, b: u32) -> bool {
        self.crease(a, b) >= SHARPNESS_INFINITE
    }

    /// Tags vertex `v` as a corner with `sharpness`; 0 removes the tag.
    pub fn set_corner(&mut self, v: u32, sharpness: f64) {
        if sharpness > 0.0 {
            self.corners.insert(v, sharpness);
        } else {
            self.corners.remove(&v);
        }
    }

    /// Sharpness of vertex `v` (0 when untagged).
    pub fn corner(&self, v: u32) -> f64 {
        self.corners.get(&v).copied().unwrap_or(0.0)
    }

    /// Whether vertex `v` is tagged as an infinitely sharp corner.
    pub fn is_corner(&self, v: u32) -> bool {
        self.corner(v) >= SHARPNESS_INFINITE
    }

    /// All crease tags as `((a, b), sharpness)` with `a < b`, sorted.
    pub fn creases(&self) -> Vec<((u32, u32), f64)> {
        let mut v: Vec<_> = self.creases.iter().map(|(&k, &s)| (k, s)).collect();
        v.sort_by_key(|x| x.0);
        v
    }

    /// All corner tags as `(vertex, sharpness)`, sorted by vertex.
    pub fn corners(&self) -> Vec<(u32, f64)> {
        let mut v: Vec<_> = self.corners.iter().map(|(&k, &s)| (k, s)).collect();
        v.sort_by_key(|x| x.0);
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tags_are_order_independent() {
        let mut t = Tags::new();
        t.set_crease(5, 2, SHARPNESS_INFINITE);
        assert!(t.is_sharp_edge(2, 5));
        t.set_crease(2, 5, 0.0);
        assert!(t.is_empty());
        t.set_corner(3, SHARPNESS_INFINITE);
        assert!(t.is_corner(3));
        assert_eq!(t.corners(), vec![(3, SHARPNESS_INFINITE)]);
    }
}
