"""Bad input raises ValueError (or TypeError for unknown keywords) with the reason; no crash."""

import numpy as np
import pytest

import subfit
from conftest import ellipsoid_cloud

POINTS, _ = ellipsoid_cloud(2000, seed=9)


@pytest.mark.parametrize(
    "points,match",
    [
        (np.zeros((100, 2)), r"shape \(n, 3\)"),
        (np.zeros(30), r"shape \(n, 3\)"),
        (np.zeros((5, 3)), "at least 10"),
        (np.vstack([POINTS[:50], [[np.nan, 0, 0]]]), r"points\[50\] is not finite"),
        (np.vstack([POINTS[:50], [[np.inf, 0, 0]]]), "not finite"),
        ([["a", "b", "c"]] * 20, "numeric"),
    ],
)
def test_fit_bad_points(points, match):
    with pytest.raises(ValueError, match=match):
        subfit.fit(points)


@pytest.mark.parametrize(
    "kwargs,match",
    [
        ({"scheme": "butterfly"}, "scheme"),
        ({"method": "xyz"}, "method"),
        ({"tolerance": -1.0}, "tolerance"),
        ({"tolerance": float("nan")}, "tolerance"),
        ({"max_control_points": 2}, "max_control_points"),
        ({"sample_level": 9}, "sample_level"),
        ({"normals": np.ones((3, 3))}, "one row per point"),
        ({"normals": np.zeros((2000, 3))}, "zero"),
        ({"faces": np.array([[0, 1, 5000]])}, "out of range"),
        ({"faces": np.array([[0, 1]])}, "at least 3"),
        ({"faces": np.array([[0.5, 1, 2]])}, "integer"),
    ],
)
def test_fit_bad_options(kwargs, match):
    with pytest.raises(ValueError, match=match):
        subfit.fit(POINTS, **kwargs)


def test_unknown_keyword_is_a_type_error():
    with pytest.raises(TypeError):
        subfit.fit(POINTS, not_an_option=1)


def test_surface_bad_input():
    v = np.eye(3)
    with pytest.raises(ValueError, match="out of range"):
        subfit.Surface(v, [[0, 1, 3]])
    with pytest.raises(ValueError, match="triangles|Loop"):
        subfit.Surface(np.vstack([v, [[1, 1, 1]]]), [[0, 1, 3, 2]], scheme="loop")
    s = subfit.Surface(np.vstack([v, [[0, 0, 0]]]), [[0, 1, 2], [0, 3, 1], [1, 3, 2], [0, 2, 3]])
    with pytest.raises(ValueError, match="level"):
        s.sample(12)
    with pytest.raises(ValueError, match="face"):
        s.evaluate(10, 0.1, 0.1)
    with pytest.raises(ValueError, match="outside"):
        s.evaluate(0, 2.0, 0.1)
    with pytest.raises(ValueError, match="shape"):
        s.closest_point(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="not finite"):
        s.closest_point(np.full((1, 3), np.nan))


def test_import_subfit_does_not_need_torch_and_subfit_torch_says_how_to_get_it():
    import subprocess
    import sys

    code = (
        "import sys; sys.modules['torch'] = None\n"
        "import subfit; print(subfit.__version__)\n"
        "try:\n    import subfit.torch\nexcept ImportError as e:\n    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert subfit.__version__ in out and "pip install torch" in out
