//! The tile rasterizer behind [`super`]: primitives projected to pixel coordinates, binned into
//! `TILE × TILE` pixel tiles by their bounding boxes grown by the cutoff distance; each tile
//! visits, primitive by primitive, the pixels that can lie within the cutoff (the grown box cut
//! by a disc around the primitive, row by row), `LANES` pixels of a row at a time (forward:
//! the product of the `1 − D` factors; backward: the gradient of the loss w.r.t. the projected
//! triangle corners).
//!
//! Everything here is in pixel units: coordinates in pixels, `σ` in pixel², distances in
//! pixels. The world ↔ pixel map (a constant Jacobian) lives in [`super::camera`].

// The kernels index several per-lane arrays in step (`for j in 0..LANES`), the form the
// compiler vectorizes and the clearest to read.
#![allow(clippy::needless_range_loop)]

use rayon::prelude::*;

use super::camera::Camera;
use super::image::{Image, SoftOptions};

/// Side of a square tile, pixels.
pub(super) const TILE: usize = 32;

/// Pixels evaluated together: the kernels are loops over `[f64; LANES]` without branches,
/// which the compiler turns into SIMD instructions.
const LANES: usize = 4;

/// A chunk of `LANES` pixel values.
type Lanes = [f64; LANES];

/// Row stride of the tile buffers: a chunk starting near the end of a tile row spills up to
/// `LANES − 1` values into padding columns, which hold no pixel.
const STRIDE: usize = TILE + LANES;

/// Length of a tile buffer.
const TILE_BUF: usize = TILE * STRIDE;

/// Exponents are clamped to `±Z_MAX` (beyond it `1 − D` or `D` is below 1e-304 anyway).
const Z_MAX: f64 = 700.0;

/// The soft coverage function in pixel units, with the cutoff folded in.
///
/// `D(s) = sigmoid(s/σ)` for the signed squared distance `s` (positive inside). The kept factor
/// is `q̃ = min(1, (1 − D)/(1 − ε))`: exactly 1 (no effect) once `D ≤ ε`, i.e. beyond the cutoff
/// distance `√(σ·ln((1 − ε)/ε))` outside the primitive, and continuous there, so the pixel value
/// `I = 1 − Π q̃` and its gradient have no jump when a primitive crosses the cutoff. The kernels
/// accumulate `P = Π 1/q̃ = Π (1 + e^{s/σ})(1 − ε)` (a multiplication per visit, no division)
/// and take `Q = Π q̃ = 1/P` per pixel; `P` may overflow to `+∞`, which gives `Q = 0`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Soft {
    inv_sigma: f64,
    /// Squared cutoff distance outside a primitive, px²: `D = ε` there.
    cut2: f64,
    /// `1 − ε`.
    keep: f64,
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
            keep: 1.0 - eps,
        }
    }

    /// Distance beyond a primitive where its coverage drops to `ε`, pixels.
    pub(super) fn cut_radius(&self) -> f64 {
        self.cut2.sqrt()
    }

    /// `e^{s/σ}` with the exponent clamped to `±Z_MAX`.
    #[inline(always)]
    fn exp(&self, s: f64) -> f64 {
        let z = s * self.inv_sigma;
        let z = if z > Z_MAX { Z_MAX } else { z };
        let z = if z < -Z_MAX { -Z_MAX } else { z };
        exp(z)
    }
}

/// `1/k!` for `k = 0..=13`.
const INV_FACTORIALS: [f64; 14] = [
    1.0,
    1.0,
    1.0 / 2.0,
    1.0 / 6.0,
    1.0 / 24.0,
    1.0 / 120.0,
    1.0 / 720.0,
    1.0 / 5_040.0,
    1.0 / 40_320.0,
    1.0 / 362_880.0,
    1.0 / 3_628_800.0,
    1.0 / 39_916_800.0,
    1.0 / 479_001_600.0,
    1.0 / 6_227_020_800.0,
];

