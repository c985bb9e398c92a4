//! A polygon cage from a position field (Jakob et al. 2015 §5 extract the graph of the
//! lattice points; here its dual is taken from the mesh's triangles, which keeps the result a
//! manifold with the surface's orientation).
//!
//! 1. **Regions.** Two neighbouring vertices whose rounded lattice points coincide (integer
//!    offset `(0, 0)` between them, [`super::field::compat_position`]) belong to one region
//!    (union-find, as §5's collapse of edges between coincident lattice points). A region
//!    becomes a cage vertex at the mean of its lattice points.
//! 2. **Clean-up.** A region of fewer than [`MIN_REGION_SHARE`] of the mean region size, or
//!    touching fewer than three other regions (an island), is merged into the neighbour it
//!    shares the most mesh edges with.
//! 3. **Dual.** Every mesh triangle whose corners lie in three different regions gives a cage
//!    triangle with its orientation (the dual of the regions' partition, as in the Voronoi
//!    dual of Valette, Chassery & Prost, "Generic remeshing of 3D triangular meshes with
//!    metric-dependent discrete Voronoi diagrams", TVCG 2008, §5); repeated triangles are
//!    kept once. Where four regions meet at a lattice cell, two such triangles share the
//!    cell's diagonal, and pairing them ([`crate::quads`]) gives the quad.
//! 4. **Manifold repair.** Where the dual is not a manifold (an edge of three faces, two fans
//!    at a vertex, a folded pair), a region involved is merged into its neighbour and the dual
//!    taken again, at most [`MAX_REPAIRS`] times.
//!
//! Cost: `O(E α(V))` for the regions, `O(T)` for each dual, `O(R · T)` in all for `R` repairs.

use subfit_mesh::vec3::{add, cross, dot, scale, sub};
use subfit_mesh::{HalfEdgeMesh, PolyMesh, Polygons, TopologyError};

use super::field::Graph;
use super::offsets::Offsets;

/// Regions smaller than this share of the mean region size (vertices of the working mesh) are
/// merged into a neighbour: a lattice point reached by one or two vertices is a rounding
/// accident at a seam of the field, not a cage vertex of its own.
pub(crate) const MIN_REGION_SHARE: f64 = 0.25;

/// Most merges of the manifold repair before the extraction gives up, as a share of the
/// regions: a lattice that needs more is no cage of its lattice any more.
pub(crate) const MAX_REPAIR_SHARE: f64 = 0.05;

/// Why the extraction failed.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum ExtractError {
    /// The dual did not become a manifold within [`MAX_REPAIRS`] merges.
    NotManifold(String),
    /// Fewer than four regions.
    TooFewRegions(usize),
}

/// The regions of the lattice offsets `offsets` over `graph`: vertices joined by edges of
/// offset zero; a region id per vertex, ids `0..count`.
pub(crate) fn regions(graph: &Graph, offsets: &Offsets) -> Vec<u32> {
    let n = graph.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            let up = parent[parent[x as usize] as usize];
            parent[x as usize] = up;
            x = up;
        }
        x
    }
    for i in 0..n {
        for &j in graph.neighbors(i) {
            if (j as usize) > i && offsets.is_zero(i as u32, j) {
                let (a, b) = (find(&mut parent, i as u32), find(&mut parent, j));
                if a != b {
                    parent[a.max(b) as usize] = a.min(b);
                }
            }
        }
    }
    let mut id = vec![u32::MAX; n];
    let mut next = 0;
    (0..n)
        .map(|v| {
            let r = find(&mut parent, v as u32) as usize;
            if id[r] == u32::MAX {
                id[r] = next;
                next += 1;
            }
            id[r]
        })
        .collect()
}

/// Per region: the other regions it shares mesh edges with, and how many.
fn shared_edges(graph: &Graph, labels: &[u32], count: usize) -> Vec<Vec<(u32, u32)>> {
    let mut out: Vec<Vec<(u32, u32)>> = vec![Vec::new(); count];
    for i in 0..graph.len() {
        let a = labels[i];
        for &j in graph.neighbors(i) {
            let b = labels[j as usize];
            if a != b {
                let list = &mut out[a as usize];
                match list.iter_mut().find(|(r, _)| *r == b) {
                    Some((_, c)) => *c += 1,
                    None => list.push((b, 1)),
                }
            }
        }
    }
    out
}

