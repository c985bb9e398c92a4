"""``subfit.torch``: differentiable layers for fitting subdivision surfaces in PyTorch.

The loop of Xie et al. 2023 (§4.1) — control points → limit samples → IMLS distance to a scan,
plus an ARAP regularizer on the cage — with each piece exact and sparse, on CPU (or any device
for the operator):

- :class:`LimitSurface` — control points ``(n, 3)`` or ``(b, n, 3)`` → limit samples
  ``(s, 3)`` / ``(b, s, 3)`` through the sparse sampling operator ``C`` (torch sparse CSR);
  the backward pass is ``Cᵀ`` (itself differentiable, so double backward works).
- :func:`imls` / :class:`IMLS` — the IMLS distance ``f(x) = Σ nᵢᵀ(x − pᵢ) φᵢ / Σ φᵢ``,
  ``φ(r) = (1 − r²/h²)⁴`` (eq. 2–3), value and analytic gradient computed natively (kd-tree,
  parallel); gradients flow to the query points (the scan is a constant).
- :func:`arap` / :class:`ARAP` — the ARAP energy of Sorkine & Alexa 2007 (eq. 5 of Xie et al.):
  ``Σᵢ Σⱼ wᵢⱼ ‖(xᵢ − xⱼ) − Rᵢ(rᵢ − rⱼ)‖²`` with cotangent weights of the rest shape and the
  optimal rotations ``Rᵢ`` (SVD, reflections removed); zero for rigid motions.

Importing this module needs PyTorch (``pip install torch``); ``import subfit`` does not.
"""

from __future__ import annotations

import warnings
from typing import Any, Optional, Tuple, Union

try:
    import torch
except ImportError as e:  # pragma: no cover - exercised only without torch
    raise ImportError("subfit.torch needs PyTorch: pip install torch") from e

import numpy as np

from . import _subfit
from ._arrays import FacesLike, faces_from_flat, faces_to_flat, tags_to_arrays

__all__ = ["LimitSurface", "imls", "IMLS", "arap", "ARAP", "cotangent_weights"]

Tensor = torch.Tensor
ArrayOrTensor = Union[Tensor, np.ndarray]


# ------------------------------------------------------------------------------------------
# The sparse limit operator
# ------------------------------------------------------------------------------------------
class _SparseApply(torch.autograd.Function):
    """``y = A x`` for a sparse ``A`` with ``Aᵀ`` given; backward ``Aᵀ g`` through the same
    function, so it is differentiable again."""

    @staticmethod
    def forward(ctx: Any, x: Tensor, a: Tensor, at: Tensor) -> Tensor:  # type: ignore[override]
        ctx.a, ctx.at = a, at
        return a @ x

    @staticmethod
    def backward(ctx: Any, g: Tensor) -> Tuple[Optional[Tensor], None, None]:  # type: ignore[override]
        if not ctx.needs_input_grad[0]:
            return None, None, None
        return _SparseApply.apply(g.contiguous(), ctx.at, ctx.a), None, None


def _csr_arrays(indptr: np.ndarray, indices: np.ndarray, data: np.ndarray, shape: tuple):
    """CSR arrays of the transpose (a stable counting sort by column)."""
    nrows, ncols = shape
    rows = np.repeat(np.arange(nrows, dtype=np.int64), np.diff(indptr))
    order = np.argsort(indices, kind="stable")
    t_indptr = np.zeros(ncols + 1, dtype=np.int64)
    np.cumsum(np.bincount(indices, minlength=ncols), out=t_indptr[1:])
    return t_indptr, rows[order], data[order]


