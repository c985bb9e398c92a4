//! Local refinement of polygon cages (`refine_polygons`): conformity (no T-vertex), topology
//! kept, tags carried, the limit surface barely changed, quads kept.

mod common;

use std::collections::HashMap;

use subfit_fit::internals::face_owners;
use subfit_fit::{refine_polygons, PolyRefinement};
use subfit_measure::MeshDistance;
use subfit_mesh::shapes::{octahedron_mesh, torus_mesh};
use subfit_mesh::{HalfEdgeMesh, PolyMesh, Polygons, Tags, SHARPNESS_INFINITE};
use subfit_subdiv::{sampling_operator, Options, Scheme};

use common::quad_sphere;

/// An open `n × n` quad grid on z = 0 (one boundary loop), with the two quads at the centre
/// merged into a hexagon when `hexagon`.
fn quad_patch(n: usize, hexagon: bool) -> PolyMesh {
    let id = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    let mut pos = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            pos.push([i as f64 / n as f64, j as f64 / n as f64, 0.0]);
        }
    }
    let mut faces = Polygons::new();
    let c = n / 2;
    for i in 0..n {
        for j in 0..n {
            if hexagon && i == c && (j == c || j == c - 1) {
                if j == c - 1 {
                    // Quads (c, c−1) and (c, c) without their shared edge.
                    faces.push(&[
                        id(i, j),
                        id(i + 1, j),
                        id(i + 1, j + 1),
                        id(i + 1, j + 2),
                        id(i, j + 2),
                        id(i, j + 1),
                    ]);
                }
                continue;
            }
            faces.push(&[id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    PolyMesh::new(pos, faces)
}

/// A mixed cage: the quad torus with every third quad cut into two triangles.
fn mixed_torus() -> PolyMesh {
    let m = torus_mesh(1.0, 0.4, 8, 6, false);
    let mut faces = Polygons::new();
    for (f, q) in m.faces.iter().enumerate() {
        if f % 3 == 0 {
            faces.push(&[q[0], q[1], q[2]]);
            faces.push(&[q[0], q[2], q[3]]);
        } else {
            faces.push(q);
        }
    }
    PolyMesh::new(m.positions, faces)
}

/// Seeded marks: each face with probability `p` (a small LCG; no test dependency needed).
fn random_marks(n: usize, p: f64, seed: u64) -> Vec<bool> {
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (0..n)
        .map(|_| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) < p
        })
        .collect()
}

fn cc() -> Options {
    Options::new(Scheme::CatmullClark)
}

fn quad_fraction(m: &PolyMesh) -> f64 {
    m.faces.iter().filter(|f| f.len() == 4).count() as f64 / m.faces.len() as f64
}

/// Every check of a conforming refinement of `before` into `r`.
#[track_caller]
fn assert_conforming(before: &PolyMesh, r: &PolyRefinement, what: &str) {
    let after = &r.mesh;
    // Directed edges once each; an undirected edge has two faces in opposite directions, or
    // one face on the boundary.
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for f in after.faces.iter() {
        assert!(f.len() >= 3, "{what}: degenerate face {f:?}");
        for i in 0..f.len() {
            let e = (f[i], f[(i + 1) % f.len()]);
            assert_ne!(e.0, e.1, "{what}: repeated vertex in {f:?}");
            *directed.entry(e).or_default() += 1;
        }
    }
    assert!(
        directed.values().all(|&c| c == 1),
        "{what}: a directed edge twice"
    );
    let he0 = HalfEdgeMesh::from_mesh(before).unwrap();
    let he1 = HalfEdgeMesh::from_mesh(after).expect("manifold, consistently oriented");
    assert_eq!(
        he1.euler_characteristic(),
        he0.euler_characteristic(),
        "{what}: χ"
    );
    assert_eq!(
        he1.boundary_loops().len(),
        he0.boundary_loops().len(),
        "{what}: loops"
    );
    // Boundary edges of the result lie on boundary edges of the cage (split or not).
    let boundary0: usize = he0.boundary_loops().iter().map(Vec::len).sum();
    let boundary1: usize = he1.boundary_loops().iter().map(Vec::len).sum();
    assert!(boundary1 >= boundary0, "{what}");
    // No T-vertex: a split edge is an edge of no face any more, its halves are.
    let has = |a: u32, b: u32| directed.contains_key(&(a, b)) || directed.contains_key(&(b, a));
    for &((a, b), m) in &r.edge_points {
        assert!(
            !has(a, b),
            "{what}: split edge ({a}, {b}) still used: T-vertex at {m}"
        );
        assert!(has(a, m) && has(m, b), "{what}: halves of ({a}, {b})");
    }
    // Every new point is an edge point of a split edge or a face point inside one parent.
    let nv = before.num_vertices();
    let edge_pts: Vec<u32> = r.edge_points.iter().map(|e| e.1).collect();
    for (f, face) in after.faces.iter().enumerate() {
        for &v in face {
            if v as usize >= nv && !edge_pts.contains(&v) {
                let p = r.parents[f];
                let siblings: Vec<usize> = (0..r.parents.len())
                    .filter(|&g| r.parents[g] == p)
                    .collect();
                assert!(siblings.len() > 1, "{what}: face point in an unsplit face");
                for (g, other) in after.faces.iter().enumerate() {
                    if other.contains(&v) {
                        assert_eq!(r.parents[g], p, "{what}: face point {v} in two parents");
                    }
                }
            }
        }
    }
    // Old points keep their ids, parents are consecutive and cover every old face.
    assert!(after.num_vertices() >= nv);
    assert!(
        r.parents
            .windows(2)
            .all(|w| w[0] <= w[1] && w[1] <= w[0] + 1),
        "{what}"
    );
    assert_eq!(*r.parents.last().unwrap() as usize + 1, before.faces.len());
    assert_eq!(r.parents[0], 0);
}

#[test]
fn refinement_is_conforming_on_quad_mixed_and_ngon_cages() {
    let cages = [
        ("quad sphere", quad_sphere(3)),
        ("mixed torus", mixed_torus()),
        ("hexagon patch", quad_patch(6, true)),
        ("octahedron", octahedron_mesh(1.0, 1.0, 1.0)),
    ];
    for (name, cage) in &cages {
        for (seed, p) in [(1, 0.05), (2, 0.2), (3, 0.5), (4, 1.0)] {
            let marked = random_marks(cage.faces.len(), p, seed);
            for scheme in [Scheme::CatmullClark, Scheme::Loop] {
                if scheme == Scheme::Loop && !cage.faces.is_triangles() {
                    continue;
                }
                let r =
                    refine_polygons(cage, &Tags::new(), &marked, &Options::new(scheme)).unwrap();
                let what = format!("{name}, p = {p}, {scheme:?}");
                assert_conforming(cage, &r, &what);
                if marked.contains(&true) {
                    assert!(r.stats.new_points > 0, "{what}");
                    assert!(r.stats.red >= r.stats.marked, "{what}");
                }
                // A second refinement of the result, with other marks, stays conforming.
                let marked2 = random_marks(r.mesh.faces.len(), p, seed + 10);
                let r2 =
                    refine_polygons(&r.mesh, &r.tags, &marked2, &Options::new(scheme)).unwrap();
                assert_conforming(&r.mesh, &r2, &format!("{what}, second"));
            }
        }
    }
}

/// The templates: one marked quad in a grid gives 4 quads and, around it, 2-quad... no: the
/// four edge neighbours get one split edge (quad + triangle), the diagonal ones none.
#[test]
fn one_marked_quad_closes_with_quad_triangle_pairs() {
    let cage = quad_patch(5, false);
    let centre = 2 * 5 + 2;
    let mut marked = vec![false; cage.faces.len()];
    marked[centre] = true;
    let r = refine_polygons(&cage, &Tags::new(), &marked, &cc()).unwrap();
    assert_eq!((r.stats.red, r.stats.green, r.stats.new_points), (1, 4, 5));
    assert_eq!(r.mesh.faces.len(), 25 - 5 + 4 + 4 * 2);
    let tris = r.mesh.faces.iter().filter(|f| f.len() == 3).count();
    assert_eq!(tris, 4);
    assert_conforming(&cage, &r, "one quad");
    // Two opposite split edges close with two quads, two adjacent ones with three quads.
    let mut marked = vec![false; cage.faces.len()];
    marked[2 * 5 + 1] = true;
    marked[2 * 5 + 3] = true; // the centre quad has its left and right edges split
    marked[5 + 1] = true; // (1, 1) and (0, 2) split two adjacent edges of (1, 2)
    marked[2] = true;
    let r = refine_polygons(&cage, &Tags::new(), &marked, &cc()).unwrap();
    assert_conforming(&cage, &r, "templates");
    let children = |p: usize| r.parents.iter().filter(|&&q| q as usize == p).count();
    let sizes = |p: usize| -> Vec<usize> {
        let mut s: Vec<usize> = (0..r.parents.len())
            .filter(|&g| r.parents[g] as usize == p)
            .map(|g| r.mesh.faces.iter().nth(g).unwrap().len())
            .collect();
        s.sort_unstable();
        s
    };
    assert_eq!(sizes(centre), vec![4, 4], "opposite");
    assert_eq!(children(5 + 2), 3);
    assert_eq!(sizes(5 + 2), vec![4, 4, 4], "adjacent");
}

#[test]
fn quads_stay_dominant() {
    let cage = quad_sphere(6);
    // A patch of 3 × 3 quads on one side, marked twice over.
    let mut mesh = cage.clone();
    let mut tags = Tags::new();
    for round in 0..2 {
        let centre = mesh.positions[0];
        let marked: Vec<bool> = mesh
            .faces
            .iter()
            .map(|f| {
                let c = f.iter().fold([0.0; 3], |s, &v| {
                    let p = mesh.positions[v as usize];
                    [s[0] + p[0], s[1] + p[1], s[2] + p[2]]
                });
                let c = c.map(|x| x / f.len() as f64);
                let d2: f64 = (0..3).map(|k| (c[k] - centre[k]).powi(2)).sum();
                d2 < (0.45f64 / (1 + round) as f64).powi(2)
            })
            .collect();
        assert!(marked.contains(&true));
        let r = refine_polygons(&mesh, &tags, &marked, &cc()).unwrap();
        assert_conforming(&mesh, &r, "patch");
        mesh = r.mesh;
        tags = r.tags;
    }
    let q = quad_fraction(&mesh);
    assert!(
        q >= 0.9,
        "quad fraction {q}: {:?}",
        mesh.faces.size_histogram()
    );
    assert!(mesh.faces.len() > cage.faces.len() + 20);
}

#[test]
fn split_creases_give_two_creases_and_corners_stay() {
    let cage = quad_sphere(2);
    let f0 = cage.faces.iter().next().unwrap().to_vec();
    let far = cage.faces.iter().last().unwrap().to_vec();
    let mut tags = Tags::new();
    tags.set_crease(f0[0], f0[1], SHARPNESS_INFINITE);
    tags.set_crease(far[0], far[1], 1.0); // on an unsplit face far away
    tags.set_corner(f0[2], 3.0);
    let mut marked = vec![false; cage.faces.len()];
    marked[0] = true;
    let r = refine_polygons(&cage, &tags, &marked, &cc()).unwrap();
    let m = r
        .edge_points
        .iter()
        .find(|e| e.0 == (f0[0].min(f0[1]), f0[0].max(f0[1])))
        .unwrap()
        .1;
    assert_eq!(r.tags.crease(f0[0], m), SHARPNESS_INFINITE);
    assert_eq!(r.tags.crease(m, f0[1]), SHARPNESS_INFINITE);
    assert_eq!(r.tags.crease(f0[0], f0[1]), 0.0);
    assert_eq!(r.tags.crease(far[0], far[1]), 1.0);
    assert_eq!(r.tags.creases().len(), 3);
    assert_eq!(r.tags.corner(f0[2]), 3.0);
    // The crease's edge point is its midpoint (the crease rule).
    let (a, b) = (
        cage.positions[f0[0] as usize],
        cage.positions[f0[1] as usize],
    );
    for k in 0..3 {
        assert!((r.mesh.positions[m as usize][k] - 0.5 * (a[k] + b[k])).abs() < 1e-14);
    }
}

/// Level-`l` limit samples of a cage under Catmull-Clark.
fn samples(m: &PolyMesh, tags: &Tags, level: usize) -> (Vec<[f64; 3]>, Polygons) {
    let op = sampling_operator(&m.faces, m.num_vertices(), tags, &cc(), level).unwrap();
    (op.position.apply(&m.positions), op.faces)
}

#[test]
fn limit_surface_is_unchanged_by_a_full_split_and_barely_by_a_local_one() {
    // Bounds on the move, as a fraction of the cage's diagonal: the octahedron is so coarse
    // (6 points) that one split face changes the neighbourhood of every vertex.
    for (name, cage, bound) in [
        ("quad sphere", quad_sphere(3), 0.02),
        ("mixed torus", mixed_torus(), 0.03),
        ("hexagon patch", quad_patch(6, true), 0.001),
        ("octahedron", octahedron_mesh(1.0, 0.7, 0.5), 0.05),
    ] {
        let n = cage.num_vertices();
        let (before, _) = samples(&cage, &Tags::new(), 2);
        // Everything marked: one uniform Catmull-Clark step, the same limit surface.
        let all =
            refine_polygons(&cage, &Tags::new(), &vec![true; cage.faces.len()], &cc()).unwrap();
        assert!(all.mesh.faces.is_quads(), "{name}");
        let (after, _) = samples(&all.mesh, &Tags::new(), 1);
        for v in 0..n {
            for k in 0..3 {
                assert!(
                    (before[v][k] - after[v][k]).abs() < 1e-12,
                    "{name}: {v}: {:?} vs {:?}",
                    before[v],
                    after[v]
                );
            }
        }
        // A local patch: the limit surface moves by a small fraction of the cage's size, and
        // not at all at old points whose neighbourhood is untouched.
        let marked = random_marks(cage.faces.len(), 0.15, 5);
        let r = refine_polygons(&cage, &Tags::new(), &marked, &cc()).unwrap();
        let (s0, f0) = samples(&cage, &Tags::new(), 3);
        let (s1, f1) = samples(&r.mesh, &Tags::new(), 3);
        let d01 = MeshDistance::new(&s0, &f0).distances(&s1);
        let d10 = MeshDistance::new(&s1, &f1).distances(&s0);
        let worst = d01
            .iter()
            .chain(&d10)
            .map(|p| p.distance)
            .fold(0.0, f64::max);
        let size = cage
            .bounding_box()
            .map(|(lo, hi)| (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt())
            .unwrap();
        assert!(worst < bound * size, "{name}: moved {worst} of {size}");
        // Old points two face rings away from every touched face keep their limit points.
        let touched: Vec<bool> = {
            let mut t = vec![false; n];
            for (f, face) in cage.faces.iter().enumerate() {
                let changed = r.parents.iter().filter(|&&p| p as usize == f).count() > 1;
                if changed {
                    face.iter().for_each(|&v| t[v as usize] = true);
                }
            }
            for _ in 0..2 {
                let prev = t.clone();
                for face in cage.faces.iter() {
                    if face.iter().any(|&v| prev[v as usize]) {
                        face.iter().for_each(|&v| t[v as usize] = true);
                    }
                }
            }
            t
        };
        let (l0, _) = samples(&cage, &Tags::new(), 0);
        let (l1, _) = samples(&r.mesh, &Tags::new(), 0);
        for v in (0..n).filter(|&v| !touched[v]) {
            for k in 0..3 {
                assert!((l0[v][k] - l1[v][k]).abs() < 1e-12, "{name}: {v}");
            }
        }
    }
}

/// `face_owners` maps every level-`l` face of a mixed cage with an `n`-gon to the control face
/// it descends from, under Catmull-Clark: an `n`-gon has `n · 4^(l−1)` descendants.
#[test]
fn face_owners_handle_quads_triangles_and_ngons() {
    for cage in [quad_patch(4, true), mixed_torus()] {
        for level in 0..3 {
            let op =
                sampling_operator(&cage.faces, cage.num_vertices(), &Tags::new(), &cc(), level)
                    .unwrap();
            let owners = face_owners(&cage.faces, &op);
            assert_eq!(owners.len(), op.faces.len());
            for (f, face) in cage.faces.iter().enumerate() {
                let count = owners.iter().filter(|&&o| o as usize == f).count();
                let expect = if level == 0 {
                    1
                } else {
                    face.len() * 4usize.pow(level as u32 - 1)
                };
                assert_eq!(count, expect, "level {level}, face {f}");
            }
            // Each level-l face's corners lie in its owner's level-1 children: check that the
            // sample faces of one owner are connected and geometrically inside its face's
            // neighbourhood — here: their centroid is nearer to the owner's centroid than to
            // any other control face's.
            let samples = op.position.apply(&cage.positions);
            let centroid = |pts: &mut dyn Iterator<Item = [f64; 3]>| {
                let (mut c, mut k) = ([0.0; 3], 0.0);
                for p in pts {
                    (0..3).for_each(|i| c[i] += p[i]);
                    k += 1.0;
                }
                c.map(|x| x / k)
            };
            let control: Vec<[f64; 3]> = cage
                .faces
                .iter()
                .map(|f| centroid(&mut f.iter().map(|&v| cage.positions[v as usize])))
                .collect();
            for (g, face) in op.faces.iter().enumerate() {
                let c = centroid(&mut face.iter().map(|&v| samples[v as usize]));
                let d2 = |q: [f64; 3]| (0..3).map(|i| (q[i] - c[i]).powi(2)).sum::<f64>();
                let own = d2(control[owners[g] as usize]);
                let best = control.iter().map(|&q| d2(q)).fold(f64::INFINITY, f64::min);
                assert!(own <= best * 4.0 + 1e-12, "level {level}: face {g}");
            }
        }
    }
}

/// `quad_patch` with the quad at `(i, j)` of every `(i, j)` in `cut` split into two
/// triangles along its diagonal.
fn quad_patch_with_triangles(n: usize, cut: &[(usize, usize)]) -> PolyMesh {
    let mut m = quad_patch(n, false);
    let mut faces = Polygons::new();
    for (f, q) in m.faces.iter().enumerate() {
        if cut.contains(&(f / n, f % n)) {
            faces.push(&[q[0], q[1], q[2]]);
            faces.push(&[q[0], q[2], q[3]]);
        } else {
            faces.push(q);
        }
    }
    m.faces = faces;
    m
}

/// A triangle of a small cluster with one split edge turns into quads (a full split), so a
/// quad-dominant cage stays quad-dominant; a large triangle region is bisected instead, so one
/// split does not spread over it.
#[test]
fn small_triangle_clusters_split_into_quads_large_ones_are_bisected() {
    // One triangle pair at (2, 3), next to the marked quad (2, 2).
    let cage = quad_patch_with_triangles(5, &[(2, 3)]);
    let marked_at = |cage: &PolyMesh, i: usize, j: usize| {
        // The quad whose first corner is grid point (i, j).
        let mut marked = vec![false; cage.faces.len()];
        let f = cage
            .faces
            .iter()
            .position(|q| q.len() == 4 && q[0] == (i * 6 + j) as u32)
            .unwrap();
        marked[f] = true;
        marked
    };
    let r = refine_polygons(&cage, &Tags::new(), &marked_at(&cage, 2, 2), &cc()).unwrap();
    assert_conforming(&cage, &r, "triangle pair");
    // The pair's triangle on the split edge becomes 3 quads; its partner gets one split edge
    // and becomes 3 quads too; the quads around close with quad + triangle templates.
    let pair_children: Vec<usize> = (0..r.parents.len())
        .filter(|&g| {
            let p = r.parents[g] as usize;
            cage.faces.iter().nth(p).unwrap().len() == 3
        })
        .map(|g| r.mesh.faces.iter().nth(g).unwrap().len())
        .collect();
    assert_eq!(
        pair_children,
        vec![4; 6],
        "both triangles of the pair split into quads"
    );

    // A 5 × 2 block of cut quads (20 triangles) beside the marked quad: the triangle on the split
    // edge is bisected, nothing spreads through the block.
    let block: Vec<(usize, usize)> = (0..5).flat_map(|i| (3..5).map(move |j| (i, j))).collect();
    let cage = quad_patch_with_triangles(5, &block);
    let r = refine_polygons(&cage, &Tags::new(), &marked_at(&cage, 2, 2), &cc()).unwrap();
    assert_conforming(&cage, &r, "triangle block");
    assert_eq!(r.stats.red, 1, "only the marked quad is split fully");
    assert_eq!(r.stats.new_points, 5);
}

/// The quad/triangle scheme refines a triangle-dominant cage with its own split (four
/// triangles, Loop's), so an all-triangle cage refines exactly as under Loop; a quad-dominant
/// cage splits its triangles into three quads and stays quad-dominant.
#[test]
fn quad_triangle_refinement_follows_the_cage() {
    let tris = torus_mesh(1.0, 0.4, 8, 6, true);
    let qt = Options::new(Scheme::QuadTriangle);
    for seed in 0..4 {
        let marked = random_marks(tris.faces.len(), 0.3, seed);
        let a = refine_polygons(&tris, &Tags::new(), &marked, &qt).unwrap();
        let b = refine_polygons(&tris, &Tags::new(), &marked, &Options::new(Scheme::Loop)).unwrap();
        assert_conforming(&tris, &a, "triangle torus");
        assert!(a.mesh.faces.is_triangles(), "seed {seed}");
        assert_eq!(a.mesh.faces, b.mesh.faces, "seed {seed}");
        for (p, q) in a.mesh.positions.iter().zip(&b.mesh.positions) {
            let d = (0..3).map(|k| (p[k] - q[k]).abs()).fold(0.0, f64::max);
            assert!(d < 1e-12, "seed {seed}: {p:?} vs {q:?}");
        }
    }
    let mixed = mixed_torus();
    assert!(quad_fraction(&mixed) >= 0.5);
    let r = refine_polygons(&mixed, &Tags::new(), &vec![true; mixed.faces.len()], &qt).unwrap();
    assert_conforming(&mixed, &r, "mixed torus");
    assert_eq!(quad_fraction(&r.mesh), 1.0);
}