/// Renumbers `labels` to `0..count` in order of first use; returns the count.
fn compact(labels: &mut [u32]) -> usize {
    let max = labels.iter().copied().max().map_or(0, |m| m as usize + 1);
    let mut id = vec![u32::MAX; max];
    let mut next = 0u32;
    for l in labels.iter_mut() {
        if id[*l as usize] == u32::MAX {
            id[*l as usize] = next;
            next += 1;
        }
        *l = id[*l as usize];
    }
    next as usize
}

/// Merges region `r` into the neighbour it shares the most edges with (ties: the lower id).
/// Returns false when `r` has no neighbour.
fn merge_region(labels: &mut [u32], neighbors: &[(u32, u32)], r: u32) -> bool {
    let Some(&(into, _)) = neighbors
        .iter()
        .max_by(|x, y| x.1.cmp(&y.1).then(y.0.cmp(&x.0)))
    else {
        return false;
    };
    for l in labels.iter_mut() {
        if *l == r {
            *l = into;
        }
    }
    true
}

/// Makes every boundary loop (vertex ids in order) meet each region in one arc at most — a
/// region met twice is kept on its longest arc, its other arcs given to the region before
/// them along the loop (a lattice row along the boundary zigzags across it) — and gives a
/// loop that meets fewer than three regions three of its own, its vertices split into three
/// arcs: a hole smaller than a lattice cell is kept as a triangle of the cage, not closed.
/// Returns per vertex whether it was given such an arc (its region is then never merged away
/// for being small).
pub(crate) fn keep_loops(labels: &mut [u32], loops: &[Vec<u32>]) -> Vec<bool> {
    let mut protected = vec![false; labels.len()];
    let mut next = labels.iter().copied().max().map_or(0, |m| m + 1);
    for l in loops {
        if l.len() < 3 {
            continue;
        }
        while let Some((start, len, into)) = repeated_arc(labels, l) {
            for k in start..start + len {
                labels[l[k % l.len()] as usize] = into;
            }
        }
        let mut distinct: Vec<u32> = l.iter().map(|&v| labels[v as usize]).collect();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() >= 3 {
            continue;
        }
        for (k, &v) in l.iter().enumerate() {
            labels[v as usize] = next + (3 * k / l.len()) as u32;
            protected[v as usize] = true;
        }
        next += 3;
    }
    protected
}

/// An arc of loop `l` whose region also has a longer arc on the loop: `(start, length, the
/// region before it)`; `None` when every region has one arc.
fn repeated_arc(labels: &[u32], l: &[u32]) -> Option<(usize, usize, u32)> {
    let n = l.len();
    let at = |k: usize| labels[l[k % n] as usize];
    // Start at an arc's beginning (a loop of one region has none).
    let first = (0..n).find(|&k| at(k + n - 1) != at(k))?;
    let mut arcs: Vec<(usize, usize, u32)> = Vec::new();
    let mut k = first;
    while k < first + n {
        let mut j = k + 1;
        while j < first + n && at(j) == at(k) {
            j += 1;
        }
        arcs.push((k, j - k, at(k)));
        k = j;
    }
    let m = arcs.len();
    for (i, &(start, len, label)) in arcs.iter().enumerate() {
        let longest = arcs
            .iter()
            .enumerate()
            .filter(|(_, a)| a.2 == label)
            .max_by_key(|(j, a)| (a.1, std::cmp::Reverse(*j)))
            .map(|(j, _)| j);
        if longest != Some(i) {
            let before = arcs[(i + m - 1) % m].2;
            return Some((start, len, before));
        }
    }
    None
}

