//! `subfit init TARGET [--control-points N] [--from-points] -o control.obj`: an initial control
//! mesh with the target's topology (DESIGN.md §3.6), written in the target's coordinates.
//!
//! It is the library's start ([`subfit::initialize`]): the input read, repaired and analysed as
//! `subfit fit` does, and the first start `fit` would fit built with the same defaults — mesh
//! targets simplified (topology-preserving QEM); point clouds, or any target with
//! `--from-points`, contoured (IMLS on an adaptive octree + marching tetrahedra) and then
//! simplified. The default size is [`subfit::init::default_control_points`]:
//! `clamp(round(1.5·√points), 200, 2000)`. `--quad-dominant` pairs the triangles into quads
//! ([`subfit::init::pair_triangles`]). `--curvature-lines` builds Lavoué et al.'s cage instead
//! ([`subfit::init::curvature_lines`]).

use std::process::ExitCode;
use std::time::Instant;

use anyhow::bail;
use subfit::init::{InitReport, InitSource};
use subfit::io::{Encoding, Format, WriteOptions};
use subfit::mesh::PolyMesh;
use subfit::pipeline_report::Topology;
use subfit::target::Target;
use subfit::{initialize, FitScanOptions, InitialCage, Initialized, Input, Progress, Step};

use crate::cli::{InitArgs, SchemeArg};

pub fn run(a: InitArgs) -> anyhow::Result<ExitCode> {
    // Validate the flags before reading anything.
    match Format::from_path(&a.output) {
        None => bail!(
            "{}: cannot tell the output format from the extension (use .obj, .ply, .off or .stl)",
            a.output.display()
        ),
        Some(Format::Xyz) => bail!(
            "{}: a point format cannot hold a control mesh (use .obj, .ply, .off or .stl)",
            a.output.display()
        ),
        Some(_) => {}
    }
    if a.output.is_dir() {
        bail!("{}: is a directory", a.output.display());
    }
    if a.scheme == SchemeArg::Loop && a.quad_dominant {
        bail!("--quad-dominant makes quads, but Loop subdivision needs triangles: use --scheme catmull-clark or quad-tri");
    }
    let options = options(&a);
    let t0 = Instant::now();
    let (mesh, _) = crate::progress::load(&a.target)?;
    if a.require_genus && a.genus.is_none() && mesh.faces.is_empty() {
        bail!("--require-genus on a point cloud needs --genus G (the genus it should have)");
    }
    // A mesh that cannot be used as one may still be contoured from its vertices.
    let hint = !a.from_points && !mesh.faces.is_empty();
    let input = Input::Mesh {
        mesh,
        name: a.target.display().to_string(),
    };
    let built = initialize_with_progress(input, &options, &a, hint)?;
    let t = Instant::now();
    let out = write_cage(&a, &built.prepared.target, &built.start.cage, &built.tags)?;
    let write_time = t.elapsed();
    if let Some(r) = &built.start.curvature_report {
        print_curvature_lines(&a, r, &out, t0);
        return Ok(ExitCode::SUCCESS);
    }
    if let Some(r) = &built.start.init_report {
        let topology = built.prepared.topology.or(built.prepared.expected_topology);
        let faces = built.prepared.mesh_faces();
        let requested = built.start.summary.requested_control_points.unwrap_or(0);
        print_summary(
            &a,
            &built.prepared.target,
            topology.map(|t| (t, faces)),
            r,
            requested,
            &out,
        );
        print_notes(r, &out, requested);
        out!(
            "time: read and analyse {:.3} s, contour {:.3} s, simplify {:.3} s, pair {:.3} s, write {:.3} s, total {:.3} s",
            built.prepared.read_and_analyse_seconds(),
            r.timings.contour.as_secs_f64(),
            r.timings.simplify.as_secs_f64(),
            r.timings.pair.as_secs_f64(),
            write_time.as_secs_f64(),
            t0.elapsed().as_secs_f64()
        );
    }
    out!("wrote {}", a.output.display());
    Ok(ExitCode::SUCCESS)
}

