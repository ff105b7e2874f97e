"""Result objects of :func:`gyrolab.allan`: one channel (:class:`AllanResult`) and the channels
of one record (:class:`AllanResults`, a mapping by channel), with tidy tables and plots."""

from __future__ import annotations

import html
import json
import os
import tempfile
from dataclasses import dataclass, field
from typing import Any, Dict, Iterator, List, Mapping, Optional, Tuple, Union

import numpy as np

# Standard gravity (CGPM 1901), m/s^2 per g: accelerometer bias readings are in micro-g.
_G_N = 9.80665

# The slope-line terms of a gyro (deg/s curve) and of an accelerometer (m/s^2 curve): the
# reading's term, its short symbol in plots, and the key of its value in the curve's unit
# (per-second density) and in the unit shown.
_GYRO_TERMS = {
    "arw": ("N", "arw_deg_rt_s", "arw_deg_rt_h", "deg/√h"),
    "bias_instability": ("B", "bias_instability_dph", "bias_instability_dph", "deg/h"),
    "allan_minimum": ("min", "allan_minimum_dph", "allan_minimum_dph", "deg/h"),
    "rrw": ("K", "rrw_deg_s_rt_s", "rrw_deg_h_rt_h", "deg/h/√h"),
}
_ACCEL_TERMS = {
    "vrw": ("VRW", "vrw_m_s2_rt_hz", "vrw_m_s_rt_h", "m/s/√h"),
    "bias_instability": ("B", "bias_instability_ug", "bias_instability_ug", "µg"),
    "allan_minimum": ("min", "allan_minimum_ug", "allan_minimum_ug", "µg"),
    "accel_random_walk": ("AcRW", "accel_random_walk_m_s3_rt_hz", "accel_random_walk_m_s2_rt_h", "m/s²/√h"),
}

# Above this many taus, error bars are drawn on a log-spaced subset (the curve keeps every
# point): matplotlib draws 180 k error bars in seconds, a line of 180 k points in milliseconds.
_MAX_ERROR_BARS = 60


class _Unset:
    """The value of a lazily computed field before its first use."""

    def __repr__(self) -> str:
        return "<not yet computed>"


_UNSET = _Unset()


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        return a.shape == b.shape and bool(np.array_equal(a, b, equal_nan=a.dtype.kind == "f"))
    return bool(a == b)


