//! The judge's tessellation of a limit surface: the cage refined uniformly `L` times
//! ([`subfit::subdiv::refine`]: Loop 1987, Catmull & Clark 1978, Stam & Loop 2003 with Hoppe et
//! al. 1994 creases) and every level-`L` vertex pushed to its limit point with the limit masks
//! ([`subfit::subdiv::limit_stencils`]). Those points lie exactly on the limit surface (the
//! limit of a vertex is a point of the surface, at the dyadic parameter of the vertex); the
//! level-`L` faces (quads cut along their first diagonal) are the flat triangles between them.
//! `L ≥ 1` is the deepest level with at most 1.5 times the requested number of triangles.
//!
//! This is not the fit's sampling operator (the fused `C = L_l · M_l ⋯ M_1` of
//! `subfit_subdiv::sample`) nor the report's tessellation; it is the plain refinement and limit
//! masks, which the tests cross-check against the exact evaluator. The exact evaluator itself
//! costs about a millisecond per irregular patch on a scan-sized cage (it builds each patch's
//! local refinements), too slow for a million points; the judge uses it only to polish the
//! worst data points (module `polish`).
//!
//! Deviation from the exact surface: level `L`'s vertices include the edge midpoints (in
//! parameter) of every level-`(L − 1)` edge, and the centres of its quads, so the gaps of the
//! coarser tessellation at those points are known exactly; the judge measures them along the
//! exact limit normal there (from the limit tangent masks), since their tangential part is the
//! parametrisation sliding along the surface, not a distance from it (near extraordinary
//! vertices it is ten times the normal part and more). For flat triangles over a smooth surface
//! the gap is, to leading order, a quadratic vanishing at the corners,
//! `e = Σ_{i<j} c_ij λ_i λ_j` with `c_ij = 4 e(midpoint ij)`, so `|e| ≤ (4/3) · max |e(midpoint)|`
//! over a whole triangle. The judge reports `(4/3) ·` the largest level-`(L − 1)` gap (or the
//! largest quad-centre gap, if larger): a bound for the coarser tessellation, hence a
//! conservative one for the level-`L` tessellation it measures with (gaps shrink with each level:
//! four times on smooth regions, five on a 5,000-point scan cage between levels 2 and 3).

use super::walk::Levels;
use rayon::prelude::*;
#[cfg(test)]
use subfit::mesh::vec3::dist2;
use subfit::mesh::vec3::{cross, dot, norm, sub, unit};
use subfit::mesh::{Polygons, Tags};
use subfit::subdiv::{
    limit_stencils, refine, LimitStencils, Options, Scheme, StencilMatrix, SubdivError, Topology,
};

/// A limit tessellation: positions exactly on the limit surface, flat triangles between them.
#[derive(Clone, Debug)]
pub(super) struct Tessellation {
    /// Limit points of the level-`L` vertices, `#V by 3`.
    pub positions: Vec<[f64; 3]>,
    /// Triangles, `#T by 3`.
    pub triangles: Vec<[u32; 3]>,
    /// For triangle `t`: its level-`L` face `face_of[t] / 2` and which half of it (`% 2`: 0
    /// for a triangle face or the first half `(0, 1, 2)` of a quad, 1 for the half `(0, 2, 3)`).
    pub face_of: Vec<u32>,
    /// The refinement chain, to map a level-`L` face back to its patch's parameters.
    pub levels: Levels,
    /// Bound on the gap between the flat triangles and the exact surface (module docs).
    pub deviation: f64,
}

/// Face counts `(triangles, quads, other polygons' corners)` of a face list.
fn face_kinds(faces: &Polygons) -> (usize, usize, usize) {
    faces.iter().fold((0, 0, 0), |(t, q, o), f| match f.len() {
        3 => (t + 1, q, o),
        4 => (t, q + 1, o),
        n => (t, q, o + n),
    })
}

