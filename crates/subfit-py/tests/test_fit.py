"""subfit.fit on a sampled ellipsoid: the budget, the distance to the ellipsoid, the Fit object."""

import json
import pickle
import warnings

import numpy as np
import pytest

import subfit
from conftest import AXES, ellipsoid_cloud, ellipsoid_distance


def test_fit_ellipsoid_within_budget_and_tolerance(fitted):
    assert fitted.num_control_points <= 1500
    assert fitted.scheme == "loop"
    assert fitted.vertices.shape[1] == 3 and fitted.vertices.dtype == np.float64
    assert isinstance(fitted.faces, np.ndarray) and fitted.faces.shape[1] == 3
    samples = fitted.surface().sample(3)
    d = ellipsoid_distance(samples)
    assert d.max() < 5e-3, d.max()
    assert fitted.reached
    assert fitted.report["control_points"] == fitted.num_control_points
    assert fitted.report["final"]["two_sided"]["e_rms"] <= 5e-4


def test_small_budget_is_honoured():
    points, _ = ellipsoid_cloud(5000, seed=2)
    f = subfit.fit(points, max_control_points=300, tolerance=1e-4, max_iterations=20)
    assert f.num_control_points <= 300


def test_fit_pickles_as_plain_data(fitted):
    g = pickle.loads(pickle.dumps(fitted))
    assert g == fitted
    assert g.report == fitted.report
    assert g._native is None
    np.testing.assert_array_equal(g.tags["crease_edges"], fitted.tags["crease_edges"])


def test_save_writes_the_cli_outputs_and_report_equals_json(fitted, tmp_path):
    fitted.save(tmp_path / "out")
    for name in ["control.obj", "control.usda", "limit.ply", "error.ply", "log.csv", "report.json"]:
        assert (tmp_path / "out" / name).is_file(), name
    assert json.loads((tmp_path / "out" / "report.json").read_text()) == fitted.report
    cage = subfit.read(tmp_path / "out" / "control.obj")
    np.testing.assert_allclose(cage.vertices, fitted.vertices, rtol=0, atol=1e-12)


def test_fit_from_a_file_and_progress(tmp_path):
    points, normals = ellipsoid_cloud(3000, seed=3)
    path = tmp_path / "cloud.ply"
    subfit.write(path, points, normals=normals, binary=True)
    events = []
    f = subfit.fit(path, tolerance=2e-3, max_control_points=400, progress=events.append)
    assert f.num_control_points <= 400
    kinds = {e["event"] for e in events}
    assert {"step", "iteration"} <= kinds
    assert f.report["target"] == str(path)
    assert f.report["target_points"] == 3000


def test_a_raising_progress_callback_stops_the_fit():
    points, _ = ellipsoid_cloud(3000, seed=4)

    class Stop(Exception):
        pass

    def cb(e):
        if e["event"] == "iteration":
            raise Stop()

    try:
        subfit.fit(points, max_control_points=400, progress=cb)
    except Stop:
        pass
    else:
        raise AssertionError("the callback's exception did not propagate")


def test_catmull_clark_scheme():
    points, _ = ellipsoid_cloud(4000, seed=5)
    # Catmull-Clark cages are refined locally like Loop ones (no more "Loop cages only"
    # warning); the warnings that remain still reach Python's warnings module.
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        f = subfit.fit(points, scheme="catmull-clark", tolerance=2e-3, max_control_points=800, max_iterations=30)
    assert not [w for w in caught if "Loop cages only" in str(w.message)]
    assert f.scheme == "catmull-clark"
    s = f.surface().sample(2)
    assert ellipsoid_distance(s).max() < 2e-2


def test_quads_only_gives_an_all_quad_cage_and_bad_layouts_are_refused():
    points, _ = ellipsoid_cloud(3000, seed=7)
    f = subfit.fit(points, quads="only", max_control_points=150, max_iterations=10)
    sizes = {len(face) for face in f.faces}
    assert sizes == {4}, sizes
    assert len(f.vertices) <= 150
    assert f.scheme == "catmull-clark"
    with pytest.raises(ValueError, match="quads must be"):
        subfit.fit(points, quads="hexagons", max_control_points=150)


