//! Taubin smoothing of a triangle mesh's positions, for simplifying a noisy mesh.
//!
//! Quadric simplification ([`crate::simplify`](mod@crate::simplify)) refuses a collapse that
//! turns a face's normal by more than 75–89° or against the accumulated input normals. On a
//! mesh whose vertex noise is comparable to its edge length (a raw photogrammetry or
//! structured-light mesh) the triangles are crumpled, their normals nearly random, and most
//! collapses fail those checks: the Igea cut open at its base with Gaussian vertex noise of
//! 1e-3 of the diagonal (edges 1.7e-3) stopped at 1,631 vertices when 541 were asked for. The
//! simplification then runs again on a smoothed copy: the cage only needs to be near the
//! surface, the fit follows the data.
//!
//! The smoothing is Taubin's λ|μ filter (Taubin 1995, "A signal processing approach to fair
//! surface design", §4): an umbrella step `x += λ (x̄ − x)` towards the mean of the edge
//! neighbours, then one with `μ < −λ` that undoes the shrinking of low frequencies. With
//! `λ = 0.5`, `μ = −0.53` (pass-band `k_PB = 1/λ + 1/μ ≈ 0.11`) a few passes remove the
//! vertex-scale noise and keep the shape. A boundary vertex is smoothed along its boundary
//! neighbours only, so boundary loops keep their place. Cost `O(passes · (#V + #T))`.

use std::collections::HashMap;

/// Taubin's `λ` (the shrinking step).
const LAMBDA: f64 = 0.5;
/// Taubin's `μ` (the inflating step), `μ < −λ`.
const MU: f64 = -0.53;

/// `positions` smoothed by `passes` λ|μ passes over the edges of `triangles` (see the module
/// docs). Vertices in no triangle keep their position.
pub(crate) fn taubin(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    passes: usize,
) -> Vec<[f64; 3]> {
    let neighbours = neighbours(positions.len(), triangles);
    let mut x = positions.to_vec();
    let mut next = x.clone();
    for _ in 0..passes {
        for factor in [LAMBDA, MU] {
            for (v, nb) in neighbours.iter().enumerate() {
                if nb.is_empty() {
                    continue;
                }
                let mut mean = [0.0; 3];
                for &u in nb {
                    for k in 0..3 {
                        mean[k] += x[u as usize][k];
                    }
                }
                let inv = 1.0 / nb.len() as f64;
                for k in 0..3 {
                    next[v][k] = x[v][k] + factor * (mean[k] * inv - x[v][k]);
                }
            }
            std::mem::swap(&mut x, &mut next);
        }
    }
    x
}

/// Per vertex the neighbours it is averaged with: its edge neighbours, or for a vertex on a
/// boundary edge (an edge of one triangle) its boundary neighbours.
fn neighbours(n: usize, triangles: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(3 * triangles.len());
    for t in triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let mut all = vec![Vec::new(); n];
    let mut rim = vec![Vec::new(); n];
    for (&(a, b), &count) in &edges {
        let (ai, bi) = (a as usize, b as usize);
        if ai >= n || bi >= n {
            continue;
        }
        all[ai].push(b);
        all[bi].push(a);
        if count == 1 {
            rim[ai].push(b);
            rim[bi].push(a);
        }
    }
    all.into_iter()
        .zip(rim)
        .map(|(mut a, r)| {
            let mut nb = if r.is_empty() {
                std::mem::take(&mut a)
            } else {
                r
            };
            // Sorted, so the result does not depend on the hash map's order.
            nb.sort_unstable();
            nb
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat grid in z = 0 with `k × k` vertices, spacing 1.
    fn grid(k: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut p = Vec::new();
        for j in 0..k {
            for i in 0..k {
                p.push([i as f64, j as f64, 0.0]);
            }
        }
        let mut t = Vec::new();
        for j in 0..k - 1 {
            for i in 0..k - 1 {
                let a = j * k + i;
                t.push([a, a + 1, a + k + 1]);
                t.push([a, a + k + 1, a + k]);
            }
        }
        (p, t)
    }

    #[test]
    fn noise_on_a_plane_is_removed_and_the_boundary_stays_in_place() {
        let (mut p, t) = grid(21);
        // Deterministic pseudo-random noise in [-0.3, 0.3] (a 64-bit LCG's high bits).
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        for q in p.iter_mut() {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            q[2] = 0.6 * ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5);
        }
        let rms =
            |p: &[[f64; 3]]| (p.iter().map(|q| q[2] * q[2]).sum::<f64>() / p.len() as f64).sqrt();
        // The roughness the simplification trips over: each vertex's offset from the mean of
        // its neighbours (the umbrella vector), RMS over the interior.
        let nb = neighbours(p.len(), &t);
        let rough = |p: &[[f64; 3]]| {
            let d: Vec<f64> = nb
                .iter()
                .enumerate()
                .filter(|(_, n)| n.len() == 6)
                .map(|(v, n)| p[v][2] - n.iter().map(|&u| p[u as usize][2]).sum::<f64>() / 6.0)
                .collect();
            (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt()
        };
        let (before, rough_before) = (rms(&p), rough(&p));
        let s = taubin(&p, &t, 10);
        assert!(
            rough(&s) < 0.2 * rough_before,
            "{rough_before} -> {}",
            rough(&s)
        );
        assert!(rms(&s) < 0.5 * before, "{before} -> {}", rms(&s));
        // Corner (0, 0) has boundary neighbours (1, 0) and (0, 1): it moves in z only by
        // their noise, not towards the interior in x or y by more than a fraction.
        assert!(s[0][0].abs() < 0.3 && s[0][1].abs() < 0.3, "{:?}", s[0]);
        // An edge's middle vertex stays on its edge line (y = 0) but for what the rounding
        // corners pass along the edge.
        assert!(s[10][1].abs() < 1e-3, "{:?}", s[10]);
    }

    #[test]
    fn a_sphere_keeps_its_size() {
        // Octahedron refined by midpoint subdivision and projected onto the unit sphere.
        let o = subfit_mesh::shapes::octahedron_mesh(1.0, 1.0, 1.0);
        let mut p = o.positions;
        let mut t = o.faces.triangulate_fan();
        for _ in 0..4 {
            let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
            let mut nt = Vec::new();
            for tri in &t {
                let m: Vec<u32> = (0..3)
                    .map(|i| {
                        let (a, b) = (tri[i], tri[(i + 1) % 3]);
                        *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                            let (pa, pb) = (p[a as usize], p[b as usize]);
                            let c = [0, 1, 2].map(|k| 0.5 * (pa[k] + pb[k]));
                            let l = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
                            p.push(c.map(|x| x / l));
                            p.len() as u32 - 1
                        })
                    })
                    .collect();
                nt.push([tri[0], m[0], m[2]]);
                nt.push([tri[1], m[1], m[0]]);
                nt.push([tri[2], m[2], m[1]]);
                nt.push([m[0], m[1], m[2]]);
            }
            t = nt;
        }
        let s = taubin(&p, &t, 10);
        let radius: f64 = s
            .iter()
            .map(|q| (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt())
            .sum::<f64>()
            / s.len() as f64;
        assert!((radius - 1.0).abs() < 0.01, "mean radius {radius}");
    }
}
