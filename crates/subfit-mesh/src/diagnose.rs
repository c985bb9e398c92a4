//! Topological diagnostics of an arbitrary polygon soup: counts, boundary, manifoldness,
//! orientation, degenerate and duplicate faces, components, Euler characteristic and genus.
//!
//! Nothing here assumes a manifold input and nothing panics on bad indices. Definitions:
//!
//! * A face is *analysed* when all its vertex ids are in range and it has at least three
//!   vertices, all distinct. Faces that are not analysed (out-of-range, degenerate, repeated
//!   vertex) are counted and then left out of every edge, vertex-fan, component and genus
//!   figure. Zero-area faces (only checked when positions are given) are reported but analysed.
//! * An *edge* is an unordered vertex pair used by a side of an analysed face. It is a
//!   *boundary* edge when one face side uses it, *manifold* when two sides use it in opposite
//!   directions, *inconsistently oriented* when two sides use it in the same direction, and
//!   *non-manifold* when more than two sides use it.
//! * A vertex is *non-manifold* ("bowtie") when the corners of analysed faces at it form more
//!   than one fan, two corners being in the same fan when they share an edge at the vertex.
//!   Vertices on non-manifold edges are not counted here unless they are also bowties.
//! * *Boundary loops* are the connected pieces of the boundary-edge graph in which every vertex
//!   has exactly two boundary edges (simple cycles); other pieces are counted as
//!   `untraced_boundary_components`.
//! * *Components* are sets of analysed faces connected through shared vertices; unreferenced
//!   vertices are counted separately, not as components.
//! * The Euler characteristic uses vertices of analysed faces: `χ = V − E + F`. The genus of a
//!   component is `(2 − χ_c − b_c) / 2` (Euler–Poincaré), reported only for a component with no
//!   non-manifold edge or vertex, no untraced boundary, and consistently orientable faces
//!   (flipped faces are allowed as long as some choice of orientation makes the component
//!   consistent); the total genus is their sum when every component has one.

use crate::components::{components_by, euler_characteristic, genus, Components};
use crate::edges::{corner_faces, corner_next, group_edges, ParityUnionFind, UnionFind};
use crate::halfedge::repeated_vertex;
use crate::polygons::{bounding_box, PolyMesh, Polygons};

/// How many example elements each issue list in [`IssueExamples`] keeps.
pub const MAX_EXAMPLES: usize = 10;

/// A face counts as zero-area when its vector area is at most this fraction of the squared
/// bounding-box diagonal of the positions.
pub const ZERO_AREA_RELATIVE_TOLERANCE: f64 = 1e-14;

/// The topology report of a polygon mesh (see the module docs for definitions).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct MeshReport {
    /// Number of vertices given (`#V`).
    pub num_vertices: usize,
    /// Vertices referenced by at least one in-range face index.
    pub referenced_vertices: usize,
    /// Vertices referenced by no face (`num_vertices − referenced_vertices`).
    pub unreferenced_vertices: usize,
    /// Number of faces (`#F`).
    pub num_faces: usize,
    /// `(polygon size, count)` pairs, sorted by size.
    pub face_sizes: Vec<(usize, usize)>,
    /// Faces with a vertex id `>= num_vertices`.
    pub out_of_range_faces: usize,
    /// Faces with fewer than three distinct vertices.
    pub degenerate_faces: usize,
    /// Faces with three or more distinct vertices of which one is listed twice.
    pub repeated_vertex_faces: usize,
    /// Analysed faces of (near) zero area (see [`ZERO_AREA_RELATIVE_TOLERANCE`]); `None`
    /// without positions.
    pub zero_area_faces: Option<usize>,
    /// Analysed faces whose vertex set equals that of an earlier face.
    pub duplicate_faces: usize,
    /// Faces analysed for edges, fans, components and genus.
    pub analysed_faces: usize,
    /// Vertices used by analysed faces (the `V` of χ).
    pub analysed_vertices: usize,
    /// Undirected edges of analysed faces.
    pub num_edges: usize,
    /// Edges used by exactly one face side.
    pub boundary_edges: usize,
    /// Boundary loops (simple cycles of boundary edges).
    pub boundary_loops: usize,
    /// Connected pieces of the boundary-edge graph that are not simple cycles.
    pub untraced_boundary_components: usize,
    /// Edges used by more than two face sides.
    pub non_manifold_edges: usize,
    /// Edges used by two face sides in the same direction.
    pub inconsistent_edges: usize,
    /// Vertices whose faces form more than one fan.
    pub non_manifold_vertices: usize,
    /// Number of connected components of analysed faces.
    pub num_components: usize,
    /// `χ = V − E + F` over analysed faces.
    pub euler_characteristic: i64,
    /// Total genus, when every component has one.
    pub genus: Option<u32>,
    /// No non-manifold edge or vertex and no untraced boundary.
    pub is_manifold: bool,
    /// No inconsistently oriented (and no non-manifold) edge.
    pub is_consistently_oriented: bool,
    /// No boundary edge.
    pub is_closed: bool,
    /// Per component figures, in order of each component's first face.
    pub components: Vec<ComponentReport>,
    /// A few offending elements of each kind.
    pub examples: IssueExamples,
}

