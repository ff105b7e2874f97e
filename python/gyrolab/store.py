"""The records store from Python: the evaluations that ``gyrolab eval --store`` and ``gyrolab store
add`` keep (an SQLite file, or a PostgreSQL server when shared; docs/STORE.md), read back as pandas
DataFrames with the columns of ``gyrolab store ... --csv``.

The queries are gyrolab's own (the Rust crate ``gyrolab-store`` behind the command line), so the
numbers equal those of ``gyrolab store history/lot/compare/chart``. Each call opens the store,
runs with the interpreter released and closes it again: a :class:`Store` holds only its location,
pickles, and works in forked and Dask workers. Failures raise :class:`gyrolab.Error` naming the
store (a password in a URL is masked).

>>> from gyrolab.store import Store                                   # doctest: +SKIP
>>> s = Store("gyrolab.db")                                           # doctest: +SKIP
>>> s.add("report/")                                                  # doctest: +SKIP
>>> s.lot("SIM-LOT-1")[["axis", "figure", "unit", "n", "mean", "sd", "Cpk"]]  # doctest: +SKIP
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np

from . import _gyrolab
from ._errors import Error

__all__ = ["Store", "DEFAULT_FILE", "STORE_ENV"]

#: The environment variable naming the default store (as for the command line).
STORE_ENV = "GYROLAB_STORE"
#: The default store's file name (in the current folder).
DEFAULT_FILE = "gyrolab.db"

PathLike = Union[str, "os.PathLike[str]"]


def _pandas() -> Any:
    try:
        import pandas
    except ImportError as e:  # pragma: no cover - pandas is installed with gyrolab[pandas]
        raise ImportError("gyrolab.store returns pandas DataFrames: pip install 'gyrolab[pandas]'") from e
    return pandas


def _frame(table: Tuple[List[str], List[str], List[List[Any]]], query: str, store: str) -> Any:
    """A DataFrame from a native table: text columns as objects (None where empty), numbers as
    float64 (NaN where empty), counts as pandas' nullable Int64."""
    pd = _pandas()
    names, kinds, values = table
    data: Dict[str, Any] = {}
    for name, kind, column in zip(names, kinds, values):
        if kind == "number":
            data[name] = np.array([np.nan if v is None else v for v in column], dtype=np.float64)
        elif kind == "count":
            data[name] = pd.array(column, dtype="Int64")
        else:
            data[name] = pd.array(column, dtype=object)
    df = pd.DataFrame(data, columns=names)
    df.attrs["store"] = store
    df.attrs["query"] = query
    return df


