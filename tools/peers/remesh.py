"""The two remeshing peers and the fit that turns a remesh into a Catmull-Clark cage.

* Instant Meshes (Jakob et al. 2015, "Instant field-aligned meshes"), through pyinstantmeshes:
  a quad-dominant remesh at a vertex count, written by Instant Meshes itself (its OBJ keeps the
  polygons; the package's array result is a triangulation of it).
* QuadriFlow (Huang et al. 2018, "QuadriFlow: a scalable and robust method for quadrangulation"),
  through pyquadriflow's compiled library: a pure-quad remesh at a face count.
* The fit: `subfit fit` with the remesh as the initial cage and every connectivity-changing step
  off, so the cage's points are placed by least squares (PDM, Cheng et al. 2007 §II-D1) on its
  own connectivity — the step a user would add to make a remesh a subdivision surface.

Remeshers hit a count only roughly: a result more than `COUNT_SLACK` away from the request is
remeshed again with a corrected request, and the closest result is kept.
"""
import ctypes
import json
import shutil
import subprocess

import numpy as np

from meshes import compact, read_obj_polygons

COUNT_SLACK = 0.05
"""Relative miss of the requested vertex count (dimensionless) above which a remesh is redone
with the request scaled by requested / obtained."""

ATTEMPTS = 3
"""Remeshes at most per peer (the first and two corrections)."""

def fit_flags(method="pdm"):
    """`subfit fit` flags of the peers' fit: least squares at fixed connectivity. `method`
    `pdm` (the default: point distance minimization, plain least squares) or `sdm` (Cheng et
    al.'s squared distance, subfit's own error term, to separate connectivity from fitting)."""
    return [
        "--scheme", "catmull-clark",
        "--no-refine",            # keep the remesh's connectivity: no splits, no edge flips
        "--no-quad-dominant",     # do not pair the remesh's triangles into quads
        "--no-features",          # a smooth cage: no crease or corner tags
        "--method", method,       # pdm: point distance minimization, plain least squares
        "--lambda", "1e-4",       # light umbrella smoothing, lowered per stage to 1e-5
        "--polish-power", "2",    # no reweighted (L^p) polish: least squares to the end
    ]  # fmt: skip


def closest_of(attempt, requested):
    """Run `attempt(request) -> (V, faces)` until the vertex count is within `COUNT_SLACK` of
    `requested` or `ATTEMPTS` are spent, correcting the request by the measured ratio. Returns
    `(V, faces, requests)` of the closest result."""
    best, request, requests = None, requested, []
    for _ in range(ATTEMPTS):
        requests.append(request)
        V, faces = attempt(request)
        if len(V) == 0:
            raise RuntimeError(f"the remesher returned an empty mesh for a request of {request}")
        if best is None or abs(len(V) - requested) < abs(len(best[0]) - requested):
            best = (V, faces)
        if abs(len(V) - requested) <= COUNT_SLACK * requested:
            break
        request = max(4, round(request * requested / len(V)))
        if request in requests:
            break
    return best[0], best[1], requests


def instant_meshes(surface_obj, vertices, raw_obj, open_surface):
    """Instant Meshes' quad-dominant remesh of the mesh in `surface_obj` (OBJ) at about
    `vertices` vertices, with the settings of its command line's defaults (extrinsic, 2
    smoothing steps, rotational and positional symmetry 4), deterministic, aligned to the
    boundary for an open surface. `raw_obj` is a scratch path for Instant Meshes' own output.
    Returns `(V, faces, requests)` (faces: polygons, unused vertices dropped)."""
    import pyinstantmeshes

    def attempt(request):
        pyinstantmeshes.remesh_file(
            str(surface_obj),
            str(raw_obj),
            target_vertex_count=request,
            extrinsic=True,
            align_to_boundaries=open_surface,
            smooth_iterations=2,
            deterministic=True,
        )
        return compact(*read_obj_polygons(raw_obj))

    return closest_of(attempt, vertices)


