//! Command-line syntax (clap derive). Values are checked here or in each command's `validate`
//! step before any work starts.

use std::path::PathBuf;

use clap::{Parser, Subcommand, ValueEnum};

pub use crate::cli_bench::{
    BenchCommand, BenchCorpusArgs, BenchFitArgs, BenchSequenceArgs, ConvergenceArgs, MotionArg,
};
pub use crate::cli_output::{CompletionsArgs, OutputArgs};

/// Fit compact subdivision surfaces to dense 3D scans.
#[derive(Parser, Debug)]
#[command(name = "subfit", version, about, long_about = None, propagate_version = true)]
pub struct Args {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Describe a mesh or point-cloud file: counts, bounding box, topology, defects.
    Info(InfoArgs),
    /// Convert between PLY, OBJ, OFF, STL and XYZ.
    Convert(ConvertArgs),
    /// Fit the built-in shapes (ellipsoid 0.25/0.5/1, torus, genus-2 point clouds) end to end.
    Demo(DemoArgs),
    /// Refine a control mesh uniformly (Loop or Catmull-Clark), or push it to the limit surface.
    Subdivide(SubdivideArgs),
    /// Analyse a target: normalize, estimate normals and principal curvatures per point.
    Analyze(AnalyzeArgs),
    /// Evaluate the exact limit surface at random (face, u, v) parameters.
    Eval(EvalArgs),
    /// Fit a control mesh's limit surface to a target (PDM, TDM or SDM).
    Fit(FitArgs),
    /// Build an initial control mesh with the target's topology (QEM simplification of a mesh,
    /// or an implicit surface of the points contoured and simplified).
    Init(InitArgs),
    /// Two-sided distances (RMS, mean, max / Hausdorff) between two surfaces or point sets.
    Compare(CompareArgs),
    /// Fit one cage to every frame of a deforming scan (same connectivity and vertex order in
    /// every frame), with a silhouette term against drift; writes the cages and an animated
    /// sequence.usda.
    Sequence(SequenceArgs),
    /// Benchmarks and studies that print figures.
    #[command(subcommand)]
    Bench(BenchCommand),
    /// Print a shell completion script (e.g. `subfit completions bash > ~/.local/share/bash-completion/completions/subfit`).
    Completions(CompletionsArgs),
    /// Print this command-line reference as Markdown (docs/cli.md is its output).
    #[command(hide = true)]
    HelpMarkdown,
}

/// `subfit init`.
#[derive(clap::Args, Debug)]
pub struct InitArgs {
    /// The target: a point cloud or a mesh (any supported format).
    pub target: PathBuf,
    /// Control points (vertices) of the cage [default: clamp(round(1.5·√points), 200, 2000),
    /// the rule of `subfit fit`].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=10_000_000))]
    pub control_points: Option<u32>,
    /// The cage of Lavoué et al. 2007 §4 instead of QEM (open mesh targets of genus 0): the
    /// control points of the boundary loops' subdivision curves, joined along the lines of
    /// curvature; corners tagged (`subfit fit --init curvature-lines` starts from it).
    #[arg(long, conflicts_with_all = ["control_points", "from_points"])]
    pub curvature_lines: bool,
    /// Ignore the target's faces: contour an implicit surface of its points instead of
    /// simplifying the mesh.
    #[arg(long)]
    pub from_points: bool,
    /// Fail (exit code 2) when the cage's genus differs from the target's (a mesh target's, or
    /// `--genus` for a point cloud).
    #[arg(long)]
    pub require_genus: bool,
    /// Genus expected of a point-cloud target (checked with `--require-genus`, reported otherwise).
    #[arg(long)]
    pub genus: Option<u32>,
    /// Pair the cage's triangles into quads along the target's principal curvature directions
    /// (a quad-dominant cage for Catmull-Clark, same vertex count) [default: on for
    /// `--scheme catmull-clark` and `quad-tri`, off otherwise (a triangle cage)].
    #[arg(long, conflicts_with = "no_quad_dominant")]
    pub quad_dominant: bool,
    /// Keep the cage all triangles.
    #[arg(long)]
    pub no_quad_dominant: bool,
    /// How a quad cage is laid out: `field` (edges along a cross field of the surface, few
    /// irregular vertices), `paired` (the QEM cage's triangles paired) or `only` (along the
    /// field, every face a quad; makes the cage quads without --scheme).
    #[arg(long, value_enum, default_value_t = QuadsArg::Field)]
    pub quads: QuadsArg,
    /// Sharp features of a mesh target (tags are written only into an .obj output).
    #[command(flatten)]
    pub features: FeatureArgs,
    /// Point clouds: levels of adaptive refinement of the implicit surface's octree below its
    /// band level (0–4). 1 keeps thin parts (plates, tubes thinner than about the IMLS radius)
    /// in one piece with their genus; the default 0 is better on clouds with small holes.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u8).range(0..=4))]
    pub contour_refine: u8,
    /// The scheme the cage is for: `catmull-clark` and `quad-tri` make it quad-dominant unless
    /// `--no-quad-dominant`; `loop` and `auto` keep triangles.
    #[arg(long, value_enum, default_value_t = SchemeArg::Auto)]
    pub scheme: SchemeArg,
    /// Output control mesh (.obj, .ply, .off or .stl), in the target's coordinates.
    #[arg(short, long, default_value = "control.obj")]
    pub output: PathBuf,
}