@dataclass(eq=False, repr=False)
class AllanResult:
    """An Allan-family deviation of one channel with its bounds and noise terms.

    Arrays (one value per averaging time): ``taus_s``, ``m`` (averaging factor), ``dev``,
    ``ci_low``, ``ci_high`` (NaN where no bound exists), ``n_terms``, ``alpha`` (noise type,
    NaN where not identified). ``unit`` is the unit of ``dev`` (``deg/s`` for a gyro,
    ``m/s^2`` for an accelerometer, the output's unit when uncalibrated).

    ``noise`` holds the slope-line noise terms, each key naming its unit (gyro:
    ``arw_deg_rt_h``, ``bias_instability_dph``, ``allan_minimum_dph``, ``rrw_deg_h_rt_h``, ...;
    accelerometer: ``vrw_m_s_rt_h``, ``bias_instability_ug``, ``allan_minimum_ug``,
    ``accel_random_walk_m_s2_rt_h``, ...; ``None`` when absent); each is also an attribute
    (``r.arw_deg_rt_h``, ``r.vrw_m_s_rt_h``). ``readings`` says where each term was read (its
    basis and supported tau range), ``fit`` is the five-term fit (gyro), ``gmwm`` the GMWM fit
    (its chosen model's ``parameters`` with two-sided intervals, Gauss-Markov processes with
    ``correlation_time_s``; ``quality`` ``poor`` when no model describes the curve; the keys of
    docs/JSON.md; None when not made), ``noise_note`` why there are no terms. ``stillness`` is the stillness check (``moved``, its episodes, levels in
    ``rule["unit"]``; None when no rule applies). ``taus_rounded`` maps each requested tau (s) that was not a whole
    multiple of the sample interval to the tau used.
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
    channel: str = "x"
    record: str = "<array>"
    quantity: str = "angular_rate"
    confidence: Optional[float] = None
    tau0_s: float = float("nan")
    samples: int = 0
    noise: Dict[str, Any] = field(default_factory=dict)
    readings: List[Dict[str, Any]] = field(default_factory=list)
    fit: Optional[Dict[str, Any]] = None
    noise_note: Optional[str] = None
    stillness: Optional[Dict[str, Any]] = None
    taus_rounded: Dict[float, float] = field(default_factory=dict)
    _doc: Dict[str, Any] = field(default_factory=dict)
    # The GMWM fit and the filter terms are computed by the native module only when first read
    # (``gmwm``, ``export``, ``to_dict``, pickling): ``_lazy`` is (native analyses, channel index).
    _gmwm: Any = _UNSET
    _filter_terms: Any = _UNSET
    _lazy: Any = None

    @classmethod
    def _from_json(
        cls, ch: Dict[str, Any], arrays: List[np.ndarray], rounded: Dict[float, float], lazy: Any = None
    ) -> "AllanResult":
        accel = ch.get("quantity") == "acceleration"
        terms = (ch.get("accel_noise") if accel else ch.get("noise")) or {}
        return cls(
            taus_s=arrays[0],
            m=arrays[1].astype(np.int64),
            dev=arrays[2],
            ci_low=arrays[3],
            ci_high=arrays[4],
            n_terms=arrays[5].astype(np.int64),
            alpha=arrays[6],
            kind=ch["kind"],
            unit=ch["dev_unit"],
            channel=ch["channel"],
            record=ch["file"],
            quantity=ch["quantity"],
            confidence=ch.get("confidence"),
            tau0_s=ch["tau0_s"],
            samples=ch["samples"],
            noise={k: v for k, v in terms.items() if k not in ("readings", "fit", "kalibr")},
            readings=terms.get("readings", []),
            fit=terms.get("fit"),
            noise_note=ch.get("noise_note"),
            stillness=ch.get("stillness"),
            taus_rounded=dict(rounded),
            _doc=ch,
            _lazy=lazy,
        )

    @property
    def gmwm(self) -> Optional[Dict[str, Any]]:
        """The GMWM fit (the ``gmwm`` key of docs/JSON.md), computed on first use; None when
        not made."""
        if self._gmwm is _UNSET:
            text = self._lazy[0].gmwm(self._lazy[1]) if self._lazy is not None else None
            self._gmwm = None if text is None else json.loads(text)
        return self._gmwm

    def _terms(self) -> Optional[str]:
        """The filter terms (JSON for the native ``render_export``), computed on first use."""
        if self._filter_terms is _UNSET:
            self._filter_terms = self._lazy[0].filter_terms(self._lazy[1]) if self._lazy is not None else None
        return self._filter_terms

    def __getstate__(self) -> Dict[str, Any]:
        # What is computed on first use is computed now: the native analyses do not pickle.
        state = dict(self.__dict__)
        state["_gmwm"] = self.gmwm
        state["_filter_terms"] = self._terms()
        state["_lazy"] = None
        return state

    def __setstate__(self, state: Dict[str, Any]) -> None:
        # A result pickled before the GMWM was computed on first use held it as `gmwm`.
        if "gmwm" in state:
            state = dict(state)
            state["_gmwm"] = state.pop("gmwm")
            state.setdefault("_filter_terms", state.get("_filter_terms"))
        state.setdefault("_lazy", None)
        self.__dict__.update(state)

    def __getattr__(self, name: str) -> Any:
        # The noise terms as attributes (r.arw_deg_rt_h); private names and the fields
        # themselves are never looked up here (unpickling asks before the fields exist).
        if name.startswith("_"):
            raise AttributeError(name)
        noise = self.__dict__.get("noise")
        if noise is not None and name in noise:
            return noise[name]
        known = _ACCEL_TERMS if self.__dict__.get("quantity") == "acceleration" else _GYRO_TERMS
        if any(name in (v[1], v[2]) for v in known.values()):
            return None
        raise AttributeError(f"'AllanResult' has no attribute '{name}'")

    def __dir__(self) -> List[str]:
        return sorted(set(super().__dir__()) | set(self.__dict__.get("noise") or {}))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, AllanResult):
            return NotImplemented
        names = [f for f in self.__dataclass_fields__ if not f.startswith("_")] + ["gmwm"]
        return all(_same(getattr(self, f), getattr(other, f)) for f in names)

    __hash__ = None  # type: ignore[assignment]

    def _terms_text(self) -> List[str]:
        known = _ACCEL_TERMS if self.quantity == "acceleration" else _GYRO_TERMS
        out = []
        basis = {r["term"]: r["basis"] for r in self.readings}
        for term, (sym, _, key, unit) in known.items():
            if term == "allan_minimum":
                continue
            b = basis.get(term)
            v = self.noise.get(key)
            if b == "value" and v is not None:
                out.append(f"{sym}={v:.4g} {unit}")
            elif b == "upper_bound":
                r = next(r for r in self.readings if r["term"] == term)
                out.append(f"{sym}<{r['value']:.3g} {r['unit']}")
            elif b is not None:
                out.append(f"{sym} absent")
        return out

    def __repr__(self) -> str:
        span = f"{len(self.taus_s)} taus {self.taus_s[0]:.3g}..{self.taus_s[-1]:.3g} s" if len(self.taus_s) else "no taus"
        terms = self._terms_text()
        tail = ", ".join(terms) if terms else (self.noise_note or "no noise terms")
        rate = 1.0 / self.tau0_s if self.tau0_s > 0 else float("nan")
        return (
            f"<AllanResult {self.record}:{self.channel} {self.kind} in {self.unit}, {self.samples} samples "
            f"at {rate:.6g} Hz, {span}; {tail}>"
        )

    def _repr_html_(self) -> str:
        e = html.escape
        rows = "".join(
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>".format(
                e(r["term"]),
                "" if r["value"] is None else format(r["value"], ".4g"),
                e(r["unit"]),
                e(r["basis"]),
                e(_support(r)),
            )
            for r in self.readings
        )
        rate = 1.0 / self.tau0_s if self.tau0_s > 0 else float("nan")
        head = (
            f"<b>{e(self.record)}</b> · {e(self.channel)} · {e(self.kind.upper())} in {e(self.unit)} · "
            f"{self.samples} samples at {rate:.6g} Hz · {len(self.taus_s)} taus"
        )
        if not rows:
            return f"<div>{head}<br><i>{e(self.noise_note or 'no noise terms')}</i></div>"
        return (
            f"<div>{head}<table><tr><th>term</th><th>value</th><th>unit</th><th>basis</th>"
            f"<th>support</th></tr>{rows}</table></div>"
        )

    def to_dict(self) -> Dict[str, Any]:
        """The channel's result with the keys of ``gyrolab allan --json``."""
        out = json.loads(json.dumps(self._doc))
        out["gmwm"] = self.gmwm
        return out

    def export(
        self,
        stack: str,
        path: Optional[Union[str, "os.PathLike[str]"]] = None,
        *,
        estimator: str = "slopes",
        inflate: float = 1.0,
        overbound: bool = False,
        allow_poor_fit: bool = False,
    ) -> str:
        """This channel's noise parameters as one filter stack's file (the text of ``gyrolab
        allan --export STACK=FILE``; docs/EXPORTS.md): ``stack`` one of kalibr, openvins, vins,
        orbslam3, basalt, px4, px4-qgc, ros-covariance. Returns the text; with ``path``, also
        writes it (whole or not at all). ``estimator``: slopes (default), fit or gmwm;
        ``inflate``: every value x this factor; ``overbound``: each value raised until its
        model lies on or above the curve's upper confidence bounds; ``allow_poor_fit``: write
        values from a GMWM fit flagged POOR FIT (refused by default with a
        :class:`gyrolab.Error` whose ``keyword`` is ``allow_poor_fit``, as the command line exits 7).
        Warnings (bounds written, terms not estimated) are issued as :class:`UserWarning`."""
        return _export([self], self.record, self.tau0_s, stack, path, estimator, inflate, overbound, allow_poor_fit)

    def to_dataframe(self) -> Any:
        """The curve as a tidy pandas DataFrame: ``channel``, ``tau_s``, ``m``, ``dev``,
        ``ci_low``, ``ci_high``, ``dev_unit``, ``n_terms``, ``alpha``, ``kind``."""
        import pandas as pd

        return pd.DataFrame(
            {
                "channel": self.channel,
                "tau_s": self.taus_s,
                "m": self.m,
                "dev": self.dev,
                "ci_low": self.ci_low,
                "ci_high": self.ci_high,
                "dev_unit": self.unit,
                "n_terms": self.n_terms,
                "alpha": self.alpha,
                "kind": self.kind,
            }
        )

    def noise_table(self) -> Any:
        """The noise terms as a pandas DataFrame, one row per term: ``channel``, ``term``,
        ``value`` (the value, or the upper bound), ``unit``, ``basis`` (``value``,
        ``upper_bound``, ``absent``), ``support`` (where it was read), ``tau_low_s``,
        ``tau_high_s`` (the supported tau range of a value)."""
        import pandas as pd

        return pd.DataFrame(_noise_rows(self), columns=_NOISE_COLUMNS)

    def plot(
        self, ax: Any = None, label: Optional[str] = None, asymptotes: bool = True, terms: Optional["AllanResult"] = None
    ) -> Any:
        """Draws the log-log curve with its bounds (confidence level in the legend) and the
        noise-term asymptotes over the tau ranges that support them (gyro: N, the flicker
        floor of the IEEE B, K, and the Allan minimum marked on the curve; accelerometer: VRW,
        B, acceleration random walk), in one colour per result; on ``ax`` (a new figure when
        None). Noise terms are read from the Allan deviation: an MDEV result draws the
        asymptotes of ``terms``, the OADEV (or ADEV) result of the same record, scaled to MDEV
        (NIST SP 1065 5.2.5). Needs matplotlib. Returns ax."""
        return _plot([self], ax, [label], asymptotes, [terms])


