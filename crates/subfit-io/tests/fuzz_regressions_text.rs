//! Reduced inputs from fuzzing the OBJ, OFF, STL and XYZ readers (`crates/subfit-io/fuzz`),
//! plus hostile inputs of the same kind written by hand: each must give `Ok` or `Err`, never a
//! panic, a hang or a huge allocation, and whatever is accepted must be consistent (indices in
//! range, finite positions, attribute arrays as long as the positions).

use std::path::Path;

use subfit_io::{read_bytes, ErrorKind, Format, ReadOptions};

/// Reads `data` as `format` with the fuzz targets' checks; returns the error kind, if any.
fn check(format: Format, data: &[u8]) -> Option<ErrorKind> {
    for weld in [true, false] {
        let opts = ReadOptions {
            format: Some(format),
            weld_stl: weld,
        };
        match read_bytes(data, Path::new("fuzz"), &opts) {
            Ok((m, _)) => {
                let n = m.positions.len();
                assert!(m.faces.indices().iter().all(|&i| (i as usize) < n));
                assert!(m.positions.iter().flatten().all(|c| c.is_finite()));
                assert!(m.normals.as_ref().is_none_or(|v| v.len() == n));
                assert!(m.colors.as_ref().is_none_or(|v| v.len() == n));
            }
            Err(e) => {
                // Messages must render.
                let _ = e.to_string();
                if format != Format::Stl || !weld {
                    return Some(e.kind);
                }
            }
        }
    }
    None
}

#[test]
fn obj_hostile() {
    let cases: &[&[u8]] = &[
        b"f -9223372036854775808 1 2\nv 0 0 0\n",
        b"v 0 0 0\nf 9223372036854775807 1 1\n",
        b"v 0 0 0\nf 4294967296 1 1\n",
        b"v 0 0 0\nf 4294967295 1 1\n",
        b"v 0 0 0\nf 1//-9223372036854775808 1 1\n",
        b"v 0 0 0\nvn 0 0 1\nf 1//1 1//1 1//1\n",
        b"v 0 0 0\nf 1/ 1 1\n",
        b"v 0 0 0\nf / / /\n",
        b"v 0 0 0\nf 1// 1 1\n",
        b"\\\n\\\n\\",
        b"v 0 0 \\",
        b"v 1e400 0 0\n",
        b"v 0 0 0 1e400\n",
        b"vt\n",
        b"\xef\xbb\xbfv 0 0 0\n",
        b"v 0 0 0\r\rf 1 1 1\r",
        b"#\xff\n",
        b"v 0 0 0\nvn 0 0 0\nvn 0 0 0\nf 1//1 1//2 1//1\n",
        b"v 0 0 0\nvn nan 0 0\n",
        b"g \xff\xfe\nv 0 0 0\n",
        b"P 1",
        b"P 0 0 0 0 0 4294967295",
        b"P 0 0 0 0 0 1 0 0 0 0 0 1 99999999999 0 0 0 0 0",
        b"P 0 0 0 0 0 1 0 0 0 0 0 1 1 2 0 0 0 0 3 0 0 0",
        b"P 0 0 0 0 0 1 0 0 0 0 0 1 1 0 0 0 0 0 -3 0 0 0",
        b"L 1 2",
        b"X 0",
    ];
    for c in cases {
        check(Format::Obj, c);
    }
}

#[test]
fn off_hostile() {
    let cases: &[&[u8]] = &[
        b"OFF\n4294967295 4294967295 0\n",
        b"OFF 4294967296 0 0\n",
        b"OFF\n1 1 0\n0 0 0\n9223372036854775807 0 0 0\n",
        b"OFF\n1 1 0\n0 0 0\n-1 0 0 0\n",
        b"OFF\n1 1 0\n0 0 0\n3 0 0 0 a\n",
        b"OFF",
        b"OFF 1",
        b"C",
        b"CCOFF\n",
        b"STCNOFF\n1 0\n0 0 0 0 0 1 1 1 1 0 0\n",
        b"COFF\n1 0\n0 0 0 1e999 0 0\n",
        b"OFF\n1 0\n0 0 0 # \xff\n",
        b"OFF8",
        b"\tOFF4294967295 1\n",
        b"OFF3 1\n0 0 0\n1 0 0\n0 1 0\n3\n",
        b"OFF BINARY",
        b"OFF BINARY\n",
        b"OFF BINARY\n\x7f\xff\xff\xff\x7f\xff\xff\xff\0\0\0\0",
        b"OFF BINARY\n\0\0\0\x01\0\0\0\x01\0\0\0\0\x7f\xc0\0\0\0\0\0\0\0\0\0\0",
        b"STCNOFF BINARY\n\0\0\0\x01\0\0\0\0\0\0\0\0",
        b"4OFF BINARY\n",
        b"OFF BINARY extra\n",
    ];
    for c in cases {
        check(Format::Off, c);
    }
}

#[test]
fn stl_hostile() {
    let mut lying = vec![0u8; 84];
    lying[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    let mut one = vec![b' '; 80];
    one.extend_from_slice(&1u32.to_le_bytes());
    one.extend_from_slice(&[0u8; 50]);
    let mut solid_one = one.clone();
    solid_one[..5].copy_from_slice(b"solid");
    let cases: Vec<&[u8]> = vec![
        &lying,
        &one,
        &solid_one,
        b"solid",
        b"solid\n",
        b"solid\nfacet",
        b"solid\nfacet normal 0 0 0 outer loop endloop endfacet endsolid",
        b"solid\nfacet normal 0 0 0 outer loop vertex 0 0 0 vertex 0 0 0 vertex 0 0 0 endloop endfacet",
        b"solid\r",
        b"solid \xff",
        b"   solid\nendsolid\nsolid\nendsolid",
    ];
    for c in cases {
        check(Format::Stl, c);
    }
    // A binary file announcing 2^32 - 1 facets is rejected without allocating for them.
    assert!(matches!(
        check(Format::Stl, &lying),
        Some(ErrorKind::Truncated(_))
    ));
}

#[test]
fn xyz_hostile() {
    let cases: &[&[u8]] = &[
        b"18446744073709551615\n",
        b"-1\n0 0 0\n",
        b"0\n",
        b"1\n1\n",
        b",,,\n",
        b"0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n",
        b"0 0 0 0 nan 0 0\n",
        b"0 0 0 nan\n",
        b"/\n/",
        b"0 0 0\n\xff",
        b"p",
        b"p 0 0\n",
        b"d 1 1 1\n",
        b"p 0 0 0\n\xff 1 1\n",
        b"1\n0 0 0\n0\n",
        b"1\n0 0 0\n1\n",
        b"0 0 0 nan nan nan\n",
        b"0 0 0 nan nan nan nan\n",
        b"0 0 0 1 0 0 nan nan nan nan\n",
        b"0 0 0\n-",
        b"0\n",
    ];
    for c in cases {
        check(Format::Xyz, c);
    }
}