/// Figures of one connected component.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct ComponentReport {
    /// Analysed faces.
    pub faces: usize,
    /// Vertices.
    pub vertices: usize,
    /// Edges.
    pub edges: usize,
    /// Boundary edges.
    pub boundary_edges: usize,
    /// Boundary loops.
    pub boundary_loops: usize,
    /// `χ = V − E + F` of the component.
    pub euler_characteristic: i64,
    /// No non-manifold edge or vertex and no untraced boundary.
    pub manifold: bool,
    /// Whether the faces can be oriented consistently (judged across manifold edges).
    pub orientable: bool,
    /// Genus, when the component is manifold and orientable.
    pub genus: Option<u32>,
}

/// Up to [`MAX_EXAMPLES`] offending elements of each kind, lowest ids first.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct IssueExamples {
    /// Faces with an out-of-range vertex id.
    pub out_of_range_faces: Vec<u32>,
    /// Faces with fewer than three distinct vertices.
    pub degenerate_faces: Vec<u32>,
    /// Faces listing a vertex twice.
    pub repeated_vertex_faces: Vec<u32>,
    /// Zero-area faces.
    pub zero_area_faces: Vec<u32>,
    /// Faces duplicating an earlier face (later id).
    pub duplicate_faces: Vec<u32>,
    /// Non-manifold edges as `(min, max)` vertex pairs.
    pub non_manifold_edges: Vec<[u32; 2]>,
    /// Inconsistently oriented edges as `(min, max)` vertex pairs.
    pub inconsistent_edges: Vec<[u32; 2]>,
    /// Non-manifold vertices.
    pub non_manifold_vertices: Vec<u32>,
}

fn push_example<T>(list: &mut Vec<T>, x: T) {
    if list.len() < MAX_EXAMPLES {
        list.push(x);
    }
}

/// Diagnoses a [`PolyMesh`] (with its positions, so zero-area faces are checked).
pub fn diagnose_mesh(mesh: &PolyMesh) -> MeshReport {
    diagnose(&mesh.faces, mesh.num_vertices(), Some(&mesh.positions))
}

