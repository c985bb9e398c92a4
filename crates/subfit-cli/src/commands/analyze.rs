//! `subfit analyze TARGET [-o OUT.ply]`: build the target (normalization, kd-tree, normals,
//! principal curvatures and directions), print timings per phase and summary statistics, and
//! optionally write the per-point results as a binary PLY; with `--features`, the sharp features
//! (of a mesh: `detect_features`; of a point cloud: `detect_cloud_features`) as a PLY of
//! vertices and edges.

use std::process::ExitCode;

use anyhow::{bail, Context};
use serde::Serialize;
use subfit::io::ply::VertexProperty;
use subfit::io::{Encoding, WriteOptions};
use subfit::mesh::PolyMesh;
use subfit::target::{Neighborhood, NormalSource, Phase, Progress, Target, TargetOptions};

use crate::cli::AnalyzeArgs;

#[derive(Serialize)]
struct Summary {
    file: String,
    input_points: usize,
    points: usize,
    merged_duplicates: usize,
    /// Points dropped as outliers (point clouds only).
    outliers_removed: usize,
    /// Estimated noise level, normalized units (see `TargetStats::noise_level`).
    noise_level: f64,
    /// Median distance to the 16th nearest neighbour, normalized units.
    point_spacing: f64,
    /// Neighbours per fit (`Knn`; widened on noisy scans), 0 for a radius neighbourhood.
    neighborhood_k: usize,
    /// Iterations of the orientation's winding-field refinement (0: skipped).
    field_iterations: usize,
    triangles: usize,
    normal_origin: String,
    flipped_normals: usize,
    ambiguous_normals: usize,
    degenerate_fits: usize,
    /// Points whose quadric disagrees with its neighbours' (foot points blended there).
    untrusted_quadrics: usize,
    orientation_components: usize,
    neighborhood_size: [f64; 3],
    neighborhood_radius: [f64; 3],
    /// Quantiles (0, 5, 50, 95, 100 %) of the signed principal curvatures, normalized units.
    k1_quantiles: [f64; 5],
    k2_quantiles: [f64; 5],
    /// Normalized units → original units: multiply lengths by this.
    scale_to_original: f64,
    /// Sharp features (mesh targets always; point clouds with `--features`).
    features: Option<FeatureSummary>,
    /// Seconds per phase.
    timings: Timings,
}

/// Counts of [`subfit::target::detect_features`] (meshes) or
/// [`subfit::target::detect_cloud_features`] (point clouds: the curves' polyline segments are
/// the "sharp edges").
#[derive(Serialize)]
struct FeatureSummary {
    /// "mesh" or "cloud".
    source: &'static str,
    angle_deg: f64,
    sharp_edges: usize,
    sharp_edges_before_cleaning: usize,
    curves: usize,
    closed_curves: usize,
    corners: usize,
    darts: usize,
    /// Point clouds: points that passed the per-point test (before tracing and cleaning).
    #[serde(skip_serializing_if = "Option::is_none")]
    feature_points: Option<usize>,
    seconds: f64,
}

/// The features found, with the seconds they took.
enum Found {
    Mesh(subfit::target::Features, f64),
    Cloud(subfit::target::CloudFeatures, f64),
}

impl Found {
    /// What the summary says of these features (found at `angle_deg`).
    fn summary(&self, angle_deg: f64) -> FeatureSummary {
        match self {
            Found::Mesh(f, seconds) => FeatureSummary {
                source: "mesh",
                angle_deg,
                sharp_edges: f.edges.len(),
                sharp_edges_before_cleaning: f.raw_edges,
                curves: f.curves.len(),
                closed_curves: f.curves.iter().filter(|c| c.closed).count(),
                corners: f.corners.len(),
                darts: f.darts.len(),
                feature_points: None,
                seconds: *seconds,
            },
            Found::Cloud(f, seconds) => FeatureSummary {
                source: "cloud",
                angle_deg,
                sharp_edges: f.segments().len(),
                sharp_edges_before_cleaning: f.segments().len(),
                curves: f.curves.len(),
                closed_curves: f.curves.iter().filter(|c| c.closed).count(),
                corners: f.corners.len(),
                darts: f.darts,
                feature_points: Some(f.feature_points),
                seconds: *seconds,
            },
        }
    }
}

#[derive(Serialize)]
struct Timings {
    read: f64,
    validate: f64,
    normalize: f64,
    merge: f64,
    index: f64,
    outliers: f64,
    estimate: f64,
    orient: f64,
    orient_propagate: f64,
    orient_winding: f64,
    orient_field: f64,
    mesh_index: f64,
    total: f64,
}

