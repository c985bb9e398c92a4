//! The tile rasterizer behind [`super`]: primitives projected to pixel coordinates, binned into
//! `TILE × TILE` pixel tiles by their bounding boxes grown by the cutoff distance, then each
//! tile visits, triangle by triangle, only the pixels of that grown box (forward: the product
//! of the `1 − D` factors; backward: the gradient of the loss w.r.t. the projected corners).
//!
//! Everything here is in pixel units: coordinates in pixels, `σ` in pixel², distances in
//! pixels. The world ↔ pixel map (a constant Jacobian) lives in [`super::camera`].

use rayon::prelude::*;

use super::{Camera, Image, SoftOptions};

/// Side of a square tile, pixels.
pub(super) const TILE: usize = 16;

/// Largest exponent fed to `exp` (beyond it the factor `1 − D` underflows anyway).
const Z_MAX: f64 = 700.0;

/// The soft coverage function in pixel units, with the cutoff folded in.
///
/// `D(s) = sigmoid(s/σ)` for the signed squared distance `s` (positive inside). The kept factor
/// is `q̃ = min(1, (1 − D)/(1 − ε))`: exactly 1 (no effect) once `D ≤ ε`, i.e. beyond the cutoff
/// distance `√(σ·ln((1 − ε)/ε))` outside the primitive, and continuous there, so the pixel value
/// `I = 1 − Π q̃` and its gradient have no jump when a primitive crosses the cutoff.
#[derive(Clone, Copy, Debug)]
pub(super) struct Soft {
    inv_sigma: f64,
    /// Squared cutoff distance outside a primitive, px²: `D = ε` there.
    cut2: f64,
    /// `1/(1 − ε)`.
    rescale: f64,
}

impl Soft {
    #[track_caller]
    pub(super) fn new(options: &SoftOptions) -> Self {
        let (sigma, eps) = (options.sigma, options.epsilon);
        assert!(
            sigma > 0.0 && sigma.is_finite(),
            "SoftOptions::sigma must be positive, got {sigma}"
        );
        assert!(
            eps > 0.0 && eps < 0.5,
            "SoftOptions::epsilon must lie in (0, 0.5), got {eps}"
        );
        Self {
            inv_sigma: 1.0 / sigma,
            cut2: sigma * ((1.0 - eps) / eps).ln(),
            rescale: 1.0 / (1.0 - eps),
        }
    }

    /// Distance beyond a primitive where its coverage drops to `ε`, pixels.
    pub(super) fn cut_radius(&self) -> f64 {
        self.cut2.sqrt()
    }

    /// `(q̃, D)` for the signed squared distance `s` (px², positive inside); `None` beyond the
    /// cutoff, where `q̃ = 1`.
    #[inline]
    fn factor(&self, s: f64) -> Option<(f64, f64)> {
        if s <= -self.cut2 {
            return None;
        }
        let e = (s * self.inv_sigma).min(Z_MAX).exp();
        let q = 1.0 / (1.0 + e);
        Some((q * self.rescale, e * q))
    }
}

/// A shape in pixel coordinates with a signed squared distance to its boundary.
pub(super) trait Primitive: Sync {
    /// `[x_min, y_min, x_max, y_max]`, pixels.
    fn bbox(&self) -> [f64; 4];
    /// `±d²`, `d` the distance from `p` to the boundary: positive inside, negative outside.
    fn signed_sq(&self, p: [f64; 2]) -> f64;
}

/// A projected triangle with its edges precomputed. Either orientation; a zero-area triangle
/// has no inside (its coverage is that of its edges).
#[derive(Clone, Copy, Debug)]
pub(super) struct TriPx {
    v: [[f64; 2]; 3],
    /// `e[k] = v[k+1] − v[k]`.
    e: [[f64; 2]; 3],
    /// `1/|e[k]|²`, 0 for a zero-length edge.
    inv_len2: [f64; 3],
    /// Sign of the signed area (+1, −1, or 0 when degenerate).
    orient: f64,
}

/// The nearest boundary point of a triangle to a pixel centre.
#[derive(Clone, Copy, Debug)]
struct Closest {
    /// Signed squared distance, positive inside.
    s: f64,
    inside: bool,
    /// The nearest edge `k`, from `v[k]` to `v[k+1]`.
    edge: usize,
    /// Parameter of the nearest point on that edge, in `[0, 1]`.
    t: f64,
    /// `p − nearest point`.
    r: [f64; 2],
}

