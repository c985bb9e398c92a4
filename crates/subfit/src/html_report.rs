//! What a person looks at after a fit: `report.html` (the limit surface coloured by its
//! distance to the data on the papers' scale — Cheng 2007 §IV-D — with the cage as a wireframe
//! and the target's points, orbit controls and a colour bar, then the summary, the plots and
//! the stage table) and `preview.png` (the same surface rendered on the CPU).
//!
//! Large limit tessellations are shown at a coarser level of the same limit surface (at most
//! [`VIEW_TRIANGLES`] triangles), each vertex with its own distance to the data, so the page
//! stays small and quick; the files written beside it keep the full resolution.

use subfit_fit::{DataTerm, FootPointTerm};
use subfit_measure::DistanceStats;
use subfit_mesh::PolyMesh;
use subfit_report::html::{Block, ColorScale, Layer, LayerKind, Page, Scene, Section};
use subfit_report::plot::{
    bar_chart, histogram_chart, log_chart_with, Bar, HistogramOptions, LogChartOptions, Series,
};
use subfit_report::preview::ColorBar as PreviewColorBar;
use subfit_report::{error_color, preview_png, PreviewOptions, Wireframe};
use subfit_subdiv::{sampling_operator, Scheme};

use crate::error::Error;
use crate::fitted::Fitted;

/// Most triangles shown in the viewer.
pub const VIEW_TRIANGLES: usize = 300_000;
/// Most target points shown in the viewer.
pub const VIEW_POINTS: usize = 200_000;

/// The limit surface as shown: positions in the input's coordinates, triangles, and each
/// vertex's distance to the data (unit cube) with its colour.
#[derive(Clone, Debug)]
pub struct ViewMesh {
    /// Positions, input coordinates.
    pub positions: Vec<[f64; 3]>,
    /// Triangles (polygons fan-triangulated).
    pub triangles: Vec<[u32; 3]>,
    /// Distance of each vertex to the data, unit-cube units.
    pub errors: Vec<f64>,
    /// The error colour of each vertex.
    pub colors: Vec<[u8; 3]>,
    /// The refinement level shown.
    pub level: usize,
}

impl Fitted {
    /// The error colour scale (unit cube): the one asked for (`--error-scale`), else the
    /// final surface → data `E_max`.
    pub fn error_scale(&self) -> f64 {
        let asked = self.report.error_color_scale_unit_cube;
        if asked > 0.0 {
            asked
        } else {
            self.stages.report.last.e_max.max(f64::MIN_POSITIVE)
        }
    }

    /// The limit surface as the viewer and the preview show it: the written tessellation when
    /// it has at most [`VIEW_TRIANGLES`] triangles, else the finest coarser level that has,
    /// with its own distances to the data.
    pub fn view_mesh(&self) -> Result<ViewMesh, Error> {
        let triangles = |faces: &subfit_mesh::Polygons| {
            faces
                .iter()
                .map(|f| f.len().saturating_sub(2))
                .sum::<usize>()
        };
        let written = self.report.limit_tessellation.level;
        let full = triangles(&self.limit.faces);
        let (positions, faces, errors, level) = if full <= VIEW_TRIANGLES {
            (
                self.limit.positions.clone(),
                self.limit.faces.clone(),
                self.local_error.clone(),
                written,
            )
        } else {
            // Each level down has a quarter of the triangles.
            let mut level = written;
            let mut count = full;
            while level > 1 && count > VIEW_TRIANGLES {
                level -= 1;
                count /= 4;
            }
            let cage = &self.normalized;
            let op = sampling_operator(
                &cage.faces,
                cage.positions.len(),
                &self.tags,
                &self.fit.subdivision(),
                level,
            )
            .map_err(|e| Error::Output(e.to_string()))?;
            let positions = op.position.apply(&cage.positions);
            let term = FootPointTerm::from_options(&self.target, &self.fit);
            let mut err2 = term.squared_errors(&positions);
            term.measured_errors(&positions, &mut err2);
            let errors = err2.into_iter().map(f64::sqrt).collect();
            (positions, op.faces, errors, level)
        };
        let scale = self.error_scale();
        Ok(ViewMesh {
            positions: positions
                .iter()
                .map(|&p| self.target.to_original(p))
                .collect(),
            triangles: faces.triangulate_fan(),
            colors: errors.iter().map(|&e| error_color(e / scale)).collect(),
            errors,
            level,
        })
    }

