"""``subfit.fit_sequence`` and its result ``subfit.Sequence``: the pipeline of
``subfit sequence`` from Python."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import _subfit
from ._arrays import Faces, FacesLike, as_float_rows, faces_from_flat, faces_to_flat, tags_from_arrays
from ._surface import Surface

PathLike = Union[str, "os.PathLike[str]"]
FrameLike = Union[PathLike, npt.ArrayLike, Tuple[npt.ArrayLike, Optional[FacesLike]]]


class Sequence:
    """One cage fitted to every frame of a deforming scan.

    Returned by :func:`subfit.fit_sequence`; ``len(sequence)`` is the number of frames. It
    holds native data and does not pickle (save it instead).

    Attributes
    ----------
    vertices : (frames, n, 3) float64
        Control points of every frame (same order, same connectivity), input coordinates.
    faces : (m, 3) or (m, 4) int64, or a list of int64 arrays
        Cage faces (every frame).
    scheme : str
        ``"loop"``, ``"catmull-clark"`` or ``"quad-tri"``.
    tags : dict
        Crease and corner tags (as :class:`subfit.Fit`).
    report : dict
        The report, equal to ``report.json``: ``report["frames"][i]["two_sided"]``,
        ``["drift"]``, ``["timings_s"]``, …
    """

    def __init__(self, nat: Any) -> None:
        offsets, indices = nat.faces()
        self.vertices = nat.vertices()
        self.faces: Faces = faces_from_flat(offsets, indices)
        self.scheme: str = nat.scheme()
        self.tags = tags_from_arrays(nat.tags())
        self.report: dict = json.loads(nat.report_json())
        self._native = nat

    def __len__(self) -> int:
        return len(self.vertices)

    def surface(self, frame: int) -> Surface:
        """Frame ``frame``'s limit surface as a :class:`subfit.Surface` (0 is the first frame;
        negative indices count from the end, as for ``vertices``). Raises ``IndexError`` for a
        frame out of range."""
        return Surface(self.vertices[frame], self.faces, self.scheme, self.tags)

    def save(self, directory: PathLike, fps: float = 24.0) -> Path:
        """Writes the outputs of ``subfit sequence`` into ``directory`` (created if missing).

        ``frame_0000.obj`` … (each frame's cage), ``sequence.usda`` (one mesh with time-sampled
        points at ``fps`` frames per second, scheme and creases: an animated cage for Blender or
        usdview) and ``report.json``.

        Parameters
        ----------
        directory : str or os.PathLike
            Where to write (created with its parents if missing; files in it are replaced).
        fps : float
            Frames per second of ``sequence.usda``'s time samples (default 24).

        Returns
        -------
        pathlib.Path
            ``directory``.

        Raises
        ------
        OSError
            A file that cannot be written.
        """
        d = Path(directory)
        d.mkdir(parents=True, exist_ok=True)
        self._native.write_into(str(d), float(fps))
        return d

    def __getstate__(self) -> dict:
        raise TypeError("a subfit.Sequence holds native data and does not pickle; save() it")

    def __repr__(self) -> str:
        worst = self.report.get("worst_rms_fraction_of_diagonal", float("nan"))
        return (
            f"Sequence({len(self)} frames, {self.vertices.shape[1]} control points, "
            f"scheme={self.scheme!r}, worst two-sided E_rms={100 * worst:.3f}% of a diagonal)"
        )


def _frames(frames: Iterable[FrameLike]) -> Iterator[tuple]:
    for i, f in enumerate(frames):
        name = f"frame {i}"
        if isinstance(f, (str, os.PathLike)):
            from ._io import read

            path = os.fspath(f)
            m = read(path)
            pts, faces, name = m.vertices, m.faces, path
        elif isinstance(f, tuple) and len(f) == 2:
            pts, faces = f
        else:
            pts, faces = f, None
        yield (
            as_float_rows(f"frame {i} points", pts),
            None if faces is None else faces_to_flat(faces),
            name,
        )


def fit_sequence(
    frames: Iterable[FrameLike],
    *,
    template: Optional[Union[Surface, Tuple[npt.ArrayLike, FacesLike]]] = None,
    control_points: Optional[int] = None,
    silhouette_views: int = 8,
    progress: Optional[Callable[[dict], Any]] = None,
    **options: Any,
) -> Sequence:
    """Fits one cage to every frame of a deforming scan: the pipeline of ``subfit sequence``.

    The template is the first frame fitted as :func:`subfit.fit` would (or ``template``, a
    cage in the first frame's coordinates); each next frame starts from the template carried
    onto it by an embedded deformation (``track_nodes`` nodes inside the body, 0: off, each
    frame then starts from the previous cage; it follows motion along the surface), and is
    fitted with the data term, smoothing, an as-rigid-as-possible term towards the template
    (as the tracking carried it) and a soft silhouette term from ``silhouette_views`` views
    (Xie et al. 2023 §4.2; 0 turns it off). Every frame's cage has the template's connectivity
    and vertex order.

    Parameters
    ----------
    frames : iterable
        Frames in order, pulled one at a time (a generator streams): each a path, an
        ``(n, 3)`` point array, or a ``(points, faces)`` pair; connectivity may differ.
    template : Surface or (vertices, faces), optional
        The template cage, in the first frame's coordinates.
    control_points : int, optional
        Size (and budget) of the template fitted to the first frame.
    silhouette_views : int
        Views of the silhouette term (0: off).
    progress : callable, optional
        Called with ``{"frame", "name", "e_rms", "e_max", "seconds"}`` after each frame; an
        exception it raises stops the run and propagates.
    **options
        The other flags of ``subfit sequence``: ``scheme`` ("auto"), ``method`` ("sdm" or
        "imls"), ``arap`` (0.01), ``lambda_`` (1e-5), ``iterations`` (12), ``tolerance``
        (5e-4), ``sample_level`` (2), ``silhouette_resolution`` (128),
        ``silhouette_weight``, ``track_nodes`` (60), ``markers``: known places of points over
        the frames (motion capture, tracked features), a path to a CSV file with the header
        ``frame,marker,x,y,z`` or rows ``(frame, name, (x, y, z))`` (frame 0 the first; every
        marker must be in frame 0); the tracking pulls them there, which pins what the
        surfaces leave free, sliding along them.

    Returns
    -------
    Sequence
        Every frame's cage (one connectivity), the scheme, tags and the report.

    Raises
    ------
    ValueError
        A bad frame (named by its index), bad options, an unusable mesh.
    RuntimeError
        Numerical failure.
    KeyboardInterrupt
        Ctrl-C (checked once per frame).

    Examples
    --------
    >>> import numpy as np, subfit
    >>> d = np.random.default_rng(0).normal(size=(2000, 3))
    >>> sphere = d / np.linalg.norm(d, axis=1, keepdims=True)
    >>> frames = (sphere * [1.0, 1.0, 1.0 + 0.1 * t] for t in range(3))  # stretching along z
    >>> seq = subfit.fit_sequence(frames, control_points=100)
    >>> len(seq), seq.vertices.shape[1] <= 100  # (frames, control points, 3)
    (3, True)
    >>> top = seq.vertices[:, :, 2].max(axis=1)  # the cage follows the stretch
    >>> bool(top[0] < top[1] < top[2])
    True
    """
    if "scheme" in options:
        options["scheme_name"] = options.pop("scheme")
    tmpl = None
    if template is not None:
        if isinstance(template, Surface):
            tv, tf = template.vertices, template.faces
        elif isinstance(template, (tuple, list)) and len(template) == 2:
            tv, tf = template
        else:
            raise ValueError("template must be a Surface or a (vertices, faces) pair")
        tmpl = (as_float_rows("template vertices", tv), faces_to_flat(tf))
    nat = _subfit.fit_sequence(
        _frames(frames), template=tmpl, control_points=control_points,
        silhouette_views=int(silhouette_views), progress=progress, **options,
    )
    return Sequence(nat)
