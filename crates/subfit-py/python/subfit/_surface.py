"""``subfit.Surface``: a control mesh with a subdivision scheme, and its limit surface.

Loop (triangles) and Catmull-Clark (any polygons) with OpenSubdiv's boundary, crease and corner
rules. Sampling is a sparse linear operator over the control points (``operator(level) @
vertices == sample(level)``); evaluation at ``(face, u, v)`` is exact (Stam-style eigen-analysis
near extraordinary vertices by local refinement), with first and second derivatives.
"""

from __future__ import annotations

from typing import Any, NamedTuple, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import _subfit
from ._arrays import (
    Faces,
    FacesLike,
    as_float_rows,
    as_index_array,
    faces_from_flat,
    faces_to_flat,
    tags_from_arrays,
    tags_to_arrays,
)

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]


class Evaluation(NamedTuple):
    """Exact limit values at parameters ``(face, u, v)``, returned by :meth:`Surface.evaluate`:
    ``k`` rows, or one row squeezed (``(3,)``, ``(3, 3)``) for scalar parameters. Lengths are
    in the control points' units.

    Attributes
    ----------
    position : (k, 3) float64
        Limit positions ``S(u, v)``.
    du : (k, 3) float64
        First derivatives ``∂S/∂u``.
    dv : (k, 3) float64
        First derivatives ``∂S/∂v``.
    normal : (k, 3) float64
        Unit normals ``du × dv / |du × dv|`` (zero where degenerate).
    second : (k, 3, 3) float64
        Second derivatives ``S_uu, S_uv, S_vv`` (NaN where unavailable).
    """

    position: F64
    du: F64
    dv: F64
    normal: F64
    second: F64


class ClosestPoints(NamedTuple):
    """Closest points on the limit surface, one row per query (``k`` queries), returned by
    :meth:`Surface.closest_point`; ``(face, u, v)`` can be passed to :meth:`Surface.evaluate`.

    Attributes
    ----------
    points : (k, 3) float64
        The closest points ``S``.
    face : (k,) int64
        The control-mesh face of each.
    u : (k,) float64
        First parameter in the face's domain.
    v : (k,) float64
        Second parameter.
    distance : (k,) float64
        Distance ``|q − S|`` (the control points' units).
    """

    points: F64
    face: I64
    u: F64
    v: F64
    distance: F64


class ClosestPointDetails(NamedTuple):
    """:class:`ClosestPoints` with the sub-patch, normal, signed distance and convergence,
    returned by ``Surface.closest_point(points, full=True)``.

    Attributes
    ----------
    points, face, u, v, distance
        As :class:`ClosestPoints`.
    sub : (k,) int64
        Sub-patch: the corner of a Catmull-Clark ``n``-gon (``n ≠ 4``), else 0 (pass it to
        :meth:`Surface.evaluate` with ``face, u, v``).
    signed_distance : (k,) float64
        ``(q − S)·n``, positive on the side the normal points to.
    normal : (k, 3) float64
        Unit normals at the closest points.
    converged : (k,) bool
        Whether the Newton search reached its tolerance.
    """

    points: F64
    face: I64
    u: F64
    v: F64
    distance: F64
    sub: I64
    signed_distance: F64
    normal: F64
    converged: npt.NDArray[np.bool_]


def _csr(parts: tuple) -> Any:
    try:
        import scipy.sparse as sp
    except ImportError:  # pragma: no cover - scipy is a dependency
        raise ImportError("subfit: operator() returns a scipy.sparse.csr_matrix; pip install scipy") from None
    indptr, indices, data, shape = parts
    return sp.csr_matrix((data, indices, indptr), shape=shape)


