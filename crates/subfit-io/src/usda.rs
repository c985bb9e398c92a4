//! USDA (USD ASCII) writer for control cages: a `UsdGeom.Mesh` with its subdivision scheme,
//! boundary interpolation, creases and corners, so USD tools, Blender and OpenSubdiv-based
//! renderers show the limit surface rather than the cage.
//!
//! The layer holds one `Xform` prim `/subfit` (the default prim) with one `Mesh` child `cage`:
//! `points` (`point3f[]`: USD stores mesh points in single precision — the cage written here
//! is rounded to f32, document-level precision is in the OBJ/PLY outputs), `faceVertexCounts`,
//! `faceVertexIndices`, `extent`, `subdivisionScheme` (`loop` or `catmullClark`; a quad/triangle
//! cage as `catmullClark` with `triangleSubdivisionRule = "smooth"` and the custom attribute
//! `subfit:scheme = "quadTriangle"`),
//! `interpolateBoundary` (`edgeOnly` or `edgeAndCorner`), `creaseIndices`/`creaseLengths`/
//! `creaseSharpnesses` (one two-vertex crease per tagged edge) and `cornerIndices`/
//! `cornerSharpnesses`. Orientation is right-handed (counter-clockwise faces), as OBJ/PLY.
//!
//! An animated cage ([`write_animated`], e.g. a cage tracked through a scan sequence) is the
//! same mesh with `points.timeSamples` and `extent.timeSamples` (one sample per frame, at time
//! codes 0, 1, …) and the layer's `startTimeCode`, `endTimeCode`, `timeCodesPerSecond` and
//! `framesPerSecond`: the topology is written once, so a player streams only the points.
//! References: the UsdGeomMesh schema (Pixar USD documentation, "UsdGeomMesh") and the time
//! samples and layer time metadata of the USD glossary ("TimeSample", "TimeCode").

use std::fmt::Write as _;

use subfit_mesh::{bounding_box, PolyMesh, Polygons, Tags};

/// The `subdivisionScheme` token.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UsdScheme {
    /// `loop` (triangle meshes).
    Loop,
    /// `catmullClark`.
    CatmullClark,
    /// A Stam–Loop quad/triangle cage: USD has no such scheme, so the nearest standard is
    /// written (`catmullClark` with `triangleSubdivisionRule = "smooth"`) and the real scheme
    /// is kept in the custom attribute `subfit:scheme = "quadTriangle"`.
    QuadTriangle,
    /// `none`: a plain polygon mesh.
    None,
}

/// The `interpolateBoundary` token.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UsdBoundary {
    /// `edgeOnly`: boundary edges are creases, valence-2 boundary vertices stay smooth.
    EdgeOnly,
    /// `edgeAndCorner`: as `edgeOnly`, and valence-2 boundary vertices are corners.
    EdgeAndCorner,
}

/// Writes `mesh` (faces required) with crease/corner `tags` as a USDA layer into `out`.
/// Normals and colours are not written (a subdivision surface computes its own normals).
pub fn write(
    mesh: &PolyMesh,
    tags: &Tags,
    scheme: UsdScheme,
    boundary: UsdBoundary,
    out: &mut Vec<u8>,
) {
    let cage = Cage {
        faces: &mesh.faces,
        tags,
        scheme,
        boundary,
    };
    cage.write(Points::Still(&mesh.positions), out);
}

/// Writes an animated cage as a USDA layer into `out`: one mesh with the connectivity
/// `faces`, the crease/corner `tags` and the `scheme` and `boundary` of [`write()`], whose
/// `points` and `extent` are sampled at time codes `0, 1, …, N − 1` from `frames` (`N` frames,
/// each `#V by 3`). The layer plays from `startTimeCode = 0` to `endTimeCode = N − 1` at
/// `fps` time codes (and frames) per second (24 is the film convention USD assumes when the
/// rate is not authored). Cost: O(N · #V + #F), about 40 bytes per point and frame.
///
/// # Panics
/// If `frames` is empty, its frames differ in length, or `fps` is not positive and finite
/// (not otherwise checked: [`crate::write_usda_animated_file`] validates its input into
/// errors). Face indices are not checked against the point count.
#[track_caller]
pub fn write_animated(
    faces: &Polygons,
    frames: &[Vec<[f64; 3]>],
    tags: &Tags,
    scheme: UsdScheme,
    boundary: UsdBoundary,
    fps: f64,
    out: &mut Vec<u8>,
) {
    let count = frames.first().expect("an animation needs a frame").len();
    assert!(
        frames.iter().all(|p| p.len() == count),
        "every frame must have the same number of points"
    );
    assert!(
        fps > 0.0 && fps.is_finite(),
        "frames per second must be positive and finite, not {fps}"
    );
    let cage = Cage {
        faces,
        tags,
        scheme,
        boundary,
    };
    cage.write(Points::Sampled { frames, fps }, out);
}

