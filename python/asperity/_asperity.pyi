# Type stubs of the compiled module asperity._asperity (python/src/lib.rs). Units are SI.
from __future__ import annotations

import os
import pathlib
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str
PRESETS: List[Tuple[str, float, float]]
"""The preset local laws: (name, mu_s, mu_d). Illustrative placeholders, not measurements."""

class Error(ValueError):
    """Bad input or a computation that failed: one line naming the argument and the reason."""

_Path = Union[str, "os.PathLike[str]"]
_Lengths = Union[float, Tuple[float, float]]
_Map = npt.ArrayLike

class Topography:
    """A height map: heights [m], shape (ny, nx), on a window of physical size (lx, ly) [m]."""

    def __init__(
        self, heights: _Map, physical_size: _Lengths, periodic: bool = False, *, max_points: Optional[int] = None
    ) -> None: ...
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
    def height_unit(self) -> Optional[str]:
        """Height unit the file states or read_topography was given (heights are in metres)."""
    @property
    def file(self) -> Optional[pathlib.Path]: ...
    @property
    def missing_points(self) -> int: ...
    def detrend(self, kind: str = "plane") -> Topography:
        """Levelled (least squares): "none", "mean", "plane", "poly:N" (N ≤ 8) or "sphere"; or line
        by line, "line:N" (N ≤ 3) or "line:median", optionally then the whole map ("line:1,plane")."""
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
    def add_cap(self, radius: float, *, paraboloid: bool = False) -> Topography:
        """A spherical cap of radius [m] added, apex at the centre (a ball levelled flat)."""
    def fill_missing(self) -> Topography:
        """Missing points filled harmonically."""
    def statistics(self) -> Dict[str, float]:
        """SurfaceTopography's mean, rms_height [m], rms_gradient, rms_slope_from_profile [1],
        rms_curvature_from_area, rms_curvature_from_profile [1/m]."""

class Profile:
    """A line profile: heights [m] along x at increasing positions [m] (as stored when the file
    states no unit and none was given)."""

    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """Positions along x [m], the first 0: a float64 copy."""
    @property
    def heights(self) -> npt.NDArray[np.float64]:
        """Heights [m], NaN where missing: a float64 copy."""
    @property
    def points(self) -> int:
        """Number of points."""
    @property
    def length(self) -> float:
        """Length [m]: points × step when uniform, else the last position."""
    @property
    def step(self) -> Optional[float]:
        """The step [m] of equally spaced positions; None when they are not."""
    @property
    def channel(self) -> str:
        """The column the heights come from."""
    @property
    def height_unit(self) -> Optional[str]:
        """The heights' unit as the file states it; None when unknown."""
    @property
    def file(self) -> Optional[pathlib.Path]:
        """The file read."""
    @property
    def missing_points(self) -> int:
        """Number of missing (NaN) points."""
    def statistics(self) -> Dict[str, float]:
        """SurfaceTopography's mean, rms_height [m] (Rq), rms_slope [1] (Rdq), rms_curvature
        [1/m] (Rddq) of a line scan."""
    def detrend(self, kind: str = "plane") -> Profile:
        """Levelled (least squares): "mean", "plane" (the straight line), "poly:N" or "line:N"
        (degree N along x), "line:median" or "none"."""

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
    displacement: npt.NDArray[np.float64]
    """Elastic surface displacement [m], (ny, nx)."""
    contact_fraction: float
    contact_area: float
    """Real contact area [m²]."""
    contact_points: int
    patches: int
    patch_sizes: List[int]
    """Patch sizes in pixels, largest first."""
    max_pressure: float
    """Largest local pressure [Pa]."""
    edge_load_fraction: float
    """Share of the load within 2 % of the window's edges (above 0.01: a warning)."""
    load_above_hardness_fraction: Optional[float]
    """Share of the load at p ≥ hardness; None without a hardness."""
    hardness: Optional[float]
    """Hardness [Pa] given to contact, or None."""
    plastic: bool
    """Whether the pressure was capped at the hardness."""
    effective_modulus: float
    """E* [Pa]."""
    iterations: int
    operator_applications: Optional[float]
    """FFT pairs; None with adhesion."""
    residual: float
    seconds: float
    """Wall-clock time of the solve [s]."""
    physical_size: Tuple[float, float]
    """(lx, ly) [m]."""
    boundary: str
    """"periodic" or "free"."""
    warnings: List[str]
    """The warnings about this load, as warnings.warn gave them."""
    compressive_force: Optional[float]
    """With adhesion: N_c [N], the integral of pressure; None without."""
    adhesive_force: Optional[float]
    """With adhesion: N_a = N_c − N [N], the integral of the tension."""
    traction: Optional[npt.NDArray[np.float64]]
    """With adhesion: traction [Pa], (ny, nx), tensile negative."""
    separation: Optional[float]
    """With adhesion: separation [m] (periodic: mean gap)."""
    pull_off: Optional[float]
    """With pull_off=True: the pull-off force [N]."""

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
        """As curve.csv: {"element_shear_n" [N], "force_n" [N], "coefficient", "stuck", "peak"}."""

