//! Crease and corner tags as a JSON sidecar (`control.tags.json`), for readers that ignore the
//! tags of the cage file itself.
//!
//! Where tags are understood: control.usda's `creaseIndices`/`creaseLengths`/
//! `creaseSharpnesses`/`cornerIndices`/`cornerSharpnesses` are read by usdview, Houdini,
//! Blender's USD importer and OpenSubdiv; control.obj's `t crease`/`t corner` statements
//! ([`crate::obj`]) by OpenSubdiv's own OBJ reader (its tutorials' `Shape`) and by subfit, but
//! not by Blender's, Maya's or most other OBJ importers, which skip `t` lines. This sidecar
//! carries the same tags for any other tool:
//!
//! ```json
//! {
//!   "format": "subfit-tags",
//!   "version": 1,
//!   "vertex_count": 8,
//!   "sharpness_infinite": 10,
//!   "creases": [{"vertices": [0, 1], "sharpness": 10}],
//!   "corners": [{"vertex": 0, "sharpness": 10}]
//! }
//! ```
//!
//! Vertex indices are 0-based into the cage's vertex list (control.obj's `v` lines in order);
//! sharpness follows OpenSubdiv (`sharpness_infinite` and above: infinitely sharp). Creases
//! are sorted by their vertex pair, corners by vertex.

use std::fmt::Write as _;

use subfit_mesh::{Tags, SHARPNESS_INFINITE};

/// The tags of a cage of `vertex_count` vertices as the sidecar JSON (see the module docs),
/// ending with a newline.
pub fn write(tags: &Tags, vertex_count: usize) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        "{{\n  \"format\": \"subfit-tags\",\n  \"version\": 1,\n  \"vertex_count\": {vertex_count},\n  \"sharpness_infinite\": {},\n  \"creases\": [",
        number(SHARPNESS_INFINITE)
    );
    let creases = tags.creases();
    for (i, ((a, b), sharp)) in creases.iter().enumerate() {
        let sep = if i == 0 { "\n    " } else { ",\n    " };
        let _ = write!(
            s,
            "{sep}{{\"vertices\": [{a}, {b}], \"sharpness\": {}}}",
            number(*sharp)
        );
    }
    s.push_str(if creases.is_empty() {
        "],\n"
    } else {
        "\n  ],\n"
    });
    s.push_str("  \"corners\": [");
    let corners = tags.corners();
    for (i, (v, sharp)) in corners.iter().enumerate() {
        let sep = if i == 0 { "\n    " } else { ",\n    " };
        let _ = write!(
            s,
            "{sep}{{\"vertex\": {v}, \"sharpness\": {}}}",
            number(*sharp)
        );
    }
    s.push_str(if corners.is_empty() {
        "]\n}\n"
    } else {
        "\n  ]\n}\n"
    });
    s
}

/// A JSON number: the shortest round-trip form of a finite `x` (tags are finite).
fn number(x: f64) -> String {
    if x.is_finite() {
        let mut b = ryu::Buffer::new();
        b.format_finite(x).trim_end_matches(".0").to_string()
    } else {
        "null".into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tags_are_written_in_order() {
        let mut tags = Tags::new();
        tags.set_crease(3, 1, SHARPNESS_INFINITE);
        tags.set_crease(0, 2, 2.5);
        tags.set_corner(4, SHARPNESS_INFINITE);
        let s = write(&tags, 5);
        let creases = s.find("\"vertices\": [0, 2], \"sharpness\": 2.5").unwrap();
        let second = s.find("\"vertices\": [1, 3], \"sharpness\": 10}").unwrap();
        assert!(creases < second, "{s}");
        assert!(s.contains("{\"vertex\": 4, \"sharpness\": 10}"), "{s}");
        assert!(s.contains("\"vertex_count\": 5"), "{s}");
        let empty = write(&Tags::new(), 3);
        assert!(
            empty.contains("\"creases\": [],\n  \"corners\": []\n}"),
            "{empty}"
        );
    }
}
