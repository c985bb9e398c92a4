//! Hand-written binary files in the variants real files come in: binary OFF in both byte
//! orders, with and without per-face colour counts; PLY big-endian with `uchar`, `int` and
//! `uint` list types and extra vertex and face properties; PLY header lines no reader knows;
//! NaN colours (read as 0) next to NaN positions (an error naming the vertex).

use std::path::Path;

use subfit_io::{read_bytes, Encoding, Error, ErrorKind, FileInfo, Location, ReadOptions};
use subfit_mesh::PolyMesh;

fn read(name: &str, bytes: &[u8]) -> Result<(PolyMesh, FileInfo), Error> {
    read_bytes(bytes, Path::new(name), &ReadOptions::default())
}

fn faces(m: &PolyMesh) -> Vec<Vec<u32>> {
    m.faces.iter().map(|f| f.to_vec()).collect()
}

/// A tetrahedron (a quad-free shape whose every face size is 3) plus one quad on a fifth point,
/// with coordinates exact in f32.
const POINTS: [[f32; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [1.5, 0.0, 0.0],
    [0.0, -2.25, 0.0],
    [0.0, 0.0, 0.125],
    [3.0, 3.0, 3.0],
];
const FACES: [&[u32]; 5] = [
    &[0, 2, 1],
    &[0, 1, 3],
    &[0, 3, 2],
    &[1, 2, 3],
    &[1, 4, 3, 2],
];

/// Binary OFF bytes: `header` line, then counts, vertices (plus `extra` floats per vertex) and
/// faces, in the given byte order, with or without a colour count (and `nc` components).
fn binary_off(header: &str, big: bool, colour_counts: bool, extra: &[f32]) -> Vec<u8> {
    let mut out = header.as_bytes().to_vec();
    let int = |out: &mut Vec<u8>, v: i32| {
        out.extend(if big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        })
    };
    let float = |out: &mut Vec<u8>, v: f32| {
        out.extend(if big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        })
    };
    for c in [5, 5, 9] {
        int(&mut out, c);
    }
    for p in POINTS {
        p.iter().chain(extra).for_each(|&v| float(&mut out, v));
    }
    for (i, f) in FACES.iter().enumerate() {
        int(&mut out, f.len() as i32);
        f.iter().for_each(|&v| int(&mut out, v as i32));
        if colour_counts {
            // Faces carry 0, 3 or 4 colour components, as files mix them.
            let nc = [0, 3, 4, 0, 3][i];
            int(&mut out, nc);
            (0..nc).for_each(|_| float(&mut out, 0.5));
        }
    }
    out
}

fn expect_shape(m: &PolyMesh) {
    let want: Vec<[f64; 3]> = POINTS.iter().map(|p| p.map(f64::from)).collect();
    assert_eq!(m.positions, want);
    assert_eq!(
        faces(m),
        FACES.iter().map(|f| f.to_vec()).collect::<Vec<_>>()
    );
}

#[test]
fn binary_off_in_every_byte_order_and_face_layout() {
    for big in [true, false] {
        for counts in [true, false] {
            let bytes = binary_off("OFF BINARY\n", big, counts, &[]);
            let (m, info) = read("t.off", &bytes).unwrap_or_else(|e| panic!("{e}"));
            expect_shape(&m);
            let enc = if big {
                Encoding::BinaryBigEndian
            } else {
                Encoding::BinaryLittleEndian
            };
            assert_eq!(info.encoding, enc);
            // The spec's layout reads silently; any other is said.
            let spec = big && counts;
            assert_eq!(info.warnings.is_empty(), spec, "{:?}", info.warnings);
            if !spec {
                assert!(info.warnings[0].contains(if big {
                    "big-endian"
                } else {
                    "little-endian"
                }));
            }
        }
    }
    // NOFF and COFF: per-vertex normals and RGBA colours (a NaN channel reads as 0).
    let bytes = binary_off(
        "# a comment line\nCNOFF BINARY\r\n",
        true,
        true,
        &[0.0, 0.0, 1.0, 1.0, f32::NAN, 0.5, 1.0],
    );
    let (m, _) = read("t.off", &bytes).unwrap_or_else(|e| panic!("{e}"));
    expect_shape(&m);
    assert_eq!(m.normals.unwrap(), vec![[0.0, 0.0, 1.0]; 5]);
    assert_eq!(m.colors.unwrap(), vec![[255, 0, 128]; 5]);
}

#[test]
fn broken_binary_off_is_refused_with_its_byte() {
    let good = binary_off("OFF BINARY\n", true, true, &[]);
    // Cut inside the last face: no layout reads it; the error names a byte inside the data.
    let e = read("t.off", &good[..good.len() - 2]).unwrap_err();
    assert!(
        matches!(e.location, Location::Byte(b) if b > 11 && b < good.len() as u64),
        "{e}"
    );
    assert!(e.to_string().contains("binary OFF"), "{e}");
    // An index out of range in every layout.
    let mut bad = good.clone();
    let at = 11 + 12 + 5 * 12 + 4;
    bad[at..at + 4].copy_from_slice(&7i32.to_be_bytes());
    let e = read("t.off", &bad).unwrap_err();
    assert!(
        matches!(e.kind, ErrorKind::IndexOutOfRange { index: 7, count: 5 }),
        "{e}"
    );
    // Trailing garbage.
    let mut long = good.clone();
    long.extend_from_slice(b"xyz");
    let e = read("t.off", &long).unwrap_err();
    assert!(e.to_string().contains("after the last face"), "{e}");
    // A NaN position.
    let mut nan = good;
    nan[11 + 12 + 4..11 + 12 + 8].copy_from_slice(&f32::NAN.to_be_bytes());
    let e = read("t.off", &nan).unwrap_err();
    assert!(
        matches!(e.kind, ErrorKind::NonFinite(ref s) if s.contains("vertex 0")),
        "{e}"
    );
}

