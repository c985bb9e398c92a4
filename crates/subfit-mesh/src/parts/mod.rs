//! Generated CAD parts with their exact surfaces known: the test cases of CAD tessellations.
//!
//! Each [`Part`] is a solid extruded along `z` from a planar profile (a rectangle, a polygon, a
//! disc, an annulus, a rounded rectangle, a plate drilled by a grid of holes), tessellated as a
//! CAD exporter does ([`Part::tessellate`]): every vertex on the true surface, circles and arcs
//! cut into as few segments as keep each chord's sag within the chord height, planar faces in as
//! few triangles as their outline allows (fans and strips of long thin triangles), the walls in
//! strips. [`Part::distance`] is the exact distance of a point to the part's surface (the
//! extrusion of the profile's exact signed distance: `min(max(d₂, d_z), 0) + ‖max((d₂, d_z), 0)‖`,
//! Quílez's formula for extrusions), so a fit can be measured against the part itself rather
//! than against its facets.

mod profile;
mod tessellate;

pub use profile::Profile;

use crate::PolyMesh;

/// A solid extruded along `z` from `z = 0` to `z = height`.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// The cross-section.
    pub profile: Profile,
    /// Height of the extrusion.
    pub height: f64,
}

impl Part {
    /// A box `[0, x] × [0, y] × [0, z]`.
    pub fn block(x: f64, y: f64, z: f64) -> Self {
        Self {
            profile: Profile::Polygon(vec![[0.0, 0.0], [x, 0.0], [x, y], [0.0, y]]),
            height: z,
        }
    }

    /// A prism over a counter-clockwise polygon that is star-shaped from its first vertex
    /// (every other vertex seen from it: the caps are fans from it), e.g. an L profile listed
    /// from its inner corner.
    pub fn prism(polygon: Vec<[f64; 2]>, height: f64) -> Self {
        Self {
            profile: Profile::Polygon(polygon),
            height,
        }
    }

    /// An L-shaped angle bracket: the profile (0,0) (2,0) (2,1) (1,1) (1,2) (0,2) scaled by
    /// `size`, height `height`.
    pub fn l_bracket(size: f64, height: f64) -> Self {
        let p = [
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
        ];
        Self::prism(p.iter().map(|q| q.map(|c| c * size)).collect(), height)
    }

    /// A solid cylinder of radius `radius` around the `z` axis.
    pub fn cylinder(radius: f64, height: f64) -> Self {
        Self {
            profile: Profile::Disc { radius },
            height,
        }
    }

    /// A tube: radii `outer` > `inner` around the `z` axis (genus 1).
    pub fn tube(outer: f64, inner: f64, height: f64) -> Self {
        Self {
            profile: Profile::Annulus { outer, inner },
            height,
        }
    }

    /// A block `[0, x] × [0, y] × [0, height]` whose four vertical edges are filleted with
    /// radius `radius`.
    pub fn filleted_block(x: f64, y: f64, height: f64, radius: f64) -> Self {
        Self {
            profile: Profile::RoundedRectangle {
                size: [x, y],
                radius,
            },
            height,
        }
    }

    /// A plate of `cells[0] × cells[1]` square cells of side `cell`, each drilled through at
    /// its centre by a hole of radius `hole_radius` (< `cell / 2`), thickness `thickness`
    /// (genus `cells[0] · cells[1]`).
    pub fn drilled_plate(cells: [usize; 2], cell: f64, hole_radius: f64, thickness: f64) -> Self {
        Self {
            profile: Profile::DrilledPlate {
                cells,
                cell,
                hole_radius,
            },
            height: thickness,
        }
    }

    /// The exact distance of `p` to the part's surface.
    pub fn distance(&self, p: [f64; 3]) -> f64 {
        let d2 = self.profile.signed_distance([p[0], p[1]]);
        let dz = (-p[2]).max(p[2] - self.height);
        let outside = d2.max(0.0).hypot(dz.max(0.0));
        (d2.max(dz).min(0.0) + outside).abs()
    }

    /// The diagonal of the part's bounding box.
    pub fn diagonal(&self) -> f64 {
        let (lo, hi) = self.profile.bounds();
        (hi[0] - lo[0]).hypot(hi[1] - lo[1]).hypot(self.height)
    }

    /// The part tessellated as a CAD exporter does (see the module docs): curves cut so that
    /// no chord sags more than `chord` (units of the part), planar faces as fans and strips of
    /// long triangles; with `max_edge`, the walls are also cut into rows and the outlines'
    /// straight segments into pieces no longer than it (a finer export of the same part).
    /// Closed, oriented outwards, vertices welded.
    ///
    /// # Panics
    /// If `chord` is not positive or the part's dimensions are not (see [`Profile`]).
    #[track_caller]
    pub fn tessellate(&self, chord: f64, max_edge: Option<f64>) -> PolyMesh {
        assert!(
            chord > 0.0 && self.height > 0.0,
            "chord and height must be > 0"
        );
        tessellate::extrude(&self.profile, self.height, chord, max_edge)
    }
}

#[cfg(test)]
mod tests;