/// Merges small and island regions (module step 2) until none is left; regions holding a
/// `protected` vertex are not merged for being small. Returns the count.
pub(crate) fn clean_regions(graph: &Graph, labels: &mut [u32], protected: &[bool]) -> usize {
    loop {
        let count = compact(labels);
        let mut size = vec![0usize; count];
        for &l in labels.iter() {
            size[l as usize] += 1;
        }
        let min = MIN_REGION_SHARE * graph.len() as f64 / count.max(1) as f64;
        let shared = shared_edges(graph, labels, count);
        let mut kept = vec![false; count];
        for (v, &p) in protected.iter().enumerate() {
            if p {
                kept[labels[v] as usize] = true;
            }
        }
        // The smallest offending region first, one a round (merges change the neighbours).
        let worst = (0..count)
            .filter(|&r| ((size[r] as f64) < min && !kept[r]) || shared[r].len() < 3)
            .min_by_key(|&r| (size[r], r));
        match worst {
            Some(r) if count > 4 => {
                if !merge_region(labels, &shared[r], r as u32) {
                    return count;
                }
            }
            _ => return count,
        }
    }
}

/// The dual triangles of `labels` over `tris` (module step 3): repeated ones once; a triangle
/// met in both orientations is dropped (a fold of the partition).
fn dual_triangles(tris: &[[u32; 3]], labels: &[u32]) -> Vec<[u32; 3]> {
    let mut keyed: Vec<([u32; 3], [u32; 3])> = Vec::new();
    for t in tris {
        let l = t.map(|v| labels[v as usize]);
        if l[0] == l[1] || l[1] == l[2] || l[0] == l[2] {
            continue;
        }
        // Rotate so the smallest label is first: the same oriented triangle has one form.
        let k = (0..3).min_by_key(|&k| l[k]).unwrap_or(0);
        let r = [l[k], l[(k + 1) % 3], l[(k + 2) % 3]];
        let mut key = r;
        key.sort_unstable();
        keyed.push((key, r));
    }
    keyed.sort_unstable();
    keyed.dedup();
    let mut out = Vec::new();
    let mut i = 0;
    while i < keyed.len() {
        let mut j = i + 1;
        while j < keyed.len() && keyed[j].0 == keyed[i].0 {
            j += 1;
        }
        if j - i == 1 {
            out.push(keyed[i].1);
        }
        i = j;
    }
    out
}

/// The region a topology error points at: for an edge, the endpoint of fewer mesh vertices
/// (never a ghost, ids from `ghosts` on).
fn culprit(e: &TopologyError, size: &[usize], ghosts: u32) -> Option<u32> {
    let pick = |a: u32, b: u32| {
        if a >= ghosts || b >= ghosts {
            a.min(b)
        } else if size[a as usize] <= size[b as usize] {
            a
        } else {
            b
        }
    };
    match e {
        TopologyError::NonManifoldEdge { a, b, .. } => Some(pick(a.0, b.0)),
        TopologyError::InconsistentOrientation { a, b, .. } => Some(pick(a.0, b.0)),
        TopologyError::NonManifoldVertex { vertex, .. } => Some(vertex.0),
        _ => None,
    }
}

/// Per pair of adjacent regions `(a, b)`, `a < b`: whether the lattice offset between them is
/// a diagonal `(±1, ±1)` by the majority of the mesh edges joining them.
pub(crate) fn diagonal_pairs(
    graph: &Graph,
    offsets: &Offsets,
    labels: &[u32],
) -> std::collections::BTreeSet<(u32, u32)> {
    let mut votes: std::collections::BTreeMap<(u32, u32), (u32, u32)> = Default::default();
    for i in 0..graph.len() {
        for &j in graph.neighbors(i) {
            let (a, b) = (labels[i], labels[j as usize]);
            if a >= b {
                continue;
            }
            let Some(d) = offsets.get(i as u32, j) else {
                continue;
            };
            let e = votes.entry((a, b)).or_default();
            e.1 += 1;
            if d[0].abs() == 1 && d[1].abs() == 1 {
                e.0 += 1;
            }
        }
    }
    votes
        .into_iter()
        .filter(|(_, (diag, all))| 2 * diag > *all)
        .map(|(k, _)| k)
        .collect()
}

