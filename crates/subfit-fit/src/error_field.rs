//! Error fields: where a missed maximum error sits, so refinement enriches the whole region
//! rather than one face (Lavoué et al. 2005, §5.2, "principal error field extraction",
//! Fig. 10–11).
//!
//! Lavoué et al. take the sample of largest error and every sample connected to it whose
//! error is above half of that maximum; the faces holding those samples are the error field.
//! Where the field is a plateau (or already holds a control point) they enrich every face of
//! it: the error is a lack of degrees of freedom over the region, which one more point in one
//! face does not supply. Here the samples are summarised per control face (the largest error
//! of its samples, [`FaceError::max`]), fields grow over faces sharing a vertex, and every face
//! above the maximum-error tolerance seeds one (worst first; a face already in a field seeds
//! none). A field's faces score at least `max / (½ · seed max)` ≥ 1 against the tolerance, so
//! refinement splits them all, in order of their own error, and the faces around a field
//! (sharing a vertex with it) score just above 1: Lavoué et al. merge the field's faces and
//! join the new point to all of their neighbours; splitting the ring too gives the new points
//! room to move, where a split field held by unsplit neighbours barely changes shape.
//!
//! Why: a deep concave fold (the corner of a mouth, the root of a horn) leaves data points far
//! from a smooth limit surface. Refinement by the tolerance alone splits the one face whose
//! samples miss by more than the tolerance, the split adds a point the neighbours hold in
//! place, and the next stage splits the same spot again: on the camel head, with an RMS
//! tolerance of 6.5e-4 and a maximum of 7e-3 of the diagonal, five stages each split one face
//! and the data → surface maximum stayed at 1.05 % of the diagonal. With the field alone (four
//! faces) it stayed at 1.01 %; with the field and its ring the fit met its tolerances at 380
//! control points with a Hausdorff distance of 0.68 % (the beetle: 0.64 % → 0.51 %, 218 → 254
//! control points).

use subfit_mesh::Polygons;

use crate::remesh::FaceError;

/// The share of a field's seed error down to which connected faces join it (Lavoué et al.'s
/// `T = d_max / 2`).
pub const FIELD_THRESHOLD: f64 = 0.5;

/// How much of its own error a face of the ring around a field adds to its score of 1: ring
/// faces are split after the field's own when the budget cannot take all.
const RING_SCORE: f64 = 1e-3;

/// One principal error field: its faces (the seed first) and the seed's largest error.
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorField {
    /// The faces of the field, the seed first.
    pub faces: Vec<u32>,
    /// The seed face's largest error (Lavoué et al.'s `d_max`).
    pub seed_max: f64,
}

/// The faces around each vertex (CSR).
pub(crate) struct VertexFaces {
    start: Vec<usize>,
    around: Vec<u32>,
}