/// A big-endian PLY with `double` coordinates, an extra `float confidence` and `uchar` RGB
/// per vertex, and faces with a list of the given count/index types, a face colour and a
/// `list uchar float texcoord`.
fn big_endian_ply(count_ty: &str, index_ty: &str, colour: [f32; 2]) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat binary_big_endian 1.0\ncomment made by hand\nelement vertex 5\n\
         property float confidence\nproperty double x\nproperty double y\nproperty double z\n\
         property float red\nproperty float green\nproperty uchar blue\nproperty short flags\n\
         element face 5\nproperty uchar red\nproperty list {count_ty} {index_ty} vertex_indices\n\
         property list uchar float texcoord\nelement edge 0\nproperty int vertex1\nend_header\n"
    )
    .into_bytes();
    let put = |out: &mut Vec<u8>, ty: &str, v: f64| match ty {
        "uchar" => out.push(v as u8),
        "int" => out.extend((v as i32).to_be_bytes()),
        "uint" => out.extend((v as u32).to_be_bytes()),
        "ushort" => out.extend((v as u16).to_be_bytes()),
        _ => unreachable!("{ty}"),
    };
    for p in POINTS {
        out.extend(0.5f32.to_be_bytes());
        p.iter()
            .for_each(|&c| out.extend(f64::from(c).to_be_bytes()));
        out.extend(colour[0].to_be_bytes());
        out.extend(colour[1].to_be_bytes());
        out.push(200);
        out.extend(7i16.to_be_bytes());
    }
    for f in FACES {
        out.push(9);
        put(&mut out, count_ty, f.len() as f64);
        f.iter().for_each(|&v| put(&mut out, index_ty, v as f64));
        out.push(2);
        out.extend(0.25f32.to_be_bytes());
        out.extend(0.75f32.to_be_bytes());
    }
    out
}

#[test]
fn big_endian_ply_with_list_types_and_extra_properties() {
    for (count_ty, index_ty) in [
        ("uchar", "int"),
        ("uchar", "uint"),
        ("int", "int"),
        ("uint", "uint"),
        ("ushort", "uint"),
    ] {
        let bytes = big_endian_ply(count_ty, index_ty, [1.0, 0.5]);
        let (m, info) =
            read("t.ply", &bytes).unwrap_or_else(|e| panic!("{count_ty} {index_ty}: {e}"));
        expect_shape(&m);
        assert_eq!(info.encoding, Encoding::BinaryBigEndian);
        assert_eq!(m.colors.unwrap(), vec![[255, 128, 200]; 5]);
        assert!(m.normals.is_none());
        assert!(info.warnings.is_empty(), "{:?}", info.warnings);
    }
}

#[test]
fn ply_nan_colours_read_as_zero_nan_positions_are_refused() {
    let bytes = big_endian_ply("uchar", "int", [f32::NAN, 0.5]);
    let (m, info) = read("t.ply", &bytes).unwrap();
    assert_eq!(m.colors.unwrap(), vec![[0, 128, 200]; 5]);
    assert!(
        info.warnings
            .iter()
            .any(|w| w.contains("5 vertices have a NaN colour")),
        "{:?}",
        info.warnings
    );
    // The same in ascii, and a NaN position there.
    let head = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
                property float z\nproperty uchar red\nproperty uchar green\nproperty float blue\n\
                end_header\n";
    let (m, _) = read(
        "t.ply",
        format!("{head}0 0 0 1 2 nan\n1 1 1 1 2 0.5\n").as_bytes(),
    )
    .unwrap();
    assert_eq!(m.colors.unwrap(), vec![[1, 2, 0], [1, 2, 128]]);
    let e = read(
        "t.ply",
        format!("{head}0 0 0 1 2 0\n1 nan 1 1 2 0.5\n").as_bytes(),
    )
    .unwrap_err();
    assert!(
        matches!(e.kind, ErrorKind::NonFinite(ref s) if s.contains("vertex 1")),
        "{e}"
    );
    // Binary: the error names the element.
    let mut bytes = big_endian_ply("uchar", "int", [1.0, 0.5]);
    let start = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let rec = 4 + 24 + 4 + 4 + 1 + 2;
    let at = start + 2 * rec + 4 + 8;
    bytes[at..at + 8].copy_from_slice(&f64::NAN.to_be_bytes());
    let e = read("t.ply", &bytes).unwrap_err();
    assert_eq!(
        e.location,
        Location::Element {
            kind: "vertex".into(),
            index: 2
        }
    );
    assert!(matches!(e.kind, ErrorKind::NonFinite(_)), "{e}");
}

#[test]
fn ply_header_lines_no_reader_knows_are_skipped_and_named() {
    let text =
        "ply\nformat ascii 1.0\nobj_info is_cyberware_data 1\nobj_info num_cols 3\nbye\nbye\n\
                element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                element range_grid 2\nproperty list uchar int vertex_indices\nend_header\n\
                0 0 0\n1 0 0\n0 1 0\n1 0\n0\n";
    let (m, info) = read("t.ply", text.as_bytes()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.positions.len(), 3);
    assert!(m.faces.is_empty());
    assert_eq!(
        info.warnings,
        vec!["2 header line(s) with an unknown keyword skipped: line 5 `bye`, line 6 `bye`"]
    );
    // Comments may hold any bytes.
    let text =
        b"ply\nformat ascii 1.0\ncomment cr\xe9\xe9 par\nelement vertex 1\nproperty float x\n\
                 property float y\nproperty float z\nend_header\n0 0 0\n";
    assert_eq!(read("t.ply", text).unwrap().0.positions.len(), 1);
}
