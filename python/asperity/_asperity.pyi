# Type stubs of the compiled module asperity._asperity (python/src/lib.rs). Units are SI.
from __future__ import annotations

import os
import pathlib
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
PRESETS: List[Tuple[str, float, float]]
"""The preset local laws: (name, mu_s, mu_d). Illustrative placeholders, not measurements."""

class Error(ValueError):
    """Bad input or a computation that failed: the command line's one-line message."""

_Path = Union[str, "os.PathLike[str]"]
_Lengths = Union[float, Tuple[float, float]]
_Map = npt.ArrayLike

class Topography:
    """A height map: heights [m], shape (ny, nx), on a window of physical size (lx, ly) [m]."""

    def __init__(self, heights: _Map, physical_size: _Lengths, periodic: bool = False) -> None: ...
    @property
    def heights(self) -> npt.NDArray[np.float64]:
        """Heights [m], float64 (ny, nx): a read-only view, no copy."""
    @property
    def physical_size(self) -> Optional[Tuple[float, float]]:
        """(lx, ly) [m], or None when the file states none."""
    @property
    def pixel_size(self) -> Optional[Tuple[float, float]]:
        """(dx, dy) [m], or None without a physical size."""
    @property
    def shape(self) -> Tuple[int, int]:
        """(ny, nx)."""
    @property
    def periodic(self) -> bool: ...
    @property
    def channels(self) -> List[str]:
        """Channel names of the file it was read from."""
    @property
    def channel(self) -> str: ...
    @property
    def unit(self) -> Optional[str]:
        """Height unit the file states (heights are in metres all the same)."""
    @property
    def file(self) -> Optional[pathlib.Path]: ...
    @property
    def missing_points(self) -> int: ...
    def detrend(self, kind: str = "plane") -> Topography:
        """Levelled: "none", "mean", "plane", "poly:N" (N ≤ 8) or "sphere"."""
    def crop(
        self,
        x: Optional[Tuple[float, float]] = None,
        y: Optional[Tuple[float, float]] = None,
        *,
        columns: Optional[Tuple[int, int]] = None,
        rows: Optional[Tuple[int, int]] = None,
    ) -> Topography:
        """The part inside x, y [m] from the origin, or columns, rows [pixels], end excluded."""
    def resample(self, pixel_size: float, *, max_points: Optional[int] = None) -> Topography:
        """Resampled to the pixel size [m] nearest to pixel_size that divides the size."""
    def fill_missing(self) -> Topography:
        """Missing points filled harmonically."""

class ContactSolution:
    """One load of a contact solve."""

    load: float
    """Normal load N [N]."""
    mean_pressure: float
    """N / (lx·ly) [Pa]."""
    pressure: npt.NDArray[np.float64]
    """Pressure [Pa], (ny, nx)."""
    gap: npt.NDArray[np.float64]
    """Gap [m], (ny, nx): zero on the contact."""
    contact_fraction: float
    contact_area: float
    """Real contact area [m²]."""
    contact_points: int
    patches: int
    patch_sizes: List[int]
    """Patch sizes in pixels, largest first."""
    iterations: int
    residual: float
    seconds: float
    """Wall-clock time of the solve [s]."""
    physical_size: Tuple[float, float]
    boundary: str

class ClassShare:
    """Count and shares of one class of elements at the critical state."""

    count: int
    normal_fraction: float
    """Fraction of the normal load N."""
    friction_fraction: float
    """Fraction of the static friction force F_S."""

class Onset:
    """The onset of sliding under the stick-slip transition model (equal load sharing)."""

    @property
    def static_coefficient(self) -> float: ...
    @property
    def dynamic_coefficient(self) -> float: ...
    @property
    def friction_drop(self) -> float:
        """F_S / (mu_d N)."""
    @property
    def mu_s(self) -> float: ...
    @property
    def mu_d(self) -> float: ...
    @property
    def law(self) -> Optional[str]: ...
    @property
    def elements(self) -> int: ...
    @property
    def critical_index(self) -> int: ...
    @property
    def critical_pressure(self) -> float:
        """Pressure of the critical elements [Pa]."""
    @property
    def normal_force(self) -> Optional[float]:
        """N [N], None without a physical size or pixel area."""
    @property
    def static_force(self) -> Optional[float]:
        """F_S [N], None without a physical size or pixel area."""
    @property
    def critical(self) -> ClassShare: ...
    @property
    def pre_sliding(self) -> ClassShare: ...
    @property
    def subcritical(self) -> ClassShare: ...
    @property
    def classes(self) -> npt.NDArray[np.int8]:
        """0 no contact, 1 pre-sliding, 2 critical, 3 subcritical; (ny, nx)."""
    def stress_ratio(self, fraction: float = 1.0) -> npt.NDArray[np.float64]:
        """Local τ/σ at δ = fraction · δ_peak, NaN out of contact; (ny, nx)."""
    def curve(self, loading: str = "equal_load_sharing", max_points: int = 2000) -> Dict[str, Any]:
        """{"shear" [N], "force" [N], "coefficient", "stuck", "peak"}."""

def read_topography(
    path: _Path,
    channel: Union[str, int, None] = None,
    *,
    size: Optional[_Lengths] = None,
    height_unit: Optional[str] = None,
    format: Optional[str] = None,
    max_points: Optional[int] = None,
) -> Topography: ...
def compound(ball: Topography, wafer: Topography) -> Topography: ...
def generate(
    *,
    size: _Lengths,
    grid: Union[int, Tuple[int, int]],
    seed: int,
    hurst: Optional[float] = None,
    rms: Optional[float] = None,
    rms_slope: Optional[float] = None,
    rolloff: Optional[float] = None,
    cutoff: Optional[float] = None,
    long_cutoff: Optional[float] = None,
    sphere_radius: Optional[float] = None,
    paraboloid: bool = False,
    max_points: Optional[int] = None,
) -> Topography: ...
def psd(
    topography: Topography, window: str = "auto"
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """(q [rad/m], C(q) [m⁴])."""
def contact(
    topography: Topography,
    loads: Union[float, Sequence[float]],
    *,
    youngs: float = 130e9,
    poisson: float = 0.26,
    youngs2: Optional[float] = None,
    poisson2: Optional[float] = None,
    boundary: str = "periodic",
    tolerance: float = 1e-10,
    max_iter: int = 20000,
) -> List[ContactSolution]: ...
def onset(
    pressure: Union[_Map, ContactSolution],
    physical_size: Optional[_Lengths] = None,
    *,
    mu_s: Optional[float] = None,
    mu_d: Optional[float] = None,
    law: Optional[str] = None,
    pixel_area: Optional[float] = None,
) -> Onset: ...
def _analyse_shs(
    time_s: Sequence[float],
    friction_n: Sequence[float],
    normal_n: Sequence[float],
    displacement_m: Optional[Sequence[float]],
    speed: float,
    window: float,
    peak_within: float,
    min_duration: float,
    hold_fraction: float,
    slide_fraction: float,
    group_tolerance: float,
) -> str: ...
def _run_study(
    study_file: Optional[str],
    study_json: Optional[str],
    out: str,
    quick: bool,
    fresh: bool,
    progress: Optional[Callable[[Dict[str, Any]], None]],
) -> str: ...
