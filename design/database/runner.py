"""Evaluate a table of designs with a scenario: validation first, then one simulation per row.

:func:`evaluate_designs` checks every row before anything is simulated (missing columns,
non-numeric or physically invalid values are reported together, with their 1-based row numbers,
as one :class:`DesignTableError`), warns about values outside the paper's sampling ranges, then
evaluates the rows (optionally on several worker processes with joblib, or on a Dask cluster
given its scheduler address) and returns the rows in the same order with the performance columns
and ``status``. A row whose simulation raises (or whose Dask worker dies) gets
``status = "failed: <reason>"`` and empty (NaN) outputs; the batch goes on.

Per-row isolation (:mod:`~holofold.design.database.row_limits`): ``on_invalid="skip"`` records
invalid
rows as ``failed: invalid design: <the problems>`` in their place and simulates the others
(``"fail"``, the default, refuses the table); each row has a time limit (``row_timeout``, by
default the scenario's) past which it is recorded as ``failed: timeout after ... s`` and the
run goes on.
"""

from __future__ import annotations

import logging
import math
import re
import sys
import warnings
from collections import Counter
from collections.abc import Iterator
from contextlib import closing, contextmanager, nullcontext
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from holofold.design.database.faults import as_environment_fault
from holofold.design.database.row_limits import (
    RowTimeout,
    call_with_limit,
    check_on_invalid,
    resolve_row_timeout,
    timeout_reason,
)
from holofold.design.database.row_status import STATE_COLUMNS, status_columns
from holofold.design.scenarios import Scenario, load_scenario
from holofold.design.scenarios.base import check_row, single_thread
from holofold.geometry.fault_points import fault_point
from holofold.mechanics.kernels import check_environment
from holofold.mechanics.status import Status

__all__ = [
    "DesignTableError",
    "ValidatedTable",
    "validate_designs",
    "evaluate_designs",
    "iter_results",
    "plan_tasks",
    "results_table",
    "progress_bar",
    "check_scheduler",
    "check_workers",
    "dask_scheduler",
]

log = logging.getLogger(__name__)

_MAX_LISTED = 20
# scheme://host:port, host a name, an IPv4 address or a bracketed IPv6 address
_ADDRESS = re.compile(r"[a-z][a-z0-9+.-]*://(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):[0-9]{1,5}")


class DesignTableError(ValueError):
    """The design table cannot be evaluated (missing columns or invalid rows)."""


@dataclass(frozen=True)
class ValidatedTable:
    """Rows ready to simulate.

    Attributes
    ----------
    rows : list of dict
        One dict of feature -> float per valid row, in table order (optional features filled
        in).
    warnings : list of str
        Summary lines for values outside the paper's sampling ranges.
    invalid : dict
        0-based table position -> its problems (``"; "``-joined) of each invalid row; empty
        unless validated with ``on_invalid="skip"``.
    """

    rows: list
    warnings: list
    invalid: dict = field(default_factory=dict)

    @property
    def positions(self) -> list[int]:
        """0-based table position of each of :attr:`rows`."""
        n = len(self.rows) + len(self.invalid)
        return [i for i in range(n) if i not in self.invalid]

    def invalid_outputs(self, scenario: Scenario) -> dict[int, dict]:
        """Position -> the failed output recorded for each invalid row."""
        return {i: _invalid_output(scenario, why) for i, why in self.invalid.items()}

    def skipped_line(self) -> str | None:
        """One line saying how many invalid rows were skipped (the first of them), or None."""
        if not self.invalid:
            return None
        i, why = min(self.invalid.items())
        n = len(self.rows) + len(self.invalid)
        return (
            f"{len(self.invalid)} of {n} row(s) invalid, recorded as failed and not simulated "
            f"(first: row {i + 1}: {why})"
        )


def _as_number(v):
    if isinstance(v, bool | np.bool_):
        return None
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return f