/// `subfit compare`.
#[derive(clap::Args, Debug)]
pub struct CompareArgs {
    /// First surface (a mesh) or point set.
    pub a: PathBuf,
    /// Second surface (a mesh) or point set.
    pub b: PathBuf,
    /// Points sampled uniformly by area on each mesh (point sets use all their points).
    #[arg(long, default_value_t = 200_000, value_parser = clap::value_parser!(u32).range(100..=100_000_000))]
    pub samples: u32,
    /// Random seed of the sampling.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Treat A as a control mesh and compare its exact limit surface under this scheme
    /// (`auto`: Loop for triangle meshes, Catmull-Clark otherwise).
    #[arg(long, value_enum)]
    pub scheme: Option<SchemeArg>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Also write a self-contained HTML page showing both surfaces coloured by their distance
    /// to the other.
    #[arg(long, value_name = "OUT.html")]
    pub html: Option<PathBuf>,
    /// Also list the N samples of each side farthest from the other (where the error is).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub worst: u32,
}

/// `subfit fit`.
#[derive(clap::Args, Debug)]
pub struct FitArgs {
    /// The target: a point cloud or a mesh (any supported format).
    pub target: PathBuf,
    /// Initial control mesh in the target's coordinates (any mesh format), or how to build one
    /// with the target's topology: `qem` (QEM simplification of a mesh target, contouring of an
    /// implicit surface for a point cloud), `curvature-lines` (open mesh targets of genus 0:
    /// the boundary curves' control points joined along the lines of curvature, Lavoué et al.
    /// 2007 §4; fitted with the quad/triangle scheme unless --scheme is given), or `auto`: QEM,
    /// and for an open genus-0 mesh of at most 10,000 points (CAD-like patches) the
    /// curvature-line start as well, keeping the fit within the tolerances with fewer control
    /// points; report.json `init.source` and `init.curvature_lines` say which and what the
    /// other gave.
    #[arg(long, default_value = "auto")]
    pub init: String,
    /// Use only the target's points (and normals): ignore its faces, as for a scan.
    #[arg(long)]
    pub as_points: bool,
    /// Control points of the automatic initial mesh [default: from the target's size,
    /// clamp(1.5·√points, 200, 2000)].
    #[arg(long, value_parser = clap::value_parser!(u32).range(4..=1_000_000))]
    pub control_points: Option<u32>,
    /// Error term: point (PDM), tangent (TDM) or squared distance (SDM), Cheng et al. 2007; or
    /// the IMLS distance of Xie et al. 2023 (IMLS).
    #[arg(long, value_enum, default_value_t = MethodArg::Sdm)]
    pub method: MethodArg,
    /// `--method imls`: support radius h of the IMLS kernel, in unit-cube units (the target is
    /// scaled so its longest side is 1; Xie et al.'s h₀) [default: half the point spacing
    /// (distance to the 16th nearest neighbour), at least 4 × the noise level].
    #[arg(long)]
    pub imls_radius: Option<f64>,
    /// Weight α of the as-rigid-as-possible regularizer on the control mesh, rest shape the
    /// initial cage (Xie et al. 2023 eq. 5; 0.01 for clean scans, 0.1 for noisy ones in the
    /// paper); added to the --lambda smoothing (give --lambda 0 for ARAP alone). 0: off.
    #[arg(long, default_value_t = 0.0)]
    pub arap: f64,
    /// Step control: none, Levenberg-Marquardt, or Armijo backtracking.
    #[arg(long, value_enum, default_value_t = StepArg::Lm)]
    pub step: StepArg,
    /// Optimizer: Gauss-Newton on the sparse normal equations, or a first-order method on the
    /// objective's gradient Cᵀ ∂E/∂S (Xie et al. 2023 fit with Adam); an iteration of a
    /// first-order method is 25 gradient steps.
    #[arg(long, value_enum, default_value_t = OptimizerArg::GaussNewton)]
    pub optimizer: OptimizerArg,
    /// `--optimizer adam`: the step size, in unit-cube units (the largest move of a control
    /// point per step).
    #[arg(long, default_value_t = 1e-3)]
    pub learning_rate: f64,
    /// Smoothing weight λ of the first stage (dimensionless; 0 disables smoothing).
    #[arg(long, default_value_t = 1e-3)]
    pub lambda: f64,
    /// Smallest λ: each stage multiplies λ by 0.1 down to this [default: min(1e-5, --lambda)].
    #[arg(long)]
    pub lambda_end: Option<f64>,
    /// Refinement level at which the limit surface is sampled.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(0..=6))]
    pub sample_level: u32,
    /// Iterations over all stages at most.
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    pub max_iterations: u32,
    /// Iterations of one stage at most (a stage also ends when the error stalls).
    #[arg(long, default_value_t = 6, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    pub stage_iterations: u32,
    /// Stop when E_rms (unit-cube units) is at most this; exit code 1 if it is not reached.
    /// Without --tolerance, --max-error and --max-control-points the tolerances are the
    /// target's (fractions of its bounding-box diagonal, two-sided): RMS 0.075 % and Hausdorff
    /// 0.7 % for a scan (its boundary vertices 0.4 %), 0.04 % and 0.2 % for a CAD part with
    /// sharp edges, RMS only for a noisy scan. Otherwise it is 5e-4 unless given.
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// Also require E_max (unit-cube units) to be at most this; exit code 1 if it is not.
    #[arg(long)]
    pub max_error: Option<f64>,
    /// Judge --tolerance and --max-error on the surface → data distance only (Cheng et al.'s
    /// measure). By default both directions must hold: the limit surface within the tolerance
    /// of the data and the data within it of the limit surface.
    #[arg(long)]
    pub one_sided: bool,
    /// Weight of the data → surface part of the objective (dimensionless, relative to the
    /// surface → data mean): data points at the data's or the limit surface's boundary pull
    /// their nearest limit sample, so open rims reach the data's edge. 0 fits one-sided, as
    /// the papers.
    #[arg(long, default_value_t = 1.0)]
    pub coverage: f64,
    /// Inside the thin parts of a closed mesh (limbs, tentacles, plates), pull a sample that
    /// sank past the middle by the wall facing its own way, not the nearer opposite wall
    /// (foot points that face the sample; sheets and single views keep the closest point).
    /// The default; `--no-facing` takes the plain closest point, as the papers.
    #[arg(long, overrides_with = "no_facing")]
    pub facing: bool,
    /// Foot points are the plain closest points, also inside thin parts (the papers' rule;
    /// see `--facing`, the default).
    #[arg(long, overrides_with = "facing")]
    pub no_facing: bool,
    /// The chordal tolerance, for CAD exports (STL/OBJ tessellations): fit the part the facets
    /// stand for, not the facets. The fit aims at the facets' curved interpolant (PN triangles
    /// through the vertices with the surface's normals), which the facets cut by up to their
    /// chord height; curved faces come out smooth, planes and creases stay. Errors are measured
    /// against the interpolant; the report says how far the facets lie from it. No effect on a
    /// mesh not recognised as a tessellation (a warning says so).
    #[arg(long)]
    pub chordal: bool,
    /// The control-point budget: the initial cage and every refinement stay within it (exit
    /// code 2 when the target's topology needs more) [default: 5000]. A budget given without
    /// --tolerance and --max-error is spent on the best cage it holds: the tolerance is then
    /// 5e-4, not the target's.
    #[arg(long, value_parser = clap::value_parser!(u32).range(4..=10_000_000))]
    pub max_control_points: Option<u32>,
    /// Keep the initial cage's connectivity: no local refinement, no edge flips.
    #[arg(long)]
    pub no_refine: bool,
    /// No edge flips between stages.
    #[arg(long)]
    pub no_flips: bool,
    /// Split a face of the initial cage at most this many times (levels of local refinement).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u8).range(1..=12))]
    pub max_depth: u8,
    /// The last stage's polish of the best cage towards a lower maximum error: the surface →
    /// data error raised to this power (iteratively reweighted least squares), kept only when
    /// the maximum falls by more than 2 % with the RMS up by at most 3 %. 2 turns it off.
    #[arg(long, default_value_t = 3.0, value_parser = polish_power)]
    pub polish_power: f64,
    /// After a refinement, optimize only the new control points and the faces around them
    /// (`--local-rings` rings), holding the rest fixed: faster stages on large cages.
    #[arg(long)]
    pub local: bool,
    /// Rings of faces around the refined region that `--local` also optimizes.
    #[arg(long, default_value_t = 2, requires = "local")]
    pub local_rings: u32,
    /// Local enrichment (Lavoué et al. 2005 §5.2): an error field (the worst face and the faces
    /// around it above half its error) of which fewer than `--local-field-share` of the error
    /// points are at least this fraction of its maximum is a local peak: its faces are merged
    /// and one control point is added, where the faces of a diffuse field are split.
    #[arg(long, default_value_t = 0.8, value_parser = local_field_peak)]
    pub local_field_peak: f64,
    /// The share of an error field's points close to its maximum below which it is local
    /// (Lavoué et al.: 50 %); 0 turns local enrichment off. Fields are enriched locally only
    /// once the RMS tolerance is met, inside the cage (not on its rim) and not around a point
    /// added so before.
    #[arg(long, default_value_t = 0.5, value_parser = unit_interval)]
    pub local_field_share: f64,
    /// Error that maps to red in error.ply (unit-cube units) [default: the final E_max].
    #[arg(long)]
    pub error_scale: Option<f64>,
    /// Subdivision scheme; `auto`: the quad/triangle scheme for an open mesh target (unless the
    /// cage is given; on the automatic cage's triangles it is Loop, and the curvature-line start
    /// brings quads; control.usda is then written as Loop when the cage has no quads), Loop for
    /// other all-triangle cages, Catmull-Clark otherwise.
    #[arg(long, value_enum, default_value_t = SchemeArg::Auto)]
    pub scheme: SchemeArg,
    /// Pair the cage's triangles into quads along the target's principal curvature directions
    /// (a quad-dominant cage, same control points) [default: on for `--scheme catmull-clark`
    /// and `quad-tri`, off for Loop and for `auto`, which keeps the automatic cage's
    /// triangles].
    #[arg(long, conflicts_with = "no_quad_dominant")]
    pub quad_dominant: bool,
    /// Keep the cage all triangles (see `--quad-dominant`).
    #[arg(long)]
    pub no_quad_dominant: bool,
    /// How a quad cage is laid out: `field` (edges along a cross field of the surface, few
    /// irregular vertices; the paired cage where the target has sharp features), `paired` (the
    /// QEM cage's triangles paired) or `only` (along the field, every face a quad; makes the
    /// cage quads, fitted with Catmull-Clark, without --scheme).
    #[arg(long, value_enum, default_value_t = QuadsArg::Field)]
    pub quads: QuadsArg,
    /// Sharp features of a mesh target.
    #[command(flatten)]
    pub features: FeatureArgs,
    /// Point clouds: levels of adaptive refinement of the implicit surface's octree below its
    /// band level (0–4). 1 keeps thin parts (plates, tubes thinner than about the IMLS radius)
    /// in one piece with their genus; 0 is better on clouds with small holes. Default: 0, and
    /// 1 for a one-sided cloud (a single view: trimming removes 40 % of the contour or more).
    #[arg(long, value_parser = clap::value_parser!(u8).range(0..=4))]
    pub contour_refine: Option<u8>,
    /// Output directory (control.obj, control.usda, control.tags.json, limit.ply, error.ply,
    /// log.csv, preview.png, report.html, report.json).
    #[arg(short, long, default_value = "subfit-fit")]
    pub output: PathBuf,
    /// What is printed, and the limit tessellation's faces.
    #[command(flatten)]
    pub report: OutputArgs,
}