/// The points of the mesh: one set, or one per time code.
#[derive(Clone, Copy)]
enum Points<'a> {
    Still(&'a [[f64; 3]]),
    Sampled {
        frames: &'a [Vec<[f64; 3]>],
        fps: f64,
    },
}

/// What [`write()`] and [`write_animated`] share: the topology and its subdivision attributes.
struct Cage<'a> {
    faces: &'a Polygons,
    tags: &'a Tags,
    scheme: UsdScheme,
    boundary: UsdBoundary,
}

impl Cage<'_> {
    fn write(&self, points: Points<'_>, out: &mut Vec<u8>) {
        let (num_points, num_frames) = match points {
            Points::Still(p) => (p.len(), 1),
            Points::Sampled { frames, .. } => (frames[0].len(), frames.len()),
        };
        let mut s =
            String::with_capacity(48 * num_points * num_frames + 32 * self.faces.len() + 512);
        s.push_str("#usda 1.0\n(\n    defaultPrim = \"subfit\"\n    doc = \"subdivision cage written by subfit\"\n");
        if let Points::Sampled { frames, fps } = points {
            let _ = write!(
                s,
                "    startTimeCode = 0\n    endTimeCode = {}\n    timeCodesPerSecond = {fps}\n    framesPerSecond = {fps}\n",
                frames.len() - 1
            );
        }
        s.push_str("    metersPerUnit = 1\n    upAxis = \"Z\"\n)\n\n");
        s.push_str("def Xform \"subfit\" (\n    kind = \"component\"\n)\n{\n");
        s.push_str("    def Mesh \"cage\"\n    {\n");
        match points {
            _ if num_points == 0 => {}
            Points::Still(p) => {
                let _ = writeln!(s, "        float3[] extent = {}", extent(bounding_box(p)));
            }
            Points::Sampled { frames, .. } => samples(
                &mut s,
                "float3[] extent",
                frames.iter().map(|p| extent(bounding_box(p))),
            ),
        }
        list(
            &mut s,
            "int[] faceVertexCounts",
            self.faces.iter().map(|p| p.len().to_string()),
        );
        list(
            &mut s,
            "int[] faceVertexIndices",
            self.faces.indices().iter().map(|v| v.to_string()),
        );
        match points {
            Points::Still(p) => list(&mut s, "point3f[] points", p.iter().map(|&p| point(p))),
            Points::Sampled { frames, .. } => samples(
                &mut s,
                "point3f[] points",
                frames.iter().map(|p| array(p.iter().map(|&p| point(p)))),
            ),
        }
        self.subdivision_attributes(&mut s);
        s.push_str("    }\n}\n");
        out.extend_from_slice(s.as_bytes());
    }

    /// Orientation, scheme, boundary rule, creases and corners.
    fn subdivision_attributes(&self, s: &mut String) {
        let quad_triangle = self.scheme == UsdScheme::QuadTriangle;
        let scheme = match self.scheme {
            UsdScheme::Loop => "loop",
            UsdScheme::CatmullClark | UsdScheme::QuadTriangle => "catmullClark",
            UsdScheme::None => "none",
        };
        let boundary = match self.boundary {
            UsdBoundary::EdgeOnly => "edgeOnly",
            UsdBoundary::EdgeAndCorner => "edgeAndCorner",
        };
        let _ = writeln!(s, "        uniform token orientation = \"rightHanded\"");
        let _ = writeln!(s, "        uniform token subdivisionScheme = \"{scheme}\"");
        if quad_triangle {
            let _ = writeln!(
                s,
                "        uniform token triangleSubdivisionRule = \"smooth\""
            );
            let _ = writeln!(
                s,
                "        custom uniform token subfit:scheme = \"quadTriangle\""
            );
        }
        let _ = writeln!(
            s,
            "        uniform token interpolateBoundary = \"{boundary}\""
        );
        let _ = writeln!(
            s,
            "        uniform token faceVaryingLinearInterpolation = \"cornersPlus1\""
        );
        let creases = self.tags.creases();
        if !creases.is_empty() {
            list(
                s,
                "int[] creaseIndices",
                creases
                    .iter()
                    .flat_map(|((a, b), _)| [a.to_string(), b.to_string()]),
            );
            list(
                s,
                "int[] creaseLengths",
                creases.iter().map(|_| "2".to_string()),
            );
            list(
                s,
                "float[] creaseSharpnesses",
                creases.iter().map(|(_, w)| f(*w)),
            );
        }
        let corners = self.tags.corners();
        if !corners.is_empty() {
            list(
                s,
                "int[] cornerIndices",
                corners.iter().map(|(v, _)| v.to_string()),
            );
            list(
                s,
                "float[] cornerSharpnesses",
                corners.iter().map(|(_, w)| f(*w)),
            );
        }
    }
}

/// `(x, y, z)` in single precision.
fn point(p: [f64; 3]) -> String {
    format!("({}, {}, {})", f(p[0]), f(p[1]), f(p[2]))
}

