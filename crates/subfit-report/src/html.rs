//! Self-contained HTML reports (`report.html`): a page of sections (tables, SVG plots, text)
//! around a WebGL viewer of a [`Scene`] — meshes coloured by error, wireframes, points.
//!
//! Everything the page needs is inlined: the viewer script (three.js with its orbit controls,
//! bundled from npm at build time by `build.rs`, see [`VIEWER_BUILT`]), the style, the plots
//! and the geometry (base64 little-endian arrays in a JSON block), so the file opens by
//! double-click with no network. [`render`] returns the page; nothing here touches files.

use std::fmt::Write as _;

use base64::Engine as _;
use serde::Serialize;

use crate::color::error_color;

include!(concat!(env!("OUT_DIR"), "/viewer_built.rs"));

/// The bundled viewer script (or, when [`VIEWER_BUILT`] is false, a script saying why not).
const VIEWER_JS: &str = include_str!(concat!(env!("OUT_DIR"), "/viewer.js"));

/// What a scene layer draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LayerKind {
    /// Triangles (`indices` in threes), shaded, coloured per vertex when `colors` is given.
    Mesh,
    /// Line segments (`indices` in twos).
    Lines,
    /// Points (`indices` unused).
    Points,
}

/// One toggleable layer of a [`Scene`].
#[derive(Clone, Debug)]
pub struct Layer {
    /// Name shown beside its check box.
    pub name: String,
    /// What it draws.
    pub kind: LayerKind,
    /// Shown when the page opens.
    pub visible: bool,
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Triangles or segments as vertex indices (flattened).
    pub indices: Vec<u32>,
    /// Per-vertex colours (the error colours of [`error_color`]).
    pub colors: Option<Vec<[u8; 3]>>,
    /// Per-vertex values read out on a click (e.g. the distance to the data).
    pub values: Option<Vec<f32>>,
    /// What the values are, with their unit (`"distance to the data (mm)"`).
    pub value_label: String,
    /// Colour without per-vertex colours, `#rrggbb`.
    pub color: String,
}

impl Layer {
    /// A layer with no geometry yet.
    pub fn new(name: impl Into<String>, kind: LayerKind, color: &str) -> Self {
        Self {
            name: name.into(),
            kind,
            visible: true,
            positions: Vec::new(),
            indices: Vec::new(),
            colors: None,
            values: None,
            value_label: String::new(),
            color: color.into(),
        }
    }
}

/// The geometry shown in the viewer.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// The layers, drawn in order.
    pub layers: Vec<Layer>,
    /// The camera's up direction (`None`: +y).
    pub up: Option<[f64; 3]>,
    /// The colour scale drawn beside the viewer.
    pub color_scale: Option<ColorScale>,
}

/// The error colour scale: blue at 0 to red at `scale`, labelled in every unit given.
#[derive(Clone, Debug)]
pub struct ColorScale {
    /// The value shown red (and above), in the first unit.
    pub scale: f64,
    /// Units the labels are written in: a name and the factor from the first unit (the first
    /// is `("unit cube", 1.0)`; e.g. `("% of diagonal", 100 / diagonal)`).
    pub units: Vec<(String, f64)>,
    /// What is coloured (`"distance to the data"`).
    pub label: String,
}

/// A block of a section.
#[derive(Clone, Debug)]
pub enum Block {
    /// A paragraph of text (escaped).
    Text(String),
    /// A table: a header row and rows of cells (escaped).
    Table {
        /// Column headings.
        header: Vec<String>,
        /// Rows.
        rows: Vec<Vec<String>>,
    },
    /// Name/value pairs, as a two-column table.
    Pairs(Vec<(String, String)>),
    /// An SVG figure (trusted markup from [`crate::plot`]) with a caption.
    Figure {
        /// The `<svg>` element.
        svg: String,
        /// The caption (escaped).
        caption: String,
    },
    /// Preformatted text (escaped), e.g. a command line.
    Code(String),
}

/// A titled part of the page.
#[derive(Clone, Debug)]
pub struct Section {
    /// The heading.
    pub heading: String,
    /// Its blocks, in order.
    pub blocks: Vec<Block>,
}