class LimitSurface(torch.nn.Module):
    """Control points → limit-surface samples, through the exact sparse sampling operator.

    Parameters
    ----------
    faces : (m, 3) or (m, 4) array_like of int, or a list of polygons
        The control mesh's faces (its topology; positions come in ``forward``).
    scheme : {"loop", "catmull-clark", "quad-tri"}
        Subdivision scheme.
    level : int
        Sampling level: the samples are the limit positions of the vertices of the
        ``level``-times refined mesh (``s ≈ n · 4^level``).
    num_vertices : int, optional
        Number of control points (default: the largest index in ``faces`` plus one).
    tags : dict, optional
        Crease/corner tags (see :class:`subfit.Surface`).

    Shapes
    ------
    ``forward(control)``: ``(n, 3)`` → ``(s, 3)``, or ``(b, n, 3)`` → ``(b, s, 3)``; float32 or
    float64 (the operator is stored in float64 and cast to the input's dtype and device).

    Attributes
    ----------
    sample_faces : (f, 3|4) LongTensor
        Faces of the refined mesh over the samples (for normals, rendering, edge losses).

    Notes
    -----
    ``forward`` is ``C @ control``; backward is ``Cᵀ @ grad`` (sparse CSR on CPU; any device
    with sparse CSR matmul support). Cost O(nnz(C)) ≈ 12–15 · s multiply-adds per column.

    Raises
    ------
    ValueError
        Unusable faces (indices out of range, non-manifold, non-triangles for Loop), an
        unknown scheme, a level out of ``[0, 8]``.

    Examples
    --------
    >>> import torch
    >>> from subfit.torch import LimitSurface
    >>> layer = LimitSurface([[0, 1, 2], [3, 2, 1], [3, 0, 2], [3, 1, 0]], scheme="loop", level=2)
    >>> control = torch.eye(4, 3, dtype=torch.float64, requires_grad=True)  # a tetrahedron
    >>> samples = layer(control)
    >>> tuple(samples.shape), tuple(layer.sample_faces.shape)
    ((34, 3), (64, 3))
    >>> samples.square().sum().backward()  # gradients reach the control points through Cᵀ
    >>> tuple(control.grad.shape)
    (4, 3)
    """

    def __init__(self, faces: FacesLike, scheme: str = "loop", level: int = 3, *,
                 num_vertices: Optional[int] = None, tags: Optional[dict] = None) -> None:
        super().__init__()
        counts, indices = faces_to_flat(faces)
        n = int(num_vertices) if num_vertices is not None else (int(indices.max()) + 1 if indices.size else 0)
        (indptr, idx, data, shape), (foff, fidx) = _subfit.sampling_operator(
            counts, indices, n, scheme, int(level), tags_to_arrays(tags, n)
        )
        t_indptr, t_idx, t_data = _csr_arrays(indptr, idx, data, shape)
        self.scheme = scheme
        self.level = int(level)
        self.num_vertices = n
        self.num_samples = int(shape[0])
        self.register_buffer("_crow", torch.from_numpy(indptr), persistent=False)
        self.register_buffer("_col", torch.from_numpy(idx), persistent=False)
        self.register_buffer("_val", torch.from_numpy(data), persistent=False)
        self.register_buffer("_t_crow", torch.from_numpy(t_indptr), persistent=False)
        self.register_buffer("_t_col", torch.from_numpy(t_idx), persistent=False)
        self.register_buffer("_t_val", torch.from_numpy(t_data), persistent=False)
        sf = faces_from_flat(foff, fidx)
        sf = np.asarray(sf) if isinstance(sf, np.ndarray) else np.stack(sf)
        self.register_buffer("sample_faces", torch.from_numpy(np.ascontiguousarray(sf)), persistent=False)
        self._cache: dict = {}

    def _apply(self, fn: Any, *args: Any, **kwargs: Any) -> "LimitSurface":
        # `.float()`/`.half()` must not round the stored operator: keep its weights in float64
        # (forward casts them to the input's dtype) and let device moves through.
        vals = (self._val, self._t_val)
        super()._apply(fn, *args, **kwargs)
        for name, old in zip(("_val", "_t_val"), vals):
            if getattr(self, name).dtype != torch.float64:
                setattr(self, name, old.to(device=getattr(self, name).device))
        return self

    def _operators(self, dtype: torch.dtype, device: torch.device) -> Tuple[Tensor, Tensor]:
        key = (dtype, device, self._val.data_ptr())
        ops = self._cache.get(key)
        if ops is None:
            n, s = self.num_vertices, self.num_samples
            with warnings.catch_warnings():  # "sparse CSR support is in beta"
                warnings.simplefilter("ignore", UserWarning)
                a = torch.sparse_csr_tensor(
                    self._crow.to(device), self._col.to(device),
                    self._val.to(device=device, dtype=torch.float64).to(dtype), (s, n),
                    check_invariants=False,
                )
                at = torch.sparse_csr_tensor(
                    self._t_crow.to(device), self._t_col.to(device),
                    self._t_val.to(device=device, dtype=torch.float64).to(dtype), (n, s),
                    check_invariants=False,
                )
            ops = self._cache[key] = (a, at)
        return ops

    def operator(self) -> Any:
        """The operator as a ``scipy.sparse.csr_matrix`` ``(s, n)`` (float64)."""
        import scipy.sparse as sp

        return sp.csr_matrix((self._val.cpu().numpy(), self._col.cpu().numpy(), self._crow.cpu().numpy()),
                             shape=(self.num_samples, self.num_vertices))

    def forward(self, control: Tensor) -> Tensor:
        """Limit samples ``(s, 3)`` of ``control (n, 3)``, or ``(b, s, 3)`` of ``(b, n, 3)``, in
        ``control``'s dtype and device. Raises ``TypeError`` for a non-tensor, ``ValueError``
        for another shape or a dtype other than float32/float64."""
        if not isinstance(control, torch.Tensor):
            raise TypeError("LimitSurface expects a torch.Tensor of control points")
        if control.dtype not in (torch.float32, torch.float64):
            raise ValueError(f"control points must be float32 or float64, got {control.dtype}")
        batched = control.dim() == 3
        if control.dim() not in (2, 3) or control.shape[-2:] != (self.num_vertices, 3):
            raise ValueError(
                f"control points must have shape ({self.num_vertices}, 3) or (b, {self.num_vertices}, 3), "
                f"got {tuple(control.shape)}"
            )
        a, at = self._operators(control.dtype, control.device)
        if batched:
            b = control.shape[0]
            x = control.permute(1, 0, 2).reshape(self.num_vertices, b * 3).contiguous()
            y = _SparseApply.apply(x, a, at)
            return y.reshape(self.num_samples, b, 3).permute(1, 0, 2)
        return _SparseApply.apply(control.contiguous(), a, at)

    def extra_repr(self) -> str:
        """The module's line in ``repr``: scheme, level, control points and samples."""
        return f"scheme={self.scheme!r}, level={self.level}, control_points={self.num_vertices}, samples={self.num_samples}"


