//! A latitude–longitude triangulated sphere for the silhouette tests and benchmark.

/// A UV sphere of radius `r` around `c`: `n_lon` segments around the z axis, `n_lat` bands
/// from pole to pole (both ≥ 3), `2·n_lon·(n_lat − 1)` outward triangles, closed.
pub fn uv_sphere(
    r: f64,
    c: [f64; 3],
    n_lon: usize,
    n_lat: usize,
) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut positions = vec![[c[0], c[1], c[2] + r]];
    for i in 1..n_lat {
        let theta = std::f64::consts::PI * i as f64 / n_lat as f64;
        for j in 0..n_lon {
            let phi = std::f64::consts::TAU * j as f64 / n_lon as f64;
            positions.push([
                c[0] + r * theta.sin() * phi.cos(),
                c[1] + r * theta.sin() * phi.sin(),
                c[2] + r * theta.cos(),
            ]);
        }
    }
    positions.push([c[0], c[1], c[2] - r]);
    let south = (positions.len() - 1) as u32;
    let ring = |i: usize, j: usize| (1 + (i - 1) * n_lon + j % n_lon) as u32;
    let mut triangles = Vec::with_capacity(2 * n_lon * (n_lat - 1));
    for j in 0..n_lon {
        triangles.push([0, ring(1, j), ring(1, j + 1)]);
        triangles.push([south, ring(n_lat - 1, j + 1), ring(n_lat - 1, j)]);
    }
    for i in 1..n_lat - 1 {
        for j in 0..n_lon {
            let (a, b) = (ring(i, j), ring(i + 1, j));
            let (c, d) = (ring(i + 1, j + 1), ring(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    (positions, triangles)
}
