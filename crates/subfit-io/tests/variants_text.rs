//! Hand-written text files in the variants real files come in (see `wild_variants.rs` for the
//! real ones): OFF with a glued keyword and faces over several lines, OBJ with empty corner
//! slots, partial `vt`, non-UTF-8 names and per-corner normals, MNI surfaces. Each checks what
//! is read and what the reader says about it.

use std::path::Path;

use subfit_io::{read_bytes, Error, ErrorKind, FileInfo, Location, ReadOptions};
use subfit_mesh::PolyMesh;

fn read(name: &str, bytes: &[u8]) -> Result<(PolyMesh, FileInfo), Error> {
    read_bytes(bytes, Path::new(name), &ReadOptions::default())
}

fn ok(name: &str, bytes: &[u8]) -> (PolyMesh, Vec<String>) {
    let (m, info) =
        read(name, bytes).unwrap_or_else(|e| panic!("{e}\n{}", String::from_utf8_lossy(bytes)));
    (m, info.warnings)
}

fn err(name: &str, bytes: &[u8]) -> Error {
    match read(name, bytes) {
        Ok((m, _)) => panic!("accepted {} points", m.positions.len()),
        Err(e) => e,
    }
}

fn faces(m: &PolyMesh) -> Vec<Vec<u32>> {
    m.faces.iter().map(|f| f.to_vec()).collect()
}

fn warned(w: &[String], part: &str) -> bool {
    w.iter().any(|s| s.contains(part))
}

// ------------------------------------------------------------------------------------ OFF

#[test]
fn off_keyword_glued_to_the_counts_after_blanks() {
    let text =
        b"\t   OFF4 1 0 # a comment\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 1.0 0.0 0.0 0.75\n";
    let (m, w) = ok("t.off", text);
    assert_eq!(m.positions.len(), 4);
    assert_eq!(faces(&m), vec![vec![0, 1, 2, 3]]);
    assert!(w.is_empty(), "{w:?}");
    // The same with the keyword announcing colours, glued as well.
    let (m, _) = ok(
        "t.off",
        b"COFF3 1 0\n0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n3 0 1 2\n",
    );
    assert_eq!(m.colors.unwrap()[2], [0, 0, 255]);
    // Not a glued count: still an unknown keyword.
    let e = err("t.off", b"OFFx 1 0\n");
    assert!(
        matches!(e.kind, ErrorKind::Syntax(ref s) if s.contains("OFFx")),
        "{e}"
    );
}

#[test]
fn off_faces_spread_over_lines() {
    let text = b"OFF\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 2 2\n\
                 4 0 1\n  2\n3 0.5 0.5 0.5\n\
                 3 # the count alone\n4\n1 2\n";
    let (m, _) = ok("t.off", text);
    assert_eq!(faces(&m), vec![vec![0, 1, 2, 3], vec![4, 1, 2]]);
    // A face whose indices never come: named at its first line.
    let e = err("t.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0\n1\n");
    assert_eq!(e.location, Location::Line(6));
    assert!(
        matches!(e.kind, ErrorKind::Syntax(ref s) if s.contains("lists 2")),
        "{e}"
    );
    // An index out of range on a continuation line is named at that line.
    let e = err("t.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0\n1 7\n");
    assert_eq!(e.location, Location::Line(7));
    assert!(matches!(
        e.kind,
        ErrorKind::IndexOutOfRange { index: 7, count: 3 }
    ));
}

#[test]
fn off_comments_may_hold_any_bytes() {
    let (m, _) = ok(
        "t.off",
        b"OFF # caf\xe9\n3 1 0\n0 0 0\n1 0 0 # \xff\xfe\n0 1 0\n3 0 1 2\n",
    );
    assert_eq!(m.positions.len(), 3);
    let e = err("t.off", b"OFF\n3 1 0\n0 0 0\n1 \xe9 0\n0 1 0\n3 0 1 2\n");
    assert_eq!(e.location, Location::Line(4));
    assert!(e.to_string().contains("not UTF-8"), "{e}");
}