/// Sharp features of mesh targets, for `fit` and `init`.
#[derive(clap::Args, Debug, Clone)]
pub struct FeatureArgs {
    /// Mesh targets: dihedral angle (degrees) from which an edge of the data is a sharp
    /// feature. The initial cage keeps the feature curves as edges tagged as infinitely sharp
    /// creases, and their corners as corners (control.usda; control.obj as OpenSubdiv `t`
    /// lines). Default 40; `fit` with its default tolerances detects a CAD part's features
    /// again from 20° (a coarse fillet's facets meet at kinks).
    #[arg(long, value_parser = feature_angle)]
    pub feature_angle: Option<f64>,
    /// A smooth cage for a mesh target: no feature detection, no crease or corner tags.
    #[arg(long)]
    pub no_features: bool,
    /// Semi-sharp creases: each crease gets a finite OpenSubdiv sharpness from the data's
    /// fillet width along its curve (a rounded edge rounds in the limit too; a designed crease
    /// stays infinitely sharp), instead of all infinitely sharp.
    #[arg(long, conflicts_with = "no_features")]
    pub semi_sharp: bool,
    /// Point clouds (experimental): trace the cloud's crease curves (normal discontinuities)
    /// and build the cage along them, with crease and corner tags, as for meshes.
    #[arg(long, conflicts_with = "no_features")]
    pub cloud_features: bool,
}

