"""The design summary: what ``design.json`` holds and ``report.html`` shows, as typed records.

A :class:`DesignSummary` is built by the design loop and read back from ``design.json`` by
:meth:`DesignSummary.from_json`, its one validation: every later reader (the report page, a
script) gets the same checked record. Its parts:

* :class:`Pick`: one design put forward (the chosen one, or an alternative) with its features,
  performance, margins, whether it meets the target and can be built, and why it is there;
* :class:`Timings`: seconds per stage of this invocation and summed over every invocation
  on the folder (a resumed run reports both);
* the rounds (:class:`~holofold.design.loop.rounds.Round`), the pilot's distributions
  (:class:`~holofold.design.report.describe.Distribution`) and the part's fit on the printer's bed
  (:class:`~holofold.design.loop.buildability.PartFit`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

from holofold.design.loop.buildability import PartFit
from holofold.design.loop.rounds import Round, VerifiedRule
from holofold.design.report.describe import Distribution

__all__ = ["Pick", "Timings", "DesignSummary", "STAGES"]

STAGES = ("database", "mine", "verify", "refine", "choose", "files")


def _finite_or_none(v):
    if v is None:
        return None
    if isinstance(v, bool):
        return v
    if isinstance(v, (int, float)):
        return float(v) if math.isfinite(v) else None
    return v


def _numbers(d, where: str) -> dict:
    if not isinstance(d, Mapping):
        raise ValueError(f"{where} must map names to values")
    out = {}
    for k, v in d.items():
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float))):
            raise ValueError(f"{where}: {k} = {v!r:.40} must be a number or null")
        out[str(k)] = None if v is None else float(v)
    return out


def _margins(d, where: str) -> dict:
    """Margins: numbers, with +-inf written as the strings "inf"/"-inf" (== and !=)."""
    if not isinstance(d, Mapping):
        raise ValueError(f"{where} must map conditions to margins")
    out = {}
    for k, v in d.items():
        if v in ("inf", "-inf"):
            v = float(v)
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float))):
            raise ValueError(f"{where}: {k} = {v!r:.40} must be a number")
        out[str(k)] = math.nan if v is None else float(v)
    return out


def _margin_json(v: float):
    if math.isinf(v):
        return "inf" if v > 0 else "-inf"
    return None if math.isnan(v) else v


@dataclass(frozen=True)
class Pick:
    """One design put forward.

    Attributes
    ----------
    source : str
        Why ("best inside rule 1 of round 2", "nearest to the target").
    features, performance : dict
        SI values (None where not finite).
    status, origin : str
        Its simulation status and where it was simulated (``database``, ``refine-1``, ...).
    margins : dict
        Per target condition, the margin (>= 0: met; +-inf for == and !=).
    worst_margin : float
    meets : bool
    buildable : bool or None
        Its thick panels do not overlap (None: the scenario has no overlap column).
    objective : float or None
        The objective's value for it.
    rule : VerifiedRule or None
        The rule it is the best design of.
    """

    source: str
    features: dict
    performance: dict
    status: str
    origin: str
    margins: dict
    worst_margin: float
    meets: bool
    buildable: bool | None
    objective: float | None
    rule: VerifiedRule | None = None

    def to_json(self) -> dict:
        return {
            "source": self.source,
            "features": {k: _finite_or_none(v) for k, v in self.features.items()},
            "performance": {k: _finite_or_none(v) for k, v in self.performance.items()},
            "status": self.status,
            "origin": self.origin,
            "margins": {k: _margin_json(v) for k, v in self.margins.items()},
            "worst_margin": _margin_json(self.worst_margin),
            "meets_target": self.meets,
            "buildable": self.buildable,
            "objective": _finite_or_none(self.objective),
            "rule": None
            if self.rule is None
            else {"round": self.rule.round, "rank": self.rule.rank},
        }

    @classmethod
    def from_json(cls, d, rules: Mapping) -> Pick:
        if not isinstance(d, Mapping):
            raise ValueError("a design must be an object")
        where = f"design {d.get('source', '')!r}"
        for k in ("features", "performance", "margins"):
            if k not in d:
                raise ValueError(f"{where}: missing {k!r}")
        ref = d.get("rule")
        rule = None
        if ref is not None:
            key = (ref.get("round"), ref.get("rank")) if isinstance(ref, Mapping) else None
            if key not in rules:
                raise ValueError(f"{where}: rule {ref!r} is not one of the rounds' rules")
            rule = rules[key]
        wm = d.get("worst_margin")
        wm = float(wm) if wm in ("inf", "-inf") else (math.nan if wm is None else float(wm))
        b = d.get("buildable")
        return cls(
            source=str(d.get("source", "")),
            features=_numbers(d["features"], f"{where} features"),
            performance=_numbers(d["performance"], f"{where} performance"),
            status=str(d.get("status", "")),
            origin=str(d.get("origin", "")),
            margins=_margins(d["margins"], f"{where} margins"),
            worst_margin=wm,
            meets=bool(d.get("meets_target", False)),
            buildable=None if b is None else bool(b),
            objective=None if d.get("objective") is None else float(d["objective"]),
            rule=rule,
        )


@dataclass(frozen=True)
class Timings:
    """Seconds per stage (:data:`STAGES`) of this invocation and of every invocation on the
    folder (``runs`` of them, this one included)."""

    this_run: dict
    all_runs: dict
    runs: int

    def __post_init__(self):
        for name in ("this_run", "all_runs"):
            for k, v in getattr(self, name).items():
                if not isinstance(v, (int, float)) or not v >= 0:
                    raise ValueError(f"timings {name}: {k} = {v!r} must be seconds >= 0")
        if self.runs < 1:
            raise ValueError(f"timings: runs = {self.runs} must be >= 1")

    def to_json(self) -> dict:
        r = lambda d: {k: round(float(v), 3) for k, v in d.items()}  # noqa: E731
        return {"this_run": r(self.this_run), "all_runs": r(self.all_runs), "runs": self.runs}

    @classmethod
    def from_json(cls, d) -> Timings:
        if not isinstance(d, Mapping):
            raise ValueError("timings must be an object")
        if "this_run" not in d:  # a summary of an older holofold: one invocation's stages
            return cls(dict(d), dict(d), 1)
        return cls(dict(d["this_run"]), dict(d["all_runs"]), int(d.get("runs", 1)))


@dataclass(frozen=True)
class DesignSummary:
    """Everything ``holofold design`` found (module docstring).

    Attributes
    ----------
    scenario : mapping
        Name, kind, description, source, fixed setting, features and performance columns
        (each with ``name``, ``unit``, ``display_unit``, ``description`` and the feature
        ranges).
    target, objective : str
    mined_target : str
        What the rules were mined and verified for: the target, and with a buildability
        condition (``overlap <= ...``) unless overlapping panels are allowed.
    allow_overlap : bool
    answer : str
        ``rule``, ``designs``, ``nearest`` or ``none`` (:mod:`~holofold.design.loop.choice`).
    headline : str
        The answer in a sentence or three, shown first.
    chosen : Pick or None
    alternatives : tuple of Pick
    rounds : tuple of Round
    database : mapping
        ``rows``, ``failed``, ``by_origin`` (rows per origin) and ``path``.
    pilot : mapping or None
        ``rows``, ``meeting``, ``stopped`` (bool), ``reason`` and ``distributions``.
    distributions : tuple of Distribution
        The target's columns over every simulated design.
    fabrication : PartFit or None
    extras : mapping
        Kind-specific facts for the report (the gripper's closed state, ...).
    files : mapping
        Stable key -> ``{"path": ..., "label": ...}`` (the fabrication set's record, paths
        relative to the design folder).
    images : mapping
        Name -> path relative to the design folder.
    warnings : tuple of str
    timings : Timings or None
    """

    scenario: Mapping
    target: str
    objective: str
    allow_overlap: bool
    answer: str
    headline: str
    chosen: Pick | None
    alternatives: tuple[Pick, ...] = ()
    rounds: tuple[Round, ...] = ()
    database: Mapping = field(default_factory=dict)
    pilot: Mapping | None = None
    distributions: tuple[Distribution, ...] = ()
    mined_target: str = ""
    fabrication: PartFit | None = None
    extras: Mapping = field(default_factory=dict)
    files: Mapping = field(default_factory=dict)
    images: Mapping = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    timings: Timings | None = None

    def __post_init__(self):
        from holofold.design.loop.choice import ANSWER_KINDS

        if not isinstance(self.scenario, Mapping) or "name" not in self.scenario:
            raise ValueError("the summary's scenario must be an object with a name")
        if self.answer not in ANSWER_KINDS:
            raise ValueError(f"answer {self.answer!r} is not one of {ANSWER_KINDS}")
        if (self.chosen is None) != (self.answer == "none"):
            raise ValueError("a summary has a chosen design unless every simulation failed")
        paths = [(f"images: {k!r}", rel) for k, rel in self.images.items()]
        for key, entry in self.files.items():
            if not isinstance(entry, Mapping) or not isinstance(entry.get("label"), str):
                raise ValueError(f"files: {key!r} must be {{'path': ..., 'label': ...}}")
            paths.append((f"files: {key!r}", entry.get("path")))
        for where, rel in paths:
            if not isinstance(rel, str) or rel.startswith("/") or ".." in rel.split("/"):
                raise ValueError(f"{where} -> {rel!r} must be a path inside the folder")

    @property
    def rules(self) -> dict:
        """(round, rank) -> VerifiedRule over every round."""
        return {(r.round, r.rank): r for rd in self.rounds for r in rd.rules}

    @property
    def units(self) -> dict:
        """Column name -> SI unit."""
        return {
            c["name"]: c.get("unit", "")
            for key in ("features", "performance")
            for c in self.scenario.get(key) or []
            if isinstance(c, Mapping)
        }

    def to_json(self) -> dict:
        c = self.chosen
        out = {
            "scenario": dict(self.scenario),
            "target": self.target,
            "objective": self.objective,
            "mined_target": self.mined_target or self.target,
            "allow_overlap": self.allow_overlap,
            "answer": self.answer,
            "headline": self.headline,
            # the chosen design's facts at the top level, as design.json always had them
            "features": {} if c is None else c.to_json()["features"],
            "performance": {} if c is None else c.to_json()["performance"],
            "status": None if c is None else c.status,
            "units": self.units,
            "margins": {} if c is None else c.to_json()["margins"],
            "worst_margin": None if c is None else _margin_json(c.worst_margin),
            "meets_target": False if c is None else c.meets,
            "buildable": None if c is None else c.buildable,
            "rule": None if c is None or c.rule is None else c.rule.to_json(),
            "verified_precision": None if c is None or c.rule is None else c.rule.precision,
            # the chosen rule verified at the loop's bar (90 %, interval from 80 %), or below it
            "rule_meets_bar": None if c is None or c.rule is None else c.rule.meets_bar,
            "chosen": None if c is None else c.to_json(),
            "alternatives": [a.to_json() for a in self.alternatives],
            "rounds": [r.to_json() for r in self.rounds],
            "database": dict(self.database),
            "pilot": None if self.pilot is None else dict(self.pilot),
            "distributions": [d.to_json() for d in self.distributions],
            "fabrication": None if self.fabrication is None else self.fabrication.to_json(),
            "extras": dict(self.extras),
            "files": dict(self.files),
            "images": dict(self.images),
            "warnings": list(self.warnings),
            "timings": None if self.timings is None else self.timings.to_json(),
        }
        return out

    @classmethod
    def from_json(cls, d) -> DesignSummary:
        """The one validation of a summary read back (``design.json``); one line per problem."""
        if not isinstance(d, Mapping):
            raise TypeError(f"the summary must be a mapping, got {type(d).__name__}")
        missing = [k for k in ("scenario", "target", "answer", "headline") if k not in d]
        if missing:
            raise ValueError(f"the summary lacks {', '.join(missing)}")
        if not isinstance(d["scenario"], Mapping):
            raise ValueError("summary['scenario'] must be a mapping")
        rounds = tuple(Round.from_json(r) for r in d.get("rounds") or [])
        rules = {(r.round, r.rank): r for rd in rounds for r in rd.rules}
        chosen = None if d.get("chosen") is None else Pick.from_json(d["chosen"], rules)
        pilot = d.get("pilot")
        if pilot is not None and not isinstance(pilot, Mapping):
            raise ValueError("summary['pilot'] must be an object or null")
        return cls(
            scenario=d["scenario"],
            target=str(d["target"]),
            objective=str(d.get("objective", "margin")),
            allow_overlap=bool(d.get("allow_overlap", False)),
            answer=str(d["answer"]),
            headline=str(d["headline"]),
            chosen=chosen,
            alternatives=tuple(Pick.from_json(a, rules) for a in d.get("alternatives") or []),
            rounds=rounds,
            database=dict(d.get("database") or {}),
            pilot=pilot,
            distributions=tuple(Distribution.from_json(x) for x in d.get("distributions") or []),
            mined_target=str(d.get("mined_target") or d["target"]),
            fabrication=None
            if d.get("fabrication") is None
            else PartFit.from_json(d["fabrication"]),
            extras=dict(d.get("extras") or {}),
            files={
                str(k): dict(v) if isinstance(v, Mapping) else v
                for k, v in (d.get("files") or {}).items()
            },
            images={str(k): str(v) for k, v in (d.get("images") or {}).items()},
            warnings=tuple(str(w) for w in d.get("warnings") or ()),
            timings=None if d.get("timings") is None else Timings.from_json(d["timings"]),
        )
