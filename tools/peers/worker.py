"""One peer of one entry, run in a process of its own by peers.py, so a crash of a native
library (MeshLab, Instant Meshes, QuadriFlow) or their printing to stdout touches nothing but
this entry's log:

    python3 worker.py PEER JOB.json RESULT.json

JOB.json is written by peers.py (see `peers.entry_job`); RESULT.json receives the peer's row of
peers.json without `entry` and `peer` (error rows included: any exception becomes `error`).
"""
import json
import pathlib
import shutil
import sys
import time
import traceback

from meshes import (
    atomic_write_text,
    connectivity,
    euler_and_loops,
    read_obj_polygons,
    split_nonmanifold_vertices,
    write_obj,
)

SURFACE = "poisson-surface.ply"
"""The full-resolution Poisson surface of a point cloud, the remeshers' input."""

PEERS = ("poisson-qem", "instant-meshes", "quadriflow")


def outputs(peer):
    """The files and folders a peer writes into its entry's folder."""
    if peer == "poisson-qem":
        names = ["poisson-qem.ply", "poisson-qem-trimmed.ply", "poisson-qem-untrimmed.ply"]
        return names + [SURFACE, SURFACE + ".json"]
    return [f"{peer}.obj", f"{peer}-remesh.obj", f"{peer}-fit"]


def clear(peer, entry_dir):
    """Remove a peer's outputs of an earlier run, so a failing run leaves none behind."""
    for name in outputs(peer):
        path = entry_dir / name
        if path.is_dir():
            shutil.rmtree(path)
        else:
            path.unlink(missing_ok=True)


def poisson_qem(job, entry_dir):
    """The Poisson + QEM peer: writes poisson-qem.ply (and, for an open input, the other variant
    of trimming as poisson-qem-trimmed.ply or poisson-qem-untrimmed.ply); for a point cloud also
    the full Poisson surface the remeshers start from."""
    import poisson_qem as pq

    start = time.perf_counter()
    ms = pq.load(job["input_ply"], job["kind"])
    open_input = pq.is_open(ms)
    pq.reconstruct(ms, job["depth"], job["threads"])
    poisson_vertices = ms.current_mesh().vertex_number()
    pq.remove_small_components(ms)
    closed_id = ms.current_mesh_id()
    notes = [f"screened Poisson depth {job['depth']}: {poisson_vertices} vertices"]
    variants = {"untrimmed": closed_id}
    if open_input:
        threshold = pq.trim_by_density(ms, job["trim_quantile"])
        variants["trimmed"] = ms.current_mesh_id()
        notes.append(
            f"trimming below density {threshold:.3f} (quantile {job['trim_quantile']}) "
            f"left {ms.current_mesh().vertex_number()} vertices"
        )
    keep = "trimmed" if open_input and job["category"] in ("open", "range") else "untrimmed"
    notes.append(f"kept the {keep} surface")
    if job["kind"] == "points":
        ms.set_current_mesh(variants[keep])
        pq.save_ply(ms, entry_dir / SURFACE)
        surface = {"seconds": time.perf_counter() - start, "variant": keep}
        atomic_write_text(entry_dir / (SURFACE + ".json"), json.dumps(surface))
    target = job["vertices"]
    got = pq.decimate(ms, variants[keep], target)
    pq.save_ply(ms, entry_dir / "poisson-qem.ply")
    seconds = time.perf_counter() - start
    row = mesh_row(ms, "poisson-qem.ply", seconds)
    notes.append(f"quadric edge collapse to {got} vertices (asked {target})")
    del variants[keep]
    for name, mesh_id in variants.items():
        other = pq.decimate(ms, mesh_id, target)
        pq.save_ply(ms, entry_dir / f"poisson-qem-{name}.ply")
        notes.append(f"poisson-qem-{name}.ply: the other variant, {other} vertices")
    row["note"] = "; ".join(notes)
    return row


def mesh_row(ms, file, seconds):
    """The figures of MeshLab's current mesh, a triangle mesh judged as itself."""
    m = ms.current_mesh()
    figures = connectivity(m.face_matrix().tolist(), m.vertex_number())
    return {"kind": "mesh", "scheme": None, "file": file, "seconds": seconds, **figures}


