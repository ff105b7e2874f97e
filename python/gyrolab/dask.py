"""Many records on a Dask cluster: :func:`allan_records` evaluates every record (a file gyrolab
reads) on the workers of any Dask deployment (a ``distributed.Client``: LocalCluster,
dask-jobqueue, ...; or dask's default scheduler through ``dask.bag``) and gathers one pandas
DataFrame.

Each task runs :func:`gyrolab.allan` on one record with the interpreter released, so worker
threads run in parallel; results and errors pickle. A failing record raises a
:class:`gyrolab.Error` whose message starts with the record (``errors="raise"``), or is kept
as one row of ``df.attrs["failures"]`` while the others are evaluated (``errors="collect"``).

>>> from distributed import Client, LocalCluster                     # doctest: +SKIP
>>> import gyrolab.dask
>>> with LocalCluster(n_workers=2, threads_per_worker=1) as c, Client(c) as client:  # doctest: +SKIP
...     table = gyrolab.dask.allan_records(paths, client=client, rate_hz=100.0)
"""

from __future__ import annotations

import os
from typing import Any, Dict, Iterable, List, Optional, Tuple

from ._errors import Error

__all__ = ["allan_records", "allan_record"]

_WHAT = ("noise", "curves")


def allan_record(record: Any, what: str = "noise", **options: Any) -> List[Dict[str, Any]]:
    """One record's rows (``what="noise"``: its noise table; ``"curves"``: its tidy curves),
    each with a ``record`` column: the task :func:`allan_records` runs on a worker. A failure
    is a :class:`gyrolab.Error` naming the record (its ``file`` attribute too)."""
    import gyrolab

    name = os.fspath(record)
    try:
        result = gyrolab.allan(name, record=name, **options)
    except Error as e:
        raise type(e)(
            e.message if e.message.startswith(name) else f"{name}: {e.message}",
            file=e.file or name,
            line=e.line,
            column=e.column,
            keyword=e.keyword,
        ) from None
    except (OSError, ValueError, TypeError) as e:
        raise Error(f"{name}: {e}", file=name) from None
    table = result.noise_table() if what == "noise" else result.to_dataframe()
    table.insert(0, "record", name)
    return table.to_dict("records")


def _task(record: Any, what: str, options: Dict[str, Any], collect: bool) -> Tuple[List[Dict[str, Any]], Optional[Dict[str, Any]]]:
    if not collect:
        return allan_record(record, what, **options), None
    try:
        return allan_record(record, what, **options), None
    except Error as e:
        return [], {"record": os.fspath(record), "error": str(e)}


def allan_records(
    records: Iterable[Any],
    client: Any = None,
    *,
    what: str = "noise",
    errors: str = "raise",
    npartitions: Optional[int] = None,
    **options: Any,
) -> Any:
    """Evaluates every record (file paths) with :func:`gyrolab.allan` on a Dask cluster and
    returns one pandas DataFrame: with ``what="noise"`` one row per record, channel and noise
    term (``record``, ``channel``, ``term``, ``value``, ``unit``, ``basis``, ``support``, ...);
    with ``what="curves"`` the tidy curves (``record``, ``channel``, ``tau_s``, ``dev``, ...).

    ``client``: a ``distributed.Client`` (tasks by ``client.map``, one per record); None uses
    ``dask.bag`` with dask's current scheduler (``npartitions`` partitions, default one per
    record up to 100). ``options`` go to :func:`gyrolab.allan` (``rate_hz``, ``kind``,
    ``taus``, ``units``, ...). ``errors="raise"`` (default) raises the first failing record's
    :class:`gyrolab.Error`, its message starting with the record; ``"collect"`` evaluates the
    others and lists the failures in ``df.attrs["failures"]`` (``record``, ``error``).
    """
    import pandas as pd

    if what not in _WHAT:
        raise Error(f"what='{what}': expected 'noise' or 'curves'", keyword="what")
    if errors not in ("raise", "collect"):
        raise Error(f"errors='{errors}': expected 'raise' or 'collect'", keyword="errors")
    paths = [os.fspath(r) for r in records]
    collect = errors == "collect"
    if client is not None:
        futures = client.map(_task, paths, what=what, options=options, collect=collect, pure=False)
        outcomes = client.gather(futures)
    else:
        import dask.bag as db

        parts = npartitions or max(1, min(len(paths), 100))
        outcomes = db.from_sequence(paths, npartitions=parts).map(_task, what, options, collect).compute()
    rows = [row for found, _ in outcomes for row in found]
    failures = [f for _, f in outcomes if f is not None]
    table = pd.DataFrame(rows)
    table.attrs["failures"] = failures
    return table
