"""Which exceptions are a design's own failure and which are the environment's.

A row whose simulation raises is either the design's own failure (a singular model, a solve
that does not converge, an invalid or self-overlapping design, a timeout): a failed row, stored
with its reason; or an environment fault (a missing or broken module, a shared library that
fails to load, out of memory, a compile failure): the run stops with one line naming the cause
and the fix, before more rows are spent, and the fault is never stored as a row
(:class:`~holofold.geometry.errors.EnvironmentFault`).

:func:`as_environment_fault` tells the two apart for a live exception; :func:`stored_fault`
recognises the text older holofold versions stored for such rows (``failed:
ModuleNotFoundError: ...``), so that a resume simulates them again.
"""

from __future__ import annotations

import re

from holofold.geometry.errors import EnvironmentFault

__all__ = ["as_environment_fault", "stored_fault", "ENVIRONMENT_NAMES"]

#: exception names that are the environment's, as stored in status text by older versions
ENVIRONMENT_NAMES = (
    "EnvironmentFault",
    "ImportError",
    "ModuleNotFoundError",
    "MemoryError",
    "OSError",
    "TypingError",
    "LoweringError",
    "NumbaError",
    "UnsupportedError",
)
_NAMES = "|".join(ENVIRONMENT_NAMES)
_STORED = re.compile(rf"^(?:failed:\s*)?(?:[A-Za-z_][\w.]*\.)?({_NAMES})\b")


def _is_compile_failure(exc: BaseException) -> bool:
    """An exception of numba or llvmlite (without importing either)."""
    return any(
        (getattr(t, "__module__", "") or "").split(".")[0] in ("numba", "llvmlite")
        for t in type(exc).__mro__
    )


def as_environment_fault(exc: BaseException, where: str = "") -> EnvironmentFault | None:
    """The :class:`EnvironmentFault` that ``exc`` is (one line: cause and fix), or None when
    it is the design's own failure.

    ``where`` names what was running (``"row 3 of arch"``) for the message.
    """
    at = f" while simulating {where}" if where else ""
    first = (str(exc).strip().splitlines() or [""])[0][:300]
    resume = "; then run the same command again to resume"
    if isinstance(exc, EnvironmentFault):
        return exc
    if isinstance(exc, ImportError):
        name = getattr(exc, "name", None) or "a module"
        return EnvironmentFault(
            f"environment fault{at}: {type(exc).__name__}: {first}; install or repair "
            f"{name} (pip install {name}, or reinstall holofold){resume}"
        )
    if isinstance(exc, MemoryError):
        return EnvironmentFault(
            f"environment fault{at}: out of memory (MemoryError); use fewer --workers, a "
            f"smaller design or a machine with more memory{resume}"
        )
    if isinstance(exc, OSError):
        return EnvironmentFault(
            f"environment fault{at}: {type(exc).__name__}: {first}; a shared library or file "
            f"of the installation cannot be used: reinstall the package that ships it{resume}"
        )
    if _is_compile_failure(exc):
        return EnvironmentFault(
            f"environment fault{at}: the compiled kernels failed ({type(exc).__name__}: "
            f"{first}); reinstall numba and llvmlite matching numpy{resume}"
        )
    return None


def stored_fault(reason: str) -> bool:
    """Whether a stored failure reason is an environment fault recorded by an older version
    (``ModuleNotFoundError: No module named 'numba'``): not the design's own, so a resume
    simulates the row again."""
    return bool(_STORED.match(str(reason).strip()))