impl FeatureArgs {
    /// The library's feature options (`None`: off).
    pub fn options(&self) -> Option<subfit::target::FeatureOptions> {
        (!self.no_features).then(|| {
            let default = subfit::target::FeatureOptions::default();
            subfit::target::FeatureOptions {
                angle_deg: self.feature_angle.unwrap_or(default.angle_deg),
                ..default
            }
        })
    }
}

/// `subfit sequence`.
#[derive(clap::Args, Debug)]
pub struct SequenceArgs {
    /// The frames, in order: meshes or point clouds (any supported format); their
    /// connectivity may differ between frames.
    #[arg(required = true)]
    pub frames: Vec<PathBuf>,
    /// The template cage, in the first frame's coordinates [default: fit the first frame].
    #[arg(long)]
    pub template: Option<PathBuf>,
    /// Control points of the template fitted to the first frame (also its budget: it is not
    /// refined beyond them) [default: `subfit fit`'s rule, refined to the tolerance].
    #[arg(long, value_parser = clap::value_parser!(u32).range(4..=1_000_000), conflicts_with = "template")]
    pub control_points: Option<u32>,
    /// Views of the soft silhouette term around each frame (Xie et al. 2023 §4.2); 0 turns it
    /// off.
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(0..=64))]
    pub silhouette_views: u32,
    /// Pixels per side of the silhouette images.
    #[arg(long, default_value_t = 128)]
    pub silhouette_resolution: u32,
    /// Weight of the silhouette loss (mean squared pixel difference) against the data term.
    #[arg(long, default_value_t = subfit::DEFAULT_SILHOUETTE_WEIGHT)]
    pub silhouette_weight: f64,
    /// Data term of every frame: SDM (Cheng et al.) or IMLS (Xie et al.).
    #[arg(long, value_enum, default_value_t = MethodArg::Sdm)]
    pub method: MethodArg,
    /// Nodes of the embedded deformation, inside the body, that carries the template onto each
    /// new frame before its fit (it follows motion along the surface, which closest points do
    /// not see); 0 turns the tracking off (each frame then starts from the previous cage).
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(0..=2000))]
    pub track_nodes: u32,
    /// Known places of markers over the frames (motion capture, tracked texture features), a
    /// CSV file with the header frame,marker,x,y,z (frame: 0 the first FRAME given; positions
    /// in the frames' units). The tracking pulls them there, which pins what the surfaces
    /// leave free: sliding along them. Every marker must be in frame 0.
    #[arg(long)]
    pub markers: Option<PathBuf>,
    /// Weight α of the as-rigid-as-possible term towards the template (as the tracking carried
    /// it onto the frame).
    #[arg(long, default_value_t = 0.01)]
    pub arap: f64,
    /// Umbrella smoothing λ per frame.
    #[arg(long, default_value_t = 1e-5)]
    pub lambda: f64,
    /// LM iterations per frame at most.
    #[arg(long, default_value_t = 12, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub iterations: u32,
    /// A frame (and the template fit) stops when both directions' E_rms (unit-cube units of
    /// the first frame) are at most this.
    #[arg(long, default_value_t = 5e-4)]
    pub tolerance: f64,
    /// Refinement level at which the limit surface is sampled in every frame after the
    /// template's fit (which samples at level 3).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(0..=6))]
    pub sample_level: u32,
    /// Subdivision scheme of the template; `auto` picks Loop for all-triangle cages.
    #[arg(long, value_enum, default_value_t = SchemeArg::Auto)]
    pub scheme: SchemeArg,
    /// Frames per second of sequence.usda.
    #[arg(long, default_value_t = 24.0)]
    pub fps: f64,
    /// Output directory (frame_0000.obj …, sequence.usda, report.json).
    #[arg(short, long, default_value = "subfit-sequence")]
    pub output: PathBuf,
}