def remesher_input(job, entry_dir, scratch):
    """The surface a remesher starts from: the model itself for a mesh, the Poisson surface
    for a point cloud. Returns `(V, F, open?, OBJ path, seconds already spent, note)`."""
    import poisson_qem as pq

    seconds, note = 0.0, None
    if job["kind"] == "points":
        path = entry_dir / SURFACE
        if not path.exists():
            raise RuntimeError("a point cloud: the remeshers need its Poisson surface (failed)")
        sidecar = json.loads((entry_dir / (SURFACE + ".json")).read_text())
        seconds = sidecar["seconds"]
        note = f"remeshed the {sidecar['variant']} Poisson surface ({seconds:.1f} s of the total)"
        ms = pq.load(path, "mesh")
    else:
        ms = pq.load(job["input_ply"], "mesh")
    m = ms.current_mesh()
    obj = scratch / "surface.obj"
    ms.save_current_mesh(str(obj), save_vertex_normal=False, save_vertex_color=False)
    return m.vertex_matrix(), m.face_matrix(), pq.is_open(ms), obj, seconds, note


def remesher(peer, job, entry_dir):
    """A remeshing peer: remesh (`<peer>-remesh.obj`), fit as a Catmull-Clark cage by least
    squares (`<peer>-fit/`), copy the cage to `<peer>.obj`."""
    import remesh

    scratch = entry_dir / ".scratch"
    scratch.mkdir(exist_ok=True)
    V, F, open_surface, obj, seconds, surface_note = remesher_input(job, entry_dir, scratch)
    start = time.perf_counter()
    if peer == "instant-meshes":
        out = remesh.instant_meshes(obj, job["vertices"], scratch / "raw.obj", open_surface)
        what = "Instant Meshes quad-dominant remesh"
    else:
        out = remesh.quadriflow(V, F, job["vertices"], open_surface)
        what = "QuadriFlow pure-quad remesh"
    RV, faces, requests = out
    RV, faces, copies = split_nonmanifold_vertices(RV, faces)
    remesh_file = entry_dir / f"{peer}-remesh.obj"
    write_obj(remesh_file, RV, faces)
    remesh_seconds = time.perf_counter() - start
    as_points = False
    if job["kind"] == "mesh":
        mine, theirs = euler_and_loops(faces, len(RV)), euler_and_loops(F.tolist(), len(V))
        as_points = mine != theirs
    with open(entry_dir / "log.txt", "a") as log:
        control, fit_summary = remesh.fit_cage(
            job["subfit"], job["input"], remesh_file, entry_dir / f"{peer}-fit", log,
            as_points, job["fit_method"],
        )  # fmt: skip
    seconds += time.perf_counter() - start
    shutil.copyfile(control, entry_dir / f".{peer}.obj.tmp")
    (entry_dir / f".{peer}.obj.tmp").replace(entry_dir / f"{peer}.obj")
    CV, cage = read_obj_polygons(entry_dir / f"{peer}.obj")
    figures = connectivity(cage, len(CV))
    notes = [
        f"{what}: asked {job['vertices']} vertices (requests {requests}), "
        f"got {len(RV)} vertices / {len(faces)} faces in {remesh_seconds:.1f} s",
        f"{fit_summary} (flags: {' '.join(remesh.fit_flags(job['fit_method']))})",
    ]
    if surface_note:
        notes.insert(0, surface_note)
    if copies:
        notes.append(f"split {copies} non-manifold vertices of the remesh (one copy per fan)")
    if as_points:
        notes.append(
            f"the remesh's (Euler characteristic, boundary loops) {mine} differ from the "
            f"model's {theirs}: fitted to the model's points (--as-points)"
        )
    return {
        "kind": "limit",
        "scheme": "catmull-clark",
        "file": f"{peer}.obj",
        "seconds": seconds,
        **figures,
        "note": "; ".join(notes),
    }


def run(peer, job):
    """The peer's row (without `entry`/`peer`); `file` relative to the entry's folder."""
    entry_dir = pathlib.Path(job["entry_dir"])
    if peer == "poisson-qem":
        return poisson_qem(job, entry_dir)
    return remesher(peer, job, entry_dir)


def main(argv):
    peer, job_path, result_path = argv[1:4]
    job = json.loads(pathlib.Path(job_path).read_text())
    start = time.perf_counter()
    try:
        row = run(peer, job)
        row["error"] = None
    except Exception as e:  # every failure becomes the row's error, never a crash
        traceback.print_exc()
        row = {"error": f"{type(e).__name__}: {e}", "seconds": time.perf_counter() - start}
    sys.stdout.flush()
    atomic_write_text(result_path, json.dumps(row))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
