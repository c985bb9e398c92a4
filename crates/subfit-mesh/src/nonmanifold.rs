//! Repairs of face lists that are not a surface: faces that repeat a vertex or each other, and
//! edges shared by more than two faces.
//!
//! Meshes from scanners, photogrammetry and mesh tools carry these defects (Botsch et al.,
//! *Polygon Mesh Processing*, 2010, ch. 8, "mesh repair"; Attene et al., "Polygon mesh
//! repairing: an application perspective", ACM Computing Surveys 45(2), 2013, §3): a triangle
//! whose corners collapsed onto one vertex, the same face written twice, a stray triangle
//! ("fin") hanging from an edge of the surface, two parts of a model touching along an edge, a
//! thin part that a volumetric reconstruction collapsed into a sheet of no thickness, both of
//! whose sides are written as the same triangles turned. The half-edge structure, the
//! subdivision and the fit need an edge-manifold surface; refusing the whole scan for one such
//! face helps nobody. Two repairs, each reporting what it did:
//!
//! * [`clean_faces`]: a vertex repeated in a row is listed once (`a b b c` → `a b c`); a face
//!   left with fewer than three vertices, or repeating one elsewhere (`a b a c`), is dropped; of
//!   faces with the same vertex set in the same turn the first is kept — unless some face of
//!   that set turns the other way: then all are kept, as the sides of a sheet of no thickness,
//!   for the cut to pair each with the surface it continues (dropping one side leaves the
//!   other's neighbours without their partner, and keeping the first copy of each face mixes
//!   the two sides into a surface that cannot be oriented).
//! * [`cut_nonmanifold_edges`]: at an edge with more than two faces the faces are paired so
//!   that the surfaces continue each other with consistent orientations, by their order around
//!   the edge ([`crate::edge_pairs`]), and the pairs are cut apart: each keeps its own copy of
//!   the edge's vertices (found as fans of faces, as [`crate::split_bowties`] does), so a fin
//!   becomes a separate piece and two sheets touching along an edge become two sheets. Where
//!   the copies cannot separate the pairs — the surface passes the edge twice around both of
//!   its ends, as where the two sides of a thin sheet fold into each other at its rim — each
//!   pair after the first gets a vertex of its own at the edge's middle and its two faces are
//!   split there (no face is dropped, no position moves). A piece the cut took off that is
//!   smaller than a hundredth of the part it hung from ([`FLAP_FRACTION`]) is a flap of debris
//!   (a fin, a sheet of no thickness closed on itself) and is dropped (its vertices stay,
//!   unused).
//!
//! Positions are never changed (the only vertices added are copies and edge middles). Cost
//! `O(#H log #H)` for the duplicate search, `O(#H · α)` for the cut plus the pairing
//! ([`crate::edge_pairs`]).

use std::collections::{HashMap, HashSet};

use crate::edge_pairs::pair_up;
use crate::edges::{corner_next, group_edges};
use crate::polygons::{PolyMesh, Polygons};

/// A piece the cut takes off a connected part is dropped as a flap when it has fewer than
/// `1 / FLAP_FRACTION` of the part's faces.
pub const FLAP_FRACTION: usize = 100;

/// Up to this many examples are kept in the reports.
const MAX_EXAMPLES: usize = crate::diagnose::MAX_EXAMPLES;

/// What [`clean_faces`] did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FaceCleanReport {
    /// Faces that listed a vertex twice in a row and were shortened (and kept).
    pub faces_shortened: usize,
    /// Faces dropped because fewer than three distinct vertices were left, or one repeated
    /// elsewhere in the face.
    pub degenerate_dropped: usize,
    /// Faces dropped because an earlier face has the same vertices in the same turn, and no
    /// face of those vertices turns the other way.
    pub duplicates_dropped: usize,
    /// Faces kept although an earlier face has the same vertices, because faces of those
    /// vertices come in both turns: the two sides of a sheet of no thickness (or a part written
    /// twice, once inside out), left for [`cut_nonmanifold_edges`] to pair.
    pub opposite_duplicates_kept: usize,
    /// Up to [`crate::diagnose::MAX_EXAMPLES`] input face ids of each kind of repair, in input
    /// order.
    pub examples: Vec<u32>,
}

