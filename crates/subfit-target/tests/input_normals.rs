//! Input normals with inconsistent signs (a range image written without orienting its normals
//! toward the scanner) are re-oriented; consistent ones, either sign, are kept as given.

use subfit_target::{NormalOrigin, Target, TargetOptions};

/// A 60 × 60 grid on a paraboloid with its exact unit normals (facing `+z`), and a generator
/// of pseudo-random signs (a fixed linear congruential sequence: the test is deterministic).
fn sheet() -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let m = 60;
    let mut p = Vec::new();
    let mut n = Vec::new();
    for i in 0..m * m {
        let (x, y) = (
            (i % m) as f64 / (m - 1) as f64 - 0.5,
            (i / m) as f64 / (m - 1) as f64 - 0.5,
        );
        p.push([x, y, 0.4 * (x * x + y * y)]);
        let g = [-0.8 * x, -0.8 * y, 1.0];
        let l = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
        n.push([g[0] / l, g[1] / l, g[2] / l]);
    }
    (p, n)
}

fn signs(count: usize) -> Vec<bool> {
    let mut s = 12345u64;
    (0..count)
        .map(|_| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 33) % 3 == 0 // about a third flipped
        })
        .collect()
}

/// `n` with about a third of the normals turned over ([`signs`]).
fn flipped(n: &[[f64; 3]]) -> Vec<[f64; 3]> {
    n.iter()
        .zip(signs(n.len()))
        .map(|(v, f)| if f { v.map(|c| -c) } else { *v })
        .collect()
}

#[test]
fn inconsistent_input_normals_are_oriented_again() {
    let (p, n) = sheet();
    let given = flipped(&n);
    let t = Target::from_points(&p, Some(&given), &TargetOptions::default()).unwrap();
    let st = t.stats();
    assert!(st.reoriented_input_normals, "{}", st.opposed_input_normals);
    assert!(
        st.opposed_input_normals > 0.3,
        "{}",
        st.opposed_input_normals
    );
    // One sign for the whole sheet, and each normal along the true one (directions kept).
    let up = t.normals().iter().filter(|v| v[2] > 0.0).count();
    let total = t.normals().len();
    assert!(up == total || up == 0, "{up} of {total} normals face +z");
    let s = if up == total { 1.0 } else { -1.0 };
    for (i, v) in t.normals().iter().enumerate() {
        let m = t.to_normalized(p[i]);
        let j = (0..total)
            .min_by(|&a, &b| {
                let d = |q: [f64; 3]| (0..3).map(|k| (q[k] - m[k]).powi(2)).sum::<f64>();
                d(t.points()[a]).total_cmp(&d(t.points()[b]))
            })
            .unwrap();
        let c: f64 = (0..3).map(|k| s * t.normals()[j][k] * n[i][k]).sum();
        assert!(c > 0.99, "point {i}: normal {v:?} against {:?}", n[i]);
        if i > 200 {
            break; // a sample is enough (the search is quadratic)
        }
    }
}

#[test]
fn consistent_input_normals_are_kept_either_sign() {
    let (p, n) = sheet();
    for sign in [1.0, -1.0] {
        let given: Vec<[f64; 3]> = n.iter().map(|v| v.map(|c| sign * c)).collect();
        let t = Target::from_points(&p, Some(&given), &TargetOptions::default()).unwrap();
        let st = t.stats();
        assert_eq!(st.normal_origin, NormalOrigin::Input);
        assert!(!st.reoriented_input_normals);
        assert!(
            st.opposed_input_normals < 1e-9,
            "{}",
            st.opposed_input_normals
        );
        assert!(t.normals().iter().all(|v| sign * v[2] > 0.0));
    }
}

/// A mesh's vertex normals are never re-oriented by the neighbour test: its faces orient it,
/// and on a coarse mesh neighbours across a thin part rightly face away from each other.
#[test]
fn a_mesh_keeps_its_vertex_normals() {
    let (p, n) = sheet();
    let given = flipped(&n);
    let m = 60u32;
    let mut faces = subfit_mesh::Polygons::new();
    for j in 0..m - 1 {
        for i in 0..m - 1 {
            let v = j * m + i;
            faces.push(&[v, v + 1, v + m + 1]);
            faces.push(&[v, v + m + 1, v + m]);
        }
    }
    let mut mesh = subfit_mesh::PolyMesh::new(p, faces);
    mesh.normals = Some(given);
    let t = Target::build(&mesh, &TargetOptions::default(), None).unwrap();
    assert!(!t.stats().reoriented_input_normals);
}
