"""gyrolab for Python: gyroscope and IMU test evaluation over numpy arrays.

The computations are gyrolab's own (the Rust library ``gyrolab-eval`` behind the command-line
program), so the numbers are those of ``gyrolab allan --json``, ``gyrolab bias --json`` and
``gyrolab rate --json``; ``to_dict()`` gives the same keys.

Units are part of every name: ``taus_s``, ``arw_deg_rt_h``, ``bias_instability_dph`` ...

>>> import numpy as np, gyrolab
>>> x = np.random.default_rng(1).normal(0.0, 0.01, 360_000)   # deg/s at 100 Hz
>>> r = gyrolab.allan(x, rate_hz=100.0)
>>> r.taus_s[0], round(r.noise["arw_deg_rt_h"], 3)            # doctest: +SKIP
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _gyrolab
from ._gyrolab import Error, __version__

__all__ = [
    "Error",
    "AllanResult",
    "allan",
    "bias",
    "rate_table",
    "simulate_static",
    "read",
    "read_with_units",
    "evaluate_plan",
    "apply",
    "__version__",
]

PathLike = Union[str, "os.PathLike[str]"]


def _float_array(x: Any, name: str, check_finite: bool = True) -> np.ndarray:
    """A 1-D float64 array (no copy when x already is one); a clear error otherwise.
    ``check_finite=False`` leaves the finiteness check to the native call (``allan`` refuses a
    non-finite sample with its index in the pass that integrates the record)."""
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise Error(f"{name}: expected a 1-D array of numbers ({e})") from None
    if a.ndim != 1:
        raise Error(f"{name}: expected a 1-D array, got {a.ndim} dimensions with shape {a.shape}")
    if a.size == 0:
        raise Error(f"{name}: the array is empty")
    if not check_finite:
        return a
    # A finite sum (one vectorised pass, no temporary) proves every sample finite; otherwise
    # look for the bad sample (the sum of finite samples can also overflow).
    if np.isfinite(np.add.reduce(a)):
        return a
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        raise Error(
            f"{name}[{bad[0]}] = {a[bad[0]]} is not a finite number ({bad.size} such samples): "
            "the evaluation needs a complete record"
        )
    return a


def _taus_text(taus: Union[str, Sequence[float]]) -> str:
    if isinstance(taus, str):
        return taus
    return ",".join(repr(float(t)) for t in taus)


@dataclass
class AllanResult:
    """An Allan-family deviation with its bounds and noise terms.

    Arrays (one value per averaging time): ``taus_s``, ``m`` (averaging factor), ``dev``,
    ``ci_low``, ``ci_high`` (NaN where no bound exists), ``n_terms``, ``alpha`` (noise type,
    NaN where not identified). ``noise`` holds the slope-line noise terms with their units
    (``arw_deg_rt_h``, ``bias_instability_dph``, ``rrw_deg_h_rt_h``, ...; ``None`` when absent),
    ``readings`` where each was read, ``fit`` the five-term fit, ``unit`` the unit of ``dev``.
    """

    taus_s: np.ndarray
    m: np.ndarray
    dev: np.ndarray
    ci_low: np.ndarray
    ci_high: np.ndarray
    n_terms: np.ndarray
    alpha: np.ndarray
    kind: str
    unit: str
    noise: Dict[str, Any] = field(default_factory=dict)
    readings: List[Dict[str, Any]] = field(default_factory=list)
    fit: Optional[Dict[str, Any]] = None
    _doc: Dict[str, Any] = field(default_factory=dict, repr=False)

    def to_dict(self) -> Dict[str, Any]:
        """The result with the keys of ``gyrolab allan --json``."""
        return json.loads(json.dumps(self._doc))

    def plot(self, ax: Any = None, label: Optional[str] = None) -> Any:
        """Draws the log-log curve with its bounds and the N, B, K asymptotes on ``ax``
        (a new figure when None); needs matplotlib. Returns the axes."""
        try:
            import matplotlib.pyplot as plt
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("plot() needs matplotlib: pip install matplotlib") from e
        if ax is None:
            _, ax = plt.subplots(figsize=(7, 5))
        t, d = self.taus_s, self.dev
        lo = np.where(np.isfinite(self.ci_low), d - self.ci_low, 0.0)
        hi = np.where(np.isfinite(self.ci_high), self.ci_high - d, 0.0)
        ax.errorbar(t, d, yerr=[lo, hi], fmt="o-", ms=3, capsize=2, label=label or self.kind.upper())
        n = self.noise.get("arw_deg_rt_s")
        b = self.noise.get("bias_instability_dph")
        b_min = self.noise.get("allan_minimum_dph")
        k = self.noise.get("rrw_deg_s_rt_s")
        if self.unit == "deg/s":
            tt = np.geomspace(t[0], t[-1], 50)
            if n:
                ax.plot(tt, n / np.sqrt(tt), "--", lw=1, label=f"N = {self.noise['arw_deg_rt_h']:.3g} deg/√h")
            if b and b_min:
                # The flat level is the Allan minimum (0.6643 B, IEEE 952), given by gyrolab.
                ax.plot(tt, np.full_like(tt, b_min / 3600.0), ":", lw=1, label=f"B = {b:.3g} deg/h (minimum {b_min:.3g})")
            if k:
                ax.plot(tt, k * np.sqrt(tt / 3.0), "-.", lw=1, label=f"K = {self.noise['rrw_deg_h_rt_h']:.3g} deg/h/√h")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("averaging time τ (s)")
        ax.set_ylabel(f"{self.kind.upper()} σ(τ) ({self.unit})")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(loc="best", fontsize="small")
        return ax


def allan(
    x: Any,
    rate_hz: float,
    kind: str = "oadev",
    taus: Union[str, Sequence[float]] = "octave",
    confidence: Optional[float] = 0.683,
    unit: str = "dps",
    scale_factor: Optional[float] = None,
    null: Optional[float] = None,
    fit_range_s: Optional[Tuple[float, float]] = None,
) -> AllanResult:
    """Allan-family deviation of rate samples ``x`` taken at ``rate_hz``.

    ``kind``: oadev (default), adev, mdev, tdev, hdev, ohdev, totdev. ``taus``: "octave",
    "decade", "all", "N/decade" or a list of seconds. ``confidence``: level of the bounds, or None.
    ``unit``: of ``x``: "dps", "dph", "rad_s" (rates), or "v", "mv", "lsb" with ``scale_factor``
    (output units per deg/s) and ``null`` for noise terms in deg units. The computation runs
    with the interpreter released.
    """
    a = _float_array(x, "x", check_finite=False)
    doc_json, arrays = _gyrolab.allan(
        a,
        float(rate_hz),
        kind,
        _taus_text(taus),
        confidence,
        unit,
        scale_factor,
        null,
        fit_range_s,
    )
    doc = json.loads(doc_json)
    ch = doc["channels"][0]
    noise = ch.get("noise") or {}
    return AllanResult(
        taus_s=arrays[0],
        m=arrays[1].astype(np.int64),
        dev=arrays[2],
        ci_low=arrays[3],
        ci_high=arrays[4],
        n_terms=arrays[5].astype(np.int64),
        alpha=arrays[6],
        kind=doc.get("kind", kind),
        unit=ch.get("dev_unit", unit),
        noise={k: v for k, v in noise.items() if k not in ("readings", "fit", "kalibr")},
        readings=noise.get("readings", []),
        fit=noise.get("fit"),
        _doc=doc,
    )


def bias(
    x: Any,
    rate_hz: Optional[float] = None,
    unit: str = "v",
    scale_factor: Optional[float] = None,
    null: Optional[float] = None,
    latitude_deg: Optional[float] = None,
    smoothing_s: Optional[Sequence[float]] = None,
    time_s: Any = None,
    temp_c: Any = None,
) -> Dict[str, Any]:
    """Static (bias) test of one record: the figures of ``gyrolab bias --json`` (one test) as a
    dict: ``mean_output``, ``bias_dph`` (with ``scale_factor`` and ``null``), ``bias_stability_dph``
    per smoothing time, drift, temperature model (with ``temp_c``), data quality.

    Give ``rate_hz`` or ``time_s``. ``unit`` is that of ``x``: "v", "mv", "lsb", "dps", "rad_s".
    """
    a = _float_array(x, "x")
    t = None if time_s is None else _float_array(time_s, "time_s")
    c = None if temp_c is None else _float_array(temp_c, "temp_c")
    if rate_hz is None and t is None:
        raise Error("give rate_hz or time_s")
    text = _gyrolab.bias(
        a,
        None if rate_hz is None else float(rate_hz),
        unit,
        scale_factor,
        null,
        latitude_deg,
        None if smoothing_s is None else [float(s) for s in smoothing_s],
        t,
        c,
    )
    return json.loads(text)


def rate_table(
    rates_dps: Any = None,
    outputs: Any = None,
    runs: Optional[Sequence[int]] = None,
    strokes: Optional[Sequence[str]] = None,
    *,
    unit: str = "v",
    files: Optional[Sequence[PathLike]] = None,
    data: Any = None,
    axis_names: Optional[Sequence[str]] = None,
    coverage: float = 3.0,
    order: int = 1,
    half_hysteresis: bool = False,
    nonlinearity_limit_pct: Optional[float] = None,
) -> Dict[str, Any]:
    """Rate-table evaluation: scale factor, nonlinearity, asymmetry, hysteresis, repeatability,
    ... as ``gyrolab rate --json`` (a dict with ``axes``).

    From arrays (one entry per sample or plateau mean: ``rates_dps``, ``outputs`` in ``unit``,
    ``runs`` numbers, ``strokes`` "fwd"/"rev"), from a pandas DataFrame ``data`` with columns
    ``rate_dps``, ``run``, ``stroke`` and the output (``output_<unit>``), or from ``files``
    (long, wide or raw logs, as the command line reads them).
    """
    if files is not None:
        return json.loads(
            _gyrolab.rate_table_files([str(f) for f in files], list(axis_names) if axis_names else None, coverage, order)
        )
    if data is not None:
        out_cols = [c for c in data.columns if str(c).startswith("output_")]
        if len(out_cols) != 1:
            raise Error(f"data: expected one output_<unit> column, found {out_cols}")
        unit = str(out_cols[0])[len("output_"):]
        rates_dps, outputs = data["rate_dps"].to_numpy(), data[out_cols[0]].to_numpy()
        runs, strokes = data["run"].to_numpy(), data["stroke"].astype(str).to_numpy()
    if rates_dps is None or outputs is None or runs is None or strokes is None:
        raise Error("give rates_dps, outputs, runs and strokes, or data=DataFrame, or files=[...]")
    text = _gyrolab.rate_table(
        _float_array(rates_dps, "rates_dps"),
        _float_array(outputs, "outputs"),
        [int(r) for r in runs],
        [str(s) for s in strokes],
        unit,
        float(coverage),
        int(order),
        bool(half_hysteresis),
        nonlinearity_limit_pct,
        (axis_names[0] if axis_names else "x"),
    )
    return json.loads(text)


def simulate_static(
    duration_s: float,
    rate_hz: float = 100.0,
    seed: int = 1,
    preset: Optional[str] = None,
    arw_deg_rt_h: Optional[float] = None,
    bias_instability_dph: Optional[float] = None,
    rrw_deg_h_rt_h: Optional[float] = None,
    bias_dph: Optional[float] = None,
    temp_c: Optional[float] = None,
    temp_ramp_c_per_h: Optional[float] = None,
    record_temperature: bool = False,
) -> Dict[str, np.ndarray]:
    """A simulated static record with known truth (the samples ``gyrolab simulate static`` writes
    for the same seed): ``{"time_s", "output"}`` (deg/s unless a preset sets another unit), plus
    ``"temp_c"`` when ``record_temperature``."""
    t, y, c = _gyrolab.simulate_static(
        float(duration_s),
        float(rate_hz),
        int(seed),
        preset,
        arw_deg_rt_h,
        bias_instability_dph,
        rrw_deg_h_rt_h,
        bias_dph,
        temp_c,
        temp_ramp_c_per_h,
        bool(record_temperature),
    )
    out = {"time_s": t, "output": y}
    if record_temperature:
        out["temp_c"] = c
    return out


def read(
    path: PathLike,
    as_dataframe: Optional[bool] = None,
    units: Optional[Sequence[str]] = None,
    time_column: Optional[str] = None,
    names: Optional[Sequence[str]] = None,
    topic: Optional[str] = None,
) -> Any:
    """Reads a time-series file gyrolab reads (CSV, TSV, Kalibr imu0.csv, headerless, Parquet;
    ROS 2 MCAP, ROS 1 bags and PX4 ULog by content, ``topic`` picking one IMU topic): a
    pandas DataFrame when pandas is installed (column units in ``df.attrs["units"]``), else (or
    with ``as_dataframe=False``) a dict of column name -> float64 array; :func:`read_with_units`
    gives arrays and units. ``units`` (``["gx=rad/s", "m/s^2"]``), ``time_column`` and ``names``
    (for a file without a header row) as the CLI's ``--unit``, ``--time-column``, ``--names``."""
    arrays, units = _gyrolab.read(
        str(path), None if units is None else list(units), time_column, None if names is None else list(names), topic
    )
    if as_dataframe is not False:
        try:
            import pandas as pd
        except ImportError:
            if as_dataframe:
                raise
            return arrays
        df = pd.DataFrame(arrays)
        df.attrs["units"] = dict(units)
        return df
    return arrays


