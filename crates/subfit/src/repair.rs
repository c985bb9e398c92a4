//! Reading a target and repairing what a user expects repaired, each repair with a warning:
//!
//! 0. vertices that no face uses are dropped: left in, they would widen the bounding box that
//!    the tolerances and the reported fractions of the diagonal are relative to;
//! 1. vertices at exactly the same position are welded ([`subfit_mesh::weld_coincident`]): a
//!    mesh exported with its vertices split along texture seams is one surface, not one patch
//!    per chart with a boundary along every seam;
//! 2. faces that collapse onto a repeated vertex are shortened or dropped, and faces written
//!    twice are written once ([`subfit_mesh::clean_faces`]);
//! 3. edges with more than two faces are cut into pairs of faces that continue each other
//!    ([`subfit_mesh::cut_nonmanifold_edges`]): a stray triangle hanging from the surface comes
//!    off as a piece of its own;
//! 4. non-manifold vertices are split into one per fan of faces
//!    ([`subfit_mesh::split_bowties`]): holes that touch at a vertex;
//! 5. faces that disagree with their neighbours are turned ([`subfit_mesh::reorient_faces`]):
//!    a messy scan.
//!
//! Only what cannot be repaired is refused: a non-orientable part (a Möbius strip).

use subfit_mesh::{
    clean_faces, cut_nonmanifold_edges, reorient_faces, split_bowties, weld_coincident, PolyMesh,
    ReorientError,
};

use crate::error::Error;
use crate::options::Input;
use crate::pipeline_report::Reorientation;

/// Repairs `mesh` (named `name` in the warnings) in place, as the module docs say, calling `warn`
/// once per repair; returns what was re-oriented. A point cloud (no faces) is left alone. On
/// an error (a non-orientable component) the other repairs are kept and no face is turned.
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
            clause(", ", e.flap_faces_dropped, "faces of flaps that came off dropped"),
            clause(", ", e.faces_dropped, "faces the cut could not separate dropped")
        ));
    }
    let b = split_bowties(mesh);
    if b.vertices_split > 0 {
        warn(format!(
            "split {} non-manifold vertices of {name} (faces meeting only at a vertex, e.g. vertex {}) into one vertex per fan",
            b.vertices_split, b.examples[0]
        ));
    }
    let (faces, r) = reorient_faces(&mesh.faces, mesh.num_vertices(), Some(&mesh.positions))?;
    if !r.needed {
        return Ok(None);
    }
    warn(format!(
        "re-oriented {} faces in {} components of {name}",
        r.flipped_faces, r.repaired_components
    ));
    mesh.faces = faces;
    Ok(Some(Reorientation {
        faces_flipped: r.flipped_faces,
        components_changed: r.repaired_components,
    }))
}

/// `"{sep}{n} {what}"` when `n > 0`, else nothing: an optional part of a warning.
fn clause(sep: &str, n: usize, what: &str) -> String {
    if n > 0 {
        format!("{sep}{n} {what}")
    } else {
        String::new()
    }
}

/// Reads `input` (a file, or takes the mesh given) and repairs it ([`repair_mesh`]) unless its
/// faces are not used (`as_points`). Returns the mesh, its name for messages and what was
/// re-oriented. The reader's warnings ([`subfit_io::FileInfo::warnings`]) go to `warn` first.
pub(crate) fn read_input(
    input: Input,
    as_points: bool,
    warn: &mut dyn FnMut(String),
) -> Result<(PolyMesh, String, Option<Reorientation>), Error> {
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
    let reoriented = if as_points {
        None
    } else {
        repair_mesh(&mut mesh, &name, warn).map_err(|e| Error::input(&name, e))?
    };
    Ok((mesh, name, reoriented))
}
