//! Marching tetrahedra (the ambiguity-free variant of Lorensen & Cline 1987's marching cubes):
//! the zero set of the piecewise-linear interpolant of node values over a conforming
//! tetrahedral mesh, one triangle or quad (two triangles) per tetrahedron with a sign change,
//! vertices welded by mesh-edge keys. Negative is inside; an exact zero counts as outside, so
//! callers nudge zeros to a tiny positive number. Used on the octree of
//! [`crate::contour()`] and on the uniform grid of [`crate::carve()`].

use subfit_mesh::{Cancel, Cancelled};

use crate::octree::{KeyMap, KUHN};
use subfit_mesh::vec3::{cross, dot, sub};

/// Accumulates the zero set of tetrahedra over nodes numbered `0..n`.
pub(crate) struct Marcher<'a> {
    value: &'a [f64],
    pos: &'a dyn Fn(usize) -> [f64; 3],
    order: &'a dyn Fn(usize) -> u64,
    edge_vertex: KeyMap<(usize, usize), u32>,
    /// Vertices of the zero set.
    pub(crate) positions: Vec<[f64; 3]>,
    /// Triangles, oriented so that their normals point to positive values (outside).
    pub(crate) tris: Vec<[u32; 3]>,
}

impl<'a> Marcher<'a> {
    /// A marcher over nodes with values `value` (`#nodes`), positions `pos(i)` and a total
    /// order `order(i)` (distinct per node) that fixes from which end an edge's crossing is
    /// interpolated, so that the result does not depend on node numbering.
    pub(crate) fn new(
        value: &'a [f64],
        pos: &'a dyn Fn(usize) -> [f64; 3],
        order: &'a dyn Fn(usize) -> u64,
    ) -> Self {
        Self {
            value,
            pos,
            order,
            edge_vertex: KeyMap::default(),
            positions: Vec::new(),
            tris: Vec::new(),
        }
    }

    /// The vertex on edge `a`–`b` (created at the linear zero crossing, kept 2 % away from the
    /// nodes).
    fn vertex_on(&mut self, a: usize, b: usize) -> u32 {
        let key = if (self.order)(a) <= (self.order)(b) {
            (a, b)
        } else {
            (b, a)
        };
        let (value, pos, positions) = (self.value, self.pos, &mut self.positions);
        *self.edge_vertex.entry(key).or_insert_with(|| {
            let (va, vb) = (value[key.0], value[key.1]);
            let t = (va / (va - vb)).clamp(0.02, 0.98);
            let (pa, pb) = (pos(key.0), pos(key.1));
            positions.push([0, 1, 2].map(|k| pa[k] + t * (pb[k] - pa[k])));
            (positions.len() - 1) as u32
        })
    }

    /// Adds the zero set of the tetrahedron with nodes `v`.
    pub(crate) fn tet(&mut self, v: [usize; 4]) {
        let value = self.value;
        // Inside nodes first, each side in the order of `v` (a stable sort).
        let mut sorted = v;
        sorted.sort_by_key(|&i| value[i] >= 0.0);
        let n_in = v.iter().filter(|&&i| value[i] < 0.0).count();
        let (inside, outside) = sorted.split_at(n_in);
        let mut polygon = [(0, 0); 4];
        let corners = match n_in {
            1 => {
                for (k, &o) in outside.iter().enumerate() {
                    polygon[k] = (inside[0], o);
                }
                3
            }
            3 => {
                for (k, &i) in inside.iter().enumerate() {
                    polygon[k] = (i, outside[0]);
                }
                3
            }
            2 => {
                let ([a, b], [c, d]) = ([inside[0], inside[1]], [outside[0], outside[1]]);
                polygon = [(a, c), (a, d), (b, d), (b, c)];
                4
            }
            _ => return,
        };
        let centroid = |s: &[usize]| {
            let mut m = [0.0; 3];
            for &i in s {
                let p = (self.pos)(i);
                for k in 0..3 {
                    m[k] += p[k] / s.len() as f64;
                }
            }
            m
        };
        let dir = sub(centroid(outside), centroid(inside));
        let mut vs = [0u32; 4];
        for k in 0..corners {
            vs[k] = self.vertex_on(polygon[k].0, polygon[k].1);
        }
        let mut emit = |t: [u32; 3]| {
            let p = t.map(|i| self.positions[i as usize]);
            let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
            self.tris.push(if dot(n, dir) >= 0.0 {
                t
            } else {
                [t[0], t[2], t[1]]
            });
        };
        emit([vs[0], vs[1], vs[2]]);
        if corners == 4 {
            emit([vs[0], vs[2], vs[3]]);
        }
    }
}

/// A uniform grid of `dims` nodes (x fastest), spacing `cell`, first node at `origin`.
pub(crate) struct Grid {
    pub(crate) dims: [usize; 3],
    pub(crate) origin: [f64; 3],
    pub(crate) cell: f64,
}

impl Grid {
    pub(crate) fn coords(&self, i: usize) -> [usize; 3] {
        let x = i % self.dims[0];
        let y = (i / self.dims[0]) % self.dims[1];
        [x, y, i / (self.dims[0] * self.dims[1])]
    }
    pub(crate) fn pos(&self, i: usize) -> [f64; 3] {
        let c = self.coords(i);
        [0, 1, 2].map(|k| self.origin[k] + c[k] as f64 * self.cell)
    }
    pub(crate) fn on_boundary(&self, i: usize) -> bool {
        let c = self.coords(i);
        (0..3).any(|k| c[k] == 0 || c[k] + 1 == self.dims[k])
    }
    pub(crate) fn neighbors6(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let c = self.coords(i);
        let strides = [1, self.dims[0], self.dims[0] * self.dims[1]];
        (0..3).flat_map(move |k| {
            let down = (c[k] > 0).then(|| i - strides[k]);
            let up = (c[k] + 1 < self.dims[k]).then(|| i + strides[k]);
            down.into_iter().chain(up)
        })
    }
}

/// Vertices and outward triangles of a marched grid.
pub(crate) type Surface = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// Marching tetrahedra over every grid cell with a sign change, each cell cut into the 6 Kuhn
/// tetrahedra ([`KUHN`]). Returns vertices and outward triangles. Cost `O(#nodes)`; `cancel`
/// polled per slab of cells.
pub(crate) fn march_grid(
    grid: &Grid,
    value: &[f64],
    cancel: &Cancel,
) -> Result<Surface, Cancelled> {
    let [nx, ny, nz] = grid.dims;
    let corner_off: [usize; 8] =
        std::array::from_fn(|c| (c & 1) + nx * (((c >> 1) & 1) + ny * ((c >> 2) & 1)));
    let pos = |i: usize| grid.pos(i);
    let order = |i: usize| i as u64;
    let mut m = Marcher::new(value, &pos, &order);
    for z in 0..nz - 1 {
        cancel.check()?;
        for y in 0..ny - 1 {
            for x in 0..nx - 1 {
                let base = x + nx * (y + ny * z);
                let ids = corner_off.map(|o| base + o);
                let neg = ids.map(|i| value[i] < 0.0);
                if neg.iter().all(|&s| s) || neg.iter().all(|&s| !s) {
                    continue;
                }
                for tet in &KUHN {
                    m.tet(tet.map(|c| ids[c]));
                }
            }
        }
    }
    Ok((m.positions, m.tris))
}
