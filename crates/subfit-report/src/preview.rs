//! A CPU software rasterizer for `preview.png`: a triangle mesh in the error colours
//! ([`crate::error_color`], Cheng et al. 2007 §IV-D), optionally with the control cage as a
//! wireframe and a colour bar, for terminals, CI logs and READMEs where no WebGL viewer runs.
//!
//! The pipeline is the textbook one (Foley & van Dam, *Computer Graphics*, §15.4 z-buffer and
//! §16.2.4 Gouraud shading), in named steps:
//!
//! 1. [`Camera::frame`]: the view is auto-framed to the bounding sphere of the mesh and cage
//!    (centre of the bounding box, largest distance from it), so no near-plane clipping is ever
//!    needed: every vertex lies in front of the camera.
//! 2. `shade_vertices`: area-weighted vertex normals; each vertex's colour is lit by a headlight
//!    (a light at the eye), Lambert plus ambient, two-sided (`|n·l|`) so faces whose winding is
//!    flipped are shaded as their neighbours rather than black.
//! 3. `raster::render_bands`: the supersampled image (2×2 samples per pixel by default) is cut into
//!    bands of rows; triangles and wire edges are binned to the bands they overlap; each band is
//!    rasterized on its own (z-buffer, edge functions, barycentric interpolation of the lit vertex
//!    colours), wire edges drawn over it depth-tested with a bias, then box-filtered down to
//!    pixels. Bands run in parallel with rayon when the mesh or image is large.
//! 4. `colorbar::draw`: an optional vertical colour bar on the right with tick labels in a
//!    built-in 5×7 bitmap font (digits, `.`, `-`, `+`, `e`, `%`; other characters are blank).
//! 5. [`Image::to_png`]: RGB8 PNG bytes via the pure-Rust `png` crate.
//!
//! Output is deterministic for given input: bands own disjoint pixels and visit their triangles
//! in index order; ties in depth go to the lower triangle index; wire samples are overwritten
//! with one solid colour, so order does not matter.
//!
//! Cost: `O(#V + #T + #E + samples)` work, plus for each triangle the samples of its bounding
//! box; memory `O(#V + #T + w·h)`. About 1M triangles at 800×600 take well under a second in
//! release on two cores (`cargo run --release -p subfit-report --example preview_bench`).

mod colorbar;
mod raster;

use subfit_mesh::PolyMesh;

/// How 3-D points are projected. Both are framed on the bounding sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Parallel projection: sizes do not depend on depth; good for judging shapes and areas.
    Orthographic,
    /// Pinhole perspective with the given field of view across the smaller side of the
    /// viewport (degrees, clamped to `[1, 170]`).
    /// Colours and depth are interpolated affinely in screen space (1/z for depth): exact for
    /// depth, and the colour error is invisible for triangles a few pixels across.
    Perspective {
        /// Field of view in degrees.
        fov_y_deg: f64,
    },
}

/// Which world axis points up on the screen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UpAxis {
    /// `+y` up, `+z` towards the front (OBJ, PLY scans, three.js).
    Y,
    /// `+z` up, `-y` towards the front (Blender, CAD).
    Z,
}

/// Where the camera looks from. The camera always looks at the centre of the bounding sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Turn to the right of the front axis, degrees. Default `35`.
    pub azimuth_deg: f64,
    /// Height above the horizontal plane, degrees, in `[-89, 89]`. Default `25`.
    pub elevation_deg: f64,
    /// Which axis is up. Default [`UpAxis::Y`].
    pub up: UpAxis,
    /// Projection. Default [`Projection::Orthographic`].
    pub projection: Projection,
    /// The bounding sphere's radius as a fraction of half the smaller side of the viewport.
    /// Default `0.92`; `1` touches the edges.
    pub zoom: f64,
}

impl Default for View {
    /// A three-quarter view from the front-right-above, orthographic.
    fn default() -> Self {
        Self {
            azimuth_deg: 35.0,
            elevation_deg: 25.0,
            up: UpAxis::Y,
            projection: Projection::Orthographic,
            zoom: 0.92,
        }
    }
}