/// Parses a feature angle: degrees in `(0, 180)`.
fn feature_angle(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|e| format!("{e}"))?;
    if v > 0.0 && v < 180.0 {
        Ok(v)
    } else {
        Err(format!(
            "{v}: a dihedral angle in degrees, between 0 and 180 (exclusive)"
        ))
    }
}

/// `--quads`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum QuadsArg {
    /// Edges along a cross field.
    Field,
    /// The QEM cage's triangles paired.
    Paired,
    /// Along a cross field, all quads.
    Only,
}

impl QuadsArg {
    /// The library's layout.
    pub fn layout(self) -> subfit::QuadLayout {
        match self {
            Self::Field => subfit::QuadLayout::Field,
            Self::Paired => subfit::QuadLayout::Paired,
            Self::Only => subfit::QuadLayout::Only,
        }
    }
}

/// `--quad-dominant` / `--no-quad-dominant` as the library's `Option<bool>` (`None`: neither).
pub fn quad_dominant_flag(on: bool, off: bool) -> Option<bool> {
    match (on, off) {
        (true, _) => Some(true),
        (_, true) => Some(false),
        _ => None,
    }
}

/// An error term named on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// Point distance minimization.
    Pdm,
    /// Tangent distance minimization.
    Tdm,
    /// Squared distance minimization.
    Sdm,
    /// The IMLS distance (Xie et al. 2023).
    Imls,
}

