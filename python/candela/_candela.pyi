"""Type stubs of the extension module (the Rust side of the package; use `candela` instead)."""

from typing import Any, Callable, Dict, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

class CandelaError(ValueError):
    """An error candela reports; the message names the file, line:column or field."""

class Cancelled(CandelaError):
    """A render stopped before it finished; the message says what was written."""

class FileError(OSError, CandelaError):
    """A file that cannot be read or written; errno is the system's, or None for a file candela
    refuses itself (FIFO, device, directory, over its size limit)."""

def render(
    scene: str,
    out: str,
    *,
    spp: Optional[int] = None,
    seed: Optional[int] = None,
    max_depth: Optional[int] = None,
    threads: Optional[int] = None,
    illuminance: bool = False,
    caustics: Optional[str] = None,
    exposure_ev: Optional[float] = None,
    units: str = "si",
    target_error: Optional[float] = None,
    target_fraction: float = 1.0,
    target_floor_cd_m2: Optional[float] = None,
    max_spp: Optional[int] = None,
    max_time_s: Optional[float] = None,
    checkpoint_interval_s: Optional[float] = None,
    resume: bool = False,
    overwrite: bool = False,
    save_state: bool = False,
    falsecolour: bool = False,
    shard: Optional[str] = None,
    alpha_opic: bool = False,
    mesopic: bool = False,
    spectral_bands: Optional[int] = None,
    progress: Optional[Callable[[int, int, float], Optional[bool]]] = None,
    cancel: Any = None,
) -> Dict[str, Any]: ...
def merge(
    states: List[str], out: str, *, exposure_ev: Optional[float] = None, partial: bool = False
) -> Dict[str, Any]: ...
def scene_dict_to_ron(json: str) -> str: ...
def check_scene_text(text: str, name: str) -> None: ...
def check_scene_file(path: str) -> Tuple[int, int]: ...
def read_scene_file(path: str) -> str: ...
def sd_to_xyz(
    wavelengths_nm: npt.NDArray[np.float64],
    values: npt.NDArray[np.float64],
    kind: str,
    illuminant: Optional[Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]] = None,
    observer: str = "1931",
    method: str = "integration",
) -> npt.NDArray[np.float64]: ...
def xyz_to_xy_array(xyz: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
def xyz_to_cct_duv(xyz: npt.NDArray[np.float64], method: str = "ohno2013") -> npt.NDArray[np.float64]: ...
def cri(wavelengths_nm: npt.NDArray[np.float64], values: npt.NDArray[np.float64]) -> Dict[str, npt.NDArray[np.float64]]: ...
def alpha_opic(wavelengths_nm: npt.NDArray[np.float64], values: npt.NDArray[np.float64]) -> Dict[str, npt.NDArray[np.float64]]: ...
def tm30(wavelengths_nm: npt.NDArray[np.float64], values: npt.NDArray[np.float64]) -> Dict[str, npt.NDArray[np.float64]]: ...
def named_spectrum(name: str) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def read_exr(path: str) -> Dict[str, Any]: ...
def read_state(path: str) -> Dict[str, Any]: ...
