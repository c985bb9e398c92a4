//! Hand-written point lists in the variants real files come in: VTK/ioa3d `p x y z` files,
//! Leica PTS (count lines, `x y z i r g b`, several scans), colour versus normal columns
//! decided from the values, and files cut short (see `wild_variants.rs` for the real ones).

use std::path::Path;

use subfit_io::{read_bytes, Error, ErrorKind, Location, ReadOptions};
use subfit_mesh::PolyMesh;

fn ok(text: &str) -> (PolyMesh, Vec<String>) {
    match read_bytes(text.as_bytes(), Path::new("t.xyz"), &ReadOptions::default()) {
        Ok((m, info)) => (m, info.warnings),
        Err(e) => panic!("{e}\n{text}"),
    }
}

fn err(text: &str) -> Error {
    match read_bytes(text.as_bytes(), Path::new("t.xyz"), &ReadOptions::default()) {
        Ok((m, _)) => panic!("accepted {} points:\n{text}", m.positions.len()),
        Err(e) => e,
    }
}

fn warned(w: &[String], part: &str) -> bool {
    w.iter().any(|s| s.contains(part))
}

#[test]
fn vtk_pts_statements() {
    let text = "# Created by ioa3d\nd 1 1 1\ns 1 1 1\ng 1 0 0\np 0.5 0.25 1\np 1 2 3\n\
                g 0 1 0\np 4 5 6\n";
    let (m, w) = ok(text);
    assert_eq!(
        m.positions,
        vec![[0.5, 0.25, 1.0], [1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]
    );
    assert!(m.normals.is_none() && m.colors.is_none());
    assert!(warned(&w, "`g` ×2 (first on line 4)"), "{w:?}");
    assert!(warned(&w, "`d` ×1 (first on line 2)"), "{w:?}");
    // No point statement at all: said, with what the file holds.
    let e = err("d 1 1 1\ns 1 1 1\n");
    assert!(
        matches!(e.kind, ErrorKind::Syntax(ref s) if s.contains("no `p x y z`") && s.contains("`s`"))
    );
    // A bare number line among statements is an error naming it.
    let e = err("p 0 0 0\n1 2 3\n");
    assert_eq!(e.location, Location::Line(2));
    // `p` lines must agree on their values like any point list.
    let e = err("p 0 0 0\np 1 2\n");
    assert_eq!(e.location, Location::Line(2));
}

#[test]
fn leica_pts_counts_and_columns() {
    // Count line, x y z intensity r g b; intensity outside any colour range.
    let (m, w) = ok("2\n0 0 0 -1200 255 10 30\n1 1 1 350 0 128 255\n");
    assert_eq!(m.colors.unwrap(), vec![[255, 10, 30], [0, 128, 255]]);
    assert!(m.normals.is_none());
    assert!(warned(&w, "intensity in column 4"), "{w:?}");
    // Two scans, each after its count.
    let (m, _) = ok("2\n0 0 0 5\n1 1 1 5\n1\n2 2 2 5\n");
    assert_eq!(m.positions.len(), 3);
    // A count that does not match its block.
    let e = err("2\n0 0 0\n1\n2 2 2\n");
    assert_eq!(e.location, Location::Line(1));
    assert!(matches!(e.kind, ErrorKind::BadCount(_)), "{e}");
    let e = err("1\n0 0 0\n1 1 1\n");
    assert_eq!(e.location, Location::Line(1));
    // Only x y z i: the intensity is ignored.
    let (m, w) = ok("1\n0 0 0 0.5\n");
    assert_eq!(m.positions.len(), 1);
    assert!(warned(&w, "column(s) 4 ignored"), "{w:?}");
}

#[test]
fn six_columns_are_normals_or_colours_by_their_values() {
    // Unit vectors: normals.
    let (m, w) = ok("0 0 0 0 0 1\n1 0 0 0.6 0.8 0\n");
    assert_eq!(m.normals.unwrap()[1], [0.6, 0.8, 0.0]);
    assert!(m.colors.is_none());
    assert!(
        warned(&w, "nx ny nz in columns 4-6 (unit vectors)"),
        "{w:?}"
    );
    // Integers in 0..255: colours.
    let (m, w) =
        ok("5648349.89 665187.52 241.76 117 73 49\n5648349.77 665187.40 244.85 91 87 255\n");
    assert!(m.normals.is_none());
    assert_eq!(m.colors.unwrap(), vec![[117, 73, 49], [91, 87, 255]]);
    assert!(warned(&w, "colours, not normals"), "{w:?}");
    // Values in 0..1 that are not unit vectors: colours scaled by 255.
    let (m, _) = ok("0 0 0 1 0.5 0\n1 1 1 0.2 0.2 0.2\n");
    assert_eq!(m.colors.unwrap(), vec![[255, 128, 0], [51, 51, 51]]);
    // Neither: normals as written (scaled normals), and said.
    let (m, w) = ok("0 0 0 0 0 3\n1 1 1 -2 0 0\n");
    assert_eq!(m.normals.unwrap()[1], [-2.0, 0.0, 0.0]);
    assert!(warned(&w, "not unit vectors, not colour values"), "{w:?}");
    // Mostly unit with a few zero normals (points without an estimate): still normals.
    let mut text = String::new();
    for i in 0..19 {
        text += &format!("{i} 0 0 0 1 0\n");
    }
    text += "19 0 0 0 0 0\n";
    assert!(ok(&text).0.normals.is_some());
}

#[test]
fn seven_and_more_columns() {
    // CloudCompare `x y z r g b a`: constant opaque alpha.
    let (m, w) = ok("0 0 0 117.0 73.0 49.0 255.0\n1 1 1 91.0 87.0 74.0 255.0\n");
    assert_eq!(m.colors.unwrap(), vec![[117, 73, 49], [91, 87, 74]]);
    assert!(
        warned(&w, "alpha in column 7 (always 255, dropped)"),
        "{w:?}"
    );
    // A varying last column: Leica `x y z i r g b`.
    let (m, _) = ok("0 0 0 10 20 30 40\n1 1 1 11 21 31 41\n");
    assert_eq!(m.colors.unwrap(), vec![[20, 30, 40], [21, 31, 41]]);
    // Unit normals first, then something: normals, the rest ignored.
    let (m, _) = ok("0 0 0 0 0 1 0.7\n");
    assert!(m.normals.is_some() && m.colors.is_none());
    // Normals then colours, and colours then normals.
    let (m, _) = ok("0 0 0 0 1 0 9 8 7\n");
    assert_eq!(
        (m.normals.unwrap()[0], m.colors.unwrap()[0]),
        ([0.0, 1.0, 0.0], [9, 8, 7])
    );
    let (m, _) = ok("0 0 0 9 8 7 0 1 0\n");
    assert_eq!(
        (m.normals.unwrap()[0], m.colors.unwrap()[0]),
        ([0.0, 1.0, 0.0], [9, 8, 7])
    );
    // `x y z r g b a nx ny nz`.
    let (m, _) = ok("0 0 0 9 8 7 255 1 0 0\n");
    assert_eq!(
        (m.normals.unwrap()[0], m.colors.unwrap()[0]),
        ([1.0, 0.0, 0.0], [9, 8, 7])
    );
}

#[test]
fn nan_colours_read_as_zero_but_never_nan_positions_or_normals() {
    let (m, _) = ok("0 0 0 10 nan 30\n1 1 1 10 20 30\n");
    assert_eq!(m.colors.unwrap(), vec![[10, 0, 30], [10, 20, 30]]);
    let e = err("0 0 0\n1 nan 1\n");
    assert_eq!(e.location, Location::Line(2));
    assert!(matches!(e.kind, ErrorKind::NonFinite(_)));
    let e = err("0 0 0 0 0 1\n1 1 1 0 nan 1\n2 2 2 1 0 0\n");
    assert_eq!(e.location, Location::Line(2));
    assert!(
        matches!(e.kind, ErrorKind::NonFinite(ref s) if s.contains("normal")),
        "{e}"
    );
}

#[test]
fn a_file_cut_short_is_refused_naming_its_last_line() {
    let full = "0.1159 -0.5514 0.5933\n0.1023 -0.5919 0.5770\n";
    for cut in ["-0.1959", "-0.1959 0.2", "-0.1959 0.2 1e", "-"] {
        let e = err(&format!("{full}{cut}"));
        assert_eq!(e.location, Location::Line(3), "{cut}");
        let ErrorKind::Truncated(s) = &e.kind else {
            panic!("{cut}: {e}")
        };
        assert!(s.contains("seems truncated") && s.contains(cut), "{s}");
    }
    // Complete last line without a line break: read.
    assert_eq!(ok(&format!("{full}1 2 3")).0.positions.len(), 3);
    // A short line that ends with a line break, or is not the last, is a plain error.
    for text in [format!("{full}1 2\n"), format!("0 0 0\n1 2\n{full}")] {
        let e = err(&text);
        assert!(
            matches!(e.kind, ErrorKind::Syntax(ref s) if s.contains("columns")),
            "{e}"
        );
    }
    // A counted file cut at a line end: the count says so, and the missing line break too.
    let e = err(&format!("3\n{}", full.trim_end()));
    assert!(
        matches!(e.kind, ErrorKind::BadCount(ref s) if s.contains("seems truncated")),
        "{e}"
    );
}
