"""The first peer: MeshLab's screened Poisson reconstruction (Kazhdan & Hoppe 2013, "Screened
Poisson surface reconstruction") followed by MeshLab's quadric edge-collapse decimation
(Garland & Heckbert 1997) to a given vertex count — what a user with MeshLab would run to get a
small mesh from a scan. Everything goes through pymeshlab's filters; the only numpy is the
density quantile of the trimming step and the choice among decimation attempts.

Steps (see README.md for why each setting):
* oriented points: a mesh is sampled uniformly by area (MeshLab's Monte Carlo sampling, the
  faces' normals), `SAMPLES` points or its vertex count if larger — a tessellated CAD part's
  vertices sit on its edges only and leave its flat faces without samples; a point cloud's
  normals are estimated by MeshLab from 10 neighbours (PCA) and oriented by MeshLab's
  propagation over the neighbour graph (vcglib `PointCloudNormal`, no viewpoint);
* screened Poisson at octree depth 8 (MeshLab's default), `preclean` on;
* optional trimming by density: MeshLab stores PoissonRecon's density estimate (the octree
  depth the local sampling supports, a log2 scale) as vertex quality; vertices below a quantile
  of it are removed, the usual practice for open surfaces (Open3D's tutorial, PoissonRecon's
  SurfaceTrimmer);
* components smaller than 10 % of the bounding-box diagonal removed (MeshLab's default);
* quadric edge collapse, repeated from the same Poisson mesh with a corrected face target until
  the vertex count is hit or stops improving.
"""
import pathlib

import numpy as np
import pymeshlab

SAMPLES = 20_000
"""Points sampled on a mesh for Poisson (at least; a mesh with more vertices gets as many, so a
dense scan is sampled about as densely as its vertices). Measured on the corpus's tessellated
CAD plate (618 vertices on its edges): Poisson from the vertices misses the plate (two-sided
RMS 5e-2 of the diagonal), from 20,000 samples not (3.4e-4; 50,000: 1.8e-4, at twice the
time on the scans)."""

DEPTH = 8
"""Octree depth of the Poisson solve: MeshLab's default. Depth 8 resolves 1/256 of the
bounding box, finer than the few thousand vertices the result is decimated to."""

SMALL_COMPONENT_PERCENT = 10.0
"""Components whose bounding-box diagonal is below this percentage of the whole mesh's are
removed after Poisson and after trimming (MeshLab's default for the filter)."""

TRIM_QUANTILE = {"mesh": 0.05, "points": 0.2}
"""Share of the Poisson vertices, lowest density first, removed by trimming (dimensionless), by
input kind. Chosen on the open meshes and range scans of the corpus and data (table in
README.md): a single-view cloud leaves a large Poisson cap behind the scanned side, an
area-sampled open mesh a thin rim."""

DECIMATION_ATTEMPTS = 6
"""Decimations tried from the Poisson mesh before the closest vertex count is kept."""


def load(path, kind):
    """A MeshSet holding the model at `path` (any format MeshLab reads). For `kind == "points"`
    any faces are dropped: the model is a point cloud."""
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path))
    m = ms.current_mesh()
    if m.vertex_number() == 0:
        raise ValueError(f"{path}: no vertices")
    if kind == "points" and m.face_number() > 0:
        ms.add_mesh(pymeshlab.Mesh(vertex_matrix=m.vertex_matrix()), "points")
    elif kind == "mesh" and m.face_number() == 0:
        raise ValueError(f"{path}: the row says `mesh` but the file has no faces")
    return ms


def is_open(ms):
    """Whether the current mesh has boundary edges (a point cloud counts as open)."""
    m = ms.current_mesh()
    return m.face_number() == 0 or ms.get_topological_measures()["boundary_edges"] > 0


def reconstruct(ms, depth=DEPTH, threads=1):
    """Oriented points (see the module doc), then screened Poisson on them. The Poisson mesh
    becomes current; its vertex quality is the density estimate. Returns its mesh id."""
    m = ms.current_mesh()
    if m.face_number() == 0:
        ms.compute_normal_for_point_clouds(k=10, smoothiter=0)
    else:
        samples = max(SAMPLES, m.vertex_number())
        ms.generate_sampling_montecarlo(samplenum=samples, perfacenormal=True, exactnum=True)
    ms.generate_surface_reconstruction_screened_poisson(
        depth=depth, preclean=True, threads=threads
    )
    if ms.current_mesh().face_number() == 0:
        raise RuntimeError("screened Poisson returned an empty surface")
    return ms.current_mesh_id()


def remove_small_components(ms, percent=SMALL_COMPONENT_PERCENT):
    """Remove the current mesh's connected components smaller than `percent` % of its
    bounding-box diagonal."""
    ms.meshing_remove_connected_component_by_diameter(
        mincomponentdiag=pymeshlab.PercentageValue(percent), removeunref=True
    )


def trim_by_density(ms, quantile):
    """On a copy of the current (Poisson) mesh, remove the vertices whose density is below the
    `quantile` of all, then small components. The copy becomes current. Returns the density
    threshold (PoissonRecon's log2 depth units)."""
    density = ms.current_mesh().vertex_scalar_array()
    threshold = float(np.quantile(density, quantile))
    ms.generate_copy_of_current_mesh()
    ms.compute_selection_by_condition_per_vertex(condselect=f"q < {threshold!r}")
    ms.meshing_remove_selected_vertices()
    ms.meshing_remove_unreferenced_vertices()
    remove_small_components(ms)
    if ms.current_mesh().face_number() == 0:
        raise RuntimeError(f"trimming at density {threshold:.3f} removed the whole surface")
    return threshold


def decimate(ms, mesh_id, vertices):
    """Quadric edge collapse of a copy of mesh `mesh_id` to `vertices` vertices, as close as
    MeshLab gets: MeshLab takes a face target, so the target starts from the source's
    faces-per-vertex ratio and is corrected by the measured ratio, from the same source each
    time. The closest result becomes current (ties: the first). Returns its vertex count.
    Boundaries are not frozen: MeshLab's `preserveboundary` forbids every boundary collapse, and
    a trimmed surface's jagged rim alone then holds more vertices than the target."""
    ms.set_current_mesh(mesh_id)
    source = ms.current_mesh()
    if source.vertex_number() <= vertices:
        ms.generate_copy_of_current_mesh()
        return source.vertex_number()
    target = max(4, round(vertices * source.face_number() / source.vertex_number()))
    best, tried = None, set()
    for _ in range(DECIMATION_ATTEMPTS):
        if target in tried:
            break
        tried.add(target)
        ms.set_current_mesh(mesh_id)
        ms.generate_copy_of_current_mesh()
        ms.meshing_decimation_quadric_edge_collapse(
            targetfacenum=target,
            preserveboundary=False,
            preservenormal=True,
            planarquadric=True,
            qualitythr=0.3,
        )
        got = ms.current_mesh().vertex_number()
        if best is None or abs(got - vertices) < abs(best[1] - vertices):
            best = (ms.current_mesh_id(), got)
        if got == vertices:
            break
        target = max(4, round(target * vertices / got)) if got else target * 2
    ms.set_current_mesh(best[0])
    return best[1]


def save_ply(ms, path):
    """Write the current mesh as a binary PLY with positions and faces only, atomically."""
    path = pathlib.Path(path)
    tmp = path.with_name(f".{path.stem}.tmp{path.suffix}")
    ms.save_current_mesh(
        str(tmp),
        binary=True,
        save_vertex_quality=False,
        save_vertex_normal=False,
        save_vertex_color=False,
        save_face_color=False,
        save_face_quality=False,
    )
    tmp.replace(path)