def validate_designs(
    scenario: Scenario, table: pd.DataFrame, on_invalid: str = "fail"
) -> ValidatedTable:
    """Check every row of ``table`` before any simulation.

    ``on_invalid="skip"``: invalid rows are not refused but returned in
    :attr:`ValidatedTable.invalid` (missing columns are still refused).

    Raises
    ------
    DesignTableError
        Listing missing columns, or (``on_invalid="fail"``) every invalid row (1-based
        data-row numbers, up to 20 listed).
    """
    check_on_invalid(on_invalid)
    missing = [c for c in scenario.required_features if c not in table.columns]
    if missing:
        raise DesignTableError(
            f"missing column(s) {', '.join(missing)} for scenario {scenario.name!r} "
            f"(needs {', '.join(scenario.required_features)}; SI units)"
        )
    present = [c.name for c in scenario.features if c.name in table.columns]
    problems: list[str] = []
    invalid: dict[int, str] = {}
    rows: list[dict] = []
    warn_counts: Counter = Counter()
    warn_first: dict[str, tuple[int, str]] = {}
    records = table[present].to_dict("records")
    for i, rec in enumerate(records, start=1):
        row: dict = {}
        bad = []
        for c in scenario.features:
            if c.name not in rec:
                row[c.name] = c.default
                continue
            v = _as_number(rec[c.name])
            if v is None or (not c.required and math.isnan(v)):
                if c.required:
                    bad.append(f"{c.name} = {rec[c.name]!r} is not a number")
                else:
                    row[c.name] = c.default
                continue
            if math.isnan(v) or math.isinf(v):
                bad.append(f"{c.name} is {'missing' if math.isnan(v) else 'infinite'}")
                continue
            row[c.name] = v
        if not bad:  # the one check of the row: check_row's, as Scenario.evaluate's
            bad = check_row(scenario.features, scenario.check, row, scenario.name)
        if bad:
            problems.append(f"row {i}: " + "; ".join(bad))
            invalid[i - 1] = "; ".join(bad)
            continue
        for c in scenario.features:
            v = row.get(c.name)
            w = None if v is None else c.out_of_range(v)
            if w:
                warn_counts[c.name] += 1
                warn_first.setdefault(c.name, (i, w))
        rows.append(row)
    if problems and on_invalid == "fail":
        head = problems[:_MAX_LISTED]
        more = len(problems) - len(head)
        tail = f"\n  ... and {more} more invalid row(s)" if more else ""
        raise DesignTableError(
            f"{len(problems)} invalid row(s) for scenario {scenario.name!r}, nothing simulated:\n  "
            + "\n  ".join(head)
            + tail
            + "\n(on_invalid='skip', --on-invalid skip: record them as failed rows, simulate "
            "the others)"
        )
    warnings = [
        f"{warn_first[k][1]} (row {warn_first[k][0]}; {n} row(s) in all)"
        for k, n in warn_counts.items()
    ]
    return ValidatedTable(rows=rows, warnings=warnings, invalid=invalid)


def _failed_output(scenario: Scenario, status: Status) -> dict:
    """NaN outputs and ``status``."""
    return {**dict.fromkeys(scenario.performance_names, float("nan")), "status": status}


def _invalid_output(scenario: Scenario, why: str) -> dict:
    """NaN outputs and ``status = "failed: invalid design: <problems>"``."""
    return _failed_output(scenario, Status.failed(f"invalid design: {why}"))


def _failed(scenario: Scenario, exc: BaseException) -> dict:
    """NaN outputs and ``status = "failed: <ExceptionName>: <first line of the message>"``."""
    return _failed_output(scenario, Status.from_exception(exc))


def _checked_output(scenario: Scenario, out: dict) -> dict:
    """``out`` with a :class:`Status`; a converged row with a non-finite output is not."""
    status = Status.parse(out.get("status", "failed: the evaluator returned no status"))
    if status.converged:
        values = {c: _as_number(out.get(c)) for c in scenario.performance_names}
        bad = [c for c, v in values.items() if v is None or not math.isfinite(v)]
        if bad:
            status = Status.not_converged(f"non-finite output: {', '.join(bad)}")
    return {**out, "status": status}