// ------------------------------------------------------------------------------------ OBJ

const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

#[test]
fn obj_empty_corner_slots() {
    for corners in [
        "1// 2// 3// 4//",
        "1/ 2/ 3/ 4/",
        "1/1/ 2/1/ 3/1/ 4/1/",
        "1// 2/1 3 4/1/",
    ] {
        let text = format!("{SQUARE}vt 0 0\nf {corners}\n");
        let (m, _) = ok("t.obj", text.as_bytes());
        assert_eq!(faces(&m), vec![vec![0, 1, 2, 3]], "{corners}");
        assert!(m.normals.is_none());
    }
    for bad in ["/1", "//", "1/2/3/4"] {
        let e = err("t.obj", format!("{SQUARE}f {bad} 2 3\n").as_bytes());
        assert_eq!(e.location, Location::Line(5), "{bad}");
        assert!(
            matches!(e.kind, ErrorKind::Syntax(ref s) if s.contains("corner")),
            "{e}"
        );
    }
}

#[test]
fn obj_texture_coordinates_on_some_faces_only() {
    let text = format!("{SQUARE}vt 0 0\nvt 1 0\nvt 1 1\nf 1 2 3\nf 1/1 3/3 4/2\nf 2/2 3/3 4\n");
    let (m, _) = ok("t.obj", text.as_bytes());
    assert_eq!(faces(&m), vec![vec![0, 1, 2], vec![0, 2, 3], vec![1, 2, 3]]);
}

#[test]
fn obj_names_and_comments_may_hold_any_bytes() {
    let mut text = b"# Max2Obj caf\xe9\nmtllib r\xe9gr.mtl\ng Terrain\xe6k\no \xff\xfe\n".to_vec();
    text.extend_from_slice(SQUARE.as_bytes());
    text.extend_from_slice(b"usemtl TerraindM-\xe6k\ns off\nf 1 2 3 4 # \xe9\n");
    let (m, _) = ok("t.obj", &text);
    assert_eq!(faces(&m), vec![vec![0, 1, 2, 3]]);
    // Numbers must still be numbers: the line is named and the bytes called out.
    let e = err("t.obj", b"v 0 0 0\nv 1 \xe9 0\n");
    assert_eq!(e.location, Location::Line(2));
    assert!(
        matches!(e.kind, ErrorKind::Syntax(ref s) if s.contains("UTF-8")),
        "{e}"
    );
    // An unknown statement in bytes is still an unknown statement.
    let e = err("t.obj", b"v 0 0 0\n\xe9t 1\n");
    assert!(matches!(e.kind, ErrorKind::Syntax(ref s) if s.contains("unknown OBJ statement")));
}

#[test]
fn obj_corner_normals_become_vertex_normals() {
    // A folded pair of triangles with one `vn` per face: the shared edge's vertices average
    // them, the others keep their face's normal exactly as written.
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 -1\nvn -1 0 0\n\
                f 1//1 3//1 2//1\nf 1//2 4//2 3//2\n";
    let (m, w) = ok("t.obj", text.as_bytes());
    let n = m.normals.unwrap();
    let h = std::f64::consts::FRAC_1_SQRT_2;
    for v in [0, 2] {
        assert!((n[v][0] + h).abs() < 1e-15 && n[v][1] == 0.0 && (n[v][2] + h).abs() < 1e-15);
    }
    assert_eq!(n[1], [0.0, 0.0, -1.0]);
    assert_eq!(n[3], [-1.0, 0.0, 0.0]);
    assert!(
        warned(&w, "2 vertices have corners with different normals"),
        "{w:?}"
    );
    // Opposite normals cancel: the first corner's is kept.
    let text =
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 -1\nf 1//1 2//1 3//1\nf 1//2 3//2 2//2\n";
    assert_eq!(
        ok("t.obj", text.as_bytes()).0.normals.unwrap()[0],
        [0.0, 0.0, 1.0]
    );
    // Corners without a normal are passed over while every vertex has one elsewhere.
    let text = format!("{SQUARE}vn 0 0 1\nf 1//1 2//1 3//1 4//1\nf 1 3 4\n");
    let (m, w) = ok("t.obj", text.as_bytes());
    assert_eq!(m.normals.unwrap(), vec![[0.0, 0.0, 1.0]; 4]);
    assert!(warned(&w, "3 face corners have no `vn`"), "{w:?}");
    // A vertex with no normal at all: dropped, and said.
    let text = format!("{SQUARE}vn 0 0 1\nf 1//1 2//1 3//1\nf 1 3 4\n");
    let (m, w) = ok("t.obj", text.as_bytes());
    assert!(m.normals.is_none());
    assert!(warned(&w, "1 of 4 vertices have no normal"), "{w:?}");
}

