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
    """What :func:`read` returns."""

    #: ``(n, 3)`` float64 positions.
    vertices: npt.NDArray[np.float64]
    #: ``(m, k)`` int64 faces when uniform, a list of int64 arrays otherwise, ``None`` for a
    #: point cloud.
    faces: Optional[Faces]
    #: ``(n, 3)`` float64 vertex normals, or ``None``.
    normals: Optional[npt.NDArray[np.float64]]
    #: ``(n, 3)`` uint8 vertex colours, or ``None``.
    colors: Optional[npt.NDArray[np.uint8]]
    #: The format read: ``"ply"``, ``"obj"``, ``"off"``, ``"stl"`` or ``"xyz"``.
    format: str


def read(path: PathLike) -> Mesh:
    """Reads a mesh or point cloud: PLY (ascii/binary, face lists and tristrips), OBJ, OFF,
    STL (ascii/binary; vertices welded), XYZ/PTS (``x y z [nx ny nz]``).

    The format comes from the extension, else from the content. Raises ``FileNotFoundError``
    (and other ``OSError``) when the system refuses, ``ValueError`` naming the line or element
    when the content is malformed.
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

    The format comes from the extension: ``.ply`` (``binary=True`` for little-endian binary),
    ``.obj``, ``.off``, ``.stl`` (``binary=True`` for binary), ``.xyz``/``.pts``, or ``.usda``:
    a USD subdivision cage with ``scheme`` (``"loop"``, ``"catmull-clark"``, ``"quad-tri"``, ``"none"``;
    USD has no quad/triangle scheme: such a cage is written as ``catmullClark`` with the smooth
    triangle rule, or as ``loop``, the same surface, when it has no quads), crease/corner ``tags`` (see :class:`subfit.Surface`) and ``boundary`` interpolation
    (``"edge-only"`` or ``"edge-and-corner"``). ``vertices`` ``(n, 3)``, ``normals``
    ``(n, 3)``, ``colors`` ``(n, 3)`` uint8.
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