/// An optimizer named on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OptimizerArg {
    /// Gauss-Newton with the --step control (Cheng et al. 2007).
    GaussNewton,
    /// Adam (Kingma & Ba 2015), step size --learning-rate.
    Adam,
    /// L-BFGS (argmin's, More-Thuente line search, 7 correction pairs).
    Lbfgs,
}

/// A step control named on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum StepArg {
    /// Take the full step.
    None,
    /// Levenberg-Marquardt damping with the gain ratio.
    Lm,
    /// Armijo backtracking on the step length.
    Armijo,
}

/// `subfit eval`.
#[derive(clap::Args, Debug)]
pub struct EvalArgs {
    /// The control mesh (any mesh format).
    pub control: PathBuf,
    /// Number of random samples.
    #[arg(long, default_value_t = 10_000, value_parser = clap::value_parser!(u32).range(1..=100_000_000))]
    pub samples: u32,
    /// Subdivision scheme; `auto` picks Loop for all-triangle meshes, Catmull-Clark otherwise.
    #[arg(long, value_enum, default_value_t = SchemeArg::Auto)]
    pub scheme: SchemeArg,
    /// Boundary interpolation rule.
    #[arg(long, value_enum, default_value_t = BoundaryArg::EdgeOnly)]
    pub boundary: BoundaryArg,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output point cloud (.ply gets the parameters as extra properties `face sub u v`; other
    /// formats get points and normals).
    #[arg(short, long)]
    pub output: PathBuf,
}

/// `subfit analyze`.
#[derive(clap::Args, Debug)]
pub struct AnalyzeArgs {
    /// The target: a point cloud or a mesh (any supported format).
    pub target: PathBuf,
    /// Write the normalized points with normals, curvatures and principal directions to this
    /// binary PLY (f64).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Neighbours per point for normals and curvature (default 24).
    #[arg(long, conflicts_with = "radius", value_parser = clap::value_parser!(u32).range(10..=1000))]
    pub neighbors: Option<u32>,
    /// Neighbourhood radius in normalized (unit-cube) units instead of k nearest.
    #[arg(long)]
    pub radius: Option<f64>,
    /// Estimate normals from the points even when the file has normals or faces.
    #[arg(long)]
    pub estimate_normals: bool,
    /// Degree of the local polynomial fitted per point (2: quadric as in the papers; 3: cubic).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u8).range(2..=3))]
    pub jet_degree: u8,
    /// Detect sharp features (crease curves, corners, darts) and write them to this PLY
    /// (vertices with a `kind`: 0 curve, 1 corner, 2 dart; feature edges as an `edge`
    /// element), in the input's coordinates. Meshes: sharp mesh edges; point clouds: curves
    /// traced along normal discontinuities.
    #[arg(long, value_name = "FILE.ply")]
    pub features: Option<PathBuf>,
    /// Dihedral angle (degrees) from which a mesh edge is sharp.
    #[arg(long, default_value_t = 40.0)]
    pub feature_angle: f64,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

/// `subfit subdivide`.
#[derive(clap::Args, Debug)]
pub struct SubdivideArgs {
    /// The control mesh (any mesh format).
    pub control: PathBuf,
    /// Subdivision scheme; `auto` picks Loop for all-triangle meshes, Catmull-Clark otherwise.
    #[arg(long, value_enum, default_value_t = SchemeArg::Auto)]
    pub scheme: SchemeArg,
    /// Number of uniform refinement levels.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(0..=8))]
    pub levels: u32,
    /// Write limit positions and limit normals of the refined vertices instead of the refined
    /// control points.
    #[arg(long)]
    pub limit: bool,
    /// Boundary interpolation rule (OpenSubdiv's VTX_BOUNDARY_EDGE_ONLY / EDGE_AND_CORNER).
    #[arg(long, value_enum, default_value_t = BoundaryArg::EdgeOnly)]
    pub boundary: BoundaryArg,
    /// Output file (format from the extension: .ply, .obj, .off, .stl, .xyz).
    #[arg(short, long)]
    pub output: PathBuf,
}

/// A subdivision scheme named on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SchemeArg {
    /// Loop for triangle meshes, Catmull-Clark otherwise.
    Auto,
    /// Loop (triangles only).
    Loop,
    /// Catmull-Clark (any polygons).
    CatmullClark,
    /// The Stam–Loop quad/triangle hybrid: Catmull-Clark on quads, Loop on triangles.
    #[value(name = "quad-tri")]
    QuadTri,
}

/// A boundary rule named on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BoundaryArg {
    /// Boundary edges are creases; the boundary limit is the cubic B-spline of the boundary.
    EdgeOnly,
    /// As edge-only, and boundary vertices on a single face are corners.
    EdgeAndCorner,
}

