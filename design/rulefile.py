"""Rules files: the JSON that ``holofold mine --json`` writes and ``holofold verify`` reads.

One record per rule, best first::

    {"rank": 1, "rule": "W <= 0.0021 and m in {16, 24}",
     "bounds": {"W": {"gt": null, "le": 0.0021}, "m": {"in": [16, 24]}},
     "estimate": {"precision": .., "interval": [.., ..], "rows": ..},
     "train": {"precision": .., "recall": .., "support": .., "oob_precision": ..},
     "test": {"precision": .., "recall": .., "support": ..}}

``estimate`` is the precision the rule is expected to have on new designs, with its 95 %
interval and the rows behind it: training rows out of bag for the trees that found the rule and,
when test scores are given, the held-out rows inside it (docs/rule-miner.md section 9);
``train`` are the training rows, ``test`` the held-out rows.

``bounds`` constrains each feature by an interval ``gt < x <= le`` (null for an open side) or
a set of categorical levels ``in``; values are SI. :func:`rules_to_records` makes the records
from a fitted miner, :func:`write_rules` writes them, :func:`read_rules` reads and validates a
file (every problem is one line naming the file, the rule and what was expected).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pandas as pd

from holofold.design.rules import ForestRuleMiner, level_value
from holofold.geometry.outputs import write_json

__all__ = ["rules_to_records", "rules_to_json", "write_rules", "read_rules", "RulesFileError"]


class RulesFileError(ValueError):
    """A rules file that cannot be used (not JSON, or records of the wrong shape)."""


def _num(v: float):
    return None if not math.isfinite(v) else float(v)


def rules_to_records(miner: ForestRuleMiner, test: pd.DataFrame | None = None) -> list[dict]:
    """The kept rules, best first, as JSON-ready dicts.

    Each has ``rule`` (text), ``bounds`` (per constrained feature ``{"gt": .., "le": ..}``
    with null for an open side, or ``{"in": [levels]}``), ``estimate`` (``precision``, its
    95 % ``interval``, the ``rows`` behind it: ``out_of_bag_rows`` plus ``held_out_rows``, the
    latter from ``test``), ``train`` (precision, recall, support, oob_precision) and, when
    ``test`` is given (``evaluation.rule_scores`` of held-out rows), ``test``.
    """
    oob = miner.rules_["estimate_support"].to_numpy()
    est = miner.rule_estimates(None if test is None else test.reset_index(drop=True))
    out = []
    for i, row in miner.rules_.iterrows():
        bounds = {}
        for name, b in zip(miner.feature_names_, miner.rule_bounds(i), strict=True):
            if b is None:
                continue
            if miner._encoding.categorical[miner.feature_names_.index(name)]:
                bounds[name] = {"in": [level_value(v) for v in b]}
            elif math.isfinite(b[0]) or math.isfinite(b[1]):
                bounds[name] = {"gt": _num(b[0]), "le": _num(b[1])}
        rec = {
            "rank": int(i) + 1,
            "rule": row["rule"],
            "bounds": bounds,
            "estimate": {
                "precision": float(est.loc[i, "estimate"]),
                "interval": [float(est.loc[i, "estimate_low"]), float(est.loc[i, "estimate_high"])],
                "rows": int(est.loc[i, "estimate_support"]),
                "out_of_bag_rows": int(oob[i]),
                "held_out_rows": int(est.loc[i, "estimate_support"] - oob[i]),
            },
            "train": {
                "precision": float(row["precision"]),
                "recall": float(row["recall"]),
                "support": int(row["support"]),
            },
        }
        rec["train"]["oob_precision"] = float(row["oob_precision"])
        if test is not None:
            t = test.iloc[i]
            rec["test"] = {
                "precision": float(t["precision"]),
                "recall": float(t["recall"]),
                "support": int(t["support"]),
            }
        out.append(rec)
    return out


def rules_to_json(miner: ForestRuleMiner, test: pd.DataFrame | None = None, **kw) -> str:
    """:func:`rules_to_records` as a JSON string (``kw`` go to ``json.dumps``)."""
    kw.setdefault("indent", 2)
    return json.dumps(rules_to_records(miner, test), **kw)


def write_rules(path, records: list[dict]) -> Path:
    """Write rule records as strict JSON (no NaN or Infinity), atomically."""
    return write_json(path, records)


def _bound_error(path, k: int, name: str, what: str) -> RulesFileError:
    return RulesFileError(f"{path}: rule {k}: bounds of {name!r}: {what}")


def _check_bound(path, k: int, name: str, b) -> dict:
    if not isinstance(b, dict):
        raise _bound_error(path, k, name, f"expected an object, got {type(b).__name__}")
    if "in" in b:
        levels = b["in"]
        if not isinstance(levels, list) or not levels:
            raise _bound_error(path, k, name, "'in' must be a non-empty list of levels")
        if not all(isinstance(v, int | float) and not isinstance(v, bool) for v in levels):
            raise _bound_error(path, k, name, "'in' levels must be numbers")
        return {"in": [float(v) for v in levels]}
    unknown = set(b) - {"gt", "le"}
    if unknown or not b:
        raise _bound_error(path, k, name, "expected keys 'gt'/'le' (numbers or null) or 'in'")
    out = {}
    for side in ("gt", "le"):
        v = b.get(side)
        ok = v is None or (isinstance(v, int | float) and not isinstance(v, bool))
        if not ok or (v is not None and not math.isfinite(v)):
            raise _bound_error(path, k, name, f"{side!r} must be a finite number or null")
        out[side] = None if v is None else float(v)
    if out["gt"] is not None and out["le"] is not None and not out["gt"] < out["le"]:
        raise _bound_error(path, k, name, f"empty interval ({out['gt']}, {out['le']}]")
    return out


def read_rules(path) -> list[dict]:
    """The records of a rules file, checked: each has ``rank``, ``rule`` and ``bounds``.

    Raises
    ------
    RulesFileError
        The file is not JSON or not a list of rule records; the message names the place.
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
        if not isinstance(rec, dict) or not isinstance(rec.get("bounds"), dict):
            raise RulesFileError(f"{path}: rule {k} has no 'bounds' object")
        bounds = {str(n): _check_bound(path, k, n, b) for n, b in rec["bounds"].items()}
        out.append({**rec, "rank": rec.get("rank", k), "rule": str(rec.get("rule", "")),
                    "bounds": bounds})  # fmt: skip
    return out