def test_facing_is_an_option_and_reaches_the_report(fitted):
    # A mesh target (the fitted tessellation): facing foot points apply to meshes.
    pos, tris = fitted.surface().tessellation(2)
    # None: left to the default, which is on (as `subfit fit`; `--no-facing` is False).
    for facing in (False, None):
        given = {} if facing is None else {"facing": facing}
        m = subfit.fit(pos, faces=tris, max_control_points=600, max_iterations=10, **given)
        assert m.report["options"]["facing"] is (facing is None)
        assert ellipsoid_distance(m.surface().sample(2)).max() < 1e-2


def test_chordal_fits_the_part_a_coarse_export_stands_for():
    # A cylinder of radius 1 exported with 16 segments, capped by fans: the chordal fit's
    # limit surface lies closer to the true cylinder than the facets (at mid-height).
    m, h = 16, 2.0
    angles = 2 * np.pi * np.arange(m) / m
    ring = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    pos = np.concatenate(
        [np.c_[ring, np.zeros(m)], np.c_[ring, np.full(m, h)], [[0, 0, 0], [0, 0, h]]]
    )
    tris = []
    for i in range(m):
        j = (i + 1) % m
        tris += [[i, j, m + j], [i, m + j, m + i], [2 * m, j, i], [2 * m + 1, m + i, m + j]]
    tris = np.array(tris)
    plain = subfit.fit(pos, faces=tris)
    curved = subfit.fit(pos, faces=tris, chordal=True)
    assert plain.report["options"]["chordal_levels"] is None
    assert curved.report["options"]["chordal_levels"] == 4
    assert curved.num_control_points <= len(pos)

    def radial_error(f):
        p = f.surface().sample(3)
        side = np.abs(p[:, 2] - h / 2) < 0.25 * h
        return np.sqrt(np.mean((np.hypot(p[side, 0], p[side, 1]) - 1.0) ** 2))

    assert radial_error(curved) < 0.5 * radial_error(plain)


def test_mesh_target_and_given_initial_cage(fitted):
    # A dense triangle mesh (the fitted limit tessellation) as the target.
    pos, tris = fitted.surface().tessellation(3)
    m = subfit.fit(pos, faces=tris, tolerance=1e-3, max_control_points=1500, max_iterations=30)
    assert m.num_control_points <= 1500
    assert ellipsoid_distance(m.surface().sample(2)).max() < 5e-3
    # Refit the points starting from a given cage (no refinement: the cage is kept).
    points, _ = ellipsoid_cloud(4000, seed=6)
    g = subfit.fit(points, init=m.surface(), refine=False, max_iterations=10, tolerance=1e-3)
    assert g.num_control_points == m.num_control_points
    np.testing.assert_array_equal(g.faces, m.faces)
    with pytest.raises(ValueError, match="control_points"):
        subfit.fit(points, init=m, control_points=100)
    # Local enrichment's thresholds are checked before anything is fitted.
    with pytest.raises(ValueError, match="local_field_share"):
        subfit.fit(points, local_field_share=1.5)
    with pytest.raises(ValueError, match="local_field_peak"):
        subfit.fit(points, local_field_peak=0.4)


def test_curvature_line_start_on_an_open_patch():
    # Half of a cylinder (one boundary loop, four corners): Lavoué et al.'s cage of the boundary
    # curve's control points, fitted with the quad/triangle scheme; "qem" is the other start.
    n = 24
    a, z = np.meshgrid(np.linspace(0.0, np.pi, n), np.linspace(0.0, 1.0, n))
    pos = np.stack([0.5 * np.cos(a), 0.5 * np.sin(a), z], axis=-1).reshape(-1, 3)
    idx = np.arange(n * n).reshape(n, n)
    quads = np.stack([idx[:-1, :-1], idx[:-1, 1:], idx[1:, 1:], idx[1:, :-1]], -1).reshape(-1, 4)
    tris = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    f = subfit.fit(pos, faces=tris, scheme="quad-tri", init="curvature-lines", tolerance=2e-3)
    assert f.report["init"]["source"] == "CurvatureLines"
    assert f.report["init"]["curvature_lines"]["corners"] == 4
    assert f.report["init"]["control_points"] <= 30
    assert f.reached
    q = subfit.fit(pos, faces=tris, scheme="quad-tri", init="qem", tolerance=2e-3)
    assert q.report["init"]["source"] == "Mesh"
    with pytest.raises(ValueError, match="curvature-lines"):
        subfit.fit(pos, faces=tris, init="lines")
    # Loop needs triangles: said before anything is fitted.
    with pytest.raises(ValueError, match="quad-tri"):
        subfit.fit(pos, faces=tris, scheme="loop", init="curvature-lines")