/// `subfit info`.
#[derive(clap::Args, Debug)]
pub struct InfoArgs {
    /// The file to describe (.ply, .obj, .off, .stl, .xyz/.pts/.txt).
    pub file: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Read the file as this format, whatever its extension.
    #[arg(long, value_enum)]
    pub format: Option<FormatArg>,
}

/// `subfit convert`.
#[derive(clap::Args, Debug)]
pub struct ConvertArgs {
    /// Input file.
    pub input: PathBuf,
    /// Output file; its extension picks the format unless `--to` is given.
    pub output: PathBuf,
    /// Output format.
    #[arg(long, value_enum)]
    pub to: Option<FormatArg>,
    /// Input format, whatever the input's extension.
    #[arg(long, value_enum)]
    pub from: Option<FormatArg>,
    /// Output encoding (PLY: all; STL: ascii or binary; others: ascii).
    #[arg(long, value_enum, default_value_t = EncodingArg::Auto)]
    pub encoding: EncodingArg,
    /// Store single-precision floats in binary PLY (default: double, lossless).
    #[arg(long)]
    pub single: bool,
    /// Do not merge identical STL corners into shared vertices.
    #[arg(long)]
    pub no_weld: bool,
}

/// `subfit demo`.
#[derive(clap::Args, Debug)]
pub struct DemoArgs {
    /// Output directory.
    #[arg(short, long, default_value = "subfit-demo")]
    pub output: PathBuf,
    /// Points per shape.
    #[arg(long, default_value_t = 50_000, value_parser = clap::value_parser!(u32).range(10..=50_000_000))]
    pub points: u32,
    /// Gaussian noise, as a fraction of the bounding-box diagonal (0.002 = 0.2%).
    #[arg(long, default_value_t = 0.0)]
    pub noise: f64,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Only write the sampled point clouds; do not fit them.
    #[arg(long)]
    pub no_fit: bool,
}