# ------------------------------------------------------------------------------------------
# IMLS
# ------------------------------------------------------------------------------------------
def _as_np(name: str, a: ArrayOrTensor) -> np.ndarray:
    if isinstance(a, torch.Tensor):
        a = a.detach().cpu().numpy()
    arr = np.asarray(a, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"{name} must have shape (n, 3), got {arr.shape}")
    return np.ascontiguousarray(arr)


class _ImlsFunction(torch.autograd.Function):
    @staticmethod
    def forward(ctx: Any, samples: Tensor, field: Any) -> Tensor:  # type: ignore[override]
        x = samples.detach().to(device="cpu", dtype=torch.float64).reshape(-1, 3).contiguous().numpy()
        values, grads = field.evaluate(x)
        g = torch.from_numpy(grads).to(device=samples.device, dtype=samples.dtype)
        ctx.save_for_backward(g.reshape(samples.shape))
        return torch.from_numpy(values).to(device=samples.device, dtype=samples.dtype).reshape(samples.shape[:-1])

    @staticmethod
    @torch.autograd.function.once_differentiable
    def backward(ctx: Any, grad_out: Tensor) -> Tuple[Tensor, None]:  # type: ignore[override]
        (g,) = ctx.saved_tensors
        return grad_out.unsqueeze(-1) * g, None


