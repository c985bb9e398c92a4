"""Fit a folder of scans on a Dask cluster.

    python examples/python/batch_dask.py SCANS_DIR [-o out] [--scheduler tcp://host:8786]

Without ``--scheduler`` a ``dask.distributed.LocalCluster`` on this machine is started (one
process per worker; each fit also uses subfit's own thread pool, so few workers with one
thread each are best). With it, the same code submits to an existing cluster.

On a real cluster: ``pip install ./crates/subfit-py`` (or the built wheel) into the workers'
environment, start ``dask scheduler`` and ``dask worker tcp://scheduler:8786 --nthreads 1`` on
each node (or dask-jobqueue / dask-kubernetes / Coiled), and pass ``--scheduler``. The scans'
paths must be readable by the workers (a shared file system), or read them here and submit the
arrays — ``subfit.fit`` takes plain arrays and returns a picklable ``subfit.Fit``. Ray: the same
functions run as ``ray.remote(fit_one).remote(path, out)`` tasks, or unchanged through Dask on
Ray (``ray.util.dask.enable_dask_on_ray()``).
"""

import argparse
from pathlib import Path
from typing import Any, List, NamedTuple

import subfit

SCAN_EXTENSIONS = {".ply", ".obj", ".off", ".stl", ".xyz", ".pts"}


class Result(NamedTuple):
    """One scan's result: its path, the output directory's name and the fit (plain data)."""

    path: str
    name: str
    fit: subfit.Fit


def fit_one(path: str, out_dir: str, **options: Any) -> Result:
    """Runs on a worker: fits one scan, writes its outputs into ``out_dir/<stem>``."""
    name = Path(path).stem
    f = subfit.fit(path, **options)
    f.save(Path(out_dir) / name)
    return Result(str(path), name, f)


def fit_all(client: Any, paths: List[Path], out_dir: Path, **options: Any) -> List[Result]:
    """Fits every scan on ``client``'s cluster; results in the order of ``paths``."""
    futures = client.map(fit_one, [str(p) for p in paths], out_dir=str(out_dir), pure=False, **options)
    return client.gather(futures)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scans", type=Path, help="a folder of scans")
    ap.add_argument("-o", "--output", type=Path, default=Path("subfit-batch"))
    ap.add_argument("--scheduler", help="address of a running Dask scheduler (default: a LocalCluster)")
    ap.add_argument("--workers", type=int, default=2, help="LocalCluster workers")
    ap.add_argument("--tolerance", type=float, default=5e-4)
    ap.add_argument("--max-control-points", type=int, default=5000)
    a = ap.parse_args()

    from distributed import Client, LocalCluster

    paths = sorted(p for p in a.scans.iterdir() if p.suffix.lower() in SCAN_EXTENSIONS)
    if not paths:
        raise SystemExit(f"{a.scans}: no scans ({', '.join(sorted(SCAN_EXTENSIONS))})")
    a.output.mkdir(parents=True, exist_ok=True)
    cluster = None if a.scheduler else LocalCluster(n_workers=a.workers, threads_per_worker=1)
    with Client(a.scheduler or cluster) as client:
        print(f"dashboard: {client.dashboard_link}")
        results = fit_all(client, paths, a.output, tolerance=a.tolerance, max_control_points=a.max_control_points)
    if cluster is not None:
        cluster.close()
    for r in results:
        two = r.fit.report["final"]["two_sided"]
        print(f"{r.name}: {r.fit.num_control_points} control points, two-sided E_rms {two['e_rms']:.2e}, "
              f"reached={r.fit.reached} → {a.output / r.name}/")


if __name__ == "__main__":
    main()