/// A file format named on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum FormatArg {
    /// Stanford PLY.
    Ply,
    /// Wavefront OBJ.
    Obj,
    /// Object File Format.
    Off,
    /// Stereolithography.
    Stl,
    /// Point list (x y z [nx ny nz]).
    Xyz,
}

impl From<FormatArg> for subfit::io::Format {
    fn from(f: FormatArg) -> Self {
        use subfit::io::Format;
        match f {
            FormatArg::Ply => Format::Ply,
            FormatArg::Obj => Format::Obj,
            FormatArg::Off => Format::Off,
            FormatArg::Stl => Format::Stl,
            FormatArg::Xyz => Format::Xyz,
        }
    }
}

/// An output encoding named on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum EncodingArg {
    /// Binary little-endian for PLY and STL, text for the others.
    Auto,
    /// Text.
    Ascii,
    /// Binary little-endian.
    Binary,
    /// Binary big-endian (PLY only).
    BinaryBe,
}

/// A number that `ok` accepts; the error names the interval `range`.
fn number_in(s: &str, ok: impl Fn(f64) -> bool, range: &str) -> Result<f64, String> {
    let p: f64 = s.parse().map_err(|e| format!("{e}"))?;
    if ok(p) {
        Ok(p)
    } else {
        Err(format!("{p} is not in {range}"))
    }
}

/// `--local-field-peak`: a number in (0.5, 1].
fn local_field_peak(s: &str) -> Result<f64, String> {
    number_in(s, |p| p > 0.5 && p <= 1.0, "(0.5, 1]")
}

/// `--local-field-share`: a number in [0, 1].
fn unit_interval(s: &str) -> Result<f64, String> {
    number_in(s, |p| (0.0..=1.0).contains(&p), "[0, 1]")
}

/// `--polish-power`: a number in [2, 8].
fn polish_power(s: &str) -> Result<f64, String> {
    number_in(s, |p| (2.0..=8.0).contains(&p), "[2, 8]")
}
