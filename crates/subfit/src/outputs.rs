//! The files a fit writes, in the input's coordinates ([`OUTPUTS`], in the order a front end
//! moves them into place, the report last): the cage as OBJ (crease and corner tags as
//! OpenSubdiv `t` statements, and again as `control.tags.json` for OBJ readers that skip them:
//! [`subfit_io::tags_json`]) and as a UsdGeom Mesh with its scheme and tags, the limit tessellation with normals, the same coloured by the distance to
//! the target (Cheng 2007 §IV-D colours), the per-iteration log, the page a person looks at
//! (`report.html`, [`crate::html_report`]) and the report.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use subfit_fit::StagesReport;
use subfit_io::ply::VertexProperty;
use subfit_io::usda::{UsdBoundary, UsdScheme};
use subfit_io::{Encoding, WriteOptions};
use subfit_mesh::{PolyMesh, Polygons};
use subfit_report::error_color;
use subfit_subdiv::{BoundaryRule, Scheme};

use crate::error::Error;
use crate::fitted::Fitted;

/// The files [`Fitted::write_into`] writes, in the order to move them into place.
pub const OUTPUTS: [&str; 9] = [
    "control.obj",
    "control.usda",
    "control.tags.json",
    "limit.ply",
    "error.ply",
    "log.csv",
    "preview.png",
    "report.html",
    "report.json",
];

impl Fitted {
    /// Writes every file of [`OUTPUTS`] into `dir` (which must exist; each file atomically,
    /// the report last) and completes the report with the colour scale and the output time.
    /// A front end that wants all or none in place writes into a staging directory and
    /// renames them (the CLI does).
    ///
    /// Errors: a file that cannot be written; [`Error::Interrupted`] when the run's token is
    /// cancelled (checked before each file).
    pub fn write_into(&mut self, dir: &Path) -> Result<(), Error> {
        let t = Instant::now();
        let check = || self.cancel.check().map_err(|_| Error::Interrupted);
        check()?;
        subfit_io::write_obj_with_tags_file(&dir.join("control.obj"), &self.cage, &self.tags)?;
        let usd_scheme = usd_scheme(self.scheme, &self.cage.faces);
        let usd_boundary = usd_boundary(self.fit.boundary);
        check()?;
        subfit_io::write_usda_file(
            &dir.join("control.usda"),
            &self.cage,
            &self.tags,
            usd_scheme,
            usd_boundary,
        )?;
        check()?;
        subfit_io::write_tags_json_file(
            &dir.join("control.tags.json"),
            &self.tags,
            self.cage.num_vertices(),
        )?;
        let last = self.stages.report.last;
        let limit = self.limit.clone();
        let local = &self.local_error;
        let scale = self
            .report
            .error_color_scale_or(last.e_max)
            .max(f64::MIN_POSITIVE);
        let limit = PolyMesh {
            positions: limit
                .positions
                .iter()
                .map(|&p| self.target.to_original(p))
                .collect(),
            ..limit
        };
        let binary = WriteOptions {
            format: None,
            encoding: Encoding::BinaryLittleEndian,
            single_precision: false,
        };
        check()?;
        subfit_io::write_file(&dir.join("limit.ply"), &limit, &binary)?;
        let unit = self.report.normalized_unit_in_original_units;
        let error_original: Vec<f64> = local.iter().map(|e| e * unit).collect();
        let colored = PolyMesh {
            colors: Some(local.iter().map(|&e| error_color(e / scale)).collect()),
            ..limit
        };
        check()?;
        subfit_io::write_ply_with_properties(
            &dir.join("error.ply"),
            &colored,
            &[
                VertexProperty {
                    name: "error",
                    values: &error_original,
                },
                VertexProperty {
                    name: "error_unit_cube",
                    values: local,
                },
            ],
            &binary,
        )?;
        check()?;
        subfit_io::write_atomic(
            &dir.join("log.csv"),
            log_csv(&self.stages.report).as_bytes(),
        )?;
        self.report.error_color_scale_unit_cube = scale;
        check()?;
        let view = self.view_mesh()?;
        let png = self.preview_png(&view)?;
        check()?;
        subfit_io::write_atomic(&dir.join("preview.png"), &png)?;
        self.report.timings_s.output = t.elapsed().as_secs_f64();
        let html = self.report_html(&view);
        subfit_io::write_atomic(&dir.join("report.html"), html.as_bytes())?;
        self.report.timings_s.output = t.elapsed().as_secs_f64();
        self.report.timings_s.total += self.report.timings_s.output;
        check()?;
        let json =
            serde_json::to_string_pretty(&self.report).map_err(|e| Error::Output(e.to_string()))?;
        subfit_io::write_atomic(&dir.join("report.json"), (json + "\n").as_bytes())?;
        Ok(())
    }

