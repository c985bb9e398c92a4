//! From a face of the `L`-times refined cage back to the exact evaluator's parameters: which
//! patch it lies in and the `(u, v)` of its corners (`subfit::subdiv::eval`'s
//! parametrisation), read off the documented child order of [`subfit::subdiv::refine`]:
//! * Loop triangle `(a, b, c)` → `(a, ab, ca)`, `(b, bc, ab)`, `(c, ca, bc)`, `(ab, bc, ca)`;
//! * quad `(v_0 … v_3)` → for each `i`, `(v_i, e_{i,i+1}, F, e_{i−1,i})`;
//! * a Catmull-Clark `n`-gon (`n ≠ 4`; quad/triangle `n ≥ 5`) → `n` such quads, child `k` being
//!   the evaluator's sub-patch `k` (unit square, `v_k` at `(0, 0)`, `F` at `(1, 1)`).
//!
//! Children of a face are consecutive in parent order; after the first level every face has 4.
//! Edge and face points sit at parameter midpoints and centres, so the maps are affine.

use subfit::mesh::{FaceId, Polygons};
use subfit::subdiv::{Scheme, SurfaceParam};

type Uv = (f64, f64);

fn mid(a: Uv, b: Uv) -> Uv {
    (0.5 * (a.0 + b.0), 0.5 * (a.1 + b.1))
}

const UNIT_SQUARE: [Uv; 4] = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];

/// The refinement chain's bookkeeping: enough to walk from a level-`L` face to its patch.
#[derive(Clone, Debug)]
pub(super) struct Levels {
    scheme: Scheme,
    level: usize,
    /// First level-1 child of each control face (`#F + 1` entries).
    first_child: Vec<u32>,
    /// Corner count of each control face.
    sizes: Vec<u32>,
}

impl Levels {
    /// The chain of `level ≥ 1` refinements of `faces` under `scheme`.
    pub fn new(faces: &Polygons, scheme: Scheme, level: usize) -> Self {
        let sizes: Vec<u32> = (0..faces.len())
            .map(|f| faces.face_len(FaceId(f as u32)) as u32)
            .collect();
        let mut first_child = Vec::with_capacity(sizes.len() + 1);
        first_child.push(0u32);
        for &n in &sizes {
            // Triangles (except under Catmull-Clark) and quads split 1 → 4; n-gons into n quads.
            let kids = if n == 4 || (n == 3 && scheme != Scheme::CatmullClark) {
                4
            } else {
                n
            };
            first_child.push(first_child.last().unwrap() + kids);
        }
        Self {
            scheme,
            level,
            first_child,
            sizes,
        }
    }

    /// The patch `(face, sub)` of level-`L` face `f` and the parameters of its corners (3 for a
    /// triangle patch, 4 for a quad; the rest unused).
    pub fn corners(&self, f: u32) -> (u32, u32, [Uv; 4]) {
        let mut path = Vec::with_capacity(self.level);
        let mut g = f;
        for _ in 1..self.level {
            path.push(g % 4);
            g /= 4;
        }
        let f0 = self.first_child.partition_point(|&s| s <= g) - 1;
        let k1 = g - self.first_child[f0];
        let n0 = self.sizes[f0];
        let split = self.scheme.splits_into_quads(n0 as usize) && n0 != 4;
        let (sub, mut corners, triangle) = if split {
            (k1, UNIT_SQUARE, false)
        } else if n0 == 3 {
            let c = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.0, 0.0)];
            (0, child(c, true, k1), true)
        } else {
            (0, child(UNIT_SQUARE, false, k1), false)
        };
        for &k in path.iter().rev() {
            corners = child(corners, triangle, k);
        }
        (f0 as u32, sub, corners)
    }

    /// The parameter of the point with barycentric weights `bary` on the tessellation triangle
    /// whose `face_of` entry is `h` (see `Tessellation::face_of`).
    pub fn param(&self, h: u32, bary: [f64; 3]) -> SurfaceParam {
        let (face, sub, c) = self.corners(h / 2);
        let tri = if h % 2 == 0 {
            [c[0], c[1], c[2]]
        } else {
            [c[0], c[2], c[3]]
        };
        SurfaceParam {
            face,
            sub,
            u: (0..3).map(|i| bary[i] * tri[i].0).sum(),
            v: (0..3).map(|i| bary[i] * tri[i].1).sum(),
        }
    }
}

/// The corner parameters of child `k` of a face with corner parameters `c` (a triangle's in
/// `c[0..3]`).
fn child(c: [Uv; 4], triangle: bool, k: u32) -> [Uv; 4] {
    if triangle {
        let (m01, m12, m20) = (mid(c[0], c[1]), mid(c[1], c[2]), mid(c[2], c[0]));
        let t = match k {
            0 => [c[0], m01, m20],
            1 => [c[1], m12, m01],
            2 => [c[2], m20, m12],
            _ => [m01, m12, m20],
        };
        [t[0], t[1], t[2], t[0]]
    } else {
        let k = k as usize;
        let centre = mid(mid(c[0], c[2]), mid(c[1], c[3]));
        [
            c[k],
            mid(c[k], c[(k + 1) % 4]),
            centre,
            mid(c[(k + 3) % 4], c[k]),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn children_tile_their_parent() {
        // Each child map shrinks the parameter area by 4, and the children's centroids are
        // where the 1→4 split puts them.
        let tri = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.0, 0.0)];
        assert_eq!(
            child(tri, true, 3)[..3],
            [(0.5, 0.0), (0.5, 0.5), (0.0, 0.5)]
        );
        assert_eq!(
            child(tri, true, 1)[..3],
            [(1.0, 0.0), (0.5, 0.5), (0.5, 0.0)]
        );
        assert_eq!(
            child(UNIT_SQUARE, false, 2),
            [(1.0, 1.0), (0.5, 1.0), (0.5, 0.5), (1.0, 0.5)]
        );
        // A pentagon and a triangle under quad/triangle, two levels: level-2 face 4 · 7 + 1 is
        // child 1 of level-1 face 7, the triangle's child 2; face 4 · 3 + 2 is child 2 of the
        // pentagon's sub-patch 3.
        let faces = Polygons::from_raw(vec![0, 5, 8], vec![0, 1, 2, 3, 4, 0, 4, 5]).unwrap();
        let l = Levels::new(&faces, Scheme::QuadTriangle, 2);
        assert_eq!(l.first_child, vec![0, 5, 9]);
        let (face, sub, c) = l.corners(4 * 7 + 1);
        assert_eq!((face, sub), (1, 0));
        assert_eq!(c[..3], [(0.0, 0.5), (0.25, 0.5), (0.0, 0.75)][..]);
        let (face, sub, c) = l.corners(4 * 3 + 2);
        assert_eq!((face, sub), (0, 3));
        assert_eq!(c, [(1.0, 1.0), (0.5, 1.0), (0.5, 0.5), (1.0, 0.5)]);
    }
}
