"""A design rule as one small typed record: its conditions, its scores, its JSON form, and the
one way it is applied to a table.

A :class:`Rule` is a box: one :class:`Condition` per constrained feature, either an interval
``gt < x <= le`` (SI values, scikit-learn's sides; ``None`` for an open side) or a set of
categorical ``levels``. It is applied in float64 to the table's own values
(:meth:`Rule.mask`), by the miner, the verifier and the design loop alike. Its JSON form
(:meth:`Rule.to_json`, :meth:`Rule.from_json`) carries the SI bounds, which are what is applied,
and a display form (values in each column's display unit, and the rule as text:
``tcrease <= 0.779 mm and m in {16, 24}``). Every check of a rule's shape is in
:meth:`Condition.__post_init__`, so a rule from the miner, a file or a mapping is validated once
and the same way.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from holofold.design.rules.text import condition_text, level_value

__all__ = ["Condition", "Score", "Estimate", "Rule", "RuleError"]


class RuleError(ValueError):
    """A rule of the wrong shape (the message names the feature and what was expected)."""


def _real(v) -> bool:
    return isinstance(v, int | float | np.integer | np.floating) and not isinstance(v, bool)


@dataclass(frozen=True)
class Condition:
    """One feature's condition: ``gt < x <= le`` (SI, None for an open side) or ``x in levels``.

    Attributes
    ----------
    feature : str
    gt, le : float or None
        The interval's open lower and closed upper end; at least one is a finite number and
        ``gt < le``. Unused (None) for a set of levels.
    levels : tuple of float or None
        Allowed values of a categorical feature (non-empty, finite, sorted, distinct).
    """

    feature: str
    gt: float | None = None
    le: float | None = None
    levels: tuple[float, ...] | None = None

    def __post_init__(self):
        where = f"condition on {self.feature!r}"
        if not isinstance(self.feature, str) or not self.feature:
            raise RuleError(f"a condition needs a feature name, got {self.feature!r}")
        if self.levels is not None:
            if self.gt is not None or self.le is not None:
                raise RuleError(f"{where}: give levels or an interval, not both")
            lv = self.levels
            if isinstance(lv, str | bytes) or not isinstance(lv, Sequence | np.ndarray):
                raise RuleError(f"{where}: levels must be a list of numbers, got {lv!r:.60}")
            if not len(lv) or not all(_real(v) and math.isfinite(v) for v in lv):
                raise RuleError(f"{where}: levels must be a non-empty list of finite numbers")
            object.__setattr__(self, "levels", tuple(sorted({float(v) for v in lv})))
            return
        ends = {}
        for side in ("gt", "le"):
            v = getattr(self, side)
            if v is not None and (not _real(v) or math.isnan(v)):
                raise RuleError(f"{where}: {side!r} = {v!r:.60} must be a number or null")
            v = None if v is None or math.isinf(v) and (v < 0) == (side == "gt") else v
            if v is not None and math.isinf(v):
                raise RuleError(f"{where}: {side!r} = {v} leaves no value inside")
            ends[side] = None if v is None else float(v)
            object.__setattr__(self, side, ends[side])
        if ends["gt"] is None and ends["le"] is None:
            raise RuleError(f"{where}: an interval needs 'gt' or 'le' (or give 'in' levels)")
        if ends["gt"] is not None and ends["le"] is not None and not ends["gt"] < ends["le"]:
            raise RuleError(f"{where}: empty interval ({ends['gt']}, {ends['le']}]")

    @property
    def categorical(self) -> bool:
        return self.levels is not None

    def mask(self, values) -> np.ndarray:
        """(n,) bool: which of ``values`` (SI, as float64) meet the condition."""
        x = np.asarray(values, dtype=np.float64)
        if self.levels is not None:
            return np.isin(x, np.asarray(self.levels, dtype=np.float64))
        inside = np.ones(x.shape, dtype=bool)
        if self.gt is not None:
            inside &= x > self.gt
        if self.le is not None:
            inside &= x <= self.le
        return inside

    def text(self, column=None, digits: int = 3) -> str:
        """``tcrease <= 0.779 mm``, ``0.5 < W <= 2 mm``, ``m in {16, 24}`` (``column``: the
        feature's :class:`~holofold.design.scenarios.Column`, for its display unit)."""
        return condition_text(self.feature, self.gt, self.le, self.levels, column, digits)

    def to_json(self) -> dict:
        """``{"gt": .., "le": ..}`` (null for an open side) or ``{"in": [levels]}``, SI."""
        if self.levels is not None:
            return {"in": [level_value(v) for v in self.levels]}
        return {"gt": self.gt, "le": self.le}

    def display_json(self, column) -> dict:
        """The bounds in ``column``'s display unit: ``{"gt": .., "le": .., "unit": "mm"}``."""
        if self.levels is not None:
            return self.to_json()
        f = column.display_factor
        return {
            "gt": None if self.gt is None else self.gt * f,
            "le": None if self.le is None else self.le * f,
            "unit": column.display_unit,
        }

    @classmethod
    def from_json(cls, feature: str, data) -> Condition:
        """The condition of a JSON bound (:meth:`to_json`'s form); :class:`RuleError` if it
        has another shape."""
        shape = '{"gt": number or null, "le": number or null} or {"in": [numbers]}'
        if not isinstance(data, Mapping) or not data or set(data) - {"gt", "le", "in"}:
            raise RuleError(f"bounds of {feature!r} = {data!r:.60} must be {shape}")
        if "in" in data:
            if set(data) != {"in"}:
                raise RuleError(f"bounds of {feature!r}: give 'in' or 'gt'/'le', not both")
            return cls(feature, levels=data["in"])
        return cls(feature, gt=data.get("gt"), le=data.get("le"))


@dataclass(frozen=True)
class Score:
    """Precision, recall and support of a rule on some rows (training or held-out)."""

    precision: float
    recall: float
    support: int

    def to_json(self) -> dict:
        return {"precision": _num(self.precision), "recall": _num(self.recall),
                "support": int(self.support)}  # fmt: skip


@dataclass(frozen=True)
class Estimate:
    """The precision a rule is expected to have on new designs, with its 95 % interval and
    the rows behind it (out of bag for the trees that found it, plus held-out rows)."""

    precision: float
    low: float
    high: float
    rows: int
    out_of_bag_rows: int
    held_out_rows: int = 0

    def to_json(self) -> dict:
        return {
            "precision": _num(self.precision),
            "interval": [_num(self.low), _num(self.high)],
            "rows": int(self.rows),
            "out_of_bag_rows": int(self.out_of_bag_rows),
            "held_out_rows": int(self.held_out_rows),
        }


def _num(v):
    return None if v is None or not math.isfinite(float(v)) else float(v)


@dataclass(frozen=True)
class Rule:
    """A design rule: a box of conditions, best-first ``rank`` and its scores.

    Attributes
    ----------
    conditions : tuple of Condition
        One per constrained feature (a feature at most once); empty: every design.
    rank : int
        1 for the best rule of a list.
    estimate : Estimate, optional
    train, test : Score, optional
        On the training and held-out rows; ``oob_precision`` is the pooled out-of-bag
        precision of the trees that found the rule.
    """

    conditions: tuple[Condition, ...] = ()
    rank: int = 1
    estimate: Estimate | None = None
    train: Score | None = None
    test: Score | None = None
    oob_precision: float | None = None

    def __post_init__(self):
        conds = tuple(self.conditions)
        if not all(isinstance(c, Condition) for c in conds):
            raise RuleError("a rule's conditions must be Condition records")
        names = [c.feature for c in conds]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise RuleError(f"a rule constrains {dup[0]!r} twice")
        object.__setattr__(self, "conditions", conds)
        if isinstance(self.rank, bool) or not isinstance(self.rank, int | np.integer):
            raise RuleError(f"a rule's rank must be an integer, got {self.rank!r}")
        object.__setattr__(self, "rank", int(self.rank))

    @property
    def features(self) -> tuple[str, ...]:
        """The constrained features, in the rule's order."""
        return tuple(c.feature for c in self.conditions)

    def condition(self, feature: str) -> Condition | None:
        return next((c for c in self.conditions if c.feature == feature), None)

    def with_rank(self, rank: int) -> Rule:
        return replace(self, rank=rank)

    def mask(self, table: pd.DataFrame) -> np.ndarray:
        """(n,) bool: the rows of ``table`` inside the rule (float64, ``gt < x <= le``).

        Raises :class:`RuleError` when the table lacks a constrained feature.
        """
        inside = np.ones(len(table), dtype=bool)
        for c in self.conditions:
            if c.feature not in table.columns:
                raise RuleError(
                    f"the rule constrains {c.feature!r}, which is not a column of the table"
                )
            inside &= c.mask(table[c.feature].to_numpy(dtype=np.float64))
        return inside

    def text(self, columns: Mapping | None = None, digits: int = 3) -> str:
        """The rule as text in display units: ``tcrease <= 0.779 mm and m in {16, 24}``
        (``columns``: name -> Column; features without one are bare SI numbers)."""
        cols = columns or {}
        parts = [c.text(cols.get(c.feature), digits) for c in self.conditions]
        return " and ".join(parts) if parts else "(any design)"

    def to_json(self, columns: Mapping | None = None) -> dict:
        """The JSON form: ``rank``, ``rule`` (text in display units), ``bounds`` (SI, what is
        applied), ``display`` (the bounds in display units, for the features with a column),
        and ``estimate``, ``train``, ``test`` when known."""
        cols = columns or {}
        out = {
            "rank": self.rank,
            "rule": self.text(cols),
            "bounds": {c.feature: c.to_json() for c in self.conditions},
            "display": {
                c.feature: c.display_json(cols[c.feature])
                for c in self.conditions
                if c.feature in cols
            },
        }
        if self.estimate is not None:
            out["estimate"] = self.estimate.to_json()
        if self.train is not None:
            out["train"] = self.train.to_json()
            if self.oob_precision is not None:
                out["train"]["oob_precision"] = _num(self.oob_precision)
        if self.test is not None:
            out["test"] = self.test.to_json()
        return out

    @classmethod
    def from_json(cls, data, rank: int = 1) -> Rule:
        """A rule from its JSON form (:meth:`to_json`; only ``bounds`` is required, SI).

        Raises
        ------
        RuleError
            A record of another shape; the message names the feature and what was expected.
        """
        if not isinstance(data, Mapping) or not isinstance(data.get("bounds"), Mapping):
            raise RuleError("a rule record needs a 'bounds' object")
        conds = tuple(Condition.from_json(str(k), v) for k, v in data["bounds"].items())
        r = data.get("rank", rank)
        return cls(
            conds,
            rank=r if isinstance(r, int) and not isinstance(r, bool) else rank,
            estimate=_estimate(data.get("estimate")),
            train=_score(data.get("train")),
            test=_score(data.get("test")),
            oob_precision=_opt((data.get("train") or {}).get("oob_precision")
                               if isinstance(data.get("train"), Mapping) else None),
        )  # fmt: skip

    @classmethod
    def from_bounds(cls, bounds: Mapping, rank: int = 1) -> Rule:
        """A rule from a mapping feature -> JSON bound (``{"gt": .., "le": ..}`` or
        ``{"in": [..]}``)."""
        if not isinstance(bounds, Mapping):
            raise RuleError(f"a rule's bounds must be a mapping feature -> bound, got "
                            f"{bounds!r:.60}")  # fmt: skip
        return cls.from_json({"bounds": bounds}, rank=rank)


def _opt(v):
    return float(v) if _real(v) and math.isfinite(v) else None


def _score(d) -> Score | None:
    if not isinstance(d, Mapping) or _opt(d.get("precision")) is None:
        return None
    rec = _opt(d.get("recall"))
    sup = d.get("support")
    return Score(_opt(d["precision"]), float("nan") if rec is None else rec,
                 int(sup) if _real(sup) and math.isfinite(sup) else 0)  # fmt: skip


def _estimate(d) -> Estimate | None:
    if not isinstance(d, Mapping) or _opt(d.get("precision")) is None:
        return None
    ci = d.get("interval")
    lo, hi = ci if isinstance(ci, list) and len(ci) == 2 else (None, None)
    ints = [d.get(k) for k in ("rows", "out_of_bag_rows", "held_out_rows")]
    ints = [int(v) if _real(v) and math.isfinite(v) else 0 for v in ints]
    return Estimate(
        _opt(d["precision"]),
        float("nan") if _opt(lo) is None else _opt(lo),
        float("nan") if _opt(hi) is None else _opt(hi),
        *ints,
    )