impl FaceCleanReport {
    /// Whether any face was changed or dropped.
    pub fn changed(&self) -> bool {
        self.faces_shortened + self.degenerate_dropped + self.duplicates_dropped > 0
    }
}

/// Cleans the faces of `mesh` as the module docs say; returns what was done. Vertices are not
/// touched (a vertex no face uses any more stays, unused). The mesh is unchanged when every face
/// is proper and unique.
pub fn clean_faces(mesh: &mut PolyMesh) -> FaceCleanReport {
    let mut report = FaceCleanReport::default();
    let mut example = vec![false; mesh.faces.len()];
    // Each proper face, shortened, with its vertex set and its turn (see `turn`).
    let mut proper: Vec<Option<Proper>> = Vec::with_capacity(mesh.faces.len());
    for (f, src) in mesh.faces.iter().enumerate() {
        let face = shortened(src);
        let repeats = (0..face.len()).any(|i| face[i + 1..].contains(&face[i]));
        if face.len() < 3 || repeats {
            report.degenerate_dropped += 1;
            example[f] = true;
            proper.push(None);
            continue;
        }
        if face.len() < src.len() {
            report.faces_shortened += 1;
            example[f] = true;
        }
        let mut key = face.clone();
        key.sort_unstable();
        let t = turn(&face);
        proper.push(Some((face, key, t)));
    }
    // Per vertex set: the turns its faces come in (bit 0: false, bit 1: true).
    let mut turns: HashMap<&[u32], u8> = HashMap::with_capacity(proper.len());
    for (_, key, t) in proper.iter().flatten() {
        *turns.entry(key.as_slice()).or_default() |= 1 << u8::from(*t);
    }
    let mut out = Polygons::with_capacity(mesh.faces.len(), mesh.faces.indices().len());
    let mut seen: HashSet<&[u32]> = HashSet::with_capacity(proper.len());
    for (f, p) in proper.iter().enumerate() {
        let Some((face, key, _)) = p else { continue };
        if seen.insert(key.as_slice()) {
            out.push(face);
        } else if turns[key.as_slice()] == 3 {
            // Both sides of a sheet: kept for the cut to pair.
            out.push(face);
            report.opposite_duplicates_kept += 1;
        } else {
            report.duplicates_dropped += 1;
            example[f] = true;
        }
    }
    report.examples = (0..example.len() as u32)
        .filter(|&f| example[f as usize])
        .take(MAX_EXAMPLES)
        .collect();
    if report.changed() {
        mesh.faces = out;
    }
    report
}

/// A proper face of [`clean_faces`]: its vertices (shortened), their sorted set, its turn.
type Proper = (Vec<u32>, Vec<u32>, bool);

/// `src` with a vertex equal to the one before it (cyclically) skipped: `a b b c` → `a b c`.
fn shortened(src: &[u32]) -> Vec<u32> {
    let mut face: Vec<u32> = Vec::with_capacity(src.len());
    for (i, &v) in src.iter().enumerate() {
        let prev = src[(i + src.len() - 1) % src.len()];
        if v != prev || src.len() == 1 {
            face.push(v);
        }
    }
    if face.is_empty() && !src.is_empty() {
        face.push(src[0]);
    }
    face
}

/// Which way `face` turns, comparable between faces of the same vertices: from its smallest
/// vertex, whether the next vertex is smaller than the previous one. A face and its reverse
/// turn opposite ways.
pub(crate) fn turn(face: &[u32]) -> bool {
    let n = face.len();
    let m = (0..n).min_by_key(|&i| face[i]).unwrap_or(0);
    face[(m + 1) % n] < face[(m + n - 1) % n]
}

/// What [`cut_nonmanifold_edges`] did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct EdgeCutReport {
    /// Edges that had more than two faces.
    pub edges_cut: usize,
    /// Vertex copies added so that the pairs of faces at those edges come apart.
    pub vertices_added: usize,
    /// Of the cut edges, those whose pairs the vertex copies could not separate (the surface
    /// passes the edge twice around each end): each pair after the first got a vertex of its
    /// own at the edge's middle, its two faces split there.
    pub edges_split: usize,
    /// Faces of flaps dropped: pieces the cut took off, smaller than `1 / FLAP_FRACTION` of the
    /// part they hung from.
    pub flap_faces_dropped: usize,
    /// Up to [`crate::diagnose::MAX_EXAMPLES`] of the cut edges (input vertex ids).
    pub examples: Vec<[u32; 2]>,
}

