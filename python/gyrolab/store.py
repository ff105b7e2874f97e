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

    def add(
        self,
        report_folder: PathLike,
        plan: Optional[PathLike] = None,
        user: Optional[str] = None,
        password: Optional[str] = None,
    ) -> int:
        """Stores a finished report folder (``gyrolab eval --out``; its plan: ``plan``, else the
        one its results.json names, with every input hashed and kept) as a new evaluation; the
        store is created when missing. A store with accounts needs the account that stores it:
        ``user`` and ``password`` (default: the ``GYROLAB_USER`` and ``GYROLAB_PASSWORD``
        environment variables, as for the command line). Returns the evaluation id."""
        user, password = _account(user, password)
        eid, _name = _gyrolab.store_add(
            self.location, os.fspath(report_folder), None if plan is None else os.fspath(plan), user, password
        )
        return int(eid)

    def check(self) -> Dict[str, Any]:
        """Re-verifies the store (``gyrolab store check --json``): the SQLite file's pages, the
        protecting triggers, every hash-chain link against its row, every stored report file and
        raw record against its SHA-256. ``problems`` is empty when the store is whole; ``head``
        is the chain head to keep elsewhere."""
        return json.loads(_gyrolab.store_check(self.location))

    def accounts(self) -> List[Dict[str, Any]]:
        """Every account (``gyrolab store user list --json``): name, display name, role,
        disabled, created (the database's time) and by whom."""
        return list(json.loads(_gyrolab.store_accounts(self.location)))

    def add_user(
        self,
        name: str,
        role: str,
        new_password: str,
        display_name: Optional[str] = None,
        user: Optional[str] = None,
        password: Optional[str] = None,
    ) -> str:
        """Adds an account (``gyrolab store user add``; role ``viewer``, ``operator``,
        ``approver`` or ``admin``; the password hashed with Argon2id). The store's first account
        is an admin, added by no one; every later one by the admin ``user`` with ``password``
        (default: ``GYROLAB_USER``, ``GYROLAB_PASSWORD``). Returns the line saying so."""
        user, password = _account(user, password)
        return str(_gyrolab.store_add_user(self.location, name, role, new_password, display_name, user, password))

    def issue(
        self,
        id: int,
        signing_key: PathLike,
        meaning: str = "approved",
        report_number: Optional[str] = None,
        user: Optional[str] = None,
        password: Optional[str] = None,
    ) -> Dict[str, Any]:
        """Issues evaluation ``id`` (``gyrolab store issue``): an approver (``user`` with
        ``password``; default ``GYROLAB_USER``, ``GYROLAB_PASSWORD``) who did not store it signs
        its manifest with the lab's private key file ``signing_key``; the store gives the report
        number (or ``report_number``) and the issue date from its clock. ``meaning``:
        ``approved`` or ``reviewed``. Returns the issued report (number, date, signer, key,
        chain head, status)."""
        user, password = _account(user, password, needed="issuing needs an approver's account")
        return json.loads(
            _gyrolab.store_issue(self.location, int(id), user, password, os.fspath(signing_key), meaning, report_number)
        )

    def amend(
        self,
        id: int,
        reason: str,
        signing_key: PathLike,
        meaning: str = "approved",
        user: Optional[str] = None,
        password: Optional[str] = None,
    ) -> Dict[str, Any]:
        """Issues the correction ``id`` of an issued evaluation as an amendment (``gyrolab store
        amend``, ISO/IEC 17025 7.8.8): "Amendment N to report R" with ``reason``; the report it
        replaces stays retrievable, marked superseded. As :meth:`issue` otherwise."""
        user, password = _account(user, password, needed="amending needs an approver's account")
        return json.loads(
            _gyrolab.store_issue(self.location, int(id), user, password, os.fspath(signing_key), meaning, None, reason)
        )

    def reevaluate(
        self,
        id: int,
        out: PathLike,
        reason: str,
        by: Optional[str] = None,
        user: Optional[str] = None,
        password: Optional[str] = None,
    ) -> Dict[str, Any]:
        """Evaluates the current evaluation ``id`` again under this gyrolab (``gyrolab store
        reevaluate --json``): its plan and inputs where they are when unchanged, else the raw
        records the store keeps, into the report folder ``out``, stored as a revision (by the
        account ``user``, or ``by`` in a store without accounts) for ``reason``. Returns the
        revision's id and every figure whose value or verdict changed."""
        user, password = _account(user, password)
        return json.loads(
            _gyrolab.store_reevaluate(self.location, int(id), os.fspath(out), reason, by, user, password)
        )

    def inputs(self, id: int, out: PathLike) -> Tuple[str, List[str]]:
        """Writes the plan and raw records of evaluation ``id`` into the new folder ``out``, as
        they stood relative to the plan, each checked against its SHA-256 (``gyrolab store report
        ID --inputs``). Returns the plan's path and the records' paths."""
        plan, files = _gyrolab.store_inputs(self.location, int(id), os.fspath(out))
        return str(plan), [str(f) for f in files]

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



def _account(
    user: Optional[str], password: Optional[str], needed: Optional[str] = None
) -> Tuple[Optional[str], Optional[str]]:
    """The account of a write: ``user`` and ``password``, else ``GYROLAB_USER`` and
    ``GYROLAB_PASSWORD``; none at all for a store without accounts (unless ``needed`` says why
    one is)."""
    user = user if user is not None else (os.environ.get("GYROLAB_USER") or None)
    if user is not None and password is None:
        password = os.environ.get("GYROLAB_PASSWORD")
    if user is not None and password is None:
        raise Error(f"user {user!r} needs its password: password=... or GYROLAB_PASSWORD")
    if user is None and needed is not None:
        raise Error(f"{needed}: user=... and password=... (or GYROLAB_USER and GYROLAB_PASSWORD)")
    return user, password


def _masked(location: str) -> str:
    """The location with any password masked (``***``), as every message of the store shows it."""
    return str(_gyrolab.store_masked(location))
