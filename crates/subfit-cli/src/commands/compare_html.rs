//! `subfit compare A B --html OUT.html`: both surfaces in one viewer, each coloured by its
//! distance to the other (the papers' scale, red at the Hausdorff distance), with the two
//! distance histograms. A control mesh compared through `--scheme` is shown as its limit
//! surface; a surface larger than the viewer's budget is shown as a subset of its vertices.

use anyhow::Context;
use rayon::prelude::*;
use subfit::measure::DistanceStats;
use subfit::mesh::{PolyMesh, Tags};
use subfit::report::error_color;
use subfit::report::html::{self, Block, ColorScale, Layer, LayerKind, Page, Scene, Section};
use subfit::report::plot::{histogram_chart, HistogramOptions};
use subfit::subdiv::{sampling_operator, Options};
use subfit::target::TriangleBvh;
use subfit::{VIEW_POINTS, VIEW_TRIANGLES};

use crate::cli::CompareArgs;

/// What is drawn of one side: positions with triangles (none: points).
struct Shown {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
}

/// A's limit surface (with `scheme`) or A itself, within the viewer's budget.
fn shown(mesh: &PolyMesh, scheme: Option<(&Options, &Tags)>) -> anyhow::Result<Shown> {
    if let Some((options, tags)) = scheme {
        let per_level = |l: u32| mesh.faces.len() * 4usize.pow(l) * 2;
        let level = (1..=6u32)
            .take_while(|&l| per_level(l) <= VIEW_TRIANGLES)
            .last()
            .unwrap_or(1);
        let op = sampling_operator(
            &mesh.faces,
            mesh.positions.len(),
            tags,
            options,
            level as usize,
        )
        .context("cannot tessellate the limit surface")?;
        return Ok(Shown {
            positions: op.position.apply(&mesh.positions),
            triangles: op.faces.triangulate_fan(),
        });
    }
    let triangles = mesh.faces.triangulate_fan();
    if !triangles.is_empty() && triangles.len() <= VIEW_TRIANGLES {
        return Ok(Shown {
            positions: mesh.positions.clone(),
            triangles,
        });
    }
    let stride = mesh.positions.len().div_ceil(VIEW_POINTS).max(1);
    Ok(Shown {
        positions: mesh.positions.iter().step_by(stride).copied().collect(),
        triangles: Vec::new(),
    })
}

fn layer(name: &str, s: &Shown, distances: &[f64], scale: f64, color: &str) -> Layer {
    let kind = if s.triangles.is_empty() {
        LayerKind::Points
    } else {
        LayerKind::Mesh
    };
    let mut l = Layer::new(name, kind, color);
    l.positions = s
        .positions
        .iter()
        .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32])
        .collect();
    l.indices = s.triangles.as_flattened().to_vec();
    l.colors = Some(distances.iter().map(|&d| error_color(d / scale)).collect());
    l.values = Some(distances.iter().map(|&d| d as f32).collect());
    l.value_label = "distance to the other surface".into();
    l
}

/// The page; `to_b` measures a distance to B, `ab`/`ba` are the comparison's statistics and
/// `dab`/`dba` its distances.
#[allow(clippy::too_many_arguments)]
pub fn page(
    a: &CompareArgs,
    ma: &PolyMesh,
    mb: &PolyMesh,
    scheme: Option<(&Options, &Tags)>,
    to_b: impl Fn([f64; 3]) -> f64 + Sync,
    ab: &DistanceStats,
    ba: &DistanceStats,
    dab: &[f64],
    dba: &[f64],
    diagonal: f64,
) -> anyhow::Result<String> {
    let sa = shown(ma, scheme)?;
    let sb = shown(mb, None)?;
    let da: Vec<f64> = sa.positions.par_iter().map(|&x| to_b(x)).collect();
    // B's vertices against what is shown of A (its limit tessellation: within its chordal
    // error of the exact distance) or A's own triangles.
    let a_tris = if sa.triangles.is_empty() {
        ma.faces.triangulate_fan()
    } else {
        sa.triangles.clone()
    };
    let a_vertices = if sa.triangles.is_empty() {
        ma.positions.clone()
    } else {
        sa.positions.clone()
    };
    let db: Vec<f64> = if a_tris.is_empty() {
        let index = subfit::target::PointIndex::new(&a_vertices).context("cannot index A")?;
        sb.positions
            .par_iter()
            .map(|x| index.nearest(x).distance)
            .collect()
    } else {
        let bvh = TriangleBvh::new(a_vertices, a_tris);
        sb.positions
            .par_iter()
            .map(|&x| bvh.closest(x).map_or(f64::INFINITY, |c| c.distance))
            .collect()
    };
    let scale = ab.max.max(ba.max).max(f64::MIN_POSITIVE);
    let name_a = a.a.display().to_string();
    let name_b = a.b.display().to_string();
    let mut layer_b = layer(&format!("B: {name_b}"), &sb, &db, scale, "#909090");
    layer_b.visible = false;
    let scene = Scene {
        layers: vec![
            layer(&format!("A: {name_a}"), &sa, &da, scale, "#b0b0b0"),
            layer_b,
        ],
        up: None,
        color_scale: Some(ColorScale {
            scale,
            units: vec![
                ("input units".into(), 1.0),
                (
                    "% of B's diagonal".into(),
                    100.0 / diagonal.max(f64::MIN_POSITIVE),
                ),
            ],
            label: "distance to the other surface".into(),
        }),
    };
    let pct = |v: f64| format!("{}%", html::number(100.0 * v / diagonal));
    let row = |name: &str, d: &DistanceStats| {
        vec![
            name.to_string(),
            d.samples.to_string(),
            html::number(d.rms),
            html::number(d.mean),
            html::number(d.max),
            pct(d.rms),
            pct(d.max),
        ]
    };
    let histogram = histogram_chart(
        "Distances both ways",
        &[("A → B", dab), ("B → A", dba)],
        &HistogramOptions {
            unit: "input units".into(),
            ..HistogramOptions::default()
        },
    );
    let page = Page {
        title: format!("subfit compare: {name_a} and {name_b}"),
        headline: format!(
            "Hausdorff distance {} ({} of B's diagonal); RMS A → B {}, B → A {}.",
            html::number(scale),
            pct(scale),
            html::number(ab.rms),
            html::number(ba.rms)
        ),
        scene: Some(scene),
        sections: vec![
            Section {
                heading: "Distances".into(),
                blocks: vec![
                    Block::Table {
                        header: [
                            "direction",
                            "samples",
                            "RMS",
                            "mean",
                            "max",
                            "RMS / diagonal",
                            "max / diagonal",
                        ]
                        .map(String::from)
                        .to_vec(),
                        rows: vec![row("A → B", ab), row("B → A", ba)],
                    },
                    Block::Text(if scheme.is_some() {
                        "A is a control mesh: its exact limit surface is measured (exact closest points) and shown tessellated.".into()
                    } else {
                        "Both are measured as given (samples uniform by area, exact point–triangle distances).".into()
                    }),
                ],
            },
            Section {
                heading: "Plots".into(),
                blocks: vec![Block::Figure {
                    svg: histogram,
                    caption: "Fraction of each direction's samples per logarithmic distance bin."
                        .into(),
                }],
            },
        ],
    };
    Ok(html::render(&page))
}