/// Cuts every edge of `mesh` with more than two faces, as the module docs say; returns what was
/// done. Faces must list every vertex once and be in range ([`clean_faces`] first); others are
/// left alone and do not count. The mesh is unchanged when it has no such edge.
pub fn cut_nonmanifold_edges(mesh: &mut PolyMesh) -> EdgeCutReport {
    let mut report = EdgeCutReport::default();
    let nv = mesh.num_vertices();
    let valid = |f: &[u32]| {
        f.len() >= 3
            && f.iter().all(|&v| (v as usize) < nv)
            && (0..f.len()).all(|i| !f[i + 1..].contains(&f[i]))
    };
    let ok: Vec<bool> = mesh.faces.iter().map(valid).collect();
    let next = corner_next(&mesh.faces);
    let groups = group_edges(&mesh.faces, &next, nv, |f| ok[f]);
    let idx = mesh.faces.indices();
    for e in 0..groups.len() {
        let g = groups.group(e);
        if g.len() > 2 {
            report.edges_cut += 1;
            if report.examples.len() < MAX_EXAMPLES {
                let (a, b) = (idx[g[0] as usize], idx[next[g[0] as usize] as usize]);
                report.examples.push([a.min(b), a.max(b)]);
            }
        }
    }
    if report.edges_cut == 0 {
        return report;
    }
    let before = crate::face_components(&mesh.faces, nv);
    let pairs = pair_up(&mesh.faces, &mesh.positions, &next, &groups);
    drop(groups);
    // Per half-edge, the pair (or single) it is in.
    let mut pair_of = vec![u32::MAX; idx.len()];
    for p in 0..pairs.len() {
        for &h in pairs.group(p) {
            pair_of[h as usize] = p as u32;
        }
    }
    let split = crate::bowtie::split_fans(mesh, |_, _, _| pairs);
    report.vertices_added = split.vertices_added;
    // Pairs still on one edge: every pair but the first gets a vertex in the middle.
    let next = corner_next(&mesh.faces);
    let groups = group_edges(&mesh.faces, &next, mesh.num_vertices(), |f| ok[f]);
    let mut middle: Vec<(u32, u32)> = Vec::new();
    let mut m = mesh.num_vertices() as u32;
    for e in 0..groups.len() {
        let g = groups.group(e);
        if g.len() <= 2 {
            continue;
        }
        report.edges_split += 1;
        let first = pair_of[g[0] as usize];
        let mut extra: Vec<u32> = g.iter().map(|&h| pair_of[h as usize]).collect();
        extra.retain(|&p| p != first);
        extra.sort_unstable();
        extra.dedup();
        for p in extra {
            middle.extend(
                g.iter()
                    .filter(|&&h| pair_of[h as usize] == p)
                    .map(|&h| (h, m)),
            );
            m += 1;
        }
    }
    drop(groups);
    let origin = split_at_middles(mesh, &middle, &next);
    // Flaps: pieces the cut took off a part, smaller than a hundredth of it.
    let after = crate::face_components(&mesh.faces, mesh.num_vertices());
    let (sizes, whole) = (after.face_counts(), before.face_counts());
    let flap: Vec<bool> = (0..mesh.faces.len())
        .map(|f| {
            let (part, piece) = (before.face_labels[origin[f] as usize], after.face_labels[f]);
            part != u32::MAX
                && piece != u32::MAX
                && sizes[piece as usize] * FLAP_FRACTION < whole[part as usize]
        })
        .collect();
    report.flap_faces_dropped = flap.iter().filter(|&&d| d).count();
    if report.flap_faces_dropped > 0 {
        let mut out = Polygons::with_capacity(mesh.faces.len(), mesh.faces.indices().len());
        for (f, face) in mesh.faces.iter().enumerate() {
            if !flap[f] {
                out.push(face);
            }
        }
        mesh.faces = out;
    }
    report
}