/// The deepest refinement level whose tessellation has at most `1.5 · target` triangles (so
/// between `0.375` and `1.5` times the target), at least 1, and that count. The cap bounds the
/// memory: about 450 bytes per triangle at the peak (refinement, limit stencils, parry's BVH).
pub(super) fn level_for(faces: &Polygons, scheme: Scheme, target: usize) -> (usize, usize) {
    let (t0, q0, o0) = face_kinds(faces);
    // Faces after one level: Loop and quad/triangle split triangles into 4 triangles, quads into
    // 4 quads; Catmull-Clark splits every n-gon into n quads, as quad/triangle does n ≥ 5.
    let (mut t, mut q) = match scheme {
        Scheme::Loop => (4 * t0, 0),
        Scheme::CatmullClark => (0, 3 * t0 + 4 * q0 + o0),
        Scheme::QuadTriangle => (4 * t0, 4 * q0 + o0),
    };
    let tris = |t: usize, q: usize| (t + 2 * q) as f64;
    let cap = 1.5 * target.max(1) as f64;
    let mut level = 1;
    // A face list with no face the scheme splits (quads under Loop) stays at level 1; the
    // refinement then reports it.
    while 4.0 * tris(t, q) <= cap && tris(t, q) > 0.0 {
        (t, q, level) = (4 * t, 4 * q, level + 1);
    }
    (level, tris(t, q) as usize)
}

/// Tessellates the limit of `faces` over `positions` (control points) with `tags` under
/// `options` at refinement `level` (≥ 1; module docs). Cost: `level` refinements and the limit
/// stencils of the last level, O(#triangles) time and memory (about 300 bytes per triangle at
/// the peak).
pub(super) fn tessellate(
    faces: &Polygons,
    positions: &[[f64; 3]],
    tags: &Tags,
    options: &Options,
    level: usize,
) -> Result<Tessellation, SubdivError> {
    let (mut f, mut p, mut t) = (faces.clone(), positions.to_vec(), tags.clone());
    let mut coarse = (f.clone(), p.len());
    for _ in 0..level {
        let r = refine(&f, p.len(), &t, options)?;
        coarse = (f, p.len());
        p = r.matrix.apply(&p);
        (f, t) = (r.faces, r.tags);
    }
    let stencils = limit_stencils(&f, p.len(), &t, options)?;
    let limit = stencils.position.apply(&p);
    let deviation = coarse_gap(&coarse.0, coarse.1, &limit, &stencils, &p, options.scheme)?;
    drop(stencils);
    let mut triangles = Vec::with_capacity(2 * f.len());
    let mut face_of = Vec::with_capacity(2 * f.len());
    for (i, face) in f.iter().enumerate() {
        let i = i as u32;
        triangles.push([face[0], face[1], face[2]]);
        face_of.push(2 * i);
        if face.len() == 4 {
            triangles.push([face[0], face[2], face[3]]);
            face_of.push(2 * i + 1);
        }
    }
    Ok(Tessellation {
        positions: limit,
        triangles,
        face_of,
        levels: Levels::new(faces, options.scheme, level),
        deviation,
    })
}