/// `e^z` for `|z| ≤ 708`, within a few ulp, without branches so that it vectorizes (the C
/// library's `exp` is an opaque call). Cody–Waite reduction `z = n·ln 2 + r`, `|r| ≤ ½ ln 2`,
/// a degree-13 Taylor polynomial for `e^r` (remainder below 5e-18) evaluated by Estrin's scheme
/// (a dependency chain of 4 multiply-adds instead of Horner's 13), and `2^n` assembled in the
/// exponent bits.
#[inline(always)]
pub(super) fn exp(z: f64) -> f64 {
    // 1.5·2^52: adding it rounds to an integer, which then sits in the low mantissa bits.
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    const LN2_HI: f64 = 6.931_471_803_691_238e-1;
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    const C: [f64; 14] = INV_FACTORIALS;
    let shifted = z * std::f64::consts::LOG2_E + SHIFT;
    let n = shifted - SHIFT;
    let r = (z - n * LN2_HI) - n * LN2_LO;
    let (r2, r4) = (r * r, r * r * (r * r));
    let q0 = (C[0] + C[1] * r) + (C[2] + C[3] * r) * r2;
    let q1 = (C[4] + C[5] * r) + (C[6] + C[7] * r) * r2;
    let q2 = (C[8] + C[9] * r) + (C[10] + C[11] * r) * r2;
    let q3 = C[12] + C[13] * r;
    let p = (q0 + q1 * r4) + (q2 + q3 * r4) * (r4 * r4);
    let n_bits = shifted.to_bits().wrapping_sub(SHIFT.to_bits());
    p * f64::from_bits(n_bits.wrapping_add(1023) << 52)
}

/// A shape in pixel coordinates with a signed squared distance to its boundary.
pub(super) trait Primitive: Sync {
    /// `[x_min, y_min, x_max, y_max]`, pixels.
    fn bbox(&self) -> [f64; 4];
    /// A disc `(centre, radius)` containing the shape, pixels.
    fn bounding_disc(&self) -> ([f64; 2], f64);
    /// `±d²` at the pixel centres `(x[j], y[j])`, `d` the distance to the boundary: positive
    /// inside, negative outside.
    fn signed_sq(&self, x: &Lanes, y: &Lanes) -> Lanes;
}

/// A projected triangle with its edges precomputed. Either orientation; a zero-area triangle
/// has no inside (its coverage is that of its edges).
#[derive(Clone, Copy, Debug)]
pub(super) struct TriPx {
    v: [[f64; 2]; 3],
    /// `e[k] = v[k+1] − v[k]`.
    e: [[f64; 2]; 3],
    /// `e[k]/|e[k]|²` (zero for a zero-length edge): `t = w·g[k]`.
    g: [[f64; 2]; 3],
    /// `orient·e[k]`, `orient` the sign of the signed area (+1, −1, or 0 when degenerate):
    /// `n[k] × w > 0` on the inner side of every edge.
    n: [[f64; 2]; 3],
}