def _quadriflow_call(V, F, faces, preserve_boundary, seed):
    """One call of QuadriFlow's C entry point on numpy buffers. pyquadriflow's Python wrapper
    copies every vertex through Python lists; this passes the arrays directly to the same
    library with the same signature and frees the result the same way."""
    from pyQuadriFlow import pyQuadriFlow as qf

    lib = qf.QuadriFlow_clib
    remesh = lib.remesh_quadriflow
    remesh.argtypes = [ctypes.c_int] * 4 + [
        ctypes.POINTER(ctypes.c_float * 3),
        ctypes.POINTER(ctypes.c_int * 3),
    ] + [ctypes.c_bool] * 5
    remesh.restype = ctypes.POINTER(qf.MESH_DATA)
    lib.free_mem.argtypes = [ctypes.POINTER(qf.MESH_DATA)]
    V32 = np.ascontiguousarray(V, dtype=np.float32)
    F32 = np.ascontiguousarray(F, dtype=np.int32)
    result = remesh(
        faces, seed, len(V32), len(F32),
        V32.ctypes.data_as(ctypes.POINTER(ctypes.c_float * 3)),
        F32.ctypes.data_as(ctypes.POINTER(ctypes.c_int * 3)),
        False, preserve_boundary, False, False, False,
    )  # fmt: skip
    data = result.contents
    if data.has_error:
        message = data.str_error.decode("ascii", "replace") if data.str_error else "?"
        lib.free_mem(result)
        raise RuntimeError(f"QuadriFlow: {message}")
    n, m = data.nn_verts, data.nn_faces
    floats, ints = ctypes.POINTER(ctypes.c_float), ctypes.POINTER(ctypes.c_int)
    out_v = np.ctypeslib.as_array(ctypes.cast(data.vertices, floats), (n * 3,))
    out_f = np.ctypeslib.as_array(ctypes.cast(data.faces, ints), (m * 4,))
    out_v, out_f = out_v.reshape(n, 3).astype(np.float64), out_f.reshape(m, 4).tolist()
    lib.free_mem(result)
    return compact(out_v, out_f)


def quadriflow(V, F, vertices, open_surface, seed=0):
    """QuadriFlow's pure-quad remesh of the triangle mesh (`V` #V by 3, `F` #F by 3) at about
    `vertices` vertices. QuadriFlow takes a face count; a closed quad mesh has about as many
    faces as vertices (V - F = 2 - 2·genus), so the first request is `vertices` faces. Default
    QuadriFlow settings (no sharp-edge preservation, no adaptive scale, plain SAT and flow
    solvers), boundaries preserved on an open surface, fixed seed.
    Returns `(V, faces, requests)`."""

    def attempt(request):
        return _quadriflow_call(V, F, request, open_surface, seed)

    return closest_of(attempt, vertices)


def fit_cage(subfit, target, init, out_dir, log, as_points=False, method="pdm"):
    """Fit the cage `init` to `target` by `subfit fit` with `fit_flags(method)` into `out_dir`; its
    output goes to the open file `log`. `as_points`: fit to the target's points only (subfit
    refuses a cage whose topology differs from a mesh target's; a point target has none).
    Exit code 1 (tolerance not reached, outputs written) is a result; anything else without a
    control.obj raises RuntimeError with subfit's last lines.
    Returns `(control.obj path, short summary from report.json)`."""
    cmd = [str(subfit), "fit", str(target), "--init", str(init), *fit_flags(method)]
    cmd += ["-o", str(out_dir)]
    if as_points:
        cmd.append("--as-points")
    n_init = len(read_obj_polygons(init)[0])
    if n_init > 5000:  # subfit's default budget would refuse the cage
        cmd += ["--max-control-points", str(n_init)]
    if out_dir.exists():
        shutil.rmtree(out_dir)
    log.write("$ " + " ".join(cmd) + "\n")
    log.flush()
    run = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    log.write(run.stdout)
    log.flush()
    control = out_dir / "control.obj"
    if run.returncode not in (0, 1) or not control.exists():
        tail = " | ".join(run.stdout.strip().splitlines()[-3:])
        raise RuntimeError(f"subfit fit exited with {run.returncode}: {tail}")
    summary = f"subfit fit exit {run.returncode}"
    try:
        report = json.loads((out_dir / "report.json").read_text())
        summary += f", {len(report.get('iterations', []))} iterations, stop {report.get('stop')}"
    except (OSError, ValueError):
        pass
    return control, summary