    /// One line: control points, stages, iterations, why it stopped, errors both ways.
    pub fn summary(&self) -> String {
        let r = &self.report;
        let two = &r.r#final.two_sided;
        let polish = match r.stages.last().and_then(|s| s.polish_kept) {
            Some(true) => " (the last a max-error polish, kept)",
            Some(false) => " (the last a max-error polish, not kept)",
            None => "",
        };
        let starts = if r.budget_starts.len() > 1 {
            let all: Vec<String> = r
                .budget_starts
                .iter()
                .map(|s| format!("{}", s.initial_control_points))
                .collect();
            format!(
                " (the best of {} starts under the budget: {})",
                all.len(),
                all.join(", ")
            )
        } else {
            String::new()
        };
        format!(
            "{} → {} control points{starts}, {} stages{polish}, {} iterations ({}): E_rms {:.3e} → {:.3e}, E_max {:.3e} → {:.3e} (surface → data); two-sided E_rms {:.3e}, E_max {:.3e} ({:.2e} / {:.2e} of the diagonal; unit cube)",
            r.init.control_points,
            r.control_points,
            r.stages.len(),
            r.iterations.len(),
            r.stop,
            r.initial.e_rms,
            r.r#final.e_rms,
            r.initial.e_max,
            r.r#final.e_max,
            two.e_rms,
            two.e_max,
            two.e_rms_fraction_of_diagonal,
            two.e_max_fraction_of_diagonal,
        )
    }
}

impl crate::pipeline_report::Report {
    /// The error colour scale: the one asked for, else `default`.
    fn error_color_scale_or(&self, default: f64) -> f64 {
        if self.error_color_scale_unit_cube > 0.0 {
            self.error_color_scale_unit_cube
        } else {
            default
        }
    }
}

/// The per-iteration table of all stages as CSV (unit-cube units; times in seconds): a row
/// for the initial mesh (iteration 0), then one per iteration, numbered across stages.
pub fn log_csv(r: &StagesReport) -> String {
    let mut s = String::from(
        "stage,iteration,lambda,control_points,accepted,e_max,e_rms,e_max_diag,e_rms_diag,objective,trial_objective,damping,step_length,gain_ratio,t_sample,t_project,t_assemble,t_solve,t_evaluate\n",
    );
    let i = &r.initial;
    let (lambda0, n0) = r
        .stages
        .first()
        .map_or((0.0, 0), |s| (s.lambda, s.num_control_points));
    let _ = writeln!(
        s,
        "0,0,{lambda0},{n0},true,{},{},{},{},{},{},,,,,,,,",
        i.e_max, i.e_rms, i.e_max_diag, i.e_rms_diag, i.objective, i.objective
    );
    let mut k = 0;
    for st in &r.stages {
        for row in &st.fit.iterations {
            k += 1;
            let e = &row.errors;
            let t = &row.timings;
            let _ = writeln!(
                s,
                "{},{k},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                st.stage,
                st.lambda,
                st.num_control_points,
                row.accepted,
                e.e_max,
                e.e_rms,
                e.e_max_diag,
                e.e_rms_diag,
                e.objective,
                row.trial_objective,
                row.damping,
                row.step_length,
                row.gain_ratio,
                t.sample.as_secs_f64(),
                t.project.as_secs_f64(),
                t.assemble.as_secs_f64(),
                t.solve.as_secs_f64(),
                t.evaluate.as_secs_f64()
            );
        }
    }
    s
}

/// The USD `subdivisionScheme` a cage of `scheme` with `faces` is written with. A
/// quad/triangle cage of triangles only is written as `loop`: on triangles the scheme is Loop
/// (Stam & Loop 2003; checked against OpenSubdiv's Loop in `subfit-subdiv`'s golden tests), so
/// USD shows the fitted surface exactly, where USD's nearest scheme for quads and triangles
/// together (Catmull-Clark with the smooth triangle rule) would not.
pub fn usd_scheme(scheme: Scheme, faces: &Polygons) -> UsdScheme {
    match scheme {
        Scheme::Loop => UsdScheme::Loop,
        Scheme::CatmullClark => UsdScheme::CatmullClark,
        Scheme::QuadTriangle if faces.is_triangles() => UsdScheme::Loop,
        Scheme::QuadTriangle => UsdScheme::QuadTriangle,
    }
}

/// The USD `interpolateBoundary` of a boundary rule.
pub(crate) fn usd_boundary(rule: BoundaryRule) -> UsdBoundary {
    match rule {
        BoundaryRule::EdgeOnly => UsdBoundary::EdgeOnly,
        BoundaryRule::EdgeAndCorner => UsdBoundary::EdgeAndCorner,
    }
}
