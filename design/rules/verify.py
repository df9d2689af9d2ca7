"""Checking a mined rule by simulating fresh designs inside it.

A rule found on a database says "designs in this box meet the target". :func:`verify_rule`
samples new designs uniformly inside the box (intersected with the scenario's ranges),
simulates them, and reports the fraction that really meets the target, with a 95 % Wilson
interval: the rule's precision on designs it has never seen.
"""

from __future__ import annotations

import hashlib
import json
import tempfile
from collections.abc import Mapping, Sequence
from contextlib import nullcontext
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from holofold.design.database.batches import grow
from holofold.design.database.row_limits import check_on_invalid, resolve_row_timeout
from holofold.design.database.row_status import failed_rows
from holofold.design.database.runner import dask_scheduler
from holofold.design.database.sampling import sample_designs
from holofold.design.database.store import build_database
from holofold.design.database.tables import write_table
from holofold.design.loop.rounds import Counts, wilson
from holofold.design.rules.record import Rule
from holofold.design.rules.targets import parse_target
from holofold.design.scenarios import Scenario, load_scenario
from holofold.geometry.outputs import write_json

__all__ = [
    "as_rule",
    "rule_ranges",
    "rule_mask",
    "rule_key",
    "verify_rule",
    "verify_rules",
    "write_verification",
    "Verification",
]


def as_rule(rule: Rule | Mapping) -> Rule:
    """``rule`` as a :class:`Rule`: a Rule as it is; a rule record (with ``bounds``) or a mapping
    feature -> bound, checked once (:meth:`Rule.from_json`); a ValueError names the problem."""
    if isinstance(rule, Rule):
        return rule
    if isinstance(rule, Mapping) and "bounds" in rule:
        return Rule.from_json(rule)
    return Rule.from_bounds(rule)


def rule_ranges(scenario: Scenario, rule: Rule | Mapping) -> dict:
    """Sampling ranges of a rule's box (a :class:`Rule`, or its ``bounds`` mapping).

    Continuous features: the interval ``(gt, le]`` intersected with the scenario's range;
    categorical: the allowed levels (an interval over a categorical feature: the levels in it).
    """
    rule = as_rule(rule)
    cols = {c.name: c for c in scenario.features}
    out: dict = {}
    for cond in rule.conditions:
        name = cond.feature
        if name not in cols:
            raise ValueError(f"rule constrains {name!r}, which is not a feature of {scenario.name}")
        c = cols[name]
        if cond.levels is not None:
            out[name] = list(cond.levels)
            continue
        lo, hi = cond.gt, cond.le
        if c.choices:  # an interval over a categorical feature: the levels inside it
            inside = [v for v in c.choices if (lo is None or v > lo) and (hi is None or v <= hi)]
            if not inside:
                raise ValueError(f"rule range of {name} ({lo}, {hi}] holds none of {c.choices}")
            out[name] = inside
            continue
        lo = c.low if lo is None else max(lo, c.low)
        hi = c.high if hi is None else min(hi, c.high)
        if not lo <= hi:
            raise ValueError(
                f"rule range of {name} ({cond.gt}, {cond.le}] lies outside the "
                f"scenario's range [{c.low}, {c.high}]"
            )
        out[name] = (lo, hi)
    return out


def rule_key(rule: Rule | Mapping) -> str:
    """8 hex digits naming a rule's box (its SI bounds as canonical JSON): the folder of its
    verification designs, so a changed rule never meets another rule's designs."""
    bounds = {c.feature: c.to_json() for c in as_rule(rule).conditions}
    text = json.dumps(bounds, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:8]


def rule_mask(table: pd.DataFrame, rule: Rule | Mapping) -> np.ndarray:
    """(n,) bool: the rows of ``table`` inside ``rule`` (:meth:`Rule.mask`)."""
    return as_rule(rule).mask(table)


@dataclass(frozen=True)
class Verification:
    """Fresh designs inside a rule and how many meet the target.

    ``designs`` holds the simulated rows with ``meets_target``; ``precision`` is the fraction
    of every fresh design meeting the target, a failed simulation counted as not meeting it
    (it is a design inside the rule that does not work), ``interval`` its 95 % Wilson interval.
    """

    designs: pd.DataFrame
    n_ok: int
    n_failed: int
    n_meeting: int

    @classmethod
    def of(cls, results: pd.DataFrame, target) -> Verification:
        """Count the simulated ``results`` (with ``status``) meeting ``target`` (a Target)."""
        res = results.copy()
        failed = pd.Series(failed_rows(res), index=res.index)
        meets = pd.Series(False, index=res.index)
        ok = res.loc[~failed]
        if len(ok):
            meets.loc[~failed] = target.evaluate(ok)
        res["meets_target"] = meets
        return cls(res, int((~failed).sum()), int(failed.sum()), int(meets.sum()))

    @property
    def precision(self) -> float:
        n = self.n_ok + self.n_failed
        return self.n_meeting / n if n else float("nan")

    @property
    def interval(self) -> tuple[float, float]:
        """95 % Wilson interval (exact at p = 0 and p = 1; NaN when nothing simulated)."""
        return wilson(self.n_meeting, self.n_ok + self.n_failed)

    @property
    def counts(self) -> Counts:
        return Counts(self.n_ok, self.n_failed, self.n_meeting)

    def summary(self) -> dict:
        """JSON-ready counts, precision and interval (None where no design simulated)."""
        lo, hi = self.interval
        finite = self.n_ok + self.n_failed > 0
        return {
            "simulated": self.n_ok,
            "failed": self.n_failed,
            "meeting_target": self.n_meeting,
            "precision": self.precision if finite else None,
            "precision_95ci": [lo, hi] if finite else None,
        }

    def describe(self) -> str:
        """One line: how many fresh designs meet the target, with the interval."""
        if not self.n_ok + self.n_failed:
            return "no fresh design simulated"
        lo, hi = self.interval
        failed = f"; {self.n_failed} failed, counted as not meeting it" if self.n_failed else ""
        return (
            f"fresh designs meeting the target: {self.n_meeting}/{self.n_ok + self.n_failed} = "
            f"{self.precision:.3f} (95 % CI {lo:.3f}-{hi:.3f}{failed})"
        )