/// Diagnoses `faces` over `num_vertices` vertices; `positions` (`#V by 3`, any units), when
/// given, enables the zero-area check (faces with a vertex beyond `positions.len()` are skipped
/// by that check).
///
/// Never panics on bad input. Cost: `O(#V + #H)` time up to small sorts (per smaller-endpoint
/// edge bucket and per hash run of duplicate candidates) plus an `O(#F log #F)` sort of face
/// hashes; about 40 bytes per half-edge of scratch memory.
pub fn diagnose(
    faces: &Polygons,
    num_vertices: usize,
    positions: Option<&[[f64; 3]]>,
) -> MeshReport {
    let mut r = MeshReport {
        num_vertices,
        num_faces: faces.len(),
        face_sizes: faces.size_histogram(),
        ..Default::default()
    };
    let analysed = classify_faces(faces, num_vertices, &mut r);
    let next = corner_next(faces);
    let groups = group_edges(faces, &next, num_vertices, |f| analysed[f]);
    let idx = faces.indices();
    let corner_face = corner_faces(faces);

    // Edges: classify; `mate` pairs the two half-edges of each two-sided edge.
    let mut mate = vec![u32::MAX; idx.len()];
    let mut boundary_degree = vec![0u32; num_vertices];
    let mut bad_edge = vec![false; groups.len()];
    r.num_edges = groups.len();
    for (e, bad) in bad_edge.iter_mut().enumerate() {
        let g = groups.group(e);
        let h0 = g[0] as usize;
        let (a, b) = (idx[h0], idx[next[h0] as usize]);
        let key = [a.min(b), a.max(b)];
        match g.len() {
            1 => {
                r.boundary_edges += 1;
                boundary_degree[a as usize] += 1;
                boundary_degree[b as usize] += 1;
            }
            2 => {
                let h1 = g[1] as usize;
                mate[h0] = h1 as u32;
                mate[h1] = h0 as u32;
                if idx[h1] == a {
                    r.inconsistent_edges += 1;
                    push_example(&mut r.examples.inconsistent_edges, key);
                }
            }
            _ => {
                r.non_manifold_edges += 1;
                *bad = true;
                push_example(&mut r.examples.non_manifold_edges, key);
            }
        }
    }
    // Orientability: only in doubt when some edge is inconsistently oriented (otherwise the
    // given orientation is a consistent one).
    let non_orientable_faces = if r.inconsistent_edges > 0 {
        non_orientable_faces(&groups, idx, &corner_face, faces.len())
    } else {
        Vec::new()
    };

    // Non-manifold vertices: more than one fan of corners.
    let fan_count = if r.non_manifold_edges == 0 {
        fans_by_walking(faces, &analysed, &next, &mate, num_vertices)
    } else {
        fans_by_union_find(faces, &analysed, &groups, &next, num_vertices)
    };
    let mut vertex_bad = vec![false; num_vertices];
    for (v, &n) in fan_count.iter().enumerate() {
        if n > 1 {
            r.non_manifold_vertices += 1;
            vertex_bad[v] = true;
            push_example(&mut r.examples.non_manifold_vertices, v as u32);
        }
    }

    let comps = components_by(num_vertices, faces.len(), |f| {
        let s = if analysed[f] {
            faces.face(crate::FaceId(f as u32))
        } else {
            &[]
        };
        s.iter().copied()
    });
    let loops = boundary_loops(&groups, idx, &next, &boundary_degree, &comps, &mut r);
    summarize_components(
        &comps,
        &groups,
        idx,
        &bad_edge,
        &vertex_bad,
        &loops,
        &non_orientable_faces,
        &mut r,
    );
    if let Some(p) = positions {
        count_zero_area(faces, &analysed, p, &mut r);
    }
    count_duplicates(faces, &analysed, &mut r);
    r
}

/// Faces where the parity union-find over two-sided edges finds an odd cycle (one face per
/// contradiction). Cost `O(#E · α)`.
fn non_orientable_faces(
    groups: &crate::edges::EdgeGroups,
    idx: &[u32],
    corner_face: &[u32],
    nf: usize,
) -> Vec<u32> {
    let mut parity = ParityUnionFind::new(nf);
    let mut out = Vec::new();
    for e in 0..groups.len() {
        if let &[h0, h1] = groups.group(e) {
            let same = idx[h0 as usize] == idx[h1 as usize];
            let (f0, f1) = (corner_face[h0 as usize], corner_face[h1 as usize]);
            if !parity.relate(f0, f1, u8::from(same)) {
                out.push(f0);
            }
        }
    }
    out
}