class Surface:
    """A subdivision surface: control points, faces, scheme and crease/corner tags.

    Parameters
    ----------
    vertices : (n, 3) array_like of float
        Control points.
    faces : (m, 3) or (m, 4) array_like of int, or a list of polygons
        Faces over the control points, counter-clockwise seen from outside.
    scheme : {"loop", "catmull-clark", "quad-tri"}
        Loop needs triangles; Catmull-Clark takes any polygons.
    tags : dict, optional
        ``{"crease_edges": (k, 2) int, "crease_sharpness": (k,) float, "corners": (c,) int,
        "corner_sharpness": (c,) float}``; sharpness defaults to 10 (infinitely sharp, as
        OpenSubdiv). Boundaries are creases (OpenSubdiv's ``edge-only``).

    Raises
    ------
    ValueError
        Wrong shapes, non-finite values, indices out of range, non-manifold or otherwise
        unusable topology, non-triangles for Loop.

    Notes
    -----
    Immutable. The sampling operator of each level is built on first use and kept, so
    ``sample``/``operator`` at the same level are cheap afterwards. Pickling keeps the
    arrays (operators are rebuilt).

    Examples
    --------
    A unit cube as a Catmull-Clark cage (vertex ``4x + 2y + z`` at ``(x, y, z)``):

    >>> import numpy as np, subfit
    >>> cube = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    >>> quads = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]
    >>> s = subfit.Surface(cube, quads, scheme="catmull-clark")
    >>> s.sample(2).shape  # the limit positions of the twice-refined cube's 98 vertices
    (98, 3)
    >>> e = s.evaluate(0, 0.5, 0.5)  # the middle of face 0 (the side x = 0)
    >>> bool(np.allclose(e.position[1:], 0.5)), bool(np.allclose(e.normal, [-1, 0, 0]))
    (True, True)
    """

    def __init__(
        self,
        vertices: npt.ArrayLike,
        faces: FacesLike,
        scheme: str = "loop",
        tags: Optional[dict] = None,
    ) -> None:
        v = as_float_rows("vertices", vertices)
        counts, indices = faces_to_flat(faces)
        t = tags_to_arrays(tags, len(v))
        self._native = _subfit.NativeSurface(v, counts, indices, scheme, t)
        v = v.copy()  # frozen below; never the caller's array
        v.setflags(write=False)
        self._vertices = v
        self._counts = counts
        self._indices = indices
        self._tags = None if t is None else tags_from_arrays(t)

    # -- the data -------------------------------------------------------------------------
    @property
    def vertices(self) -> F64:
        """``(n, 3)`` float64 control points (read-only)."""
        return self._vertices

    @property
    def faces(self) -> Faces:
        """``(m, k)`` int64 faces when all have ``k`` vertices, else a list of arrays."""
        offsets = np.concatenate([[0], np.cumsum(self._counts)])
        return faces_from_flat(offsets, self._indices)

    @property
    def scheme(self) -> str:
        """``"loop"``, ``"catmull-clark"`` or ``"quad-tri"``."""
        return self._native.scheme

    @property
    def tags(self) -> Optional[dict]:
        """Crease and corner tags (see the class docs), or ``None``."""
        return self._tags

    @property
    def num_vertices(self) -> int:
        """Number of control points ``n``."""
        return len(self._vertices)

    @property
    def num_faces(self) -> int:
        """Number of control-mesh faces ``m``."""
        return len(self._counts)

    def with_vertices(self, vertices: npt.ArrayLike) -> "Surface":
        """The same faces, scheme and tags with new control points ``(n, 3)`` (a deformed
        cage); raises ``ValueError`` when the shape differs from :attr:`vertices`."""
        v = as_float_rows("vertices", vertices)
        if v.shape != self._vertices.shape:
            raise ValueError(f"vertices must have shape {self._vertices.shape}, got {v.shape}")
        return Surface(v, self.faces, self.scheme, self._tags)

    # -- sampling -------------------------------------------------------------------------
    def sample(self, level: int = 3, *, normals: bool = False) -> Union[F64, Tuple[F64, F64]]:
        """Limit positions of the vertices of the ``level``-times refined mesh.

        Parameters
        ----------
        level : int
            Refinement level in ``[0, 8]`` (default 3): 0 gives the limit positions of the
            control points themselves; each level multiplies the ``s`` samples by about 4.
        normals : bool
            Also return the unit limit normals (default ``False``).

        Returns
        -------
        (s, 3) float64, or a pair of them
            Positions, or ``(positions, unit_normals)`` with ``normals=True``. Row ``i`` is
            vertex ``i`` of :meth:`tessellation`.

        Raises
        ------
        ValueError
            ``level`` out of range.

        Notes
        -----
        Cost: building the operator once per level (sparse, O(s)), then one sparse product.
        """
        pos, nrm = self._native.sample(int(level), bool(normals))
        return (pos, nrm) if normals else pos

    def operator(self, level: int = 3, *, which: str = "position") -> Any:
        """The sampling operator ``C`` as a ``scipy.sparse.csr_matrix`` of shape ``(s, n)``.

        ``C @ vertices == sample(level)`` (to round-off); rows sum to 1. Row ``i`` is vertex
        ``i`` of :meth:`tessellation`. The operator depends on the faces, scheme and tags only,
        so it serves any positions of the control points (a least-squares fit, a PyTorch
        layer: :class:`subfit.torch.LimitSurface`).

        Parameters
        ----------
        level : int
            Refinement level in ``[0, 8]`` (default 3), as :meth:`sample`.
        which : {"position", "tangent1", "tangent2"}
            The limit positions (default) or one of the two limit tangent operators (rows
            sum to 0).

        Raises
        ------
        ValueError
            ``level`` out of range or an unknown ``which``.

        Examples
        --------
        >>> import numpy as np, subfit
        >>> tetrahedron = subfit.Surface(np.eye(4, 3), [[0, 1, 2], [3, 2, 1], [3, 0, 2], [3, 1, 0]])
        >>> C = tetrahedron.operator(2)
        >>> C.shape, bool(np.allclose(C.sum(axis=1), 1))
        ((34, 4), True)
        >>> bool(np.allclose(C @ tetrahedron.vertices, tetrahedron.sample(2)))
        True
        """
        return _csr(self._native.operator(int(level), which))

    def tessellation(self, level: int = 3) -> Tuple[F64, Faces]:
        """The limit surface as a mesh: ``(sample(level) (s, 3), faces)`` with the faces of
        the ``level``-times refined mesh (triangles for Loop, quads for Catmull-Clark; ``level``
        in ``[0, 8]``, default 3, else ``ValueError``) — e.g. for
        ``trimesh.Trimesh(*surface.tessellation(3))``."""
        pos = self.sample(level)
        offsets, indices = self._native.level_faces(int(level))
        return pos, faces_from_flat(offsets, indices)

    # -- exact evaluation -----------------------------------------------------------------
    def _params(self, face: Any, u: Any, v: Any, sub: Any) -> Tuple[tuple, bool]:
        scalar = all(np.ndim(x) == 0 for x in (face, u, v)) and np.ndim(sub if sub is not None else 0) == 0
        f, uu, vv, ss = np.broadcast_arrays(
            as_index_array("face", face), np.asarray(u, dtype=np.float64),
            np.asarray(v, dtype=np.float64), as_index_array("sub", 0 if sub is None else sub),
        )
        flat = tuple(np.ascontiguousarray(a.reshape(-1)) for a in (f, uu, vv, ss))
        return flat, scalar

    def evaluate(self, face: npt.ArrayLike, u: npt.ArrayLike, v: npt.ArrayLike, *,
                 sub: Optional[npt.ArrayLike] = None) -> Evaluation:
        """Exact limit position, derivatives and normal at ``(face, u, v)``.

        ``face``, ``u``, ``v`` (and ``sub``) broadcast against each other; ``k`` parameters give
        ``(k, 3)`` arrays, scalars give ``(3,)``. The domain of a triangle (Loop) is
        ``u, v ≥ 0, u + v ≤ 1``, of a quad ``[0, 1]²``, with ``(0, 0)`` at the face's first
        vertex; a Catmull-Clark ``n``-gon (``n ≠ 4``) has ``n`` quad sub-patches selected by
        ``sub`` (its corner; default 0). Returns an :class:`Evaluation`. Raises ``ValueError``
        for a face, sub-patch or ``(u, v)`` out of range.
        """
        (f, uu, vv, ss), scalar = self._params(face, u, v, sub)
        out = Evaluation(*self._native.evaluate(f, uu, vv, ss))
        return Evaluation(*(a[0] for a in out)) if scalar else out

    def evaluation_operator(self, face: npt.ArrayLike, u: npt.ArrayLike, v: npt.ArrayLike, *,
                            sub: Optional[npt.ArrayLike] = None) -> Any:
        """Weights of the limit positions at ``k`` parameters over the control points: a
        ``scipy.sparse.csr_matrix`` ``(k, n)`` with ``W @ vertices == evaluate(...).position``
        (arguments and errors as :meth:`evaluate`)."""
        (f, uu, vv, ss), _ = self._params(face, u, v, sub)
        return _csr(self._native.evaluation_operator(f, uu, vv, ss))

    def closest_point(self, points: npt.ArrayLike, *, full: bool = False
                      ) -> Union[ClosestPoints, ClosestPointDetails]:
        """Closest points on the limit surface to ``points (k, 3)`` (the control points' units).

        Returns ``(points (k, 3), face (k,), u (k,), v (k,), distance (k,))`` as
        :class:`ClosestPoints`; ``full=True`` adds the sub-patch, signed distance, normal and
        convergence flag (:class:`ClosestPointDetails`). A BVH over a tessellation gives the
        start, Newton's method on the exact surface refines it across patch boundaries.
        Cost: building the tessellation once per call, then a few exact evaluations per query
        (parallel). Raises ``ValueError`` for points that are not ``(k, 3)`` finite numbers.

        Examples
        --------
        >>> import numpy as np, subfit
        >>> tetrahedron = subfit.Surface(np.eye(4, 3), [[0, 1, 2], [3, 2, 1], [3, 0, 2], [3, 1, 0]])
        >>> q = np.array([[1.0, 1.0, 1.0], [0.25, 0.25, 0.25]])  # one outside, one inside
        >>> c = tetrahedron.closest_point(q, full=True)
        >>> c.points.shape, bool(c.signed_distance[0] > 0), bool(c.signed_distance[1] < 0)
        ((2, 3), True, True)
        >>> bool(np.allclose(tetrahedron.evaluate(c.face, c.u, c.v).position, c.points))
        True
        """
        q = as_float_rows("points", points)
        p, face, sub, u, v, d, sd, n, conv = self._native.closest_point(q)
        if full:
            return ClosestPointDetails(p, face, u, v, d, sub, sd, n, conv)
        return ClosestPoints(p, face, u, v, d)

    # -- Python protocol ------------------------------------------------------------------
    def __reduce__(self) -> Any:
        return (Surface, (np.array(self._vertices), self.faces, self.scheme, self._tags))

    def __repr__(self) -> str:
        return f"Surface({self.num_vertices} control points, {self.num_faces} faces, scheme={self.scheme!r})"