/// A wireframe overlay, e.g. the control cage: its own positions (`#C by 3`, same units as the
/// mesh) and edges (`#E by 2` indices into them).
#[derive(Clone, Copy, Debug)]
pub struct Wireframe<'a> {
    /// Wire vertex positions, `#C by 3`.
    pub positions: &'a [[f64; 3]],
    /// Edges as pairs of indices into `positions`, `#E by 2`.
    pub edges: &'a [[u32; 2]],
}

/// A vertical colour bar in the [`crate::error_color`] scale, labelled at 0, ⅓, ⅔ and 1 of
/// `max` (the colour stops blue, green, yellow, red).
#[derive(Clone, Debug, PartialEq)]
pub struct ColorBar {
    /// The value shown by red (the error scale the colours were made with), in the caller's
    /// units (e.g. unit-cube units, or percent of the diagonal with `suffix = "%"`).
    pub max: f64,
    /// Appended to every label, e.g. `"%"`. Only digits, `.`, `-`, `+`, `e`, `%` and space
    /// have glyphs; other characters are left blank.
    pub suffix: String,
}

/// How the preview is drawn. Every field has a documented default ([`Default`]).
#[derive(Clone, Debug, PartialEq)]
pub struct PreviewOptions {
    /// Image width in pixels, `1..=16384`. Default `800`.
    pub width: u32,
    /// Image height in pixels, `1..=16384`. Default `600`.
    pub height: u32,
    /// Camera. Default [`View::default`].
    pub view: View,
    /// Background colour. Default light grey `[240, 240, 240]`.
    pub background: [u8; 3],
    /// Samples per pixel along each axis (antialiasing), `1..=4`. Default `2` (2×2).
    pub supersample: u32,
    /// Ambient light, fraction of full brightness in `[0, 1]`; the headlight adds the rest
    /// times `|n·l|`. Default `0.3`.
    pub ambient: f64,
    /// Wire colour. Default dark grey `[30, 30, 30]`.
    pub wire_color: [u8; 3],
    /// Wire width in pixels. Default `1.0`.
    pub wire_width: f64,
    /// How far a wire may lie behind the surface and still be drawn, as a fraction of the
    /// bounding-sphere radius. Default `0.01`.
    pub wire_depth_bias: f64,
    /// Colour bar on the right; the mesh is framed in the rest of the image. Default `None`.
    pub color_bar: Option<ColorBar>,
}

impl Default for PreviewOptions {
    fn default() -> Self {
        Self {
            width: 800,
            height: 600,
            view: View::default(),
            background: [240, 240, 240],
            supersample: 2,
            ambient: 0.3,
            wire_color: [30, 30, 30],
            wire_width: 1.0,
            wire_depth_bias: 0.01,
            color_bar: None,
        }
    }
}

/// Why a preview could not be drawn.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PreviewError {
    /// No vertices or no triangles.
    #[error("nothing to draw: the mesh has {vertices} vertices and {triangles} triangles")]
    EmptyMesh {
        /// Number of vertices given.
        vertices: usize,
        /// Number of triangles given.
        triangles: usize,
    },
    /// Width, height or supersampling out of range.
    #[error("image size {width}x{height} with {supersample}x supersampling is out of range (1..=16384 pixels, 1..=4 samples)")]
    BadSize {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
        /// Requested supersampling.
        supersample: u32,
    },
    /// The colour array does not have one colour per vertex.
    #[error("{colors} colours for {vertices} vertices")]
    ColorCount {
        /// Number of colours given.
        colors: usize,
        /// Number of vertices given.
        vertices: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {triangle} refers to vertex {index}, but there are {vertices} vertices")]
    IndexOutOfRange {
        /// The triangle (after fan triangulation, for polygon meshes).
        triangle: usize,
        /// The offending index.
        index: u32,
        /// Number of vertices.
        vertices: usize,
    },
    /// A wire edge refers to a wire vertex that does not exist.
    #[error("wire edge {edge} refers to vertex {index}, but there are {vertices} wire vertices")]
    WireIndexOutOfRange {
        /// The edge.
        edge: usize,
        /// The offending index.
        index: u32,
        /// Number of wire vertices.
        vertices: usize,
    },
    /// A mesh or wire position is NaN or infinite.
    #[error("{what} vertex {vertex} has a non-finite coordinate")]
    NonFinite {
        /// `"mesh"` or `"wire"`.
        what: &'static str,
        /// The vertex.
        vertex: usize,
    },
    /// The PNG encoder failed (should not happen when writing to memory).
    #[error("PNG encoding failed: {0}")]
    Png(String),
}

