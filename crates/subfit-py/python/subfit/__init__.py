"""subfit: fit compact subdivision surfaces (Loop, Catmull-Clark) to dense 3D scans.

numpy arrays in, numpy arrays and plain objects out:

- :func:`fit` — the whole pipeline of ``subfit fit`` (scan → cage whose limit surface is within
  a tolerance), returning a picklable :class:`Fit`;
- :func:`fit_sequence` — one cage fitted to every frame of a deforming scan (``subfit
  sequence``), returning a :class:`Sequence`;
- :class:`Surface` — a control mesh with a scheme: limit samples, the sparse sampling operator
  (``scipy.sparse.csr_matrix``), exact evaluation with derivatives, closest points;
- :func:`read` / :func:`write` — PLY, OBJ, OFF, STL, XYZ (and USDA cages on writing);
- ``subfit.torch`` (needs PyTorch) — :class:`~subfit.torch.LimitSurface`,
  :func:`~subfit.torch.imls`, :func:`~subfit.torch.arap`, differentiable.

Bad arrays raise ``ValueError`` naming the argument and the reason; numerical failures raise
``RuntimeError`` with diagnostics. Long computations release the GIL.
"""

from ._subfit import __version__
from ._fit import Fit, fit
from ._io import Mesh, read, write
from ._sequence import Sequence, fit_sequence
from ._surface import ClosestPointDetails, ClosestPoints, Evaluation, Surface

__all__ = [
    "__version__",
    "fit",
    "Fit",
    "fit_sequence",
    "Sequence",
    "Surface",
    "Evaluation",
    "ClosestPoints",
    "ClosestPointDetails",
    "read",
    "write",
    "Mesh",
]


def __getattr__(name: str):  # PEP 562: ``subfit.torch`` without importing torch eagerly
    if name == "torch":
        import importlib

        return importlib.import_module(".torch", __name__)
    raise AttributeError(f"module 'subfit' has no attribute {name!r}")