class Slide:
    """The onset of sliding with elastic sharing between the contact points."""

    load: float
    """N [N]."""
    contact_points: int
    mu_s: float
    mu_d: float
    law: Optional[str]
    slip_distance: Optional[float]
    """d_c [m]: 0 for the instant drop, None for a measured curve."""
    static_force: float
    """F_S [N]."""
    static_coefficient: float
    friction_drop: float
    """F_S / (mu_d N)."""
    peak_displacement: Optional[float]
    """δ at F_S [m]; None when F_S is the steady sliding force."""
    stuck: ClassShare
    critical: ClassShare
    weakening: ClassShare
    """Slipped before the peak, 0 < s < d_c."""
    weakened: ClassShare
    """Slipped before the peak, s ≥ d_c (at mu_d)."""
    equal_sharing_static_coefficient: float
    equal_sharing_friction_drop: float
    equal_sharing_same_law_static_coefficient: Optional[float]
    """Equal sharing with the same slip weakening; None for a measured curve."""
    equal_sharing_same_law_friction_drop: Optional[float]
    shear_x: npt.NDArray[np.float64]
    """Shear along x at the peak [Pa], (ny, nx)."""
    shear_y: npt.NDArray[np.float64]
    """Shear along y at the peak [Pa], (ny, nx)."""
    classes: npt.NDArray[np.int8]
    """0 no contact, 1 weakened, 2 critical, 3 stuck, 4 weakening; (ny, nx)."""
    steps: int
    solves: int
    iterations: int
    seconds: float
    def curve(self) -> Dict[str, npt.NDArray[Any]]:
        """As curve.csv: {"displacement_m" [m], "force_n" [N], "coefficient", "stick_points",
        "slip_points"}."""

class PartialSlip:
    """A partial-slip state at an imposed tangential force."""

    load: float
    """N [N]."""
    mu: float
    tangential_force: float
    """Q [N]."""
    displacement: float
    """δ [m]."""
    stick_points: int
    slip_points: int
    shear_x: npt.NDArray[np.float64]
    shear_y: npt.NDArray[np.float64]
    classes: npt.NDArray[np.int8]
    solves: int
    iterations: int
    seconds: float

def read_topography(
    path: _Path,
    channel: Union[str, int, None] = None,
    *,
    size: Optional[_Lengths] = None,
    height_unit: Optional[str] = None,
    position_unit: Optional[str] = None,
    format: Optional[str] = None,
    max_points: Optional[int] = None,
) -> Union[Topography, Profile]:
    """A Topography (2-D map), or a Profile when the file holds a line profile."""
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
    topography: Union[Topography, Profile], window: str = "auto"
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """(q [rad/m], C(q) [m⁴]; of a Profile its 1-D spectrum [m³])."""
def contact(
    topography: Topography,
    loads: Union[float, Sequence[float]],
    *,
    youngs: float = 130e9,
    poisson: float = 0.26,
    youngs2: Optional[float] = None,
    poisson2: Optional[float] = None,
    hardness: Optional[float] = None,
    plastic: bool = False,
    boundary: str = "periodic",
    tolerance: float = 1e-10,
    max_iter: int = 20000,
    device: str = "cpu",
    adhesion_work: Optional[float] = None,
    adhesion_stress: Optional[float] = None,
    adhesion_range: Optional[float] = None,
    adhesion_law: str = "maugis",
    pull_off: bool = False,
) -> List[ContactSolution]:
    """Elastic (or, with plastic=True, elastic–perfectly-plastic) normal contact; loads [N], moduli and hardness [Pa];
    with adhesion_work [J/m²] and adhesion_stress [Pa] or adhesion_range [m], adhesive (loads may be tensile)."""
def onset(
    pressure: Union[_Map, ContactSolution],
    physical_size: Optional[_Lengths] = None,
    *,
    mu_s: Optional[float] = None,
    mu_d: Optional[float] = None,
    law: Optional[str] = None,
    curve: Optional[_Path] = None,
    window: Optional[Tuple[float, float]] = None,
    pixel_area: Optional[float] = None,
) -> Onset:
    """curve: CSV of (displacement, friction coefficient): mu_s its peak, mu_d its mean after
    the peak or over window (start, end) past it, in the curve's displacement unit."""
@overload
def slide(
    solution: ContactSolution,
    *,
    mu_s: Optional[float] = None,
    mu_d: Optional[float] = None,
    law: Optional[str] = None,
    curve: Optional[_Path] = None,
    curve_unit: Optional[float] = None,
    window: Optional[Tuple[float, float]] = None,
    slip_distance: Optional[float] = None,
    tangential_force: None = None,
    tolerance: float = 1e-6,
    max_iter: int = 20000,
) -> Slide:
    """The onset of sliding with elastic sharing; slip_distance [m] (default 2e-9, 0: the
    instant drop); a curve followed past its peak as μ(slip), its displacements in curve_unit
    [m]."""
@overload
def slide(
    solution: ContactSolution,
    *,
    mu_s: Optional[float] = None,
    mu_d: Optional[float] = None,
    law: Optional[str] = None,
    curve: None = None,
    curve_unit: None = None,
    window: None = None,
    slip_distance: None = None,
    tangential_force: float,
    tolerance: float = 1e-6,
    max_iter: int = 20000,
) -> PartialSlip:
    """The partial-slip state at tangential_force [N] under Coulomb friction at mu_s."""
def _analyse_shs(
    time_s: Sequence[float],
    friction_n: Sequence[float],
    normal_n: Sequence[float],
    displacement_m: Optional[Sequence[float]],
    speed: float,
    window: float,
    window_start: float,
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
