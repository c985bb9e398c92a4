"""Opens files that subfit wrote with the readers users reach for first -- trimesh, Open3D,
meshio and MeshLab's (pymeshlab) -- and prints what each reader saw: one JSON line
{"FILE": {"trimesh": {...}, "open3d": {...}, "meshio": {...}, "meshlab": {...}}, ...}, each entry the counts
the reader found ("vertices", "faces" (polygons as the reader keeps them) and "triangles"
(after its own triangulation)) or {"error": "..."} when it refused the file. JSON and CSV
files are parsed with the standard library ("json": keys, "csv": rows). The caller compares
the counts with what it wrote.

Readers are asked as a script would: trimesh.load(process=False) (no merging of vertices);
Open3D's mesh reader for meshes (the tensor API for OBJ, whose legacy reader skips faces
that are not triangles) and its point-cloud reader for files without faces; meshio.read;
pymeshlab.MeshSet().load_new_mesh (MeshLab's importers, chosen by the extension).

Usage: python3 open_outputs.py FILE...   (exit 2 when a reader is not installed)
"""

import csv
import json
import os
import sys


def mesh_counts(vertices, faces, triangles):
    return {"vertices": int(vertices), "faces": int(faces), "triangles": int(triangles)}


def with_trimesh(path):
    import trimesh

    geometry = trimesh.load(path, process=False)
    if isinstance(geometry, trimesh.Scene):
        geometry = geometry.dump(concatenate=True)
    if isinstance(geometry, trimesh.PointCloud):
        return mesh_counts(len(geometry.vertices), 0, 0)
    # trimesh keeps triangles only: its face count is the triangle count.
    return mesh_counts(len(geometry.vertices), len(geometry.faces), len(geometry.faces))


def has_faces(path):
    """Whether a PLY/OBJ/OFF/STL file has faces, from its own text (to pick Open3D's reader)."""
    ext = os.path.splitext(path)[1].lower()
    if ext == ".xyz":
        return False
    if ext == ".stl":
        return True
    with open(path, "rb") as f:
        head = f.read(1 << 16)
    if ext == ".ply":
        header = head.split(b"end_header")[0]
        for line in header.splitlines():
            parts = line.split()
            if parts[:2] == [b"element", b"face"]:
                return int(parts[2]) > 0
        return False
    if ext == ".obj":
        with open(path, "rb") as f:
            return any(line.startswith(b"f ") for line in f)
    return True


def with_open3d(path):
    import open3d as o3d

    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    if not has_faces(path):
        cloud = o3d.io.read_point_cloud(path)
        return mesh_counts(len(cloud.points), 0, 0)
    if path.lower().endswith(".obj"):
        mesh = o3d.t.io.read_triangle_mesh(path)
        triangles = mesh.triangle.indices.shape[0] if "indices" in mesh.triangle else 0
        return mesh_counts(mesh.vertex.positions.shape[0], triangles, triangles)
    mesh = o3d.io.read_triangle_mesh(path)
    return mesh_counts(len(mesh.vertices), len(mesh.triangles), len(mesh.triangles))


def with_meshio(path):
    import meshio

    mesh = meshio.read(path)
    faces = 0
    triangles = 0
    for block in mesh.cells:
        if block.type == "vertex":
            continue
        n = block.data.shape[1] if block.data.ndim == 2 else 3
        faces += len(block.data)
        triangles += len(block.data) * (n - 2)
    return mesh_counts(len(mesh.points), faces, triangles)


def with_meshlab(path):
    import pymeshlab

    meshes = pymeshlab.MeshSet()
    meshes.load_new_mesh(path)
    mesh = meshes.current_mesh()
    # MeshLab keeps triangles only: it triangulates polygons on load, so face_number() is the
    # triangle count, and marks the diagonals it added as "faux" edges, from which
    # polygonal_face_list() gives back the polygons as the file had them.
    polygons = len(mesh.polygonal_face_list()) if mesh.face_number() else 0
    return mesh_counts(mesh.vertex_number(), polygons, mesh.face_number())


READERS = {"trimesh": with_trimesh, "open3d": with_open3d, "meshio": with_meshio, "meshlab": with_meshlab}


def read(path):
    ext = os.path.splitext(path)[1].lower()
    if ext == ".json":
        with open(path) as f:
            return {"json": {"keys": len(json.load(f))}}
    if ext == ".csv":
        with open(path, newline="") as f:
            return {"csv": {"rows": sum(1 for _ in csv.reader(f)) - 1}}
    out = {}
    for name, reader in READERS.items():
        try:
            out[name] = reader(path)
        except (Exception, SystemExit) as e:  # a refusal is the finding (meshio exits)
            out[name] = {"error": f"{type(e).__name__}: {e}"}
    return out


def main():
    try:
        import meshio  # noqa: F401
        import open3d  # noqa: F401
        import pymeshlab  # noqa: F401
        import trimesh  # noqa: F401
    except ImportError as e:
        print(f"{e.name} is not installed (tools/output-checks/requirements.txt)", file=sys.stderr)
        return 2
    print(json.dumps({path: read(path) for path in sys.argv[1:]}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