def _evaluate_one(
    scenario: Scenario, row: dict, limit_threads: bool, timeout: float | None = None
) -> dict:
    """Evaluate one row within ``timeout`` seconds (None: no limit); any exception becomes a
    ``failed: ...`` status, running past the limit ``failed: timeout after ... s``."""
    try:
        with single_thread() if limit_threads else nullcontext():
            out = call_with_limit(timeout, scenario.simulate, row)  # the row checked before
        return _checked_output(scenario, out)
    except RowTimeout:
        return _failed_output(scenario, Status.failed(timeout_reason(timeout)))
    except Exception as exc:  # noqa: BLE001 - a failed row must not stop the batch
        _raise_environment_fault(scenario, exc)
        return _failed(scenario, exc)


def _raise_environment_fault(scenario: Scenario, exc: BaseException) -> None:
    """Raise the :class:`~holofold.geometry.errors.EnvironmentFault` that ``exc`` is (the run
    stops, nothing stored); return if it is the design's own failure."""
    fault = as_environment_fault(exc, f"a design of {scenario.name}")
    if fault is not None:
        raise fault from None


#: rows per task when a scenario evaluates batches (``Scenario.evaluate_batch``): enough to
#: amortise the per-iteration overhead, few enough to keep two workers busy to the end
BATCH_ROWS = 16


def plan_tasks(scenario: Scenario, rows: list) -> list[list[int]]:
    """Positions of ``rows`` in tasks: one row each, or up to :data:`BATCH_ROWS` rows with the
    same ``scenario.batch_key`` when the scenario evaluates batches."""
    if scenario.evaluate_batch is None or scenario.batch_key is None or len(rows) <= 1:
        return [[i] for i in range(len(rows))]
    groups: dict = {}
    for i, r in enumerate(rows):
        try:
            key = scenario.batch_key(r)
        except Exception:  # noqa: BLE001 - the row fails on its own in evaluate
            key = ("row", i)
        groups.setdefault(key, []).append(i)
    return [g[j : j + BATCH_ROWS] for g in groups.values() for j in range(0, len(g), BATCH_ROWS)]


def _evaluate_batch(
    scenario: Scenario, rows: list, limit_threads: bool, timeout: float | None = None
) -> list[dict]:
    """Evaluate rows of one batch key together, within ``len(rows) * timeout`` seconds; if
    that raises or runs past its limit, each row on its own with its own limit (so a row
    whose simulation raises or hangs fails alone, as with :func:`_evaluate_one`)."""
    if len(rows) == 1 or scenario.evaluate_batch is None:
        return [_evaluate_one(scenario, r, limit_threads, timeout) for r in rows]
    limit = None if timeout is None else timeout * len(rows)
    try:
        with single_thread() if limit_threads else nullcontext():
            outs = call_with_limit(limit, scenario.evaluate_batch, rows)
        return [_checked_output(scenario, o) for o in outs]
    except (Exception, RowTimeout) as exc:  # noqa: BLE001 - fall back to the rows one by one
        if isinstance(exc, Exception):
            _raise_environment_fault(scenario, exc)
        return [_evaluate_one(scenario, r, limit_threads, timeout) for r in rows]


def check_workers(workers) -> int:
    """``workers`` as an int: >= 1 processes, or -1 for every core (else ``ValueError``)."""
    w = int(workers)
    if w == 0 or w < -1:
        raise ValueError(f"workers = {workers} must be >= 1 or -1 (all cores)")
    return w


