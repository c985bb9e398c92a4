//! Consistent face orientation of a manifold polygon soup: faces are re-oriented per connected
//! component so that every interior edge is traversed once in each direction.
//!
//! The method is the breadth-first propagation across manifold edges of mesh repair (Botsch et
//! al., *Polygon Mesh Processing*, 2010, ch. 8, on orientation artifacts): two faces sharing an
//! edge agree when they traverse it in opposite directions, so each edge fixes the *relative*
//! orientation of its two faces, and a breadth-first search from any face of a component
//! decides every other face of it. The component's *global*
//! orientation is then chosen:
//!
//! * a component that is already consistent is left as it is (never flipped as a whole);
//! * otherwise, when positions are given and the component is closed, the orientation whose
//!   signed volume (divergence theorem over the fan triangles) is positive — outward — unless
//!   the volume is not decisive (below [`VOLUME_DECISIVE`] of the sum of the absolute terms,
//!   e.g. a flat double sheet);
//! * otherwise the orientation of the majority of its faces (ties: that of its lowest face).
//!
//! Components are the classes of faces connected through manifold edges (faces meeting only at
//! a vertex are oriented independently). What cannot be repaired is refused: an edge used by
//! more than two face sides ([`ReorientError::NonManifoldEdge`]) and a non-orientable component
//! such as a Möbius strip, where the propagation meets a face from two sides with opposite
//! demands ([`ReorientError::NonOrientable`]). Non-manifold vertices are not this module's
//! concern (their faces are oriented like any others; [`crate::HalfEdgeMesh::new`] still
//! refuses them).
//!
//! Caveat: a closed component nested inside another (the inner wall of a hollow shell) should
//! face inward; if it is inconsistent, the volume rule turns it outward.

use crate::edges::{corner_faces, corner_next, group_edges};
use crate::halfedge::{validate_faces, TopologyError};
use crate::ids::{FaceId, VertexId};
use crate::polygons::Polygons;

/// The signed volume decides a component's orientation when `|V| ≥ this · Σ|V_t|` over its
/// fan triangles `t` (relative to the component's centroid).
pub const VOLUME_DECISIVE: f64 = 1e-6;

/// What [`reorient_faces`] did.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct ReorientReport {
    /// Faces whose vertex order was reversed.
    pub flipped_faces: usize,
    /// Connected components (faces connected through manifold edges).
    pub components: usize,
    /// Components in which at least one face was flipped.
    pub repaired_components: usize,
    /// Of those, the ones whose orientation the signed volume decided (the others: the
    /// majority of their faces).
    pub decided_by_volume: usize,
    /// Edges of the input traversed twice in the same direction.
    pub inconsistent_edges: usize,
    /// Whether anything was flipped (`false`: the input was already consistent).
    pub needed: bool,
}

/// Why faces cannot be oriented consistently.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ReorientError {
    /// A face is malformed (fewer than 3 vertices, a vertex out of range or listed twice).
    #[error("{0}")]
    Invalid(TopologyError),
    /// More than two face sides use an edge: there is no consistent orientation across it.
    #[error("edge {a}-{b} is shared by {count} faces (non-manifold edge), e.g. faces {f0} and {f1}; faces cannot be oriented consistently across it")]
    NonManifoldEdge {
        /// Smaller endpoint.
        a: VertexId,
        /// Larger endpoint.
        b: VertexId,
        /// Number of face sides using the edge.
        count: usize,
        /// One face using it.
        f0: FaceId,
        /// Another face using it.
        f1: FaceId,
    },
    /// A component is not orientable (e.g. a Möbius strip): walking across its edges from
    /// `face` leads back to `face` reversed.
    #[error("the faces around face {face} cannot be oriented consistently (a non-orientable surface, such as a Möbius strip)")]
    NonOrientable {
        /// A face where the contradiction was found.
        face: FaceId,
    },
}