def _imls_autograd(samples: Tensor, points: Tensor, normals: Tensor, field: Any) -> Tensor:
    """The IMLS values in torch arithmetic over the native kd-tree's neighbour lists: exact,
    differentiable in the samples, the points and the normals (and twice)."""
    flat = samples.reshape(-1, 3)
    off, idx, nearest = field.neighbors(flat.detach().to(device="cpu", dtype=torch.float64).contiguous().numpy())
    dev, dt = samples.device, samples.dtype
    q = torch.repeat_interleave(torch.arange(len(flat), device=dev), torch.from_numpy(np.diff(off)).to(dev))
    j = torch.from_numpy(idx).to(dev)
    jn = torch.from_numpy(nearest).to(dev)
    p = points.to(device=dev, dtype=dt)
    n = normals.to(device=dev, dtype=dt)
    n = n / n.norm(dim=1, keepdim=True)
    d = flat[q] - p[j]
    t = (1 - (d * d).sum(1) / (field.h * field.h)).clamp_min(0)
    phi = t.square().square()
    s = (n[j] * d).sum(1)
    den = torch.zeros(len(flat), dtype=dt, device=dev).index_add(0, q, phi)
    num = torch.zeros(len(flat), dtype=dt, device=dev).index_add(0, q, s * phi)
    fallback = (n[jn] * (flat - p[jn])).sum(1)
    ok = den > 0
    f = torch.where(ok, num / torch.where(ok, den, torch.ones_like(den)), fallback)
    return f.reshape(samples.shape[:-1])


class IMLS(torch.nn.Module):
    """The IMLS distance to a scan, with the kd-tree built once (reuse it across steps).

    ``points (p, 3)`` and ``normals (p, 3)`` (normalized here) define the implicit surface
    ``f(x) = Σ nᵢᵀ(x − pᵢ) φᵢ(x) / Σ φᵢ(x)``, ``φ(r) = (1 − r²/h²)⁴`` for ``r < h`` (Xie et al.
    2023 eq. 2–3, after Öztireli et al. 2009). Where no point lies within ``h`` the signed
    distance to the nearest point's tangent plane is used. ``forward(samples (..., 3))`` →
    ``(...)`` values in the samples' dtype.

    Gradients: with respect to the samples, the exact analytic gradient computed natively
    (value and gradient in one parallel pass). When ``points`` or ``normals`` are tensors that
    require grad, the values are instead computed in torch over the native neighbour lists, so
    gradients reach them too (exact; slower). The kd-tree is built here, over the points as
    they are now: if they move, build a new ``IMLS`` (or call :func:`imls`) each step.

    Parameters
    ----------
    points : (p, 3) tensor or array_like of float
        The scan's points.
    normals : (p, 3) tensor or array_like of float
        Their normals (any length, not zero; normalized here), oriented outwards: ``f`` is
        positive outside.
    h : float
        The kernel's support radius, in the points' units (a few point spacings; Xie et al.
        use about twice the mean spacing).

    Raises
    ------
    ValueError
        Arrays that are not ``(p, 3)``, a zero normal, ``h ≤ 0``; in ``forward``, samples
        that are not a float32/float64 tensor of shape ``(..., 3)``.

    Examples
    --------
    >>> import numpy as np, torch
    >>> from subfit.torch import IMLS
    >>> d = np.random.default_rng(0).normal(size=(5000, 3))
    >>> sphere = d / np.linalg.norm(d, axis=1, keepdims=True)  # unit sphere, normals = points
    >>> f = IMLS(sphere, sphere, h=0.2)
    >>> x = torch.tensor([[0.0, 0.0, 1.1], [0.0, 0.0, 0.9]], requires_grad=True)
    >>> values = f(x)  # about +0.1 (outside) and -0.1 (inside)
    >>> bool(torch.allclose(values, torch.tensor([0.1, -0.1]), atol=0.01))
    True
    >>> values.sum().backward(); bool(x.grad[0, 2] > 0.9)  # the gradient is about the normal
    True
    """

    def __init__(self, points: ArrayOrTensor, normals: ArrayOrTensor, h: float) -> None:
        super().__init__()
        self.field = _subfit.ImlsField(_as_np("points", points), _as_np("normals", normals), float(h))
        differentiable = any(isinstance(a, torch.Tensor) and a.requires_grad for a in (points, normals))
        self._scan = (points, normals) if differentiable else None

    @property
    def h(self) -> float:
        """The support radius (units of the points)."""
        return self.field.h

    def forward(self, samples: Tensor) -> Tensor:
        """IMLS values ``(...)`` at ``samples (..., 3)``, in the samples' dtype and device."""
        if not isinstance(samples, torch.Tensor) or samples.shape[-1:] != (3,):
            raise ValueError(f"samples must be a tensor of shape (..., 3), got {getattr(samples, 'shape', type(samples))}")
        if samples.dtype not in (torch.float32, torch.float64):
            raise ValueError(f"samples must be float32 or float64, got {samples.dtype}")
        if self._scan is not None and torch.is_grad_enabled():
            p, n = (torch.as_tensor(a) for a in self._scan)
            return _imls_autograd(samples, p, n, self.field)
        return _ImlsFunction.apply(samples, self.field)