/// The library's options for `a`: those of `subfit fit` with its defaults, no budget beyond
/// a count asked, and the flags of `init`.
fn options(a: &InitArgs) -> FitScanOptions {
    let defaults = FitScanOptions::default();
    let mut o = FitScanOptions {
        init: if a.curvature_lines {
            InitialCage::CurvatureLines
        } else {
            InitialCage::Qem
        },
        control_points: a.control_points.map(|n| n as usize),
        as_points: a.from_points,
        scheme: crate::commands::fit::scheme_of(a.scheme),
        quad_dominant: crate::cli::quad_dominant_flag(a.quad_dominant, a.no_quad_dominant),
        quads: a.quads.layout(),
        // The fit's defaults decide as they do for `subfit fit` without a tolerance.
        target_tolerances: true,
        cad_feature_angle: defaults
            .cad_feature_angle
            .filter(|_| a.features.feature_angle.is_none()),
        cancel: crate::interrupt::token(),
        ..defaults
    };
    o.stages.max_control_points = usize::MAX;
    o.target.mesh_closest_point = false;
    o.init_options.expected_genus = a.genus;
    o.init_options.require_genus = a.require_genus;
    o.init_options.features = a.features.options();
    o.init_options.semi_sharp = a.features.semi_sharp;
    o.init_options.cloud_features = a.features.cloud_features;
    o.init_options.contour.refine_levels = usize::from(a.contour_refine);
    o.init_options.one_sided_refine = usize::from(a.contour_refine);
    o
}

/// [`initialize`] with a spinner per step and warnings on stderr.
fn initialize_with_progress(
    input: Input,
    options: &FitScanOptions,
    a: &InitArgs,
    contour_hint: bool,
) -> anyhow::Result<Initialized> {
    let mut spinner: Option<indicatif::ProgressBar> = None;
    let building = if a.curvature_lines {
        "fitting boundary curves and cutting along curvature lines"
    } else {
        "building the initial control mesh"
    };
    let mut on = |p: Progress<'_>| match p {
        Progress::Step(s) => {
            if let Some(sp) = spinner.take() {
                sp.finish_and_clear();
            }
            match s {
                Step::Analyse => spinner = Some(crate::progress::spinner("analysing the target")),
                Step::Init => spinner = Some(crate::progress::spinner(building)),
                Step::Read | Step::Fit => {}
            }
        }
        Progress::Warning(w) => eprintln!("subfit: warning: {w}"),
        Progress::Iteration { .. } | Progress::Stage(_) => {}
    };
    let built = initialize(input, options, Some(&mut on));
    if let Some(sp) = spinner.take() {
        sp.finish_and_clear();
    }
    built.map_err(|e| {
        let unusable_mesh = matches!(
            &e,
            subfit::Error::Input { .. }
                | subfit::Error::Init {
                    source: subfit::init::InitError::InvalidMesh(_),
                    ..
                }
        );
        let hint = if contour_hint && unusable_mesh {
            " (use --from-points to contour its vertices instead)"
        } else {
            ""
        };
        anyhow::anyhow!("cannot build the initial control mesh: {e}{hint}")
    })
}

/// What the QEM or contour start noted: concave corners, the space-carving fallback, a count
/// not reached, a genus missed.
fn print_notes(report: &InitReport, out: &PolyMesh, requested: usize) {
    if report.concave.creases > 0 {
        out!(
            "note: {} concave corner sector(s) split by a crease so the limit surface does not fold there ({} control point(s) added)",
            report.concave.creases, report.concave.inserted
        );
    }
    if let Some(r) = report.carve_radius {
        out!(
            "note: the implicit surface missed genus {}; used the space-carving fallback \
             (normals ignored, radius {r:.4} unit cube; the cage sits about that far outside)",
            report.genus_target
        );
    }
    if !report.simplify.reached_target && report.cross_field.is_none() {
        eprintln!(
            "subfit: warning: no legal collapse left at {} vertices ({requested} requested)",
            out.num_vertices()
        );
    }
}

/// `--curvature-lines`: what [`subfit::init::curvature_lines`] built.
fn print_curvature_lines(
    a: &InitArgs,
    r: &subfit::init::curvature_lines::CurvatureLineReport,
    out: &PolyMesh,
    t0: Instant,
) {
    let quads = out.faces.iter().filter(|f| f.len() == 4).count();
    out!(
        "boundary curves: {} loop(s), control points {:?}, {} corner(s), largest distance of a boundary vertex {:.2e} unit cube",
        r.boundary_loops,
        r.curve_control_points,
        r.corners,
        r.curve_max_error
    );
    out!(
        "cage: {} vertices, {} faces ({quads} quads, {} triangles, {} larger), {} link(s) between loops, {} cut(s) along curvature lines, {} fan(s)",
        out.num_vertices(),
        out.num_faces(),
        out.faces.iter().filter(|f| f.len() == 3).count(),
        out.faces.iter().filter(|f| f.len() > 4).count(),
        r.links,
        r.cuts,
        r.fans
    );
    out!(
        "time: curves {:.3} s, links {:.3} s, cuts {:.3} s, total {:.3} s",
        r.seconds.curves,
        r.seconds.links,
        r.seconds.cuts,
        t0.elapsed().as_secs_f64()
    );
    out!("wrote {}", a.output.display());
}

