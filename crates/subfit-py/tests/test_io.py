"""subfit.read / subfit.write round trips and their errors."""

import numpy as np
import pytest

import subfit


@pytest.mark.parametrize("ext,binary", [("ply", False), ("ply", True), ("obj", False), ("off", False)])
def test_mesh_round_trip(tmp_path, ext, binary):
    v = np.random.default_rng(0).normal(size=(4, 3))
    f = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
    path = tmp_path / f"m.{ext}"
    subfit.write(path, v, f, binary=binary)
    m = subfit.read(path)
    np.testing.assert_allclose(m.vertices, v, atol=0, rtol=0)
    np.testing.assert_array_equal(m.faces, f)
    assert m.format == ext


def test_point_cloud_with_normals(tmp_path):
    p = np.random.default_rng(1).normal(size=(50, 3))
    n = p / np.linalg.norm(p, axis=1, keepdims=True)
    subfit.write(tmp_path / "c.xyz", p, normals=n)
    m = subfit.read(tmp_path / "c.xyz")
    assert m.faces is None
    np.testing.assert_allclose(m.normals, n, atol=1e-15)


def test_usda_cage(tmp_path):
    v = np.eye(3)
    subfit.write(tmp_path / "c.usda", np.vstack([v, [[0, 0, 0]]]), [[0, 1, 2], [0, 3, 1]], scheme="loop",
                 tags={"crease_edges": [[0, 1]]})
    text = (tmp_path / "c.usda").read_text()
    assert 'subdivisionScheme = "loop"' in text and "creaseIndices" in text


def test_read_errors(tmp_path):
    with pytest.raises(FileNotFoundError):
        subfit.read(tmp_path / "missing.ply")
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
    with pytest.raises(ValueError, match="out of range"):
        subfit.read(bad)
    with pytest.raises(ValueError, match="extension"):
        subfit.write(tmp_path / "x.unknown", np.zeros((3, 3)))
