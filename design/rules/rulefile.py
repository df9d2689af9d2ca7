"""Rules files: the JSON that ``holofold mine --json`` writes and ``holofold verify`` reads.

One record per rule, best first (:meth:`~holofold.design.rules.record.Rule.to_json`)::

    {"rank": 1, "rule": "W <= 2.1 mm and m in {16, 24}",
     "bounds": {"W": {"gt": null, "le": 0.0021}, "m": {"in": [16, 24]}},
     "display": {"W": {"gt": null, "le": 2.1, "unit": "mm"}},
     "estimate": {"precision": .., "interval": [.., ..], "rows": .., ...},
     "train": {"precision": .., "recall": .., "support": .., "oob_precision": ..},
     "test": {"precision": .., "recall": .., "support": ..}}

``bounds`` constrains each feature by an interval ``gt < x <= le`` (null for an open side) or
a set of categorical levels ``in``; values are SI and are what is applied. ``rule`` and
``display`` show the same bounds in each column's display unit (mm, um, degrees), for reading.
``estimate`` is the precision the rule is expected to have on new designs, with its 95 %
interval and the rows behind it: training rows out of bag for the trees that found the rule and,
when test scores are given, the held-out rows inside it (docs/rule-miner.md section 9);
``train`` are the training rows, ``test`` the held-out rows.

:func:`mined_rules` makes :class:`~holofold.design.rules.record.Rule` records from a fitted
miner, :func:`write_rules` writes them, :func:`read_rules` reads a file and checks each record
once (every problem is one line naming the file, the rule and what was expected).
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from holofold.design.rules import ForestRuleMiner
from holofold.design.rules.record import Condition, Estimate, Rule, RuleError, Score
from holofold.geometry.outputs import write_json

__all__ = [
    "mined_rules",
    "rules_to_records",
    "rules_to_json",
    "write_rules",
    "read_rules",
    "RulesFileError",
]


class RulesFileError(ValueError):
    """A rules file that cannot be used (not JSON, or records of the wrong shape)."""


def mined_rules(miner: ForestRuleMiner, test: pd.DataFrame | None = None) -> list[Rule]:
    """The kept rules of a fitted miner, best first, as :class:`Rule` records.

    Each has its conditions (SI), ``estimate`` (precision, 95 % interval, the rows behind it:
    out-of-bag rows plus, from ``test``, held-out rows), ``train`` scores and
    ``oob_precision``, and ``test`` scores when ``test`` (``evaluation.rule_scores`` of the
    held-out rows) is given.
    """
    oob = miner.rules_["estimate_support"].to_numpy()
    est = miner.rule_estimates(None if test is None else test.reset_index(drop=True))
    cats = dict(zip(miner.feature_names_, miner._encoding.categorical, strict=True))
    out = []
    for i, row in miner.rules_.iterrows():
        conds = []
        for name, b in zip(miner.feature_names_, miner.rule_bounds(i), strict=True):
            if b is None:
                continue
            if cats[name]:
                conds.append(Condition(name, levels=tuple(b)))
            elif np.isfinite(b[0]) or np.isfinite(b[1]):
                conds.append(Condition(name, gt=float(b[0]), le=float(b[1])))
        n_rows = int(est.loc[i, "estimate_support"])
        t = None if test is None else test.iloc[i]
        out.append(
            Rule(
                tuple(conds),
                rank=int(i) + 1,
                estimate=Estimate(
                    float(est.loc[i, "estimate"]),
                    float(est.loc[i, "estimate_low"]),
                    float(est.loc[i, "estimate_high"]),
                    n_rows,
                    int(oob[i]),
                    n_rows - int(oob[i]),
                ),  # fmt: skip
                train=Score(float(row["precision"]), float(row["recall"]), int(row["support"])),
                test=None
                if t is None
                else Score(
                    float(t["precision"]), float(t["recall"]), int(t["support"])
                ),  # fmt: skip
                oob_precision=float(row["oob_precision"]),
            )
        )
    return out


def rules_to_records(
    miner: ForestRuleMiner, test: pd.DataFrame | None = None, columns: Mapping | None = None
) -> list[dict]:
    """:func:`mined_rules` in their JSON form (:meth:`Rule.to_json`; ``columns`` name ->
    Column for the display form)."""
    return [r.to_json(columns) for r in mined_rules(miner, test)]


def rules_to_json(miner: ForestRuleMiner, test: pd.DataFrame | None = None, **kw) -> str:
    """:func:`rules_to_records` as a JSON string (``kw`` go to ``json.dumps``)."""
    columns = kw.pop("columns", None)
    kw.setdefault("indent", 2)
    return json.dumps(rules_to_records(miner, test, columns), **kw)


def write_rules(path, rules: Sequence[Rule], columns: Mapping | None = None) -> Path:
    """Write rules (best first) as strict JSON, atomically: each :meth:`Rule.to_json` with
    ``columns`` (name -> Column) giving the display form."""
    return write_json(path, [r.to_json(columns) for r in rules])


def read_rules(path) -> list[Rule]:
    """The rules of a rules file, each checked once (:meth:`Rule.from_json`).

    Raises
    ------
    RulesFileError
        The file is not JSON or not a list of rule records; the message names the file, the
        rule and what was expected.
    OSError
        The file cannot be read.
    """
    path = Path(path)
    try:
        data = json.loads(path.read_text())
    except json.JSONDecodeError as exc:
        raise RulesFileError(f"{path} is not valid JSON: {exc}") from None
    except UnicodeDecodeError:
        raise RulesFileError(f"{path} is not a text file") from None
    if not isinstance(data, list) or not data:
        raise RulesFileError(f"{path} is not a rules file of `holofold mine --json` (a list)")
    out = []
    for k, rec in enumerate(data, start=1):
        try:
            out.append(Rule.from_json(rec, rank=k))
        except RuleError as exc:
            raise RulesFileError(f"{path}: rule {k}: {exc}") from None
    return out