impl TriPx {
    fn new(v: [[f64; 2]; 3]) -> Self {
        let mut e = [[0.0; 2]; 3];
        let mut inv_len2 = [0.0; 3];
        for k in 0..3 {
            let b = v[(k + 1) % 3];
            e[k] = [b[0] - v[k][0], b[1] - v[k][1]];
            let len2 = e[k][0] * e[k][0] + e[k][1] * e[k][1];
            inv_len2[k] = if len2 > 0.0 { 1.0 / len2 } else { 0.0 };
        }
        // Twice the signed area, e0 × (v2 − v0): positive when counter-clockwise, where the
        // inside lies to the left of every edge.
        let area2 = e[0][0] * (v[2][1] - v[0][1]) - e[0][1] * (v[2][0] - v[0][0]);
        let orient = if area2 > 0.0 {
            1.0
        } else if area2 < 0.0 {
            -1.0
        } else {
            0.0
        };
        Self {
            v,
            e,
            inv_len2,
            orient,
        }
    }

    #[inline]
    fn closest(&self, p: [f64; 2]) -> Closest {
        let mut inside = self.orient != 0.0;
        let mut best = Closest {
            s: f64::INFINITY,
            inside: false,
            edge: 0,
            t: 0.0,
            r: [0.0; 2],
        };
        for k in 0..3 {
            let (a, e) = (self.v[k], self.e[k]);
            let w = [p[0] - a[0], p[1] - a[1]];
            inside &= (e[0] * w[1] - e[1] * w[0]) * self.orient > 0.0;
            let t = ((w[0] * e[0] + w[1] * e[1]) * self.inv_len2[k]).clamp(0.0, 1.0);
            let r = [w[0] - t * e[0], w[1] - t * e[1]];
            let d2 = r[0] * r[0] + r[1] * r[1];
            if d2 < best.s {
                best = Closest {
                    s: d2,
                    inside: false,
                    edge: k,
                    t,
                    r,
                };
            }
        }
        best.inside = inside;
        if !inside {
            best.s = -best.s;
        }
        best
    }
}

impl Primitive for TriPx {
    fn bbox(&self) -> [f64; 4] {
        let [a, b, c] = self.v;
        [
            a[0].min(b[0]).min(c[0]),
            a[1].min(b[1]).min(c[1]),
            a[0].max(b[0]).max(c[0]),
            a[1].max(b[1]).max(c[1]),
        ]
    }

    #[inline]
    fn signed_sq(&self, p: [f64; 2]) -> f64 {
        self.closest(p).s
    }
}

/// A projected ball: a disc of centre `c` and radius `r`, pixels.
#[derive(Clone, Copy, Debug)]
pub(super) struct DiscPx {
    c: [f64; 2],
    r: f64,
}

impl Primitive for DiscPx {
    fn bbox(&self) -> [f64; 4] {
        [
            self.c[0] - self.r,
            self.c[1] - self.r,
            self.c[0] + self.r,
            self.c[1] + self.r,
        ]
    }

    #[inline]
    fn signed_sq(&self, p: [f64; 2]) -> f64 {
        let d = ((p[0] - self.c[0]).powi(2) + (p[1] - self.c[1]).powi(2)).sqrt() - self.r;
        -d * d.abs()
    }
}

/// One view's primitives binned into tiles.
pub(super) struct View<P> {
    prims: Vec<P>,
    /// Inclusive pixel range `[x0, y0, x1, y1]` each primitive can reach (its box grown by the
    /// cutoff, clipped to the image).
    range: Vec<[u32; 4]>,
    /// Index of each primitive in the caller's list (triangle or point index).
    source: Vec<u32>,
    resolution: usize,
    tiles_x: usize,
    /// Primitives of tile `t`: `items[start[t]..start[t + 1]]`, in increasing order.
    start: Vec<u32>,
    items: Vec<u32>,
}

