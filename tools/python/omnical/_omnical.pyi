# Type stub of the extension module omnical._omnical, written by hand from the bindings
# (tools/python/bind_*.cc); tests/python/test_stub.py checks that it names every public
# class, function, method and property of the module with the same parameter names.
import os
from typing import Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

PathLike = Union[str, "os.PathLike[str]"]
ArrayLike = npt.ArrayLike
# progress(stage, done, total) -> None or bool (False cancels); total 0: unknown.
Progress = Optional[Callable[[str, int, int], Optional[bool]]]
_STATUS_NAMES: List[str]

class InputError(ValueError):
    """Bad input: the library's one-line message naming the file and field."""

class Cancelled(RuntimeError):
    """A long call stopped because its progress callback returned False."""

class Sensor:
    """A catadioptric sensor: lens, mirror profile and mirror pose, as in sensor.yaml."""
    @staticmethod
    def load(path: PathLike) -> "Sensor": ...
    @staticmethod
    def from_yaml(text: str, source: str = "<string>") -> "Sensor": ...
    @staticmethod
    def from_parameters(parameters: dict) -> "Sensor": ...
    def save(self, path: PathLike) -> None: ...
    def to_yaml(self) -> str: ...
    @property
    def parameters(self) -> dict: ...
    @property
    def profile(self) -> str: ...
    @property
    def lens(self) -> str: ...
    @property
    def rim_radius_mm(self) -> float: ...
    @property
    def image_size(self) -> Tuple[int, int]: ...
    @property
    def is_axial(self) -> bool: ...
    def project(self, points: ArrayLike) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint8]]: ...
    def unproject(self, pixels: ArrayLike) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.uint8]]: ...
