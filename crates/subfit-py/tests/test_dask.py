"""A Dask LocalCluster batch gives the same cages as a serial loop."""

import sys

import numpy as np
import pytest

import subfit
from conftest import REPO, ellipsoid_cloud, need


def test_dask_batch_equals_serial(tmp_path):
    need("dask")
    need("distributed")
    sys.path.insert(0, str(REPO / "examples" / "python"))
    try:
        import batch_dask
    finally:
        sys.path.pop(0)
    from distributed import Client, LocalCluster

    clouds = []
    for i, axes in enumerate([(0.25, 0.5, 1.0), (0.4, 0.5, 0.8), (0.3, 0.3, 0.6)]):
        p, n = ellipsoid_cloud(3000, seed=20 + i, axes=np.array(axes))
        path = tmp_path / f"scan{i}.ply"
        subfit.write(path, p, normals=n, binary=True)
        clouds.append(path)
    options = dict(tolerance=2e-3, max_control_points=400)
    serial = [subfit.fit(p, **options) for p in clouds]
    with LocalCluster(n_workers=1, threads_per_worker=3, processes=False, dashboard_address=None) as cluster:
        with Client(cluster) as client:
            results = batch_dask.fit_all(client, clouds, tmp_path / "out", **options)
    assert [r.path for r in results] == [str(p) for p in clouds]
    for r, s in zip(results, serial):
        assert r.fit.scheme == s.scheme
        np.testing.assert_array_equal(r.fit.faces, s.faces)
        np.testing.assert_allclose(r.fit.vertices, s.vertices, rtol=0, atol=1e-9)
        assert (tmp_path / "out" / r.name / "report.json").is_file()
