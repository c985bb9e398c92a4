"""Tests of tools/peers (optional, not part of CI): the connectivity figures against meshes whose
figures are known, and the whole script on an icosphere it writes, when pymeshlab,
pyinstantmeshes, pyquadriflow and a subfit binary are there (skipped with a notice otherwise).

    pip install -r tools/peers/requirements.txt pytest
    python3 -m pytest tools/peers/tests -rs
"""
import importlib.util
import json
import pathlib
import shutil
import subprocess
import sys

import numpy as np
import pytest

HERE = pathlib.Path(__file__).resolve().parent
PEERS = HERE.parent
REPO = PEERS.parents[1]
sys.path.insert(0, str(PEERS))

from meshes import (  # noqa: E402 (after the path)
    compact,
    connectivity,
    euler_and_loops,
    read_obj_polygons,
    split_nonmanifold_vertices,
    write_obj,
)


def icosphere(levels):
    """A unit icosphere: the icosahedron split 1-to-4 `levels` times, projected to the sphere.
    Vertices 10·4^levels + 2; the 12 icosahedron corners keep valence 5."""
    t = (1 + 5**0.5) / 2
    V = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
         [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]  # fmt: skip
    F = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
         [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
         [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]  # fmt: skip
    V = [np.array(v, dtype=float) / np.linalg.norm(v) for v in V]

    def mid(a, b, middle):
        key = (min(a, b), max(a, b))
        if key not in middle:
            m = V[a] + V[b]
            V.append(m / np.linalg.norm(m))
            middle[key] = len(V) - 1
        return middle[key]

    for _ in range(levels):
        middle, G = {}, []
        for a, b, c in F:
            ab, bc, ca = mid(a, b, middle), mid(b, c, middle), mid(c, a, middle)
            G += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        F = G
    return np.array(V), F


def grid(n):
    """An n×n grid of quads on the unit square: (n+1)² vertices, interior valence 4,
    boundary valence 3 except the 4 corners (valence 2)."""
    V = [[i / n, j / n, 0.0] for j in range(n + 1) for i in range(n + 1)]
    F = [[j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i]
         for j in range(n) for i in range(n)]  # fmt: skip
    return np.array(V), F


def test_connectivity_of_known_meshes():
    V, F = icosphere(2)
    c = connectivity(F, len(V))
    assert c == {"vertices": 162, "faces": 320, "quad_fraction": 0.0, "irregular_vertices": 12}
    assert euler_and_loops(F, len(V)) == (2, 0)
    V, F = grid(4)
    c = connectivity(F, len(V))
    assert c == {"vertices": 25, "faces": 16, "quad_fraction": 1.0, "irregular_vertices": 4}
    assert euler_and_loops(F, len(V)) == (1, 1)
    cube = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]
    assert connectivity(cube, 8)["irregular_vertices"] == 8  # valence 3 inside


def test_split_nonmanifold_vertices():
    # Two fans of two triangles each meet at vertex 0 only (a bow tie of quads' halves).
    V = np.zeros((7, 3))
    F = [[0, 1, 2], [0, 2, 3], [0, 4, 5], [0, 5, 6]]
    V2, F2, copies = split_nonmanifold_vertices(V, F)
    assert copies == 1 and len(V2) == 8
    assert F2[:2] == F[:2] and F2[2:] == [[7, 4, 5], [7, 5, 6]]
    assert euler_and_loops(F2, 8) == (2, 2)  # two discs
    V, F = icosphere(1)
    assert split_nonmanifold_vertices(V, F)[2] == 0


def test_obj_round_trip_and_compact(tmp_path):
    V, F = grid(2)
    F = [F[0] + [F[0][-1]]] + F[1:]  # a repeated corner, as remeshers write triangles
    V = np.vstack([V, [[5.0, 5.0, 5.0]]])  # an unused vertex
    V2, F2 = compact(V, F)
    assert len(V2) == 9 and F2[0] == [0, 1, 4, 3]
    write_obj(tmp_path / "m.obj", V2, F2)
    V3, F3 = read_obj_polygons(tmp_path / "m.obj")
    assert F3 == F2 and np.allclose(V3, V2)
    (tmp_path / "bad.obj").write_text("v 0 0 0\nf 1 2 x\n")
    with pytest.raises(ValueError, match="bad.obj:2"):
        read_obj_polygons(tmp_path / "bad.obj")