def check_scheduler(scheduler: str) -> str:
    """Check a Dask scheduler address before anything is done with it.

    Parameters
    ----------
    scheduler : str
        ``"local"`` (a local Dask cluster) or an address ``scheme://host:port`` such as
        ``tcp://10.0.0.5:8786``.

    Returns
    -------
    str
        The address without surrounding blanks (``"local"`` in lower case).

    Raises
    ------
    ValueError
        The address does not look like one, or the optional package ``distributed`` is
        missing.
    """
    address = str(scheduler).strip()
    if address.lower() == "local":
        address = "local"
    elif not _ADDRESS.fullmatch(address) or int(address.rsplit(":", 1)[1]) > 65535:
        raise ValueError(
            f"Dask scheduler {scheduler!r} is not an address: expected 'local' or "
            "scheme://host:port, e.g. tcp://10.0.0.5:8786"
        )
    try:
        import distributed  # noqa: F401
    except ImportError:
        raise ValueError(
            f"running on a Dask cluster (scheduler {address!r}) needs the optional package "
            'distributed: pip install "holofold[cluster]"'
        ) from None
    return address


@contextmanager
def dask_scheduler(scheduler: str, workers: int = 1) -> Iterator[str]:
    """Context manager giving the address of a running Dask scheduler.

    Parameters
    ----------
    scheduler : str
        An address (checked by :func:`check_scheduler`, used as is) or ``"local"``: a
        ``distributed.LocalCluster`` runs for the duration of the block with ``workers``
        single-threaded worker processes (-1: one per core).
    workers : int
        Worker processes of the local cluster; ignored for a remote scheduler.

    Yields
    ------
    str
        The scheduler address.
    """
    address = check_scheduler(scheduler)
    workers = check_workers(workers)
    if address != "local":
        if workers != 1:
            log.info("workers = %s ignored: the Dask cluster at %s has its own", workers, address)
        yield address
        return
    from distributed import LocalCluster
    from joblib import cpu_count

    n = cpu_count() if workers == -1 else workers
    log.info("starting a local Dask cluster with %d worker process(es)", n)
    # LocalCluster quietens only distributed's own handler; its INFO records would still reach
    # the root logger's handlers (as in the CLI), so quieten the logger for the block
    quiet = logging.getLogger("distributed")
    level = quiet.level
    quiet.setLevel(max(level, logging.WARNING))
    try:
        with LocalCluster(  # scheduler, workers and dashboard on loopback only
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address="127.0.0.1:0",
        ) as cluster:
            yield cluster.scheduler_address
    finally:
        quiet.setLevel(level)


def _worker_ready(scenario: Scenario) -> str:
    """Run on every Dask worker before a batch: unpickling ``scenario`` imports holofold."""
    return scenario.name


def _iter_on_dask(
    scenario: Scenario, rows: list, limit_threads: bool, address: str, timeout: float | None
) -> Iterator[tuple[int, dict]]:
    """Evaluate ``rows`` on the Dask scheduler at ``address``, yielding results as they finish.

    Every row is submitted at once; ``(i, result)`` pairs (``i`` the 0-based position in
    ``rows``) come in order of completion. A task that errs outside :func:`_evaluate_one` (its
    worker died: ``KilledWorker``) yields a failed row. Workers that cannot import holofold
    raise ``ValueError`` before anything is submitted; a lost scheduler (cancelled futures)
    raises. When the generator ends early (an exception, or ``close()``: wrap it in
    :func:`contextlib.closing`), the tasks still pending are cancelled.
    """
    from distributed import Client

    # distributed's own log lines (reconnection attempts, tracebacks of a lost scheduler) would
    # bury the one line this run ends with: quieten them for the block, and after it when the
    # cluster was lost (its client threads go on logging while they shut down)
    levels = {
        name: logging.getLogger(name).level
        for name in ["distributed", *logging.root.manager.loggerDict]
        if name.split(".")[0] == "distributed"
    }
    for name in levels:
        logging.getLogger(name).setLevel(logging.CRITICAL + 1)
    lost = True
    try:
        try:
            client = Client(address, set_as_default=False, timeout=SCHEDULER_TIMEOUT)
        except (OSError, TimeoutError) as exc:
            raise ClusterError(
                f"cannot reach the Dask scheduler at {address} within {SCHEDULER_TIMEOUT:g} s "
                f"({type(exc).__name__}); start it, or check the address"
            ) from None
        try:
            yield from _on_client(client, scenario, rows, limit_threads, address, timeout)
            lost = False
        except GeneratorExit:
            lost = False
            raise
        finally:
            try:
                client.close(timeout=2)
            except Exception:  # noqa: BLE001 - a lost scheduler: nothing left to close
                pass
    finally:
        if not lost:
            for name, level in levels.items():
                logging.getLogger(name).setLevel(level)


