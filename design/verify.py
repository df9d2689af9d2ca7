"""Checking a mined rule by simulating fresh designs inside it.

A rule found on a database says "designs in this box meet the target". :func:`verify_rule`
samples new designs uniformly inside the box (intersected with the scenario's ranges),
simulates them, and reports the fraction that really meets the target, with a 95 % Wilson
interval: the rule's precision on designs it has never seen.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from contextlib import nullcontext
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from holofold.design.row_limits import check_on_invalid, resolve_row_timeout
from holofold.design.row_status import failed_rows
from holofold.design.runner import dask_scheduler, evaluate_designs
from holofold.design.sampling import sample_designs
from holofold.design.scenarios import Scenario, load_scenario
from holofold.design.tables import write_table
from holofold.design.targets import parse_target
from holofold.geometry.outputs import write_json

__all__ = [
    "rule_ranges",
    "rule_mask",
    "verify_rule",
    "verify_rules",
    "write_verification",
    "Verification",
]


def rule_ranges(scenario: Scenario, bounds: Mapping[str, Mapping]) -> dict:
    """Sampling ranges of the box ``bounds`` (the ``bounds`` of a mined rule's JSON record).

    Continuous features: ``{"gt": a, "le": b}`` (null for an open side) intersected with the
    scenario's range; categorical: ``{"in": [levels]}``.
    """
    cols = {c.name: c for c in scenario.features}
    out: dict = {}
    if not isinstance(bounds, Mapping):
        raise ValueError(f"a rule's bounds must be a mapping feature -> box, got {bounds!r:.60}")
    for name, b in bounds.items():
        if name not in cols:
            raise ValueError(f"rule constrains {name!r}, which is not a feature of {scenario.name}")
        c = cols[name]
        levels, lo, hi = _check_bound(name, b)
        if levels is not None:
            out[name] = levels
            continue
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
                f"rule range of {name} ({b.get('gt')}, {b.get('le')}] lies outside the "
                f"scenario's range [{c.low}, {c.high}]"
            )
        out[name] = (lo, hi)
    return out


def _number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and not math.isnan(v)


def _check_bound(name: str, b) -> tuple[list | None, float | None, float | None]:
    """(levels, low, high) of one feature's box; one clear line for a malformed one."""
    shape = '{"gt": number or null, "le": number or null} or {"in": [numbers]}'
    if not isinstance(b, Mapping) or not b or set(b) - {"gt", "le", "in"}:
        raise ValueError(f"bounds of {name} = {b!r:.60} must be {shape}")
    if "in" in b:
        v = b["in"]
        if set(b) != {"in"} or not isinstance(v, list) or not v or not all(map(_number, v)):
            raise ValueError(f"bounds of {name}: 'in' = {v!r:.60} must be a list of numbers")
        return [float(x) for x in v], None, None
    lo, hi = b.get("gt"), b.get("le")
    for key, v in (("gt", lo), ("le", hi)):
        if v is not None and not _number(v):
            raise ValueError(f"bounds of {name}: {key!r} = {v!r:.60} must be a number or null")
    lo = None if lo is None or lo == -math.inf else float(lo)
    hi = None if hi is None or hi == math.inf else float(hi)
    return None, lo, hi


def rule_mask(table: pd.DataFrame, bounds: Mapping[str, Mapping]) -> np.ndarray:
    """(n,) bool: the rows of ``table`` inside the box ``bounds`` (a rule record's)."""
    inside = np.ones(len(table), bool)
    for name, b in bounds.items():
        col = table[name].to_numpy(dtype=float)
        if "in" in b:
            inside &= np.isin(col, np.asarray(b["in"], dtype=float))
            continue
        if b.get("gt") is not None:
            inside &= col > float(b["gt"])
        if b.get("le") is not None:
            inside &= col <= float(b["le"])
    return inside


@dataclass(frozen=True)
class Verification:
    """Fresh designs inside a rule and how many meet the target.

    ``designs`` holds the simulated rows with ``meets_target``; ``precision`` is the fraction
    of successfully simulated rows meeting the target, ``interval`` its 95 % Wilson interval.
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
        return self.n_meeting / self.n_ok if self.n_ok else float("nan")

    @property
    def interval(self) -> tuple[float, float]:
        n, p, z = self.n_ok, self.precision, 1.959964
        if not n:
            return (float("nan"), float("nan"))
        centre = (p + z * z / (2 * n)) / (1 + z * z / n)
        half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
        lo = 0.0 if self.n_meeting == 0 else max(0.0, centre - half)
        hi = 1.0 if self.n_meeting == n else min(1.0, centre + half)
        return (lo, hi)  # exact at p = 0 and p = 1 (no round-off past the estimate)

    def summary(self) -> dict:
        """JSON-ready counts, precision and interval (None where no design simulated)."""
        lo, hi = self.interval
        finite = self.n_ok > 0
        return {
            "simulated": self.n_ok,
            "failed": self.n_failed,
            "meeting_target": self.n_meeting,
            "precision": self.precision if finite else None,
            "precision_95ci": [lo, hi] if finite else None,
        }

    def describe(self) -> str:
        """One line: how many fresh designs meet the target, with the interval."""
        if not self.n_ok:
            return f"no fresh design simulated successfully ({self.n_failed} failed)"
        lo, hi = self.interval
        return (
            f"fresh designs meeting the target: {self.n_meeting}/{self.n_ok} = "
            f"{self.precision:.3f} (95 % CI {lo:.3f}-{hi:.3f}; {self.n_failed} failed)"
        )


def verify_rule(
    scenario: Scenario | str,
    bounds: Mapping[str, Mapping],
    target: str,
    n: int = 50,
    *,
    seed: int = 0,
    workers: int = 1,
    progress: bool | None = None,
    scheduler: str | None = None,
    on_invalid: str = "skip",
    row_timeout: float | str | None = None,
) -> Verification:
    """Simulate ``n`` fresh designs inside a rule and count those meeting ``target``.

    ``workers``, ``progress``, ``scheduler`` (a Dask scheduler address or ``"local"``),
    ``on_invalid`` and ``row_timeout`` are passed to
    :func:`holofold.design.runner.evaluate_designs`: with ``on_invalid="skip"`` fresh designs
    the scenario's check refuses (a box reaching past a validity limit) are failed rows, as
    are rows past their time limit; failed rows count in ``n_failed``, not in the precision.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    tgt = parse_target(target, scenario.performance_names)
    designs = sample_designs(scenario, n, seed=seed, ranges=rule_ranges(scenario, bounds))
    res = evaluate_designs(
        scenario, designs, workers=workers, progress=progress, scheduler=scheduler,
        on_invalid=on_invalid, row_timeout=row_timeout,
    )  # fmt: skip
    return Verification.of(res, tgt)


def verify_rules(
    scenario: Scenario | str,
    rules: Sequence[Mapping],
    target: str,
    n: int = 50,
    *,
    seed: int = 0,
    workers: int = 1,
    progress: bool | None = None,
    scheduler: str | None = None,
    on_invalid: str = "skip",
    row_timeout: float | str | None = None,
) -> list[Verification]:
    """:func:`verify_rule` for each rule record (``bounds`` as in a rules file), in order.

    Every rule is checked against the scenario before anything is simulated; rule ``i``
    (1-based) samples with seed ``seed + i``. A local Dask cluster (``scheduler="local"``) is
    started once for all rules. ``on_invalid`` and ``row_timeout`` as in :func:`verify_rule`.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    parse_target(target, scenario.performance_names)
    check_on_invalid(on_invalid)
    resolve_row_timeout(scenario.row_timeout, row_timeout)
    if int(n) < 1:
        raise ValueError(f"n = {n} designs per rule must be >= 1")
    for r in rules:
        rule_ranges(scenario, r["bounds"])
    cluster = dask_scheduler(scheduler, workers) if scheduler else nullcontext()
    with cluster as address:
        return [
            verify_rule(
                scenario,
                r["bounds"],
                target,
                n,
                seed=seed + i,
                workers=1 if address else workers,
                progress=progress,
                scheduler=address,
                on_invalid=on_invalid,
                row_timeout=row_timeout,
            )  # fmt: skip
            for i, r in enumerate(rules, start=1)
        ]


def write_verification(folder, rules: Sequence[Mapping], results: Sequence[Verification]):
    """``verify.json`` (one record per rule: rank, rule, bounds and the summary) and
    ``verify_rule{i}.csv`` (the simulated designs) in ``folder``; returns the records."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    report = []
    for i, (r, v) in enumerate(zip(rules, results, strict=True), start=1):
        report.append({"rank": i, "rule": r.get("rule"), "bounds": r["bounds"], **v.summary()})
        write_table(v.designs, folder / f"verify_rule{i}.csv")
    write_json(folder / "verify.json", report)
    return report