/// A whole report page.
#[derive(Clone, Debug, Default)]
pub struct Page {
    /// The page title (and first heading).
    pub title: String,
    /// A line under the title (e.g. the headline errors).
    pub headline: String,
    /// The viewer's scene; `None` for a page of plots only.
    pub scene: Option<Scene>,
    /// The sections under the viewer.
    pub sections: Vec<Section>,
}

#[derive(Serialize)]
struct LayerJson<'a> {
    name: &'a str,
    kind: LayerKind,
    visible: bool,
    positions: String,
    indices: String,
    colors: Option<String>,
    values: Option<String>,
    value_label: &'a str,
    color: &'a str,
}

#[derive(Serialize)]
struct SceneJson<'a> {
    up: Option<[f64; 3]>,
    layers: Vec<LayerJson<'a>>,
}

fn b64(bytes: &[u8]) -> String {
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

fn f32_bytes<'a>(values: impl Iterator<Item = &'a f32>) -> Vec<u8> {
    values.flat_map(|v| v.to_le_bytes()).collect()
}

fn scene_json(scene: &Scene) -> String {
    let layers = scene
        .layers
        .iter()
        .map(|l| LayerJson {
            name: &l.name,
            kind: l.kind,
            visible: l.visible,
            positions: b64(&f32_bytes(l.positions.iter().flatten())),
            indices: b64(&l
                .indices
                .iter()
                .flat_map(|i| i.to_le_bytes())
                .collect::<Vec<u8>>()),
            colors: l.colors.as_ref().map(|c| b64(c.as_flattened())),
            values: l.values.as_ref().map(|v| b64(&f32_bytes(v.iter()))),
            value_label: &l.value_label,
            color: &l.color,
        })
        .collect();
    let json = serde_json::to_string(&SceneJson {
        up: scene.up,
        layers,
    })
    .expect("plain data serializes");
    // Inside <script>: no "</" may close the element early.
    json.replace("</", "<\\/")
}

/// Escapes text for HTML content and attribute values.
pub fn escape(text: &str) -> String {
    let mut s = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&#39;"),
            c => s.push(c),
        }
    }
    s
}