/// An RGB8 image, rows top to bottom.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `height × width × 3` bytes, row-major, RGB.
    pub rgb: Vec<u8>,
}

impl Image {
    /// The colour of pixel `(x, y)` (`y = 0` is the top row).
    ///
    /// # Panics
    /// If the pixel is outside the image.
    #[track_caller]
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside the image"
        );
        let i = 3 * (y as usize * self.width as usize + x as usize);
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    /// Encodes the image as PNG (RGB, 8 bits, default compression). Deterministic.
    pub fn to_png(&self) -> Result<Vec<u8>, PreviewError> {
        let mut out = Vec::new();
        let mut enc = png::Encoder::new(&mut out, self.width, self.height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let png_err = |e: png::EncodingError| PreviewError::Png(e.to_string());
        let mut writer = enc.write_header().map_err(png_err)?;
        writer.write_image_data(&self.rgb).map_err(png_err)?;
        writer.finish().map_err(png_err)?;
        Ok(out)
    }
}

/// Renders a triangle mesh with per-vertex colours (and optionally a wireframe) to an image.
///
/// * `positions`: `#V by 3`; `triangles`: `#T by 3` indices into `positions`;
///   `colors`: `#V by 3`, e.g. [`crate::error_color`] of each vertex's error.
///
/// Errors: an empty mesh, a bad size, a colour count other than `#V`, an index out of range or
/// a non-finite position ([`PreviewError`]). Degenerate triangles are skipped silently.
/// Cost: see the module docs.
pub fn render(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    colors: &[[u8; 3]],
    wireframe: Option<Wireframe<'_>>,
    options: &PreviewOptions,
) -> Result<Image, PreviewError> {
    validate(positions, triangles, colors, wireframe, options)?;
    let s = options.supersample;
    let bar = options
        .color_bar
        .as_ref()
        .map(|b| colorbar::layout(b, options));
    let bar_width = bar.as_ref().map_or(0, |b| b.width);
    let viewport = raster::Viewport {
        width: (options.width - bar_width.min(options.width - 1)) * s,
        full_width: options.width * s,
        height: options.height * s,
        supersample: s,
    };
    let camera = Camera::frame(positions, wireframe, &options.view, &viewport);
    let verts = shade_vertices(positions, triangles, colors, &camera, options.ambient);
    let wire = wireframe.map(|w| raster::project_wire(w, &camera, options));
    let mut image = raster::render_bands(&verts, triangles, wire.as_ref(), &viewport, options);
    if let Some(bar) = bar {
        colorbar::draw(&mut image, &bar);
    }
    Ok(image)
}

/// [`render`] for a polygon mesh: faces are fan-triangulated
/// ([`subfit_mesh::Polygons::triangulate_fan`]); `colors` is `#V by 3`.
pub fn render_polymesh(
    mesh: &PolyMesh,
    colors: &[[u8; 3]],
    wireframe: Option<Wireframe<'_>>,
    options: &PreviewOptions,
) -> Result<Image, PreviewError> {
    let triangles = mesh.faces.triangulate_fan();
    render(&mesh.positions, &triangles, colors, wireframe, options)
}

/// [`render`] then [`Image::to_png`]: the bytes of `preview.png`.
pub fn preview_png(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    colors: &[[u8; 3]],
    wireframe: Option<Wireframe<'_>>,
    options: &PreviewOptions,
) -> Result<Vec<u8>, PreviewError> {
    render(positions, triangles, colors, wireframe, options)?.to_png()
}