_NOISE_COLUMNS = ["channel", "term", "value", "unit", "basis", "support", "tau_low_s", "tau_high_s"]


def _support(r: Dict[str, Any]) -> str:
    if r.get("tau_range_s"):
        lo, hi = r["tau_range_s"]
        slope = r.get("local_slope")
        s = f"tau {lo:.3g}..{hi:.3g} s"
        return s + (f", slope {slope:.2f}" if slope is not None else "")
    if r.get("reason"):
        s = str(r["reason"])
        if r.get("needed_record_s"):
            s += f" (needs a record of {r['needed_record_s']:.3g} s)"
        return s
    if r.get("tau_s") is not None:
        return f"at tau {r['tau_s']:.3g} s"
    return ""


def _noise_rows(r: AllanResult) -> List[Tuple[Any, ...]]:
    rows = []
    for g in r.readings:
        lo, hi = g["tau_range_s"] if g.get("tau_range_s") else (np.nan, np.nan)
        value = np.nan if g["value"] is None else g["value"]
        rows.append((r.channel, g["term"], value, g["unit"], g["basis"], _support(g), lo, hi))
    return rows


def _export(
    results: List[AllanResult],
    record: str,
    tau0_s: float,
    stack: str,
    path: Any,
    estimator: str,
    inflate: float,
    overbound: bool,
    allow_poor_fit: bool = False,
) -> str:
    import warnings

    from . import _gyrolab

    terms = [t for t in (r._terms() for r in results) if t is not None]
    motion = [r.stillness["motion"] for r in results if r.stillness and r.stillness.get("motion")]
    text, notes = _gyrolab.render_export(
        terms, record, 1.0 / tau0_s, stack, estimator, float(inflate), bool(overbound), motion,
        bool(allow_poor_fit),
    )
    for n in notes:
        warnings.warn(n, UserWarning, stacklevel=3)
    if path is not None:
        target = os.fspath(path)
        folder = os.path.dirname(os.path.abspath(target))
        fd, tmp = tempfile.mkstemp(prefix=".gyrolab-", suffix=".tmp", dir=folder)
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as f:
                f.write(text)
            os.replace(tmp, target)
        except BaseException:
            if os.path.exists(tmp):
                os.unlink(tmp)
            raise
    return text