    /// `preview.png`: the shown limit surface in error colours with the cage as a wireframe and
    /// the colour scale in percent of the bounding-box diagonal, rendered on the CPU.
    pub fn preview_png(&self, view: &ViewMesh) -> Result<Vec<u8>, Error> {
        let edges = edges(&self.cage);
        let options = PreviewOptions {
            width: 960,
            height: 720,
            color_bar: Some(PreviewColorBar {
                max: 100.0 * self.error_scale() / self.report.bbox_diagonal_unit_cube,
                suffix: "%".into(),
            }),
            ..PreviewOptions::default()
        };
        preview_png(
            &view.positions,
            &view.triangles,
            &view.colors,
            Some(Wireframe {
                positions: &self.cage.positions,
                edges: &edges,
            }),
            &options,
        )
        .map_err(|e| Error::Output(format!("preview.png: {e}")))
    }

    /// The self-contained `report.html` page (see the module docs).
    pub fn report_html(&self, view: &ViewMesh) -> String {
        subfit_report::html::render(&self.report_page(view))
    }

    fn report_page(&self, view: &ViewMesh) -> Page {
        let r = &self.report;
        let two = &r.r#final.two_sided;
        let unit = r.normalized_unit_in_original_units;
        let diagonal = r.bbox_diagonal_unit_cube;
        let headline = format!(
            "{} control points ({}), two-sided E_rms {} and E_max {} of the bounding-box diagonal ({} / {} in the input's units); {}.",
            r.control_points,
            scheme_name(self.scheme),
            percent(two.e_rms_fraction_of_diagonal),
            percent(two.e_max_fraction_of_diagonal),
            sig(two.e_rms_original_units),
            sig(two.e_max_original_units),
            if r.tolerance_reached {
                "tolerance reached"
            } else {
                "tolerance not reached"
            }
        );
        Page {
            title: format!("subfit: {}", r.target),
            headline,
            scene: Some(self.scene(view, unit, diagonal)),
            sections: vec![
                self.summary_section(view),
                self.plot_section(),
                self.stage_section(),
            ],
        }
    }

    fn scene(&self, view: &ViewMesh, unit: f64, diagonal: f64) -> Scene {
        let f32s = |p: &[[f64; 3]]| -> Vec<[f32; 3]> {
            p.iter()
                .map(|q| [q[0] as f32, q[1] as f32, q[2] as f32])
                .collect()
        };
        let mut surface = Layer::new("limit surface", LayerKind::Mesh, "#b8b8b8");
        surface.positions = f32s(&view.positions);
        surface.indices = view.triangles.as_flattened().to_vec();
        surface.colors = Some(view.colors.clone());
        surface.values = Some(view.errors.iter().map(|&e| (e * unit) as f32).collect());
        surface.value_label = "distance to the data (input units)".into();

        let mut cage = Layer::new("cage", LayerKind::Lines, "#202020");
        cage.positions = f32s(&self.cage.positions);
        cage.indices = edges(&self.cage).into_iter().flatten().collect();

        let mut points = Layer::new("target points", LayerKind::Points, "#3a6ea5");
        let all = self.target.points();
        let stride = all.len().div_ceil(VIEW_POINTS).max(1);
        let shown: Vec<[f64; 3]> = all
            .iter()
            .step_by(stride)
            .map(|&p| self.target.to_original(p))
            .collect();
        points.positions = f32s(&shown);
        points.visible = false;
        points.name = if stride > 1 {
            format!("target points (1 in {stride})")
        } else {
            "target points".into()
        };

        Scene {
            layers: vec![surface, cage, points],
            up: None,
            color_scale: Some(ColorScale {
                scale: self.error_scale(),
                units: vec![
                    ("unit cube".into(), 1.0),
                    ("% of diagonal".into(), 100.0 / diagonal),
                    ("input units".into(), unit),
                ],
                label: "distance to the data".into(),
            }),
        }
    }

