"""``subfit.fit`` and its result ``subfit.Fit``: the pipeline of ``subfit fit`` from Python."""

from __future__ import annotations

import json
import os
import warnings
from pathlib import Path
from typing import Any, Callable, Optional, Union

import numpy as np
import numpy.typing as npt

from . import _subfit
from ._arrays import Faces, FacesLike, as_float_rows, faces_from_flat, faces_to_flat, tags_from_arrays
from ._surface import Surface

PathLike = Union[str, "os.PathLike[str]"]


class Fit:
    """A fitted subdivision surface: the cage in the input's coordinates and the report.

    Plain data — numpy arrays, strings and a dict — so it pickles (Dask, multiprocessing)
    and compares by value. The process that ran the fit also keeps the analysed scan, so
    :meth:`save` there writes every output of ``subfit fit``. A Fit is returned by
    :func:`subfit.fit`; its constructor is not part of the API.

    Attributes
    ----------
    vertices : (n, 3) float64
        Control points.
    faces : (m, 3) or (m, 4) int64, or a list of int64 arrays
        Cage faces (uniform faces as one array).
    scheme : str
        ``"loop"``, ``"catmull-clark"`` or ``"quad-tri"``.
    tags : dict
        Crease and corner tags: ``crease_edges (k, 2)``, ``crease_sharpness (k,)``,
        ``corners (c,)``, ``corner_sharpness (c,)``.
    report : dict
        The report, equal to ``report.json`` (``report["final"]["two_sided"]["e_rms"]``, …).
    reached : bool
        Whether the requested tolerances were met (both ways unless ``one_sided=True``).
    summary : str
        One line: control points, stages, iterations, errors both ways (the CLI's closing
        line); empty for a Fit made by hand.
    """

    def __init__(self, vertices: npt.NDArray[np.float64], faces: Faces, scheme: str, tags: dict,
                 report: dict, reached: bool, summary: str = "", native: Any = None) -> None:
        self.vertices = vertices
        self.faces = faces
        self.scheme = scheme
        self.tags = tags
        self.report = report
        self.reached = reached
        self.summary = summary
        self._native = native

    @classmethod
    def _from_native(cls, nat: Any) -> "Fit":
        offsets, indices = nat.faces()
        return cls(
            vertices=nat.vertices(),
            faces=faces_from_flat(offsets, indices),
            scheme=nat.scheme(),
            tags=tags_from_arrays(nat.tags()),
            report=json.loads(nat.report_json()),
            reached=nat.reached(),
            summary=nat.summary(),
            native=nat,
        )

    @property
    def num_control_points(self) -> int:
        """Number of control points."""
        return len(self.vertices)

    def surface(self) -> Surface:
        """The fitted limit surface as a :class:`subfit.Surface` (the cage's vertices, faces,
        scheme and tags): sample it, evaluate it, project points onto it."""
        return Surface(self.vertices, self.faces, self.scheme, self.tags)

    def save(self, directory: PathLike, *, limit_quads: bool = False) -> Path:
        """Writes the outputs of ``subfit fit`` into ``directory`` (created if missing).

        control.obj, control.usda (scheme and creases, for Blender/USD), control.tags.json (the
        creases for OBJ readers that skip OpenSubdiv's tags), limit.ply (the limit
        tessellation with normals), error.ply (coloured by the distance to the scan), log.csv,
        preview.png, report.html and report.json. A Fit that was pickled into another process
        no longer holds the scan: there only control.obj, control.usda and report.json are
        written (with a ``RuntimeWarning``).

        Parameters
        ----------
        directory : str or os.PathLike
            Where to write (created with its parents if missing; files in it are replaced).
        limit_quads : bool
            Keep the limit tessellation's quads in limit.ply and error.ply (a Catmull-Clark or
            quad/triangle cage's refinement), as ``subfit fit --limit-quads``. Default
            ``False``: each quad is split into two triangles along the diagonal the errors
            were measured on, so every face has three corners (trimesh refuses a PLY whose
            faces differ in size). A Loop fit's tessellation is triangles either way.

        Returns
        -------
        pathlib.Path
            ``directory``.

        Raises
        ------
        OSError
            A file that cannot be written.

        Examples
        --------
        >>> import numpy as np, subfit
        >>> d = np.random.default_rng(0).normal(size=(2000, 3))
        >>> f = subfit.fit(d / np.linalg.norm(d, axis=1, keepdims=True), scheme="catmull-clark",
        ...                tolerance=2e-3, max_control_points=200)
        >>> out = f.save("sphere-fit", limit_quads=True)
        >>> sorted(p.name for p in out.iterdir())[:4]
        ['control.obj', 'control.tags.json', 'control.usda', 'error.ply']
        >>> subfit.read(out / "limit.ply").faces.shape[1]  # quads: a Catmull-Clark tessellation
        4
        """
        d = Path(directory)
        d.mkdir(parents=True, exist_ok=True)
        if self._native is not None:
            self._native.write_into(str(d), limit_quads=bool(limit_quads))
            self.report = json.loads(self._native.report_json())
            return d
        warnings.warn(
            "subfit: this Fit was unpickled and no longer holds the scan; writing control.obj, "
            "control.usda and report.json only (save where the fit ran for limit.ply, error.ply, log.csv)",
            RuntimeWarning,
            stacklevel=2,
        )
        from ._io import write

        write(d / "control.obj", self.vertices, self.faces)
        write(d / "control.usda", self.vertices, self.faces, scheme=self.scheme, tags=self.tags)
        (d / "report.json").write_text(json.dumps(self.report, indent=2) + "\n")
        return d

    def release_scan(self) -> None:
        """Drops the analysed scan this Fit keeps for :meth:`save` (its kd-tree, normals and
        limit tessellation: memory of the order of the scan's size), as pickling does; a later
        :meth:`save` writes control.obj, control.usda and report.json only."""
        self._native = None

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        state["_native"] = None
        return state

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Fit):
            return NotImplemented
        return (
            self.scheme == other.scheme
            and np.array_equal(self.vertices, other.vertices)
            and _faces_equal(self.faces, other.faces)
        )

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        two = self.report.get("final", {}).get("two_sided", {})
        return (
            f"Fit({self.num_control_points} control points, scheme={self.scheme!r}, "
            f"two-sided E_rms={two.get('e_rms', float('nan')):.3e}, reached={self.reached})"
        )


