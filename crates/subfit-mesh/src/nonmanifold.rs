//! Repairs of face lists that are not a surface: faces that repeat a vertex or each other, and
//! edges shared by more than two faces.
//!
//! Meshes from scanners, photogrammetry and mesh tools carry these defects (Botsch et al.,
//! *Polygon Mesh Processing*, 2010, ch. 8, "mesh repair"; Attene et al., "Polygon mesh
//! repairing: an application perspective", ACM Computing Surveys 45(2), 2013, §3): a triangle
//! whose corners collapsed onto one vertex, the same face written twice, a stray triangle
//! ("fin") hanging from an edge of the surface, two parts of a model touching along an edge. The
//! half-edge structure, the subdivision and the fit need an edge-manifold surface; refusing the
//! whole scan for one such face helps nobody. Two repairs, each reporting what it did:
//!
//! * [`clean_faces`]: a vertex repeated in a row is listed once (`a b b c` → `a b c`); a face
//!   left with fewer than three vertices, or repeating one elsewhere (`a b a c`), is dropped; of
//!   faces with the same vertex set (in either orientation) the first is kept.
//! * [`cut_nonmanifold_edges`]: at an edge with more than two faces the faces are paired, best
//!   pair first — faces that traverse the edge in opposite directions (consistently oriented)
//!   before the others, then the pair whose surfaces continue most smoothly across the edge
//!   (normals most nearly aligned, after turning one of an inconsistent pair) — and the pairs
//!   are cut apart: each keeps its own copy of the edge's vertices (found as fans of faces, as
//!   [`crate::split_bowties`] does), so a fin becomes a separate piece and two sheets touching
//!   along an edge become two sheets. A piece the cut took off that is smaller than a hundredth
//!   of the part it hung from ([`FLAP_FRACTION`]) is a flap of debris and is dropped (its
//!   vertices stay, unused). The rare edge whose faces stay joined through their other edges
//!   (the copies would not separate them) keeps its best pair and loses its other faces.
//!
//! Positions are never changed. Cost `O(#H log #H)` for the duplicate search, `O(#H · α)` for
//! the cut.

use std::collections::HashSet;

use crate::edges::{corner_faces, corner_next, group_edges, EdgeGroups};
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
    /// Faces dropped because an earlier face has the same vertices.
    pub duplicates_dropped: usize,
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
    let mut out = Polygons::with_capacity(mesh.faces.len(), mesh.faces.indices().len());
    let mut seen: HashSet<Vec<u32>> = HashSet::with_capacity(mesh.faces.len());
    let mut face: Vec<u32> = Vec::new();
    for (f, src) in mesh.faces.iter().enumerate() {
        face.clear();
        for (i, &v) in src.iter().enumerate() {
            // Cyclically: skip a vertex equal to the one before it.
            let prev = src[(i + src.len() - 1) % src.len()];
            if v != prev || src.len() == 1 {
                face.push(v);
            }
        }
        if face.is_empty() && !src.is_empty() {
            face.push(src[0]);
        }
        let shortened = face.len() < src.len();
        let repeats = (0..face.len()).any(|i| face[i + 1..].contains(&face[i]));
        let mut example = false;
        if face.len() < 3 || repeats {
            report.degenerate_dropped += 1;
            example = true;
        } else {
            let mut key = face.clone();
            key.sort_unstable();
            if seen.insert(key) {
                out.push(&face);
                if shortened {
                    report.faces_shortened += 1;
                    example = true;
                }
            } else {
                report.duplicates_dropped += 1;
                example = true;
            }
        }
        if example && report.examples.len() < MAX_EXAMPLES {
            report.examples.push(f as u32);
        }
    }
    if report.changed() {
        mesh.faces = out;
    }
    report
}

/// What [`cut_nonmanifold_edges`] did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct EdgeCutReport {
    /// Edges that had more than two faces.
    pub edges_cut: usize,
    /// Vertex copies added so that the pairs of faces at those edges come apart.
    pub vertices_added: usize,
    /// Faces of flaps dropped: pieces the cut took off, smaller than `1 / FLAP_FRACTION` of the
    /// part they hung from.
    pub flap_faces_dropped: usize,
    /// Faces dropped at edges the copies could not separate.
    pub faces_dropped: usize,
    /// Up to [`crate::diagnose::MAX_EXAMPLES`] of the cut edges (input vertex ids).
    pub examples: Vec<[u32; 2]>,
}