class AllanResults(Mapping[str, AllanResult]):
    """The channels of one record analysed in one call: a mapping channel name ->
    :class:`AllanResult` (in the record's order), with tidy tables of all of them."""

    def __init__(self, results: Dict[str, AllanResult], record: str = "<array>") -> None:
        self._results = dict(results)
        self.record = record

    def __getitem__(self, key: str) -> AllanResult:
        return self._results[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._results)

    def __len__(self) -> int:
        return len(self._results)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, AllanResults):
            return NotImplemented
        return self.record == other.record and list(self) == list(other) and all(self[k] == other[k] for k in self)

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        lines = [f"<AllanResults {self.record}: {len(self)} channels"]
        for r in self._results.values():
            terms = r._terms_text()
            lines.append(f"  {r.channel} ({r.unit}): " + (", ".join(terms) if terms else (r.noise_note or "no noise terms")))
        return "\n".join(lines) + ">"

    def _repr_html_(self) -> str:
        return "".join(r._repr_html_() for r in self._results.values())

    def to_dataframe(self) -> Any:
        """Every channel's curve in one tidy DataFrame (see :meth:`AllanResult.to_dataframe`)."""
        import pandas as pd

        return pd.concat([r.to_dataframe() for r in self._results.values()], ignore_index=True)

    def noise_table(self) -> Any:
        """Every channel's noise terms in one DataFrame (see :meth:`AllanResult.noise_table`)."""
        import pandas as pd

        return pd.DataFrame([row for r in self._results.values() for row in _noise_rows(r)], columns=_NOISE_COLUMNS)

    def to_dict(self) -> Dict[str, Any]:
        """``{channel: to_dict()}``."""
        return {k: r.to_dict() for k, r in self._results.items()}

    def export(
        self,
        stack: str,
        path: Optional[Union[str, "os.PathLike[str]"]] = None,
        *,
        estimator: str = "slopes",
        inflate: float = 1.0,
        overbound: bool = False,
        allow_poor_fit: bool = False,
    ) -> str:
        """The record's noise parameters as one filter stack's file, gyro and accelerometer
        channels combined by the largest value per entry, as ``gyrolab allan --export`` does
        (see :meth:`AllanResult.export`)."""
        first = next(iter(self._results.values()))
        return _export(
            list(self._results.values()), self.record, first.tau0_s, stack, path, estimator, inflate, overbound,
            allow_poor_fit,
        )

    def plot(self, ax: Any = None, asymptotes: bool = False, terms: Optional["AllanResults"] = None) -> Any:
        """Every channel's curve on one axes (one colour each; a gyro and an accelerometer have
        different units: plot them separately, ``results['gx'].plot()``). ``terms``: the OADEV
        results of the same channels, whose asymptotes an MDEV result draws (see
        :meth:`AllanResult.plot`)."""
        sources = [None if terms is None else terms.get(k) for k in self._results]
        return _plot(list(self._results.values()), ax, [None] * len(self), asymptotes, sources)


