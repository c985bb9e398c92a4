//! Local enrichment: one control point for a local error field (Lavoué et al. 2005, §5.2,
//! case 1).
//!
//! Lavoué et al. extract the principal error field (the sample of largest error `d_max` and
//! the samples connected to it with an error above `d_max / 2`; here [`crate::error_field`],
//! over control faces) and tell two cases apart by the share of the field's error points
//! whose error is close to `d_max` (at least `0.8 · d_max`):
//!
//! 1. below 50 %, the error is a Gaussian-like peak, a **local** error: the topology there is
//!    not right, so the faces the field touches are merged into one and **one** control point
//!    is added in it, joined to the merged face's corners;
//! 2. otherwise the field is a plateau, a lack of degrees of freedom over the region, and every
//!    face of it is enriched (the face splits of [`crate::stage_refine`]). So is a field that
//!    already holds a control point: one more point would not bring enough freedom.
//!
//! Both thresholds are options ([`crate::StageOptions::local_field_peak`],
//! [`crate::StageOptions::local_field_share`]). Here the error points are the level-`l`
//! sub-faces of the control faces (their largest corner error, surface → data) and the data
//! points (their distance to the limit surface, data → surface), each counted in the control
//! face it falls in. A field is merged only when its faces form a disc with no control point
//! inside, no crease among the edges it removes, no edge on the cage's rim and no corner that
//! an earlier local enrichment added (Lavoué et al.'s "the field already contains a control
//! point"); any other field is treated as diffuse. The stages ([`crate::stages`]) enrich
//! locally only once the RMS tolerance is met, when what is left are peaks: Lavoué et al.
//! insert points after each optimization has converged, and on the camel head points added
//! while the RMS still missed left a deep fold 1.1 % of the diagonal off (706 → 303 control
//! points, tolerance missed). The new point starts at the centroid of the merged face's
//! corners and is placed by the next stage's fit.
//!
//! Measured with `subfit fit` defaults (two-sided tolerances), `--local-field-share 0` against
//! the default: face 291 → 243 control points, fandisk 259 → 224, camel head 706 → 707,
//! armadillo 1,110 → 1,114, `bun000_points.ply` 651 → 678 (Hausdorff 0.83 → 0.79 % of the
//! diagonal); the beetle, the Stanford bunny, the armadillo with 27 holes, the Igea cut,
//! bunny, fertility, rocker arm and Igea unchanged (no field was local).
//!
//! Cost: `O(S)` for the shares (`S` error points) and, per merged field, `O(F · v)` for its
//! `F` faces of valence `v` around their corners.

use std::collections::HashMap;

use subfit_mesh::{PolyMesh, Polygons, Tags};

use subfit_measure::PointToLimit;
use subfit_subdiv::SamplingOperator;

use crate::error_field::{
    error_fields, scores_of_fields, two_sided_max, ErrorField, VertexFaces, FIELD_THRESHOLD,
};
use crate::remesh::FaceError;
use crate::stage_options::StageOptions;

/// The error points of a measured cage: each level-`l` sub-face of `op` (its largest corner
/// error, `err2` being the squared errors of its vertices) and each data point (`to_surface`;
/// from `rim_from` on, boundary vertices, whose distance counts `rim_scale` times), with the
/// control face it falls in (`owners`, per sub-face).
pub(crate) fn error_points(
    op: &SamplingOperator,
    owners: &[u32],
    err2: &[f64],
    to_surface: &[PointToLimit],
    rim_from: usize,
    rim_scale: f64,
) -> Vec<(u32, f32)> {
    let mut points = Vec::with_capacity(op.faces.len() + to_surface.len());
    for (f, &o) in op.faces.iter().zip(owners) {
        let e2 = f.iter().map(|&v| err2[v as usize]).fold(0.0, f64::max);
        points.push((o, e2.sqrt() as f32));
    }
    for (i, p) in to_surface.iter().enumerate() {
        let d = if i >= rim_from {
            rim_scale * p.distance
        } else {
            p.distance
        };
        points.push((owners[p.face as usize], d as f32));
    }
    points
}

