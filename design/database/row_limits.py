"""Per-row isolation: a time limit per simulated row and what to do with invalid rows.

:func:`call_with_limit` runs one row's simulation with a time limit in whatever thread it is
called from (the main thread, a joblib/loky worker process, a Dask worker thread): a watchdog
timer raises :class:`RowTimeout` in that thread when the limit passes (CPython's
``PyThreadState_SetAsyncExc``, the mechanism behind ``KeyboardInterrupt`` in threads). The
exception arrives at the next Python bytecode the thread runs, so it interrupts a solver
between two iterations or two compiled calls; one compiled call (a numba kernel, a LAPACK
solve) is not cut short, it runs to its end first. A row that returns after its deadline
(the watchdog had no chance to interrupt it: one long compiled call, or the interpreter's
thread switch interval of 5 ms) is a timeout too, so whether a row times out depends only on
how long it ran. Nothing is checked inside the solvers, so a row that finishes within its
limit gives bit for bit the results it gives without one.
"""

from __future__ import annotations

import ctypes
import heapq
import itertools
import math
import os
import threading
import time

__all__ = [
    "RowTimeout",
    "ON_INVALID",
    "call_with_limit",
    "check_on_invalid",
    "resolve_row_timeout",
    "timeout_reason",
]

#: what the runner does with invalid rows: ``fail`` refuses the table (nothing simulated),
#: ``skip`` records them as failed rows with their reason and simulates the others
ON_INVALID = ("fail", "skip")


class RowTimeout(BaseException):
    """A row ran past its time limit (a BaseException: ``except Exception`` in a scenario's
    code does not swallow it)."""


def check_on_invalid(on_invalid) -> str:
    """``on_invalid`` checked: ``"fail"`` or ``"skip"`` (else ``ValueError``)."""
    if on_invalid not in ON_INVALID:
        raise ValueError(f"on_invalid = {on_invalid!r} must be 'fail' or 'skip'")
    return on_invalid


def resolve_row_timeout(default: float | None, row_timeout=None) -> float | None:
    """The time limit in seconds per row, or None for no limit.

    ``row_timeout`` None takes ``default`` (the scenario's ``row_timeout``); 0, ``inf`` or
    ``"none"`` mean no limit; anything else must be a number > 0.
    """
    value = default if row_timeout is None else row_timeout
    if value is None:
        return None
    if isinstance(value, str) and value.strip().lower() in ("none", "inf", "off"):
        return None
    try:
        t = float(value)
    except (TypeError, ValueError):
        t = math.nan
    if isinstance(value, bool) or math.isnan(t) or t < 0:
        raise ValueError(f"row_timeout = {value!r} must be seconds > 0, or 0 / 'none' for no limit")
    return None if t == 0 or math.isinf(t) else t


def timeout_reason(limit: float) -> str:
    """The status reason of a row stopped at ``limit`` seconds: ``timeout after ... s``."""
    return f"timeout after {limit:g} s (row_timeout)"


def _raise_in(thread_id: int, exc_type) -> None:
    """Make ``exc_type`` arrive in thread ``thread_id`` (None: cancel one not yet arrived)."""
    arg = None if exc_type is None else ctypes.py_object(exc_type)
    ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(thread_id), arg)


class _Watchdog:
    """One daemon thread per process raising :class:`RowTimeout` in threads past their
    deadline (starting a timer thread per row would cost ~0.4 ms, 3 % of a single-Miura row)."""

    def __init__(self):
        self._cond = threading.Condition()
        self._heap: list = []  # (deadline, token, thread id)
        self._live: set = set()  # tokens armed and not yet disarmed or fired
        self._fired: set = set()
        self._count = itertools.count()
        self._pid = None

    def arm(self, seconds: float) -> int:
        with self._cond:
            if self._pid != os.getpid():  # first use, or a forked child: no thread yet
                self._pid = os.getpid()
                self._heap, self._live, self._fired = [], set(), set()
                threading.Thread(target=self._run, name="holofold-row-timeout", daemon=True).start()
            token = next(self._count)
            heapq.heappush(self._heap, (time.monotonic() + seconds, token, threading.get_ident()))
            self._live.add(token)
            self._cond.notify()
            return token

    def disarm(self, token: int) -> bool:
        """Stop watching ``token``; True if its exception was raised (and withdrawn if it
        had not arrived yet)."""
        with self._cond:
            self._live.discard(token)
            fired = token in self._fired
            self._fired.discard(token)
            if fired:
                _raise_in(threading.get_ident(), None)
            return fired

    def _run(self):
        with self._cond:
            while True:
                while self._heap and self._heap[0][1] not in self._live:
                    heapq.heappop(self._heap)  # disarmed
                if not self._heap:
                    self._cond.wait()
                    continue
                deadline, token, thread = self._heap[0]
                wait = deadline - time.monotonic()
                if wait > 0:
                    self._cond.wait(wait)
                    continue
                heapq.heappop(self._heap)
                self._live.discard(token)
                self._fired.add(token)
                _raise_in(thread, RowTimeout)


_WATCHDOG = _Watchdog()


def call_with_limit(seconds: float | None, fn, *args):
    """``fn(*args)``, raising :class:`RowTimeout` if it runs longer than ``seconds``.

    ``seconds`` None: no limit (``fn`` is called as is). The watch ends when ``fn`` returns
    or raises, and a :class:`RowTimeout` raised for it that has not yet arrived is withdrawn,
    so nothing arrives after this function has returned. ``fn`` returning after the
    deadline raises :class:`RowTimeout` as well.
    """
    if seconds is None:
        return fn(*args)
    deadline = time.monotonic() + seconds
    token = _WATCHDOG.arm(seconds)
    try:
        out = fn(*args)
    finally:
        _WATCHDOG.disarm(token)
    if time.monotonic() > deadline:
        raise RowTimeout(f"returned after its limit of {seconds:g} s")
    return out
