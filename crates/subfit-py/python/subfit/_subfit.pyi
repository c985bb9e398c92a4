"""Type stubs of the native module ``subfit._subfit`` (pyo3). Private: use the ``subfit`` API."""

from typing import Any, Callable, Optional, Tuple

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
FaceArrays = Tuple[I64, I64]
TagArrays = Tuple[I64, F64, I64, F64]
Csr = Tuple[I64, I64, F64, Tuple[int, int]]

__version__: str

class NativeFit:
    def vertices(self) -> F64: ...
    def faces(self) -> FaceArrays: ...
    def tags(self) -> TagArrays: ...
    def scheme(self) -> str: ...
    def report_json(self) -> str: ...
    def reached(self) -> bool: ...
    def summary(self) -> str: ...
    def write_into(self, dir: str, limit_quads: bool = False) -> None: ...

def fit(
    points: F64,
    faces: Optional[FaceArrays] = None,
    normals: Optional[F64] = None,
    *,
    scheme: str = "loop",
    method: str = "sdm",
    step: str = "lm",
    tolerance: Optional[float] = None,
    max_error: Optional[float] = None,
    max_control_points: Optional[int] = None,
    control_points: Optional[int] = None,
    as_points: bool = False,
    init: Optional[Tuple[F64, FaceArrays]] = None,
    init_method: Optional[str] = None,
    lambda_start: float = 1e-3,
    lambda_end: Optional[float] = None,
    sample_level: int = 3,
    max_iterations: int = 100,
    stage_iterations: int = 6,
    one_sided: bool = False,
    coverage: float = 1.0,
    facing: bool = True,
    chordal: bool = False,
    refine: bool = True,
    edge_flips: bool = True,
    max_depth: int = 5,
    local: bool = False,
    local_rings: Optional[int] = None,
    local_field_peak: float = 0.8,
    local_field_share: float = 0.5,
    error_scale: Optional[float] = None,
    imls_radius: Optional[float] = None,
    arap: float = 0.0,
    quads: str = "field",
    name: Optional[str] = None,
    progress: Optional[Callable[[dict], Any]] = None,
) -> NativeFit: ...

class NativeSequence:
    def vertices(self) -> npt.NDArray[np.float64]: ...
    def faces(self) -> FaceArrays: ...
    def tags(self) -> TagArrays: ...
    def scheme(self) -> str: ...
    def report_json(self) -> str: ...
    def write_into(self, dir: str, fps: float) -> None: ...

def fit_sequence(
    frames: Any,
    *,
    template: Optional[Tuple[F64, FaceArrays]] = None,
    control_points: Optional[int] = None,
    scheme_name: str = "auto",
    method: str = "sdm",
    arap: float = 0.01,
    lambda_: float = 1e-5,
    iterations: int = 12,
    tolerance: float = 5e-4,
    sample_level: int = 2,
    silhouette_views: int = 8,
    silhouette_resolution: int = 128,
    silhouette_weight: float = ...,
    track_nodes: int = 60,
    markers: Any = None,
    progress: Optional[Callable[[dict], Any]] = None,
) -> NativeSequence: ...

class NativeSurface:
    def __init__(self, vertices: F64, counts: I64, indices: I64, scheme_name: str,
                 tag_arrays: Optional[TagArrays] = None) -> None: ...
    @property
    def scheme(self) -> str: ...
    def sample(self, level_: int, normals: bool = False) -> Tuple[F64, Optional[F64]]: ...
    def operator(self, level_: int, which: str = "position") -> Csr: ...
    def level_faces(self, level_: int) -> Tuple[I64, I64]: ...
    def evaluate(self, face: I64, u: F64, v: F64, sub: I64) -> Tuple[F64, F64, F64, F64, F64]: ...
    def evaluation_operator(self, face: I64, u: F64, v: F64, sub: I64) -> Csr: ...
    def closest_point(self, points: F64) -> Tuple[F64, I64, I64, F64, F64, F64, F64, F64, npt.NDArray[np.bool_]]: ...

def sampling_operator(counts: I64, indices: I64, num_vertices: int, scheme_name: str, level_: int,
                      tag_arrays: Optional[TagArrays] = None) -> Tuple[Csr, Tuple[I64, I64]]: ...

class ImlsField:
    def __init__(self, points: F64, normals: F64, h: float) -> None: ...
    @property
    def h(self) -> float: ...
    def __len__(self) -> int: ...
    def evaluate(self, x: F64) -> Tuple[F64, F64]: ...

def read(path: str) -> Tuple[F64, Optional[F64], Optional[npt.NDArray[np.uint8]], Tuple[I64, I64], str]: ...
def write(path: str, vertices: F64, faces: Optional[FaceArrays] = None, normals: Optional[F64] = None,
          colors: Optional[npt.NDArray[np.uint8]] = None, binary: bool = False, scheme: str = "catmull-clark",
          tag_arrays: Optional[TagArrays] = None, boundary: str = "edge-only") -> None: ...
def formats() -> list: ...