/// A stage's cage and what it carries per face, as error fields change it.
pub(crate) struct FieldCage<'a> {
    pub(crate) mesh: &'a mut PolyMesh,
    pub(crate) tags: &'a Tags,
    /// Refinement scores (faces above 1 are split).
    pub(crate) score: &'a mut Vec<f64>,
    /// Refinement depth.
    pub(crate) depth: &'a mut Vec<u8>,
    /// Surface → data and data → surface errors.
    pub(crate) per_face: &'a mut (Vec<FaceError>, Vec<FaceError>),
    /// The points local enrichment added in earlier stages.
    pub(crate) enriched: &'a mut Vec<bool>,
}

impl FieldCage<'_> {
    /// The error fields of a stage that missed its maximum: the local ones (once the RMS is
    /// met, `rms_unmet` false) get a control point each ([`enrich_locally`]), and the faces of
    /// the others and their rings get scores to be split. Every per-face value is carried to
    /// the new cage (merged faces go; the faces around a new point get score 0, default
    /// errors and their parent's depth + 1). Returns the points added.
    pub(crate) fn enrich(
        self,
        points: &[(u32, f32)],
        stages: &StageOptions,
        rms_unmet: bool,
    ) -> usize {
        let n = self.mesh.num_vertices();
        let max = two_sided_max(&self.per_face.0, &self.per_face.1);
        let mut fields = error_fields(&self.mesh.faces, n, &max, stages.tolerance_max);
        // Only once the RMS is met: what is left is peaks (on the camel head, points added
        // while the RMS still missed left a deep fold 1.1 % of the diagonal off).
        let room = if rms_unmet {
            0
        } else {
            stages.max_control_points.saturating_sub(n)
        };
        let inserted = enrich_locally(
            &mut fields,
            points,
            self.mesh,
            self.tags,
            self.enriched,
            stages,
            room,
        );
        // The other fields are scored on the cage they were found on.
        let field = scores_of_fields(&self.mesh.faces, n, &max, &fields);
        for (s, f) in self.score.iter_mut().zip(field) {
            *s = s.max(f);
        }
        let Some(r) = inserted else {
            return 0;
        };
        let carry = |v: &[FaceError]| -> Vec<FaceError> {
            r.parents
                .iter()
                .zip(&r.fresh)
                .map(|(&p, &new)| {
                    if new {
                        FaceError::default()
                    } else {
                        v[p as usize]
                    }
                })
                .collect()
        };
        *self.per_face = (carry(&self.per_face.0), carry(&self.per_face.1));
        let parents = r.parents.iter().zip(&r.fresh);
        *self.score = parents
            .clone()
            .map(|(&p, &new)| if new { 0.0 } else { self.score[p as usize] })
            .collect();
        *self.depth = parents
            .map(|(&p, &new)| self.depth[p as usize].saturating_add(new as u8))
            .collect();
        self.enriched.resize(r.mesh.num_vertices(), false);
        self.enriched[n..].fill(true);
        *self.mesh = r.mesh;
        r.points
    }
}

/// Which of `fields` (disjoint, over `num_faces` faces) are local: of a field's error points
/// (`points`: control face and error) with an error of at least [`FIELD_THRESHOLD`] × its
/// maximum, fewer than `share` have one of at least `peak` × it. One pass over the points.
pub(crate) fn local_fields(
    fields: &[ErrorField],
    points: &[(u32, f32)],
    num_faces: usize,
    peak: f64,
    share: f64,
) -> Vec<bool> {
    let mut field_of = vec![u32::MAX; num_faces];
    for (i, field) in fields.iter().enumerate() {
        for &f in &field.faces {
            field_of[f as usize] = i as u32;
        }
    }
    // Per field: error points above the low and the high threshold.
    let mut counts = vec![(0usize, 0usize); fields.len()];
    for &(f, e) in points {
        let i = field_of[f as usize];
        if i != u32::MAX {
            let (m, e) = (fields[i as usize].seed_max, e as f64);
            if e >= FIELD_THRESHOLD * m {
                counts[i as usize].0 += 1;
                if e >= peak * m {
                    counts[i as usize].1 += 1;
                }
            }
        }
    }
    counts
        .iter()
        .map(|&(low, high)| low > 0 && (high as f64) < share * low as f64)
        .collect()
}