/// Re-orients `faces` (over `num_vertices` vertices) consistently per connected component (see
/// the module doc). `positions` (`#V by 3`, optional) let closed components take the outward
/// orientation. A flipped face keeps its first vertex: `[v0, v1, …, vk]` becomes
/// `[v0, vk, …, v1]`. Returns the faces (a copy of the input when nothing was flipped) and a
/// report.
///
/// Errors: [`ReorientError::Invalid`] for a malformed face, [`ReorientError::NonManifoldEdge`]
/// naming the first such edge in `(min, max)` vertex order, [`ReorientError::NonOrientable`].
/// Cost: `O(#V + #H)` (the edge grouping of [`crate::HalfEdgeMesh::new`] and one
/// breadth-first search), plus `O(#H)` for the volumes.
pub fn reorient_faces(
    faces: &Polygons,
    num_vertices: usize,
    positions: Option<&[[f64; 3]]>,
) -> Result<(Polygons, ReorientReport), ReorientError> {
    validate_faces(faces, num_vertices).map_err(ReorientError::Invalid)?;
    let nf = faces.len();
    let idx = faces.indices();
    let next = corner_next(faces);
    let face_of = corner_faces(faces);
    let groups = group_edges(faces, &next, num_vertices, |_| true);
    let mut report = ReorientReport::default();

    // Face adjacency across manifold edges: (neighbour, must differ in parity).
    let mut degree = vec![0u32; nf + 1];
    let mut pairs: Vec<(u32, u32, bool)> = Vec::with_capacity(groups.len());
    for e in 0..groups.len() {
        let g = groups.group(e);
        match g.len() {
            1 => {}
            2 => {
                let (h0, h1) = (g[0] as usize, g[1] as usize);
                let same_direction = idx[h0] == idx[h1];
                report.inconsistent_edges += usize::from(same_direction);
                let (f0, f1) = (face_of[h0], face_of[h1]);
                pairs.push((f0, f1, same_direction));
                degree[f0 as usize + 1] += 1;
                degree[f1 as usize + 1] += 1;
            }
            count => {
                let (h0, h1) = (g[0] as usize, g[1] as usize);
                let (a, b) = (idx[h0], idx[next[h0] as usize]);
                return Err(ReorientError::NonManifoldEdge {
                    a: VertexId(a.min(b)),
                    b: VertexId(a.max(b)),
                    count,
                    f0: FaceId(face_of[h0]),
                    f1: FaceId(face_of[h1]),
                });
            }
        }
    }
    let boundary_faces: Vec<u32> = (0..groups.len())
        .filter(|&e| groups.group(e).len() == 1)
        .map(|e| face_of[groups.group(e)[0] as usize])
        .collect();
    drop(groups);
    for f in 0..nf {
        degree[f + 1] += degree[f];
    }
    let mut fill = degree.clone();
    let mut adj = vec![(0u32, false); degree[nf] as usize];
    for &(f0, f1, differ) in &pairs {
        adj[fill[f0 as usize] as usize] = (f1, differ);
        fill[f0 as usize] += 1;
        adj[fill[f1 as usize] as usize] = (f0, differ);
        fill[f1 as usize] += 1;
    }
    drop((pairs, fill));

    // Breadth-first search per component: parity relative to the component's lowest face.
    const UNSEEN: u8 = 2;
    let mut parity = vec![UNSEEN; nf];
    let mut component = vec![u32::MAX; nf];
    let mut members: Vec<Vec<u32>> = Vec::new();
    let mut queue = std::collections::VecDeque::new();
    for seed in 0..nf {
        if parity[seed] != UNSEEN {
            continue;
        }
        let c = members.len() as u32;
        let mut list = vec![seed as u32];
        parity[seed] = 0;
        component[seed] = c;
        queue.push_back(seed as u32);
        while let Some(f) = queue.pop_front() {
            let pf = parity[f as usize];
            for &(g, differ) in &adj[degree[f as usize] as usize..degree[f as usize + 1] as usize] {
                let want = pf ^ u8::from(differ);
                match parity[g as usize] {
                    UNSEEN => {
                        parity[g as usize] = want;
                        component[g as usize] = c;
                        list.push(g);
                        queue.push_back(g);
                    }
                    p if p != want => {
                        return Err(ReorientError::NonOrientable { face: FaceId(g) });
                    }
                    _ => {}
                }
            }
        }
        members.push(list);
    }
    report.components = members.len();
    let mut closed = vec![true; members.len()];
    for &f in &boundary_faces {
        closed[component[f as usize] as usize] = false;
    }

    // Global orientation per component; `flip[f]` is the final decision.
    let mut flip = vec![false; nf];
    for (c, list) in members.iter().enumerate() {
        let odd = list.iter().filter(|&&f| parity[f as usize] == 1).count();
        if odd == 0 {
            continue; // already consistent
        }
        let by_volume = match positions {
            Some(p) if closed[c] => signed_volume(faces, list, &parity, p),
            _ => None,
        };
        // Invert the parities when the volume says so, or when most faces have parity 1.
        let invert = match by_volume {
            Some(v) => v < 0.0,
            None => odd > list.len() - odd,
        };
        report.decided_by_volume += usize::from(by_volume.is_some());
        report.repaired_components += 1;
        for &f in list {
            flip[f as usize] = (parity[f as usize] == 1) != invert;
        }
    }
    report.flipped_faces = flip.iter().filter(|&&f| f).count();
    report.needed = report.flipped_faces > 0;

    let mut out = Polygons::with_capacity(nf, idx.len());
    let mut buf = Vec::new();
    for (f, poly) in faces.iter().enumerate() {
        if flip[f] {
            buf.clear();
            buf.push(poly[0]);
            buf.extend(poly[1..].iter().rev());
            out.push(&buf);
        } else {
            out.push(poly);
        }
    }
    Ok((out, report))
}

/// Signed volume of the faces `list` with their parity-1 faces reversed, relative to their
/// centroid (fan triangles); `None` when it is not decisive (see [`VOLUME_DECISIVE`]) or a
/// position is missing or not finite.
fn signed_volume(
    faces: &Polygons,
    list: &[u32],
    parity: &[u8],
    positions: &[[f64; 3]],
) -> Option<f64> {
    let at = |v: u32| positions.get(v as usize).copied();
    let (mut c, mut n) = ([0.0; 3], 0usize);
    for &f in list {
        for &v in faces.face(FaceId(f)) {
            let p = at(v)?;
            for k in 0..3 {
                c[k] += p[k];
            }
            n += 1;
        }
    }
    let c = c.map(|x| x / n.max(1) as f64);
    let rel = |v: u32| at(v).map(|p| [p[0] - c[0], p[1] - c[1], p[2] - c[2]]);
    let (mut vol, mut abs) = (0.0, 0.0);
    for &f in list {
        let poly = faces.face(FaceId(f));
        let a = rel(poly[0])?;
        for w in poly[1..].windows(2) {
            let (b, d) = (rel(w[0])?, rel(w[1])?);
            let t = a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0])
                + a[2] * (b[0] * d[1] - b[1] * d[0]);
            vol += if parity[f as usize] == 1 { -t } else { t };
            abs += t.abs();
        }
    }
    (vol.is_finite() && vol.abs() >= VOLUME_DECISIVE * abs && abs > 0.0).then_some(vol)
}