# Large-m limits of Mod sigma^2 / sigma^2 (the ratio R(n) of NIST SP 1065, section 5.2.5) for
# white, flicker and random-walk rate noise: 1/2, 27/40 (= (27/20) ln 2 / (2 ln 2)) and 33/40
# (= (11/20) pi^2 / ((2/3) pi^2)); their square roots scale the Allan asymptotes to MDEV.
_MDEV_SCALE = {"white": np.sqrt(0.5), "flicker": np.sqrt(27.0 / 40.0), "random_walk": np.sqrt(33.0 / 40.0)}
_NOISE_OF_TERM = {
    "arw": "white",
    "vrw": "white",
    "allan_minimum": "flicker",
    "rrw": "random_walk",
    "accel_random_walk": "random_walk",
}


def _asymptotes(r: AllanResult, source: Optional[AllanResult] = None) -> List[Tuple[str, np.ndarray, np.ndarray, str]]:
    """The slope lines of the terms read as values, each over its supported tau range:
    (label, taus, level, line style). The terms are those of ``source`` (an OADEV or ADEV
    result of the same record; ``r`` itself by default), scaled to ``r``'s kind (1 for OADEV
    and ADEV, the square root of SP 1065's R(n) limit for MDEV); no lines for other kinds."""
    source = r if source is None else source
    if source.kind not in ("oadev", "adev") or source.quantity not in ("angular_rate", "acceleration"):
        return []
    if r.kind in ("oadev", "adev"):
        scale = {"white": 1.0, "flicker": 1.0, "random_walk": 1.0}
        prefix = ""
    elif r.kind == "mdev":
        scale = _MDEV_SCALE
        prefix = "MDEV "
    else:
        return []
    if source is not r and (source.unit != r.unit or source.quantity != r.quantity):
        raise ValueError(f"terms= is in {source.unit} ({source.quantity}), the curve in {r.unit} ({r.quantity})")
    accel = source.quantity == "acceleration"
    terms = _ACCEL_TERMS if accel else _GYRO_TERMS
    found = {g["term"]: g for g in source.readings if g["basis"] == "value" and g.get("tau_range_s")}
    out = []
    for term, (sym, density_key, key, unit) in terms.items():
        g = found.get(term)
        v, shown = source.noise.get(density_key), source.noise.get(key)
        if g is None or v is None or shown is None or term not in _NOISE_OF_TERM:
            continue
        k = scale[_NOISE_OF_TERM[term]]
        lo, hi = g["tau_range_s"]
        tt = np.geomspace(lo, hi, 24) if hi > lo else np.array([lo, hi])
        if term in ("arw", "vrw"):
            out.append((f"{prefix}{sym} = {shown:.3g} {unit}", tt, k * v / np.sqrt(tt), "--"))
        elif term in ("rrw", "accel_random_walk"):
            out.append((f"{prefix}{sym} = {shown:.3g} {unit}", tt, k * v * np.sqrt(tt / 3.0), "-."))
        elif term == "allan_minimum":
            # The flicker floor 0.664 B (IEEE Std 952 / 1293): the level of the Allan minimum.
            level = v * _G_N * 1e-6 if accel else v / 3600.0
            ieee = source.noise.get("bias_instability_ug" if accel else "bias_instability_dph")
            factor = "0.664 B" if not prefix else "0.664·√(27/40) B"
            text = f"{prefix}B (IEEE) = {ieee:.3g} {unit}: floor {factor}" if ieee is not None else f"{prefix}floor {shown:.3g} {unit}"
            out.append((text, tt, np.full_like(tt, k * level), ":"))
    return out