fn validate(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    colors: &[[u8; 3]],
    wireframe: Option<Wireframe<'_>>,
    o: &PreviewOptions,
) -> Result<(), PreviewError> {
    let n = positions.len();
    if n == 0 || triangles.is_empty() {
        return Err(PreviewError::EmptyMesh {
            vertices: n,
            triangles: triangles.len(),
        });
    }
    let size_ok = |v: u32| (1..=16384).contains(&v);
    if !size_ok(o.width) || !size_ok(o.height) || !(1..=4).contains(&o.supersample) {
        return Err(PreviewError::BadSize {
            width: o.width,
            height: o.height,
            supersample: o.supersample,
        });
    }
    if colors.len() != n {
        return Err(PreviewError::ColorCount {
            colors: colors.len(),
            vertices: n,
        });
    }
    for (t, tri) in triangles.iter().enumerate() {
        if let Some(&index) = tri.iter().find(|&&i| i as usize >= n) {
            return Err(PreviewError::IndexOutOfRange {
                triangle: t,
                index,
                vertices: n,
            });
        }
    }
    check_finite(positions, "mesh")?;
    if let Some(w) = wireframe {
        check_finite(w.positions, "wire")?;
        let m = w.positions.len();
        for (e, edge) in w.edges.iter().enumerate() {
            if let Some(&index) = edge.iter().find(|&&i| i as usize >= m) {
                return Err(PreviewError::WireIndexOutOfRange {
                    edge: e,
                    index,
                    vertices: m,
                });
            }
        }
    }
    Ok(())
}

fn check_finite(points: &[[f64; 3]], what: &'static str) -> Result<(), PreviewError> {
    match points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        Some(vertex) => Err(PreviewError::NonFinite { what, vertex }),
        None => Ok(()),
    }
}

/// A camera framed on a bounding sphere, mapping world points to supersampled screen
/// coordinates (`x` right, `y` down, in samples) and a depth key (smaller is nearer, affine in
/// screen space).
#[derive(Clone, Debug)]
pub(crate) struct Camera {
    center: [f64; 3],
    right: [f64; 3],
    up: [f64; 3],
    /// From the eye towards the centre.
    forward: [f64; 3],
    /// Bounding-sphere radius (1 for a single point).
    radius: f64,
    /// Eye distance from the centre (perspective), or `2 · radius` (orthographic: only depth).
    distance: f64,
    /// Samples per world unit (orthographic) or focal length in samples (perspective).
    scale: f64,
    perspective: bool,
    cx: f64,
    cy: f64,
}