#: seconds a run waits to reach its Dask scheduler, or to see it again once lost
SCHEDULER_TIMEOUT = 20.0


def worker_timeout() -> float:
    """Seconds a Dask run waits while its cluster has no worker, before it stops with one
    line: ``HOLOFOLD_WORKER_TIMEOUT`` (default 120)."""
    import os

    text = os.environ.get("HOLOFOLD_WORKER_TIMEOUT", "120")
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not value > 0:
        raise ValueError(f"HOLOFOLD_WORKER_TIMEOUT = {text!r} must be seconds > 0")
    return value


class ClusterError(OSError):
    """The Dask cluster cannot go on (its scheduler is lost, or it has no workers); the
    message is one line with what to do (finished database chunks are kept: run again)."""


def _lost(address: str, exc: BaseException) -> ClusterError:
    return ClusterError(
        f"lost the Dask scheduler at {address} ({type(exc).__name__}); every finished chunk "
        "is stored: start the scheduler and workers again and run the same command to resume"
    )


def _n_workers(client) -> int:
    """Workers the scheduler knows now (raises if it cannot be asked)."""
    return len(client.sync(client.scheduler.ncores, workers=None))


def _on_client(client, scenario, rows, limit_threads, address, timeout):
    """:func:`_iter_on_dask` on a connected ``client``."""
    import concurrent.futures
    import time

    from distributed import as_completed

    n = len(rows)
    limit = worker_timeout()
    try:
        if not _n_workers(client):
            log.info("no Dask workers at %s yet: waiting up to %g s", address, limit)
            try:
                client.wait_for_workers(1, timeout=limit)
            except TimeoutError:
                raise ClusterError(_no_workers(address, limit)) from None
    except ClusterError:
        raise
    except (OSError, concurrent.futures.CancelledError) as exc:
        raise _lost(address, exc) from None
    # a worker that cannot unpickle a task drops out of the cluster and the batch would wait
    # forever; client.run reports the same failure instead
    try:
        client.run(_worker_ready, scenario)
    except (OSError, concurrent.futures.CancelledError) as exc:
        raise _lost(address, exc) from None
    except Exception as exc:  # noqa: BLE001 - whatever the workers raised
        raise ValueError(
            f"the Dask workers of {address} cannot run holofold ({exc}); install it on "
            'every worker: pip install "holofold[cluster]"'
        ) from None
    futures = client.map(
        _evaluate_one, [scenario] * n, rows, [limit_threads] * n, [timeout] * n, pure=False
    )
    where = {f.key: i for i, f in enumerate(futures)}
    done = as_completed(futures, loop=client.loop)
    checked = idle = time.monotonic()
    try:
        while not done.is_empty():
            if not done.has_ready():
                time.sleep(0.05)
                now = time.monotonic()
                if now - checked < 1.0:
                    continue
                checked = now  # once a second: is the scheduler there, has it workers?
                if client.status != "running":
                    raise _lost(address, ConnectionError(f"client {client.status}"))
                if _n_workers(client):
                    idle = now
                elif now - idle > limit:
                    raise ClusterError(_no_workers(address, limit))
                continue
            for f in done.next_batch(block=False):
                if f.status == "cancelled":  # the scheduler forgot it: lost
                    raise _lost(address, concurrent.futures.CancelledError())
                if f.status == "error":  # the worker died (KilledWorker), or the environment
                    _raise_environment_fault(scenario, f.exception())
                    out = _failed(scenario, f.exception())
                else:
                    out = f.result()
                f.release()  # the cluster forgets the result; the caller holds the only copy
                yield where[f.key], out
    except (OSError, concurrent.futures.CancelledError, TimeoutError) as exc:
        if isinstance(exc, ClusterError):
            raise
        raise _lost(address, exc) from None
    finally:  # interrupted (Ctrl-C, lost scheduler): leave nothing running on the cluster
        try:
            client.cancel([f for f in futures if not f.done()])
        except Exception:  # noqa: BLE001 - a lost scheduler cancelled them already
            pass


