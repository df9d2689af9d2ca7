"""A row's outcome as typed columns: ``state`` and ``reason``.

Every simulated table (a database, an evaluated table, verification designs) carries

``state``
    ``"converged"``, ``"not converged"`` or ``"failed"`` (:class:`~holofold.mechanics.Outcome`);
``reason``
    why, for a row that did not converge or failed (``""`` for a converged row);

and, for people reading a CSV, ``status``: the two in one line (``failed: <reason>``), which
the library writes but never reads back. Tables written by older versions have ``status``
only: :func:`with_state` derives the typed columns from it when a table is read (migration
on read), so old databases stay readable.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from holofold.design.database.faults import stored_fault
from holofold.mechanics.status import Outcome, Status

__all__ = [
    "STATE_COLUMNS",
    "with_state",
    "status_columns",
    "row_statuses",
    "failed_rows",
    "converged_rows",
    "stale_rows",
]

#: the outcome columns of a simulated table, in order
STATE_COLUMNS = ("status", "state", "reason")
_STATES = {o.value: o for o in Outcome}


def status_columns(statuses) -> dict[str, list]:
    """``{"status": text, "state": outcome, "reason": text}`` columns of :class:`Status`
    objects, one entry per row."""
    statuses = list(statuses)
    return {
        "status": [str(s) for s in statuses],
        "state": [s.outcome.value for s in statuses],
        "reason": ["; ".join(s.reasons) for s in statuses],
    }


def with_state(frame: pd.DataFrame) -> pd.DataFrame:
    """``frame`` with typed ``state`` and ``reason`` columns: as they are, or derived once from
    the ``status`` text of a table an older version wrote (a frame without either is
    returned as is)."""
    if "state" in frame.columns and "reason" in frame.columns:
        return frame
    if "status" not in frame.columns:
        return frame
    cols = status_columns(Status.parse(s) for s in frame["status"])
    out = frame.copy()
    out["state"] = cols["state"]
    out["reason"] = cols["reason"]
    return out


def row_statuses(frame: pd.DataFrame) -> list[Status]:
    """The :class:`Status` of each row, from the typed columns."""
    frame = with_state(frame)
    out = []
    for state, reason in zip(frame["state"], frame["reason"], strict=True):
        outcome = _STATES.get(str(state))
        if outcome is None:
            raise ValueError(f"state {state!r} is not one of {', '.join(_STATES)}")
        converged = outcome is Outcome.CONVERGED
        out.append(Status() if converged else Status(outcome, (str(reason),)))
    return out


def _state(frame: pd.DataFrame) -> np.ndarray:
    return with_state(frame)["state"].astype(str).to_numpy()


def failed_rows(frame: pd.DataFrame) -> np.ndarray:
    """(n,) bool: the failed rows (no outputs)."""
    return _state(frame) == Outcome.FAILED.value


def converged_rows(frame: pd.DataFrame) -> np.ndarray:
    """(n,) bool: the converged rows."""
    return _state(frame) == Outcome.CONVERGED.value


def stale_rows(frame: pd.DataFrame, retry_failed: bool = False) -> np.ndarray:
    """(n,) bool: the stored rows a resume simulates again: failures that were not the
    design's own (an environment fault an older version stored as a row), and with
    ``retry_failed`` every failed row."""
    frame = with_state(frame)
    failed = failed_rows(frame)
    if retry_failed:
        return failed
    return failed & np.array([stored_fault(r) for r in frame["reason"]], bool)
