//! OBJ, OFF, STL and XYZ: round trips, every accepted form, every malformed case with its
//! error kind and location, and the shared data corpus (`SUBFIT_DATA`).

use std::path::{Path, PathBuf};

use subfit_io::{
    read_bytes, write_bytes, Encoding, Error, ErrorKind, Format, Location, ReadOptions,
    WriteOptions,
};
use subfit_mesh::{PolyMesh, Polygons};

/// A malformed input, where the error must be, and a test of its kind.
type Case<T> = (T, Location, fn(&ErrorKind) -> bool);

fn read_as(format: Format, text: &[u8]) -> Result<PolyMesh, Error> {
    let opts = ReadOptions {
        format: Some(format),
        ..ReadOptions::default()
    };
    read_bytes(text, Path::new("test"), &opts).map(|(m, _)| m)
}

fn ok(format: Format, text: &str) -> PolyMesh {
    read_as(format, text.as_bytes()).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn err(format: Format, text: impl AsRef<[u8]>) -> Error {
    match read_as(format, text.as_ref()) {
        Ok(m) => panic!("accepted: {m:?}"),
        Err(e) => e,
    }
}

fn write(mesh: &PolyMesh, format: Format, encoding: Encoding) -> Vec<u8> {
    let opts = WriteOptions {
        format: Some(format),
        encoding,
        ..WriteOptions::default()
    };
    write_bytes(mesh, format, &opts).unwrap()
}

fn faces(m: &PolyMesh) -> Vec<Vec<u32>> {
    m.faces.iter().map(|f| f.to_vec()).collect()
}

/// A closed octahedron with awkward coordinates (thirds, tiny and huge values, -0.0) and
/// one quad-free triangle list; plus per-vertex normals and colours.
fn octahedron() -> PolyMesh {
    let positions = vec![
        [1.0 / 3.0, 0.0, -0.0],
        [-1.0 / 3.0, 1e-300, 0.0],
        [0.0, 2.0 / 3.0, 0.1],
        [0.0, -2.0 / 3.0, 0.2],
        [0.0, 6.02e23, 1.0 / 7.0],
        [-0.0, 0.0, -1.0 / 7.0],
    ];
    let tris = [
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    let mut m = PolyMesh::new(positions, Polygons::from_triangles(&tris));
    m.normals = Some(
        m.positions
            .iter()
            .map(|p| [p[0] * 0.5, p[1] - 0.25, 1.0 / 3.0])
            .collect(),
    );
    m.colors = Some((0..6).map(|i| [i * 40, 255 - i * 40, 7]).collect());
    m
}

fn bits(v: &[[f64; 3]]) -> Vec<[u64; 3]> {
    v.iter().map(|p| p.map(f64::to_bits)).collect()
}

/// Bit equality of two coordinate lists, reporting only the first difference.
#[track_caller]
fn same_bits(a: &[[f64; 3]], b: &[[f64; 3]], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths");
    if let Some(i) = (0..a.len()).find(|&i| bits(&a[i..=i]) != bits(&b[i..=i])) {
        panic!("{what}: row {i}: {:?} != {:?}", a[i], b[i]);
    }
}

fn polygons() -> PolyMesh {
    let positions = (0..7)
        .map(|i| [i as f64 * 0.1, (i * i) as f64 / 3.0, -(i as f64)])
        .collect();
    let mut faces = Polygons::new();
    faces.push(&[0, 1, 2]);
    faces.push(&[0, 2, 3, 4]);
    faces.push(&[4, 3, 2, 1, 5, 6]);
    PolyMesh::new(positions, faces)
}

// ----------------------------------------------------------------------------- round trips

#[test]
fn obj_round_trip_is_bit_exact() {
    let mut m = octahedron();
    m.colors = None;
    let back = ok(
        Format::Obj,
        std::str::from_utf8(&write(&m, Format::Obj, Encoding::Ascii)).unwrap(),
    );
    same_bits(&back.positions, &m.positions, "positions");
    same_bits(
        back.normals.as_ref().unwrap(),
        m.normals.as_ref().unwrap(),
        "normals",
    );
    assert_eq!(back.faces, m.faces);
    assert_eq!(back.colors, None);

    let p = polygons();
    let back = ok(
        Format::Obj,
        std::str::from_utf8(&write(&p, Format::Obj, Encoding::Ascii)).unwrap(),
    );
    assert_eq!(back, p);
}

#[test]
fn off_round_trip_all_variants() {
    let full = octahedron();
    for (normals, colors, keyword) in [
        (false, false, "OFF"),
        (true, false, "NOFF"),
        (false, true, "COFF"),
        (true, true, "CNOFF"),
    ] {
        let mut m = full.clone();
        if !normals {
            m.normals = None;
        }
        if !colors {
            m.colors = None;
        }
        let text = write(&m, Format::Off, Encoding::Ascii);
        assert!(text.starts_with(keyword.as_bytes()), "{keyword}");
        let back = ok(Format::Off, std::str::from_utf8(&text).unwrap());
        same_bits(&back.positions, &m.positions, "positions");
        assert_eq!(
            back.normals.as_deref().map(bits),
            m.normals.as_deref().map(bits)
        );
        assert_eq!(back.colors, m.colors);
        assert_eq!(back.faces, m.faces);
    }
    let p = polygons();
    assert_eq!(
        ok(
            Format::Off,
            std::str::from_utf8(&write(&p, Format::Off, Encoding::Ascii)).unwrap()
        ),
        p
    );
}

#[test]
fn xyz_round_trip() {
    let mut m = octahedron();
    m.colors = None;
    m.faces = Polygons::new();
    let back = ok(
        Format::Xyz,
        std::str::from_utf8(&write(&m, Format::Xyz, Encoding::Ascii)).unwrap(),
    );
    same_bits(&back.positions, &m.positions, "positions");
    same_bits(
        back.normals.as_ref().unwrap(),
        m.normals.as_ref().unwrap(),
        "normals",
    );
    m.normals = None;
    let back = ok(
        Format::Xyz,
        std::str::from_utf8(&write(&m, Format::Xyz, Encoding::Ascii)).unwrap(),
    );
    assert_eq!(back, m);
}

#[test]
fn stl_round_trip_welds_back_to_the_closed_mesh() {
    let mut m = octahedron();
    m.normals = None;
    m.colors = None;
    m.positions[4][1] = 6.0; // keep the f32 round trip meaningful
    let as_f32: Vec<[f64; 3]> = m
        .positions
        .iter()
        .map(|p| p.map(|c| c as f32 as f64))
        .collect();
    for enc in [Encoding::BinaryLittleEndian, Encoding::Ascii] {
        let bytes = write(&m, Format::Stl, enc);
        let (back, info) = read_bytes(&bytes, Path::new("x.stl"), &ReadOptions::default()).unwrap();
        assert_eq!(info.encoding, enc);
        assert_eq!(back.positions.len(), 6, "{enc:?}");
        assert_eq!(back.faces.len(), 8);
        // Vertices come in order of first use, which is 0 2 4 1 3 5 here.
        let order = [0usize, 2, 4, 1, 3, 5];
        for (k, &v) in order.iter().enumerate() {
            let got = back.positions[k].map(|c| c as f32);
            assert_eq!(got, as_f32[v].map(|c| c as f32), "{enc:?} vertex {k}");
        }
        // Unwelded: one vertex per corner.
        let opts = ReadOptions {
            weld_stl: false,
            ..ReadOptions::default()
        };
        let (raw, _) = read_bytes(&bytes, Path::new("x.stl"), &opts).unwrap();
        assert_eq!(raw.positions.len(), 24);
    }
    // Polygons become fans.
    let p = polygons();
    let bytes = write(&p, Format::Stl, Encoding::BinaryLittleEndian);
    assert_eq!(bytes.len(), 84 + 50 * (1 + 2 + 4));
    assert!(!bytes.starts_with(b"solid"));
}

#[test]
fn stl_weld_treats_negative_zero_as_zero() {
    let text =
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n\
                endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex -0 -0.0 0\nvertex 0 1 0\n\
                vertex -1 0 0\nendloop\nendfacet\nendsolid t\n";
    let m = ok(Format::Stl, text);
    assert_eq!(m.positions.len(), 4);
    assert_eq!(faces(&m), vec![vec![0, 1, 2], vec![0, 2, 3]]);
}

// ----------------------------------------------------------------------------- OBJ forms

#[test]
fn obj_all_face_forms_and_negative_indices() {
    let text = "# a comment\nmtllib x.mtl\no thing\ng group\ns 1\nusemtl red\n\
                v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0 1.0\n\
                vt 0 0\nvt 1 0\nvt 1 1 0\n\
                vn 0 0 1\n\
                f 1 2 3\nf 1/1 2/2 3/3\nf 1//1 3//1 4//1\nf 1/1/1 2/2/1 3/3/1 4/1/1\n\
                f -4 -3 -2 -1\nf -4/-3/-1 -2/-1/-1 -1//-1\n\
                l 1 2\np 3\n";
    let m = ok(Format::Obj, text);
    assert_eq!(m.positions.len(), 4);
    assert_eq!(
        faces(&m),
        vec![
            vec![0, 1, 2],
            vec![0, 1, 2],
            vec![0, 2, 3],
            vec![0, 1, 2, 3],
            vec![0, 1, 2, 3],
            vec![0, 2, 3]
        ]
    );
    // Some corners have no normal, but every vertex has a corner with `vn 0 0 1`: kept.
    assert_eq!(m.normals.unwrap(), vec![[0.0, 0.0, 1.0]; 4]);
}

#[test]
fn obj_normals_consistent_split_and_paired() {
    let consistent = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nvn 0 0 1\nvn 0 0 -1\n\
                      f 1//1 2//2 3//1\nf 2//2 4//3 3//1\n";
    let m = ok(Format::Obj, consistent);
    assert_eq!(
        m.normals.unwrap(),
        vec![
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0]
        ]
    );
    // Same values under different indices count as the same normal.
    let by_value =
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 1\nf 1//1 2//1 3//1\nf 1//2 3//2 2//2\n";
    assert!(ok(Format::Obj, by_value).normals.is_some());
    // Vertex 1 gets two different normals: their normalized mean; the others keep theirs.
    let split =
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 2 0 0\nf 1//1 2//1 3//1\nf 1//2 3//1 2//1\n";
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let n = ok(Format::Obj, split).normals.unwrap();
    assert!((n[0][0] - h).abs() < 1e-15 && n[0][1] == 0.0 && (n[0][2] - h).abs() < 1e-15);
    assert_eq!(&n[1..], &[[0.0, 0.0, 1.0]; 2]);
    // An unused vertex has no normal: dropped.
    let unused = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nvn 0 0 1\nf 1//1 2//1 3//1\n";
    assert!(ok(Format::Obj, unused).normals.is_none());
    // Point cloud with normals: paired in order.
    let cloud = "v 0 0 0\nvn 1 0 0\nv 1 0 0\nvn 0 1 0\n";
    let m = ok(Format::Obj, cloud);
    assert_eq!(m.normals.unwrap(), vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    assert!(m.faces.is_empty());
}

#[test]
fn obj_colours_continuation_and_forward_references() {
    let m = ok(
        Format::Obj,
        "v 0 0 0 1 0 0.5\nv 1 0 0 0 1 2\nv 0 1 0 0 0 0\nf 1 2 3\n",
    );
    assert_eq!(
        m.colors.unwrap(),
        vec![[255, 0, 128], [0, 255, 255], [0, 0, 0]]
    );
    // Colour on only some vertices: dropped.
    let m = ok(Format::Obj, "v 0 0 0 1 0 0.5\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    assert!(m.colors.is_none());
    // Continuation lines (also with CRLF endings), and faces before their vertices.
    let m = ok(
        Format::Obj,
        "f 1 \\\r\n 2 \\\n3\r\nv 0 0 \\\n 0\nv 1 0 0\nv 0 1 0\n",
    );
    assert_eq!(faces(&m), vec![vec![0, 1, 2]]);
    assert_eq!(m.positions[0], [0.0; 3]);
}

#[test]
fn obj_errors() {
    let cases: Vec<Case<&str>> = vec![
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
            Location::Line(4),
            |k| matches!(k, ErrorKind::IndexOutOfRange { index: 4, count: 3 }),
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",
            Location::Line(4),
            |k| {
                matches!(
                    k,
                    ErrorKind::IndexOutOfRange {
                        index: -4,
                        count: 3
                    }
                )
            },
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
            Location::Line(4),
            |k| matches!(k, ErrorKind::Syntax(s) if s.contains("index 0")),
        ),
        (
            "v 0 0 0\nv 1 nan 0\n",
            Location::Line(2),
            |k| matches!(k, ErrorKind::NonFinite(s) if s.contains("nan")),
        ),
        ("v 0 0 0\nvn inf 0 0\n", Location::Line(2), |k| {
            matches!(k, ErrorKind::NonFinite(_))
        }),
        (
            "v 0 0 0\nv 1 0 x1\n",
            Location::Line(2),
            |k| matches!(k, ErrorKind::Syntax(s) if s.contains("`x1`")),
        ),
        ("v 0 0\n", Location::Line(1), |k| {
            matches!(k, ErrorKind::Syntax(_))
        }),
        ("v 0 0 0 1 2\n", Location::Line(1), |k| {
            matches!(k, ErrorKind::Syntax(_))
        }),
        (
            "v 0 0 0\nv 1 0 0\nf 1 2\n",
            Location::Line(3),
            |k| matches!(k, ErrorKind::Syntax(s) if s.contains("2 corner")),
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf /1 2 3\n",
            Location::Line(4),
            |k| matches!(k, ErrorKind::Syntax(s) if s.contains("`/1`")),
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//2 2 3\n",
            Location::Line(4),
            |k| matches!(k, ErrorKind::Syntax(s) if s.contains("normal index 2")),
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n",
            Location::Line(4),
            |k| matches!(k, ErrorKind::Syntax(_)),
        ),
        (
            "v 0 0 0\nbogus 1 2\n",
            Location::Line(2),
            |k| matches!(k, ErrorKind::Syntax(s) if s.contains("`bogus`")),
        ),
        ("# only a comment\no x\n", Location::File, |k| {
            matches!(k, ErrorKind::Empty)
        }),
        ("", Location::File, |k| matches!(k, ErrorKind::Empty)),
        ("v 0 0 0\nv 1 0 0\n\u{fffd}", Location::Line(3), |_| true),
    ];
    for (text, loc, want) in cases {
        let e = err(Format::Obj, text);
        assert_eq!(e.location, loc, "{text:?}: {e}");
        assert!(want(&e.kind), "{text:?}: {e}");
    }
    // Invalid UTF-8 on line 2.
    let e = err(Format::Obj, b"v 0 0 0\nv 1 \xff 0\n");
    assert_eq!(e.location, Location::Line(2));
    assert!(
        matches!(e.kind, ErrorKind::Syntax(ref s) if s.contains("UTF-8")),
        "{e}"
    );
}

// ----------------------------------------------------------------------------- OFF forms

#[test]
fn off_variants_with_comments() {
    let plain = "# leading comment\n\nOFF # keyword\n# counts next\n4 2 0\n0 0 0\n1 0 0 # v1\n\n\
                 1 1 0\n0 1 0\n3 0 1 2\n# between faces\n4 0 1 2 3 255 0 0\n";
    let m = ok(Format::Off, plain);
    assert_eq!(m.positions.len(), 4);
    assert_eq!(faces(&m), vec![vec![0, 1, 2], vec![0, 1, 2, 3]]);
    assert!(m.normals.is_none() && m.colors.is_none());

    let same_line = "OFF 3 1 3\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert_eq!(ok(Format::Off, same_line).faces.len(), 1);
    let no_keyword = "3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert_eq!(ok(Format::Off, no_keyword).faces.len(), 1);

    let coff_ints = "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0\n0 1 0 0 0 128 10\n3 0 1 2\n";
    let m = ok(Format::Off, coff_ints);
    assert_eq!(
        m.colors.unwrap(),
        vec![[255, 0, 0], [0, 255, 0], [0, 0, 128]]
    );
    let coff_floats = "COFF\n3 1 0\n0 0 0 1.0 0 0 1\n1 0 0 0 1 0.5 1\n0 1 0 0 0 0 1e0\n3 0 1 2\n";
    let m = ok(Format::Off, coff_floats);
    assert_eq!(
        m.colors.unwrap(),
        vec![[255, 0, 0], [0, 255, 128], [0, 0, 0]]
    );

    let noff = "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n";
    assert_eq!(
        ok(Format::Off, noff).normals.unwrap(),
        vec![[0.0, 0.0, 1.0]; 3]
    );
    for kw in ["CNOFF", "NCOFF"] {
        let text = format!(
            "{kw}\n3 1 0\n0 0 0 0 0 1 1 2 3\n1 0 0 0 0 1 1 2 3 4\n0 1 0 0 0 1 1 2 3\n3 0 1 2\n"
        );
        let m = ok(Format::Off, &text);
        assert_eq!(m.normals.unwrap().len(), 3);
        assert_eq!(m.colors.unwrap(), vec![[1, 2, 3]; 3]);
    }
    let stoff = "STOFF\n3 1 0\n0 0 0 0.5 0.5\n1 0 0 1 0\n0 1 0 0 1\n3 0 1 2\n";
    assert_eq!(ok(Format::Off, stoff).positions.len(), 3);
    let empty = "OFF\n0 0 0\n";
    assert!(ok(Format::Off, empty).positions.is_empty());
}

#[test]
fn off_errors() {
    let cases: Vec<Case<&str>> = vec![
        (
            "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n",
            Location::Element {
                kind: "vertex".into(),
                index: 3,
            },
            |k| matches!(k, ErrorKind::Truncated(_)),
        ),
        (
            "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
            Location::Element {
                kind: "face".into(),
                index: 1,
            },
            |k| matches!(k, ErrorKind::Truncated(_)),
        ),
        (
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n",
            Location::Line(7),
            |k| matches!(k, ErrorKind::BadCount(_)),
        ),
        (
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
            Location::Line(6),
            |k| matches!(k, ErrorKind::IndexOutOfRange { index: 3, count: 3 }),
        ),
        (
            "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n",
            Location::Line(6),
            |k| {
                matches!(
                    k,
                    ErrorKind::IndexOutOfRange {
                        index: -1,
                        count: 3
                    }
                )
            },
        ),
        ("OFF\n-3 1 0\n", Location::Line(2), |k| {
            matches!(k, ErrorKind::BadCount(_))
        }),
        (
            "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0 7\n3 0 1 2\n",
            Location::Line(5),
            |k| matches!(k, ErrorKind::Syntax(s) if s.contains("4 values")),
        ),
        (
            "OFF\n3 1\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n",
            Location::Line(4),
            |k| matches!(k, ErrorKind::NonFinite(_)),
        ),
        (
            "OFF\n3 1\n0 0 0\n1 0 0\n0 1 z\n3 0 1 2\n",
            Location::Line(5),
            |k| matches!(k, ErrorKind::Syntax(s) if s.contains("`z`")),
        ),
        (
            "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n",
            Location::Line(6),
            |k| matches!(k, ErrorKind::Syntax(s) if s.contains("lists 3")),
        ),
        (
            "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n",
            Location::Line(6),
            |k| matches!(k, ErrorKind::Syntax(_)),
        ),
        (
            "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 1 1 1 1 1\n",
            Location::Line(6),
            |k| matches!(k, ErrorKind::Syntax(_)),
        ),
        ("4OFF\n1 0 0\n0 0 0 0\n", Location::Line(1), |k| {
            matches!(k, ErrorKind::Unsupported(_))
        }),
        ("nOFF\n3\n", Location::Line(1), |k| {
            matches!(k, ErrorKind::Unsupported(_))
        }),
        (
            "OFF BINARY\n",
            Location::Byte(11),
            |k| matches!(k, ErrorKind::Truncated(s) if s.contains("binary OFF")),
        ),
        (
            "OFX\n",
            Location::Line(1),
            |k| matches!(k, ErrorKind::Syntax(s) if s.contains("`OFX`")),
        ),
        ("OFF\n", Location::Line(1), |k| {
            matches!(k, ErrorKind::Truncated(_))
        }),
        ("# nothing\n", Location::File, |k| {
            matches!(k, ErrorKind::Empty)
        }),
    ];
    for (text, loc, want) in cases {
        let e = err(Format::Off, text);
        assert_eq!(e.location, loc, "{text:?}: {e}");
        assert!(want(&e.kind), "{text:?}: {e}");
    }
    // A lying count allocates nothing big and reports the truncation.
    let e = err(Format::Off, "OFF\n4000000000 4000000000 0\n0 0 0\n");
    assert!(matches!(e.kind, ErrorKind::Truncated(_)), "{e}");
}

// ----------------------------------------------------------------------------- STL forms

fn binary_stl(tris: &[[[f32; 3]; 3]], header: &[u8]) -> Vec<u8> {
    let mut out = vec![b' '; 80];
    out[..header.len()].copy_from_slice(header);
    out.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for t in tris {
        out.extend_from_slice(&[0u8; 12]);
        for v in t {
            for c in v {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
        out.extend_from_slice(&[0, 0]);
    }
    out
}

#[test]
fn stl_binary_with_solid_header_is_binary() {
    let tris = [[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]; 2];
    let bytes = binary_stl(&tris, b"solid but really binary");
    let (m, info) = read_bytes(&bytes, Path::new("a.stl"), &ReadOptions::default()).unwrap();
    assert_eq!(info.encoding, Encoding::BinaryLittleEndian);
    assert_eq!(m.positions.len(), 3);
    assert_eq!(faces(&m), vec![vec![0, 1, 2]; 2]);
}

#[test]
fn stl_ascii_forms() {
    // Upper case, several solids, a quad loop, tokens split over lines, CRLF.
    let text = "SOLID one\r\nFACET NORMAL 0 0 1\r\nOUTER LOOP\r\nVERTEX 0 0 0\r\nVERTEX 1 0 0\r\n\
                VERTEX 1 1 0\r\nVERTEX 0 1 0\r\nENDLOOP\r\nENDFACET\r\nENDSOLID one\r\n\
                solid\nfacet normal nan nan nan outer loop vertex 0 0 0 vertex\n1 0 0 vertex 0 0 1\n\
                endloop endfacet endsolid\n";
    let m = ok(Format::Stl, text);
    assert_eq!(faces(&m), vec![vec![0, 1, 2, 3], vec![0, 1, 4]]);
    let empty = ok(Format::Stl, "solid empty\nendsolid empty\n");
    assert!(empty.positions.is_empty());
}

#[test]
fn stl_errors() {
    let tri = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    // Binary, truncated inside facet 1.
    let mut bytes = binary_stl(&[tri, tri, tri], b"binary");
    bytes.truncate(84 + 50 + 20);
    let e = err(Format::Stl, &bytes);
    assert_eq!(
        e.location,
        Location::Element {
            kind: "facet".into(),
            index: 1
        }
    );
    assert!(
        matches!(e.kind, ErrorKind::Truncated(ref s) if s.contains("byte 134")),
        "{e}"
    );
    // Binary with a "solid" header, truncated: still read as binary.
    let mut bytes = binary_stl(&[tri, tri], b"solid x");
    bytes.truncate(84 + 50 + 49);
    let e = err(Format::Stl, &bytes);
    assert_eq!(
        e.location,
        Location::Element {
            kind: "facet".into(),
            index: 1
        }
    );
    // Binary with trailing bytes.
    let mut bytes = binary_stl(&[tri], b"binary");
    bytes.extend_from_slice(b"junk");
    let e = err(Format::Stl, &bytes);
    assert_eq!(e.location, Location::Byte(134));
    assert!(matches!(e.kind, ErrorKind::BadCount(_)), "{e}");
    // Binary NaN.
    let bytes = binary_stl(&[tri, [[0.0, f32::NAN, 0.0], tri[1], tri[2]]], b"binary");
    let e = err(Format::Stl, &bytes);
    assert_eq!(
        e.location,
        Location::Element {
            kind: "facet".into(),
            index: 1
        }
    );
    assert!(matches!(e.kind, ErrorKind::NonFinite(_)), "{e}");
    // Too short for a header.
    let e = err(Format::Stl, b"\x00\x01abc");
    assert!(matches!(e.kind, ErrorKind::Truncated(_)), "{e}");
    for empty in [&b""[..], b" \n\t\r\n"] {
        let e = err(Format::Stl, empty);
        assert!(matches!(e.kind, ErrorKind::Empty), "{e}");
    }

    let head = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";
    let cases: Vec<Case<String>> = vec![
        (format!("{head}facet normal 0 0 1\nouter loop\nvertex 0 0"), Location::Element { kind: "facet".into(), index: 1 }, |k| {
            matches!(k, ErrorKind::Truncated(_))
        }),
        (head.to_string(), Location::Line(9), |k| matches!(k, ErrorKind::Truncated(s) if s.contains("endsolid"))),
        (format!("{head}facet normal 0 0 1\nouter loop\nvertex 0 0 inf\n"), Location::Line(11), |k| {
            matches!(k, ErrorKind::NonFinite(_))
        }),
        (format!("{head}facet normal 0 0 1\nouter lop\n"), Location::Line(10), |k| {
            matches!(k, ErrorKind::Syntax(s) if s.contains("`lop`"))
        }),
        (format!("{head}facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid\n"),
            Location::Element { kind: "facet".into(), index: 1 }, |k| matches!(k, ErrorKind::Syntax(s) if s.contains("2 vertices"))),
        (format!("{head}endsolid t\ngarbage\n"), Location::Line(10), |k| matches!(k, ErrorKind::Syntax(_))),
    ];
    for (text, loc, want) in cases {
        let e = err(Format::Stl, &text);
        assert_eq!(e.location, loc, "{text:?}: {e}");
        assert!(want(&e.kind), "{text:?}: {e}");
    }
}

// ----------------------------------------------------------------------------- XYZ forms

#[test]
fn xyz_forms() {
    let m = ok(
        Format::Xyz,
        "# comment\n// another\n0 0 0\n1,2,3 // trailing\n\n4, 5, 6\n",
    );
    assert_eq!(
        m.positions,
        vec![[0.0; 3], [1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]
    );
    assert!(m.normals.is_none() && m.colors.is_none() && m.faces.is_empty());
    let m = ok(Format::Xyz, "2\n0 0 0 0 0 1\n1 1 1 0 1 0\n");
    assert_eq!(m.normals.unwrap(), vec![[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]);
    // PTS: x y z intensity r g b.
    let m = ok(Format::Xyz, "1\n0 0 0 -1200 255 10 300\n");
    assert_eq!(m.colors.unwrap(), vec![[255, 10, 255]]);
    assert!(m.normals.is_none());
    // 4 columns: intensity ignored; 9: normals, then colours (integers in 0..255).
    assert_eq!(ok(Format::Xyz, "0 0 0 7\n").positions.len(), 1);
    let m = ok(Format::Xyz, "0 0 0 1 0 0 9 9 9\n");
    assert_eq!(m.normals.unwrap(), vec![[1.0, 0.0, 0.0]]);
    assert_eq!(m.colors.unwrap(), vec![[9, 9, 9]]);
}

#[test]
fn xyz_errors() {
    let cases: Vec<Case<&str>> = vec![
        (
            "0 0 0\n1 1 1\n2 2 2 0 0 1\n",
            Location::Line(3),
            |k| matches!(k, ErrorKind::Syntax(s) if s.contains("6 columns") && s.contains("line 1")),
        ),
        ("0 0 0\n1 nan 1\n", Location::Line(2), |k| {
            matches!(k, ErrorKind::NonFinite(_))
        }),
        (
            "0 0 0\n1 1 q\n",
            Location::Line(2),
            |k| matches!(k, ErrorKind::Syntax(s) if s.contains("`q`")),
        ),
        ("0 0\n", Location::Line(1), |k| {
            matches!(k, ErrorKind::Syntax(_))
        }),
        ("3\n0 0 0\n1 1 1\n", Location::Line(1), |k| {
            matches!(k, ErrorKind::BadCount(_))
        }),
        ("# nothing\n", Location::File, |k| {
            matches!(k, ErrorKind::Empty)
        }),
    ];
    for (text, loc, want) in cases {
        let e = err(Format::Xyz, text);
        assert_eq!(e.location, loc, "{text:?}: {e}");
        assert!(want(&e.kind), "{text:?}: {e}");
    }
}

// ----------------------------------------------------------------------------- data corpus

/// `(file, vertices, faces)` from `SOURCES.md` for the formats tested here.
fn expected_counts(sources: &str) -> Vec<(String, usize, usize)> {
    sources
        .lines()
        .filter_map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            if cells.len() < 4 {
                return None;
            }
            let name = cells[1];
            let ext = Path::new(name).extension()?.to_str()?;
            if !matches!(ext, "obj" | "off" | "stl" | "xyz") {
                return None;
            }
            Some((
                name.to_string(),
                cells[2].parse().ok()?,
                cells[3].parse().ok()?,
            ))
        })
        .collect()
}

#[test]
fn shared_data_counts() {
    let Some(dir) = std::env::var_os("SUBFIT_DATA").map(PathBuf::from) else {
        if std::env::var("CI").as_deref() == Ok("true") {
            panic!("SUBFIT_DATA is not set, and CI=true requires the data test to run");
        }
        #[allow(clippy::print_stderr)]
        {
            eprintln!("note: SUBFIT_DATA is not set; skipping the shared data test");
        }
        return;
    };
    let sources = std::fs::read_to_string(dir.join("SOURCES.md")).expect("SOURCES.md");
    let expected = expected_counts(&sources);
    assert!(expected.len() >= 9, "{expected:?}");
    for (name, nv, nf) in expected {
        let path = dir.join(&name);
        let (m, info) =
            subfit_io::read_file(&path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.positions.len(), nv, "{name}");
        assert_eq!(m.faces.len(), nf, "{name}");
        assert_eq!(info.encoding, Encoding::Ascii);
        // Everything accepted is consistent, and survives a write/read round trip exactly.
        assert!(
            m.faces.indices().iter().all(|&i| (i as usize) < nv),
            "{name}"
        );
        let fmt = info.format;
        let back = read_as(fmt, &write(&m, fmt, Encoding::Ascii)).unwrap();
        same_bits(&back.positions, &m.positions, &name);
        assert_eq!(back.faces, m.faces, "{name}");
    }
}
