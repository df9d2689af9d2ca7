"""The designer's objective: which of the designs meeting a target is the best one.

``holofold design --objective "min mass"`` picks, among the designs that meet the target, the
lightest; ``"max Zstiff"`` the stiffest; the default ``"margin"`` the one with the largest
worst-case margin to the target's thresholds (:meth:`~holofold.design.rules.targets.Target.margin`).
Any performance or feature column can be minimised or maximised.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
import pandas as pd

__all__ = ["Objective", "parse_objective", "MARGIN"]

_SENSES = ("min", "max")


@dataclass(frozen=True)
class Objective:
    """What makes one design better than another.

    Attributes
    ----------
    sense : {"margin", "min", "max"}
        ``margin``: the largest worst-case margin to the target; ``min``/``max``: the smallest
        or largest value of ``column``.
    column : str or None
        The column minimised or maximised (None for ``margin``).
    """

    sense: str
    column: str | None = None

    def __post_init__(self):
        if self.sense == "margin":
            if self.column is not None:
                raise ValueError("the margin objective takes no column")
        elif self.sense not in _SENSES or not self.column:
            raise ValueError(
                f"objective {self.sense!r} {self.column!r}: expected 'min COLUMN', "
                "'max COLUMN' or 'margin'"
            )

    def __str__(self) -> str:
        return "margin" if self.sense == "margin" else f"{self.sense} {self.column}"

    @property
    def words(self) -> str:
        """How the choice reads in a sentence ("the smallest mass")."""
        if self.sense == "margin":
            return "the largest worst-case margin to the target"
        return f"the {'smallest' if self.sense == 'min' else 'largest'} {self.column}"

    def score(self, table: pd.DataFrame, target) -> np.ndarray:
        """(n,) float, larger is better; NaN where the row has no value (never chosen)."""
        if self.sense == "margin":
            return np.asarray(target.margin(table), dtype=float)
        v = table[self.column].to_numpy(dtype=float)
        return -v if self.sense == "min" else v

    def value(self, row, target) -> float:
        """The objective's own number for one row (a mass, a stiffness, or the margin)."""
        if self.sense == "margin":
            return float(target.margin(pd.DataFrame([dict(row)]))[0])
        return float(row[self.column])

    def best(self, table: pd.DataFrame, target) -> object | None:
        """Index label of the best row of ``table`` (None if no row has a finite score; ties:
        the first in table order)."""
        if not len(table):
            return None
        s = self.score(table, target)
        s = np.where(np.isnan(s), -np.inf, s)
        if not np.isfinite(s).any() and not (s == np.inf).any():
            return None
        return table.index[int(np.argmax(s))]


MARGIN = Objective("margin")


def parse_objective(text: str | Objective | None, columns: Iterable[str]) -> Objective:
    """``"margin"`` (or None), ``"min COLUMN"`` or ``"max COLUMN"``; one line naming the
    problem otherwise (the allowed columns listed)."""
    if isinstance(text, Objective):
        obj = text
    elif text is None or str(text).strip().lower() == "margin":
        return MARGIN
    else:
        words = str(text).split()
        if len(words) != 2 or words[0].lower() not in _SENSES:
            raise ValueError(
                f"objective {text!r}: expected 'min COLUMN', 'max COLUMN' or "
                "'margin' (e.g. 'min mass')"
            )
        obj = Objective(words[0].lower(), words[1])
    allowed = list(columns)
    if obj.column is not None and obj.column not in allowed:
        raise ValueError(
            f"objective {str(obj)!r}: unknown column {obj.column!r}; available: "
            + ", ".join(allowed)
        )
    return obj
