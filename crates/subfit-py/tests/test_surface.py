"""subfit.Surface: the operator reproduces the samples, closest points agree with a dense
search, evaluation agrees with the operator and with finite differences."""

import pickle

import numpy as np
import pytest

import subfit


def cube():
    v = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    quads = np.array([[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]])
    return v, quads


def octahedron():
    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float)
    f = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    return v, f


@pytest.mark.parametrize("level", [0, 1, 3])
def test_operator_times_vertices_is_sample(fitted, level):
    s = fitted.surface()
    c = s.operator(level)
    assert c.shape == (len(s.sample(level)), s.num_vertices)
    np.testing.assert_allclose(c @ fitted.vertices, s.sample(level), rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.asarray(c.sum(axis=1)).ravel(), 1.0, atol=1e-12)


def test_operator_catmull_clark_cube():
    v, q = cube()
    s = subfit.Surface(v, q, scheme="catmull-clark")
    for level in (1, 2, 4):
        np.testing.assert_allclose(s.operator(level) @ v, s.sample(level), rtol=0, atol=1e-12)
    pos, faces = s.tessellation(2)
    assert faces.shape[1] == 4 and faces.max() < len(pos)


def test_closest_point_agrees_with_dense_search():
    v, f = octahedron()
    s = subfit.Surface(v, f, scheme="loop")
    rng = np.random.default_rng(7)
    q = rng.normal(size=(200, 3)) * 0.8
    cp = s.closest_point(q)
    dense = s.sample(7)  # ~65k limit points
    dd = np.sqrt(((q[:, None, :] - dense[None, :, :]) ** 2).sum(-1)).min(1)
    # The exact search is never worse than the dense one, and the dense one is within its
    # spacing (~0.02) of it.
    assert np.all(cp.distance <= dd + 1e-9)
    assert np.all(dd - cp.distance < 2e-3)
    np.testing.assert_allclose(np.linalg.norm(cp.points - q, axis=1), cp.distance, atol=1e-12)
    # The returned parameters evaluate to the returned points.
    ev = s.evaluate(cp.face, cp.u, cp.v)
    np.testing.assert_allclose(ev.position, cp.points, atol=1e-12)
    full = s.closest_point(q, full=True)
    assert full.converged.all()


def test_evaluate_matches_operator_and_finite_differences():
    v, f = octahedron()
    s = subfit.Surface(v, f)
    # Level-0 samples are the limit positions of the control points: the corners of the faces.
    lim = s.sample(0)
    e = s.evaluate(np.arange(8), 0.0, 0.0)
    np.testing.assert_allclose(e.position, lim[f[:, 0]], atol=1e-12)
    h = 1e-6
    p = s.evaluate(3, 0.2, 0.3)
    du = (s.evaluate(3, 0.2 + h, 0.3).position - s.evaluate(3, 0.2 - h, 0.3).position) / (2 * h)
    dv = (s.evaluate(3, 0.2, 0.3 + h).position - s.evaluate(3, 0.2, 0.3 - h).position) / (2 * h)
    np.testing.assert_allclose(p.du, du, atol=1e-7)
    np.testing.assert_allclose(p.dv, dv, atol=1e-7)
    assert p.position.shape == (3,) and p.second.shape == (3, 3)
    w = s.evaluation_operator([3, 4], [0.2, 0.1], [0.3, 0.1])
    np.testing.assert_allclose(w @ v, s.evaluate([3, 4], [0.2, 0.1], [0.3, 0.1]).position, atol=1e-12)


def test_surface_pickles_and_polygon_faces():
    v, q = cube()
    s = subfit.Surface(v, [list(x) for x in q], scheme="catmull-clark")
    t = pickle.loads(pickle.dumps(s))
    np.testing.assert_array_equal(t.sample(2), s.sample(2))
    # A mixed polygon mesh (a pentagon and triangles) under Catmull-Clark.
    pv = np.array([[np.cos(a), np.sin(a), 0.0] for a in np.linspace(0, 2 * np.pi, 6)[:-1]] + [[0, 0, 1.0]])
    faces = [[0, 1, 2, 3, 4]] + [[i, (i + 1) % 5, 5] for i in range(5)]
    faces[0] = faces[0][::-1]
    m = subfit.Surface(pv, faces, scheme="catmull-clark")
    assert isinstance(m.faces, list)
    np.testing.assert_allclose(m.operator(2) @ pv, m.sample(2), atol=1e-12)
    e = m.evaluate(0, 0.5, 0.5, sub=2)
    assert np.isfinite(e.position).all()


def test_callers_arrays_stay_writable_and_faces_from_any_array():
    v, f = octahedron()
    s = subfit.Surface(v, f.astype(np.int32))
    v[0, 0] = 2.0  # the caller's array is not frozen, and the surface kept its own copy
    assert s.vertices[0, 0] == 1.0 and not s.vertices.flags.writeable
    assert subfit.Surface(v, tuple(map(tuple, f))).num_faces == 8
