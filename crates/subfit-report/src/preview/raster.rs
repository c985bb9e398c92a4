//! The banded z-buffer rasterizer behind [`super::render`]: triangles and wire segments are
//! binned to bands of sample rows, each band is drawn into its own z-buffer and box-filtered
//! down to pixels, bands in parallel.
//!
//! Sample `(i, j)` has its centre at `(i + ½, j + ½)`; a triangle covers the samples whose
//! centres lie inside it or on its edges (so neighbouring triangles leave no cracks).

use super::{Camera, Image, PreviewOptions, ScreenVertex, Wireframe};
use rayon::prelude::*;

/// Final-image rows per band (a band is `ROWS_PER_BAND × supersample` sample rows).
const ROWS_PER_BAND: u32 = 8;

/// Above this many triangles + wire edges, or samples, bands are drawn in parallel.
const PARALLEL_PRIMITIVES: usize = 20_000;
const PARALLEL_SAMPLES: usize = 1 << 20;

/// The supersampled drawing area.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Viewport {
    /// Width in samples of the part the mesh is framed in (left of the colour bar).
    pub width: u32,
    /// Width in samples of the whole image.
    pub full_width: u32,
    /// Height in samples.
    pub height: u32,
    /// Samples per pixel along each axis.
    pub supersample: u32,
}

/// A projected wire edge: screen endpoints in samples and biased depth keys.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WireSegment {
    a: [f32; 3],
    b: [f32; 3],
}

/// Projects the wire edges, moving each endpoint `wire_depth_bias × radius` towards the eye in
/// depth so that a wire lying on the surface wins the depth test.
pub(crate) fn project_wire(
    wire: Wireframe<'_>,
    camera: &Camera,
    options: &PreviewOptions,
) -> Vec<WireSegment> {
    let bias = options.wire_depth_bias.max(0.0) * camera.radius;
    let end = |i: u32| {
        let (x, y, d) = camera.project(&wire.positions[i as usize]);
        let d = (d - bias).max(1e-6 * camera.radius);
        [x as f32, y as f32, camera.depth_key(d)]
    };
    wire.edges
        .iter()
        .map(|&[i, j]| WireSegment {
            a: end(i),
            b: end(j),
        })
        .collect()
}

/// Rasterizes everything and returns the downsampled image (the colour-bar area, if any, is
/// left as background).
pub(crate) fn render_bands(
    verts: &[ScreenVertex],
    triangles: &[[u32; 3]],
    wire: Option<&Vec<WireSegment>>,
    vp: &Viewport,
    options: &PreviewOptions,
) -> Image {
    let band_h = ROWS_PER_BAND * vp.supersample;
    let n_bands = vp.height.div_ceil(band_h) as usize;
    let rows = |lo: f32, hi: f32| sample_rows(lo, hi, vp.height);
    let tri_bins = bin(triangles.len(), n_bands, band_h, |t| {
        let [a, b, c] = triangles[t].map(|i| verts[i as usize].y);
        rows(a.min(b).min(c), a.max(b).max(c))
    });
    let wire = wire.map_or(&[][..], |w| w.as_slice());
    let half_width = wire_half_width(vp, options);
    let wire_bins = bin(wire.len(), n_bands, band_h, |e| {
        let (a, b) = (wire[e].a[1], wire[e].b[1]);
        rows(a.min(b) - half_width, a.max(b) + half_width)
    });

    let (w, h) = (options.width as usize, options.height as usize);
    let mut rgb = vec![0u8; w * h * 3];
    let draw = |(band, out): (usize, &mut [u8])| {
        let y0 = band as u32 * band_h;
        let mut buf = Band::new(vp, y0, band_h.min(vp.height - y0), options.background);
        for &t in tri_bins.get(band) {
            buf.triangle(triangles[t as usize].map(|i| &verts[i as usize]));
        }
        for &e in wire_bins.get(band) {
            buf.segment(&wire[e as usize], half_width, options.wire_color);
        }
        buf.downsample(out, w);
    };
    let chunk = ROWS_PER_BAND as usize * w * 3;
    let samples = vp.full_width as usize * vp.height as usize;
    if triangles.len() + wire.len() > PARALLEL_PRIMITIVES || samples > PARALLEL_SAMPLES {
        rgb.par_chunks_mut(chunk).enumerate().for_each(draw);
    } else {
        rgb.chunks_mut(chunk).enumerate().for_each(draw);
    }
    Image {
        width: options.width,
        height: options.height,
        rgb,
    }
}