def read_with_units(
    path: PathLike,
    units: Optional[Sequence[str]] = None,
    time_column: Optional[str] = None,
    names: Optional[Sequence[str]] = None,
) -> Tuple[Dict[str, np.ndarray], Dict[str, str]]:
    """Reads a time-series file: (column -> array, column -> unit symbol); options as :func:`read`."""
    return _gyrolab.read(
        str(path), None if units is None else list(units), time_column, None if names is None else list(names)
    )


def evaluate_plan(plan: PathLike, out: PathLike) -> Dict[str, Any]:
    """Evaluates a test plan (TOML, as ``gyrolab eval``) and writes its report folder to ``out``
    (all files or none). Returns ``{"verdict": "PASS"|"FAIL"|"NOT_EVALUATED"|None, "files":
    [...], "failures": [...]}``."""
    verdict, files, failures = _gyrolab.evaluate_plan(str(plan), str(out))
    return {"verdict": verdict, "files": [str(f) for f in files], "failures": list(failures)}


def apply(outputs: Any, calibration: PathLike, axis: Optional[str] = None) -> Dict[str, np.ndarray]:
    """Applies a calibration file (from ``gyrolab rate --cal-out``) to outputs in its output unit:
    one array for an ``[[axis]]`` (``axis`` names it when the file has several) -> ``rate_dps``;
    three arrays x, y, z for a ``[triad]`` -> ``rate_x_dps``, ``rate_y_dps``, ``rate_z_dps``.
    ``status`` says per sample ``inside``, ``below``/``above`` the calibrated range (continued
    along the end tangent) or ``not_finite``."""
    arrays = [np.asarray(o, dtype=np.float64) for o in (outputs if isinstance(outputs, (list, tuple)) else [outputs])]
    for i, a in enumerate(arrays):
        if a.ndim != 1:
            raise Error(f"outputs[{i}]: expected a 1-D array, got shape {a.shape}")
    rates, status = _gyrolab.apply(str(calibration), arrays, axis)
    names = ["rate_dps"] if len(rates) == 1 else ["rate_x_dps", "rate_y_dps", "rate_z_dps"]
    out: Dict[str, np.ndarray] = dict(zip(names, rates))
    out["status"] = np.array(status)
    return out