/// A cage after [`insert_points`].
pub(crate) struct Inserted {
    /// The new cage: the old points, then one per merged field.
    pub(crate) mesh: PolyMesh,
    /// For every face of the new cage, the old face it comes from: itself when kept, the
    /// field's seed for the faces around a new point.
    pub(crate) parents: Vec<u32>,
    /// Whether each face of the new cage is one of those around a new point.
    pub(crate) fresh: Vec<bool>,
    /// Points added (fields merged).
    pub(crate) points: usize,
    /// The indices (in the `fields` given) of the fields merged.
    pub(crate) merged: Vec<usize>,
}

/// Local enrichment of a stage: the fields of `fields` that are local by Lavoué et al.'s test
/// ([`local_fields`] with the thresholds of `stages`, on the error `points`) and form discs are
/// merged, one point each ([`insert_points`], at most `room`), and removed from `fields`,
/// which keeps the others for their faces to be split. `None` (and `fields` unchanged) when
/// nothing was merged or local enrichment is off.
pub(crate) fn enrich_locally(
    fields: &mut Vec<ErrorField>,
    points: &[(u32, f32)],
    mesh: &PolyMesh,
    tags: &Tags,
    enriched: &[bool],
    stages: &StageOptions,
    room: usize,
) -> Option<Inserted> {
    if stages.local_field_share <= 0.0 || points.is_empty() || fields.is_empty() || room == 0 {
        return None;
    }
    let is_local = local_fields(
        fields,
        points,
        mesh.faces.len(),
        stages.local_field_peak,
        stages.local_field_share,
    );
    let index: Vec<usize> = (0..fields.len()).filter(|&i| is_local[i]).collect();
    let local: Vec<&ErrorField> = index.iter().map(|&i| &fields[i]).collect();
    let mut r = insert_points(mesh, tags, &local, enriched, room)?;
    r.merged = r.merged.iter().map(|&k| index[k]).collect();
    let mut merged = vec![false; fields.len()];
    for &i in &r.merged {
        merged[i] = true;
    }
    let mut i = 0;
    fields.retain(|_| {
        i += 1;
        !merged[i - 1]
    });
    Some(r)
}

/// Merges the faces of each of `fields` that forms a disc (one boundary cycle, no vertex
/// inside, no edge of `tags` inside) into one polygon and adds a point at the centroid of its
/// corners, joined to each of them (a triangle per side, in the faces' winding); at most
/// `room` fields. Other fields are left alone. `None` when no field was merged.
pub(crate) fn insert_points(
    mesh: &PolyMesh,
    tags: &Tags,
    fields: &[&ErrorField],
    enriched: &[bool],
    room: usize,
) -> Option<Inserted> {
    let nf = mesh.faces.len();
    let around = VertexFaces::new(&mesh.faces, mesh.num_vertices());
    let mut merged = vec![false; nf];
    let mut in_field = vec![false; nf];
    let mut stars: Vec<(u32, Vec<u32>)> = Vec::new();
    let mut which = Vec::new();
    for (k, field) in fields.iter().enumerate() {
        if stars.len() >= room {
            break;
        }
        for &f in &field.faces {
            in_field[f as usize] = true;
        }
        let fresh_corner = field.faces.iter().any(|&f| {
            mesh.faces
                .face(subfit_mesh::FaceId(f))
                .iter()
                .any(|&v| enriched.get(v as usize).copied().unwrap_or(false))
        });
        let cycle = (!fresh_corner)
            .then(|| disc_boundary(&mesh.faces, &around, &in_field, &field.faces, tags))
            .flatten();
        if let Some(cycle) = cycle {
            for &f in &field.faces {
                merged[f as usize] = true;
            }
            stars.push((field.faces[0], cycle));
            which.push(k);
        }
        for &f in &field.faces {
            in_field[f as usize] = false;
        }
    }
    if stars.is_empty() {
        return None;
    }
    let mut positions = mesh.positions.clone();
    let mut faces = Polygons::new();
    let mut parents = Vec::new();
    let mut fresh = Vec::new();
    for (f, face) in mesh.faces.iter().enumerate() {
        if !merged[f] {
            faces.push(face);
            parents.push(f as u32);
            fresh.push(false);
        }
    }
    for (seed, cycle) in &stars {
        let c = positions.len() as u32;
        let k = cycle.len() as f64;
        let centroid = cycle.iter().fold([0.0; 3], |a, &v| {
            let p = mesh.positions[v as usize];
            [a[0] + p[0] / k, a[1] + p[1] / k, a[2] + p[2] / k]
        });
        positions.push(centroid);
        for i in 0..cycle.len() {
            faces.push(&[cycle[i], cycle[(i + 1) % cycle.len()], c]);
            parents.push(*seed);
            fresh.push(true);
        }
    }
    Some(Inserted {
        mesh: PolyMesh::new(positions, faces),
        parents,
        fresh,
        points: stars.len(),
        merged: which,
    })
}