/// Cuts every edge of `mesh` with more than two faces, as the module docs say; returns what was
/// done. Faces must list every vertex once and be in range ([`clean_faces`] first); others are
/// left alone and do not count. The mesh is unchanged when it has no such edge.
pub fn cut_nonmanifold_edges(mesh: &mut PolyMesh) -> EdgeCutReport {
    let mut report = EdgeCutReport::default();
    let nv = mesh.num_vertices();
    let faces = &mesh.faces;
    let valid = |f: &[u32]| {
        f.len() >= 3
            && f.iter().all(|&v| (v as usize) < nv)
            && (0..f.len()).all(|i| !f[i + 1..].contains(&f[i]))
    };
    let ok: Vec<bool> = faces.iter().map(valid).collect();
    let next = corner_next(faces);
    let groups = group_edges(faces, &next, nv, |f| ok[f]);
    if (0..groups.len()).all(|e| groups.group(e).len() <= 2) {
        return report;
    }
    let normals = face_normals(faces, &mesh.positions);
    let face_of = corner_faces(faces);
    let pairing =
        |faces: &Polygons, groups: &EdgeGroups| pair_up(faces, &next, groups, &face_of, &normals);
    for e in 0..groups.len() {
        let g = groups.group(e);
        if g.len() > 2 {
            report.edges_cut += 1;
            if report.examples.len() < MAX_EXAMPLES {
                let idx = faces.indices();
                let (a, b) = (idx[g[0] as usize], idx[next[g[0] as usize] as usize]);
                report.examples.push([a.min(b), a.max(b)]);
            }
        }
    }
    let before = crate::face_components(&mesh.faces, nv);
    let split = crate::bowtie::split_fans(mesh, |faces, _, groups| pairing(faces, &groups));
    report.vertices_added = split.vertices_added;
    let faces = &mesh.faces;
    let nv = mesh.num_vertices();
    let mut drop = vec![false; faces.len()];
    let mut flap = vec![false; faces.len()];
    // What the copies could not separate: keep each such edge's best pair, drop the rest.
    let next = corner_next(faces);
    let groups = group_edges(faces, &next, nv, |f| ok[f]);
    for e in 0..groups.len() {
        let g = groups.group(e);
        if g.len() > 2 {
            let one = EdgeGroups {
                order: g.to_vec(),
                starts: vec![0, g.len() as u32],
            };
            let keep = pairing(faces, &one).group(0).to_vec();
            for &h in g {
                if !keep.contains(&h) {
                    drop[face_of[h as usize] as usize] = true;
                }
            }
        }
    }
    // Flaps: pieces the cut took off a part, smaller than a hundredth of it.
    let after = crate::face_components(faces, nv);
    let sizes = after.face_counts();
    let whole = before.face_counts();
    for (f, d) in drop.iter().enumerate() {
        let (part, piece) = (before.face_labels[f], after.face_labels[f]);
        if part == u32::MAX || piece == u32::MAX {
            continue;
        }
        let (part, piece) = (part as usize, piece as usize);
        if !*d && sizes[piece] * FLAP_FRACTION < whole[part] {
            flap[f] = true;
        }
    }
    report.faces_dropped = drop.iter().filter(|&&d| d).count();
    report.flap_faces_dropped = flap.iter().filter(|&&d| d).count();
    if report.faces_dropped + report.flap_faces_dropped > 0 {
        let mut out = Polygons::with_capacity(faces.len(), faces.indices().len());
        for (f, face) in faces.iter().enumerate() {
            if !drop[f] && !flap[f] {
                out.push(face);
            }
        }
        mesh.faces = out;
    }
    report
}

/// `groups` with every edge of more than two half-edges split into pairs, best first (see the
/// module docs), and a last single half-edge when the count is odd.
fn pair_up(
    faces: &Polygons,
    next: &[u32],
    groups: &EdgeGroups,
    face_of: &[u32],
    normals: &[[f64; 3]],
) -> EdgeGroups {
    let idx = faces.indices();
    let mut order = Vec::with_capacity(groups.order.len());
    let mut starts = Vec::with_capacity(groups.starts.len());
    for e in 0..groups.len() {
        let g = groups.group(e);
        if g.len() <= 2 {
            starts.push(order.len() as u32);
            order.extend_from_slice(g);
            continue;
        }
        let mut left: Vec<u32> = g.to_vec();
        while left.len() >= 2 {
            let mut best = (f64::NEG_INFINITY, 0, 1);
            for i in 0..left.len() {
                for j in i + 1..left.len() {
                    let (hi, hj) = (left[i] as usize, left[j] as usize);
                    let opposite = idx[hi] == idx[next[hj] as usize];
                    let (ni, nj) = (normals[face_of[hi] as usize], normals[face_of[hj] as usize]);
                    let d = crate::vec3::dot(ni, nj);
                    let score = if opposite { 2.0 + d } else { -d };
                    if score > best.0 {
                        best = (score, i, j);
                    }
                }
            }
            let (_, i, j) = best;
            starts.push(order.len() as u32);
            order.push(left[i]);
            order.push(left[j]);
            left.remove(j);
            left.remove(i);
        }
        for h in left {
            starts.push(order.len() as u32);
            order.push(h);
        }
    }
    starts.push(order.len() as u32);
    EdgeGroups { order, starts }
}

/// Unit normal of every face by Newell's method (zero for a face without area or with an id
/// out of range).
fn face_normals(faces: &Polygons, positions: &[[f64; 3]]) -> Vec<[f64; 3]> {
    faces
        .iter()
        .map(|f| {
            if f.iter().any(|&v| v as usize >= positions.len()) {
                return [0.0; 3];
            }
            crate::vec3::normalize(crate::vec3::polygon_normal(positions, f)).unwrap_or([0.0; 3])
        })
        .collect()
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
        let p = vec![[0.0; 3]; 6];
        let mut faces = Polygons::new();
        for f in [
            &[0, 1, 2][..],
            &[2, 1, 0],    // the first, turned: a duplicate
            &[1, 1, 3, 2], // shortened to 1 3 2
            &[0, 4, 4],    // two vertices left: dropped
            &[0, 4, 0, 5], // repeats 0 apart: dropped
            &[3, 4, 5, 3], // repeats 3 in a row around the end: 4 5 3
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
                examples: vec![1, 2, 3, 4, 5],
            }
        );
        assert_eq!(
            faces_of(&m),
            vec![vec![0, 1, 2], vec![1, 3, 2], vec![4, 5, 3]]
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
        assert_eq!((r.flap_faces_dropped, r.faces_dropped), (1, 0));
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
        assert_eq!((r.edges_cut, r.vertices_added, r.faces_dropped), (1, 2, 0));
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
