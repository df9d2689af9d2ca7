"""Evaluate a table of designs with a scenario: validation first, then one simulation per row.

:func:`evaluate_designs` checks every row before anything is simulated (missing columns,
non-numeric or physically invalid values are reported together, with their 1-based row numbers,
as one :class:`DesignTableError`), warns about values outside the paper's sampling ranges, then
evaluates the rows (optionally on several worker processes with joblib) and returns the rows in
the same order with the performance columns and ``status``. A row whose simulation raises gets
``status = "failed: <reason>"`` and empty (NaN) outputs; the batch goes on.
"""

from __future__ import annotations

import logging
import math
import sys
from collections import Counter
from dataclasses import dataclass

import numpy as np
import pandas as pd

from design.scenarios import Scenario, get_scenario
from design.scenarios.base import single_thread

__all__ = ["DesignTableError", "ValidatedTable", "validate_designs", "evaluate_designs"]

log = logging.getLogger(__name__)

_MAX_LISTED = 20


class DesignTableError(ValueError):
    """The design table cannot be evaluated (missing columns or invalid rows)."""


@dataclass(frozen=True)
class ValidatedTable:
    """Rows ready to simulate.

    Attributes
    ----------
    rows : list of dict
        One dict of feature -> float per row (optional features filled in).
    warnings : list of str
        Summary lines for values outside the paper's sampling ranges.
    """

    rows: list
    warnings: list


def _as_number(v):
    if isinstance(v, bool | np.bool_):
        return None
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return f


def validate_designs(scenario: Scenario, table: pd.DataFrame) -> ValidatedTable:
    """Check every row of ``table`` before any simulation.

    Raises
    ------
    DesignTableError
        Listing missing columns, or every invalid row (1-based data-row numbers, up to 20
        listed).
    """
    missing = [c for c in scenario.required_features if c not in table.columns]
    if missing:
        raise DesignTableError(
            f"missing column(s) {', '.join(missing)} for scenario {scenario.name!r} "
            f"(needs {', '.join(scenario.required_features)}; SI units)"
        )
    present = [c.name for c in scenario.features if c.name in table.columns]
    problems: list[str] = []
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
        if not bad:
            bad = scenario.check(row)
        if bad:
            problems.append(f"row {i}: " + "; ".join(bad))
            continue
        for c in scenario.features:
            v = row.get(c.name)
            w = None if v is None else c.out_of_range(v)
            if w:
                warn_counts[c.name] += 1
                warn_first.setdefault(c.name, (i, w))
        rows.append(row)
    if problems:
        head = problems[:_MAX_LISTED]
        more = len(problems) - len(head)
        tail = f"\n  ... and {more} more invalid row(s)" if more else ""
        raise DesignTableError(
            f"{len(problems)} invalid row(s) for scenario {scenario.name!r}, nothing simulated:\n  "
            + "\n  ".join(head)
            + tail
        )
    warnings = [
        f"{warn_first[k][1]} (row {warn_first[k][0]}; {n} row(s) in all)"
        for k, n in warn_counts.items()
    ]
    return ValidatedTable(rows=rows, warnings=warnings)


def _evaluate_one(scenario: Scenario, row: dict, limit_threads: bool) -> dict:
    """Evaluate one row; any exception becomes a ``failed: ...`` status."""
    try:
        if limit_threads:
            with single_thread():
                out = scenario.evaluate(row)
        else:
            out = scenario.evaluate(row)
    except Exception as exc:  # noqa: BLE001 - a failed row must not stop the batch
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        out = {c: float("nan") for c in scenario.performance_names}
        out["status"] = f"failed: {type(exc).__name__}: {reason}"
    return out


def evaluate_designs(
    scenario: Scenario | str,
    table: pd.DataFrame,
    *,
    workers: int = 1,
    progress: bool | None = None,
    limit_threads: bool = True,
    log_warnings: bool = True,
) -> pd.DataFrame:
    """Simulate every row of ``table`` with ``scenario``.

    Parameters
    ----------
    scenario : Scenario or str
        The scenario or its name (``single-miura``, ``canopy``, ``arch``).
    table : DataFrame
        Feature columns in SI units (names as in the published files); other columns are
        kept. Input columns named like a performance column are replaced.
    workers : int
        Worker processes (joblib); 1 runs in this process. -1 uses every core.
    progress : bool, optional
        Show a tqdm progress bar; default only when stderr is a terminal.
    limit_threads : bool
        Limit BLAS to one thread per evaluation (the small dense solves are much slower
        when several threads contend for the cores).
    log_warnings : bool
        Log values outside the paper's sampling ranges (callers that report
        ``validate_designs(...).warnings`` themselves pass False).

    Returns
    -------
    DataFrame
        The input rows in the same order, then the performance columns and ``status``.
    """
    if isinstance(scenario, str):
        scenario = get_scenario(scenario)
    workers = int(workers)
    if workers == 0 or workers < -1:
        raise DesignTableError(f"workers = {workers} must be >= 1 or -1 (all cores)")
    checked = validate_designs(scenario, table)
    for w in checked.warnings if log_warnings else ():
        log.warning("outside the paper's sampling ranges: %s", w)
    if progress is None:
        progress = bool(getattr(sys.stderr, "isatty", lambda: False)())
    n = len(checked.rows)
    if workers == 1 or n <= 1:
        results = (_evaluate_one(scenario, r, limit_threads) for r in checked.rows)
    else:
        from joblib import Parallel, delayed

        par = Parallel(n_jobs=workers, return_as="generator", batch_size=1)
        results = par(delayed(_evaluate_one)(scenario, r, limit_threads) for r in checked.rows)
    if progress:
        from tqdm import tqdm

        results = tqdm(results, total=n, desc=scenario.name, unit="design", file=sys.stderr)
    outs = list(results)
    perf = scenario.performance_names
    keep = [c for c in table.columns if c not in perf and c != "status"]
    replaced = [c for c in table.columns if c in perf or c == "status"]
    if replaced:
        log.info("input column(s) %s replaced by the computed values", ", ".join(replaced))
    res = table[keep].reset_index(drop=True).copy()
    for c in perf:
        res[c] = np.array([o.get(c, np.nan) for o in outs], dtype=float)
    res["status"] = [o.get("status", "") for o in outs]
    res.index = table.index
    return res