/// The colour bar as a vertical SVG gradient with its labels in every unit.
pub fn color_scale_svg(bar: &ColorScale) -> String {
    let (bar_x, top, height, width) = (10.0, 34.0, 300.0, 22.0);
    let columns = bar.units.len().max(1) as f64;
    let total_width = bar_x + width + 12.0 + 92.0 * columns;
    let mut s = String::new();
    let _ = write!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{total_width}" height="{}" font-family="sans-serif" font-size="11" role="img" aria-label="error colour scale">"#,
        top + height + 26.0
    );
    s.push_str(r#"<defs><linearGradient id="subfit-scale" x1="0" y1="1" x2="0" y2="0">"#);
    for k in 0..=12 {
        let t = k as f64 / 12.0;
        let [r, g, b] = error_color(t);
        let _ = write!(
            s,
            r#"<stop offset="{t:.4}" stop-color="rgb({r},{g},{b})"/>"#
        );
    }
    s.push_str("</linearGradient></defs>");
    let _ = write!(
        s,
        r#"<text x="{bar_x}" y="14" font-size="12">{}</text>"#,
        escape(&bar.label)
    );
    for (c, (unit, _)) in bar.units.iter().enumerate() {
        let x = bar_x + width + 12.0 + 92.0 * c as f64;
        let _ = write!(
            s,
            r##"<text x="{x}" y="28" fill="#444">{}</text>"##,
            escape(unit)
        );
    }
    let _ = write!(
        s,
        r##"<rect x="{bar_x}" y="{top}" width="{width}" height="{height}" fill="url(#subfit-scale)" stroke="#333"/>"##
    );
    for k in 0..=6 {
        let t = k as f64 / 6.0;
        let y = top + height * (1.0 - t);
        let _ = write!(
            s,
            r##"<line x1="{}" y1="{y:.1}" x2="{}" y2="{y:.1}" stroke="#333"/>"##,
            bar_x + width,
            bar_x + width + 5.0
        );
        for (c, (_, factor)) in bar.units.iter().enumerate() {
            let x = bar_x + width + 12.0 + 92.0 * c as f64;
            let value = t * bar.scale * factor;
            let text = if k == 6 {
                format!("≥ {}", number(value))
            } else {
                number(value)
            };
            let _ = write!(s, r#"<text x="{x}" y="{:.1}">{text}</text>"#, y + 4.0);
        }
    }
    s.push_str("</svg>");
    s
}

/// A number for a label: 3 significant digits, exponent form outside [1e-3, 1e4).
pub fn number(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if !v.is_finite() {
        format!("{v}")
    } else if (1e-3..1e4).contains(&v.abs()) {
        let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
        format!("{v:.digits$}")
    } else {
        format!("{v:.2e}")
    }
}

const STYLE: &str = "
body { font-family: system-ui, sans-serif; margin: 0 auto; max-width: 1280px; padding: 0 18px 40px; color: #222; }
h1 { font-size: 1.5em; margin: 18px 0 2px; } h2 { font-size: 1.15em; margin-top: 28px; border-bottom: 1px solid #ddd; }
.headline { color: #333; margin: 2px 0 12px; }
.viewer-row { display: flex; gap: 12px; align-items: flex-start; }
#subfit-viewer { flex: 1; height: 620px; border: 1px solid #ccc; background: #f4f4f4; position: relative; }
#subfit-viewer-controls { margin: 6px 0; display: flex; gap: 14px; flex-wrap: wrap; align-items: center; }
#subfit-viewer-readout { font-family: monospace; font-size: 0.9em; min-height: 1.2em; color: #333; }
.viewer-message { padding: 2em; color: #a00; }
table { border-collapse: collapse; margin: 8px 0; font-size: 0.92em; }
td, th { border: 1px solid #ddd; padding: 3px 8px; text-align: right; } th { background: #f2f2f2; }
td:first-child, th:first-child { text-align: left; }
table.pairs td { text-align: left; }
figure { display: inline-block; margin: 8px 12px 8px 0; vertical-align: top; }
figcaption { font-size: 0.85em; color: #555; max-width: 760px; }
pre { background: #f6f6f6; padding: 8px; overflow-x: auto; }
";

/// The page as one self-contained HTML document.
pub fn render(page: &Page) -> String {
    let mut s = String::with_capacity(1 << 20);
    let title = escape(&page.title);
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<meta name=\"generator\" content=\"subfit {}\">\n<title>{title}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<h1>{title}</h1>\n<p class=\"headline\" id=\"subfit-headline\">{}</p>\n",
        env!("CARGO_PKG_VERSION"),
        escape(&page.headline)
    );
    if let Some(scene) = &page.scene {
        s.push_str("<div id=\"subfit-viewer-controls\"></div>\n<div class=\"viewer-row\">\n<div id=\"subfit-viewer\"></div>\n");
        if let Some(bar) = &scene.color_scale {
            s.push_str("<div class=\"color-bar\">");
            s.push_str(&color_scale_svg(bar));
            s.push_str("</div>\n");
        }
        s.push_str("</div>\n<div id=\"subfit-viewer-readout\">Drag to turn, scroll to zoom, right-drag to pan; click the surface to read its value.</div>\n");
        s.push_str("<script id=\"subfit-scene\" type=\"application/json\">");
        s.push_str(&scene_json(scene));
        s.push_str("</script>\n");
    }
    for section in &page.sections {
        let _ = writeln!(s, "<h2>{}</h2>", escape(&section.heading));
        for block in &section.blocks {
            block_html(&mut s, block);
        }
    }
    if page.scene.is_some() {
        s.push_str("<script>\n");
        s.push_str(&VIEWER_JS.replace("</script", "<\\/script"));
        s.push_str("\nif (window.SUBFIT_VIEWER_MISSING) { document.getElementById('subfit-viewer').textContent = window.SUBFIT_VIEWER_MISSING; }\n</script>\n");
    }
    s.push_str("</body>\n</html>\n");
    s
}

fn block_html(s: &mut String, block: &Block) {
    match block {
        Block::Text(t) => {
            let _ = writeln!(s, "<p>{}</p>", escape(t));
        }
        Block::Code(t) => {
            let _ = writeln!(s, "<pre>{}</pre>", escape(t));
        }
        Block::Figure { svg, caption } => {
            let _ = writeln!(
                s,
                "<figure>{svg}<figcaption>{}</figcaption></figure>",
                escape(caption)
            );
        }
        Block::Pairs(pairs) => {
            s.push_str("<table class=\"pairs\">\n");
            for (k, v) in pairs {
                let _ = writeln!(s, "<tr><th>{}</th><td>{}</td></tr>", escape(k), escape(v));
            }
            s.push_str("</table>\n");
        }
        Block::Table { header, rows } => {
            s.push_str("<table>\n<tr>");
            for h in header {
                let _ = write!(s, "<th>{}</th>", escape(h));
            }
            s.push_str("</tr>\n");
            for row in rows {
                s.push_str("<tr>");
                for c in row {
                    let _ = write!(s, "<td>{}</td>", escape(c));
                }
                s.push_str("</tr>\n");
            }
            s.push_str("</table>\n");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn triangle_scene() -> Scene {
        let mut mesh = Layer::new("limit surface", LayerKind::Mesh, "#b0b0b0");
        mesh.positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        mesh.indices = vec![0, 1, 2];
        mesh.colors = Some(vec![[0, 0, 255], [0, 255, 0], [255, 0, 0]]);
        mesh.values = Some(vec![0.0, 0.5, 1.0]);
        Scene {
            layers: vec![mesh],
            up: None,
            color_scale: Some(ColorScale {
                scale: 1e-3,
                units: vec![("unit cube".into(), 1.0), ("% of diagonal".into(), 100.0)],
                label: "distance </script> & more".into(),
            }),
        }
    }

    #[test]
    fn page_is_self_contained_and_escaped() {
        let page = Page {
            title: "fit <of> \"x\"".into(),
            headline: "E_rms 1e-4".into(),
            scene: Some(triangle_scene()),
            sections: vec![Section {
                heading: "Summary".into(),
                blocks: vec![
                    Block::Pairs(vec![("input".into(), "a<b>.ply".into())]),
                    Block::Table {
                        header: vec!["a".into()],
                        rows: vec![vec!["1".into()]],
                    },
                ],
            }],
        };
        let html = render(&page);
        assert!(html.starts_with("<!DOCTYPE html>"));
        assert!(html.contains("fit &lt;of&gt; &quot;x&quot;"));
        assert!(html.contains("a&lt;b&gt;.ply"));
        // No external resources: nothing is loaded from a URL.
        for needle in ["src=\"http", "href=\"http", "<link ", "src=\"//"] {
            assert!(!html.contains(needle), "{needle}");
        }
        // Exactly one closing tag per opened script element.
        assert_eq!(
            html.matches("<script").count(),
            html.matches("</script>").count()
        );
        assert!(html.contains("id=\"subfit-scene\""));
        if VIEWER_BUILT {
            assert!(html.contains("OrbitControls") || html.len() > 100_000);
        }
    }

    #[test]
    fn scene_arrays_round_trip() {
        let scene = triangle_scene();
        let json: serde_json::Value = serde_json::from_str(&scene_json(&scene)).unwrap();
        let layer = &json["layers"][0];
        assert_eq!(layer["kind"], "mesh");
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(layer["positions"].as_str().unwrap())
            .unwrap();
        let floats: Vec<f32> = bytes
            .chunks(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(floats, vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
        let colors = base64::engine::general_purpose::STANDARD
            .decode(layer["colors"].as_str().unwrap())
            .unwrap();
        assert_eq!(colors, vec![0, 0, 255, 0, 255, 0, 255, 0, 0]);
    }

    #[test]
    fn numbers_for_labels() {
        assert_eq!(number(0.0), "0");
        assert_eq!(number(0.5), "0.500");
        assert_eq!(number(12.345), "12.3");
        assert_eq!(number(2e-5), "2.00e-5");
    }
}