def _plot(
    results: List[AllanResult],
    ax: Any,
    labels: List[Optional[str]],
    asymptotes: bool,
    terms: Optional[List[Optional[AllanResult]]] = None,
) -> Any:
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("plot() needs matplotlib: pip install matplotlib") from e
    if ax is None:
        _, ax = plt.subplots(figsize=(7, 5))
    sources = terms if terms is not None else [None] * len(results)
    for r, label, source in zip(results, labels, sources):
        t, d = r.taus_s, r.dev
        name = label or (r.channel if len(results) > 1 or r.channel != "x" else r.kind.upper())
        if r.confidence is not None:
            name += f" ({r.confidence * 100:.3g} % bounds)"
        (line,) = ax.plot(t, d, "o-" if len(t) <= _MAX_ERROR_BARS else "-", ms=3, label=name)
        colour = line.get_color()
        idx = np.arange(len(t))
        if len(t) > _MAX_ERROR_BARS:
            idx = np.unique(np.round(np.geomspace(1, len(t), _MAX_ERROR_BARS)).astype(int) - 1)
        lo = np.where(np.isfinite(r.ci_low[idx]), d[idx] - r.ci_low[idx], 0.0)
        hi = np.where(np.isfinite(r.ci_high[idx]), r.ci_high[idx] - d[idx], 0.0)
        if np.any(lo) or np.any(hi):
            ax.errorbar(t[idx], d[idx], yerr=[lo, hi], fmt="none", ecolor=colour, capsize=2, lw=0.8)
        if asymptotes:
            for text, tt, yy, style in _asymptotes(r, source):
                ax.plot(tt, yy, style, color=colour, lw=1, alpha=0.8, label=text)
            # The Allan minimum (the datasheet's "bias instability"), marked where it was read.
            m = next((g for g in r.readings if g["term"] == "allan_minimum" and g["basis"] == "value"), None)
            if m is not None and m.get("tau_s"):
                j = int(np.argmin(np.abs(t - m["tau_s"])))
                text = f"Allan minimum = {m['value']:.3g} {m['unit']} at τ = {t[j]:.3g} s"
                ax.plot([t[j]], [d[j]], "v", color=colour, ms=8, mfc="none", ls="none", label=text)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("averaging time τ (s)")
    units = sorted({r.unit for r in results})
    kinds = sorted({r.kind.upper() for r in results})
    ax.set_ylabel(f"{'/'.join(kinds)} σ(τ) ({', '.join(units)})")
    ax.grid(True, which="both", alpha=0.3)
    # One legend entry per label, even when several results are drawn on one axes.
    handles, texts = ax.get_legend_handles_labels()
    unique = dict(zip(texts, handles))
    ax.legend(unique.values(), unique.keys(), loc="best", fontsize="small")
    return ax