class Store:
    """A records store: an SQLite file (created by the first :meth:`add`) or a
    ``postgres://user:password@host:port/database`` URL. ``location=None`` takes the
    ``GYROLAB_STORE`` environment variable, else ``gyrolab.db`` in the current folder."""

    def __init__(self, location: Optional[PathLike] = None) -> None:
        if location is None:
            location = os.environ.get(STORE_ENV) or DEFAULT_FILE
        self.location = os.fspath(location)

    def __repr__(self) -> str:
        return f"Store({_masked(self.location)!r})"

    def add(self, report_folder: PathLike, plan: Optional[PathLike] = None) -> int:
        """Stores a finished report folder (``gyrolab eval --out``; its plan: ``plan``, else the
        one its results.json names, with every input hashed) as a new evaluation; the store is
        created when missing. Returns the evaluation id."""
        eid, _name = _gyrolab.store_add(
            self.location, os.fspath(report_folder), None if plan is None else os.fspath(plan)
        )
        return int(eid)

    def history(self, serial: str, figure: Optional[str] = None) -> Any:
        """Every figure of every evaluation (all revisions) of ``serial``, oldest first: one row
        per figure (``evaluation``, ``supersedes``, ``current``, ``revision``, ``tested``,
        ``gyrolab``, ``axis``, ``figure``, ``value``, ``unit``, ``basis``, ``U``, ``k``,
        ``limit_min``, ``limit_max``, ``verdict``, ``simulated``); only ``figure`` when given."""
        return _frame(_gyrolab.store_history(self.location, serial, figure), f"history {serial}", self._name())

    def history_svg(self, serial: str, figure: Optional[str] = None) -> str:
        """The trend plot of ``serial``'s history as an SVG document, one panel per axis and
        figure (value against evaluation id, the latest limits as lines; SIMULATED in the title
        when any value is): the same bytes as ``gyrolab store history SERIAL --svg FILE``. Only
        ``figure`` when given; a serial without values raises :class:`gyrolab.Error`."""
        svg = _gyrolab.store_history_svg(self.location, serial, figure)
        if svg is None:
            raise Error(f"serial {serial!r}: no values to plot")
        return svg

    def lot(self, lot: str, confidence: float = 0.95) -> Any:
        """Statistics of each figure over the current evaluations of ``lot`` (each device once),
        from the values only: ``n`` (devices with a value) of ``n_devices`` (every device of the
        lot), ``n_bounds`` (devices giving only an upper or lower bound, never averaged),
        ``n_not_evaluated`` (no value, the verdict NOT EVALUATED, or the figure missing),
        ``mean``, ``sd``, ``min``, ``max``, the limits, ``yield`` (conforming devices /
        ``n_devices``), ``yield_evaluated`` (values inside the limits / ``n``), Cp, Cpk, Pp, Ppk
        with their ``confidence`` intervals (``_lo``, ``_hi``; refused for a degenerate spread),
        ``outliers``, ``simulated`` and ``notes`` (bounds, devices not evaluated, fewer than 25
        values, indices refused; joined by "; ")."""
        return _frame(_gyrolab.store_lot(self.location, lot, float(confidence)), f"lot {lot}", self._name())

    def compare(self, lot1: str, lot2: str) -> Any:
        """Two lots per figure, from the values only: ``n1``, ``n2`` (values) of
        ``n_devices1``, ``n_devices2``, both means, their ``difference``, Welch's t-test
        (``welch_t``, ``dof``, ``p_means``), the F-test of the spreads (``sd_ratio``, ``F``,
        ``p_spreads``) and ``notes`` (bounds, devices not evaluated, why there is no test)."""
        return _frame(_gyrolab.store_compare(self.location, lot1, lot2), f"compare {lot1} {lot2}", self._name())

    def control_chart(self, axis: str, figure: str, lot: Optional[str] = None) -> Any:
        """Control charts of one figure of one axis, from the values only: one row per point of
        the individuals and moving-range charts (over ``lot``, or every device) and of the X-bar
        and S charts over lots, with ``center``, ``lcl``, ``ucl`` and the Nelson rules each point
        breaks. ``attrs["notes"]`` lists the devices left out (bounds, not evaluated) and why a
        chart is missing (the command line prints them on standard error)."""
        table, notes = _gyrolab.store_chart(self.location, axis, figure, lot)
        df = _frame(table, f"chart {axis} {figure}", self._name())
        df.attrs["notes"] = list(notes)
        return df

    def figures(self, lot: Optional[str] = None) -> Any:
        """The current figures of every device of ``lot`` (every device: None), one row per
        device and figure: ``axis``, ``figure``, ``unit``, ``serial``, ``evaluation``,
        ``value`` (values only), ``limit_min``, ``limit_max``, ``series_simulated``, ``basis``
        (``value``, ``upper_bound``, ``lower_bound``, or the stored basis of a device not
        evaluated), ``bound`` (the number of a bound) and ``verdict`` (of a bound or a device
        not evaluated)."""
        return _frame(_gyrolab.store_figures(self.location, lot), f"figures {lot or '(all)'}", self._name())

    def evaluation(self, id: int) -> Dict[str, Any]:
        """One stored evaluation as the JSON of ``gyrolab store show --json``: device, lot,
        plan text and SHA-256, inputs with their SHA-256, revision, every figure."""
        return json.loads(_gyrolab.store_evaluation(self.location, int(id)))

    def report(self, id: int, out: PathLike) -> List[str]:
        """Writes the stored report folder of evaluation ``id`` to ``out`` (every file checked
        against its SHA-256 first; all files or none). Returns the files written."""
        return [str(p) for p in _gyrolab.store_report(self.location, int(id), os.fspath(out))]

    def _name(self) -> str:
        return _masked(self.location)



def _masked(location: str) -> str:
    """The location with any password masked (``***``), as every message of the store shows it."""
    return str(_gyrolab.store_masked(location))