impl TriPx {
    fn new(v: [[f64; 2]; 3]) -> Self {
        let mut e = [[0.0; 2]; 3];
        let mut g = [[0.0; 2]; 3];
        for k in 0..3 {
            let b = v[(k + 1) % 3];
            e[k] = [b[0] - v[k][0], b[1] - v[k][1]];
            let len2 = e[k][0] * e[k][0] + e[k][1] * e[k][1];
            let il = if len2 > 0.0 { 1.0 / len2 } else { 0.0 };
            g[k] = [e[k][0] * il, e[k][1] * il];
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
        let n = e.map(|ek| [ek[0] * orient, ek[1] * orient]);
        Self { v, e, g, n }
    }

    /// Edge `k` seen from the pixel centres: `(orient · e_k × w, t, r)` with `w = p − v_k`,
    /// `t` the clamped parameter of the nearest point, `r = w − t·e_k`.
    #[inline(always)]
    fn edge(&self, k: usize, x: &Lanes, y: &Lanes) -> (Lanes, Lanes, [Lanes; 2]) {
        let (a, e, g, n) = (self.v[k], self.e[k], self.g[k], self.n[k]);
        let mut side = [0.0; LANES];
        let mut t = [0.0; LANES];
        let mut r = [[0.0; LANES]; 2];
        for j in 0..LANES {
            let (wx, wy) = (x[j] - a[0], y[j] - a[1]);
            side[j] = n[0] * wy - n[1] * wx;
            let tj = wx * g[0] + wy * g[1];
            let tj = if tj < 0.0 { 0.0 } else { tj };
            let tj = if tj > 1.0 { 1.0 } else { tj };
            t[j] = tj;
            r[0][j] = wx - tj * e[0];
            r[1][j] = wy - tj * e[1];
        }
        (side, t, r)
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

    fn bounding_disc(&self) -> ([f64; 2], f64) {
        let [a, b, c] = self.v;
        let m = [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0];
        let r2 = self
            .v
            .iter()
            .map(|v| (v[0] - m[0]).powi(2) + (v[1] - m[1]).powi(2))
            .fold(0.0, f64::max);
        (m, r2.sqrt())
    }

    #[inline(always)]
    fn signed_sq(&self, x: &Lanes, y: &Lanes) -> Lanes {
        let mut d2 = [f64::INFINITY; LANES];
        let mut side_min = [f64::INFINITY; LANES];
        for k in 0..3 {
            let (side, _, r) = self.edge(k, x, y);
            for j in 0..LANES {
                let dk = r[0][j] * r[0][j] + r[1][j] * r[1][j];
                d2[j] = if dk < d2[j] { dk } else { d2[j] };
                side_min[j] = if side[j] < side_min[j] {
                    side[j]
                } else {
                    side_min[j]
                };
            }
        }
        let mut s = [0.0; LANES];
        for j in 0..LANES {
            s[j] = if side_min[j] > 0.0 { d2[j] } else { -d2[j] };
        }
        s
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

    fn bounding_disc(&self) -> ([f64; 2], f64) {
        (self.c, self.r)
    }

    #[inline(always)]
    fn signed_sq(&self, x: &Lanes, y: &Lanes) -> Lanes {
        let mut s = [0.0; LANES];
        for j in 0..LANES {
            let (dx, dy) = (x[j] - self.c[0], y[j] - self.c[1]);
            let d = (dx * dx + dy * dy).sqrt() - self.r;
            s[j] = if d > 0.0 { -d * d } else { d * d };
        }
        s
    }
}

/// One view's primitives binned into tiles.
pub(super) struct View<P> {
    prims: Vec<P>,
    /// Inclusive pixel range `[x0, y0, x1, y1]` each primitive can reach (its box grown by the
    /// cutoff, clipped to the image).
    range: Vec<[u32; 4]>,
    /// A disc `[cx, cy, ρ²]` holding every pixel centre within the cutoff of the primitive.
    reach: Vec<[f64; 3]>,
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
        let mut reach = Vec::new();
        let mut source = Vec::new();
        for (src, p) in candidates {
            let b = p.bbox();
            // Pixel i is reached when its centre i + ½ lies within the grown box.
            let lo_x = (b[0] - grow - 0.5).ceil().max(0.0);
            let lo_y = (b[1] - grow - 0.5).ceil().max(0.0);
            let hi_x = (b[2] + grow - 0.5).floor().min(last);
            let hi_y = (b[3] + grow - 0.5).floor().min(last);
            if !(lo_x <= hi_x && lo_y <= hi_y) {
                continue;
            }
            let (c, r) = p.bounding_disc();
            prims.push(p);
            range.push([lo_x as u32, lo_y as u32, hi_x as u32, hi_y as u32]);
            reach.push([c[0], c[1], (r + grow) * (r + grow)]);
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
            reach,
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

    /// Pixel rectangle `[x0, x1) × [y0, y1)` of tile `t`, as `[x0, x1, y0, y1]`.
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

    /// Calls `visit(buffer index of the chunk's first pixel, x, y)` for chunks of `LANES`
    /// consecutive pixels of a row covering every pixel of tile `rect` within the cutoff of
    /// primitive `i`: the rows of its grown box cut by its reach disc. A chunk may take in
    /// pixels beyond the cutoff, or padding columns past the tile's end.
    #[inline(always)]
    fn for_chunks(&self, i: usize, rect: [usize; 4], mut visit: impl FnMut(usize, &Lanes, &Lanes)) {
        let r = self.range[i];
        let [cx, cy, rho2] = self.reach[i];
        let (x0, x1) = (
            (r[0] as usize).max(rect[0]),
            (r[2] as usize + 1).min(rect[1]),
        );
        let (y0, y1) = (
            (r[1] as usize).max(rect[2]),
            (r[3] as usize + 1).min(rect[3]),
        );
        for y in y0..y1 {
            let py = y as f64 + 0.5;
            let h2 = rho2 - (py - cy) * (py - cy);
            if h2 < 0.0 {
                continue;
            }
            let h = h2.sqrt();
            // Pixels x with |x + ½ − cx| ≤ h, clipped to [x0, x1). Casting truncates towards
            // zero, which is the floor for the non-negative values kept (cheaper than the
            // library's ceil/floor, calls without SSE4.1).
            let lo = cx - h - 0.5;
            let xa = if lo <= x0 as f64 {
                x0
            } else {
                let t = lo as usize;
                t + usize::from((t as f64) < lo)
            };
            let hi = cx + h + 0.5;
            let xb = if hi >= x1 as f64 { x1 } else { hi as usize };
            if xb <= xa {
                continue;
            }
            let row = (y - rect[2]) * STRIDE;
            let ys = [py; LANES];
            let mut x = xa;
            while x < xb {
                let mut xs = [0.0; LANES];
                for (j, xj) in xs.iter_mut().enumerate() {
                    *xj = (x + j) as f64 + 0.5;
                }
                visit(row + x - rect[0], &xs, &ys);
                x += LANES;
            }
        }
    }

    /// `P = Π 1/q̃` over the tile's pixels (buffer index `(y − y0)·STRIDE + x − x0`). With
    /// `store`, the `±e^{s/σ}` of every visited lane (`+` inside, `−` outside) are appended in
    /// visiting order, for [`backward`] to reuse.
    fn forward(&self, t: usize, soft: &Soft, mut store: Option<&mut Vec<f64>>) -> [f64; TILE_BUF] {
        let mut p = [1.0; TILE_BUF];
        let rect = self.tile_rect(t);
        for &i in self.tile_items(t) {
            let prim = &self.prims[i as usize];
            self.for_chunks(i as usize, rect, |l, x, y| {
                let s = prim.signed_sq(x, y);
                let mut e = [0.0; LANES];
                for j in 0..LANES {
                    e[j] = soft.exp(s[j]);
                }
                let chunk = &mut p[l..l + LANES];
                for j in 0..LANES {
                    let f = (1.0 + e[j]) * soft.keep;
                    chunk[j] *= if s[j] > -soft.cut2 { f } else { 1.0 };
                }
                if let Some(store) = store.as_deref_mut() {
                    let mut signed = [0.0; LANES];
                    for j in 0..LANES {
                        signed[j] = if s[j] > 0.0 { e[j] } else { -e[j] };
                    }
                    store.extend_from_slice(&signed);
                }
            });
        }
        p
    }
}

/// The triangles of a mesh seen by `camera`; a triangle with a non-finite corner is left out.
/// Cost O(#V + #F).
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
        let finite = v.iter().flatten().all(|c| c.is_finite());
        finite.then(|| (f as u32, TriPx::new(v)))
    });
    View::new(tris.flatten(), camera.resolution, soft)
}

/// The points seen by `camera`, each a ball of `radius` world units; non-finite points are left
/// out. Cost O(#points).
pub(super) fn points_view(
    camera: &Camera,
    points: &[[f64; 3]],
    radius: f64,
    soft: &Soft,
) -> View<DiscPx> {
    let r = radius / camera.pixel_size();
    let discs = points.iter().enumerate().filter_map(|(i, &p)| {
        let c = camera.project(p);
        (c[0].is_finite() && c[1].is_finite()).then_some((i as u32, DiscPx { c, r }))
    });
    View::new(discs, camera.resolution, soft)
}

/// All (view, tile) pairs, the unit of parallel work.
fn tasks<P: Primitive>(views: &[View<P>]) -> Vec<(usize, usize)> {
    views
        .iter()
        .enumerate()
        .flat_map(|(v, view)| (0..view.tile_count()).map(move |t| (v, t)))
        .collect()
}

/// The images of `views`, all tiles of all views in parallel.
pub(super) fn render<P: Primitive>(views: &[View<P>], soft: &Soft) -> Vec<Image> {
    let tasks = tasks(views);
    let tiles: Vec<[f64; TILE_BUF]> = tasks
        .par_iter()
        .map(|&(v, t)| views[v].forward(t, soft, None))
        .collect();
    let mut images: Vec<Image> = views
        .iter()
        .map(|view| Image {
            resolution: view.resolution,
            pixels: vec![0.0; view.resolution * view.resolution],
        })
        .collect();
    for (&(v, t), p) in tasks.iter().zip(&tiles) {
        let view = &views[v];
        let [x0, x1, y0, y1] = view.tile_rect(t);
        for y in y0..y1 {
            for x in x0..x1 {
                let q = 1.0 / p[(y - y0) * STRIDE + x - x0];
                images[v].pixels[y * view.resolution + x] = 1.0 - q;
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
    tasks(views)
        .par_iter()
        .map(|&(v, t)| {
            let view = &views[v];
            let target = &targets[v].pixels;
            let mut exps = Vec::new();
            let p = view.forward(t, soft, weight.map(|_| &mut exps));
            let [x0, x1, y0, y1] = view.tile_rect(t);
            let mut sum_sq = 0.0;
            // w = ∂L/∂I · Q per pixel (zero in the padding): ∂I/∂z_f = D_f·Q for z_f = s_f/σ.
            let mut w = [0.0; TILE_BUF];
            for y in y0..y1 {
                for x in x0..x1 {
                    let l = (y - y0) * STRIDE + x - x0;
                    let q = 1.0 / p[l];
                    let diff = 1.0 - q - target[y * view.resolution + x];
                    sum_sq += diff * diff;
                    if let Some(weight) = weight {
                        w[l] = weight * diff * q;
                    }
                }
            }
            let grads = if weight.is_some() {
                backward(view, t, soft, &w, &exps)
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

/// `∂L/∂(projected corners)` of the tile's triangles given `w = ∂L/∂I · Q` per pixel and the
/// signed exponentials stored by the forward pass (same visiting order).
///
/// With `z = s/σ`, `∂L/∂s = w·D/σ`; `s = ±d²`, `d² = |r|²`, `r = p − (a + t(b − a))` on the
/// nearest edge `(a, b)`, so `∂d²/∂a = −2r(1 − t)`, `∂d²/∂b = −2rt` (with `t` clamped the
/// envelope theorem leaves these unchanged).
fn backward(
    view: &View<TriPx>,
    t: usize,
    soft: &Soft,
    w: &[f64; TILE_BUF],
    exps: &[f64],
) -> Vec<(u32, [f64; 6])> {
    let rect = view.tile_rect(t);
    let mut out = Vec::new();
    let mut next = 0;
    for &i in view.tile_items(t) {
        let tri = &view.prims[i as usize];
        // Per corner and coordinate, per lane.
        let mut acc = [[0.0; LANES]; 6];
        view.for_chunks(i as usize, rect, |l, x, y| {
            let wl = &w[l..l + LANES];
            let signed_e = &exps[next..next + LANES];
            next += LANES;
            if wl.iter().all(|&v| v == 0.0) {
                return;
            }
            // (Not `[0, 1, 2].map(…)`: that is not inlined.)
            let edges = [tri.edge(0, x, y), tri.edge(1, x, y), tri.edge(2, x, y)];
            for j in 0..LANES {
                let mut d2 = [0.0; 3];
                for k in 0..3 {
                    let r = &edges[k].2;
                    d2[k] = r[0][j] * r[0][j] + r[1][j] * r[1][j];
                }
                let inside = signed_e[j] > 0.0;
                let e = signed_e[j].abs();
                let d = e / (1.0 + e);
                let ds = wl[j] * d * soft.inv_sigma;
                // ∂s/∂a = ∓2r(1 − t) (inside: s = d², outside: s = −d²).
                let f = if inside { -2.0 * ds } else { 2.0 * ds };
                let d2_min = d2[0].min(d2[1]).min(d2[2]);
                let f = if inside || d2_min < soft.cut2 { f } else { 0.0 };
                // The nearest edge (the first on ties) takes the whole derivative.
                let nearest = [
                    d2[0] <= d2[1] && d2[0] <= d2[2],
                    d2[1] < d2[0] && d2[1] <= d2[2],
                    d2[2] < d2[0] && d2[2] < d2[1],
                ];
                for k in 0..3 {
                    let (_, tk, r) = &edges[k];
                    let g = if nearest[k] { f } else { 0.0 };
                    let gb = g * tk[j];
                    let ga = g - gb;
                    // Edge k runs from corner k to corner k + 1.
                    let (a, b) = (2 * k, 2 * ((k + 1) % 3));
                    acc[a][j] += ga * r[0][j];
                    acc[a + 1][j] += ga * r[1][j];
                    acc[b][j] += gb * r[0][j];
                    acc[b + 1][j] += gb * r[1][j];
                }
            }
        });
        let g: [f64; 6] = std::array::from_fn(|m| acc[m].iter().sum());
        if g.iter().any(|&v| v != 0.0) {
            out.push((view.source[i as usize], g));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exp_matches_the_library() {
        let mut worst: f64 = 0.0;
        for i in 0..=200_000 {
            let z = -Z_MAX + 2.0 * Z_MAX * i as f64 / 200_000.0;
            let (fast, reference) = (exp(z), z.exp());
            worst = worst.max(((fast - reference) / reference).abs());
        }
        assert!(worst < 4.0 * f64::EPSILON, "relative error {worst:e}");
    }
}