def imls(samples: Tensor, points: ArrayOrTensor, normals: ArrayOrTensor, h: float) -> Tensor:
    """IMLS distance of ``samples (..., 3)`` to the scan ``points (p, 3)``, ``normals (p, 3)``
    with support radius ``h`` (the points' units).

    :class:`IMLS` keeps the kd-tree between calls; this builds it each call (O(p log p)).
    Returns ``(...)`` values; differentiable in ``samples``, and in ``points`` and
    ``normals`` when they are tensors that require grad. Arguments and errors as
    :class:`IMLS`.

    Examples
    --------
    >>> import numpy as np, torch
    >>> from subfit.torch import imls
    >>> d = np.random.default_rng(0).normal(size=(5000, 3))
    >>> sphere = d / np.linalg.norm(d, axis=1, keepdims=True)
    >>> v = imls(torch.tensor([[0.0, 1.05, 0.0]]), sphere, sphere, h=0.2)
    >>> bool(abs(v.item() - 0.05) < 0.01)
    True
    """
    return IMLS(points, normals, h)(samples)


# ------------------------------------------------------------------------------------------
# ARAP
# ------------------------------------------------------------------------------------------
def _triangles(faces: FacesLike) -> np.ndarray:
    """Fan triangulation ``(t, 3)`` of any polygons (triangles are kept as they are)."""
    counts, indices = faces_to_flat(faces)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    out = []
    for k in np.unique(counts):
        corners = indices[starts[counts == k][:, None] + np.arange(k)[None, :]]  # (m_k, k)
        out += [corners[:, [0, j, j + 1]] for j in range(1, k - 1)]
    return np.concatenate(out).astype(np.int64)


