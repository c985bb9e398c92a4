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
//! Reference: the UsdGeomMesh schema (Pixar USD documentation, "UsdGeomMesh").

use std::fmt::Write as _;

use subfit_mesh::{PolyMesh, Tags};

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
    let mut s = String::with_capacity(64 * mesh.positions.len() + 32 * mesh.faces.len() + 512);
    let quad_triangle = scheme == UsdScheme::QuadTriangle;
    let scheme = match scheme {
        UsdScheme::Loop => "loop",
        UsdScheme::CatmullClark | UsdScheme::QuadTriangle => "catmullClark",
        UsdScheme::None => "none",
    };
    let boundary = match boundary {
        UsdBoundary::EdgeOnly => "edgeOnly",
        UsdBoundary::EdgeAndCorner => "edgeAndCorner",
    };
    s.push_str("#usda 1.0\n(\n    defaultPrim = \"subfit\"\n    doc = \"subdivision cage written by subfit\"\n    metersPerUnit = 1\n    upAxis = \"Z\"\n)\n\n");
    s.push_str("def Xform \"subfit\" (\n    kind = \"component\"\n)\n{\n");
    s.push_str("    def Mesh \"cage\"\n    {\n");
    if let Some((lo, hi)) = mesh.bounding_box() {
        let _ = writeln!(
            s,
            "        float3[] extent = [({}, {}, {}), ({}, {}, {})]",
            f(lo[0]),
            f(lo[1]),
            f(lo[2]),
            f(hi[0]),
            f(hi[1]),
            f(hi[2])
        );
    }
    list(
        &mut s,
        "int[] faceVertexCounts",
        mesh.faces.iter().map(|p| p.len().to_string()),
    );
    list(
        &mut s,
        "int[] faceVertexIndices",
        mesh.faces.indices().iter().map(|v| v.to_string()),
    );
    list(
        &mut s,
        "point3f[] points",
        mesh.positions
            .iter()
            .map(|p| format!("({}, {}, {})", f(p[0]), f(p[1]), f(p[2]))),
    );
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
    let creases = tags.creases();
    if !creases.is_empty() {
        list(
            &mut s,
            "int[] creaseIndices",
            creases
                .iter()
                .flat_map(|((a, b), _)| [a.to_string(), b.to_string()]),
        );
        list(
            &mut s,
            "int[] creaseLengths",
            creases.iter().map(|_| "2".to_string()),
        );
        list(
            &mut s,
            "float[] creaseSharpnesses",
            creases.iter().map(|(_, w)| f(*w)),
        );
    }
    let corners = tags.corners();
    if !corners.is_empty() {
        list(
            &mut s,
            "int[] cornerIndices",
            corners.iter().map(|(v, _)| v.to_string()),
        );
        list(
            &mut s,
            "float[] cornerSharpnesses",
            corners.iter().map(|(_, w)| f(*w)),
        );
    }
    s.push_str("    }\n}\n");
    out.extend_from_slice(s.as_bytes());
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

fn list(s: &mut String, decl: &str, items: impl Iterator<Item = String>) {
    let _ = write!(s, "        {decl} = [");
    for (i, it) in items.enumerate() {
        if i > 0 {
            s.push_str(", ");
        }
        s.push_str(&it);
    }
    s.push_str("]\n");
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
    }
}