impl<P: Primitive> View<P> {
    /// Keeps the primitives whose grown box meets the image and bins them (counting sort).
    fn new(candidates: impl Iterator<Item = (u32, P)>, resolution: usize, soft: &Soft) -> Self {
        let grow = soft.cut_radius();
        let last = resolution as f64 - 1.0;
        let mut prims = Vec::new();
        let mut range = Vec::new();
        let mut source = Vec::new();
        for (src, p) in candidates {
            let b = p.bbox();
            // Pixel i is reached when its centre i + ½ lies within the grown box.
            let lo_x = (b[0] - grow - 0.5).ceil().max(0.0);
            let lo_y = (b[1] - grow - 0.5).ceil().max(0.0);
            let hi_x = (b[2] + grow - 0.5).floor().min(last);
            let hi_y = (b[3] + grow - 0.5).floor().min(last);
            // Also rejects NaN boxes (non-finite positions reach no pixel).
            if !(lo_x <= hi_x && lo_y <= hi_y) {
                continue;
            }
            prims.push(p);
            range.push([lo_x as u32, lo_y as u32, hi_x as u32, hi_y as u32]);
            source.push(src);
        }
        let tiles_x = resolution.div_ceil(TILE);
        let tile_span = |r: &[u32; 4]| {
            let t = TILE as u32;
            (r[0] / t..=r[2] / t, r[1] / t..=r[3] / t)
        };
        let mut start = vec![0u32; tiles_x * tiles_x + 1];
        for r in &range {
            let (xs, ys) = tile_span(r);
            for ty in ys {
                for tx in xs.clone() {
                    start[ty as usize * tiles_x + tx as usize + 1] += 1;
                }
            }
        }
        for t in 0..tiles_x * tiles_x {
            start[t + 1] += start[t];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; start[tiles_x * tiles_x] as usize];
        for (i, r) in range.iter().enumerate() {
            let (xs, ys) = tile_span(r);
            for ty in ys {
                for tx in xs.clone() {
                    let slot = &mut fill[ty as usize * tiles_x + tx as usize];
                    items[*slot as usize] = i as u32;
                    *slot += 1;
                }
            }
        }
        Self {
            prims,
            range,
            source,
            resolution,
            tiles_x,
            start,
            items,
        }
    }

    fn tile_count(&self) -> usize {
        self.tiles_x * self.tiles_x
    }

    /// Pixel rectangle `[x0, x1) × [y0, y1)` of tile `t`.
    fn tile_rect(&self, t: usize) -> [usize; 4] {
        let (x0, y0) = ((t % self.tiles_x) * TILE, (t / self.tiles_x) * TILE);
        [
            x0,
            (x0 + TILE).min(self.resolution),
            y0,
            (y0 + TILE).min(self.resolution),
        ]
    }

    fn tile_items(&self, t: usize) -> &[u32] {
        &self.items[self.start[t] as usize..self.start[t + 1] as usize]
    }

    /// Calls `visit(local pixel index, pixel centre)` for the pixels of tile `rect` that
    /// primitive `i` can reach.
    #[inline]
    fn for_pixels(&self, i: usize, rect: [usize; 4], mut visit: impl FnMut(usize, [f64; 2])) {
        let r = self.range[i];
        let (x0, x1) = ((r[0] as usize).max(rect[0]), (r[2] as usize + 1).min(rect[1]));
        let (y0, y1) = ((r[1] as usize).max(rect[2]), (r[3] as usize + 1).min(rect[3]));
        for y in y0..y1 {
            let row = (y - rect[2]) * TILE;
            let py = y as f64 + 0.5;
            for x in x0..x1 {
                visit(row + x - rect[0], [x as f64 + 0.5, py]);
            }
        }
    }

    /// The product `Q = Π q̃` over the tile's pixels (local index `(y − y0)·TILE + x − x0`).
    fn forward(&self, t: usize, soft: &Soft) -> [f64; TILE * TILE] {
        let mut q = [1.0; TILE * TILE];
        let rect = self.tile_rect(t);
        for &i in self.tile_items(t) {
            let prim = &self.prims[i as usize];
            self.for_pixels(i as usize, rect, |l, p| {
                if let Some((qf, _)) = soft.factor(prim.signed_sq(p)) {
                    q[l] *= qf;
                }
            });
        }
        q
    }
}

/// The triangles of a mesh seen by `camera`. Cost O(#V + #F).
#[track_caller]
pub(super) fn mesh_view(
    camera: &Camera,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    soft: &Soft,
) -> View<TriPx> {
    let px: Vec<[f64; 2]> = positions.iter().map(|&p| camera.project(p)).collect();
    let n = px.len();
    let tris = triangles.iter().enumerate().map(|(f, t)| {
        assert!(
            t.iter().all(|&v| (v as usize) < n),
            "triangle {f} = {t:?} indexes past the {n} positions"
        );
        let v = t.map(|v| px[v as usize]);
        (f as u32, TriPx::new(v))
    });
    View::new(tris, camera.resolution, soft)
}

/// The points seen by `camera`, each a ball of `radius` world units. Cost O(#points).
pub(super) fn points_view(
    camera: &Camera,
    points: &[[f64; 3]],
    radius: f64,
    soft: &Soft,
) -> View<DiscPx> {
    let r = radius / camera.pixel_size();
    let discs = points.iter().enumerate().map(|(i, &p)| {
        (
            i as u32,
            DiscPx {
                c: camera.project(p),
                r,
            },
        )
    });
    View::new(discs, camera.resolution, soft)
}

