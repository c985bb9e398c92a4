"""Shared fixtures: seeded ellipsoid clouds, a fitted ellipsoid, and optional-module gates.

Tests that need torch or dask skip with a printed notice when the module is missing, except
under ``CI=true``, where a missing module is a failure (CI installs them).
"""

import os
import sys
from pathlib import Path

import numpy as np
import pytest

import subfit

AXES = np.array([0.25, 0.5, 1.0])
REPO = Path(__file__).resolve().parents[3]


def ellipsoid_cloud(n: int, seed: int = 0, axes=AXES):
    """``n`` points on the ellipsoid with semi-axes ``axes`` and their outward unit normals."""
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    p = d * axes
    nrm = p / axes**2
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    return p, nrm


def ellipsoid_distance(q, axes=AXES):
    """Euclidean distance from ``q (k, 3)`` to the ellipsoid (Newton on the Lagrange condition
    ``Σ aᵢ² qᵢ² / (t + aᵢ²)² = 1`` for the closest point ``xᵢ = aᵢ² qᵢ / (t + aᵢ²)``)."""
    a2 = axes**2
    q = np.asarray(q, dtype=np.float64)
    outside = ((q / axes) ** 2).sum(1) >= 1
    t = np.where(outside, 0.0, -a2.min() + 1e-12)
    # Bisection-safe Newton: g(t) = Σ a² q² / (t + a²)² − 1 is decreasing for t > −min a².
    lo = np.full(len(q), -a2.min())
    hi = np.full(len(q), np.linalg.norm(q, axis=1) * axes.max() + 1.0)
    for _ in range(200):
        t = 0.5 * (lo + hi)
        g = (a2 * q**2 / (t[:, None] + a2) ** 2).sum(1) - 1
        lo = np.where(g > 0, t, lo)
        hi = np.where(g > 0, hi, t)
    x = a2 * q / (t[:, None] + a2)
    return np.linalg.norm(q - x, axis=1)


def need(module: str):
    """Imports ``module``; missing: a failure under ``CI=true``, else a skip with a notice."""
    try:
        return __import__(module)
    except ImportError:
        msg = f"{module} is not installed (pip install {module}); skipping its tests"
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(f"CI=true: {msg.replace('; skipping its tests', '')}")
        print(f"notice: {msg}", file=sys.stderr)
        pytest.skip(msg)


@pytest.fixture(scope="session")
def cloud():
    return ellipsoid_cloud(20000, seed=1)


@pytest.fixture(scope="session")
def fitted(cloud):
    points, normals = cloud
    return subfit.fit(points, normals=normals, tolerance=5e-4, max_control_points=1500)