def tools_missing():
    missing = [m for m in ("pymeshlab", "pyinstantmeshes", "pyQuadriFlow")
               if importlib.util.find_spec(m) is None]  # fmt: skip
    subfit = REPO / "target/release/subfit"
    if not subfit.exists() and shutil.which("subfit") is None:
        missing.append("a subfit binary (cargo build --release -p subfit-cli)")
    return missing


def test_peers_on_an_icosphere(tmp_path):
    missing = tools_missing()
    if missing:
        print(f"NOTICE: peers end-to-end test skipped: missing {', '.join(missing)}")
        pytest.skip(f"missing {', '.join(missing)}")
    V, F = icosphere(4)  # 2,562 vertices on the unit sphere
    model = tmp_path / "sphere.obj"
    write_obj(model, V, F)
    ours = {"rows": [
        {"entry": "sphere", "input": str(model), "category": "scan", "kind": "mesh",
         "control_points": 100},
        {"entry": "gone", "input": str(tmp_path / "missing.obj"), "category": "scan",
         "kind": "mesh", "control_points": 100},
        {"entry": "failed", "input": str(model), "category": "scan", "kind": "mesh",
         "control_points": None},
        {"entry": "pair", "input": str(model), "category": "cage", "kind": "cage-pair",
         "control_points": 100},
    ]}  # fmt: skip
    (tmp_path / "ours.json").write_text(json.dumps(ours))
    out = tmp_path / "peers"
    cmd = [sys.executable, str(PEERS / "peers.py"), "--ours", str(tmp_path / "ours.json"),
           "--out", str(out), "--jobs", "2"]  # fmt: skip
    run = subprocess.run(cmd, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    rows = json.loads((out / "peers.json").read_text())["peers"]
    by = {(r["entry"], r["peer"]): r for r in rows}
    assert {e for e, _ in by} == {"sphere", "gone", "pair"}  # the failed fit has no peers
    # A cage pair's dense mesh is remeshed like a mesh entry (QuadriFlow + fit is its row).
    assert by[("pair", "quadriflow")]["error"] is None, by[("pair", "quadriflow")]
    assert by[("pair", "quadriflow")]["quad_fraction"] == 1.0
    for peer in ("poisson-qem", "instant-meshes", "quadriflow"):
        assert "no such file" in by[("gone", peer)]["error"]
        r = by[("sphere", peer)]
        assert r["error"] is None, r["error"]
        assert (out / r["file"]).exists()
        assert abs(r["vertices"] - 100) <= 15, r  # the remeshers hit a count roughly
        assert r["seconds"] > 0
    assert by[("sphere", "poisson-qem")]["vertices"] == 100
    assert by[("sphere", "quadriflow")]["quad_fraction"] == 1.0
    assert by[("sphere", "instant-meshes")]["scheme"] == "catmull-clark"
    # Ground truth: every Poisson + QEM vertex lies near the unit sphere. 100 vertices make
    # triangles of area 4π/196 (circumradius 0.22), whose planes sit up to 1 − √(1 − 0.22²)
    # = 2.5 % inside the sphere; QEM places vertices between the sphere and those planes'
    # offsets, so within 3 % of the radius.
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(out / by[("sphere", "poisson-qem")]["file"]))
    radii = np.linalg.norm(ms.current_mesh().vertex_matrix(), axis=1)
    assert np.all(np.abs(radii - 1) < 0.03), (radii.min(), radii.max())
    # The remeshes are closed genus-0 surfaces like the sphere.
    for peer in ("instant-meshes", "quadriflow"):
        RV, RF = read_obj_polygons(out / "sphere" / f"{peer}-remesh.obj")
        assert euler_and_loops(RF, len(RV)) == (2, 0)
    # A second run finds the entry done and leaves peers.json as it was.
    before = (out / "peers.json").read_text()
    again = subprocess.run(cmd, capture_output=True, text=True)
    assert again.returncode == 0 and "sphere" in again.stdout and "done before" in again.stdout
    assert json.loads((out / "peers.json").read_text()) == json.loads(before)