impl VertexFaces {
    pub(crate) fn new(faces: &Polygons, num_vertices: usize) -> Self {
        let mut start = vec![0usize; num_vertices + 1];
        for f in faces.iter() {
            for &v in f {
                start[v as usize + 1] += 1;
            }
        }
        for v in 0..num_vertices {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut around = vec![0u32; start[num_vertices]];
        for (fi, f) in faces.iter().enumerate() {
            for &v in f {
                around[fill[v as usize]] = fi as u32;
                fill[v as usize] += 1;
            }
        }
        Self { start, around }
    }

    /// The faces with a corner at `v`.
    pub(crate) fn of(&self, v: u32) -> &[u32] {
        &self.around[self.start[v as usize]..self.start[v as usize + 1]]
    }
}

/// The error fields around the faces whose largest error (`max`, normalized units, one entry
/// per face of `faces` on `num_vertices` vertices) is above `tolerance_max`: worst seed first,
/// each growing over faces that share a vertex with it and whose error is at least
/// [`FIELD_THRESHOLD`] × the seed's; a face already in a field seeds none. The fields are
/// disjoint.
pub fn error_fields(
    faces: &Polygons,
    num_vertices: usize,
    max: &[f64],
    tolerance_max: f64,
) -> Vec<ErrorField> {
    let nf = faces.len();
    if tolerance_max <= 0.0 || nf == 0 {
        return Vec::new();
    }
    let mut seeds: Vec<usize> = (0..nf).filter(|&f| max[f] > tolerance_max).collect();
    if seeds.is_empty() {
        return Vec::new();
    }
    seeds.sort_by(|&a, &b| max[b].total_cmp(&max[a]).then(a.cmp(&b)));
    let around = VertexFaces::new(faces, num_vertices);
    let mut in_field = vec![false; nf];
    let mut stack = Vec::new();
    let mut fields = Vec::new();
    for seed in seeds {
        if in_field[seed] {
            continue;
        }
        let floor = FIELD_THRESHOLD * max[seed];
        let mut field = ErrorField {
            faces: Vec::new(),
            seed_max: max[seed],
        };
        in_field[seed] = true;
        stack.push(seed);
        while let Some(f) = stack.pop() {
            field.faces.push(f as u32);
            for &v in faces.face(subfit_mesh::FaceId(f as u32)) {
                for &g in around.of(v) {
                    let g = g as usize;
                    if !in_field[g] && max[g] >= floor {
                        in_field[g] = true;
                        stack.push(g);
                    }
                }
            }
        }
        fields.push(field);
    }
    fields
}

/// Per face, its score from `fields` (of [`error_fields`] over the same `faces`, `max`):
/// `max_f / (FIELD_THRESHOLD · seed max)` for a face of a field (≥ 1), just above 1 for a
/// face sharing a vertex with one (the ring), 0 for the others.
pub fn scores_of_fields(
    faces: &Polygons,
    num_vertices: usize,
    max: &[f64],
    fields: &[ErrorField],
) -> Vec<f64> {
    let mut score = vec![0.0; faces.len()];
    if fields.is_empty() {
        return score;
    }
    for field in fields {
        let floor = FIELD_THRESHOLD * field.seed_max;
        for &f in &field.faces {
            score[f as usize] = max[f as usize] / floor;
        }
    }
    // The ring around each field: its faces' shape decides whether the field's new points
    // can move where the data is.
    let around = VertexFaces::new(faces, num_vertices);
    for field in fields {
        let floor = FIELD_THRESHOLD * field.seed_max;
        for &f in &field.faces {
            for &v in faces.face(subfit_mesh::FaceId(f)) {
                for &g in around.of(v) {
                    let g = g as usize;
                    if score[g] == 0.0 {
                        score[g] = 1.0 + RING_SCORE * max[g] / floor;
                    }
                }
            }
        }
    }
    score
}

/// Per face, its score from the error fields around the faces whose largest error (`max`,
/// normalized units) is above `tolerance_max` ([`error_fields`], [`scores_of_fields`]).
#[cfg(test)]
pub fn field_scores(
    faces: &Polygons,
    num_vertices: usize,
    max: &[f64],
    tolerance_max: f64,
) -> Vec<f64> {
    let fields = error_fields(faces, num_vertices, max, tolerance_max);
    scores_of_fields(faces, num_vertices, max, &fields)
}

/// Per face, the larger of its surface → data and data → surface maxima.
pub fn two_sided_max(surface: &[FaceError], data: &[FaceError]) -> Vec<f64> {
    surface
        .iter()
        .zip(data)
        .map(|(s, d)| s.max.max(d.max))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip of 10 triangles in a row, face `i` on points `i, i+1, i+2`.
    fn strip() -> Polygons {
        let tris: Vec<[u32; 3]> = (0..10u32)
            .map(|i| {
                if i % 2 == 0 {
                    [i, i + 1, i + 2]
                } else {
                    [i + 1, i, i + 2]
                }
            })
            .collect();
        Polygons::from_triangles(&tris)
    }

    #[test]
    fn a_field_grows_over_connected_faces_above_half_its_maximum_and_takes_its_ring() {
        let faces = strip();
        // Face 4 misses the tolerance 1.0; faces 3, 5, 6 (sharing a point with it) are above
        // half of its 2.0, face 2 is below; faces 1, 2, 7, 8 touch the field (its ring);
        // faces 0 and 9 do not.
        let max = [0.1, 0.1, 0.5, 1.2, 2.0, 1.1, 1.05, 0.2, 0.1, 0.1];
        let s = field_scores(&faces, 12, &max, 1.0);
        assert_eq!(s[4], 2.0);
        for f in [3, 5, 6] {
            assert!((s[f] - max[f]).abs() < 1e-12, "{f}: {s:?}");
        }
        for f in [1, 2, 7, 8] {
            assert!(s[f] > 1.0 && s[f] < 1.01, "{f}: {s:?}");
        }
        assert_eq!((s[0], s[9]), (0.0, 0.0), "{s:?}");
        // The ring comes after the field in the order of refinement.
        assert!(s[2] < s[6]);
    }

    #[test]
    fn no_field_without_a_face_above_the_tolerance() {
        let faces = strip();
        let max = [0.5, 0.9, 0.99, 0.9, 0.5, 0.2, 0.1, 0.1, 0.1, 0.1];
        assert!(field_scores(&faces, 12, &max, 1.0)
            .iter()
            .all(|&x| x == 0.0));
        assert!(field_scores(&faces, 12, &max, 0.0)
            .iter()
            .all(|&x| x == 0.0));
    }
}
