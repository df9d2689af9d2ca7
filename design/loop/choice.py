"""Choosing the design to build from everything the loop simulated: always an answer.

:func:`choose` looks at every simulated design (database, refinement, verification and earlier
runs) and returns an :class:`Answer`, the chosen :class:`Candidate` and how it was found,
stated honestly:

``rule``
    the best verified rule over all rounds (highest verified precision, then its interval's
    lower bound) among those verified at :data:`~holofold.design.loop.rounds.RULE_QUALIFIES` or
    more that hold a simulated design meeting the target; the chosen design is the best such
    design inside it under the objective;
``designs``
    no rule qualifies: the best of the simulated designs that meet the target;
``nearest``
    no simulated design meets the target: the one with the largest worst-case margin (the
    smallest shortfall), its margins showing what it misses and by how much;
``none``
    every simulation failed.

A design whose thick panels overlap (``overlap`` above :data:`OVERLAP_TOLERANCE`) cannot be
built as designed and is never chosen unless ``allow_overlap``; converged designs are preferred
to designs whose simulation missed a tolerance. The answer also lists alternatives: the best
design of each verified rule and the best design overall under the objective.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from holofold.design.database.row_status import converged_rows, failed_rows
from holofold.design.loop.objective import Objective
from holofold.design.loop.rounds import RULE_BAR, RULE_QUALIFIES, VerifiedRule

__all__ = ["Candidate", "Answer", "choose", "OVERLAP_TOLERANCE", "ANSWER_KINDS"]

#: thick panels intersecting by at most this volume count as not overlapping, m^3 (0.001 mm^3:
#: contact and round-off of the exact booleans, far below any printed feature)
OVERLAP_TOLERANCE = 1e-12
ANSWER_KINDS = ("rule", "designs", "nearest", "none")


@dataclass(frozen=True)
class Candidate:
    """One simulated design put forward, with why.

    Attributes
    ----------
    label : object
        Its index label in the design table.
    source : str
        Why it is here ("best inside rule 1 of round 2", "best of all simulated designs").
    rule : VerifiedRule or None
        The rule it is the best design of.
    meets : bool
        It meets the target.
    buildable : bool or None
        Its thick panels do not overlap (None: the scenario has no ``overlap`` column).
    converged : bool
    margins : dict
        Per condition of the target, its margin (>= 0: met).
    worst_margin : float
    score : float
        The objective's value for it (a mass, a stiffness, or the worst margin).
    """

    label: object
    source: str
    rule: VerifiedRule | None
    meets: bool
    buildable: bool | None
    converged: bool
    margins: dict
    worst_margin: float
    score: float


@dataclass(frozen=True)
class Answer:
    """What the loop puts forward: the chosen design (None if every simulation failed), the
    kind of answer (:data:`ANSWER_KINDS`), the sentence that says so, the alternatives, and
    the counts behind it."""

    kind: str
    chosen: Candidate | None
    headline: str
    alternatives: tuple[Candidate, ...]
    simulated: int
    meeting: int
    left_out_overlap: int

    def __post_init__(self):
        if self.kind not in ANSWER_KINDS:
            raise ValueError(f"answer kind {self.kind!r} is not one of {ANSWER_KINDS}")
        if (self.chosen is None) != (self.kind == "none"):
            raise ValueError("an answer has a chosen design unless every simulation failed")


def _masks(table: pd.DataFrame, target, allow_overlap: bool):
    ok = ~failed_rows(table)
    conv = converged_rows(table)
    meets = np.zeros(len(table), bool)
    if ok.any():
        meets[ok] = target.evaluate(table.loc[ok])
    ov = (
        table["overlap"].to_numpy(dtype=float)
        if "overlap" in table
        else np.full(len(table), np.nan)
    )
    has_overlap = bool(np.isfinite(ov).any())  # a kind that computes it (NaN: not computed)
    buildable = ~(ov > OVERLAP_TOLERANCE)  # NaN: unknown, not held against the design
    allowed = buildable | allow_overlap
    return ok, conv, meets, buildable, allowed, has_overlap


def _ov_at(table: pd.DataFrame, pos: int) -> float:
    """The overlap of row ``pos`` (NaN without the column)."""
    return float(table["overlap"].iloc[pos]) if "overlap" in table else float("nan")


def _preferred(mask: np.ndarray, conv: np.ndarray) -> np.ndarray:
    """Converged rows of ``mask`` if any, else all of them."""
    return mask & conv if (mask & conv).any() else mask


def _candidate(table, label, source, rule, target, objective, masks) -> Candidate:
    ok, conv, meets, buildable, _, has_overlap = masks
    pos = table.index.get_loc(label)
    one = table.loc[[label]]
    margins = {k: float(v[0]) for k, v in target.margins(one).items()}
    return Candidate(
        label=label,
        source=source,
        rule=rule,
        meets=bool(meets[pos]),
        buildable=bool(buildable[pos]) if has_overlap and np.isfinite(_ov_at(table, pos)) else None,
        converged=bool(conv[pos]),
        margins=margins,
        worst_margin=float(target.margin(one)[0]),
        score=objective.value(table.loc[label], target),
    )


def _pct(p: float) -> str:
    return f"{100 * p:.0f} %"


def choose(
    table: pd.DataFrame,
    target,
    objective: Objective,
    rules: Sequence[VerifiedRule],
    *,
    allow_overlap: bool = False,
) -> Answer:
    """The design to build from ``table`` (every simulated design, with ``status``), the
    verified ``rules`` of every round, the ``target`` and the ``objective`` (module docstring).
    """
    table = table.reset_index(drop=True)
    masks = _masks(table, target, allow_overlap)
    ok, conv, meets, buildable, allowed, has_overlap = masks
    good = _preferred(ok & meets & allowed, conv)
    n_ok, n_meet = int(ok.sum()), int((ok & meets).sum())
    left_out = int((ok & meets & ~allowed).sum())
    ranked = sorted(
        (r for r in rules if r.precision is not None), key=VerifiedRule.sort_key, reverse=True
    )

    alternatives: list[Candidate] = []
    chosen = None
    kind = ""
    for r in ranked:
        inside = r.rule.mask(table)
        label = objective.best(table.loc[good & inside], target)
        if label is None:
            continue
        c = _candidate(table, label, f"best inside {r.label}", r, target, objective, masks)
        alternatives.append(c)
        if chosen is None and r.qualifies:
            chosen, kind = c, "rule"
    overall = objective.best(table.loc[good], target)
    if overall is not None:
        alternatives.append(
            _candidate(
                table, overall, "best of all simulated designs", None, target, objective, masks
            )
        )
        if chosen is None:
            chosen, kind = alternatives[-1], "designs"
    if has_overlap and not allow_overlap and left_out:
        loose = _preferred(ok & meets, conv)
        lab = objective.best(table.loc[loose], target)
        if lab is not None and lab != overall:
            alternatives.append(
                _candidate(
                    table,
                    lab,
                    "best if overlapping panels were allowed (--allow-overlap)",
                    None,
                    target,
                    objective,
                    masks,
                )
            )
    none_allowed = not (ok & allowed).any()  # e.g. every design's thick panels overlap
    if chosen is None:  # nothing meets the target: the smallest shortfall
        pool = _preferred(ok, conv) if none_allowed else _preferred(ok & allowed, conv)
        if pool.any():
            m = target.margin(table.loc[pool])
            m = np.where(np.isnan(m), -np.inf, m)
            label = table.index[pool][int(np.argmax(m))]
            chosen = _candidate(
                table, label, "nearest to the target", None, target, objective, masks
            )
            kind = "nearest"
        else:
            kind = "none"
    alternatives = _distinct(alternatives)
    n_good = int((ok & meets & allowed).sum())
    headline = _headline(
        kind,
        chosen,
        ranked,
        objective,
        n_ok,
        n_meet,
        n_good,
        left_out,
        len(table),
        has_overlap and not allow_overlap and not none_allowed,
    )
    return Answer(kind, chosen, headline, tuple(alternatives), n_ok, n_meet, left_out)


def _distinct(cands: list[Candidate]) -> list[Candidate]:
    """One entry per design (the first reason kept, later ones appended to it)."""
    out: dict = {}
    for c in cands:
        if c.label in out:
            first = out[c.label]
            out[c.label] = Candidate(**{**first.__dict__, "source": f"{first.source}; {c.source}"})
        else:
            out[c.label] = c
    return list(out.values())


def _headline(
    kind, chosen, ranked, objective, n_ok, n_meet, n_good, left_out, n_all, strict
) -> str:
    by = objective.words
    meeting = (
        "that meet the target with thick panels that do not overlap"
        if strict
        else "that meet the target"
    )
    overlap = (
        f" {left_out} design(s) meeting the target were left out because their thick "
        "panels overlap (--allow-overlap admits them)."
        if left_out
        else ""
    )
    if kind == "none":
        return f"Every one of the {n_all} simulations failed: there is no design to show."
    if kind == "rule":
        r = chosen.rule
        lo, hi = r.interval
        bar = (
            "verified rule of all rounds"
            if r.meets_bar
            else f"rule of all rounds, verified BELOW the loop's bar of {_pct(RULE_BAR[0])} "
            f"(interval from {_pct(RULE_BAR[1])}): about {_pct(1 - r.precision)} of designs "
            "inside it miss the target"
        )
        return (
            f"The design with {by} among the simulated designs inside {r.label}, the best "
            f"{bar} (verified precision {_pct(r.precision)}, 95 % "
            f"interval {_pct(lo)} to {_pct(hi)}, n = {r.verified.tried}"
            f"{f', {r.verified.failed} failed' if r.verified.failed else ''}); "
            f"{n_good} of {n_ok} simulated designs {meeting[5:]}.{overlap}"
        )
    if kind == "designs":
        if ranked:
            best = ranked[0]
            why = (
                f"no verified rule reached {_pct(RULE_QUALIFIES)} with a design meeting the "
                f"target (the best: {best.label}, {_pct(best.precision)})"
            )
        else:
            why = "no rule was found for this target"
        return (
            f"{why[0].upper()}{why[1:]}. Chosen: the design with {by} among the {n_good} "
            f"simulated designs (of {n_ok}) {meeting}.{overlap}"
        )
    worst = min(chosen.margins.items(), key=lambda kv: kv[1]) if chosen.margins else None
    miss = f"; it misses {worst[0]} by {_pct(-worst[1])}" if worst and worst[1] < 0 else ""
    if left_out and n_meet:
        first = (
            f"No buildable simulated design meets the target: the {n_meet} that do have "
            "overlapping thick panels (--allow-overlap admits them)."
        )
    else:
        first = f"No simulated design meets the target (of {n_ok} simulated)."
    if left_out and not strict:  # not one simulated design is buildable
        return (
            f"{first} The thick panels of every simulated design overlap; shown: the design "
            f"with the largest worst-case margin{miss}, overlapping too. Thinner panels or wider "
            "creases (the feature ranges), or --allow-overlap if the overlap is acceptable."
        )
    return (
        f"{first} Shown: the nearest design{' whose panels do not overlap' if strict else ''}, "
        f"with the largest worst-case margin{miss}. "
        "Loosen the target, widen the feature ranges or simulate more designs."
    )
