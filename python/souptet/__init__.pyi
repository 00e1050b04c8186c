# Type stub for souptet (the module's docstrings give units and defaults).
import os
from typing import Any, Callable, Dict, List, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, bytes, "os.PathLike[str]", "os.PathLike[bytes]"]
_F64 = npt.NDArray[np.float64]
_I64 = npt.NDArray[np.int64]

__version__: str

class Error(ValueError):
    status: str
    file: Optional[str]
    line: Optional[int]

class Cancelled(Exception): ...

class Cancel:
    def __init__(self) -> None: ...
    def set(self) -> None: ...
    def clear(self) -> None: ...
    def is_set(self) -> bool: ...

def read(path: _Path) -> Tuple[_F64, _I64]: ...
def read_parts(path: _Path, mode: str = ...) -> Tuple[_F64, _I64, npt.NDArray[np.int32], List[str]]: ...

class MeshResult:
    points: _F64
    tets: _I64
    boundary: _I64
    min_dihedral: float
    max_dihedral: float
    encloses: bool
    converged: bool
    h: float
    seed: int
    candidates: int
    max_distance: float
    guessed: float
    seconds: float
    embed_tet: _I64
    embed_bary: _F64
    parts: Optional[npt.NDArray[np.int32]]
    part_share: Optional[_F64]
    part_names: Optional[List[str]]
    def to_meshio(self) -> Any: ...
    def write(self, path: _Path, *, msh_version: int = ..., binary: bool = ...) -> None: ...

def mesh(
    V: npt.ArrayLike,
    F: npt.ArrayLike,
    *,
    cells: int = ...,
    size: Optional[float] = ...,
    tets: Optional[int] = ...,
    tries: int = ...,
    seed: int = ...,
    offset: float = ...,
    threads: int = ...,
    progress: Optional[Callable[[Dict[str, Any]], object]] = ...,
    float32: bool = ...,
    cancel: Optional[Cancel] = ...,
    try_all: bool = ...,
    parts: Union[None, str, npt.ArrayLike] = ...,
    part_names: Optional[List[str]] = ...,
    fill_holes: bool = ...,
    symmetry: bool = ...,
) -> MeshResult: ...

class Field:
    values: npt.NDArray[np.float32]
    inside: npt.NDArray[np.bool_]
    origin: Tuple[float, float, float]
    voxel: float
    band: float

def pseudo_volume(V: npt.ArrayLike, F: npt.ArrayLike, resolution: int = ..., *,
                  fill_holes: bool = ..., symmetry: bool = ...) -> Field: ...
def distance(V: npt.ArrayLike, F: npt.ArrayLike, resolution: int = ..., *, band: float = ...) -> Field: ...
def wrap(V: npt.ArrayLike, F: npt.ArrayLike, resolution: int = ..., *,
         fill_holes: bool = ..., symmetry: bool = ...) -> Tuple[_F64, _I64]: ...