def test_imls_method_as_the_cli():
    # The IMLS distance of Xie et al. 2023 through the same pipeline as `subfit fit --method
    # imls`: the report says which method and radius, and the cage lies on the ellipsoid.
    points, normals = ellipsoid_cloud(4000, seed=5)
    f = subfit.fit(
        points, normals=normals, method="imls", imls_radius=0.02, arap=0.01,
        tolerance=2e-3, max_control_points=400, max_iterations=30,
    )
    assert f.report["options"]["method"] == "IMLS"
    assert f.report["options"]["imls_radius"] == pytest.approx(0.02)
    assert f.report["options"]["arap"] == pytest.approx(0.01)
    d = ellipsoid_distance(f.surface().sample(2))
    assert d.max() < 2e-2, d.max()
    with pytest.raises(ValueError, match="imls"):
        subfit.fit(points, method="nope")
    with pytest.raises(ValueError, match="imls-radius"):
        subfit.fit(points, imls_radius=0.02)


_PLY_TYPES = {"char": "i1", "uchar": "u1", "short": "i2", "ushort": "u2", "int": "i4", "uint": "u4",
              "float": "f4", "double": "f8", "int8": "i1", "uint8": "u1", "int16": "i2", "uint16": "u2",
              "int32": "i4", "uint32": "u4", "float32": "f4", "float64": "f8"}


def ply_face_sizes(path):
    """``{corners: faces}`` of a binary little-endian PLY, read here from its header and bytes
    (independently of ``subfit.read``, which turns uniform faces into an array)."""
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    assert "format binary_little_endian 1.0" in header, header[:2]
    elements = []  # (name, count, [("scalar", type) | ("list", count_type, item_type)])
    for line in header:
        w = line.split()
        if w[0] == "element":
            elements.append((w[1], int(w[2]), []))
        elif w[0] == "property":
            elements[-1][2].append(("list", w[2], w[3]) if w[1] == "list" else ("scalar", w[1]))
    pos, sizes = end, {}
    for name, count, props in elements:
        if all(p[0] == "scalar" for p in props):  # fixed-size rows
            pos += count * sum(np.dtype(_PLY_TYPES[p[1]]).itemsize for p in props)
            continue
        assert name == "face" and len(props) == 1, (name, props)
        count_t = np.dtype("<" + _PLY_TYPES[props[0][1]])
        item_size = np.dtype(_PLY_TYPES[props[0][2]]).itemsize
        for _ in range(count):
            k = int(np.frombuffer(data, count_t, 1, pos)[0])
            sizes[k] = sizes.get(k, 0) + 1
            pos += count_t.itemsize + k * item_size
    assert pos == len(data), f"{path.name}: {len(data) - pos} bytes left after the elements"
    return sizes


def test_save_limit_quads_keeps_quads_only_when_asked(fitted, tmp_path):
    # A Catmull-Clark fit's limit tessellation is quads: split into triangles by default (the
    # CLI's default), kept with limit_quads=True (`subfit fit --limit-quads`).
    points, normals = ellipsoid_cloud(4000, seed=5)
    cc = subfit.fit(points, normals=normals, scheme="catmull-clark", tolerance=2e-3,
                    max_control_points=400, max_iterations=10)
    tri = ply_face_sizes(cc.save(tmp_path / "tri") / "limit.ply")
    quad = ply_face_sizes(cc.save(tmp_path / "quad", limit_quads=True) / "limit.ply")
    assert set(tri) == {3}, tri
    assert 4 in quad and set(quad) <= {3, 4}, quad
    # The same surface: every quad became two triangles.
    assert tri[3] == 2 * quad[4] + quad.get(3, 0)
    assert ply_face_sizes(tmp_path / "quad" / "error.ply") == quad
    assert ply_face_sizes(tmp_path / "tri" / "error.ply") == tri
    # A Loop fit's tessellation is triangles whatever is asked.
    assert set(ply_face_sizes(fitted.save(tmp_path / "loop", limit_quads=True) / "limit.ply")) == {3}