/// Writes `cage` (normalized units) in the target's coordinates to `a.output`, with its tags
/// into an .obj (another format has no place for them: a warning); returns what was written.
fn write_cage(
    a: &InitArgs,
    target: &Target,
    cage: &PolyMesh,
    tags: &subfit::mesh::Tags,
) -> anyhow::Result<PolyMesh> {
    let out = PolyMesh::new(
        cage.positions
            .iter()
            .map(|&p| target.to_original(p))
            .collect(),
        cage.faces.clone(),
    );
    crate::interrupt::watch_dir(&a.output);
    if Format::from_path(&a.output) == Some(Format::Obj) {
        subfit::io::write_obj_with_tags_file(&a.output, &out, tags)?;
    } else {
        if !tags.is_empty() {
            eprintln!(
                "subfit: warning: {} has no place for the cage's {} crease and {} corner tags (write .obj to keep them)",
                a.output.display(),
                tags.creases().len(),
                tags.corners().len()
            );
        }
        let wopts = WriteOptions {
            format: None,
            encoding: Encoding::Ascii,
            single_precision: false,
        };
        subfit::io::write_file(&a.output, &out, &wopts)?;
    }
    Ok(out)
}

fn print_summary(
    a: &InitArgs,
    target: &Target,
    input: Option<(Topology, usize)>,
    r: &InitReport,
    requested: usize,
    out: &PolyMesh,
) {
    let topo = |g: Option<u32>, loops: usize| match g {
        Some(g) => format!("genus {g}, {loops} boundary loop(s)"),
        None => format!("genus unknown (not a manifold), {loops} boundary loop(s)"),
    };
    match input {
        Some((t, faces)) => out!(
            "target {}: {} points, {} faces, {}",
            a.target.display(),
            target.len(),
            faces,
            topo(Some(t.genus), t.boundary_loops)
        ),
        None => out!(
            "target {}: {} points (point cloud)",
            a.target.display(),
            target.len()
        ),
    }
    match (r.source, &r.contour) {
        (InitSource::Contour, Some(c)) => out!(
            "contour: octree of {} points and {} leaves, finest {}x{}x{} (cell {:.4} unit cube), \
             {} vertices, {} faces, genus {}, {} of {} components kept",
            c.octree_nodes,
            c.leaves_per_level.iter().sum::<usize>(),
            c.nodes[0],
            c.nodes[1],
            c.nodes[2],
            c.cell_size,
            c.vertices,
            c.faces,
            c.genus,
            c.components_kept,
            c.components_found
        ),
        _ => out!(
            "simplified the mesh: {} vertices, {} faces",
            r.simplify.vertices_before,
            r.simplify.faces_before
        ),
    }
    if let Some(t) = r.trim.as_ref().filter(|t| t.open) {
        out!(
            "open cloud: {} of {} contour faces trimmed (no data within the support distance, median {:.4} unit cube), \
             {} boundary loop(s), genus {}",
            t.faces_trimmed, t.faces_before, t.support_distance, t.boundary_loops, t.genus
        );
    }
    if r.specks > 0 {
        out!(
            "{} speck(s) (seven control points each) for lone returns no piece of the trimmed surface reaches",
            r.specks
        );
    }
    let versus = if r.source == InitSource::Contour && input.is_none() && a.genus.is_none() {
        "target genus unknown (a point cloud: pass --genus G to check it)".to_owned()
    } else {
        format!(
            "target genus {} ({})",
            r.genus_target,
            if r.genus_matches { "same" } else { "DIFFERENT" }
        )
    };
    let quads = out.faces.iter().filter(|f| f.len() == 4).count();
    let triangles = out.faces.iter().filter(|f| f.len() == 3).count();
    out!(
        "cage: {} vertices ({requested} requested), {} faces ({quads} quads, {triangles} triangles{}), {}, {} component(s); {versus}",
        out.num_vertices(),
        out.num_faces(),
        match (&r.cross_field, r.pairing.is_some()) {
            (Some(q), _) => format!(
                ", along a cross field: {} irregular vertices, {} field singularities",
                q.irregular, q.singularities
            ),
            (None, true) => ", triangles paired".to_string(),
            (None, false) => String::new(),
        },
        topo(Some(r.genus_after), r.boundary_loops.1),
        r.components,
    );
    if let Some(why) = &r.cross_field_failure {
        out!("cross field: not used ({why}); the simplified cage is paired instead");
    }
}
