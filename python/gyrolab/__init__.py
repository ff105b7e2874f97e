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

import functools
import json
import warnings
import math
import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from ._errors import Error
from . import _gyrolab
from ._gyrolab import __version__
from ._results import AllanResult, AllanResults

__all__ = [
    "Error",
    "AllanResult",
    "AllanResults",
    "UNITS",
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


#: The units ``allan`` reads (``unit=`` / ``units=``), with their aliases.
UNITS = (
    "dps", "deg/s", "dph", "deg/h", "rad_s", "rad/s", "mrad_s", "mrad/s",  # angular rates
    "m/s^2", "m/s2", "g", "mg", "ug",  # accelerations
    "v", "mv", "lsb",  # sensor outputs (noise terms need scale_factor)
    "1",  # no unit: deviations in the data's own unit, no noise terms
)

_TIME_NAMES = ("time_s", "time", "t")


def _samples(x: Any, name: str, unit: Optional[str]) -> np.ndarray:
    """A 1-D float64 array of samples (the array itself when it is one: never copied); integer
    samples need their unit named, booleans are refused."""
    a = np.asarray(x)
    if a.dtype == np.bool_:
        raise Error(f"{name}: boolean samples are not measurements: give numbers", keyword=None)
    if a.dtype.kind in "iu" and unit is None:
        raise Error(
            f"{name}: integer samples (counts?): give their unit, e.g. unit='lsb' with scale_factor, "
            "or unit='dps' if they are rates in deg/s",
            keyword="unit",
        )
    if a.dtype != np.float64:
        try:
            a = a.astype(np.float64)
        except (TypeError, ValueError) as e:
            raise Error(f"{name}: expected an array of numbers ({e})") from None
    if a.ndim != 1:
        raise Error(f"{name}: expected a 1-D array, got {a.ndim} dimensions with shape {a.shape}")
    if a.size == 0:
        raise Error(f"{name}: the array is empty")
    return a


def _channels(
    x: Any, names: Optional[Sequence[str]], time: Any, unit: Optional[str], units: Any
) -> Tuple[List[str], List[np.ndarray], List[str], Optional[np.ndarray], bool]:
    """(names, arrays, units, time stamps, single): the channels of a 1-D array, a 2-D array
    (samples x channels), a dict of arrays or a pandas DataFrame."""
    given_units: Dict[str, str] = {}
    if isinstance(units, Mapping):
        given_units = {str(k): str(v) for k, v in units.items()}
    elif isinstance(units, str):
        unit = units if unit is None else unit
    elif units is not None:
        # read()'s spelling: ["gx=rad/s", "m/s^2"] (a bare unit applies to every channel)
        for u in units:
            k, eq, v = str(u).partition("=")
            if eq:
                given_units[k.strip()] = v.strip()
            else:
                unit = k.strip()
    time_name = time if isinstance(time, str) else None
    stamps = None if time is None or time_name is not None else _samples(time, "time", "s")
    single = False
    attrs_units: Dict[str, str] = {}
    if hasattr(x, "columns") and hasattr(x, "to_numpy"):  # a pandas DataFrame
        attrs_units = dict(getattr(x, "attrs", {}).get("units", {}) or {})
        cols = [str(c) for c in x.columns]
        if time_name is None and time is None:
            found = [c for c in cols if attrs_units.get(c) == "s"] or [c for c in cols if c in _TIME_NAMES]
            time_name = found[0] if found else None
        table = {str(c): x[c].to_numpy() for c in x.columns}
    elif isinstance(x, Mapping):
        table = {str(k): v for k, v in x.items()}
        cols = list(table)
        if time_name is None and time is None:
            found = [c for c in cols if c in _TIME_NAMES]
            time_name = found[0] if found else None
    else:
        a = np.asarray(x) if not isinstance(x, np.ndarray) else x
        if a.ndim == 2:
            cols = list(names) if names is not None else [f"ch{i}" for i in range(a.shape[1])]
            if len(cols) != a.shape[1]:
                raise Error(f"names: {len(cols)} names for {a.shape[1]} columns (channels are columns)", keyword="names")
            table = {c: a[:, i] for i, c in enumerate(cols)}
        else:
            single = True
            cols = [names[0] if names else "x"]
            table = {cols[0]: x}
    if time_name is not None:
        if time_name not in table:
            raise Error(f"time='{time_name}': no such column (columns: {', '.join(cols)})", keyword="time")
        stamps = _samples(table.pop(time_name), f"time ('{time_name}')", "s")
        cols = [c for c in cols if c != time_name]
    # Temperature columns read() marks are not channels.
    cols = [c for c in cols if attrs_units.get(c) != "degC"]
    if names is not None and not single and not (hasattr(x, "ndim") and getattr(x, "ndim") == 2):
        wanted = [str(n) for n in names]
        missing = [n for n in wanted if n not in table]
        if missing:
            raise Error(f"names: no such channel {missing} (channels: {', '.join(cols)})", keyword="names")
        cols = wanted
    unknown = [k for k in given_units if k not in cols]
    if unknown:
        raise Error(f"units: no channel named {unknown} (channels: {', '.join(cols)})", keyword="units")
    out_units = []
    for c in cols:
        u = given_units.get(c) or unit or attrs_units.get(c)
        out_units.append(u)
    arrays = [_samples(table[c], c if not single else "x", u) for c, u in zip(cols, out_units)]
    return cols, arrays, [u or "dps" for u in out_units], stamps, single


def _factors(taus: Sequence[float], rate_hz: Optional[float], stamps: Optional[np.ndarray]) -> Tuple[List[int], Dict[float, float]]:
    """Averaging factors of taus in seconds, each rounded to the nearest whole multiple of the
    sample interval as allantools does (m = round(tau * rate)); the taus it changed."""
    t = np.asarray([float(v) for v in taus], dtype=np.float64)
    if t.size == 0 or not np.all(np.isfinite(t)) or np.any(t <= 0):
        raise Error("taus: expected positive numbers of seconds", keyword="taus")
    if rate_hz is None:
        if stamps is None or stamps.size < 2:
            raise Error("give rate_hz (the sample rate, Hz) or time= (time stamps in seconds)", keyword="rate_hz")
        rate = (stamps.size - 1) / (stamps[-1] - stamps[0])
    else:
        rate = float(rate_hz)
    m = np.round(t * rate).astype(np.int64)
    if np.any(m < 1):
        raise Error(f"taus: {t[m < 1][0]} s is shorter than the sample interval {1.0 / rate} s", keyword="taus")
    rounded = {float(a): float(k / rate) for a, k in zip(t, m) if abs(a * rate - k) > 1e-9 * k}
    return sorted(set(int(v) for v in m)), rounded


def _window(
    arrays: List[np.ndarray],
    stamps: Optional[np.ndarray],
    rate_hz: Optional[float],
    start_s: Optional[float],
    end_s: Optional[float],
) -> Tuple[List[np.ndarray], Optional[np.ndarray]]:
    """The samples from ``start_s`` seconds after the record's first sample up to (not
    including) ``end_s``, by the time stamps or else the sample index over ``rate_hz``: the part
    ``gyrolab allan --start --end`` analyses."""
    for name, v in (("start_s", start_s), ("end_s", end_s)):
        if v is not None and (not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0):
            raise Error(f"{name}={v!r}: expected a number of seconds >= 0", keyword=name)
    if start_s is not None and end_s is not None and end_s <= start_s:
        raise Error(f"end_s {end_s} s is not after start_s {start_s} s", keyword="end_s")
    n = len(arrays[0]) if arrays else 0
    if stamps is not None:
        offset = np.asarray(stamps, dtype=np.float64) - float(stamps[0])
    elif rate_hz is not None:
        offset = np.arange(n) / float(rate_hz)
    else:
        raise Error("start_s and end_s need time stamps or rate_hz", keyword="start_s")
    keep = np.ones(n, dtype=bool)
    if start_s is not None:
        keep &= offset >= start_s
    if end_s is not None:
        keep &= offset < end_s
    if int(keep.sum()) < 2:
        length = float(offset[-1]) if n else 0.0
        raise Error(f"fewer than two samples between start_s and end_s: the record is {length} s long", keyword="start_s")
    return [a[keep] for a in arrays], (None if stamps is None else np.asarray(stamps)[keep])


def _allan(
    x: Any,
    rate_hz: Optional[float] = None,
    kind: str = "oadev",
    taus: Union[str, Sequence[float]] = "octave",
    confidence: Optional[float] = 0.683,
    unit: Optional[str] = None,
    scale_factor: Optional[float] = None,
    null: Optional[float] = None,
    fit_range_s: Optional[Sequence[float]] = None,
    *,
    units: Any = None,
    time: Any = None,
    gaps: str = "error",
    names: Optional[Sequence[str]] = None,
    record: Optional[str] = None,
    allow_motion: bool = False,
    start_s: Optional[float] = None,
    end_s: Optional[float] = None,
    topic: Optional[str] = None,
) -> Union[AllanResult, AllanResults]:
    """Allan-family deviation, confidence bounds and noise terms of rate samples.

    ``x``: a 1-D array (one channel: returns an :class:`AllanResult`); or a pandas DataFrame,
    a dict of arrays or a 2-D array (samples x channels, named by ``names``): every channel
    in one native call, returns an :class:`AllanResults` mapping channel -> result, with
    ``to_dataframe()`` and ``noise_table()``; or a file path (read as :func:`read` does).

    Sampling: ``rate_hz`` (Hz), or ``time`` (a column name, or an array of stamps in seconds;
    a DataFrame's ``time_s``/``time`` column, or the column ``read()`` marks in seconds, is
    used by default); with both, they must agree.

    ``kind``: oadev (default), adev, mdev, tdev, hdev, ohdev, totdev. ``taus``: "octave",
    "decade", "all", "N/decade", or seconds (each rounded to the nearest whole multiple of
    the sample interval as allantools does; ``result.taus_rounded`` lists the changes).
    ``confidence``: level of the bounds, or None. ``fit_range_s``: (low, high) taus of the
    five-term fit, any two-number sequence.

    Units: ``unit`` for every channel, ``units`` per channel (a dict, or read()'s
    ``["gx=rad/s", "m/s^2"]``), else a DataFrame's ``attrs["units"]`` (as read() sets them),
    else deg/s. Accepted: angular rates ``dps`` (``deg/s``), ``dph`` (``deg/h``), ``rad_s``
    (``rad/s``), ``mrad_s``; accelerations ``m/s^2`` (``m/s2``), ``g``, ``mg``, ``ug``;
    sensor outputs ``v``, ``mv``, ``lsb`` (noise terms in deg units need ``scale_factor``,
    output units per deg/s, and ``null``; refused with any other unit); ``1`` (no unit).
    Integer samples need their unit named.

    ``gaps``: "error" (default: a NaN sample or a gap in the time stamps is refused, naming
    the first) or "analyse" (computed over, as ``gyrolab allan --gaps analyse``).
    ``record``: the name results and errors carry (default the path, or ``<array>``).
    ``topic``: for a recording (ROS 2 MCAP, ROS 1 bag, PX4 ULog) with several IMU topics, the
    one to analyse, as :func:`read`'s ``topic`` and the CLI's ``--topic``.

    Stillness: a gyro (deg/s) or accelerometer (m/s^2) channel whose 1 s window means depart
    from the record's still level (docs/METHODS.md, "Stillness check") moved: the call raises
    :class:`Error` (keyword ``allow_motion``) naming the channel and the episode; with
    ``allow_motion=True`` the results carry ``stillness["moved"] = True`` and every export
    a ``MOTION:`` header line.

    Part of a record: ``start_s`` and ``end_s``, seconds from its first sample (samples at or
    after the start and before the end, by the time stamps, else the sample index over
    ``rate_hz``), as ``gyrolab allan --start --end``.

    Every channel is computed with the interpreter released, on gyrolab's own thread pool
    (safe in fork-based multiprocessing pools).
    """
    if topic is not None and not isinstance(x, (str, os.PathLike)):
        raise Error(f"topic={topic!r}: a topic picks one IMU topic of a recording file; x is not a path", keyword="topic")
    from_file = isinstance(x, (str, os.PathLike))
    if from_file:
        path = os.fspath(x)
        # A list of units (read()'s and the CLI's spelling, ["gx=rad/s", "m/s^2"]) is applied by
        # the file reader, as `gyrolab allan --unit` applies it: a bare unit per quantity (a rate
        # unit to the gyro and unnamed columns, an acceleration unit to the accelerometers).
        listed = units is not None and not isinstance(units, (Mapping, str))
        arrays, file_units = _gyrolab.read(path, [str(u) for u in units] if listed else None, None, None, topic)
        frame = dict(arrays)
        if time is None:
            tcols = [k for k, u in file_units.items() if u == "s"]
            time = tcols[0] if tcols else None
        for k, u in file_units.items():
            if u == "degC":
                frame.pop(k, None)
        merged = {k: u for k, u in file_units.items() if u not in ("s", "degC") and k in frame}
        if isinstance(units, Mapping):
            merged.update({str(k): str(v) for k, v in units.items()})
        elif listed:
            units = None
        elif units is not None or unit is not None:
            merged = {}
        x = frame
        units = merged if merged else units
        record = record or path
    # A file read above (its columns already in seconds and in its units) takes the array path.
    table = None if from_file else _named_table(x, names, taus, unit, units)
    if table is not None:
        # A DataFrame or a dict of named columns is read as the command line reads a file with
        # that header (one reading for every front end, issue 55).
        return _allan_table(
            table, x, time, unit, units, rate_hz, kind, taus, confidence, scale_factor, null, fit_range_s,
            gaps, record, allow_motion, start_s, end_s,
        )
    if gaps not in ("error", "analyse", "analyze"):
        raise Error(f"gaps='{gaps}': expected 'error' or 'analyse'", keyword="gaps")
    cols, arrays, chan_units, stamps, single = _channels(x, names, time, unit, units)
    if start_s is not None or end_s is not None:
        arrays, stamps = _window(arrays, stamps, rate_hz, start_s, end_s)
    if fit_range_s is not None:
        try:
            pair = [float(v) for v in fit_range_s]
        except (TypeError, ValueError):
            raise Error(f"fit_range_s={fit_range_s!r}: expected two numbers of seconds (low, high)", keyword="fit_range_s") from None
        if len(pair) != 2 or not (0 < pair[0] < pair[1]):
            raise Error(
                f"fit_range_s={tuple(pair)}: expected two increasing positive taus in seconds (low, high)",
                keyword="fit_range_s",
            )
        fit_range_s = pair
    rounded: Dict[float, float] = {}
    factors = None
    taus_text = "octave"
    if isinstance(taus, str):
        taus_text = taus
    else:
        factors, rounded = _factors(taus, rate_hz, stamps)
    if rate_hz is not None:
        try:
            rate_hz = float(rate_hz)
        except (TypeError, ValueError):
            raise Error(f"rate_hz={rate_hz!r}: expected a number of hertz", keyword="rate_hz") from None
    doc_json, per_channel, lazy = _gyrolab.allan_channels(
        arrays,
        cols,
        chan_units,
        rate_hz,
        stamps,
        kind,
        taus_text,
        factors,
        confidence,
        scale_factor,
        null,
        fit_range_s,
        "analyse" if gaps in ("analyse", "analyze") else "error",
        record or "<array>",
        bool(allow_motion),
    )
    channels = json.loads(doc_json)
    results = {
        ch["channel"]: AllanResult._from_json(ch, arrays_of, rounded, (lazy, i))
        for i, (ch, arrays_of) in enumerate(zip(channels, per_channel))
    }
    if single:
        return next(iter(results.values()))
    return AllanResults(results, record or "<array>")



# Unit spellings of the array path that the command line's reader writes otherwise.
_CLI_UNIT = {"m/s2": "m/s^2", "m/s**2": "m/s^2", "m/s²": "m/s^2", "m·s^-2": "m/s^2"}
# Units the array path converts first (micro-g to milli-g), which the command line has not.
_ARRAY_ONLY_UNITS = {"ug", "µg", "μg", "micro-g", "1", "none", "unitless"}


def _unit_spellings(unit: Any, units: Any) -> List[str]:
    """Every unit named in ``unit`` and ``units`` (a dict's values, a list's entries after '=')."""
    named: List[str] = []
    if isinstance(units, Mapping):
        named += [str(v) for v in units.values()]
    elif isinstance(units, str):
        named.append(units)
    elif units is not None:
        named += [str(u).partition("=")[2] or str(u) for u in units]
    if unit is not None:
        named.append(str(unit))
    return [u.strip().lower() for u in named]


def _named_table(x: Any, names: Any, taus: Any, unit: Any, units: Any) -> Optional[Dict[str, Any]]:
    """The columns of a DataFrame or dict of columns to read by their header, or None: an
    array, explicit ``names``, a list of taus (rounded against a known interval), a unit only
    the array path converts, or a frame from :func:`read` (its units are already read) take
    the array path."""
    if names is not None or not isinstance(taus, str):
        return None
    if any(u in _ARRAY_ONLY_UNITS for u in _unit_spellings(unit, units)):
        return None
    if hasattr(x, "columns") and hasattr(x, "to_numpy"):
        if getattr(x, "attrs", {}).get("units"):
            return None
        return {str(c): x[c].to_numpy() for c in x.columns}
    if isinstance(x, Mapping) and x and all(not isinstance(v, (str, bytes)) for v in x.values()):
        return {str(k): v for k, v in x.items()}
    return None


def _allan_table(
    table: Dict[str, Any], x: Any, time: Any, unit: Any, units: Any, rate_hz: Any, kind: str, taus: str,
    confidence: Any, scale_factor: Any, null: Any, fit_range_s: Any, gaps: str, record: Optional[str],
    allow_motion: bool, start_s: Any, end_s: Any,
) -> "AllanResults":
    """:func:`allan` of a named table through the command line's reader (see ``_named_table``)."""
    spell = lambda u: _CLI_UNIT.get(str(u).strip().lower(), str(u).strip())  # noqa: E731
    layout: List[str] = []
    if isinstance(units, Mapping):
        layout += [f"{k}={spell(v)}" for k, v in units.items()]
    elif isinstance(units, str):
        layout.append(spell(units))
    elif units is not None:
        for u in units:
            k, eq, v = str(u).partition("=")
            layout.append(f"{k}={spell(v)}" if eq else spell(k))
    if unit is not None:
        layout.append(spell(unit))
    time_column = None
    if isinstance(time, str):
        if time not in table:
            raise Error(f"time='{time}': no such column (columns: {', '.join(table)})", keyword="time")
        time_column = time
    elif time is not None:
        time_column = "time_s" if "time_s" not in table else "__time_s"
        table = {time_column: time, **table}
        layout.append(f"{time_column}=s")
    names = list(table)
    columns = []
    for c in names:
        a = np.asarray(table[c])
        if a.ndim != 1 or a.dtype.kind not in "iuf":
            raise Error(f"column '{c}': expected one number a row (a 1-D numeric column), got {a.dtype} of shape {a.shape}")
        columns.append(np.ascontiguousarray(a, dtype=np.float64))
    if fit_range_s is not None:
        fit_range_s = [float(v) for v in fit_range_s]
    if rate_hz is not None:
        try:
            rate_hz = float(rate_hz)
        except (TypeError, ValueError):
            raise Error(f"rate_hz={rate_hz!r}: expected a number of hertz", keyword="rate_hz") from None
    doc_json, per_channel, lazy, notes = _gyrolab.allan_table(
        columns, names, layout, time_column, rate_hz, kind, taus, None, confidence, scale_factor, null,
        fit_range_s, "analyse" if gaps == "analyze" else gaps, record or "<array>", bool(allow_motion),
        None if start_s is None else float(start_s), None if end_s is None else float(end_s),
    )
    for is_warning, text in notes:
        if is_warning:
            warnings.warn(text, UserWarning, stacklevel=3)
    channels = json.loads(doc_json)
    results = {
        ch["channel"]: AllanResult._from_json(ch, arrays_of, {}, (lazy, i))
        for i, (ch, arrays_of) in enumerate(zip(channels, per_channel))
    }
    out = AllanResults(results, record or "<array>")
    out.notes = [text for _, text in notes]
    return out


@functools.wraps(_allan)
def allan(x: Any, *args: Any, **kwargs: Any) -> Union[AllanResult, AllanResults]:
    try:
        return _allan(x, *args, **kwargs)
    except Error as e:
        # A file's errors name the file (and topic), as the CLI's do, unless they already do.
        if not isinstance(x, (str, os.PathLike)) or e.file is not None:
            raise
        where = kwargs.get("record") or os.fspath(x)
        if kwargs.get("topic"):
            where = f"{where} topic {kwargs['topic']}"
        raise Error(f"{where}: {e.message}", file=where, line=e.line, column=e.column, keyword=e.keyword) from None


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
    unit: Optional[str] = None,
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
    default "v"; ``runs`` numbers, ``strokes`` "fwd"/"rev" or "up"/"down"), from a pandas
    DataFrame ``data`` with columns ``rate_dps``, ``run``, ``stroke`` and the output
    (``output_<unit>``), or from ``files`` (long, wide or raw logs, as the command line reads
    them; ``unit`` overrides the unit they declare). ``half_hysteresis``,
    ``nonlinearity_limit_pct``, ``coverage`` and ``order`` apply to every source. Units of
    outputs: v, mv, lsb, dps, dph, rad_s, mrad_s.
    """
    sources = [n for n, v in (("rates_dps/outputs", rates_dps if rates_dps is not None else outputs), ("files", files), ("data", data)) if v is not None]
    if len(sources) > 1:
        raise Error(f"give one source of observations, not {' and '.join(sources)}", keyword=sources[1])
    if files is not None:
        return json.loads(
            _gyrolab.rate_table_files(
                [os.fspath(f) for f in files],
                list(axis_names) if axis_names else None,
                float(coverage),
                int(order),
                unit,
                bool(half_hysteresis),
                nonlinearity_limit_pct,
            )
        )
    if data is not None:
        out_cols = [c for c in data.columns if str(c).startswith("output_")]
        if len(out_cols) != 1:
            raise Error(f"data: expected one output_<unit> column, found {out_cols}", keyword="data")
        col_unit = str(out_cols[0])[len("output_"):]
        if unit is not None and unit.lower() != col_unit.lower():
            raise Error(f"unit='{unit}' but data's output column is {out_cols[0]}: leave unit out", keyword="unit")
        unit = col_unit
        rates_dps, outputs = data["rate_dps"].to_numpy(), data[out_cols[0]].to_numpy()
        runs, strokes = data["run"].to_numpy(), data["stroke"].astype(str).to_numpy()
    if rates_dps is None or outputs is None or runs is None or strokes is None:
        raise Error("give rates_dps, outputs, runs and strokes, or data=DataFrame, or files=[...]")
    text = _gyrolab.rate_table(
        _float_array(rates_dps, "rates_dps"),
        _float_array(outputs, "outputs"),
        [int(r) for r in runs],
        [str(s) for s in strokes],
        unit or "v",
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
    ``"temp_c"`` when ``record_temperature``. With no preset and no noise term it simulates a
    typical MEMS gyro (N 0.3 deg/sqrt(h), B 5 deg/h, bias 20 deg/h) and says so in a
    ``UserWarning``, as the command line does; ``arw_deg_rt_h=0`` gives a noise-free record."""
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
    (all files or none). Returns ``{"verdict": "PASS"|"FAIL"|"INCOMPLETE"|"CONDITIONAL"|None,
    "files": [...], "failures": [...], "undecided": [...]}``: the overall result of the plan's
    limits (None without limits; INCOMPLETE when a check could not be evaluated, which never
    counts as passed; CONDITIONAL inside a guard band), the files written, one line per failed
    check, and one line per check CONDITIONAL or NOT EVALUATED with its reason."""
    verdict, files, failures, undecided = _gyrolab.evaluate_plan(str(plan), str(out))
    return {
        "verdict": verdict,
        "files": [str(f) for f in files],
        "failures": list(failures),
        "undecided": list(undecided),
    }


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