/// The `[(min), (max)]` value of an `extent` (of no points: the origin).
fn extent(bounds: Option<([f64; 3], [f64; 3])>) -> String {
    let (lo, hi) = bounds.unwrap_or_default();
    format!("[{}, {}]", point(lo), point(hi))
}

/// Shortest decimal of the value rounded to f32 (USD stores these attributes as float).
fn f(v: f64) -> String {
    let v = v as f32;
    if v == 0.0 {
        return "0".into();
    }
    let mut b = ryu::Buffer::new();
    let s = b.format(v);
    s.strip_suffix(".0").unwrap_or(s).to_string()
}

/// `[a, b, …]`.
fn array(items: impl Iterator<Item = String>) -> String {
    let mut s = String::from("[");
    for (i, it) in items.enumerate() {
        if i > 0 {
            s.push_str(", ");
        }
        s.push_str(&it);
    }
    s.push(']');
    s
}

/// An attribute with one array value.
fn list(s: &mut String, decl: &str, items: impl Iterator<Item = String>) {
    let _ = writeln!(s, "        {decl} = {}", array(items));
}

/// An attribute with one value per time code `0, 1, …`, in the order given.
fn samples(s: &mut String, decl: &str, values: impl Iterator<Item = String>) {
    let _ = writeln!(s, "        {decl}.timeSamples = {{");
    for (t, v) in values.enumerate() {
        let _ = writeln!(s, "            {t}: {v},");
    }
    s.push_str("        }\n");
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfit_mesh::{shapes::cube_mesh, SHARPNESS_INFINITE};

    #[test]
    fn cube_with_a_crease_and_a_corner() {
        let mesh = cube_mesh(0.5);
        let mut tags = Tags::new();
        tags.set_crease(0, 1, SHARPNESS_INFINITE);
        tags.set_corner(7, SHARPNESS_INFINITE);
        let mut out = Vec::new();
        write(
            &mesh,
            &tags,
            UsdScheme::CatmullClark,
            UsdBoundary::EdgeOnly,
            &mut out,
        );
        let text = String::from_utf8(out).unwrap();
        assert!(text.starts_with("#usda 1.0\n"));
        assert!(text.contains("int[] faceVertexCounts = [4, 4, 4, 4, 4, 4]"));
        assert!(text.contains("uniform token subdivisionScheme = \"catmullClark\""));
        assert!(text.contains("int[] creaseIndices = [0, 1]"));
        assert!(text.contains("float[] creaseSharpnesses = [10]"));
        assert!(text.contains("int[] cornerIndices = [7]"));
        assert!(text.contains("(-0.5, -0.5, -0.5)"));
        assert_eq!(text.matches('{').count(), text.matches('}').count());
        assert!(!text.contains("timeSamples") && !text.contains("TimeCode"));
    }

    #[test]
    fn animated_cube_has_time_samples_and_time_codes() {
        let mesh = cube_mesh(0.5);
        let frames: Vec<Vec<[f64; 3]>> = (0..3)
            .map(|t| {
                let shift = t as f64;
                mesh.positions
                    .iter()
                    .map(|p| [p[0] + shift, p[1], p[2]])
                    .collect()
            })
            .collect();
        let mut out = Vec::new();
        write_animated(
            &mesh.faces,
            &frames,
            &Tags::new(),
            UsdScheme::Loop,
            UsdBoundary::EdgeOnly,
            24.0,
            &mut out,
        );
        let text = String::from_utf8(out).unwrap();
        for line in [
            "    startTimeCode = 0\n",
            "    endTimeCode = 2\n",
            "    timeCodesPerSecond = 24\n",
            "    framesPerSecond = 24\n",
            "        float3[] extent.timeSamples = {\n",
            "            2: [(1.5, -0.5, -0.5), (2.5, 0.5, 0.5)],\n",
            "        point3f[] points.timeSamples = {\n",
            "            1: [(0.5, -0.5, -0.5), (1.5, -0.5, -0.5), ",
            "        int[] faceVertexCounts = [4, 4, 4, 4, 4, 4]\n",
            "        uniform token subdivisionScheme = \"loop\"\n",
        ] {
            assert!(text.contains(line), "missing {line:?} in\n{text}");
        }
        assert_eq!(text.matches("point3f[] points").count(), 1);
        assert_eq!(text.matches('{').count(), text.matches('}').count());
    }

    #[test]
    #[should_panic(expected = "same number of points")]
    fn frames_of_different_lengths_are_refused() {
        let mesh = cube_mesh(0.5);
        let frames = vec![mesh.positions.clone(), mesh.positions[..7].to_vec()];
        write_animated(
            &mesh.faces,
            &frames,
            &Tags::new(),
            UsdScheme::CatmullClark,
            UsdBoundary::EdgeOnly,
            24.0,
            &mut Vec::new(),
        );
    }
}
