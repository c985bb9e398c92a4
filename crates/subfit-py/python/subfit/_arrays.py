"""Array coercion shared by the public API: array-likes in, contiguous numpy arrays out.

Shapes and values are validated again by the native module (which raises ``ValueError`` with
the argument, the row and the reason); here arrays are only converted, and a dtype that cannot
be converted (strings, objects) gives a ``ValueError`` instead of numpy's ``TypeError``.
"""

from __future__ import annotations

from typing import Any, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

#: Faces: an ``(m, k)`` integer array (every face with ``k`` vertices), or a sequence of
#: per-face index sequences (polygons of any size).
FacesLike = Union[npt.ArrayLike, Sequence[Sequence[int]]]

#: Faces as returned: ``(m, k)`` int64 when every face has ``k`` vertices, else a list of
#: ``(k_i,)`` int64 arrays.
Faces = Union[npt.NDArray[np.int64], list]


def as_float_rows(name: str, a: Any, columns: int = 3) -> npt.NDArray[np.float64]:
    """``a`` as a C-contiguous float64 array; a 1-D array of ``columns`` values is one row."""
    try:
        arr = np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name} must be a numeric array of shape (n, {columns}): {e}") from None
    if arr.ndim != 2:
        raise ValueError(f"{name} must have shape (n, {columns}), got shape {arr.shape}")
    return np.ascontiguousarray(arr)


def as_index_array(name: str, a: Any) -> npt.NDArray[np.int64]:
    """``a`` as a contiguous int64 array; floats with integral values are accepted."""
    arr = np.asarray(a)
    if arr.dtype.kind == "b" or arr.dtype.kind not in "iuf":
        raise ValueError(f"{name} must hold integer indices, got dtype {arr.dtype}")
    if arr.dtype.kind == "f":
        if not np.all(np.isfinite(arr)) or not np.all(arr == np.round(arr)):
            raise ValueError(f"{name} must hold integer indices, got non-integral values")
    return np.ascontiguousarray(arr, dtype=np.int64)


def faces_to_flat(faces: FacesLike) -> Tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """Faces as ``(counts (m,), indices (Σ counts,))`` int64 arrays for the native module."""
    if not isinstance(faces, (list, tuple)) or (
        len(faces) > 0
        and all(hasattr(f, "__len__") for f in faces)
        and len({len(f) for f in faces}) == 1
    ):
        # An array (numpy, torch, …) or equal-length polygons: one (m, k) array.
        arr = as_index_array("faces", faces)
        if arr.ndim != 2:
            raise ValueError(f"faces must have shape (m, k) or be a list of polygons, got shape {arr.shape}")
        m, k = arr.shape
        return np.full(m, k, dtype=np.int64), arr.reshape(-1)
    try:
        polys = [as_index_array(f"faces[{i}]", f).reshape(-1) for i, f in enumerate(faces)]
    except TypeError:
        raise ValueError("faces must be an (m, k) integer array or a list of index sequences") from None
    counts = np.array([len(p) for p in polys], dtype=np.int64)
    indices = np.concatenate(polys) if polys else np.zeros(0, dtype=np.int64)
    return counts, np.ascontiguousarray(indices, dtype=np.int64)


def faces_from_flat(offsets: npt.NDArray[np.int64], indices: npt.NDArray[np.int64]) -> Faces:
    """Faces from ``(offsets (m + 1,), indices)``: ``(m, k)`` when uniform, else a list."""
    counts = np.diff(offsets)
    if len(counts) > 0 and np.all(counts == counts[0]):
        return indices.reshape(len(counts), int(counts[0]))
    return np.split(indices, offsets[1:-1])


def tags_to_arrays(tags: Optional[dict], n: int) -> Optional[tuple]:
    """A tags dict (see :class:`subfit.Surface`) as the four arrays the native module takes."""
    if tags is None:
        return None
    if not isinstance(tags, dict):
        raise ValueError("tags must be a dict with keys crease_edges, crease_sharpness, corners, corner_sharpness")
    unknown = set(tags) - {"crease_edges", "crease_sharpness", "corners", "corner_sharpness"}
    if unknown:
        raise ValueError(f"tags: unknown keys {sorted(unknown)}")
    edges = as_index_array("tags['crease_edges']", tags.get("crease_edges", np.zeros((0, 2))))
    edges = edges.reshape(-1, 2) if edges.size == 0 or edges.ndim == 2 else edges
    if edges.ndim != 2:
        raise ValueError(f"tags['crease_edges'] must have shape (k, 2), got {edges.shape}")
    default_sharp = 10.0
    es = np.ascontiguousarray(
        tags.get("crease_sharpness", np.full(len(edges), default_sharp)), dtype=np.float64
    ).reshape(-1)
    corners = as_index_array("tags['corners']", tags.get("corners", np.zeros(0))).reshape(-1)
    cs = np.ascontiguousarray(
        tags.get("corner_sharpness", np.full(len(corners), default_sharp)), dtype=np.float64
    ).reshape(-1)
    return (np.ascontiguousarray(edges), es, corners, cs)


def tags_from_arrays(arrays: tuple) -> dict:
    """The native module's four tag arrays as a dict."""
    e, es, c, cs = arrays
    return {"crease_edges": e, "crease_sharpness": es, "corners": c, "corner_sharpness": cs}
