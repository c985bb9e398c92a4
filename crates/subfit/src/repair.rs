//! Reading a target and repairing what a user expects repaired, each repair with a warning:
//!
//! 0. vertices that no face uses are dropped: left in, they would widen the bounding box that
//!    the tolerances and the reported fractions of the diagonal are relative to;
//! 1. vertices at exactly the same position are welded ([`subfit_mesh::weld_coincident`]): a
//!    mesh exported with its vertices split along texture seams is one surface, not one patch
//!    per chart with a boundary along every seam;
//! 2. faces that collapse onto a repeated vertex are shortened or dropped, and faces written
//!    twice in the same turn are written once ([`subfit_mesh::clean_faces`]); a face written
//!    again turned is kept: the two sides of a sheet of no thickness (a thin part of a scan that
//!    the reconstruction collapsed);
//! 3. edges with more than two faces are cut into pairs of faces that continue each other with
//!    consistent orientations, by their order around the edge
//!    ([`subfit_mesh::cut_nonmanifold_edges`], [`subfit_mesh::edge_pairs`]): a stray triangle
//!    hanging from the surface comes off as a piece of its own, and each side of a sheet of no
//!    thickness continues the side of the surface it faces;
//! 4. what the cut leaves of a part written twice, once inside out, goes
//!    ([`subfit_mesh::drop_twin_sides`]): a sheet written on both sides keeps one, a part that
//!    repeats another is dropped;
//! 5. non-manifold vertices are split into one per fan of faces
//!    ([`subfit_mesh::split_bowties`]): holes that touch at a vertex;
//! 6. faces that disagree with their neighbours are turned ([`subfit_mesh::reorient_faces`]):
//!    a messy scan. Non-orientable pieces (a Möbius strip) smaller than a hundredth of the mesh
//!    ([`FLAP_FRACTION`]) are dropped, as the flaps the cut takes off are;
//! 7. the vertices that only dropped faces used go with them.
//!
//! What stays non-orientable is not refused: [`repair_or_points`] (what the pipeline reads
//! with) takes such a mesh as its points, to be fitted as `--as-points` would, and says why.

use subfit_mesh::nonmanifold::FLAP_FRACTION;
use subfit_mesh::{
    clean_faces, cut_nonmanifold_edges, diagnose_mesh, drop_twin_sides, face_components,
    reorient_faces, split_bowties, weld_coincident, PolyMesh, Polygons, ReorientError,
};

use crate::error::Error;
use crate::options::Input;
use crate::pipeline_report::Reorientation;

