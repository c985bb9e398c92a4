//! Inputs that attack the PLY reader's counts and bounds, kept as regression tests.
//!
//! The `read_ply` fuzz target ran 22.8 million inputs (5 minutes, seeded with small valid
//! ascii/binary files) without a crash; these are the hand-reduced shapes of what it explores
//! that a careless reader gets wrong: counts that lie about the data (huge allocations),
//! elements without properties (endless loops), list counts near the type limits, and headers
//! cut short. Each must give an error of the stated kind, quickly and without panicking.

use std::path::Path;

use subfit_io::{ply, read_bytes, ErrorKind, Format, ReadOptions};

/// `(input, expected error kind as a predicate)`.
type Case = (&'static [u8], fn(&ErrorKind) -> bool);

fn truncated(k: &ErrorKind) -> bool {
    matches!(k, ErrorKind::Truncated(_))
}
fn bad_count(k: &ErrorKind) -> bool {
    matches!(k, ErrorKind::BadCount(_))
}
fn bad_header(k: &ErrorKind) -> bool {
    matches!(k, ErrorKind::BadHeader(_))
}
fn non_finite(k: &ErrorKind) -> bool {
    matches!(k, ErrorKind::NonFinite(_))
}
fn out_of_range(k: &ErrorKind) -> bool {
    matches!(k, ErrorKind::IndexOutOfRange { .. })
}

const CASES: &[Case] = &[
    // Header cut short, or nothing after the magic.
    (b"ply", truncated),
    (b"ply\n", truncated),
    (b"ply\nformat ascii 1.0\nend_heade", truncated),
    (b"\xffply\n", bad_header),
    (b"ply\n\xff\n", bad_header),
    // Counts at and past u64.
    (
        b"ply\nformat binary_little_endian 1.0\nelement vertex 18446744073709551615\n\
          property float x\nproperty float y\nproperty float z\nend_header\n",
        bad_count,
    ),
    (
        b"ply\nformat ascii 1.0\nelement vertex 99999999999999999999999\nend_header\n",
        bad_count,
    ),
    (
        b"ply\nformat ascii 1.0\nelement vertex -0x1\nend_header\n",
        bad_header,
    ),
    // A huge element without properties is skipped without looping over its count.
    (
        b"ply\nformat binary_big_endian 1.0\nelement nothing 18446744073709551615\n\
          element vertex 1\nproperty double x\nproperty double y\nproperty double z\n\
          end_header\n\x7f\xf0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0",
        non_finite,
    ),
    (
        b"ply\nformat ascii 1.0\nelement nothing 18446744073709551615\nelement vertex 1\n\
          property float x\nproperty float y\nproperty float z\nend_header\n1e400 0 0\n",
        non_finite,
    ),
    // List counts larger than the data, in ascii and binary, for used and skipped lists.
    (
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
          property float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n\
          0 0 0\n4294967295 0 0 0\n",
        bad_count,
    ),
    (
        b"ply\nformat binary_little_endian 1.0\nelement junk 1\nproperty list uint double j\n\
          element vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n\
          \xff\xff\xff\xff\0\0\0\0",
        truncated,
    ),
    (
        b"ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n\
          property float y\nproperty float z\nelement tristrips 1\n\
          property list int uchar vertex_indices\nend_header\n\xff\xff\xff\x7f\x00",
        truncated,
    ),
    // A one-byte-per-record face count far beyond the file.
    (
        b"ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n\
          property float y\nproperty float z\nelement face 4294967295\n\
          property list uchar uchar vertex_indices\nend_header\n\x00\x00",
        bad_count,
    ),
    // Indices at the type limits.
    (
        b"ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n\
          property float y\nproperty float z\nelement face 1\n\
          property list uchar uint vertex_indices\nend_header\n\
          \0\0\0\0\0\0\0\0\0\0\0\0\x03\0\0\0\0\0\0\0\0\xff\xff\xff\xff",
        out_of_range,
    ),
    (
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
          property float z\nelement tristrips 1\nproperty list int int vertex_indices\n\
          end_header\n0 0 0\n3 0 0 -9223372036854775808\n",
        out_of_range,
    ),
];

#[test]
fn adversarial_inputs_give_errors_not_panics() {
    for (i, &(bytes, expected)) in CASES.iter().enumerate() {
        match ply::read(bytes, Path::new("fuzz.ply"), &mut Vec::new()) {
            Ok(_) => panic!("case {i} accepted"),
            Err(e) => assert!(expected(&e.kind), "case {i}: {e}"),
        }
    }
}

#[test]
fn every_prefix_of_a_valid_binary_file_is_handled() {
    let mut bytes = b"ply\r\nformat binary_little_endian 1.0\r\nelement vertex 3\r\n\
        property float x\r\nproperty float y\r\nproperty float z\r\nelement face 1\r\n\
        property list uchar int vertex_indices\r\nend_header\r\n"
        .to_vec();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes.push(3);
    for i in [0i32, 1, 2] {
        bytes.extend_from_slice(&i.to_le_bytes());
    }
    let opts = ReadOptions {
        format: Some(Format::Ply),
        ..ReadOptions::default()
    };
    for n in 0..bytes.len() {
        assert!(
            read_bytes(&bytes[..n], Path::new("p.ply"), &opts).is_err(),
            "prefix {n}"
        );
    }
    let (mesh, _) = read_bytes(&bytes, Path::new("p.ply"), &opts).unwrap();
    assert_eq!(mesh.faces.len(), 1);
}