/// `(4/3) ·` the largest gap of the tessellation of `coarse` (over `nv` vertices) at its edge
/// midpoints, and the largest at its quad centres if larger. Their exact limit points are the
/// next level's edge and face points (child order of [`subfit::subdiv::refine`]: vertex points,
/// edge points in [`Topology`] edge order, face points of the non-triangles), with limit
/// `position`s and `stencils` over that level's points `fine`. A gap is measured along the exact
/// surface normal there: its tangential part is the parametrisation sliding along the surface
/// (large near extraordinary vertices), not a distance from it.
fn coarse_gap(
    coarse: &Polygons,
    nv: usize,
    position: &[[f64; 3]],
    stencils: &LimitStencils,
    fine: &[[f64; 3]],
    scheme: Scheme,
) -> Result<f64, SubdivError> {
    let topo = Topology::new(coarse, nv)?;
    let ne = topo.num_edges();
    let gap = |k: usize, flat: [f64; 3]| {
        let g = sub(position[k], flat);
        let tangent = |m: &StencilMatrix| {
            let (cols, w) = m.row(k);
            cols.iter().zip(w).fold([0.0; 3], |acc, (&c, &w)| {
                std::array::from_fn(|i| acc[i] + w * fine[c as usize][i])
            })
        };
        match unit(cross(
            tangent(&stencils.tangent1),
            tangent(&stencils.tangent2),
        )) {
            Some(n) => dot(g, n).abs(),
            // No normal (degenerate tangents): the whole gap.
            None => norm(g),
        }
    };
    let mid = (0..ne as u32)
        .into_par_iter()
        .map(|e| {
            let [a, b] = topo.edge_vertices(e).map(|v| position[v as usize]);
            gap(
                nv + e as usize,
                std::array::from_fn(|k| 0.5 * (a[k] + b[k])),
            )
        })
        .reduce(|| 0.0, f64::max);
    let mut centre = 0.0f64;
    if scheme != Scheme::Loop {
        // Face points: one per face (Catmull-Clark) or per non-triangle (quad/triangle), in face
        // order; the flat point of a quad's centre is the mean of its corners' limits. n-gons
        // (n ≠ 4) have no bilinear centre and are covered by their edges.
        let mut k = nv + ne;
        for face in coarse.iter() {
            if scheme == Scheme::QuadTriangle && face.len() == 3 {
                continue;
            }
            if face.len() == 4 {
                let flat = std::array::from_fn(|c| {
                    face.iter().map(|&v| position[v as usize][c]).sum::<f64>() / 4.0
                });
                centre = centre.max(gap(k, flat));
            }
            k += 1;
        }
    }
    Ok((4.0 / 3.0 * mid).max(centre))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat_grid(m: usize) -> (Vec<[f64; 3]>, Polygons) {
        let mut p = Vec::new();
        for j in 0..=m {
            for i in 0..=m {
                p.push([i as f64, j as f64, 0.0]);
            }
        }
        let at = |i: usize, j: usize| (j * (m + 1) + i) as u32;
        let mut faces = Polygons::new();
        for j in 0..m {
            for i in 0..m {
                faces.push(&[at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        (p, faces)
    }

    #[test]
    fn levels_come_near_the_target() {
        let (_, quads) = flat_grid(5);
        // 25 quads: level 1 has 100 quads = 200 triangles, each level ×4.
        assert_eq!(level_for(&quads, Scheme::CatmullClark, 1), (1, 200));
        assert_eq!(level_for(&quads, Scheme::CatmullClark, 2_000), (2, 800));
        assert_eq!(level_for(&quads, Scheme::CatmullClark, 2_134), (3, 3_200));
        assert_eq!(level_for(&quads, Scheme::CatmullClark, 8_000), (3, 3_200));
        let tri = Polygons::from_triangles(&[[0, 1, 2]]);
        assert_eq!(level_for(&tri, Scheme::Loop, 1_000_000), (10, 1 << 20));
        let penta = Polygons::from_raw(vec![0, 5], vec![0, 1, 2, 3, 4]).unwrap();
        assert_eq!(level_for(&penta, Scheme::QuadTriangle, 10), (1, 10));
        let quad = Polygons::from_quads(&[[0, 1, 2, 3]]);
        assert_eq!(level_for(&quad, Scheme::Loop, 1_000), (1, 0));
    }

    #[test]
    fn a_flat_cage_is_tessellated_exactly() {
        // A planar Catmull-Clark grid: the limit is planar, so every gap is 0 and every limit
        // point lies in the plane; a wrong edge-point numbering would show as a large gap.
        let (mut p, faces) = flat_grid(5);
        for x in &mut p {
            x[0] += 0.3 * (x[1] * 1.7).sin();
        }
        let opts = Options::new(Scheme::CatmullClark);
        let t = tessellate(&faces, &p, &Tags::new(), &opts, 2).unwrap();
        assert_eq!(t.triangles.len(), 25 * 16 * 2);
        assert!(t.deviation < 1e-12, "{}", t.deviation);
        assert!(t.positions.iter().all(|x| x[2].abs() < 1e-12));
    }

    /// A prism over a regular `n`-gon (two `n`-gon caps, `n` quad sides), outward winding.
    fn prism(n: usize) -> (Vec<[f64; 3]>, Polygons) {
        let mut p = Vec::new();
        for z in [0.0, 1.0] {
            for i in 0..n {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                p.push([a.cos(), a.sin(), z + 0.1 * (2.0 * a).sin()]);
            }
        }
        let n32 = n as u32;
        let mut f = Polygons::new();
        f.push(&(0..n32).rev().collect::<Vec<_>>());
        f.push(&(n32..2 * n32).collect::<Vec<_>>());
        for i in 0..n32 {
            let j = (i + 1) % n32;
            f.push(&[i, j, n32 + j, n32 + i]);
        }
        (p, f)
    }

    #[test]
    fn limit_points_agree_with_the_exact_evaluator() {
        // Every corner of every tessellation triangle, mapped back to its patch's parameters
        // through the refinement's child order, is the exact evaluator's point there: checks
        // the refinement + limit masks against Stam's evaluation and the parameter walk.
        use subfit::mesh::shapes::{cheng_ellipsoid_cage, cube_mesh};
        use subfit::mesh::SHARPNESS_INFINITE;
        use subfit::subdiv::Evaluator;
        let ellipsoid = cheng_ellipsoid_cage(0.5, 0.8, 1.0, false);
        let cube = cube_mesh(0.5);
        let mut creased = Tags::new();
        for f in cube.faces.iter().take(2) {
            for k in 0..4 {
                creased.set_crease(f[k], f[(k + 1) % 4], SHARPNESS_INFINITE);
            }
        }
        let mut semi = Tags::new();
        semi.set_crease(0, 1, 1.5);
        let (tri_prism, tri_faces) = prism(3);
        let (penta, penta_faces) = prism(5);
        let cases = [
            (
                Scheme::Loop,
                ellipsoid.positions,
                ellipsoid.faces,
                Tags::new(),
            ),
            (
                Scheme::Loop,
                tri_prism.clone(),
                tri_faces.clone(),
                Tags::new(),
            ),
            (
                Scheme::CatmullClark,
                cube.positions.clone(),
                cube.faces.clone(),
                creased,
            ),
            (Scheme::CatmullClark, cube.positions, cube.faces, semi),
            (
                Scheme::CatmullClark,
                penta.clone(),
                penta_faces.clone(),
                Tags::new(),
            ),
            (Scheme::QuadTriangle, tri_prism, tri_faces, Tags::new()),
            (Scheme::QuadTriangle, penta, penta_faces, Tags::new()),
        ];
        for (scheme, p, faces, tags) in cases {
            let faces = if scheme == Scheme::Loop && !faces.is_triangles() {
                Polygons::from_triangles(&faces.triangulate_fan())
            } else {
                faces
            };
            let opts = Options::new(scheme);
            let t = tessellate(&faces, &p, &tags, &opts, 2).unwrap();
            let ev = Evaluator::new(&faces, p.len(), &tags, &opts).unwrap();
            let mut worst = 0.0f64;
            for (tri, &h) in t.triangles.iter().zip(&t.face_of) {
                for (i, &v) in tri.iter().enumerate() {
                    let mut bary = [0.0; 3];
                    bary[i] = 1.0;
                    let q = t.levels.param(h, bary);
                    let x = ev.evaluate(&p, q).unwrap().position;
                    worst = worst.max(dist2(x, t.positions[v as usize]).sqrt());
                }
            }
            assert!(worst < 1e-12, "{scheme:?}: {worst:e}");
            assert!(
                t.deviation > 0.0 && t.deviation < 0.1,
                "{scheme:?}: {}",
                t.deviation
            );
        }
    }
}
