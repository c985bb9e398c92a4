"""Small mesh helpers of the peers: polygon OBJ reading and writing, atomic file writes, and
the connectivity figures peers.json reports for every peer's output (quad fraction and
irregular vertices, as in Bommes et al. 2013, "Quad-mesh generation and processing: a survey",
§2: a vertex is regular when its valence is the one of the regular tiling).

No pymeshlab here: these run on the remeshers' polygon output, which MeshLab would triangulate.
"""
import os
import pathlib

import numpy as np


def atomic_write_text(path, text):
    """Write `text` to `path` through a temporary name in the same folder and a rename, so a
    reader never sees a partial file."""
    path = pathlib.Path(path)
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def read_obj_polygons(path):
    """Read the vertices and polygon faces of an OBJ file (`v` and `f` lines; `f` corners may be
    `v`, `v/vt`, `v//vn` or `v/vt/vn`, indices 1-based or negative). Returns `(V, faces)`:
    `V` #V by 3 float64, `faces` a list of lists of 0-based vertex indices.
    Raises ValueError naming the file and line of a malformed line."""
    vertices, faces = [], []
    with open(path) as f:
        for number, line in enumerate(f, 1):
            parts = line.split()
            if not parts:
                continue
            try:
                if parts[0] == "v":
                    vertices.append([float(x) for x in parts[1:4]])
                elif parts[0] == "f":
                    face = []
                    for corner in parts[1:]:
                        i = int(corner.split("/")[0])
                        face.append(i - 1 if i > 0 else len(vertices) + i)
                    faces.append(face)
            except (ValueError, IndexError) as e:
                raise ValueError(f"{path}:{number}: malformed `{parts[0]}` line ({e})") from e
    V = np.array(vertices, dtype=np.float64).reshape(-1, 3)
    for number, face in enumerate(faces):
        if any(i < 0 or i >= len(V) for i in face):
            raise ValueError(f"{path}: face {number} refers to a vertex that does not exist")
    return V, faces


def compact(V, faces):
    """Drop repeated corners (a quad `a b c c` written for a triangle), faces left with fewer
    than three corners, and vertices no face uses; renumber. Returns `(V, faces)`."""
    clean = []
    for face in faces:
        corners = [i for k, i in enumerate(face) if i != face[k - 1]]
        if len(set(corners)) >= 3:
            clean.append(corners)
    used = sorted({i for face in clean for i in face})
    index = {old: new for new, old in enumerate(used)}
    return np.asarray(V)[used], [[index[i] for i in face] for face in clean]


def write_obj(path, V, faces):
    """Write vertices and polygon faces as a plain OBJ (`v`, `f` with 1-based indices),
    atomically."""
    lines = ["# written by tools/peers"]
    lines += [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in np.asarray(V, dtype=np.float64)]
    lines += ["f " + " ".join(str(i + 1) for i in face) for face in faces]
    atomic_write_text(path, "\n".join(lines) + "\n")


def connectivity(faces, n_vertices):
    """The figures peers.json reports for a polygon mesh: `vertices` (those used by a face),
    `faces`, `quad_fraction` (share of faces with four corners) and `irregular_vertices`.

    A mesh whose faces are mostly quads (quad fraction >= 0.5) is judged against the quad
    tiling: an interior vertex is regular with valence 4, a boundary vertex with valence 3;
    otherwise against the triangle tiling: 6 inside, 4 on the boundary. Valence counts the
    distinct edges at a vertex; a boundary edge is used by one face. Cost O(corners)."""
    edge_uses = {}
    for face in faces:
        for k, a in enumerate(face):
            b = face[(k + 1) % len(face)]
            key = (a, b) if a < b else (b, a)
            edge_uses[key] = edge_uses.get(key, 0) + 1
    valence = np.zeros(n_vertices, dtype=np.int64)
    boundary = np.zeros(n_vertices, dtype=bool)
    for (a, b), uses in edge_uses.items():
        valence[a] += 1
        valence[b] += 1
        if uses == 1:
            boundary[a] = boundary[b] = True
    used = valence > 0
    quads = sum(1 for face in faces if len(face) == 4)
    quad_fraction = quads / len(faces) if faces else 0.0
    inner, rim = (4, 3) if quad_fraction >= 0.5 else (6, 4)
    regular = np.where(boundary, valence == rim, valence == inner)
    return {
        "vertices": int(used.sum()),
        "faces": len(faces),
        "quad_fraction": round(quad_fraction, 4),
        "irregular_vertices": int((used & ~regular).sum()),
    }


def euler_and_loops(faces, n_vertices):
    """`(χ, boundary loops)` of a polygon mesh: χ = V − E + F over the vertices faces use, and
    the connected pieces of the boundary-edge graph (edges used by one face). Two meshes with
    different pairs cannot be the same surface; `subfit fit` refuses such an initial cage."""
    edge_uses = {}
    for face in faces:
        for k, a in enumerate(face):
            b = face[(k + 1) % len(face)]
            key = (a, b) if a < b else (b, a)
            edge_uses[key] = edge_uses.get(key, 0) + 1
    used = {i for face in faces for i in face}
    parent = list(range(n_vertices))
    rim = set()
    for (a, b), uses in edge_uses.items():
        if uses == 1:
            rim.update((a, b))
            parent[_root(parent, a)] = _root(parent, b)
    loops = len({_root(parent, i) for i in rim})
    return len(used) - len(edge_uses) + len(faces), loops


def split_nonmanifold_vertices(V, faces):
    """Give each fan of faces around a vertex its own copy of the vertex (MeshLab's "repair
    non-manifold vertices by splitting"): faces are in one fan when they share an edge at the
    vertex. Remeshers leave a few vertices where two fans touch, which `subfit fit` refuses.
    Returns `(V, faces, copies made)`; non-manifold edges are left as they are."""
    around = {}
    for f, face in enumerate(faces):
        for k, v in enumerate(face):
            around.setdefault(v, []).append((f, face[k - 1], face[(k + 1) % len(face)]))
    V = [np.asarray(p, dtype=np.float64) for p in V]
    faces = [list(face) for face in faces]
    copies = 0
    for v, incident in around.items():
        parent = {f: f for f, _, _ in incident}
        by_neighbour = {}
        for f, a, b in incident:
            for w in (a, b):
                if w in by_neighbour:
                    parent[_root(parent, f)] = _root(parent, by_neighbour[w])
                else:
                    by_neighbour[w] = f
        fans = sorted({_root(parent, f) for f, _, _ in incident})
        for fan in fans[1:]:
            V.append(V[v].copy())
            copies += 1
            for f, _, _ in incident:
                if _root(parent, f) == fan:
                    faces[f] = [len(V) - 1 if i == v else i for i in faces[f]]
    return np.array(V).reshape(-1, 3), faces, copies


def _root(parent, i):
    """Union-find root of `i` in `parent` (a list or dict), with path halving."""
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i