def _faces_equal(a: Faces, b: Faces) -> bool:
    if isinstance(a, np.ndarray) and isinstance(b, np.ndarray):
        return np.array_equal(a, b)
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return False
    return len(a) == len(b) and all(np.array_equal(x, y) for x, y in zip(a, b))


def fit(
    points: Union[npt.ArrayLike, PathLike],
    *,
    faces: Optional[FacesLike] = None,
    normals: Optional[npt.ArrayLike] = None,
    scheme: str = "auto",
    method: str = "sdm",
    tolerance: Optional[float] = None,
    max_error: Optional[float] = None,
    max_control_points: Optional[int] = None,
    progress: Optional[Callable[[dict], Any]] = None,
    **options: Any,
) -> Fit:
    """Fits a subdivision surface to a scan: the whole pipeline of ``subfit fit``.

    The scan is analysed (normals, curvature), an initial cage with its topology is built
    (QEM simplification of a mesh, IMLS contouring of a point cloud), and fitted in stages
    with adaptive refinement until the limit surface is within the tolerances of the scan
    (both ways by default). Lengths are in unit-cube units: the scan is scaled uniformly into
    ``[0, 1]³`` (longest side 1) for the tolerances; the result is in the input's coordinates.

    Parameters
    ----------
    points : (n, 3) array_like of float, or a path
        Scan points (at least 10). A path (str or ``os.PathLike``) is read with
        :func:`subfit.read` and its faces and normals used.
    faces : (m, 3|4) array_like of int or list of polygons, optional
        Faces of a mesh target (a dense triangle mesh, say).
    normals : (n, 3) array_like of float, optional
        Normals of the points (orientation hints; estimated when absent).
    scheme : {"loop", "catmull-clark", "quad-tri", "auto"}
        Subdivision scheme (``auto``, as ``subfit fit``: the quad/triangle scheme for an open
        mesh target, which is Loop on the automatic cage's triangles and gets quads from the
        curvature-line start; Loop for other all-triangle cages, Catmull-Clark otherwise).
    method : {"sdm", "tdm", "pdm", "imls"}
        Error term: squared, tangent or point distance minimization (Cheng et al. 2007), or
        the IMLS distance (Xie et al. 2023; ``imls_radius`` sets its kernel radius, ``arap``
        the weight of its as-rigid-as-possible regularizer, as ``subfit fit``).
    tolerance : float, optional
        Target E_rms (unit-cube units, in (0, 1)). Without ``tolerance``, ``max_error`` and
        ``max_control_points`` the tolerances are the target's, fractions of its bounding-box
        diagonal: RMS 0.075 % and Hausdorff 0.7 % for a scan (its boundary vertices 0.4 %),
        0.04 % and 0.2 % for a CAD part with sharp edges, RMS only for a noisy scan (as
        ``subfit fit``); otherwise 5e-4 unless given.
    max_error : float, optional
        Also require E_max ≤ this (unit-cube units).
    max_control_points : int, optional
        Control-point budget (5000 when not given): the initial cage and every refinement
        stay within it.
    progress : callable, optional
        Called with a dict per event: ``{"event": "step", "step": "analyse"}``,
        ``{"event": "iteration", "stage", "iteration", "e_rms", "e_max", ...}``,
        ``{"event": "stage", ...}``, ``{"event": "warning", "message"}``. An exception it
        raises stops the fit and propagates.
    **options
        The other flags of ``subfit fit``, same names and defaults: ``step`` ("lm", "armijo",
        "none"), ``control_points`` (initial cage size), ``as_points`` (ignore ``faces``),
        ``init`` (a :class:`Surface`, :class:`Fit` or ``(vertices, faces)`` initial cage, or how
        to build one: ``"auto"``, ``"qem"``, ``"curvature-lines"`` — Lavoué et al.'s cage for an
        open mesh of genus 0, fitted with the quad/triangle scheme unless ``scheme`` is
        ``"catmull-clark"``; ``"auto"`` also tries it on small open meshes, as ``subfit fit``),
        ``lambda_start`` (1e-3, ``--lambda``), ``lambda_end``, ``sample_level`` (3),
        ``max_iterations`` (100), ``stage_iterations`` (6), ``one_sided`` (False),
        ``coverage`` (1.0: weight of the data → surface part of the objective; 0 fits one-sided),
        ``facing`` (True; False is ``--no-facing``: inside thin parts of a closed mesh, a sample
        that sank past the middle is pulled by the wall facing its own way), ``chordal`` (False;
        ``--chordal``: for a CAD tessellation, fit the part its facets stand for — their curved
        interpolant, PN triangles through the vertices — rather than the facets; errors are
        measured against it and ``report["options"]["chordal_levels"]`` says it applied),
        ``refine`` (True; ``--no-refine``), ``edge_flips`` (True; ``--no-flips``),
        ``max_depth`` (5), ``local`` (False), ``local_rings`` (2), ``local_field_peak`` (0.8),
        ``local_field_share`` (0.5; 0 turns local enrichment off), ``error_scale``,
        ``imls_radius`` (``method="imls"``: the kernel's support radius h, unit-cube units;
        default half the point spacing, at least 4 × the noise level), ``arap`` (0: the weight
        of the as-rigid-as-possible regularizer, Xie et al. 2023 eq. 5), ``quads`` ("field":
        a quad cage is also laid along a cross field and the closer fit kept, or the field's
        within a tenth for its fewer irregular vertices; "paired": the simplification's
        triangles paired; "only": every face a quad, connectivity kept), ``name`` (used in
        messages).

    Returns
    -------
    Fit
        The cage (in the input's coordinates), its scheme and tags, and the report.
        ``fit.reached`` says whether the tolerances were met (not reaching them is not an
        error, as the CLI's exit code 1 is not).

    Raises
    ------
    ValueError
        Bad arrays (shape, NaN, too few points, indices out of range), bad options, an
        unusable mesh, or a budget that cannot be honoured.
    RuntimeError
        Numerical failure (with the library's diagnostics).
    KeyboardInterrupt
        Ctrl-C (checked once per iteration).

    Notes
    -----
    The GIL is released while fitting, so fits in several threads run in parallel (each
    also uses the library's own rayon thread pool, sized by ``RAYON_NUM_THREADS``, default
    one thread per core). Warnings (e.g. re-oriented faces) are issued
    as ``RuntimeWarning`` and kept in ``report["warnings"]``.

    Examples
    --------
    >>> import numpy as np, subfit
    >>> d = np.random.default_rng(0).normal(size=(2000, 3))
    >>> points = d / np.linalg.norm(d, axis=1, keepdims=True)  # a unit sphere
    >>> f = subfit.fit(points, tolerance=2e-3, max_control_points=200)
    >>> f.reached, f.num_control_points <= 200, f.scheme
    (True, True, 'loop')
    >>> f.report["final"]["two_sided"]["e_rms"] <= 2e-3  # unit-cube units
    True
    >>> s = f.surface()  # subfit.Surface: sample, evaluate, closest points
    >>> bool(np.abs(np.linalg.norm(s.sample(2), axis=1) - 1).max() < 0.02)
    True
    """
    name = options.pop("name", None)
    if isinstance(points, (str, os.PathLike)):
        from ._io import read

        path = os.fspath(points)
        m = read(path)
        points = m.vertices
        if faces is None and m.faces is not None:
            faces = m.faces
        if normals is None:
            normals = m.normals
        name = name or path
    pts = as_float_rows("points", points)
    face_arrays = None if faces is None else faces_to_flat(faces)
    nrm = None if normals is None else as_float_rows("normals", normals)
    init = options.pop("init", None)
    if isinstance(init, str):
        options["init_method"] = init
    elif init is not None:
        if isinstance(init, (Surface, Fit)):
            iv, ifaces = init.vertices, init.faces
        elif isinstance(init, (tuple, list)) and len(init) == 2:
            iv, ifaces = init
        else:
            raise ValueError("init must be a Surface, a Fit or a (vertices, faces) pair")
        options["init"] = (as_float_rows("init vertices", iv), faces_to_flat(ifaces))
    nat = _subfit.fit(
        pts, face_arrays, nrm,
        scheme=scheme, method=method,
        tolerance=None if tolerance is None else float(tolerance),
        max_error=None if max_error is None else float(max_error),
        max_control_points=None if max_control_points is None else int(max_control_points),
        name=name, progress=progress,
        **options,
    )
    return Fit._from_native(nat)
