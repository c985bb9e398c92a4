//! Round trips between every pair of formats that can carry the data: read A → write B →
//! read B must give the same positions (bit for bit), faces and normals.

use std::path::Path;

use subfit_io::{read_bytes, write_bytes, Encoding, Format, ReadOptions, WriteOptions};
use subfit_mesh::{PolyMesh, Polygons};

fn options(format: Format, encoding: Encoding) -> WriteOptions {
    WriteOptions {
        format: Some(format),
        encoding,
        single_precision: false,
    }
}

/// Every (format, encoding) that can be written.
fn writers() -> Vec<(Format, Encoding)> {
    vec![
        (Format::Ply, Encoding::Ascii),
        (Format::Ply, Encoding::BinaryLittleEndian),
        (Format::Ply, Encoding::BinaryBigEndian),
        (Format::Obj, Encoding::Ascii),
        (Format::Off, Encoding::Ascii),
        (Format::Stl, Encoding::Ascii),
        (Format::Stl, Encoding::BinaryLittleEndian),
        (Format::Xyz, Encoding::Ascii),
    ]
}

fn round_trip(mesh: &PolyMesh, f: Format, e: Encoding) -> PolyMesh {
    let bytes = write_bytes(mesh, f, &options(f, e)).unwrap();
    let name = format!("x.{}", f.name());
    read_bytes(&bytes, Path::new(&name), &ReadOptions::default())
        .unwrap_or_else(|err| panic!("{f:?} {e:?}: {err}"))
        .0
}

/// A polygon mesh with normals and awkward coordinates (not representable in f32).
fn polygon_mesh() -> PolyMesh {
    let positions = vec![
        [0.1, -1.0 / 3.0, 2.5e-7],
        [1.0 + 1e-12, 0.2, -0.0],
        [1.3, 1.7, 1e6 / 7.0],
        [0.0, 1.0, std::f64::consts::PI],
        [-0.5, 0.5, 0.25],
    ];
    let normals = positions
        .iter()
        .map(|p: &[f64; 3]| {
            let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            [p[0] / l, p[1] / l, p[2] / l]
        })
        .collect();
    let mut faces = Polygons::new();
    faces.push(&[0, 1, 2, 3]);
    faces.push(&[0, 3, 4]);
    PolyMesh {
        positions,
        normals: Some(normals),
        colors: None,
        faces,
    }
}

#[test]
fn polygon_meshes_round_trip_through_every_format_that_holds_polygons() {
    let mesh = polygon_mesh();
    for (f, e) in writers() {
        if f.losses(&mesh).is_empty() {
            let back = round_trip(&mesh, f, e);
            assert_eq!(back, mesh, "{f:?} {e:?}");
        }
    }
    // Chains: PLY → OBJ → OFF → PLY(BE) keeps everything.
    let mut m = mesh.clone();
    for (f, e) in [
        (Format::Ply, Encoding::BinaryLittleEndian),
        (Format::Obj, Encoding::Ascii),
        (Format::Off, Encoding::Ascii),
        (Format::Ply, Encoding::BinaryBigEndian),
    ] {
        m = round_trip(&m, f, e);
    }
    assert_eq!(m, mesh);
}

#[test]
fn point_clouds_with_normals_round_trip_through_ply_off_and_xyz() {
    let mut cloud = polygon_mesh();
    cloud.faces = Polygons::new();
    for (f, e) in writers() {
        if f == Format::Stl {
            continue;
        }
        let back = round_trip(&cloud, f, e);
        assert_eq!(back.positions, cloud.positions, "{f:?} {e:?}");
        assert_eq!(back.normals, cloud.normals, "{f:?} {e:?}");
        assert!(back.faces.is_empty());
    }
}

#[test]
fn stl_keeps_f32_triangles_and_welds_them_back_to_shared_vertices() {
    // f32-exact coordinates, a closed tetrahedron.
    let positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 0.5],
    ];
    let faces = Polygons::from_triangles(&[[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]);
    let mesh = PolyMesh::new(positions, faces);
    for e in [Encoding::Ascii, Encoding::BinaryLittleEndian] {
        let back = round_trip(&mesh, Format::Stl, e);
        assert_eq!(back.positions.len(), 4, "{e:?}");
        assert_eq!(back.faces.len(), 4);
        // Same triangles up to vertex renumbering.
        let key = |m: &PolyMesh| {
            let mut tris: Vec<Vec<[u64; 3]>> = m
                .faces
                .iter()
                .map(|f| {
                    let mut t: Vec<[u64; 3]> = f
                        .iter()
                        .map(|&v| m.positions[v as usize].map(f64::to_bits))
                        .collect();
                    // Rotate so the smallest corner comes first, keeping the winding.
                    let i = (0..3).min_by_key(|&i| t[i]).unwrap();
                    t.rotate_left(i);
                    t
                })
                .collect();
            tris.sort();
            tris
        };
        assert_eq!(key(&back), key(&mesh), "{e:?}");
        // And back to OBJ, losslessly from here on.
        let again = round_trip(&back, Format::Obj, Encoding::Ascii);
        assert_eq!(again, back);
    }
}