def cotangent_weights(rest: ArrayOrTensor, faces: FacesLike, *, clamp: bool = True
                      ) -> Tuple[Tensor, Tensor, Tensor]:
    """Cotangent weights of the rest shape: ``(i (e,), j (e,), w (e,))`` over directed edges
    (both directions of every edge), ``wᵢⱼ = ½ (cot αᵢⱼ + cot βᵢⱼ)`` (Pinkall & Polthier;
    polygons are fan-triangulated, so quads gain a diagonal). Degenerate triangles contribute
    nothing. With ``clamp`` (default) negative weights (edges opposite obtuse angles) are set
    to 0, so the ARAP energy is ≥ 0 — unclamped, an optimizer can drive it below zero.
    float64 on the rest shape's device.

    Parameters
    ----------
    rest : (n, 3) tensor or array_like of float
        The rest shape (the cage's vertices).
    faces : (m, k) array_like of int or list of polygons
        Its faces.
    clamp : bool
        Set negative weights to 0 (default ``True``).

    Returns
    -------
    (i, j, w)
        Two ``(e,)`` int64 tensors of vertex indices and an ``(e,)`` float64 tensor of
        weights, one entry per directed edge (``e`` is twice the number of edges).

    Raises
    ------
    ValueError
        ``rest`` not ``(n, 3)``, faces referring to vertices out of range.

    Examples
    --------
    >>> import numpy as np
    >>> from subfit.torch import cotangent_weights
    >>> i, j, w = cotangent_weights(np.eye(4, 3), [[0, 1, 2], [3, 2, 1], [3, 0, 2], [3, 1, 0]])
    >>> len(i), bool((w >= 0).all())  # 6 edges, both directions
    (12, True)
    """
    r = rest.detach().to(torch.float64) if isinstance(rest, torch.Tensor) else torch.as_tensor(np.asarray(rest, dtype=np.float64))
    if r.dim() != 2 or r.shape[1] != 3:
        raise ValueError(f"rest must have shape (n, 3), got {tuple(r.shape)}")
    t = torch.from_numpy(_triangles(faces)).to(r.device)
    if t.numel() and (t.min() < 0 or t.max() >= r.shape[0]):
        raise ValueError(f"faces refer to vertices out of range for {r.shape[0]} rest vertices")
    ii, jj, ww = [], [], []
    for c in range(3):  # the angle at corner c is opposite the edge (c+1, c+2)
        a, b, o = t[:, (c + 1) % 3], t[:, (c + 2) % 3], t[:, c]
        u, v = r[a] - r[o], r[b] - r[o]
        cross = torch.linalg.norm(torch.cross(u, v, dim=1), dim=1)
        ok = cross > 1e-14 * (u.norm(dim=1) * v.norm(dim=1)).clamp_min(1e-300)
        cot = torch.where(ok, (u * v).sum(1) / cross.clamp_min(1e-300), torch.zeros_like(cross))
        ii += [a, b]
        jj += [b, a]
        ww += [0.5 * cot, 0.5 * cot]
    i, j, w = torch.cat(ii), torch.cat(jj), torch.cat(ww)
    # Merge the two triangles of each edge.
    n = r.shape[0]
    key = i * n + j
    uniq, inv = torch.unique(key, return_inverse=True)
    wsum = torch.zeros(len(uniq), dtype=torch.float64, device=r.device).index_add_(0, inv, w)
    if clamp:
        wsum = wsum.clamp_min(0.0)
    return uniq // n, uniq % n, wsum