def _no_workers(address: str, limit: float) -> str:
    return (
        f"no Dask worker at {address} for {limit:g} s (HOLOFOLD_WORKER_TIMEOUT); start some "
        f"(dask worker {address} --nthreads 1) and run the same command to resume"
    )


def iter_results(
    scenario: Scenario,
    rows: list,
    *,
    workers: int = 1,
    address: str | None = None,
    limit_threads: bool = True,
    row_timeout: float | None = None,
    tasks: list[list[int]] | None = None,
) -> Iterator[tuple[int, dict]]:
    """Simulate validated ``rows``, yielding ``(position, output)`` as each row finishes.

    ``address``: a running Dask scheduler (rows come in order of completion, see
    :func:`dask_scheduler`); otherwise joblib processes (``workers``, -1 = every core). A
    scenario with ``evaluate_batch`` gets its rows in tasks of up to :data:`BATCH_ROWS` rows of
    one ``batch_key`` (their Newton solves in lockstep; each output the row's own), which come
    in row order of their first rows; other scenarios' rows come in order. Each output has the
    performance columns and a :class:`Status`; a row whose simulation raises is a failed row,
    never an exception. Close the iterator (:func:`contextlib.closing`) to cancel what is
    still running. ``row_timeout``: seconds per row (None: no limit; a batch of k rows has
    k times as long, and past it its rows run again one by one); a row past its limit is
    ``failed: timeout after ... s``. ``tasks`` (joblib only): the positions of ``rows`` to
    simulate, task by task (default :func:`plan_tasks` of every row); a resume passes the
    tasks of an uninterrupted run that are still missing, so each row keeps its batch.
    """
    if rows:  # the environment before any row: a fault here is never a row's outcome
        check_environment()
    if address is not None:
        yield from _iter_on_dask(scenario, rows, limit_threads, address, row_timeout)
        return
    if tasks is None:
        tasks = plan_tasks(scenario, rows)
    args = (limit_threads, row_timeout)
    if workers == 1 or len(tasks) <= 1:
        outs = (_evaluate_batch(scenario, [rows[i] for i in t], *args) for t in tasks)
    else:
        from joblib import Parallel, delayed

        par = Parallel(n_jobs=workers, return_as="generator", batch_size=1)
        outs = par(delayed(_evaluate_batch)(scenario, [rows[i] for i in t], *args) for t in tasks)
    for task, out in zip(tasks, outs, strict=True):
        for pos, one in zip(task, out, strict=True):
            fault_point("row")  # test-only (HOLOFOLD_TEST_FAULT); nothing when unset
            yield pos, one


def progress_bar(total: int, desc: str, enabled: bool | None = None, initial: int = 0):
    """A tqdm bar on stderr (shown by default only on a terminal), or None."""
    if enabled is None:
        enabled = bool(getattr(sys.stderr, "isatty", lambda: False)())
    if not enabled:
        return None
    from tqdm import tqdm

    return tqdm(total=total, initial=initial, desc=desc, unit="design", file=sys.stderr)


