//! The repairs of a face list that is not a surface, on generated meshes whose true surface is
//! known: a sphere with a sheet glued along an arc of its equator, faces written again turned,
//! double-sided exports, and a lens whose thin middle is a sheet of no thickness written as two
//! coincident sides (what a volumetric reconstruction leaves at a thin part). Each repair must
//! give back that surface: closed or open as it is, orientable, with the faces it had.

use subfit_mesh::thin_shapes::two_sided_lens;
use subfit_mesh::{
    clean_faces, cut_nonmanifold_edges, diagnose_mesh, drop_twin_sides, reorient_faces,
    split_bowties, PolyMesh, Polygons,
};

/// A latitude-longitude unit sphere: `n` vertices around, `rings` rings (odd: one is the
/// equator), poles 0 (+z) and 1 (−z); faces outward. Vertex `(r, k)` is `2 + r·n + k mod n`.
fn sphere(n: u32, rings: u32) -> PolyMesh {
    let v = |r: u32, k: u32| 2 + r * n + (k % n);
    let mut p = vec![[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    for r in 0..rings {
        let phi = std::f64::consts::PI * f64::from(r + 1) / f64::from(rings + 1);
        for k in 0..n {
            let t = std::f64::consts::TAU * f64::from(k) / f64::from(n);
            p.push([phi.sin() * t.cos(), phi.sin() * t.sin(), phi.cos()]);
        }
    }
    // North cap, bands from north to south, south cap.
    let mut f = Polygons::new();
    for k in 0..n {
        f.push(&[0, v(0, k), v(0, k + 1)]);
    }
    for r in 0..rings - 1 {
        for k in 0..n {
            f.push(&[v(r, k), v(r + 1, k), v(r + 1, k + 1)]);
            f.push(&[v(r, k), v(r + 1, k + 1), v(r, k + 1)]);
        }
    }
    for k in 0..n {
        f.push(&[1, v(rings - 1, k + 1), v(rings - 1, k)]);
    }
    PolyMesh::new(p, f)
}

/// Signed volume of a closed triangle mesh (positive: faces outward).
fn volume(m: &PolyMesh) -> f64 {
    m.faces
        .iter()
        .map(|f| {
            let [a, b, c] = [0, 1, 2].map(|i| m.positions[f[i] as usize]);
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}

/// The repairs in the order `subfit::repair_mesh` runs them, then the re-orientation.
fn repair(m: &mut PolyMesh) -> subfit_mesh::EdgeCutReport {
    clean_faces(m);
    let cut = cut_nonmanifold_edges(m);
    drop_twin_sides(m);
    split_bowties(m);
    let (faces, _) = reorient_faces(&m.faces, m.num_vertices(), Some(&m.positions))
        .expect("orientable after the repairs");
    m.faces = faces;
    cut
}

/// The faces as sets of positions (bit patterns), sorted: what a surface covers, whatever its
/// vertex ids.
fn covered(m: &PolyMesh) -> Vec<Vec<[u64; 3]>> {
    let mut out: Vec<Vec<[u64; 3]>> = m
        .faces
        .iter()
        .map(|f| {
            let mut k: Vec<[u64; 3]> = f
                .iter()
                .map(|&v| m.positions[v as usize].map(f64::to_bits))
                .collect();
            k.sort_unstable();
            k
        })
        .collect();
    out.sort_unstable();
    out
}

#[test]
fn a_sheet_glued_to_a_sphere_comes_off_and_both_stay() {
    let (n, rings) = (24, 11);
    let mut m = sphere(n, rings);
    let ball = m.clone();
    // A sheet in the equator's plane, standing out of the sphere along 6 of its edges.
    let equator = |k: u32| 2 + (rings / 2) * n + k;
    let (arc, rows) = (6u32, 4u32);
    let id = |k: u32, s: u32, p: &mut Vec<[f64; 3]>| {
        if s == 0 {
            return equator(k);
        }
        let q = p[equator(k) as usize];
        let r = 1.0 + 0.1 * f64::from(s);
        p.push([q[0] * r, q[1] * r, 0.0]);
        (p.len() - 1) as u32
    };
    let mut grid = Vec::new();
    for k in 0..=arc {
        let col: Vec<u32> = (0..=rows).map(|s| id(k, s, &mut m.positions)).collect();
        grid.push(col);
    }
    for k in 0..arc as usize {
        for s in 0..rows as usize {
            let q = [
                grid[k][s],
                grid[k + 1][s],
                grid[k + 1][s + 1],
                grid[k][s + 1],
            ];
            m.faces.push(&[q[0], q[1], q[2]]);
            m.faces.push(&[q[0], q[2], q[3]]);
        }
    }
    assert_eq!(diagnose_mesh(&m).non_manifold_edges, arc as usize);
    let cut = repair(&mut m);
    assert_eq!(
        (cut.edges_cut, cut.edges_split),
        (arc as usize, 0),
        "{cut:?}"
    );
    assert_eq!(cut.vertices_added, arc as usize + 1, "{cut:?}");
    let d = diagnose_mesh(&m);
    assert!(d.is_manifold && d.is_consistently_oriented, "{d:?}");
    // The sphere, closed, with all its faces; the sheet, open, with all of its own.
    assert_eq!(d.num_components, 2, "{d:?}");
    let mut parts: Vec<_> = d
        .components
        .iter()
        .map(|c| (c.faces, c.boundary_loops, c.genus))
        .collect();
    parts.sort_unstable();
    let sheet = (2 * arc * rows) as usize;
    assert_eq!(
        parts,
        vec![(sheet, 1, Some(0)), (ball.num_faces(), 0, Some(0))]
    );
    assert_eq!(m.num_faces(), ball.num_faces() + sheet);
}

#[test]
fn a_sheet_of_no_thickness_keeps_both_sides_and_the_lens_stays_closed() {
    // The copies of the middle cells written in a checkerboard order: keeping the first copy
    // of each (what the repair did before) mixed top and bottom faces in the middle, and the
    // cut then left a surface that could not be oriented.
    let mut m = two_sided_lens(|i, j| (i + j) % 2 == 0);
    let nf = m.num_faces();
    let before = diagnose_mesh(&m);
    // 16 middle cells of 2 triangles; their edges: 16 around, 12 + 12 across, 16 diagonals.
    // Two more triangles, at corners of the rim, have all their corners on it, so both sheets
    // share them too (one more edge each: the cell's diagonal).
    assert_eq!(before.duplicate_faces, 32 + 2, "{before:?}");
    assert_eq!(before.non_manifold_edges, 56 + 2, "{before:?}");
    let clean = clean_faces(&mut m.clone());
    assert_eq!(
        (clean.duplicates_dropped, clean.opposite_duplicates_kept),
        (0, 32 + 2)
    );
    let cut = repair(&mut m);
    assert_eq!(
        (cut.edges_cut, cut.flap_faces_dropped),
        (56 + 2, 0),
        "{cut:?}"
    );
    let d = diagnose_mesh(&m);
    assert!(
        d.is_manifold && d.is_consistently_oriented && d.is_closed,
        "{d:?}"
    );
    assert_eq!((d.num_components, d.genus), (1, Some(0)), "{d:?}");
    // At the two corner triangles the surface passes the diagonal twice around both its ends
    // (top and bottom are one fan at a rim vertex): one of its pairs is split at its middle.
    assert_eq!(cut.edges_split, 2, "{cut:?}");
    assert_eq!(m.num_faces(), nf + 2 * 2, "every face kept");
    assert!(volume(&m) > 0.0, "outward");
}

#[test]
fn a_patch_written_again_turned_is_dropped() {
    let ball = sphere(24, 11);
    let mut m = ball.clone();
    // 40 faces of the sphere (8 %) written a second time, turned.
    let patch: Vec<Vec<u32>> = ball
        .faces
        .iter()
        .skip(100)
        .take(40)
        .map(|f| f.iter().rev().copied().collect())
        .collect();
    for f in &patch {
        m.faces.push(f);
    }
    assert!(diagnose_mesh(&m).non_manifold_edges > 0);
    repair(&mut m);
    let d = diagnose_mesh(&m);
    assert!(
        d.is_manifold && d.is_consistently_oriented && d.is_closed,
        "{d:?}"
    );
    assert_eq!(d.num_components, 1, "{d:?}");
    assert_eq!(covered(&m), covered(&ball));
    assert!(volume(&m) > 0.0);
}

#[test]
fn a_double_sided_export_keeps_one_side() {
    // A closed sphere written twice, the second time inside out, before the first.
    let ball = sphere(16, 7);
    let mut m = ball.clone();
    let mut faces = Polygons::new();
    for f in ball.faces.iter() {
        faces.push(&f.iter().rev().copied().collect::<Vec<_>>());
    }
    for f in ball.faces.iter() {
        faces.push(f);
    }
    m.faces = faces;
    let t = {
        clean_faces(&mut m);
        cut_nonmanifold_edges(&mut m);
        drop_twin_sides(&mut m)
    };
    assert_eq!((t.copies_dropped, t.faces_dropped), (1, ball.num_faces()));
    let d = diagnose_mesh(&m);
    assert!(
        d.is_manifold && d.is_consistently_oriented && d.is_closed,
        "{d:?}"
    );
    assert_eq!(covered(&m), covered(&ball));
    assert!(volume(&m) > 0.0, "the outward copy is kept");

    // An open sheet (the sphere's northern cap) written on both sides: one side is left.
    let cap: Vec<Vec<u32>> = ball
        .faces
        .iter()
        .take(16 * 5)
        .map(<[u32]>::to_vec)
        .collect();
    let mut faces = Polygons::new();
    for f in &cap {
        faces.push(f);
        faces.push(&f.iter().rev().copied().collect::<Vec<_>>());
    }
    let mut m = PolyMesh::new(ball.positions.clone(), faces);
    let open = PolyMesh::new(ball.positions.clone(), {
        let mut p = Polygons::new();
        cap.iter().for_each(|f| p.push(f));
        p
    });
    clean_faces(&mut m);
    cut_nonmanifold_edges(&mut m);
    let t = drop_twin_sides(&mut m);
    assert_eq!((t.pillows_halved, t.faces_dropped), (1, cap.len()));
    let d = diagnose_mesh(&m);
    assert!(d.is_manifold && d.is_consistently_oriented, "{d:?}");
    assert_eq!((d.num_components, d.boundary_loops), (1, 1), "{d:?}");
    assert_eq!(covered(&m), covered(&open));
}