class ARAP(torch.nn.Module):
    """The ARAP energy against a fixed rest shape (weights computed once).

    ``E(x) = Σᵢ Σ_{j ∈ N(i)} wᵢⱼ ‖(xᵢ − xⱼ) − Rᵢ (rᵢ − rⱼ)‖²`` (Sorkine & Alexa 2007, eq. 3;
    Xie et al. 2023 eq. 5) with cotangent weights ``wᵢⱼ`` of the rest shape ``r`` (negative
    ones clamped to 0 unless ``clamp=False``, see :func:`cotangent_weights`) and, per
    vertex, the rotation ``Rᵢ`` minimizing its term (SVD of ``Σⱼ wᵢⱼ (rᵢ − rⱼ)(xᵢ − xⱼ)ᵀ``,
    reflections removed). Since each ``Rᵢ`` is optimal, ``∂E/∂x`` is the partial derivative at
    fixed rotations (envelope theorem), which is what autograd computes here. ``E = 0`` for
    any rigid motion of the rest shape.

    ``forward(control)``: ``(n, 3)`` → scalar, ``(b, n, 3)`` → ``(b,)``; float32 or float64.

    Parameters
    ----------
    rest : (n, 3) tensor or array_like of float
        The rest shape (the cage the energy keeps the deformation close to, up to rotations).
    faces : (m, k) array_like of int or list of polygons
        Its faces (fan-triangulated for the weights).
    clamp : bool
        Set negative cotangent weights to 0 (default ``True``; see :func:`cotangent_weights`).

    Raises
    ------
    ValueError
        As :func:`cotangent_weights`; in ``forward``, control points of another shape.

    Examples
    --------
    >>> import math, numpy as np, torch
    >>> from subfit.torch import ARAP
    >>> rest = torch.eye(4, 3, dtype=torch.float64)
    >>> energy = ARAP(rest, [[0, 1, 2], [3, 2, 1], [3, 0, 2], [3, 1, 0]])
    >>> c, s = math.cos(0.3), math.sin(0.3)
    >>> turn = torch.tensor([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]], dtype=torch.float64)
    >>> bool(energy(rest @ turn.T + 5.0) < 1e-20)  # a rigid motion costs nothing
    True
    >>> bool(energy(rest * torch.tensor([1.0, 1.0, 1.5], dtype=torch.float64)) > 0)  # a stretch does
    True
    """

    def __init__(self, rest: ArrayOrTensor, faces: FacesLike, *, clamp: bool = True) -> None:
        super().__init__()
        i, j, w = cotangent_weights(rest, faces, clamp=clamp)
        r = rest.detach().to(torch.float64) if isinstance(rest, torch.Tensor) else torch.as_tensor(np.asarray(rest, dtype=np.float64))
        self.register_buffer("i", i, persistent=False)
        self.register_buffer("j", j, persistent=False)
        self.register_buffer("w", w, persistent=False)
        self.register_buffer("rest_edges", r[i] - r[j], persistent=False)
        self.num_vertices = int(r.shape[0])

    def rotations(self, control: Tensor) -> Tensor:
        """The optimal per-vertex rotations ``(…, n, 3, 3)`` for ``control`` (no gradient)."""
        with torch.no_grad():
            x = control.detach().to(torch.float64)
            e = x[..., self.i, :] - x[..., self.j, :]
            outer = self.w[:, None, None] * self.rest_edges[:, :, None] * e[..., None, :]
            s = torch.zeros(*x.shape[:-2], self.num_vertices, 3, 3, dtype=torch.float64, device=x.device)
            s.index_add_(s.dim() - 3, self.i, outer)
            u, _, vh = torch.linalg.svd(s)
            v = vh.transpose(-1, -2)
            det = torch.linalg.det(v @ u.transpose(-1, -2))
            flip = torch.ones(*det.shape, 3, dtype=torch.float64, device=x.device)
            flip[..., 2] = torch.where(det < 0, -1.0, 1.0)
            return (v * flip[..., None, :]) @ u.transpose(-1, -2)

    def forward(self, control: Tensor) -> Tensor:
        """The energy of ``control`` (``(n, 3)`` → scalar, ``(b, n, 3)`` → ``(b,)``)."""
        if control.dim() not in (2, 3) or control.shape[-2:] != (self.num_vertices, 3):
            raise ValueError(
                f"control must have shape ({self.num_vertices}, 3) or (b, {self.num_vertices}, 3), got {tuple(control.shape)}"
            )
        rot = self.rotations(control).to(control.dtype)
        e = control[..., self.i, :] - control[..., self.j, :]
        rest = self.rest_edges.to(control.dtype)
        d = e - (rot[..., self.i, :, :] @ rest[:, :, None]).squeeze(-1)
        return (self.w.to(control.dtype) * (d * d).sum(-1)).sum(-1)


def arap(control: Tensor, rest: ArrayOrTensor, faces: FacesLike, *, clamp: bool = True) -> Tensor:
    """The ARAP energy of ``control`` (``(n, 3)`` → scalar, or ``(b, n, 3)`` → ``(b,)``)
    against ``rest (n, 3)`` with ``faces``, differentiable in ``control``.

    :class:`ARAP` keeps the weights between calls; this computes them each call. Arguments
    and errors as :class:`ARAP`.

    Examples
    --------
    >>> import torch
    >>> from subfit.torch import arap
    >>> rest = torch.eye(4, 3, dtype=torch.float64)
    >>> x = (rest * 1.2).requires_grad_()  # a scaled copy: not rigid
    >>> e = arap(x, rest, [[0, 1, 2], [3, 2, 1], [3, 0, 2], [3, 1, 0]])
    >>> e.backward(); bool(e > 0), tuple(x.grad.shape)
    (True, (4, 3))
    """
    return ARAP(rest, faces, clamp=clamp).to(control.device)(control)
