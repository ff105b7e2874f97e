"""Type stubs of the gyrolab package (see the docstrings in __init__.py)."""

import os
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

PathLike = Union[str, os.PathLike[str]]
ArrayLike = npt.ArrayLike

UNITS: Tuple[str, ...]

class Error(ValueError):
    """A gyrolab evaluation failed: bad data or options (the message names file, line, field);
    pickles with its message and location attributes."""

    message: str
    file: Optional[str]
    line: Optional[int]
    column: Optional[str]
    keyword: Optional[str]
    def __init__(
        self,
        message: str = ...,
        *,
        file: Optional[str] = ...,
        line: Optional[int] = ...,
        column: Optional[str] = ...,
        keyword: Optional[str] = ...,
    ) -> None: ...

class AllanResult:
    """An Allan-family deviation of one channel with bounds and noise terms; arrays per
    averaging time; the noise terms also as attributes (``arw_deg_rt_h``, ``vrw_m_s_rt_h``)."""

    taus_s: np.ndarray
    m: np.ndarray
    dev: np.ndarray
    ci_low: np.ndarray
    ci_high: np.ndarray
    n_terms: np.ndarray
    alpha: np.ndarray
    kind: str
    unit: str
    channel: str
    record: str
    quantity: str
    confidence: Optional[float]
    tau0_s: float
    samples: int
    noise: Dict[str, Any]
    readings: List[Dict[str, Any]]
    fit: Optional[Dict[str, Any]]
    noise_note: Optional[str]
    stillness: Optional[Dict[str, Any]]
    taus_rounded: Dict[float, float]
    def __getattr__(self, name: str) -> Any: ...
    def to_dict(self) -> Dict[str, Any]:
        """The result with the keys of `gyrolab allan --json`."""
    def export(
        self,
        stack: str,
        path: Optional[Union[str, "os.PathLike[str]"]] = ...,
        *,
        estimator: str = ...,
        inflate: float = ...,
        overbound: bool = ...,
    ) -> str:
        """This channel's noise parameters as one filter stack's file (kalibr, openvins, vins,
        orbslam3, basalt, px4, px4-qgc, ros-covariance); written to `path` when given."""
    def to_dataframe(self) -> Any:
        """The curve as a tidy DataFrame."""
    def noise_table(self) -> Any:
        """The noise terms as a DataFrame (channel, term, value, unit, basis, support)."""
    def plot(
        self, ax: Any = ..., label: Optional[str] = ..., asymptotes: bool = ..., terms: Optional["AllanResult"] = ...
    ) -> Any:
        """Log-log curve with bounds and noise-term asymptotes (needs matplotlib); an MDEV curve
        draws the asymptotes of `terms` (the OADEV result of the record) scaled to MDEV; returns
        the axes."""

class AllanResults(Mapping[str, AllanResult]):
    """The channels of one record: channel -> AllanResult."""

    record: str
    def __getitem__(self, key: str) -> AllanResult: ...
    def __iter__(self) -> Iterator[str]: ...
    def __len__(self) -> int: ...
    def to_dataframe(self) -> Any: ...
    def noise_table(self) -> Any: ...
    def to_dict(self) -> Dict[str, Any]: ...
    def export(
        self,
        stack: str,
        path: Optional[Union[str, "os.PathLike[str]"]] = ...,
        *,
        estimator: str = ...,
        inflate: float = ...,
        overbound: bool = ...,
    ) -> str:
        """The record's noise parameters as one filter stack's file (channels combined)."""
    def plot(self, ax: Any = ..., asymptotes: bool = ..., terms: Optional["AllanResults"] = ...) -> Any: ...

def allan(
    x: Any,
    rate_hz: Optional[float] = ...,
    kind: str = ...,
    taus: Union[str, Sequence[float]] = ...,
    confidence: Optional[float] = ...,
    unit: Optional[str] = ...,
    scale_factor: Optional[float] = ...,
    null: Optional[float] = ...,
    fit_range_s: Optional[Sequence[float]] = ...,
    *,
    units: Any = ...,
    time: Any = ...,
    gaps: str = ...,
    names: Optional[Sequence[str]] = ...,
    record: Optional[str] = ...,
    allow_motion: bool = ...,
) -> Any:
    """Allan-family deviation of rate samples: a 1-D array gives an AllanResult; a DataFrame,
    dict of arrays, 2-D array or file path gives AllanResults (see the docstring)."""

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
    unit: Optional[str] = ...,
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
    """Evaluates a test plan into a report folder: verdict (PASS, FAIL, INCOMPLETE, CONDITIONAL), files, failures, undecided."""

def apply(outputs: Any, calibration: PathLike, axis: Optional[str] = ...) -> Dict[str, np.ndarray]:
    """Applies a calibration file to outputs: rate_dps (or rate_x/y/z_dps) and status arrays."""