def verify_rule(
    scenario: Scenario | str,
    rule: Rule | Mapping,
    target,
    n: int = 50,
    *,
    seed: int = 0,
    folder: str | Path | None = None,
    workers: int = 1,
    progress: bool | None = None,
    scheduler: str | None = None,
    on_invalid: str = "skip",
    row_timeout: float | str | None = None,
) -> Verification:
    """Simulate ``n`` fresh designs inside ``rule`` and count those meeting ``target`` (an
    expression or a :class:`~holofold.design.rules.targets.Target`).

    The designs are simulated into resumable databases in ``folder``, in batches
    ``{a:06d}-{b:06d}`` (:mod:`~holofold.design.database.batches`): a second call resumes, and a
    larger
    ``n`` adds a batch (design i depends on ``seed`` and i alone). Without ``folder`` a
    temporary one is used and removed. ``workers``, ``progress``, ``scheduler`` (a Dask
    scheduler address or ``"local"``), ``on_invalid`` and ``row_timeout`` are passed to
    :func:`holofold.design.database.store.build_database`: with ``on_invalid="skip"`` fresh designs
    the
    scenario's check refuses (a box reaching past a validity limit) are failed rows, as are
    rows past their time limit; failed rows count in ``n_failed`` and as designs that do not
    meet the target in the precision.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    tgt = parse_target(target, scenario.performance_names) if isinstance(target, str) else target
    ranges = rule_ranges(scenario, rule)

    def sample(start: int, count: int) -> pd.DataFrame:
        return sample_designs(scenario, count, seed=seed, start=start, ranges=ranges)

    def simulate(designs: pd.DataFrame, path: Path) -> pd.DataFrame:
        return build_database(
            scenario,
            designs,
            path,
            workers=workers,
            progress=progress,
            scheduler=scheduler,
            on_invalid=on_invalid,
            row_timeout=row_timeout,
        )

    with tempfile.TemporaryDirectory() if folder is None else nullcontext(folder) as where:
        res, _ = grow(Path(where), int(n), sample, simulate)
    return Verification.of(res.iloc[: int(n)], tgt)


def verify_rules(
    scenario: Scenario | str,
    rules: Sequence[Rule | Mapping],
    target,
    n: int = 50,
    *,
    seed: int = 0,
    folder: str | Path | None = None,
    workers: int = 1,
    progress: bool | None = None,
    scheduler: str | None = None,
    on_invalid: str = "skip",
    row_timeout: float | str | None = None,
) -> list[Verification]:
    """:func:`verify_rule` for each rule (a :class:`Rule` or its record), in order.

    Every rule is checked against the scenario before anything is simulated; rule ``i``
    (1-based) samples with seed ``seed + i`` into ``folder/rule{i}-{rule_key(rule)}`` (a
    changed rule gets a folder of its own). A local Dask cluster (``scheduler="local"``) is
    started once for all rules. ``on_invalid`` and ``row_timeout`` as in :func:`verify_rule`.
    This is the one verification: ``holofold verify`` and the design loop both run it.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    tgt = parse_target(target, scenario.performance_names) if isinstance(target, str) else target
    check_on_invalid(on_invalid)
    resolve_row_timeout(scenario.row_timeout, row_timeout)
    if isinstance(n, bool) or int(n) != n or int(n) < 1:
        raise ValueError(f"n = {n} designs per rule must be a whole number >= 1")
    rules = [as_rule(r) for r in rules]
    for r in rules:
        rule_ranges(scenario, r)
    cluster = dask_scheduler(scheduler, workers) if scheduler else nullcontext()
    with cluster as address:
        return [
            verify_rule(
                scenario,
                r,
                tgt,
                n,
                seed=seed + i,
                folder=None if folder is None else Path(folder) / f"rule{i}-{rule_key(r)}",
                workers=1 if address else workers,
                progress=progress,
                scheduler=address,
                on_invalid=on_invalid,
                row_timeout=row_timeout,
            )
            for i, r in enumerate(rules, start=1)
        ]


def write_verification(folder, rules: Sequence[Rule | Mapping], results: Sequence[Verification],
                       columns: Mapping | None = None):  # fmt: skip
    """``verify.json`` (one record per rule: its JSON form, :meth:`Rule.to_json` with ``columns``
    for display units, and the summary) and ``verify_rule{i}.csv`` (the simulated designs) in
    ``folder``; returns the records."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    report = []
    for i, (r, v) in enumerate(zip(rules, results, strict=True), start=1):
        rec = as_rule(r).with_rank(i).to_json(columns)
        report.append({k: rec[k] for k in ("rank", "rule", "bounds", "display")} | v.summary())
        write_table(v.designs, folder / f"verify_rule{i}.csv")
    write_json(folder / "verify.json", report)
    return report
