//! OpenSubdiv's OBJ tag statements (`t crease 2/1/0 a b s`, `t corner 1/1/0 v s`): written
//! with a cage, read back to the same tags, skipped by the mesh reader, and malformed ones
//! rejected with their line.

use std::path::Path;

use subfit_io::obj::{read, read_tags, write_with_tags};
use subfit_io::{read_tags_file, write_obj_with_tags_file, ErrorKind, Location};
use subfit_mesh::shapes::cube_mesh;
use subfit_mesh::{Tags, SHARPNESS_INFINITE};

#[test]
fn tags_round_trip_through_obj_and_the_mesh_reader_skips_them() {
    let cube = cube_mesh(0.5);
    let mut tags = Tags::new();
    tags.set_crease(0, 1, SHARPNESS_INFINITE);
    tags.set_crease(3, 1, 2.5);
    tags.set_corner(7, SHARPNESS_INFINITE);
    let mut out = Vec::new();
    write_with_tags(&cube, &tags, &mut out).unwrap();
    let text = String::from_utf8(out.clone()).unwrap();
    assert!(text.contains("t crease 2/1/0 0 1 10\n"), "{text}");
    assert!(text.contains("t corner 1/1/0 7 10\n"), "{text}");
    let back = read(&out, Path::new("cage.obj"), &mut Vec::new()).unwrap();
    assert_eq!(back.positions, cube.positions);
    assert_eq!(back.faces, cube.faces);
    assert_eq!(read_tags(&out, Path::new("cage.obj"), 8).unwrap(), tags);

    let d = tempfile::tempdir().unwrap();
    let path = d.path().join("cage.obj");
    write_obj_with_tags_file(&path, &cube, &tags).unwrap();
    assert_eq!(read_tags_file(&path, 8).unwrap(), tags);
    // Other formats carry no tags.
    assert!(read_tags_file(&d.path().join("cage.ply"), 8)
        .unwrap()
        .is_empty());
}

#[test]
fn other_tags_are_skipped_and_bad_ones_named_by_line() {
    let p = Path::new("cage.obj");
    let ok = b"v 0 0 0\nt interpolateboundary 1/0/0 2\nt crease 2/1/0 0 1 3 # sharp\n";
    let tags = read_tags(ok, p, 2).unwrap();
    assert_eq!(tags.crease(1, 0), 3.0);
    for (text, line) in [
        (&b"v 0 0 0\nt crease 1/1/0 0 1\n"[..], 2),
        (b"t crease 2/1/0 0 9 1\n", 1),
        (b"\n\nt corner 1/1/0 0 -1\n", 3),
        (b"t corner 1/1/0 0 nan\n", 1),
        (b"t crease x/1/0 0 1 1\n", 1),
    ] {
        let e = read_tags(text, p, 2).unwrap_err();
        assert!(matches!(e.kind, ErrorKind::Syntax(_)), "{e}");
        assert_eq!(e.location, Location::Line(line), "{e}");
    }
}