// ------------------------------------------------------------------------------------ MNI

/// A tetrahedron as an MNI polygon surface, colour flag 2 (per point).
const MNI: &str = "P 0.3 0.3 0.4 10 1 4\n 0 0 0\n 1 0 0\n 0 1 0\n 0 0 1\n\n\
                   -1 -1 -1\n 0 0 -1\n 0 -1 0\n -1 0 0\n\n 4\n 2 1 0 0 1 0 1 0 1 0 0 1 1 1 1 1 1\n\n\
                   3 6 9 12\n 0 2 1 0 1 3 0 3 2 1 2 3\n";

#[test]
fn mni_surface_is_read_from_an_obj_extension() {
    let (m, w) = ok("brain.obj", MNI.as_bytes());
    assert_eq!(m.positions.len(), 4);
    assert_eq!(
        faces(&m),
        vec![vec![0, 2, 1], vec![0, 1, 3], vec![0, 3, 2], vec![1, 2, 3]]
    );
    assert_eq!(m.normals.unwrap()[1], [0.0, 0.0, -1.0]);
    assert_eq!(
        m.colors.unwrap(),
        vec![[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]]
    );
    assert!(warned(&w, "MNI"), "{w:?}");
    // Flag 0: one colour for the object; no per-point colours.
    let one = MNI.replace("2 1 0 0 1 0 1 0 1 0 0 1 1 1 1 1 1", "0 1 1 1 1");
    assert!(ok("brain.obj", one.as_bytes()).0.colors.is_none());
}

#[test]
fn mni_errors_say_what_the_file_is() {
    let e = err("lines.obj", b"L 0.5 3\n0 0 0\n1 0 0\n0 1 0\n");
    assert!(
        matches!(e.kind, ErrorKind::Unsupported(ref s) if s.contains("MNI") && s.contains("lines"))
    );
    let cut = &MNI[..MNI.len() - 8];
    let e = err("brain.obj", cut.as_bytes());
    assert!(
        matches!(e.kind, ErrorKind::Truncated(ref s) if s.contains("MNI")),
        "{e}"
    );
    let e = err("brain.obj", MNI.replace("1 2 3\n", "1 2 9\n").as_bytes());
    assert!(
        matches!(e.kind, ErrorKind::IndexOutOfRange { index: 9, count: 4 }),
        "{e}"
    );
    let e = err("brain.obj", format!("{MNI}7\n").as_bytes());
    assert!(
        matches!(e.kind, ErrorKind::Syntax(ref s) if s.contains("after the last")),
        "{e}"
    );
    let e = err("brain.obj", MNI.replace("3 6 9 12", "3 6 8 12").as_bytes());
    assert!(matches!(e.kind, ErrorKind::BadCount(_)), "{e}");
    // A Wavefront file is never taken for MNI: `p` is Wavefront's point statement.
    let (m, _) = ok("t.obj", b"p 1\nv 0 0 0\n");
    assert_eq!(m.positions.len(), 1);
}
