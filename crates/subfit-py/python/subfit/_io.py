"""``subfit.read`` / ``subfit.write``: the mesh and point-cloud formats subfit reads and writes."""

from __future__ import annotations

import os
from typing import NamedTuple, Optional, Union

import numpy as np
import numpy.typing as npt

from . import _subfit
from ._arrays import Faces, FacesLike, as_float_rows, faces_from_flat, faces_to_flat, tags_to_arrays

PathLike = Union[str, "os.PathLike[str]"]


class Mesh(NamedTuple):
    """A mesh or point cloud as :func:`read` returns it (a named tuple).

    Attributes
    ----------
    vertices : (n, 3) float64
        Positions, in the file's units.
    faces : (m, k) int64, a list of int64 arrays, or None
        Faces as an array when every face has ``k`` corners, a list of per-face arrays when
        sizes differ, ``None`` for a point cloud.
    normals : (n, 3) float64 or None
        Vertex normals, when the file has them.
    colors : (n, 3) uint8 or None
        Vertex colours, when the file has them.
    format : str
        The format read: ``"ply"``, ``"obj"``, ``"off"``, ``"stl"`` or ``"xyz"``.
    """

    vertices: npt.NDArray[np.float64]
    faces: Optional[Faces]
    normals: Optional[npt.NDArray[np.float64]]
    colors: Optional[npt.NDArray[np.uint8]]
    format: str


def read(path: PathLike) -> Mesh:
    """Reads a mesh or point cloud: PLY (ascii/binary, face lists and tristrips), OBJ, OFF,
    STL (ascii/binary; vertices welded), XYZ/PTS (``x y z [nx ny nz]``).

    Parameters
    ----------
    path : str or os.PathLike
        The file. The format comes from the extension, else from the content.

    Returns
    -------
    Mesh
        ``(vertices, faces, normals, colors, format)``; ``faces`` is ``None`` for a point
        cloud.

    Raises
    ------
    OSError
        The system refuses (``FileNotFoundError``, ``PermissionError``, …).
    ValueError
        Malformed content, naming the line or element (a face index out of range, say).

    Examples
    --------
    >>> import subfit
    >>> subfit.write("triangle.obj", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    >>> m = subfit.read("triangle.obj")
    >>> m.vertices.shape, m.faces.tolist(), m.format
    ((3, 3), [[0, 1, 2]], 'obj')
    """
    pos, nrm, col, (offsets, indices), fmt = _subfit.read(os.fspath(path))
    faces = faces_from_flat(offsets, indices) if len(offsets) > 1 else None
    return Mesh(pos, faces, nrm, col, fmt)


def write(
    path: PathLike,
    vertices: npt.ArrayLike,
    faces: Optional[FacesLike] = None,
    *,
    normals: Optional[npt.ArrayLike] = None,
    colors: Optional[npt.ArrayLike] = None,
    binary: bool = False,
    scheme: str = "catmull-clark",
    tags: Optional[dict] = None,
    boundary: str = "edge-only",
) -> None:
    """Writes a mesh or point cloud, atomically (a temporary file renamed into place).

    Parameters
    ----------
    path : str or os.PathLike
        The file; its extension gives the format: ``.ply``, ``.obj``, ``.off``, ``.stl``,
        ``.xyz``/``.pts`` (points and normals), or ``.usda`` (a USD subdivision cage).
    vertices : (n, 3) array_like of float
        Positions.
    faces : (m, k) array_like of int or list of polygons, optional
        Faces (none: a point cloud).
    normals : (n, 3) array_like of float, optional
        Vertex normals (PLY, XYZ).
    colors : (n, 3) array_like, optional
        Vertex colours (PLY): uint8, or floats in [0, 1] (scaled by 255).
    binary : bool
        Little-endian binary PLY or binary STL (default ``False``: ASCII).
    scheme : {"catmull-clark", "loop", "quad-tri", "none"}
        ``.usda`` only: the subdivision scheme (default ``"catmull-clark"``). USD has no
        quad/triangle scheme: such a cage is written as ``catmullClark`` with the smooth
        triangle rule, or as ``loop``, the same surface, when it has no quads.
    tags : dict, optional
        ``.usda`` only: crease and corner tags (see :class:`subfit.Surface`).
    boundary : {"edge-only", "edge-and-corner"}
        ``.usda`` only: the boundary interpolation (default ``"edge-only"``).

    Raises
    ------
    ValueError
        An unknown extension, bad arrays (shape, NaN, indices out of range), bad options.
    OSError
        The system refuses the file.

    Examples
    --------
    >>> import numpy as np, subfit
    >>> tetrahedron = np.eye(4, 3), [[0, 1, 2], [3, 2, 1], [3, 0, 2], [3, 1, 0]]
    >>> subfit.write("tetrahedron.ply", *tetrahedron, binary=True)
    >>> subfit.write("tetrahedron.usda", *tetrahedron, scheme="loop",
    ...              tags={"crease_edges": [[0, 1]], "crease_sharpness": [2.0]})
    >>> 'subdivisionScheme = "loop"' in open("tetrahedron.usda").read()
    True
    """
    v = as_float_rows("vertices", vertices)
    f = None if faces is None else faces_to_flat(faces)
    n = None if normals is None else as_float_rows("normals", normals)
    c = None
    if colors is not None:
        c = np.asarray(colors)
        if c.dtype != np.uint8:
            if c.dtype.kind == "f" and c.size and c.max() <= 1.0:
                c = np.round(c * 255.0)
            c = np.clip(c, 0, 255).astype(np.uint8)
        c = np.ascontiguousarray(c)
    _subfit.write(os.fspath(path), v, f, n, c, bool(binary), scheme, tags_to_arrays(tags, len(v)), boundary)