/// Number of fans at each vertex (`#V` entries) when no edge has more than two sides: the
/// corners at a vertex and the two-sided edges between them form paths and cycles, walked
/// once each (orientation-agnostic). Cost `O(#H)`.
fn fans_by_walking(
    faces: &Polygons,
    analysed: &[bool],
    next: &[u32],
    mate: &[u32],
    num_vertices: usize,
) -> Vec<u32> {
    let idx = faces.indices();
    let mut prev = vec![0u32; idx.len()];
    for (h, &n) in next.iter().enumerate() {
        prev[n as usize] = h as u32;
    }
    let mut visited = vec![false; idx.len()];
    let mut fan_count = vec![0u32; num_vertices];
    // From the corner at `v` reached through half-edge `m`, the corner and its other edge.
    let step = |m: u32, v: u32| {
        if idx[m as usize] == v {
            (m, prev[m as usize])
        } else {
            (next[m as usize], next[m as usize])
        }
    };
    for (f, w) in faces.offsets().windows(2).enumerate() {
        if !analysed[f] {
            continue;
        }
        for c in w[0]..w[1] {
            if visited[c as usize] {
                continue;
            }
            visited[c as usize] = true;
            let v = idx[c as usize];
            fan_count[v as usize] += 1;
            // Leave through the outgoing side, then (if the fan is open) the incoming side.
            'sides: for mut exit in [c, prev[c as usize]] {
                loop {
                    let m = mate[exit as usize];
                    if m == u32::MAX {
                        break;
                    }
                    let (corner, other) = step(m, v);
                    if corner == c {
                        break 'sides;
                    }
                    if visited[corner as usize] {
                        break;
                    }
                    visited[corner as usize] = true;
                    exit = other;
                }
            }
        }
    }
    fan_count
}

/// Number of fans at each vertex (`#V` entries) for any soup: a union-find over corners, two
/// corners at a vertex joined when their faces share an edge at it (through any number of
/// sides). Cost `O(#H · α)`.
fn fans_by_union_find(
    faces: &Polygons,
    analysed: &[bool],
    groups: &crate::edges::EdgeGroups,
    next: &[u32],
    num_vertices: usize,
) -> Vec<u32> {
    let idx = faces.indices();
    let mut fans = crate::edges::corner_fans(faces, groups, next);
    let mut fan_count = vec![0u32; num_vertices];
    for (f, w) in faces.offsets().windows(2).enumerate() {
        if analysed[f] {
            for c in w[0]..w[1] {
                if fans.find(c) == c {
                    fan_count[idx[c as usize] as usize] += 1;
                }
            }
        }
    }
    fan_count
}

/// Per face whether it is analysed; fills the face-level counts.
fn classify_faces(faces: &Polygons, num_vertices: usize, r: &mut MeshReport) -> Vec<bool> {
    let mut referenced = vec![false; num_vertices];
    let mut analysed = vec![false; faces.len()];
    let mut scratch = Vec::new();
    for (f, poly) in faces.iter().enumerate() {
        let mut in_range = true;
        for &v in poly {
            match referenced.get_mut(v as usize) {
                Some(x) => *x = true,
                None => in_range = false,
            }
        }
        let f32 = f as u32;
        if !in_range {
            r.out_of_range_faces += 1;
            push_example(&mut r.examples.out_of_range_faces, f32);
        } else if repeated_vertex(poly, &mut scratch).is_some() || poly.len() < 3 {
            scratch.clear();
            scratch.extend_from_slice(poly);
            scratch.sort_unstable();
            scratch.dedup();
            if scratch.len() < 3 {
                r.degenerate_faces += 1;
                push_example(&mut r.examples.degenerate_faces, f32);
            } else {
                r.repeated_vertex_faces += 1;
                push_example(&mut r.examples.repeated_vertex_faces, f32);
            }
        } else {
            analysed[f] = true;
            r.analysed_faces += 1;
        }
    }
    r.referenced_vertices = referenced.iter().filter(|&&x| x).count();
    r.unreferenced_vertices = num_vertices - r.referenced_vertices;
    analysed
}

