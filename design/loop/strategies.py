"""Where a refinement round of the design loop samples: a registry of small callables.

A strategy takes a :class:`RefineRequest` (the scenario, how many designs, the seed, the last
round's rules and forest) and returns a :class:`Proposal`: the new designs, the key naming the
folder they are simulated into (so a resumed run finds them) and the words of the progress line.
:data:`STRATEGIES` holds the built-in ones (measured against each other in
``benchmarks/rare_targets.md``):

- ``"likely"``: all where the last round's forest votes for the target
  (:func:`~holofold.design.loop.acquisition.likely_designs`);
- ``"around"``: half inside the rules and half in them widened by a quarter of each range
  (:func:`refine_designs`);
- ``"mixed"`` (the default): half where the forest votes, half uniformly inside the best rule.

Another package adds one with :func:`register_strategy` or the entry-point group
``holofold.refine_strategies``. A round after one without a rule does not ask the strategy: it
samples around the designs meeting the target (:func:`around_hits`) or at random while none
does (:func:`at_random`).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from holofold.design.database.sampling import sample_designs
from holofold.design.loop.acquisition import likely_designs
from holofold.design.rules import Rule
from holofold.design.rules.verify import rule_key, rule_ranges
from holofold.design.scenarios import Scenario
from holofold.geometry import Registry

__all__ = [
    "RefineRequest",
    "Proposal",
    "STRATEGIES",
    "register_strategy",
    "refine_designs",
    "around_hits",
    "at_random",
]


@dataclass(frozen=True)
class RefineRequest:
    """What a refinement round knows.

    Attributes
    ----------
    scenario : Scenario
    n : int
        New designs to propose.
    seed : int
        The round's seed.
    start : int
        ``sample`` number of the first new design.
    rules : tuple of Rule
        The last round's rules, best first (or the box of the designs meeting the target).
    forest : ForestRuleMiner or None
        The last round's fitted forest (None when it mined no rule).
    rows : int
        Designs simulated so far.
    """

    scenario: Scenario
    n: int
    seed: int
    start: int
    rules: tuple
    forest: object
    rows: int

    @property
    def rule_keys(self) -> list[str]:
        return [rule_key(b) for b in self.rules]


@dataclass(frozen=True)
class Proposal:
    """A strategy's answer: ``designs`` (feature columns and ``sample``), ``key`` (8 hex
    digits naming their folder) and ``words`` (what the progress line says right after "N new
    designs", with its leading space or comma)."""

    designs: pd.DataFrame
    key: str
    words: str


def design_key(*parts) -> str:
    """8 hex digits naming what a refinement's designs come from (its rules, size and seed)."""
    return hashlib.sha256(json.dumps(parts, sort_keys=True).encode()).hexdigest()[:8]


def refine_designs(
    scenario: Scenario,
    rules: Sequence[Rule | Mapping],
    n: int,
    *,
    seed: int,
    start: int = 0,
    widen: float = 0.25,
) -> pd.DataFrame:
    """``n`` new designs inside and around the boxes of ``rules`` (:class:`Rule` records or
    their JSON form; shared equally).

    Half of each rule's designs lie inside its box, half in the box widened by ``widen`` of
    each feature's range on both sides (clipped to the scenario's range), so the database also
    learns where the rule's edges really are. Categorical features keep the rule's levels.
    """
    cols = {c.name: c for c in scenario.features}
    parts = []
    k = len(rules)
    counts = [n // k + (1 if i < n % k else 0) for i in range(k)]
    for i, (rule, m) in enumerate(zip(rules, counts, strict=True)):
        inside = rule_ranges(scenario, rule)
        wide = {}
        for name, r in inside.items():
            c = cols[name]
            if isinstance(r, list):
                wide[name] = r
                continue
            pad = widen * (c.high - c.low)
            wide[name] = (max(c.low, r[0] - pad), min(c.high, r[1] + pad))
        for j, ranges in enumerate((inside, wide)):
            size = m // 2 + (m % 2 if j == 0 else 0)
            if size:
                parts.append(
                    sample_designs(scenario, size, seed=seed * 1000 + 2 * i + j, ranges=ranges)
                )
    out = pd.concat(parts, ignore_index=True)
    out["sample"] = np.arange(start, start + len(out))
    return out


# ---------------------------------------------------------------------- the strategies
def mixed(q: RefineRequest) -> Proposal:
    """Half where the forest votes for the target, half uniformly inside the best rule."""
    half = q.n // 2
    vote = likely_designs(q.scenario, q.forest, q.n - half, seed=q.seed, start=q.start)
    inside = refine_designs(q.scenario, q.rules[:1], half, seed=q.seed, widen=0.0,
                            start=q.start + q.n - half)  # fmt: skip
    return Proposal(
        pd.concat([vote, inside], ignore_index=True),
        design_key("mixed", q.rule_keys, q.rows, q.n, q.seed),
        ", half where the forest votes for the target, half inside the best rule",
    )


def likely(q: RefineRequest) -> Proposal:
    """All where the forest votes for the target."""
    return Proposal(
        likely_designs(q.scenario, q.forest, q.n, seed=q.seed, start=q.start),
        design_key("likely", q.rule_keys, q.rows, q.n, q.seed),
        " where the forest votes for the target",
    )


def around(q: RefineRequest) -> Proposal:
    """Half inside the rules, half in them widened by a quarter of each range."""
    return Proposal(
        refine_designs(q.scenario, q.rules, q.n, seed=q.seed, start=q.start),
        design_key(q.rule_keys, q.n, q.seed),
        " inside and around the rules",
    )


def around_hits(q: RefineRequest) -> Proposal:
    """After a round whose few hits could not be mined: around the designs meeting the target
    (``q.rules`` holds their box)."""
    return Proposal(
        refine_designs(q.scenario, q.rules, q.n, seed=q.seed, start=q.start),
        design_key("around-hits", q.rule_keys, q.n, q.seed),
        " around the designs that meet the target",
    )


def at_random(q: RefineRequest) -> Proposal:
    """While no design meets the target: more at random."""
    return Proposal(
        sample_designs(q.scenario, q.n, seed=q.seed, start=q.start),
        design_key("random", q.n, q.seed),
        " at random (none met the target yet)",
    )


def _check_strategy(name, fn) -> Callable[[RefineRequest], Proposal]:
    if not callable(fn):
        raise TypeError(f"refinement strategy {name!r}: expected a callable, got {fn!r}")
    return fn


#: name -> strategy (a :class:`~holofold.geometry.Registry`; plug-ins from the entry-point
#: group ``holofold.refine_strategies``)
STRATEGIES: Registry[Callable[[RefineRequest], Proposal]] = Registry(
    "refinement strategy",
    {"likely": likely, "around": around, "mixed": mixed},
    group="holofold.refine_strategies",
    check=_check_strategy,
    error=ValueError,
)


def register_strategy(name: str, fn: Callable[[RefineRequest], Proposal], *,
                      replace: bool = False) -> Callable:  # fmt: skip
    """Add a refinement strategy (``run_design(..., strategy=name)``, ``--strategy name``)."""
    return STRATEGIES.register(fn, name, replace=replace)