/// Repairs `mesh` (named `name` in the warnings) in place, as the module docs say, calling `warn`
/// once per repair; returns what was re-oriented. A point cloud (no faces) is left alone. On
/// an error (a non-orientable component) the other repairs are kept and no face is turned.
///
/// ```
/// use subfit::mesh::{PolyMesh, Polygons};
///
/// // A tetrahedron with one face written twice and a vertex no face uses.
/// let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [5.0; 3]];
/// let faces = Polygons::from_triangles(&[[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2], [0, 3, 2]]);
/// let mut mesh = PolyMesh::new(positions, faces);
/// let mut warnings = Vec::new();
/// subfit::repair_mesh(&mut mesh, "tetra.obj", &mut |w| warnings.push(w)).unwrap();
/// assert_eq!((mesh.num_vertices(), mesh.num_faces()), (4, 4));
/// assert_eq!(warnings.len(), 2, "{warnings:?}"); // one per repair
/// ```
pub fn repair_mesh(
    mesh: &mut PolyMesh,
    name: &str,
    warn: &mut dyn FnMut(String),
) -> Result<Option<Reorientation>, ReorientError> {
    if mesh.faces.is_empty() {
        return Ok(None);
    }
    let unused = mesh.remove_unreferenced();
    if let Some(v) = unused.first() {
        warn(format!(
            "dropped {} vertices of {name} that no face uses (e.g. vertex {v}): they are not part of the surface and would widen its bounding box",
            unused.len()
        ));
    }
    let w = weld_coincident(mesh);
    if w.refused {
        warn(format!(
            "{name} has {} vertices at the same position as another (seams?), left apart: welding them would join three or more faces along an edge",
            w.vertices_merged
        ));
    } else if w.vertices_merged > 0 {
        warn(format!(
            "welded {} vertices of {name} at the same position as another (a mesh split along seams){}",
            w.vertices_merged,
            clause("; ", w.faces_dropped, "faces that collapsed were dropped")
        ));
    }
    let c = clean_faces(mesh);
    if c.changed() {
        let what = [
            clause(
                "",
                c.degenerate_dropped,
                "dropped with fewer than three distinct vertices",
            ),
            clause(
                ", ",
                c.faces_shortened,
                "listing a vertex twice in a row, listed once",
            ),
            clause(
                ", ",
                c.duplicates_dropped,
                "dropped as duplicates of an earlier face",
            ),
        ]
        .concat();
        warn(format!(
            "repaired faces of {name}: {} (e.g. face {})",
            what.trim_start_matches(", "),
            c.examples[0]
        ));
    }
    let e = cut_nonmanifold_edges(mesh);
    if e.edges_cut > 0 {
        let [a, b] = e.examples[0];
        warn(format!(
            "cut {} edges of {name} shared by more than two faces (e.g. {a}-{b}) into pairs of faces that continue each other{}{}{}",
            e.edges_cut,
            clause(", ", e.vertices_added, "vertices copied"),
            clause(", ", e.edges_split, "edges the surface passes twice split at their middle"),
            clause(", ", e.flap_faces_dropped, "faces of flaps that came off dropped")
        ));
    }
    let t = drop_twin_sides(mesh);
    if t.faces_dropped > 0 {
        let what = [
            clause(
                "",
                t.pillows_halved,
                "sheets written on both sides keep one side",
            ),
            clause(
                ", ",
                t.copies_dropped,
                "parts that repeat another are dropped",
            ),
        ]
        .concat();
        warn(format!(
            "dropped {} faces of {name} written a second time inside out: {}",
            t.faces_dropped,
            what.trim_start_matches(", ")
        ));
    }
    let b = split_bowties(mesh);
    if b.vertices_split > 0 {
        warn(format!(
            "split {} non-manifold vertices of {name} (faces meeting only at a vertex, e.g. vertex {}) into one vertex per fan",
            b.vertices_split, b.examples[0]
        ));
    }
    let (faces, r) = match reorient_faces(&mesh.faces, mesh.num_vertices(), Some(&mesh.positions)) {
        Err(ReorientError::NonOrientable { .. }) if drop_small_non_orientable(mesh, name, warn) => {
            reorient_faces(&mesh.faces, mesh.num_vertices(), Some(&mesh.positions))?
        }
        other => other?,
    };
    if r.needed {
        mesh.faces = faces;
    }
    // The faces the cut and the drops took away leave their vertices unused: off the surface
    // (a fin's tip), they would be fitted and measured as data points of no face.
    mesh.remove_unreferenced();
    if !r.needed {
        return Ok(None);
    }
    warn(format!(
        "re-oriented {} faces in {} components of {name}",
        r.flipped_faces, r.repaired_components
    ));
    Ok(Some(Reorientation {
        faces_flipped: r.flipped_faces,
        components_changed: r.repaired_components,
    }))
}

/// Drops the non-orientable components of `mesh` when each is smaller than
/// `1 / FLAP_FRACTION` of its faces (debris, as the flaps the cut takes off), with a warning;
/// returns whether it did. Left alone (`false`) when there is a larger one.
fn drop_small_non_orientable(
    mesh: &mut PolyMesh,
    name: &str,
    warn: &mut dyn FnMut(String),
) -> bool {
    let report = diagnose_mesh(mesh);
    let labels = face_components(&mesh.faces, mesh.num_vertices()).face_labels;
    let total = mesh.faces.len();
    let bad: Vec<usize> = (0..report.components.len())
        .filter(|&c| !report.components[c].orientable)
        .collect();
    if bad.is_empty()
        || bad
            .iter()
            .any(|&c| report.components[c].faces * FLAP_FRACTION >= total)
    {
        return false;
    }
    let drop: Vec<bool> = labels
        .iter()
        .map(|&l| l != u32::MAX && bad.contains(&(l as usize)))
        .collect();
    let example = drop.iter().position(|&d| d).unwrap_or(0);
    let mut faces = Polygons::with_capacity(total, mesh.faces.indices().len());
    for (f, face) in mesh.faces.iter().enumerate() {
        if !drop[f] {
            faces.push(face);
        }
    }
    warn(format!(
        "dropped {} faces of {name} in {} non-orientable pieces (a Möbius strip, e.g. around face {example}), each smaller than 1/{FLAP_FRACTION} of the mesh",
        total - faces.len(),
        bad.len()
    ));
    mesh.faces = faces;
    true
}