/// Half the wire width in samples (at least half a sample, so a wire is never lost).
fn wire_half_width(vp: &Viewport, options: &PreviewOptions) -> f32 {
    let w = if options.wire_width.is_finite() {
        options.wire_width
    } else {
        1.0
    };
    (0.5 * w * f64::from(vp.supersample)).max(0.5) as f32
}

/// The sample rows whose centres lie in `[lo, hi]`, clipped to the image; `None` if none.
fn sample_rows(lo: f32, hi: f32, height: u32) -> Option<(u32, u32)> {
    let first = (lo - 0.5).ceil().max(0.0);
    let last = (hi - 0.5).floor().min(height as f32 - 1.0);
    // NaN compares false, so a NaN coordinate draws nothing.
    (first <= last).then_some((first as u32, last as u32))
}

/// Primitives per band, in index order (compressed rows).
struct Bins {
    offsets: Vec<u32>,
    items: Vec<u32>,
}

impl Bins {
    fn get(&self, band: usize) -> &[u32] {
        &self.items[self.offsets[band] as usize..self.offsets[band + 1] as usize]
    }
}

/// Counting sort of `n` primitives into `n_bands` bands of `band_h` rows by their row range.
fn bin(
    n: usize,
    n_bands: usize,
    band_h: u32,
    rows: impl Fn(usize) -> Option<(u32, u32)> + Sync,
) -> Bins {
    let ranges: Vec<(u32, u32)> = (0..n)
        .into_par_iter()
        .with_min_len(1 << 14)
        .map(|i| rows(i).map_or((1, 0), |(a, b)| (a / band_h, b / band_h)))
        .collect();
    let mut offsets = vec![0u32; n_bands + 1];
    for &(a, b) in &ranges {
        for band in a..=b {
            offsets[band as usize + 1] += 1;
        }
    }
    for i in 0..n_bands {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets.clone();
    let mut items = vec![0u32; offsets[n_bands] as usize];
    for (i, &(a, b)) in ranges.iter().enumerate() {
        for band in a..=b {
            let slot = &mut fill[band as usize];
            items[*slot as usize] = i as u32;
            *slot += 1;
        }
    }
    Bins { offsets, items }
}

/// One band's samples: rows `y0 .. y0 + rows` of the supersampled image.
struct Band {
    y0: u32,
    rows: u32,
    /// Width of the whole image in samples (the row stride).
    stride: u32,
    /// Width in samples the mesh and wire are drawn in.
    clip_width: u32,
    supersample: u32,
    depth: Vec<f32>,
    color: Vec<[u8; 3]>,
}

impl Band {
    fn new(vp: &Viewport, y0: u32, rows: u32, background: [u8; 3]) -> Self {
        let n = (rows * vp.full_width) as usize;
        Self {
            y0,
            rows,
            stride: vp.full_width,
            clip_width: vp.width,
            supersample: vp.supersample,
            depth: vec![f32::INFINITY; n],
            color: vec![background; n],
        }
    }

    /// The band rows and image columns (samples, inclusive) whose centres lie in the box.
    fn clip(&self, x: (f32, f32), y: (f32, f32)) -> Option<(u32, u32, u32, u32)> {
        let (ya, yb) = sample_rows(y.0, y.1, self.y0 + self.rows)?;
        let ya = ya.max(self.y0);
        let (xa, xb) = sample_rows(x.0, x.1, self.clip_width)?;
        (ya <= yb).then_some((xa, xb, ya, yb))
    }

    /// Z-buffered triangle with barycentric interpolation of the lit vertex colours.
    fn triangle(&mut self, [a, b, c]: [&ScreenVertex; 3]) {
        let area = edge(a, b, c.x, c.y);
        if area == 0.0 || !area.is_finite() {
            return;
        }
        let inv = 1.0 / area;
        let xs = (a.x.min(b.x).min(c.x), a.x.max(b.x).max(c.x));
        let ys = (a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y));
        let Some((xa, xb, ya, yb)) = self.clip(xs, ys) else {
            return;
        };
        for y in ya..=yb {
            let py = y as f32 + 0.5;
            let row = ((y - self.y0) * self.stride) as usize;
            for x in xa..=xb {
                let px = x as f32 + 0.5;
                let l0 = edge(b, c, px, py) * inv;
                let l1 = edge(c, a, px, py) * inv;
                let l2 = edge(a, b, px, py) * inv;
                if l0 < 0.0 || l1 < 0.0 || l2 < 0.0 {
                    continue;
                }
                let z = l0 * a.z + l1 * b.z + l2 * c.z;
                let i = row + x as usize;
                if z < self.depth[i] {
                    self.depth[i] = z;
                    self.color[i] = std::array::from_fn(|k| {
                        (l0 * a.rgb[k] + l1 * b.rgb[k] + l2 * c.rgb[k])
                            .round()
                            .clamp(0.0, 255.0) as u8
                    });
                }
            }
        }
    }

    /// A wire segment with round caps, `half_width` samples either side, drawn where its
    /// (biased) depth is not behind the surface. The z-buffer is not written, so wires do not
    /// hide each other and their order does not matter.
    fn segment(&mut self, s: &WireSegment, half_width: f32, color: [u8; 3]) {
        let (dx, dy) = (s.b[0] - s.a[0], s.b[1] - s.a[1]);
        let len2 = dx * dx + dy * dy;
        let hw = half_width;
        let xs = (s.a[0].min(s.b[0]) - hw, s.a[0].max(s.b[0]) + hw);
        let ys = (s.a[1].min(s.b[1]) - hw, s.a[1].max(s.b[1]) + hw);
        let Some((xa, xb, ya, yb)) = self.clip(xs, ys) else {
            return;
        };
        for y in ya..=yb {
            let py = y as f32 + 0.5;
            let (mut lo, mut hi) = (xa, xb);
            // Columns within the strip |cross(p - a, d)| ≤ hw·|d| on this row.
            if dy.abs() > 1e-3 * len2.sqrt() {
                let c = dx * (py - s.a[1]);
                let r = hw * len2.sqrt();
                let (u, v) = ((c - r) / dy, (c + r) / dy);
                let (u, v) = (s.a[0] + u.min(v), s.a[0] + u.max(v));
                lo = lo.max((u - 0.5).ceil().max(0.0) as u32);
                hi = hi.min((v - 0.5).floor().max(0.0) as u32);
            }
            let row = ((y - self.y0) * self.stride) as usize;
            for x in lo..=hi.min(xb) {
                let px = x as f32 + 0.5;
                let t = if len2 > 0.0 {
                    (((px - s.a[0]) * dx + (py - s.a[1]) * dy) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let (ex, ey) = (s.a[0] + t * dx - px, s.a[1] + t * dy - py);
                if ex * ex + ey * ey > hw * hw {
                    continue;
                }
                let z = s.a[2] + t * (s.b[2] - s.a[2]);
                let i = row + x as usize;
                if z <= self.depth[i] {
                    self.color[i] = color;
                }
            }
        }
    }

    /// Box filter of `supersample²` samples per pixel into `out` (this band's pixel rows).
    fn downsample(&self, out: &mut [u8], width: usize) {
        let s = self.supersample as usize;
        let n = (s * s) as u32;
        for (j, row) in out.chunks_mut(width * 3).enumerate() {
            for (i, px) in row.chunks_mut(3).enumerate() {
                let mut sum = [0u32; 3];
                for dy in 0..s {
                    let base = (j * s + dy) * self.stride as usize + i * s;
                    for c in &self.color[base..base + s] {
                        for k in 0..3 {
                            sum[k] += u32::from(c[k]);
                        }
                    }
                }
                for k in 0..3 {
                    px[k] = ((sum[k] + n / 2) / n) as u8;
                }
            }
        }
    }
}

/// Twice the signed area of `(a, b, p)`.
#[inline]
fn edge(a: &ScreenVertex, b: &ScreenVertex, px: f32, py: f32) -> f32 {
    (b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x)
}