impl Camera {
    /// Frames the bounding sphere of `positions` and the wire's positions in the viewport.
    fn frame(
        positions: &[[f64; 3]],
        wireframe: Option<Wireframe<'_>>,
        view: &View,
        vp: &raster::Viewport,
    ) -> Self {
        let wire = wireframe.map_or(&[][..], |w| w.positions);
        let all = || positions.iter().chain(wire.iter());
        let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
        for p in all() {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let center: [f64; 3] = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
        let r2 = all().map(|p| dist2(p, &center)).fold(0.0, f64::max);
        let radius = if r2 > 0.0 { r2.sqrt() } else { 1.0 };

        let (az, el) = (
            view.azimuth_deg.to_radians(),
            view.elevation_deg.clamp(-89.0, 89.0).to_radians(),
        );
        // Direction from the centre to the eye in a y-up frame with +z at the front.
        let eye_dir = [az.sin() * el.cos(), el.sin(), az.cos() * el.cos()];
        let (to_world, world_up) = match view.up {
            UpAxis::Y => (
                [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                [0.0, 1.0, 0.0],
            ),
            // x stays right, y-up becomes z-up, the front +z becomes -y.
            UpAxis::Z => (
                [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]],
                [0.0, 0.0, 1.0],
            ),
        };
        let e: [f64; 3] =
            std::array::from_fn(|k| (0..3).map(|j| to_world[j][k] * eye_dir[j]).sum());
        let forward = [-e[0], -e[1], -e[2]];
        let right = normalize(cross(&forward, &world_up));
        let up = cross(&right, &forward);

        let half = 0.5 * f64::from(vp.width.min(vp.height));
        let zoom = if view.zoom > 0.0 { view.zoom } else { 0.92 };
        let (perspective, distance, scale) = match view.projection {
            Projection::Orthographic => (false, 2.0 * radius, zoom * half / radius),
            Projection::Perspective { fov_y_deg } => {
                let t = (0.5 * fov_y_deg.clamp(1.0, 170.0)).to_radians().tan();
                // The sphere's silhouette (half-angle α, sin α = r / d) spans `zoom · half`.
                let alpha = (zoom * t).atan();
                (true, radius / alpha.sin(), half / t)
            }
        };
        Self {
            center,
            right,
            up,
            forward,
            radius,
            distance,
            scale,
            perspective,
            cx: 0.5 * f64::from(vp.width),
            cy: 0.5 * f64::from(vp.height),
        }
    }

    /// Screen `(x, y)` in samples and the eye-space depth (positive, world units).
    fn project(&self, p: &[f64; 3]) -> (f64, f64, f64) {
        let q = sub(p, &self.center);
        let (x, y) = (dot(&q, &self.right), dot(&q, &self.up));
        let d = dot(&q, &self.forward) + self.distance;
        let s = if self.perspective {
            self.scale / d
        } else {
            self.scale
        };
        (self.cx + s * x, self.cy - s * y, d)
    }

    /// The depth key of eye depth `d`: affine in screen space, smaller is nearer.
    fn depth_key(&self, d: f64) -> f32 {
        if self.perspective {
            (-self.distance / d) as f32
        } else {
            (d / self.radius) as f32
        }
    }

    /// Unit vector from `p` towards the light (the eye).
    fn light_dir(&self, p: &[f64; 3]) -> [f64; 3] {
        if self.perspective {
            let eye: [f64; 3] =
                std::array::from_fn(|k| self.center[k] - self.distance * self.forward[k]);
            normalize(sub(&eye, p))
        } else {
            [-self.forward[0], -self.forward[1], -self.forward[2]]
        }
    }
}

/// A projected, lit vertex.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ScreenVertex {
    x: f32,
    y: f32,
    z: f32,
    rgb: [f32; 3],
}

/// Projects every vertex and lights its colour: two-sided Lambert from a headlight plus ambient,
/// on area-weighted vertex normals (a vertex in no triangle keeps its colour at ambient light).
fn shade_vertices(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    colors: &[[u8; 3]],
    camera: &Camera,
    ambient: f64,
) -> Vec<ScreenVertex> {
    use rayon::prelude::*;
    let mut normals = vec![[0.0f64; 3]; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| &positions[i as usize]);
        let n = cross(&sub(b, a), &sub(c, a));
        for &i in t {
            let acc = &mut normals[i as usize];
            for k in 0..3 {
                acc[k] += n[k];
            }
        }
    }
    let ambient = ambient.clamp(0.0, 1.0);
    positions
        .par_iter()
        .with_min_len(4096)
        .zip(normals.par_iter())
        .zip(colors.par_iter())
        .map(|((p, n), c)| {
            let (x, y, d) = camera.project(p);
            let len = dot(n, n).sqrt();
            let lambert = if len > 0.0 {
                (dot(n, &camera.light_dir(p)) / len).abs()
            } else {
                0.0
            };
            let light = (ambient + (1.0 - ambient) * lambert) as f32;
            ScreenVertex {
                x: x as f32,
                y: y as f32,
                z: camera.depth_key(d),
                rgb: c.map(|v| f32::from(v) * light),
            }
        })
        .collect()
}

fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn dist2(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let d = sub(a, b);
    dot(&d, &d)
}

fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = dot(&a, &a).sqrt();
    if l > 0.0 {
        a.map(|v| v / l)
    } else {
        a
    }
}

#[cfg(test)]
mod tests;
