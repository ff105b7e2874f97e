"""Type stubs of the gyrolab package (see the docstrings in __init__.py)."""

import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

PathLike = Union[str, os.PathLike[str]]
ArrayLike = npt.ArrayLike

class Error(ValueError):
    """A gyrolab evaluation failed: bad data or options (the message names file, line, field)."""

class AllanResult:
    """An Allan-family deviation with bounds and noise terms; arrays per averaging time."""

    taus_s: np.ndarray
    m: np.ndarray
    dev: np.ndarray
    ci_low: np.ndarray
    ci_high: np.ndarray
    n_terms: np.ndarray
    alpha: np.ndarray
    kind: str
    unit: str
    noise: Dict[str, Any]
    readings: List[Dict[str, Any]]
    fit: Optional[Dict[str, Any]]
    def to_dict(self) -> Dict[str, Any]:
        """The result with the keys of `gyrolab allan --json`."""
    def plot(self, ax: Any = ..., label: Optional[str] = ...) -> Any:
        """Log-log curve with bounds and N/B/K asymptotes (needs matplotlib); returns the axes."""

def allan(
    x: ArrayLike,
    rate_hz: float,
    kind: str = ...,
    taus: Union[str, Sequence[float]] = ...,
    confidence: Optional[float] = ...,
    unit: str = ...,
    scale_factor: Optional[float] = ...,
    null: Optional[float] = ...,
    fit_range_s: Optional[Tuple[float, float]] = ...,
) -> AllanResult:
    """Allan-family deviation of rate samples `x` at `rate_hz` (kind oadev, adev, mdev, tdev,
    hdev, ohdev, totdev; taus octave, decade, all, N/decade or seconds; unit dps, dph, rad_s, or
    v, mv, lsb with scale_factor and null)."""

def bias(
    x: ArrayLike,
    rate_hz: Optional[float] = ...,
    unit: str = ...,
    scale_factor: Optional[float] = ...,
    null: Optional[float] = ...,
    latitude_deg: Optional[float] = ...,
    smoothing_s: Optional[Sequence[float]] = ...,
    time_s: Optional[ArrayLike] = ...,
    temp_c: Optional[ArrayLike] = ...,
) -> Dict[str, Any]:
    """Static (bias) test of one record: the keys of one `gyrolab bias --json` test."""

def rate_table(
    rates_dps: Optional[ArrayLike] = ...,
    outputs: Optional[ArrayLike] = ...,
    runs: Optional[Sequence[int]] = ...,
    strokes: Optional[Sequence[str]] = ...,
    *,
    unit: str = ...,
    files: Optional[Sequence[PathLike]] = ...,
    data: Any = ...,
    axis_names: Optional[Sequence[str]] = ...,
    coverage: float = ...,
    order: int = ...,
    half_hysteresis: bool = ...,
    nonlinearity_limit_pct: Optional[float] = ...,
) -> Dict[str, Any]:
    """Rate-table evaluation (arrays, a DataFrame or files): the keys of `gyrolab rate --json`."""

def simulate_static(
    duration_s: float,
    rate_hz: float = ...,
    seed: int = ...,
    preset: Optional[str] = ...,
    arw_deg_rt_h: Optional[float] = ...,
    bias_instability_dph: Optional[float] = ...,
    rrw_deg_h_rt_h: Optional[float] = ...,
    bias_dph: Optional[float] = ...,
    temp_c: Optional[float] = ...,
    temp_ramp_c_per_h: Optional[float] = ...,
    record_temperature: bool = ...,
) -> Dict[str, np.ndarray]:
    """A simulated static record with known truth: time_s, output (and temp_c)."""

def read(
    path: PathLike,
    as_dataframe: Optional[bool] = ...,
    units: Optional[Sequence[str]] = ...,
    time_column: Optional[str] = ...,
    names: Optional[Sequence[str]] = ...,
    topic: Optional[str] = ...,
) -> Any:
    """A time-series file (CSV, Parquet; MCAP, ROS 1 bag, ULog by content, one IMU ``topic``)
    as a DataFrame (pandas) or a dict of float64 arrays."""

def read_with_units(
    path: PathLike,
    units: Optional[Sequence[str]] = ...,
    time_column: Optional[str] = ...,
    names: Optional[Sequence[str]] = ...,
) -> Tuple[Dict[str, np.ndarray], Dict[str, str]]:
    """A time-series file: (column -> array, column -> unit symbol)."""

def evaluate_plan(plan: PathLike, out: PathLike) -> Dict[str, Any]:
    """Evaluates a test plan into a report folder: verdict, files, failures."""

def apply(outputs: Any, calibration: PathLike, axis: Optional[str] = ...) -> Dict[str, np.ndarray]:
    """Applies a calibration file to outputs: rate_dps (or rate_x/y/z_dps) and status arrays."""