/// Triangles of `tri_cage` on either side of a lattice diagonal (`diagonal`, pairs of
/// vertex ids `a < b`) merged into quads, each triangle at most once (in face order).
pub(crate) fn pair_diagonals(
    tri_cage: &PolyMesh,
    diagonal: &std::collections::BTreeSet<(u32, u32)>,
) -> PolyMesh {
    let Ok(he) = HalfEdgeMesh::from_mesh(tri_cage) else {
        return tri_cage.clone();
    };
    let nf = tri_cage.faces.len();
    let mut mate = vec![usize::MAX; nf];
    // Edges left per vertex: no vertex is left with fewer than three (boundary vertices two).
    let mut edges_left = vec![0usize; tri_cage.num_vertices()];
    let mut floor = vec![3usize; tri_cage.num_vertices()];
    for e in 0..he.num_edges() {
        let e = subfit_mesh::EdgeId(e as u32);
        let [a, b] = he.edge_vertices(e);
        edges_left[a.0 as usize] += 1;
        edges_left[b.0 as usize] += 1;
        if he.is_boundary_edge(e) {
            floor[a.0 as usize] = 2;
            floor[b.0 as usize] = 2;
        }
    }
    let mut quads: Vec<Vec<u32>> = Vec::new();
    for f in 0..nf {
        if mate[f] != usize::MAX {
            continue;
        }
        for h in he.face_half_edges(subfit_mesh::FaceId(f as u32)) {
            let (a, b) = (he.origin(h).0, he.dest(h).0);
            if !diagonal.contains(&(a.min(b), a.max(b))) {
                continue;
            }
            let Some(t) = he.twin(h) else { continue };
            let g = he.face(t).0 as usize;
            if mate[g] != usize::MAX || g == f {
                continue;
            }
            if edges_left[a as usize] <= floor[a as usize]
                || edges_left[b as usize] <= floor[b as usize]
            {
                continue;
            }
            edges_left[a as usize] -= 1;
            edges_left[b as usize] -= 1;
            mate[f] = g;
            mate[g] = f;
            // The quad: a, (f's third), b... walking f from b, then g from a.
            let c = he.dest(he.next(h)).0;
            let d = he.dest(he.next(t)).0;
            quads.push(vec![a, d, b, c]);
            break;
        }
    }
    let mut faces = Polygons::new();
    for q in &quads {
        faces.push(q);
    }
    for (f, m) in mate.iter().enumerate() {
        if *m == usize::MAX {
            faces.push(tri_cage.faces.face(subfit_mesh::FaceId(f as u32)));
        }
    }
    PolyMesh::new(tri_cage.positions.clone(), faces)
}