    fn summary_section(&self, view: &ViewMesh) -> Section {
        let r = &self.report;
        let o = &r.options;
        let two = &r.r#final.two_sided;
        let quads = self.cage.faces.iter().filter(|f| f.len() == 4).count();
        let faces = self.cage.faces.len().max(1);
        let yes = |b: bool| if b { "yes" } else { "no" }.to_string();
        let dist = |d: &DistanceStats| {
            format!(
                "RMS {} / max {} (unit cube); {} / {} of the diagonal",
                sig(d.rms),
                sig(d.max),
                percent(d.rms / r.bbox_diagonal_unit_cube),
                percent(d.max / r.bbox_diagonal_unit_cube)
            )
        };
        let mut pairs = vec![
            ("input".into(), r.target.clone()),
            ("target points".into(), r.target_points.to_string()),
            (
                "target topology".into(),
                r.target_topology
                    .as_ref()
                    .map(|t| format!("genus {}, {} boundary loops", t.genus, t.boundary_loops))
                    .unwrap_or_else(|| "point cloud".into()),
            ),
            ("scheme".into(), scheme_name(self.scheme).into()),
            (
                "method".into(),
                format!(
                    "{} with {} steps, λ {} → {}, sample level {}",
                    o.method,
                    o.step,
                    sig(o.lambda_start),
                    sig(o.lambda_end),
                    o.sample_level
                ),
            ),
            (
                "tolerance (unit cube)".into(),
                format!(
                    "RMS {}{}{}, judged {}",
                    sig(o.tolerance_rms),
                    r.noise_floored_tolerance
                        .map(|t| format!(" (noisy scan: judged as {})", sig(t)))
                        .unwrap_or_default(),
                    o.tolerance_max
                        .map(|m| format!(", max {}", sig(m)))
                        .unwrap_or_default(),
                    if o.two_sided {
                        "both ways"
                    } else {
                        "surface → data only"
                    }
                ),
            ),
            (
                "initial cage".into(),
                format!(
                    "{} with {} control points (genus {}){}",
                    r.init.source,
                    r.init.control_points,
                    r.init.genus,
                    cross_field_note(r.init.cross_field.as_ref())
                ),
            ),
            (
                "control points".into(),
                format!("{} (budget {})", r.control_points, o.max_control_points),
            ),
            (
                "faces".into(),
                format!(
                    "{} ({:.0}% quads)",
                    self.cage.faces.len(),
                    100.0 * quads as f64 / faces as f64
                ),
            ),
            (
                "tags".into(),
                format!("{} crease edges, {} corners", r.tags.creases, r.tags.corners),
            ),
            (
                "surface → data".into(),
                dist(&two.surface_to_data),
            ),
            (
                "data → surface".into(),
                dist(&two.data_to_surface),
            ),
            ("tolerance reached".into(), yes(r.tolerance_reached)),
            ("stopped because".into(), r.stop.clone()),
            ("best stage (written)".into(), r.best_stage.to_string()),
            (
                "time".into(),
                format!(
                    "{:.2} s (read {:.2}, analyse {:.2}, initial cage {:.2}, fit {:.2}, measure {:.2}, write {:.2})",
                    r.timings_s.total,
                    r.timings_s.read,
                    r.timings_s.preprocess,
                    r.timings_s.init,
                    r.timings_s.fit,
                    r.timings_s.measure,
                    r.timings_s.output
                ),
            ),
            (
                "shown".into(),
                format!(
                    "limit surface at level {} ({} triangles; the written limit.ply is level {})",
                    view.level,
                    view.triangles.len(),
                    r.limit_tessellation.level
                ),
            ),
        ];
        for w in &r.warnings {
            pairs.push(("warning".into(), w.clone()));
        }
        Section {
            heading: "Summary".into(),
            blocks: vec![Block::Pairs(pairs)],
        }
    }

