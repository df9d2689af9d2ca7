"""Test-only fault points: a run kills itself at a chosen event, so that kill/resume tests
interrupt it where they mean to on any machine, fast or slow.

Set ``HOLOFOLD_TEST_FAULT="kill:<event>:<n>"`` in a run's environment (tests only; never set
it for real work). At the ``n``-th (1-based) ``event`` of the process the run sends SIGKILL
to its own process group (the command and its worker processes, as ``kill -9`` on the group)
when the process leads its own session (started with ``start_new_session=True`` or
``setsid``), else to itself only. Events:

``write``
    inside an atomic file write (:func:`~holofold.geometry.outputs.atomic_write`), after the
    temporary file is written and before it is renamed into place;
``written``
    just after an atomic write renamed its file into place;
``row``
    in the parent of a run, when the ``n``-th simulated row's result has arrived and before
    it is stored (``holofold.design.database.runner.iter_results``).

Unset (always outside tests) the variable costs one lookup at import and a ``None`` check
per event.
"""

from __future__ import annotations

import os
import signal

__all__ = ["fault_point", "EVENTS"]

EVENTS = ("write", "written", "row")


def _plan(text: str | None) -> tuple[str, int] | None:
    if not text:
        return None
    parts = text.split(":")
    if len(parts) != 3 or parts[0] != "kill" or parts[1] not in EVENTS or not parts[2].isdigit():
        raise ValueError(
            f"HOLOFOLD_TEST_FAULT = {text!r}: expected 'kill:<event>:<n>' with event one of "
            f"{', '.join(EVENTS)} (a test-only setting)"
        )
    return parts[1], int(parts[2])


_PLAN = _plan(os.environ.get("HOLOFOLD_TEST_FAULT"))
_seen = 0


def fault_point(event: str) -> None:
    """Count ``event``; kill the run if it is the planned one (no-op unless the variable is
    set)."""
    global _seen
    if _PLAN is None or _PLAN[0] != event:
        return
    _seen += 1
    if _seen == _PLAN[1]:
        if hasattr(os, "killpg") and os.getpgid(0) == os.getsid(0):
            os.killpg(os.getpgid(0), signal.SIGKILL)
        os.kill(os.getpid(), getattr(signal, "SIGKILL", signal.SIGTERM))