/// The boundary of the union of `field` (its faces marked in `in_field`) as one cycle of
/// vertices in the faces' winding, or `None` when the union is not a disc without inner
/// vertices or one of the edges inside it is tagged.
fn disc_boundary(
    faces: &Polygons,
    around: &VertexFaces,
    in_field: &[bool],
    field: &[u32],
    tags: &Tags,
) -> Option<Vec<u32>> {
    // The face across the directed edge a → b of face `f` (the face holding b → a).
    let across = |f: u32, a: u32, b: u32| {
        around.of(a).iter().copied().find(|&g| {
            g != f && {
                let h = faces.face(subfit_mesh::FaceId(g));
                (0..h.len()).any(|i| h[i] == b && h[(i + 1) % h.len()] == a)
            }
        })
    };
    let mut next: HashMap<u32, u32> = HashMap::new();
    let mut vertices = Vec::new();
    for &f in field {
        let face = faces.face(subfit_mesh::FaceId(f));
        for i in 0..face.len() {
            let (a, b) = (face[i], face[(i + 1) % face.len()]);
            vertices.push(a);
            match across(f, a, b) {
                Some(g) if in_field[g as usize] => {
                    if tags.crease(a, b) > 0.0 {
                        return None;
                    }
                }
                Some(_) => {
                    if next.insert(a, b).is_some() {
                        return None; // Two sides leave `a`: the union pinches there.
                    }
                }
                // A field on the cage's rim is left to the splits: on the saddle's
                // curvature-line cage, stars there left the limit surface 1.3 % of the
                // diagonal past the data's corners.
                None => return None,
            }
        }
    }
    vertices.sort_unstable();
    vertices.dedup();
    if next.len() != vertices.len() || next.len() < 3 {
        return None; // A vertex inside the union, or a degenerate one.
    }
    let start = *next.keys().min()?;
    let mut cycle = vec![start];
    let mut v = next[&start];
    while v != start {
        if cycle.len() > next.len() {
            return None;
        }
        cycle.push(v);
        v = *next.get(&v)?;
    }
    (cycle.len() == next.len()).then_some(cycle)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 × 4 quad grid on z = 0: 25 points, point `5i + j` at `(j, i)`, face `4i + j` with
    /// corners `5i + j, 5i + j + 1, 5(i+1) + j + 1, 5(i+1) + j`.
    fn grid() -> PolyMesh {
        let mut pos = Vec::new();
        for i in 0..5 {
            for j in 0..5 {
                pos.push([j as f64, i as f64, 0.0]);
            }
        }
        let mut faces = Polygons::new();
        for i in 0..4u32 {
            for j in 0..4u32 {
                faces.push(&[
                    5 * i + j,
                    5 * i + j + 1,
                    5 * (i + 1) + j + 1,
                    5 * (i + 1) + j,
                ]);
            }
        }
        PolyMesh::new(pos, faces)
    }

    fn field(faces: &[u32]) -> ErrorField {
        ErrorField {
            faces: faces.to_vec(),
            seed_max: 1.0,
        }
    }

    #[test]
    fn a_peak_is_local_and_a_plateau_is_not() {
        // Error points of face 0 (the field); face 1 is outside it.
        let local =
            |points: &[(u32, f32)], peak| local_fields(&[field(&[0])], points, 2, peak, 0.5)[0];
        // One point at the peak, three just above half of it.
        let peak = [(0, 1.0), (0, 0.6), (0, 0.55), (0, 0.52), (1, 1.0), (1, 0.9)];
        assert!(local(&peak, 0.8));
        let plateau = [(0, 1.0), (0, 0.95), (0, 0.85), (0, 0.6), (1, 0.1)];
        assert!(!local(&plateau, 0.8));
        // The thresholds are the caller's.
        assert!(local(&plateau, 0.96));
        // Two fields at once: each judged on its own points and maximum.
        let two = [
            field(&[0]),
            ErrorField {
                faces: vec![1],
                seed_max: 2.0,
            },
        ];
        let points = [(0, 1.0), (0, 0.6), (0, 0.55), (1, 2.0), (1, 1.9), (1, 1.7)];
        assert_eq!(local_fields(&two, &points, 2, 0.8, 0.5), vec![true, false]);
    }

    #[test]
    fn two_faces_merge_into_one_with_a_point_joined_to_its_six_corners() {
        let m = grid();
        // Faces 5 and 6, side by side inside the grid: a 1 × 2 rectangle with 6 corners.
        let r = insert_points(&m, &Tags::new(), &[&field(&[5, 6])], &[], 10).unwrap();
        assert_eq!((r.points, r.merged.clone()), (1, vec![0]));
        assert_eq!(r.mesh.num_vertices(), 26);
        assert_eq!(r.mesh.faces.len(), 16 - 2 + 6);
        let he = subfit_mesh::HalfEdgeMesh::from_mesh(&r.mesh).expect("a manifold");
        assert_eq!((he.genus(), he.boundary_loops().len()), (0, 1));
        let c = r.mesh.positions[25];
        assert!(
            (c[0] - 2.0).abs() + (c[1] - 1.5).abs() + c[2].abs() < 1e-12,
            "{c:?}"
        );
        assert_eq!(r.fresh.iter().filter(|&&f| f).count(), 6);
        assert!(r.parents[14..].iter().all(|&p| p == 5));
    }

    #[test]
    fn a_field_around_a_point_across_a_crease_or_on_the_rim_is_not_merged() {
        let m = grid();
        // Faces 5, 6, 9, 10 surround point 12.
        assert!(insert_points(&m, &Tags::new(), &[&field(&[5, 6, 9, 10])], &[], 10).is_none());
        // Faces 5 and 6 share the edge 7–12, tagged.
        let mut tags = Tags::new();
        tags.set_crease(7, 12, 2.0);
        assert!(insert_points(&m, &tags, &[&field(&[5, 6])], &[], 10).is_none());
        // Faces 5 and 10 touch at point 12 only: the union pinches.
        assert!(insert_points(&m, &Tags::new(), &[&field(&[5, 10])], &[], 10).is_none());
        // On the cage's rim: faces 0 and 1.
        assert!(insert_points(&m, &Tags::new(), &[&field(&[0, 1])], &[], 10).is_none());
        // Around a point a local enrichment added before (point 6 of face 5).
        let mut enriched = vec![false; 25];
        enriched[6] = true;
        assert!(insert_points(&m, &Tags::new(), &[&field(&[5])], &enriched, 10).is_none());
        assert!(insert_points(&m, &Tags::new(), &[&field(&[5])], &[], 10).is_some());
        // The room is honoured.
        assert!(insert_points(&m, &Tags::new(), &[&field(&[5])], &[], 0).is_none());
    }
}