/// Splits faces at new middle vertices: `middle` lists `(half-edge, vertex)`, the vertex (ids
/// from `#V` on, in order, each listed for the half-edges that share it) to be put at the
/// middle of the half-edge (a corner of `mesh.faces`, `next` its [`corner_next`]). A face
/// with middles on its edges loses, after each middle, the corner that follows it, as a
/// triangle of its own (middle, corner, corner after it): no face is left with three vertices
/// in a line. The middle vertices are appended (positions, normals and colours halfway).
/// Returns per face of the result the input face it came from. Cost `O(#H + #middle)`.
fn split_at_middles(mesh: &mut PolyMesh, middle: &[(u32, u32)], next: &[u32]) -> Vec<u32> {
    let nf = mesh.faces.len();
    if middle.is_empty() {
        return (0..nf as u32).collect();
    }
    let idx = mesh.faces.indices();
    let mut at = vec![u32::MAX; idx.len()];
    let mut ends: Vec<(u32, u32)> = Vec::new();
    for &(h, m) in middle {
        at[h as usize] = m;
        if m as usize - mesh.num_vertices() == ends.len() {
            ends.push((idx[h as usize], idx[next[h as usize] as usize]));
        }
    }
    let mut out = Polygons::with_capacity(nf + middle.len(), idx.len() + 3 * middle.len());
    let mut origin = Vec::with_capacity(nf + middle.len());
    let (mut ring, mut marked): (Vec<u32>, Vec<bool>) = (Vec::new(), Vec::new());
    for (f, w) in mesh.faces.offsets().windows(2).enumerate() {
        let (s, e) = (w[0] as usize, w[1] as usize);
        if (s..e).all(|h| at[h] == u32::MAX) {
            out.push(&idx[s..e]);
            origin.push(f as u32);
            continue;
        }
        // The polygon with its middles; a corner right after a middle is marked.
        ring.clear();
        marked.clear();
        for h in s..e {
            let prev = if h == s { e - 1 } else { h - 1 };
            ring.push(idx[h]);
            marked.push(at[prev] != u32::MAX);
            if at[h] != u32::MAX {
                ring.push(at[h]);
                marked.push(false);
            }
        }
        let mut i = 0;
        while i < ring.len() && ring.len() > 3 {
            if marked[i] {
                let k = ring.len();
                let (p, q) = (ring[(i + k - 1) % k], ring[(i + 1) % k]);
                out.push(&[p, ring[i], q]);
                origin.push(f as u32);
                ring.remove(i);
                marked.remove(i);
            } else {
                i += 1;
            }
        }
        out.push(&ring);
        origin.push(f as u32);
    }
    mesh.faces = out;
    let halfway = |a: [f64; 3], b: [f64; 3]| crate::vec3::scale(crate::vec3::add(a, b), 0.5);
    for &(a, b) in &ends {
        let p = halfway(mesh.positions[a as usize], mesh.positions[b as usize]);
        mesh.positions.push(p);
        if let Some(n) = mesh.normals.as_mut() {
            let h = halfway(n[a as usize], n[b as usize]);
            n.push(crate::vec3::normalize(h).unwrap_or(n[a as usize]));
        }
        if let Some(c) = mesh.colors.as_mut() {
            let (x, y) = (c[a as usize], c[b as usize]);
            c.push([0, 1, 2].map(|k| ((u16::from(x[k]) + u16::from(y[k])) / 2) as u8));
        }
    }
    origin
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::diagnose_mesh;
    use crate::shapes::torus_mesh;

    fn faces_of(m: &PolyMesh) -> Vec<Vec<u32>> {
        m.faces.iter().map(<[u32]>::to_vec).collect()
    }

    #[test]
    fn collapsed_and_repeated_faces_are_cleaned() {
        let p = vec![[0.0; 3]; 8];
        let mut faces = Polygons::new();
        for f in [
            &[0, 1, 2][..],
            &[1, 2, 0],    // the first, in the same turn: a duplicate
            &[1, 1, 3, 2], // shortened to 1 3 2
            &[0, 4, 4],    // two vertices left: dropped
            &[0, 4, 0, 5], // repeats 0 apart: dropped
            &[3, 4, 5, 3], // repeats 3 in a row around the end: 4 5 3
            &[5, 6, 7],
            &[7, 6, 5], // the one before, turned: its other side, kept
        ] {
            faces.push(f);
        }
        let mut m = PolyMesh::new(p, faces);
        let r = clean_faces(&mut m);
        assert_eq!(
            r,
            FaceCleanReport {
                faces_shortened: 2,
                degenerate_dropped: 2,
                duplicates_dropped: 1,
                opposite_duplicates_kept: 1,
                examples: vec![1, 2, 3, 4, 5],
            }
        );
        assert_eq!(
            faces_of(&m),
            vec![
                vec![0, 1, 2],
                vec![1, 3, 2],
                vec![4, 5, 3],
                vec![5, 6, 7],
                vec![7, 6, 5]
            ]
        );
        let again = m.clone();
        assert!(!clean_faces(&mut m).changed());
        assert_eq!(m, again);
    }

    /// A torus with a fin: one more triangle on one of its edges, standing out of the surface.
    fn torus_with_fin() -> (PolyMesh, [u32; 2]) {
        let mut m = torus_mesh(1.0, 0.3, 16, 8, true);
        let f = m.faces.iter().nth(5).unwrap().to_vec();
        let (a, b) = (f[0], f[1]);
        let (pa, pb) = (m.positions[a as usize], m.positions[b as usize]);
        m.positions.push([
            (pa[0] + pb[0]) / 2.0,
            (pa[1] + pb[1]) / 2.0,
            (pa[2] + pb[2]) / 2.0 + 0.4,
        ]);
        let c = (m.positions.len() - 1) as u32;
        m.faces.push(&[b, a, c]);
        (m, [a.min(b), a.max(b)])
    }

    #[test]
    fn a_fin_is_cut_off_the_surface() {
        let (mut m, edge) = torus_with_fin();
        let (nv, nf) = (m.num_vertices(), m.num_faces());
        assert_eq!(diagnose_mesh(&m).non_manifold_edges, 1);
        let r = cut_nonmanifold_edges(&mut m);
        assert_eq!(r.edges_cut, 1);
        assert_eq!(r.examples, vec![edge]);
        assert_eq!(r.vertices_added, 2, "{r:?}");
        // The fin came off as a triangle of its own, a flap, and is dropped.
        assert_eq!((r.flap_faces_dropped, r.edges_split), (1, 0));
        assert_eq!((m.num_vertices(), m.num_faces()), (nv + 2, nf - 1));
        let d = diagnose_mesh(&m);
        assert!(d.is_manifold, "{d:?}");
        let torus = torus_mesh(1.0, 0.3, 16, 8, true);
        assert_eq!(faces_of(&m), faces_of(&torus));
    }

    #[test]
    fn two_sheets_on_one_edge_come_apart_as_two_sheets() {
        // Four triangles around the edge 0-1: two flat sheets crossing at right angles.
        let p = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, 1.0, 0.0],
            [0.5, -1.0, 0.0],
            [0.5, 0.0, 1.0],
            [0.5, 0.0, -1.0],
        ];
        let mut faces = Polygons::new();
        for f in [&[0, 1, 2][..], &[0, 4, 1], &[1, 0, 3], &[1, 0, 5]] {
            faces.push(f);
        }
        let mut m = PolyMesh::new(p, faces);
        let r = cut_nonmanifold_edges(&mut m);
        assert_eq!((r.edges_cut, r.vertices_added, r.edges_split), (1, 2, 0));
        assert!(diagnose_mesh(&m).is_manifold);
        // The flat sheet (faces 0 and 2) keeps the edge; the upright one (1 and 3) gets copies.
        let f = faces_of(&m);
        assert_eq!(
            (f[0][..2].to_vec(), f[2][..2].to_vec()),
            (vec![0, 1], vec![1, 0])
        );
        assert_eq!(f[1], vec![6, 4, 7]);
        assert_eq!(f[3][..2].to_vec(), vec![7, 6]);
    }

    #[test]
    fn a_manifold_mesh_is_left_alone() {
        let m = torus_mesh(1.0, 0.3, 12, 8, true);
        let mut out = m.clone();
        assert_eq!(cut_nonmanifold_edges(&mut out), EdgeCutReport::default());
        assert!(!clean_faces(&mut out).changed());
        assert_eq!(out, m);
    }
}
