"""How a computation ended: converged, not converged (with reasons) or failed (with a reason).

One small type shared by the solvers, the scenarios and the design runner. Tables and files keep
it as text, ``str(status)``::

    converged
    not converged: Z case (snap-through): 2 of 5 increments above tol: increment 4 (...)
    failed: RuntimeError: singular tangent

and :meth:`Status.parse` reads such text back. The rule every producer follows: ``converged``
only when every solve met its tolerance and every output is finite; ``not converged`` keeps
outputs that are finite but come from iterates that missed a tolerance (as the reference
simulator does); ``failed`` has no outputs (NaN).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from enum import Enum

import numpy as np

__all__ = [
    "Outcome",
    "Status",
    "CONVERGED",
    "failed_mask",
    "converged_mask",
    "SingularSystemError",
]


class SingularSystemError(RuntimeError):
    """The reduced tangent stiffness could not be factorised or solved (a failed solve; here,
    below the linear algebra, so every solver path raises the one class)."""


class Outcome(Enum):
    """The three ways a computation can end (worst last)."""

    CONVERGED = "converged"
    NOT_CONVERGED = "not converged"
    FAILED = "failed"

    @property
    def rank(self) -> int:
        return _RANK[self]


_RANK = {Outcome.CONVERGED: 0, Outcome.NOT_CONVERGED: 1, Outcome.FAILED: 2}


@dataclass(frozen=True)
class Status:
    """Outcome of a solve, a simulation or a table row, and why.

    Attributes
    ----------
    outcome : Outcome
    reasons : tuple of str
        Empty for a converged computation; otherwise one sentence per problem.
    """

    outcome: Outcome = Outcome.CONVERGED
    reasons: tuple[str, ...] = ()

    def __post_init__(self):
        object.__setattr__(self, "outcome", Outcome(self.outcome))
        object.__setattr__(self, "reasons", tuple(str(r) for r in self.reasons))
        if self.outcome is not Outcome.CONVERGED and not self.reasons:
            raise ValueError(f"a {self.outcome.value!r} status needs a reason")
        if self.outcome is Outcome.CONVERGED and self.reasons:
            raise ValueError("a converged status has no reasons")

    # ------------------------------------------------------------------ constructors
    @classmethod
    def not_converged(cls, *reasons: str) -> Status:
        return cls(Outcome.NOT_CONVERGED, reasons)

    @classmethod
    def failed(cls, *reasons: str) -> Status:
        return cls(Outcome.FAILED, reasons)

    @classmethod
    def from_exception(cls, exc: BaseException) -> Status:
        """``failed: <ExceptionName>: <first line of the message>``."""
        text = str(exc).strip()
        first = text.splitlines()[0] if text else ""
        return cls.failed(f"{type(exc).__name__}: {first}" if first else type(exc).__name__)

    @classmethod
    def parse(cls, text) -> Status:
        """The status written as ``text`` (``str(status)``), or a :class:`Status` as is."""
        if isinstance(text, Status):
            return text
        s = str(text).strip()
        for outcome in (Outcome.NOT_CONVERGED, Outcome.FAILED, Outcome.CONVERGED):
            word = outcome.value
            if s == word:
                if outcome is Outcome.CONVERGED:
                    return CONVERGED
                return cls(outcome, ("no reason recorded",))
            if s.startswith(word + ":"):
                rest = s[len(word) + 1 :].strip()
                if outcome is Outcome.CONVERGED:
                    break
                return cls(outcome, (rest or "no reason recorded",))
        raise ValueError(f"status {s!r} is not 'converged', 'not converged: ...' or 'failed: ...'")

    @classmethod
    def gather(cls, parts: Mapping[str, Status], *, worst: Outcome | None = None) -> Status:
        """One status from labelled parts: converged if every part is, otherwise the worst
        outcome among them (capped at ``worst``) with one ``"label: why"`` reason per part that
        did not converge (a part whose outcome differs from the result's names it:
        ``"label: failed: why"``)."""
        bad = {k: s for k, s in parts.items() if not s.converged}
        if not bad:
            return CONVERGED
        outcome = max((s.outcome for s in bad.values()), key=lambda o: o.rank)
        if worst is not None and outcome.rank > worst.rank:
            outcome = worst
        reasons = tuple(
            f"{label}: " + ("; ".join(s.reasons) if s.outcome is outcome else str(s))
            for label, s in bad.items()
        )
        return cls(outcome, reasons)

    # ------------------------------------------------------------------ queries
    @property
    def converged(self) -> bool:
        return self.outcome is Outcome.CONVERGED

    @property
    def is_failed(self) -> bool:
        return self.outcome is Outcome.FAILED

    def __str__(self) -> str:
        if self.converged:
            return self.outcome.value
        return f"{self.outcome.value}: " + "; ".join(self.reasons)


#: The status of a computation that met every tolerance.
CONVERGED = Status()


def _outcomes(statuses: Iterable) -> list[Outcome]:
    return [Status.parse(s).outcome for s in statuses]


def failed_mask(statuses: Iterable) -> np.ndarray:
    """(n,) bool: which of the statuses (text or :class:`Status`) are failures."""
    return np.array([o is Outcome.FAILED for o in _outcomes(statuses)], bool)


def converged_mask(statuses: Iterable) -> np.ndarray:
    """(n,) bool: which of the statuses (text or :class:`Status`) converged."""
    return np.array([o is Outcome.CONVERGED for o in _outcomes(statuses)], bool)