def evaluate_designs(
    scenario: Scenario | str,
    table: pd.DataFrame,
    *,
    workers: int = 1,
    progress: bool | None = None,
    limit_threads: bool = True,
    log_warnings: bool = True,
    scheduler: str | None = None,
    on_invalid: str = "fail",
    row_timeout: float | str | None = None,
) -> pd.DataFrame:
    """Simulate every row of ``table`` with ``scenario``.

    Parameters
    ----------
    scenario : Scenario or str
        The scenario or its name (:data:`holofold.design.scenarios.SCENARIO_NAMES`).
    table : DataFrame
        Feature columns in SI units (names as in the published files); other columns are
        kept. Input columns named like a performance column are replaced.
    workers : int
        Worker processes (joblib); 1 runs in this process. -1 uses every core. With
        ``scheduler="local"``: the local Dask cluster's worker processes (-1: one per core);
        ignored for a remote scheduler.
    progress : bool, optional
        Show a tqdm progress bar; default only when stderr is a terminal.
    limit_threads : bool
        Limit BLAS to one thread per evaluation (the small dense solves are much slower
        when several threads contend for the cores).
    log_warnings : bool
        Log values outside the paper's sampling ranges and warn how many invalid rows were
        skipped (callers that report ``validate_designs(...).warnings`` and
        ``.skipped_line()`` themselves pass False).
    scheduler : str, optional
        Run on a Dask cluster instead of joblib: its scheduler address
        (``tcp://host:8786``), or ``"local"`` for a local cluster started for this call (see
        :func:`dask_scheduler`). Needs the ``cluster`` extra.
    on_invalid : {"fail", "skip"}
        ``"fail"``: an invalid row refuses the whole table (:class:`DesignTableError`, nothing
        simulated). ``"skip"``: invalid rows get ``status = "failed: invalid design: <their
        problems>"`` and NaN outputs in their place, the others are simulated.
    row_timeout : float, optional
        Time limit per row, seconds; a row past it gets ``status = "failed: timeout after
        ... s"`` and the run goes on. None: the scenario's ``row_timeout``; 0 or ``"none"``:
        no limit.

    Returns
    -------
    DataFrame
        The input rows in the same order, then the performance columns and ``status``.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    workers = check_workers(workers)
    if scheduler is not None:
        scheduler = check_scheduler(scheduler)
    timeout = resolve_row_timeout(scenario.row_timeout, row_timeout)
    checked = validate_designs(scenario, table, on_invalid)
    for w in checked.warnings if log_warnings else ():
        log.warning("outside the paper's sampling ranges: %s", w)
    if log_warnings and checked.invalid:
        warnings.warn(checked.skipped_line(), stacklevel=2)
    rows, where = checked.rows, checked.positions
    outs: list = [None] * len(table)
    for i, out in checked.invalid_outputs(scenario).items():
        outs[i] = out
    cluster = dask_scheduler(scheduler, workers) if scheduler and rows else nullcontext()
    bar = progress_bar(len(rows), scenario.name, progress)
    try:
        with cluster as address:
            results = iter_results(
                scenario, rows, workers=workers, address=address, limit_threads=limit_threads,
                row_timeout=timeout,
            )  # fmt: skip
            with closing(results):
                for i, out in results:
                    outs[where[i]] = out
                    if bar is not None:
                        bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    return results_table(scenario, table, outs)


def results_table(scenario: Scenario, table: pd.DataFrame, outs: list) -> pd.DataFrame:
    """The input rows (index kept), then the performance columns and ``status`` (text) of
    ``outs`` (one output of :func:`iter_results` per row, in row order)."""
    perf = scenario.performance_names
    keep = [c for c in table.columns if c not in perf and c not in STATE_COLUMNS]
    replaced = [c for c in table.columns if c in perf or c in STATE_COLUMNS]
    if replaced:
        log.info("input column(s) %s replaced by the computed values", ", ".join(replaced))
    res = table[keep].reset_index(drop=True).copy()
    for c in perf:
        res[c] = np.array([o.get(c, np.nan) for o in outs], dtype=float)
    for name, values in status_columns(o["status"] for o in outs).items():
        res[name] = values
    res.index = table.index
    return res