fn quantiles(v: &[f64]) -> [f64; 5] {
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if s.is_empty() {
        return [f64::NAN; 5];
    }
    s.sort_by(f64::total_cmp);
    let q = |p: f64| s[((s.len() - 1) as f64 * p).round() as usize];
    [q(0.0), q(0.05), q(0.5), q(0.95), q(1.0)]
}

fn phase_name(p: Phase) -> &'static str {
    match p {
        Phase::Validate => "validating",
        Phase::Normalize => "normalizing",
        Phase::Merge => "merging duplicates",
        Phase::Index => "building kd-tree",
        Phase::Outliers => "detecting outliers",
        Phase::Estimate => "fitting normals and curvatures",
        Phase::Orient => "orienting normals",
        Phase::MeshIndex => "building triangle BVH",
    }
}

pub fn run(a: AnalyzeArgs) -> anyhow::Result<ExitCode> {
    let options = target_options(&a)?;

    let t_read = std::time::Instant::now();
    let (mut mesh, _) = crate::progress::load(&a.target)?;
    crate::commands::repair_target(&mut mesh, &a.target);
    let read = t_read.elapsed().as_secs_f64();
    let feature_options = subfit::target::FeatureOptions {
        angle_deg: a.feature_angle,
        ..Default::default()
    };
    let mut features = (!mesh.faces.is_empty()).then(|| {
        let t = std::time::Instant::now();
        let f = subfit::target::detect_features(&mesh.positions, &mesh.faces, &feature_options);
        Found::Mesh(f, t.elapsed().as_secs_f64())
    });

    let bar = crate::progress::bar(1, "analysing");
    let on_progress = |p: Progress| {
        if p.done == 0 {
            crate::progress::phase(phase_name(p.phase));
        }
        bar.set_message(phase_name(p.phase));
        bar.set_length(p.total.max(1) as u64);
        bar.set_position(p.done as u64);
    };
    let target = Target::build(&mesh, &options, Some(&on_progress))
        .with_context(|| format!("{}: cannot analyse", a.target.display()))?;
    bar.finish_and_clear();
    if features.is_none() && a.features.is_some() {
        crate::progress::phase("tracing sharp features");
        let t = std::time::Instant::now();
        let f = subfit::target::detect_cloud_features(&target, &feature_options);
        features = Some(Found::Cloud(f, t.elapsed().as_secs_f64()));
    }

    let attrs = target.point_attributes();
    let summary = summarize(&a, &target, &attrs, features.as_ref(), read);

    if let Some(out) = &a.output {
        write_points(out, &attrs)?;
    }
    match (&a.features, &features) {
        (Some(out), Some(Found::Mesh(f, _))) => write_features(out, &mesh.positions, f)?,
        (Some(out), Some(Found::Cloud(f, _))) => write_cloud_features(out, &target, f)?,
        _ => {}
    }
    if a.json {
        out!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print_text(&summary, a.output.as_deref());
        if let Some(out) = &a.features {
            out!("wrote         {}", out.display());
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The target options `a` asks for, with its flags checked first.
fn target_options(a: &AnalyzeArgs) -> anyhow::Result<TargetOptions> {
    let neighborhood = match (a.neighbors, a.radius) {
        (_, Some(r)) if !(r.is_finite() && r > 0.0 && r < 1.0) => {
            bail!("--radius must be in (0, 1) (unit-cube units), got {r}")
        }
        (_, Some(r)) => Neighborhood::Radius(r),
        (Some(k), None) => Neighborhood::Knn(k as usize),
        (None, None) => TargetOptions::default().neighborhood,
    };
    for out in a.output.iter().chain(&a.features) {
        if subfit::io::Format::from_path(out) != Some(subfit::io::Format::Ply) {
            bail!(
                "{}: the analysis outputs are PLY files (.ply)",
                out.display()
            );
        }
    }
    if !(a.feature_angle.is_finite() && a.feature_angle > 0.0 && a.feature_angle < 180.0) {
        bail!(
            "--feature-angle must be in (0, 180) degrees, got {}",
            a.feature_angle
        );
    }
    Ok(TargetOptions {
        neighborhood,
        jet_degree: a.jet_degree,
        normals: if a.estimate_normals {
            NormalSource::Estimate
        } else {
            NormalSource::Auto
        },
        cancel: crate::interrupt::token(),
        ..TargetOptions::default()
    })
}

/// The summary of the analysis of `a.target`: `target`'s statistics and timings, the
/// curvature quantiles of its point attributes `attrs`, the features found, and the seconds
/// it took to read (`read`).
fn summarize(
    a: &AnalyzeArgs,
    target: &Target,
    attrs: &subfit::target::PointAttributes,
    features: Option<&Found>,
    read: f64,
) -> Summary {
    let s = target.stats();
    let t = &s.timings;
    Summary {
        file: a.target.display().to_string(),
        input_points: s.input_points,
        points: s.points,
        merged_duplicates: s.merged_duplicates,
        outliers_removed: s.outliers_removed,
        noise_level: s.noise_level,
        point_spacing: s.point_spacing,
        neighborhood_k: s.neighborhood_k,
        field_iterations: s.field_iterations,
        triangles: s.triangles,
        normal_origin: format!("{:?}", s.normal_origin).to_lowercase(),
        flipped_normals: s.flipped_normals,
        ambiguous_normals: s.ambiguous_normals,
        degenerate_fits: s.degenerate_fits,
        untrusted_quadrics: s.untrusted_quadrics,
        orientation_components: s.orientation_components,
        neighborhood_size: [
            s.neighborhood_size.0 as f64,
            s.neighborhood_size.1,
            s.neighborhood_size.2 as f64,
        ],
        neighborhood_radius: [
            s.neighborhood_radius.0,
            s.neighborhood_radius.1,
            s.neighborhood_radius.2,
        ],
        k1_quantiles: quantiles(&attrs.k1),
        k2_quantiles: quantiles(&attrs.k2),
        scale_to_original: target.normalization().length_to_original(1.0),
        features: features.map(|found| found.summary(a.feature_angle)),
        timings: Timings {
            read,
            validate: t.validate.as_secs_f64(),
            normalize: t.normalize.as_secs_f64(),
            merge: t.merge.as_secs_f64(),
            index: t.index.as_secs_f64(),
            outliers: t.outliers.as_secs_f64(),
            estimate: t.estimate.as_secs_f64(),
            orient: t.orient.as_secs_f64(),
            orient_propagate: t.orient_propagate.as_secs_f64(),
            orient_winding: t.orient_winding.as_secs_f64(),
            orient_field: t.orient_field.as_secs_f64(),
            mesh_index: t.mesh_index.as_secs_f64(),
            total: t.total.as_secs_f64(),
        },
    }
}

fn write_points(out: &std::path::Path, at: &subfit::target::PointAttributes) -> anyhow::Result<()> {
    let col = |v: &[[f64; 3]], k: usize| v.iter().map(|p| p[k]).collect::<Vec<f64>>();
    let (t1x, t1y, t1z) = (col(&at.t1, 0), col(&at.t1, 1), col(&at.t1, 2));
    let (t2x, t2y, t2z) = (col(&at.t2, 0), col(&at.t2, 1), col(&at.t2, 2));
    let props = [
        ("k1", &at.k1[..]),
        ("k2", &at.k2[..]),
        ("t1x", &t1x[..]),
        ("t1y", &t1y[..]),
        ("t1z", &t1z[..]),
        ("t2x", &t2x[..]),
        ("t2y", &t2y[..]),
        ("t2z", &t2z[..]),
    ]
    .map(|(name, values)| VertexProperty { name, values });
    let cloud = PolyMesh::point_cloud(at.points.clone(), Some(at.normals.clone()));
    let opts = WriteOptions {
        format: None,
        encoding: Encoding::BinaryLittleEndian,
        single_precision: false,
    };
    crate::interrupt::watch_dir(out);
    subfit::io::write_ply_with_properties(out, &cloud, &props, &opts)?;
    Ok(())
}

/// The feature vertices (compacted) with their kinds and the feature edges.
fn write_features(
    out: &std::path::Path,
    positions: &[[f64; 3]],
    f: &subfit::target::Features,
) -> anyhow::Result<()> {
    let mut id = std::collections::HashMap::new();
    let mut pts = Vec::new();
    let mut kinds = Vec::new();
    let mut edges = Vec::with_capacity(f.edges.len());
    let kind = |v: u32| {
        if f.corners.binary_search(&v).is_ok() {
            1
        } else if f.darts.binary_search(&v).is_ok() {
            2
        } else {
            0
        }
    };
    for e in &f.edges {
        let [a, b] = e.map(|v| {
            *id.entry(v).or_insert_with(|| {
                pts.push(positions[v as usize]);
                kinds.push(kind(v));
                (pts.len() - 1) as u32
            })
        });
        edges.push([a, b]);
    }
    crate::interrupt::watch_dir(out);
    subfit::io::write_ply_edges(out, &pts, &kinds, &edges)?;
    Ok(())
}

/// The curves of a point cloud as polylines (vertices with kinds 0 curve, 1 corner, 2 dart;
/// consecutive points joined by edges), in the input's coordinates. Corners are shared by the
/// curves that meet there.
fn write_cloud_features(
    out: &std::path::Path,
    target: &Target,
    f: &subfit::target::CloudFeatures,
) -> anyhow::Result<()> {
    let mut pts: Vec<[f64; 3]> = f.corners.iter().map(|&c| target.to_original(c)).collect();
    let mut kinds = vec![1u8; pts.len()];
    let mut edges = Vec::new();
    for c in &f.curves {
        let n = c.points.len();
        let ids: Vec<u32> = (0..n)
            .map(|i| {
                let corner = match (i, c.closed) {
                    (0, false) => c.ends[0],
                    (i, false) if i + 1 == n => c.ends[1],
                    _ => None,
                };
                corner.unwrap_or_else(|| {
                    pts.push(target.to_original(c.points[i]));
                    let free_end = !c.closed && (i == 0 || i + 1 == n);
                    kinds.push(if free_end { 2 } else { 0 });
                    (pts.len() - 1) as u32
                })
            })
            .collect();
        edges.extend(ids.windows(2).map(|w| [w[0], w[1]]));
        if c.closed && n > 2 {
            edges.push([ids[n - 1], ids[0]]);
        }
    }
    crate::interrupt::watch_dir(out);
    subfit::io::write_ply_edges(out, &pts, &kinds, &edges)?;
    Ok(())
}

fn print_text(s: &Summary, out: Option<&std::path::Path>) {
    out!("file          {}", s.file);
    out!(
        "points        {} ({} in the input, {} exact duplicates merged{})",
        s.points,
        s.input_points,
        s.merged_duplicates,
        if s.triangles > 0 {
            format!(", {} triangles", s.triangles)
        } else {
            String::new()
        }
    );
    out!("outliers      {} removed", s.outliers_removed);
    out!(
        "noise         {:.3e} normalized units ({:.3} x the point spacing {:.3e}); fits use k = {}",
        s.noise_level,
        s.noise_level / s.point_spacing.max(f64::MIN_POSITIVE),
        s.point_spacing,
        s.neighborhood_k
    );
    out!(
        "normals       {}; {} flipped by orientation, {} ambiguous, {} degenerate fits, {} orientation component(s)",
        s.normal_origin, s.flipped_normals, s.ambiguous_normals, s.degenerate_fits, s.orientation_components
    );
    out!(
        "quadrics      {} disagree with their neighbours' (foot points blended next to them)",
        s.untrusted_quadrics
    );
    out!(
        "neighbours    k min/mean/max {:.0}/{:.1}/{:.0}; radius min/median/max {:.5}/{:.5}/{:.5}",
        s.neighborhood_size[0],
        s.neighborhood_size[1],
        s.neighborhood_size[2],
        s.neighborhood_radius[0],
        s.neighborhood_radius[1],
        s.neighborhood_radius[2]
    );
    let q = |v: &[f64; 5]| {
        format!(
            "min {:.4}  5% {:.4}  median {:.4}  95% {:.4}  max {:.4}",
            v[0], v[1], v[2], v[3], v[4]
        )
    };
    out!("k1            {}", q(&s.k1_quantiles));
    out!("k2            {}", q(&s.k2_quantiles));
    out!(
        "units         1 normalized unit = {:.6} original units",
        s.scale_to_original
    );
    if let Some(f) = &s.features {
        match f.feature_points {
            None => out!(
                "features      {} sharp edges (≥ {}°; {} before cleaning) in {} curves ({} closed), {} corners, {} darts",
                f.sharp_edges, f.angle_deg, f.sharp_edges_before_cleaning, f.curves, f.closed_curves, f.corners, f.darts
            ),
            Some(p) => out!(
                "features      {} curves ({} closed, {} segments; normals ≥ {}° apart at {} points), {} corners, {} darts",
                f.curves, f.closed_curves, f.sharp_edges, f.angle_deg, p, f.corners, f.darts
            ),
        }
    }
    let t = &s.timings;
    out!(
        "time (s)      read {:.3}, validate {:.3}, normalize {:.3}, merge {:.3}, index {:.3}, outliers {:.3}, estimate {:.3}, orient {:.3} (propagate {:.3}, winding {:.3}, field {:.3} in {} iterations), mesh index {:.3}; analysis total {:.3}",
        t.read, t.validate, t.normalize, t.merge, t.index, t.outliers, t.estimate, t.orient,
        t.orient_propagate, t.orient_winding, t.orient_field, s.field_iterations, t.mesh_index, t.total
    );
    if let Some(o) = out {
        out!("wrote         {}", o.display());
    }
}