/// The images of `views`, all tiles of all views in parallel.
pub(super) fn render<P: Primitive>(views: &[View<P>], soft: &Soft) -> Vec<Image> {
    let tasks: Vec<(usize, usize)> = views
        .iter()
        .enumerate()
        .flat_map(|(v, view)| (0..view.tile_count()).map(move |t| (v, t)))
        .collect();
    let tiles: Vec<[f64; TILE * TILE]> = tasks
        .par_iter()
        .map(|&(v, t)| views[v].forward(t, soft))
        .collect();
    let mut images: Vec<Image> = views
        .iter()
        .map(|view| Image {
            resolution: view.resolution,
            pixels: vec![0.0; view.resolution * view.resolution],
        })
        .collect();
    for (&(v, t), q) in tasks.iter().zip(&tiles) {
        let view = &views[v];
        let [x0, x1, y0, y1] = view.tile_rect(t);
        for y in y0..y1 {
            for x in x0..x1 {
                images[v].pixels[y * view.resolution + x] = 1.0 - q[(y - y0) * TILE + x - x0];
            }
        }
    }
    images
}

/// What one tile contributes to the loss: `Σ (I − T)²` over its pixels, and `∂L/∂(projected
/// corners)` of the triangles it touched as `(triangle, [x0, y0, x1, y1, x2, y2])`.
pub(super) struct TileResult {
    pub view: usize,
    pub sum_sq: f64,
    pub grads: Vec<(u32, [f64; 6])>,
}

/// `Σ (I − T)²` per tile and, when `weight` is `Some(2/N)`, the gradient of
/// `L = Σ (I − T)² / N` w.r.t. the projected triangle corners. All tiles of all views in
/// parallel; results in (view, tile) order, so any sum over them is deterministic.
pub(super) fn loss_tiles(
    views: &[View<TriPx>],
    targets: &[Image],
    soft: &Soft,
    weight: Option<f64>,
) -> Vec<TileResult> {
    let tasks: Vec<(usize, usize)> = views
        .iter()
        .enumerate()
        .flat_map(|(v, view)| (0..view.tile_count()).map(move |t| (v, t)))
        .collect();
    tasks
        .par_iter()
        .map(|&(v, t)| {
            let view = &views[v];
            let target = &targets[v].pixels;
            let q = view.forward(t, soft);
            let [x0, x1, y0, y1] = view.tile_rect(t);
            let mut sum_sq = 0.0;
            // w = ∂L/∂I · Q per local pixel: ∂I/∂z_f = D_f·Q for z_f = s_f/σ.
            let mut w = [0.0; TILE * TILE];
            for y in y0..y1 {
                for x in x0..x1 {
                    let l = (y - y0) * TILE + x - x0;
                    let diff = 1.0 - q[l] - target[y * view.resolution + x];
                    sum_sq += diff * diff;
                    if let Some(weight) = weight {
                        w[l] = weight * diff * q[l];
                    }
                }
            }
            let grads = if weight.is_some() {
                backward(view, t, soft, &w)
            } else {
                Vec::new()
            };
            TileResult {
                view: v,
                sum_sq,
                grads,
            }
        })
        .collect()
}

/// `∂L/∂(projected corners)` of the tile's triangles given `w = ∂L/∂I · Q` per pixel.
///
/// With `z = s/σ`, `∂L/∂s = w·D/σ`; `s = ±d²`, `d² = |r|²`, `r = p − (a + t(b − a))` on the
/// nearest edge `(a, b)`, so `∂d²/∂a = −2r(1 − t)`, `∂d²/∂b = −2rt` (with `t` clamped the
/// envelope theorem leaves these unchanged).
fn backward(view: &View<TriPx>, t: usize, soft: &Soft, w: &[f64; TILE * TILE]) -> Vec<(u32, [f64; 6])> {
    let rect = view.tile_rect(t);
    let mut out = Vec::new();
    for &i in view.tile_items(t) {
        let tri = &view.prims[i as usize];
        let mut acc = [0.0; 6];
        let mut touched = false;
        view.for_pixels(i as usize, rect, |l, p| {
            if w[l] == 0.0 {
                return;
            }
            let c = tri.closest(p);
            let Some((_, d)) = soft.factor(c.s) else {
                return;
            };
            let ds = w[l] * d * soft.inv_sigma;
            // ∂s/∂a = ∓2r(1 − t) (inside: s = d², outside: s = −d²).
            let f = if c.inside { -2.0 * ds } else { 2.0 * ds };
            let (ia, ib) = (2 * c.edge, 2 * ((c.edge + 1) % 3));
            let (fa, fb) = (f * (1.0 - c.t), f * c.t);
            acc[ia] += fa * c.r[0];
            acc[ia + 1] += fa * c.r[1];
            acc[ib] += fb * c.r[0];
            acc[ib + 1] += fb * c.r[1];
            touched = true;
        });
        if touched {
            out.push((view.source[i as usize], acc));
        }
    }
    out
}
