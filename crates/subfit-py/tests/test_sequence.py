"""``subfit.fit_sequence``: one cage over a short deforming sequence of point clouds pulled
from a generator — same connectivity every frame, each frame within tolerance of its own
ellipsoid, outputs written, errors raised."""

import json

import numpy as np
import pytest

import subfit

from conftest import ellipsoid_cloud, ellipsoid_distance

AXES = np.array([0.25, 0.5, 1.0])


def frame_axes(t: int):
    """The ellipsoid of frame ``t``: it thickens and shortens a little per frame."""
    return AXES * np.array([1 + 0.03 * t, 1 + 0.02 * t, 1 - 0.02 * t])


def frames(count: int, pulled: list):
    for t in range(count):
        pulled.append(t)
        points, _ = ellipsoid_cloud(6000, seed=10 + t, axes=frame_axes(t))
        yield points


def test_a_sequence_of_clouds_keeps_one_cage_and_fits_every_frame(tmp_path):
    pulled: list = []
    seen: list = []
    seq = subfit.fit_sequence(
        frames(3, pulled), control_points=150, silhouette_views=2,
        silhouette_resolution=48, progress=seen.append,
    )
    assert pulled == [0, 1, 2]
    assert [s["frame"] for s in seen] == [0, 1, 2]
    assert seq.vertices.shape[0] == 3 and seq.vertices.shape[2] == 3
    assert seq.vertices.shape[1] <= 150
    assert len(seq.report["frames"]) == 3
    for t in range(3):
        f = seq.report["frames"][t]
        assert f["two_sided"]["e_rms_fraction_of_diagonal"] < 1e-3, f["two_sided"]
        # The limit surface of each frame against its own ellipsoid (exact distances).
        d = ellipsoid_distance(seq.surface(t).sample(3), frame_axes(t))
        diag = 2 * np.linalg.norm(frame_axes(t))
        assert np.sqrt(np.mean(d**2)) < 1e-3 * diag
    out = seq.save(tmp_path / "seq", fps=30)
    names = sorted(p.name for p in out.iterdir())
    assert names == ["frame_0000.obj", "frame_0001.obj", "frame_0002.obj", "report.json", "sequence.usda"]
    assert json.loads((out / "report.json").read_text())["frames_fitted"] == 3
    back = subfit.read(out / "frame_0002.obj")
    assert np.allclose(back.vertices, seq.vertices[2])


def test_a_bad_frame_is_named_and_raised():
    def bad():
        yield ellipsoid_cloud(3000, seed=1)[0]
        yield np.zeros((5, 2))

    with pytest.raises(ValueError, match="frame 1"):
        subfit.fit_sequence(bad(), control_points=60, silhouette_views=0)


def test_a_raising_progress_callback_stops_the_run():
    def stop(_):
        raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        subfit.fit_sequence(frames(3, []), control_points=60, silhouette_views=0, progress=stop)


def test_tracking_runs_by_default_and_track_nodes_zero_turns_it_off():
    for nodes, expect in [(30, True), (0, False)]:
        seq = subfit.fit_sequence(
            frames(2, []), control_points=80, silhouette_views=0, track_nodes=nodes,
        )
        f = seq.report["frames"][1]
        assert (f["tracking"] is not None) == expect, f.get("tracking")
        if expect:
            assert f["tracking"]["matched"] > 0
            assert f["tracking"]["rms_after"] <= f["tracking"]["rms_before"]
    with pytest.raises(ValueError, match="track_nodes"):
        subfit.fit_sequence(frames(1, []), control_points=60, track_nodes=-1)


def marker_rows(count: int):
    """Four markers on the ellipsoid's axes, at their places in frames 0..count-1."""
    rows = []
    for t in range(count):
        ax = frame_axes(t)
        for name, p in [("x+", (ax[0], 0, 0)), ("x-", (-ax[0], 0, 0)),
                        ("z+", (0, 0, ax[2])), ("z-", (0, 0, -ax[2]))]:
            rows.append((t, name, tuple(float(c) for c in p)))
    return rows


def test_markers_as_rows_or_a_file_reach_the_tracking(tmp_path):
    path = tmp_path / "markers.csv"
    path.write_text("frame,marker,x,y,z\n" + "".join(
        f"{t},{n},{p[0]},{p[1]},{p[2]}\n" for t, n, p in marker_rows(2)))
    for markers in [marker_rows(2), path, str(path)]:
        seq = subfit.fit_sequence(
            frames(2, []), control_points=80, silhouette_views=0, markers=markers,
        )
        tracking = seq.report["frames"][1]["tracking"]
        assert tracking["markers"] == 4, tracking
        # The markers are pulled to their places (normalized units of the first frame).
        assert tracking["marker_rms"] < 0.02, tracking


def test_bad_markers_are_refused_with_the_reason(tmp_path):
    with pytest.raises(ValueError, match="tracking step"):
        subfit.fit_sequence(frames(2, []), control_points=60, track_nodes=0,
                            markers=marker_rows(2))
    with pytest.raises(ValueError, match='"late" is not in the first frame'):
        subfit.fit_sequence(frames(2, []), control_points=60,
                            markers=marker_rows(2) + [(1, "late", (0.0, 0.0, 0.0))])
    bad = tmp_path / "bad.csv"
    bad.write_text("frame,marker,x,y,z\n0,a,1,2\n")
    with pytest.raises(ValueError, match="bad.csv:2: expected 5 fields"):
        subfit.fit_sequence(frames(2, []), control_points=60, markers=bad)
    with pytest.raises(ValueError, match="markers must be"):
        subfit.fit_sequence(frames(2, []), control_points=60, markers=[1, 2, 3])