/// The cage of regions `labels` (module steps 3–4): vertices at the mean of their regions'
/// lattice points `p`, triangles from the dual, repaired into a manifold. Each boundary loop
/// of `loops` (vertex ids in order) is closed by a cone to a ghost vertex of its own region
/// while the dual is taken and repaired, and the ghost's triangles are dropped at the end: the
/// hole comes back bounded by the regions along it, in order. Also returns the final labels.
pub(crate) fn dual_cage(
    graph: &Graph,
    tris: &[[u32; 3]],
    p: &[[f64; 3]],
    mut labels: Vec<u32>,
    protected: &[bool],
    loops: &[Vec<u32>],
) -> Result<(PolyMesh, Vec<u32>), ExtractError> {
    let n = graph.len();
    let cones = cone_triangles(tris, loops, n as u32);
    let raw = compact(&mut labels);
    let repairs = (MAX_REPAIR_SHARE * raw as f64).ceil() as usize;
    for _ in 0..=repairs {
        let count = clean_regions(graph, &mut labels, protected);
        if count < 4 {
            return Err(ExtractError::TooFewRegions(count));
        }
        // Ghost k gets region count + k.
        let mut all = labels.clone();
        all.extend((0..loops.len()).map(|k| (count + k) as u32));
        let mut faces = dual_triangles(tris, &all);
        faces.extend(dual_triangles(&cones, &all));
        let total = count + loops.len();
        let poly = Polygons::from_triangles(&faces);
        let mut size = vec![0usize; total];
        for &l in &all {
            size[l as usize] += 1;
        }
        // A region that no dual triangle reaches is an island inside another.
        let mut used = vec![false; total];
        for f in &faces {
            for &v in f {
                used[v as usize] = true;
            }
        }
        let real: Vec<[u32; 3]> = faces
            .iter()
            .filter(|f| f.iter().all(|&v| (v as usize) < count))
            .copied()
            .collect();
        let check = |faces: &Polygons, vertices: usize| match HalfEdgeMesh::new(faces, vertices) {
            Ok(_) => Ok(None),
            Err(e) => match culprit(&e, &size, count as u32) {
                Some(r) => Ok(Some(r)),
                None => Err(ExtractError::NotManifold(e.to_string())),
            },
        };
        let fault = match used.iter().position(|u| !u) {
            Some(r) => Some(r as u32),
            // Closed by the cones, then opened again: both must be manifolds.
            None => match check(&poly, total)? {
                Some(r) => Some(r),
                None => match check(&Polygons::from_triangles(&real), count)? {
                    Some(r) => Some(r),
                    None => folded(graph, p, &labels, &real, &size),
                },
            },
        };
        let Some(r) = fault else {
            let mut sum = vec![[0.0; 3]; count];
            for (v, &l) in labels.iter().enumerate() {
                sum[l as usize] = add(sum[l as usize], p[v]);
            }
            let positions = sum
                .iter()
                .zip(&size)
                .map(|(s, &k)| scale(*s, 1.0 / k as f64))
                .collect();
            return Ok((
                PolyMesh::new(positions, Polygons::from_triangles(&real)),
                labels,
            ));
        };
        if r as usize >= count {
            return Err(ExtractError::NotManifold(
                "a boundary loop's regions do not close around it".into(),
            ));
        }
        let shared = shared_edges(graph, &labels, count);
        if !merge_region(&mut labels, &shared[r as usize], r) {
            return Err(ExtractError::NotManifold(format!(
                "region {r} has no neighbour"
            )));
        }
    }
    Err(ExtractError::NotManifold(format!(
        "still not a manifold after {repairs} merges"
    )))
}

/// The smallest region of a dual triangle that faces against the surface (its normal, from
/// the regions' mean lattice points `p`, opposite to the mean normal of its regions' mesh
/// vertices): a fold of the lattice, which a fit cannot undo.
fn folded(
    graph: &Graph,
    p: &[[f64; 3]],
    labels: &[u32],
    faces: &[[u32; 3]],
    size: &[usize],
) -> Option<u32> {
    let count = faces
        .iter()
        .flatten()
        .map(|&v| v as usize + 1)
        .max()
        .unwrap_or(0);
    let mut at = vec![[0.0; 3]; count];
    let mut normal = vec![[0.0; 3]; count];
    for (v, &l) in labels.iter().enumerate() {
        if (l as usize) < count {
            at[l as usize] = add(at[l as usize], p[v]);
            normal[l as usize] = add(normal[l as usize], graph.normals[v]);
        }
    }
    faces
        .iter()
        .filter(|f| {
            let [a, b, c] = f.map(|r| scale(at[r as usize], 1.0 / size[r as usize].max(1) as f64));
            let n = cross(sub(b, a), sub(c, a));
            let m = f.iter().fold([0.0; 3], |s, &r| add(s, normal[r as usize]));
            dot(n, m) < 0.0
        })
        .flat_map(|f| f.iter().copied())
        .min_by_key(|&r| (size[r as usize], r))
}

/// The cone triangles closing each loop of `loops` to a ghost vertex `first_ghost + k`,
/// oriented like `tris` (a loop edge that a triangle runs `a → b` is run `b → a` by its cone
/// triangle).
fn cone_triangles(tris: &[[u32; 3]], loops: &[Vec<u32>], first_ghost: u32) -> Vec<[u32; 3]> {
    let mut directed: Vec<(u32, u32)> = tris
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .collect();
    directed.sort_unstable();
    let mut out = Vec::new();
    for (k, l) in loops.iter().enumerate() {
        let g = first_ghost + k as u32;
        for i in 0..l.len() {
            let (a, b) = (l[i], l[(i + 1) % l.len()]);
            if directed.binary_search(&(a, b)).is_ok() {
                out.push([g, b, a]);
            } else {
                out.push([g, a, b]);
            }
        }
    }
    out
}