/// Counts boundary loops (per component too); returns per component the loop count.
fn boundary_loops(
    groups: &crate::edges::EdgeGroups,
    idx: &[u32],
    next: &[u32],
    boundary_degree: &[u32],
    comps: &Components,
    r: &mut MeshReport,
) -> Vec<(usize, bool)> {
    let nv = boundary_degree.len();
    let mut uf = UnionFind::new(nv);
    for e in 0..groups.len() {
        let g = groups.group(e);
        if g.len() == 1 {
            let h = g[0] as usize;
            uf.union(idx[h], idx[next[h] as usize]);
        }
    }
    // Per boundary root: whether every vertex has boundary degree 2.
    let mut state = vec![0u8; nv]; // 0 none, 1 simple so far, 2 not simple
    for (v, &deg) in boundary_degree.iter().enumerate() {
        if deg > 0 {
            let root = uf.find(v as u32) as usize;
            let simple = deg == 2;
            state[root] = match (state[root], simple) {
                (0 | 1, true) => 1,
                _ => 2,
            };
        }
    }
    // Per component: (loop count, has untraced boundary).
    let mut per_comp = vec![(0usize, false); comps.count];
    for (v, &s) in state.iter().enumerate() {
        let l = comps.vertex_labels[v];
        match s {
            1 => {
                r.boundary_loops += 1;
                per_comp[l as usize].0 += 1;
            }
            2 => {
                r.untraced_boundary_components += 1;
                per_comp[l as usize].1 = true;
            }
            _ => {}
        }
    }
    per_comp
}

/// Fills per-component figures, χ, genus and the global flags.
#[allow(clippy::too_many_arguments)]
fn summarize_components(
    comps: &Components,
    groups: &crate::edges::EdgeGroups,
    idx: &[u32],
    bad_edge: &[bool],
    vertex_bad: &[bool],
    loops: &[(usize, bool)],
    non_orientable_faces: &[u32],
    r: &mut MeshReport,
) {
    let mut cs = vec![ComponentReport::default(); comps.count];
    let mut manifold = vec![true; comps.count];
    for (v, &l) in comps.vertex_labels.iter().enumerate() {
        if l != u32::MAX {
            cs[l as usize].vertices += 1;
            r.analysed_vertices += 1;
            manifold[l as usize] &= !vertex_bad[v];
        }
    }
    for &l in &comps.face_labels {
        if l != u32::MAX {
            cs[l as usize].faces += 1;
        }
    }
    for (e, &bad) in bad_edge.iter().enumerate() {
        let g = groups.group(e);
        let l = comps.vertex_labels[idx[g[0] as usize] as usize] as usize;
        cs[l].edges += 1;
        cs[l].boundary_edges += usize::from(g.len() == 1);
        manifold[l] &= !bad;
    }
    let mut orientable = vec![true; comps.count];
    for &f in non_orientable_faces {
        orientable[comps.face_labels[f as usize] as usize] = false;
    }
    let mut total_genus = Some(0u32);
    for (c, rep) in cs.iter_mut().enumerate() {
        rep.boundary_loops = loops[c].0;
        rep.manifold = manifold[c] && !loops[c].1;
        rep.orientable = orientable[c];
        rep.euler_characteristic = euler_characteristic(rep.vertices, rep.edges, rep.faces);
        rep.genus = if rep.manifold && rep.orientable {
            genus(rep.euler_characteristic, 1, rep.boundary_loops)
        } else {
            None
        };
        total_genus = total_genus.zip(rep.genus).map(|(a, b)| a + b);
    }
    r.num_components = comps.count;
    r.euler_characteristic =
        euler_characteristic(r.analysed_vertices, r.num_edges, r.analysed_faces);
    r.genus = total_genus;
    r.is_manifold = r.non_manifold_edges == 0
        && r.non_manifold_vertices == 0
        && r.untraced_boundary_components == 0;
    r.is_consistently_oriented = r.inconsistent_edges == 0 && r.non_manifold_edges == 0;
    r.is_closed = r.boundary_edges == 0;
    r.components = cs;
}