/// `"{sep}{n} {what}"` when `n > 0`, else nothing: an optional part of a warning.
fn clause(sep: &str, n: usize, what: &str) -> String {
    if n > 0 {
        format!("{sep}{n} {what}")
    } else {
        String::new()
    }
}

/// [`repair_mesh`], except that a mesh that stays non-orientable after the repairs becomes its
/// points (the vertices its faces use, with their normals when it has them; no faces), to be
/// fitted as `--as-points` would, with a warning that says why. Errors: what else
/// [`repair_mesh`] refuses (none for a mesh read by [`subfit_io`]).
pub fn repair_or_points(
    mesh: &mut PolyMesh,
    name: &str,
    warn: &mut dyn FnMut(String),
) -> Result<Option<Reorientation>, ReorientError> {
    let read = mesh.clone();
    match repair_mesh(mesh, name, warn) {
        Err(ReorientError::NonOrientable { face }) => {
            let at = mesh.faces.face(face).first().map_or(String::new(), |&v| {
                let p = mesh.positions[v as usize];
                format!(" (at {:.6}, {:.6}, {:.6})", p[0], p[1], p[2])
            });
            warn(format!(
                "{name} cannot be oriented consistently around face {face}{at}: a non-orientable surface, such as a Möbius strip; fitting its points instead, as --as-points would"
            ));
            *mesh = read;
            mesh.remove_unreferenced();
            mesh.faces = Polygons::new();
            Ok(None)
        }
        other => other,
    }
}

/// Reads `input` (a file, or takes the mesh given) and repairs it ([`repair_or_points`]) unless
/// its faces are not used (`as_points`). Returns the mesh, its name for messages and what was
/// re-oriented. The reader's warnings ([`subfit_io::FileInfo::warnings`]) go to `warn` first.
pub(crate) fn read_input(
    input: Input,
    as_points: bool,
    warn: &mut dyn FnMut(String),
) -> Result<ReadInput, Error> {
    let (mut mesh, name) = match input {
        Input::File(path) => {
            let (m, info) = subfit_io::read_file(&path, &subfit_io::ReadOptions::default())?;
            for w in info.warnings {
                warn(format!("{}: {w}", path.display()));
            }
            (m, path.display().to_string())
        }
        Input::Mesh { mesh, name } => (mesh, name),
    };
    let (reoriented, vertices) = if as_points {
        (None, Vec::new())
    } else {
        let vertices = face_vertices(&mesh);
        let r = repair_or_points(&mut mesh, &name, warn).map_err(|e| Error::input(&name, e))?;
        (r, vertices)
    };
    Ok(ReadInput {
        mesh,
        name,
        reoriented,
        vertices,
    })
}

/// An input read and repaired ([`read_input`]).
pub(crate) struct ReadInput {
    /// The repaired mesh (or points).
    pub(crate) mesh: PolyMesh,
    /// Its name for messages (the file).
    pub(crate) name: String,
    /// Faces the repair turned, if any.
    pub(crate) reoriented: Option<Reorientation>,
    /// Every vertex a face of the file uses, as read (before the repair dropped flaps or
    /// duplicates): where the final measure takes its largest data → surface distance from, so
    /// that the figure is the one a user measures against the file. Empty for points.
    pub(crate) vertices: Vec<[f64; 3]>,
}

/// The positions of the vertices some face of `mesh` uses, in index order.
fn face_vertices(mesh: &PolyMesh) -> Vec<[f64; 3]> {
    let mut used = vec![false; mesh.positions.len()];
    for f in mesh.faces.iter() {
        for &v in f {
            if let Some(u) = used.get_mut(v as usize) {
                *u = true;
            }
        }
    }
    mesh.positions
        .iter()
        .zip(&used)
        .filter_map(|(p, &u)| u.then_some(*p))
        .collect()
}