    fn plot_section(&self) -> Section {
        let r = &self.report;
        let o = &r.options;
        let along = |f: fn(&crate::pipeline_report::Errors) -> f64| -> Vec<(f64, f64)> {
            r.iterations
                .iter()
                .enumerate()
                .map(|(i, it)| (i as f64 + 1.0, f(&it.errors)))
                .collect()
        };
        // Stage k starts after the iterations of the stages before it.
        let mut vlines = Vec::new();
        let mut done = 0usize;
        for s in &r.stages {
            vlines.push((
                done as f64 + 0.5,
                format!("stage {}, λ = {}", s.stage, sig(s.lambda)),
            ));
            done += s.iterations;
        }
        let mut hlines = vec![(
            r.noise_floored_tolerance.unwrap_or(o.tolerance_rms),
            "RMS tolerance".to_string(),
        )];
        if let Some(m) = o.tolerance_max {
            hlines.push((m, "max tolerance".into()));
        }
        let errors = log_chart_with(
            "Error per iteration (surface → data, the fitter's samples)",
            "iteration",
            "error (unit cube)",
            &[
                Series {
                    name: "E_rms".into(),
                    points: along(|e| e.e_rms),
                },
                Series {
                    name: "E_max".into(),
                    points: along(|e| e.e_max),
                },
            ],
            &LogChartOptions {
                vlines,
                hlines,
                ..LogChartOptions::default()
            },
        );
        let points = bar_chart(
            "Control points per stage",
            "control points",
            &r.stages
                .iter()
                .map(|s| {
                    Bar::new(
                        format!("stage {} (λ {})", s.stage, sig(s.lambda)),
                        s.control_points as f64,
                    )
                })
                .collect::<Vec<_>>(),
        );
        let two = &r.r#final.two_sided;
        let histogram = histogram_chart(
            "Distances of the written cage, both ways",
            &[
                ("surface → data", &self.local_error),
                ("data → surface", &self.data_error),
            ],
            &HistogramOptions {
                unit: "unit cube".into(),
                vlines: vec![
                    (two.surface_to_data.rms, "RMS surface → data".into()),
                    (two.data_to_surface.rms, "RMS data → surface".into()),
                    (o.tolerance_rms, "RMS tolerance".into()),
                ],
                ..HistogramOptions::default()
            },
        );
        let t = &r.timings_s;
        let phases = bar_chart(
            "Time per phase",
            "seconds",
            &[
                ("read", t.read),
                ("analyse the target", t.preprocess),
                ("initial cage", t.init),
                ("fit", t.fit),
                ("measure both ways", t.measure),
                ("write", t.output),
            ]
            .map(|(name, v)| Bar::new(name, v)),
        );
        let figure = |svg, caption: &str| Block::Figure {
            svg,
            caption: caption.into(),
        };
        Section {
            heading: "Plots".into(),
            blocks: vec![
                figure(errors, "E_rms and E_max at the fitter's samples after each iteration (unit cube); dashed verticals start each stage with its smoothing weight λ, dashed horizontals are the tolerances."),
                figure(histogram, "Distance from the limit tessellation's vertices to the data (surface → data) and from the data samples to the surface (data → surface), fraction of each per logarithmic bin."),
                figure(points, "Control points of each stage's cage (refinement adds them between stages)."),
                figure(phases, "Wall time of each phase of the run (the write time is that of the files before this page)."),
            ],
        }
    }

    fn stage_section(&self) -> Section {
        let rows = self
            .report
            .stages
            .iter()
            .map(|s| {
                vec![
                    s.stage.to_string(),
                    sig(s.lambda),
                    s.control_points.to_string(),
                    s.faces.to_string(),
                    s.iterations.to_string(),
                    sig(s.r#final.e_rms),
                    sig(s.r#final.e_max),
                    sig(s.two_sided.rms()),
                    sig(s.two_sided.max()),
                    s.stop.clone(),
                    format!("{:.2}", s.time_s),
                ]
            })
            .collect();
        Section {
            heading: "Stages".into(),
            blocks: vec![Block::Table {
                header: [
                    "stage",
                    "λ",
                    "control points",
                    "faces",
                    "iterations",
                    "E_rms",
                    "E_max",
                    "two-sided RMS",
                    "two-sided max",
                    "stop",
                    "time (s)",
                ]
                .map(String::from)
                .to_vec(),
                rows,
            }],
        }
    }
}

/// The edges of a mesh, each once.
fn edges(mesh: &PolyMesh) -> Vec<[u32; 2]> {
    let mut e: Vec<[u32; 2]> = mesh
        .faces
        .iter()
        .flat_map(|f| {
            (0..f.len()).map(move |i| {
                let (a, b) = (f[i], f[(i + 1) % f.len()]);
                [a.min(b), a.max(b)]
            })
        })
        .collect();
    e.sort_unstable();
    e.dedup();
    e
}

fn scheme_name(s: Scheme) -> &'static str {
    match s {
        Scheme::Loop => "Loop",
        _ => "Catmull-Clark",
    }
}

fn sig(v: f64) -> String {
    subfit_report::html::number(v)
}

fn percent(fraction: f64) -> String {
    format!("{}%", subfit_report::html::number(100.0 * fraction))
}

/// The initial cage's layout for the table: along a cross field, with its valences, or why
/// not; empty when no cross field was asked.
fn cross_field_note(c: Option<&crate::pipeline_report::CrossFieldSummary>) -> String {
    match c {
        Some(c) if c.used => {
            let valences: Vec<String> = c
                .valences
                .iter()
                .map(|(v, n)| format!("{v}: {n}"))
                .collect();
            format!(
                ", along a cross field: {} irregular vertices; interior valences {}",
                c.irregular,
                valences.join(", ")
            )
        }
        Some(c) => format!(
            ", simplified and paired (no cross-field cage: {})",
            c.failure.as_deref().unwrap_or("not taken")
        ),
        None => String::new(),
    }
}
