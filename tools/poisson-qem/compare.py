#!/usr/bin/env python3
"""The baseline subfit is measured against on noisy scans (issue 16): MeshLab's screened
Poisson reconstruction followed by quadric edge-collapse decimation to the vertex count of a
subfit cage, each surface measured two-sided against the clean mesh with `subfit compare`.

    pip install pymeshlab
    python tools/poisson-qem/compare.py NOISY.ply CLEAN.mesh FIT_DIR [--subfit BIN] [--depth 9]

FIT_DIR is the output of `subfit fit NOISY.ply -o FIT_DIR` (its control.obj and report.json).
Two Poisson variants are run, both after MeshLab's point-cloud outlier selection (LoOP
probability > 0.8 over 32 neighbours) is removed and normals are estimated by MeshLab (10
neighbours; the scan has none):
* "MeshLab": as MeshLab leaves them. Its normals are not consistently oriented (about half
  point inwards), so Poisson wraps a bubble: what a user gets without more work.
* "oracle": the baseline at its best. Points farther than 3σ (σ = NOISE × the clean
  diagonal) from the clean mesh's vertices are dropped and every normal is flipped to agree
  with the nearest clean vertex's normal: knowledge subfit does not have.
Small components (diameter < 20 % of the bounding box) are removed after Poisson. Prints one
line per surface: vertices, time, and two-sided RMS and Hausdorff distances to CLEAN as
fractions of CLEAN's bounding-box diagonal. Needs numpy and scipy. Not run in CI: a one-off
measurement for the closing notes.
"""
import argparse
import json
import pathlib
import subprocess
import sys
import time

import numpy as np
import pymeshlab
from scipy.spatial import cKDTree

# The decimation to a vertex count is the scoreboard peers' (tools/peers/poisson_qem.py).
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "peers"))
from poisson_qem import decimate  # noqa: E402


def compare(subfit, a, clean, scheme=None):
    cmd = [subfit, "compare", str(a), str(clean), "--json"]
    if scheme:
        cmd += ["--scheme", scheme]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def clean_vertices(clean):
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(clean))
    ms.compute_normal_per_vertex()
    m = ms.current_mesh()
    lo, hi = m.bounding_box().min(), m.bounding_box().max()
    return m.vertex_matrix(), m.vertex_normal_matrix(), float(np.linalg.norm(hi - lo))


def poisson_qem(noisy, vertices, depth, oracle, out):
    """`oracle`: None, or (clean vertices, their normals, noise σ) to clean and orient with."""
    t = time.perf_counter()
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(noisy))
    ms.compute_selection_point_cloud_outliers(propthreshold=0.8, knearest=32)
    ms.meshing_remove_selected_vertices()
    ms.compute_normal_for_point_clouds(k=10)
    if oracle is not None:
        cv, cn, sigma = oracle
        v = ms.current_mesh().vertex_matrix()
        n = ms.current_mesh().vertex_normal_matrix()
        d, i = cKDTree(cv).query(v)
        keep = d <= 3 * sigma
        flip = np.einsum("ij,ij->i", n, cn[i]) < 0
        n[flip] *= -1
        ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v[keep], v_normals_matrix=n[keep]))
    ms.generate_surface_reconstruction_screened_poisson(depth=depth, preclean=True)
    ms.meshing_remove_connected_component_by_diameter(
        mincomponentdiag=pymeshlab.PercentageValue(20)
    )
    decimate(ms, ms.current_mesh_id(), vertices)
    ms.save_current_mesh(str(out))
    return ms.current_mesh().vertex_number(), time.perf_counter() - t


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("noisy", type=pathlib.Path)
    p.add_argument("clean", type=pathlib.Path)
    p.add_argument("fit", type=pathlib.Path)
    p.add_argument("--subfit", default="subfit")
    p.add_argument("--depth", type=int, default=9)
    p.add_argument("--noise", type=float, default=0.003, help="σ / clean diagonal")
    a = p.parse_args()
    report = json.loads((a.fit / "report.json").read_text())
    cp = sum(1 for line in (a.fit / "control.obj").open() if line.startswith("v "))
    rows = []
    ours = compare(a.subfit, a.fit / "control.obj", a.clean, "auto")
    rows.append(("subfit (limit surface)", cp, report.get("timings_s", {}).get("total"), ours))
    cv, cn, diagonal = clean_vertices(a.clean)
    for name, oracle in (("MeshLab", None), ("oracle", (cv, cn, a.noise * diagonal))):
        out = a.fit / f"poisson_qem_{name.lower()}.obj"
        v, secs = poisson_qem(a.noisy, cp, a.depth, oracle, out)
        rows.append((f"Poisson+QEM ({name})", v, secs, compare(a.subfit, out, a.clean)))
    print(f"{a.noisy.name} vs {a.clean.name}:")
    for name, v, secs, c in rows:
        s = f"{secs:6.1f} s" if isinstance(secs, (int, float)) else "      ?"
        print(
            f"  {name:32} {v:6d} vertices {s}  two-sided RMS {c['two_sided_rms_fraction']:.2e}"
            f"  Hausdorff {c['hausdorff_fraction']:.2e}  (of the clean diagonal)"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
