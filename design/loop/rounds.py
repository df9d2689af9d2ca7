"""Typed records of the design loop's rounds: each mined rule with its verification.

A :class:`VerifiedRule` is one mined rule (a :class:`~holofold.design.rules.Rule`: its box and
what the miner said of it, estimate, training and held-out precision) with the round it was
mined in and what its fresh simulations said (verified precision, 95 % Wilson interval). A
:class:`Round` is one pass of mining and verifying, with the number of designs mined from. Both
are frozen, validated once in ``__post_init__``, and go to and from ``design.json`` by
``to_json``/``from_json``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

from holofold.design.rules.record import Rule

__all__ = ["Counts", "VerifiedRule", "Round", "RULE_QUALIFIES", "RULE_BAR", "wilson"]

#: a rule is an answer when at least this share of its fresh designs met the target
RULE_QUALIFIES = 0.5
#: the loop's bar for a verified rule: this share of its fresh designs met the target, and the
#: lower end of their 95 % Wilson interval at least the second number
RULE_BAR = (0.9, 0.8)


def wilson(k: int, n: int, z: float = 1.959964) -> tuple[float, float]:
    """95 % Wilson interval of k successes in n trials (exact ends at 0 and n; NaN for n = 0)."""
    if not n:
        return (math.nan, math.nan)
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    lo = 0.0 if k == 0 else max(0.0, centre - half)
    hi = 1.0 if k == n else min(1.0, centre + half)
    return (lo, hi)


def _count(d: Mapping, key: str, where: str) -> int:
    v = d.get(key, 0)
    if isinstance(v, bool) or not isinstance(v, int) or v < 0:
        raise ValueError(f"{where}: {key} = {v!r} must be a whole number >= 0")
    return v


@dataclass(frozen=True)
class Counts:
    """Fresh designs simulated inside a rule: successful, failed, and meeting the target.

    The precision is the fraction of *all* of them that meet the target: a design whose
    simulation failed (a self-overlapping strip, a gripper that never closes, a row past its
    time limit) is a design a user of the rule could pick that does not meet it.
    """

    simulated: int
    failed: int
    meeting: int

    def __post_init__(self):
        for k in ("simulated", "failed", "meeting"):
            v = getattr(self, k)
            if isinstance(v, bool) or not isinstance(v, int) or v < 0:
                raise ValueError(f"verification {k} = {v!r} must be a whole number >= 0")
        if self.meeting > self.simulated:
            raise ValueError(f"{self.meeting} designs meeting the target of {self.simulated}")

    @property
    def tried(self) -> int:
        """Every fresh design: simulated successfully or failed."""
        return self.simulated + self.failed

    @property
    def precision(self) -> float | None:
        return self.meeting / self.tried if self.tried else None

    @property
    def interval(self) -> tuple[float, float] | None:
        return wilson(self.meeting, self.tried) if self.tried else None


@dataclass(frozen=True)
class VerifiedRule:
    """One mined rule of one round and its verification.

    Attributes
    ----------
    round : int
        The round it was mined in (0-based).
    rule : Rule
        The rule (:class:`~holofold.design.rules.Rule`: its box, rank, estimate, training and
        held-out scores).
    verified : Counts or None
        Fresh designs simulated inside the rule (None: not verified).
    text : str
        The rule in display units (``tcrease <= 0.779 mm and m in {16, 24}``).
    display : mapping
        Its bounds in display units (:meth:`Rule.to_json`'s ``display``).
    """

    round: int
    rule: Rule
    verified: Counts | None = None
    text: str = ""
    display: Mapping = field(default_factory=dict)

    def __post_init__(self):
        if isinstance(self.round, bool) or not isinstance(self.round, int) or self.round < 0:
            raise ValueError(f"a rule's round = {self.round!r} must be a whole number >= 0")
        if not isinstance(self.rule, Rule):
            raise ValueError(f"expected a Rule, got {type(self.rule).__name__}")
        if self.verified is not None and not isinstance(self.verified, Counts):
            raise ValueError("a rule's verification must be Counts")
        if not self.text:
            object.__setattr__(self, "text", self.rule.text())

    @classmethod
    def of(cls, rule: Rule, round_: int, verified: Counts | None, columns=None) -> VerifiedRule:
        """With its text and bounds in the display units of ``columns`` (name -> Column)."""
        rec = rule.to_json(columns)
        return cls(int(round_), rule, verified, rec["rule"], rec["display"])

    @property
    def rank(self) -> int:
        return self.rule.rank

    @property
    def bounds(self) -> dict:
        """Feature -> SI bound (``{"gt": .., "le": ..}`` or ``{"in": [..]}``)."""
        return {c.feature: c.to_json() for c in self.rule.conditions}

    @property
    def train_precision(self) -> float | None:
        return None if self.rule.train is None else self.rule.train.precision

    @property
    def test_precision(self) -> float | None:
        return None if self.rule.test is None else self.rule.test.precision

    @property
    def estimate(self) -> float | None:
        """The miner's expected precision on new designs (None: not estimated)."""
        return None if self.rule.estimate is None else self.rule.estimate.precision

    @property
    def label(self) -> str:
        """``rule 2 of round 1`` (rounds and ranks as the report numbers them)."""
        return f"rule {self.rank} of round {self.round}"

    @property
    def precision(self) -> float | None:
        """Verified precision (None: not verified or nothing simulated)."""
        return None if self.verified is None else self.verified.precision

    @property
    def interval(self) -> tuple[float, float] | None:
        return None if self.verified is None else self.verified.interval

    @property
    def qualifies(self) -> bool:
        """Verified at :data:`RULE_QUALIFIES` or more."""
        p = self.precision
        return p is not None and p >= RULE_QUALIFIES

    @property
    def meets_bar(self) -> bool:
        """Verified at the loop's bar (:data:`RULE_BAR`): the rule the loop stops on."""
        p, ci = self.precision, self.interval
        return p is not None and p >= RULE_BAR[0] and ci[0] >= RULE_BAR[1]

    def sort_key(self) -> tuple:
        """Best first when sorted descending: verified precision, its lower bound, held-out."""
        p = -1.0 if self.precision is None else self.precision
        lo = -1.0 if self.interval is None else self.interval[0]
        return (p, lo, self.test_precision or 0.0, -self.round, -self.rank)

    def to_json(self) -> dict:
        """The rule's record (:meth:`Rule.to_json`: rank, text, SI bounds, display bounds,
        estimate, train, test) with its round and verification."""
        rec = self.rule.to_json()
        rec["rule"], rec["display"] = self.text, dict(self.display)
        v, lo_hi = self.verified, self.interval
        return {
            "round": self.round,
            **rec,
            "verified_precision": self.precision,
            "verified_95ci": list(lo_hi) if lo_hi else None,
            "verified_n": None if v is None else v.simulated,
            "verified_failed": None if v is None else v.failed,
            "verified_meeting": None if v is None else v.meeting,
        }

    @classmethod
    def from_json(cls, d: Mapping) -> VerifiedRule:
        if not isinstance(d, Mapping):
            raise ValueError(f"a rule must be an object, got {type(d).__name__}")
        where = f"rule {d.get('rank')!r} of round {d.get('round')!r}"
        for k in ("round", "rank", "bounds"):
            if k not in d:
                raise ValueError(f"{where}: missing {k!r}")
        ver = None
        if d.get("verified_n") is not None:
            ver = Counts(
                _count(d, "verified_n", where),
                _count(d, "verified_failed", where),
                _count(d, "verified_meeting", where),
            )
        rule = Rule.from_json(d)
        display = d.get("display") if isinstance(d.get("display"), Mapping) else {}
        return cls(_count(d, "round", where), rule, ver, str(d.get("rule") or ""), display)


@dataclass(frozen=True)
class Round:
    """One round of the loop: mining from ``rows`` designs (``failed`` left out), its rules.

    ``note`` says what happened when no rule was found (the next round then samples around
    the designs meeting the target).
    """

    index: int
    rows: int
    failed: int
    meeting: int
    rules: tuple[VerifiedRule, ...] = ()
    note: str = ""

    def __post_init__(self):
        for k in ("index", "rows", "failed", "meeting"):
            v = getattr(self, k)
            if isinstance(v, bool) or not isinstance(v, int) or v < 0:
                raise ValueError(f"round {k} = {v!r} must be a whole number >= 0")
        if any(r.round != self.index for r in self.rules):
            raise ValueError(f"round {self.index} holds a rule of another round")

    @property
    def best(self) -> VerifiedRule | None:
        """Its best verified rule (None without rules)."""
        return max(self.rules, key=VerifiedRule.sort_key) if self.rules else None

    def to_json(self) -> dict:
        best = self.best
        return {
            "round": self.index,
            "rows": self.rows,
            "failed": self.failed,
            "meeting": self.meeting,
            "rules": [r.to_json() for r in self.rules],
            "best": None if best is None else best.rank,
            "note": self.note,
        }

    @classmethod
    def from_json(cls, d: Mapping) -> Round:
        if not isinstance(d, Mapping) or "round" not in d:
            raise ValueError("a round must be an object with 'round'")
        where = f"round {d.get('round')!r}"
        rules = d.get("rules") or []
        if not isinstance(rules, list):
            raise ValueError(f"{where}: rules must be a list")
        return cls(
            index=_count(d, "round", where),
            rows=_count(d, "rows", where),
            failed=_count(d, "failed", where),
            meeting=_count(d, "meeting", where),
            rules=tuple(VerifiedRule.from_json(r) for r in rules),
            note=str(d.get("note") or ""),
        )
