//! `subfit init TARGET [--control-points N] [--from-points] -o control.obj`: an initial control
//! mesh with the target's topology (DESIGN.md §3.6), written in the target's coordinates.
//!
//! Mesh targets are simplified (topology-preserving QEM); point clouds, or any target with
//! `--from-points`, are contoured (IMLS on an adaptive octree + marching tetrahedra) and then simplified. The default
//! size is [`subfit::init::default_control_points`]: `clamp(round(1.5·√points), 200, 2000)`.
//! `--quad-dominant` pairs the triangles into quads ([`subfit::init::pair_triangles`]).
//! `--curvature-lines` builds Lavoué et al.'s cage instead ([`subfit::init::curvature_lines`]).

use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context};
use subfit::init::{
    default_control_points, initial_control_mesh, InitOptions, InitReport, InitSource,
};
use subfit::io::{Encoding, Format, WriteOptions};
use subfit::mesh::{diagnose_mesh, PolyMesh};
use subfit::target::{Target, TargetOptions};

use crate::cli::InitArgs;

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

    let t0 = Instant::now();
    let (mut input, _) = crate::progress::load(&a.target)?;
    crate::commands::repair_target(&mut input, &a.target);
    let read_time = t0.elapsed();
    let use_mesh = !a.from_points && !input.faces.is_empty();
    // The target's own topology, when it has faces.
    let input_topology = (!input.faces.is_empty()).then(|| diagnose_mesh(&input));

    let t = Instant::now();
    let sp = crate::progress::spinner("analysing the target");
    let built = if use_mesh {
        let opts = TargetOptions {
            mesh_closest_point: false,
            cancel: crate::interrupt::token(),
            ..TargetOptions::default()
        };
        Target::build(&input, &opts, None)
    } else {
        let cloud = PolyMesh::point_cloud(input.positions.clone(), input.normals.clone());
        let opts = TargetOptions {
            cancel: crate::interrupt::token(),
            ..TargetOptions::default()
        };
        Target::build(&cloud, &opts, None)
    };
    sp.finish_and_clear();
    let target =
        built.with_context(|| format!("{}: cannot use as a target", a.target.display()))?;
    let target_time = t.elapsed();

    if a.curvature_lines {
        return curvature_lines(&a, &input, &target, t0);
    }
    let n = a
        .control_points
        .map_or_else(|| default_control_points(target.len()), |n| n as usize);
    let expected_genus = match (&input_topology, a.genus) {
        (_, Some(g)) => Some(g),
        (Some(d), None) => d.genus,
        (None, None) => None,
    };
    if a.require_genus && !use_mesh && expected_genus.is_none() {
        bail!("--require-genus on a point cloud needs --genus G (the genus it should have)");
    }
    if a.scheme == crate::cli::SchemeArg::Loop && a.quad_dominant {
        bail!("--quad-dominant makes quads, but Loop subdivision needs triangles: use --scheme catmull-clark or quad-tri");
    }
    let options = InitOptions {
        expected_genus,
        expected_boundary_loops: input_topology.as_ref().map(|d| d.boundary_loops),
        require_genus: a.require_genus,
        quad_dominant: crate::cli::quad_dominant_flag(a.quad_dominant, a.no_quad_dominant)
            .unwrap_or(matches!(
                a.scheme,
                crate::cli::SchemeArg::CatmullClark | crate::cli::SchemeArg::QuadTri
            )),
        cancel: crate::interrupt::token(),
        features: a.features.options(),
        semi_sharp: a.features.semi_sharp,
        cloud_features: a.features.cloud_features,
        contour: subfit::init::ContourOptions {
            refine_levels: usize::from(a.contour_refine),
            ..subfit::init::ContourOptions::default()
        },
        // Concave corners may add points, but not to a count asked for.
        max_control_points: if a.control_points.is_some() {
            n
        } else {
            usize::MAX
        },
        ..InitOptions::default()
    };
    let sp = crate::progress::spinner(if use_mesh {
        "simplifying"
    } else {
        "contouring and simplifying"
    });
    let result = initial_control_mesh(&target, use_mesh.then_some(&input), n, &options);
    sp.finish_and_clear();
    let (cage, report) = result.map_err(|e| {
        let hint = match e {
            subfit::init::InitError::InvalidMesh(_) => {
                " (use --from-points to contour its vertices instead)"
            }
            _ => "",
        };
        anyhow::anyhow!(
            "{}: cannot build the initial control mesh: {e}{hint}",
            a.target.display()
        )
    })?;

    let t = Instant::now();
    let out = write_cage(&a, &target, &cage, &report.tags)?;
    let write_time = t.elapsed();

    print_summary(&a, &target, input_topology.as_ref(), &report, n, &out);
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
    out!(
        "time: read {:.3} s, target {:.3} s, contour {:.3} s, simplify {:.3} s, pair {:.3} s, write {:.3} s, total {:.3} s",
        read_time.as_secs_f64(),
        target_time.as_secs_f64(),
        report.timings.contour.as_secs_f64(),
        report.timings.simplify.as_secs_f64(),
        report.timings.pair.as_secs_f64(),
        write_time.as_secs_f64(),
        t0.elapsed().as_secs_f64()
    );
    out!("wrote {}", a.output.display());
    if report.simplify.smoothed {
        eprintln!(
            "subfit: warning: the mesh is too noisy to simplify as it is (crumpled triangles); \
             the cage was simplified from a smoothed copy"
        );
    }
    if !report.simplify.reached_target {
        eprintln!(
            "subfit: warning: no legal collapse left at {} vertices ({n} requested)",
            out.num_vertices()
        );
    }
    if !report.genus_matches {
        eprintln!(
            "subfit: warning: the cage has genus {}, the target {}",
            report.genus_after, report.genus_target
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// `--curvature-lines`: the cage of [`subfit::init::curvature_lines`], written with its
/// corner tags.
fn curvature_lines(
    a: &InitArgs,
    input: &PolyMesh,
    target: &Target,
    t0: Instant,
) -> anyhow::Result<ExitCode> {
    use subfit::init::curvature_lines::{curvature_line_cage, CurvatureLineOptions};
    if input.faces.is_empty() {
        bail!(
            "{}: --curvature-lines needs a mesh (faces): a point cloud has no boundary loops to start from",
            a.target.display()
        );
    }
    let dense = PolyMesh::new(
        input
            .positions
            .iter()
            .map(|&p| target.to_normalized(p))
            .collect(),
        subfit::mesh::Polygons::from_triangles(&input.faces.triangulate_fan()),
    );
    let options = CurvatureLineOptions {
        cancel: crate::interrupt::token(),
        ..CurvatureLineOptions::default()
    };
    let sp = crate::progress::spinner("fitting boundary curves and cutting along curvature lines");
    let result = curvature_line_cage(target, &dense, &options);
    sp.finish_and_clear();
    let (cage, tags, r) = result.map_err(|e| {
        anyhow::anyhow!(
            "{}: cannot build the curvature-line cage: {e}",
            a.target.display()
        )
    })?;
    let out = write_cage(a, target, &cage, &tags)?;
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
    Ok(ExitCode::SUCCESS)
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
    input: Option<&subfit::mesh::MeshReport>,
    r: &InitReport,
    requested: usize,
    out: &PolyMesh,
) {
    let topo = |g: Option<u32>, loops: usize| match g {
        Some(g) => format!("genus {g}, {loops} boundary loop(s)"),
        None => format!("genus unknown (not a manifold), {loops} boundary loop(s)"),
    };
    match input {
        Some(d) => out!(
            "target {}: {} points, {} faces, {}",
            a.target.display(),
            target.len(),
            d.num_faces,
            topo(d.genus, d.boundary_loops)
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
        if r.pairing.is_some() { ", triangles paired" } else { "" },
        topo(Some(r.genus_after), r.boundary_loops.1),
        r.components,
    );
}
