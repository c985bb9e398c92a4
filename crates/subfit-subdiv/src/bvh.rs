//! A bounding-volume hierarchy over triangles for nearest-triangle queries (the starting guess of
//! the closest-point search on the limit surface).
//!
//! Median split on the longest axis of the triangle centroids, leaves of up to 4 triangles;
//! queries descend the nearer child first and prune boxes farther than the best distance.
//! Closest point on a triangle: Ericson, *Real-Time Collision Detection* (2005), §5.1.5.

/// An axis-aligned box.
#[derive(Clone, Copy, Debug)]
struct Aabb {
    lo: [f64; 3],
    hi: [f64; 3],
}

impl Aabb {
    fn empty() -> Self {
        Self {
            lo: [f64::INFINITY; 3],
            hi: [f64::NEG_INFINITY; 3],
        }
    }
    fn add(&mut self, p: [f64; 3]) {
        for ((lo, hi), x) in self.lo.iter_mut().zip(&mut self.hi).zip(p) {
            *lo = lo.min(x);
            *hi = hi.max(x);
        }
    }
    fn dist2(&self, p: [f64; 3]) -> f64 {
        let mut d = 0.0;
        for ((lo, hi), x) in self.lo.iter().zip(&self.hi).zip(p) {
            let e = (lo - x).max(0.0).max(x - hi);
            d += e * e;
        }
        d
    }
}

#[derive(Clone, Copy, Debug)]
struct Node {
    bbox: Aabb,
    /// Leaf: first triangle (in `order`) and count; inner: left child index, count 0.
    start: u32,
    count: u32,
    right: u32,
}

/// A BVH over triangles given as corner positions (`#T by 3 by 3`). Memory O(#T).
#[derive(Clone, Debug)]
pub struct TriangleBvh {
    tris: Vec<[[f64; 3]; 3]>,
    order: Vec<u32>,
    nodes: Vec<Node>,
}

/// The nearest triangle to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    /// Triangle index (into the array given to [`TriangleBvh::new`]).
    pub triangle: u32,
    /// Barycentric weights of the closest point for the triangle's three corners.
    pub bary: [f64; 3],
    /// The closest point.
    pub point: [f64; 3],
    /// Squared distance to it.
    pub dist2: f64,
}

impl TriangleBvh {
    /// Builds the hierarchy. Cost O(#T log #T).
    pub fn new(tris: Vec<[[f64; 3]; 3]>) -> Self {
        let mut bvh = Self {
            order: (0..tris.len() as u32).collect(),
            tris,
            nodes: Vec::new(),
        };
        if !bvh.tris.is_empty() {
            bvh.build(0, bvh.tris.len());
        }
        bvh
    }

    fn centroid(&self, t: u32) -> [f64; 3] {
        let c = &self.tris[t as usize];
        [
            (c[0][0] + c[1][0] + c[2][0]) / 3.0,
            (c[0][1] + c[1][1] + c[2][1]) / 3.0,
            (c[0][2] + c[1][2] + c[2][2]) / 3.0,
        ]
    }

    fn build(&mut self, start: usize, end: usize) -> u32 {
        let mut bbox = Aabb::empty();
        let mut cbox = Aabb::empty();
        for &t in &self.order[start..end] {
            for p in self.tris[t as usize] {
                bbox.add(p);
            }
            cbox.add(self.centroid(t));
        }
        let id = self.nodes.len() as u32;
        self.nodes.push(Node {
            bbox,
            start: start as u32,
            count: (end - start) as u32,
            right: 0,
        });
        if end - start <= 4 {
            return id;
        }
        let axis = (0..3)
            .max_by(|&a, &b| (cbox.hi[a] - cbox.lo[a]).total_cmp(&(cbox.hi[b] - cbox.lo[b])))
            .unwrap_or(0);
        let mid = (start + end) / 2;
        let mut slice = std::mem::take(&mut self.order);
        slice[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
            self.centroid(a)[axis].total_cmp(&self.centroid(b)[axis])
        });
        self.order = slice;
        self.build(start, mid);
        let right = self.build(mid, end);
        let n = &mut self.nodes[id as usize];
        n.count = 0;
        n.start = id + 1;
        n.right = right;
        id
    }

    /// The nearest triangle to `p`, or `None` when there are no triangles. Cost O(log #T)
    /// typically.
    pub fn nearest(&self, p: [f64; 3]) -> Option<Nearest> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut best: Option<Nearest> = None;
        let mut stack = vec![0u32];
        while let Some(i) = stack.pop() {
            let node = &self.nodes[i as usize];
            let bd = best.map_or(f64::INFINITY, |b| b.dist2);
            if node.bbox.dist2(p) > bd {
                continue;
            }
            if node.count > 0 {
                for &t in &self.order[node.start as usize..(node.start + node.count) as usize] {
                    let (point, bary) = closest_on_triangle(p, &self.tris[t as usize]);
                    let d = dist2(p, point);
                    if d < best.map_or(f64::INFINITY, |b| b.dist2) {
                        best = Some(Nearest {
                            triangle: t,
                            bary,
                            point,
                            dist2: d,
                        });
                    }
                }
            } else {
                let (l, r) = (node.start, node.right);
                let (dl, dr) = (
                    self.nodes[l as usize].bbox.dist2(p),
                    self.nodes[r as usize].bbox.dist2(p),
                );
                if dl < dr {
                    stack.push(r);
                    stack.push(l);
                } else {
                    stack.push(l);
                    stack.push(r);
                }
            }
        }
        best
    }
}

fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Closest point of triangle `t` to `p` and its barycentric weights (Ericson §5.1.5).
pub fn closest_on_triangle(p: [f64; 3], t: &[[f64; 3]; 3]) -> ([f64; 3], [f64; 3]) {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let at = |w: [f64; 3]| {
        (
            [
                w[0] * a[0] + w[1] * b[0] + w[2] * c[0],
                w[0] * a[1] + w[1] * b[1] + w[2] * c[1],
                w[0] * a[2] + w[1] * b[2] + w[2] * c[2],
            ],
            w,
        )
    };
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return at([1.0, 0.0, 0.0]);
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return at([0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return at([1.0 - v, v, 0.0]);
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return at([0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return at([1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return at([0.0, 1.0 - w, w]);
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    at([1.0 - v - w, v, w])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_matches_brute_force() {
        let mut s = 1u64;
        let mut r = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let tris: Vec<[[f64; 3]; 3]> = (0..300)
            .map(|_| {
                let c = [r(), r(), r()];
                [0, 1, 2].map(|_| [c[0] + 0.1 * r(), c[1] + 0.1 * r(), c[2] + 0.1 * r()])
            })
            .collect();
        let bvh = TriangleBvh::new(tris.clone());
        for _ in 0..200 {
            let q = [1.4 * r() - 0.2, 1.4 * r() - 0.2, 1.4 * r() - 0.2];
            let n = bvh.nearest(q).unwrap();
            let bf = tris
                .iter()
                .map(|t| dist2(q, closest_on_triangle(q, t).0))
                .fold(f64::INFINITY, f64::min);
            assert!((n.dist2 - bf).abs() <= 1e-15);
            let t = &tris[n.triangle as usize];
            let b = n.bary;
            for (k, pk) in n.point.iter().enumerate() {
                let x = b[0] * t[0][k] + b[1] * t[1][k] + b[2] * t[2][k];
                assert!((x - pk).abs() < 1e-14);
            }
        }
        assert!(TriangleBvh::new(Vec::new()).nearest([0.0; 3]).is_none());
    }
}