/// Counts analysed faces with (near) zero vector area (Newell's formula).
fn count_zero_area(faces: &Polygons, analysed: &[bool], p: &[[f64; 3]], r: &mut MeshReport) {
    let diag2 = bounding_box(p).map_or(0.0, |(lo, hi)| {
        (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>()
    });
    let tol = ZERO_AREA_RELATIVE_TOLERANCE * diag2;
    let mut count = 0;
    for (f, poly) in faces.iter().enumerate() {
        if !analysed[f] || poly.iter().any(|&v| v as usize >= p.len()) {
            continue;
        }
        let o = p[poly[0] as usize];
        let mut n = [0.0f64; 3];
        for i in 1..poly.len() - 1 {
            let a = p[poly[i] as usize];
            let b = p[poly[i + 1] as usize];
            let u = [a[0] - o[0], a[1] - o[1], a[2] - o[2]];
            let w = [b[0] - o[0], b[1] - o[1], b[2] - o[2]];
            n[0] += u[1] * w[2] - u[2] * w[1];
            n[1] += u[2] * w[0] - u[0] * w[2];
            n[2] += u[0] * w[1] - u[1] * w[0];
        }
        let area = 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if area <= tol || !area.is_finite() {
            count += 1;
            push_example(&mut r.examples.zero_area_faces, f as u32);
        }
    }
    r.zero_area_faces = Some(count);
}

/// Counts analysed faces whose sorted vertex list equals an earlier face's.
fn count_duplicates(faces: &Polygons, analysed: &[bool], r: &mut MeshReport) {
    let offs = faces.offsets();
    // Sorted copy of every analysed face, hashed.
    let mut sorted = faces.indices().to_vec();
    let mut keyed: Vec<(u64, u32)> = Vec::with_capacity(r.analysed_faces);
    for (f, w) in offs.windows(2).enumerate() {
        if !analysed[f] {
            continue;
        }
        let s = &mut sorted[w[0] as usize..w[1] as usize];
        s.sort_unstable();
        let mut hash = 0x9e37_79b9_7f4a_7c15u64 ^ s.len() as u64;
        for &v in s.iter() {
            hash = (hash ^ u64::from(v)).wrapping_mul(0x0000_0100_0000_01b3);
            hash ^= hash >> 29;
        }
        keyed.push((hash, f as u32));
    }
    keyed.sort_unstable();
    let face = |f: u32| &sorted[offs[f as usize] as usize..offs[f as usize + 1] as usize];
    let mut dups = Vec::new();
    let mut i = 0;
    while i < keyed.len() {
        let mut j = i + 1;
        while j < keyed.len() && keyed[j].0 == keyed[i].0 {
            j += 1;
        }
        // Within one hash run (faces ascending), a face is a duplicate if an earlier one matches.
        for k in i + 1..j {
            if keyed[i..k]
                .iter()
                .any(|&(_, g)| face(g) == face(keyed[k].1))
            {
                dups.push(keyed[k].1);
            }
        }
        i = j;
    }
    dups.sort_unstable();
    r.duplicate_faces = dups.len();
    r.examples.duplicate_faces = dups.into_iter().take(MAX_EXAMPLES).collect();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edges::{corner_next, group_edges};

    /// The fan walk and the corner union-find agree on soups without non-manifold edges.
    #[test]
    fn fan_walk_matches_union_find() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = |n: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % n) as u32
        };
        let mut compared = 0;
        for _ in 0..3000 {
            let nv = 3 + rnd(6) as usize;
            let mut p = Polygons::new();
            for _ in 0..1 + rnd(8) {
                let k = 3 + rnd(2);
                let f: Vec<u32> = (0..k).map(|_| rnd(nv as u64)).collect();
                p.push(&f);
            }
            let mut scratch = Vec::new();
            let analysed: Vec<bool> = p
                .iter()
                .map(|f| repeated_vertex(f, &mut scratch).is_none())
                .collect();
            let next = corner_next(&p);
            let groups = group_edges(&p, &next, nv, |f| analysed[f]);
            if (0..groups.len()).any(|e| groups.group(e).len() > 2) {
                continue;
            }
            let mut mate = vec![u32::MAX; p.indices().len()];
            for e in 0..groups.len() {
                if let &[a, b] = groups.group(e) {
                    mate[a as usize] = b;
                    mate[b as usize] = a;
                }
            }
            let walk = fans_by_walking(&p, &analysed, &next, &mate, nv);
            let uf = fans_by_union_find(&p, &analysed, &groups, &next, nv);
            assert_eq!(walk, uf, "{p:?}");
            compared += 1;
        }
        assert!(compared > 500);
    }
}
