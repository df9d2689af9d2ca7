"""What a scenario's designs can reach: each performance column's distribution.

Before asking for ``Zstiff > 5000`` a designer wants to know how stiff the designs of a
scenario are. :func:`distributions` gives, per column, quantiles over the successfully
simulated rows of a table (a database, or a small pilot sample that
:func:`pilot_sample` simulates); ``holofold describe`` prints them and ``holofold design``
shows them when its pilot finds no design meeting the target.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from holofold.design.database.row_status import failed_rows

__all__ = ["Distribution", "distributions", "distributions_text", "QUANTILES", "PILOT"]

#: the quantiles shown (min, 5 %, quartiles, 95 %, max)
QUANTILES = (0.0, 0.05, 0.25, 0.5, 0.75, 0.95, 1.0)
#: designs in a pilot sample (``holofold describe`` of a scenario; ``holofold design``'s first
#: batch): enough that a target met by 5 % of designs is seen with probability 0.92
PILOT = 50


@dataclass(frozen=True)
class Distribution:
    """One column over the successfully simulated rows of a table.

    Attributes
    ----------
    name, unit : str
    rows : int
        Rows with a finite value.
    failed : int
        Rows whose simulation failed (no value).
    quantiles : tuple of float
        At :data:`QUANTILES`, in ``unit`` (NaN without rows).
    """

    name: str
    unit: str
    rows: int
    failed: int
    quantiles: tuple[float, ...]

    def __post_init__(self):
        if len(self.quantiles) != len(QUANTILES):
            raise ValueError(
                f"{self.name}: {len(self.quantiles)} quantiles, expected {len(QUANTILES)}"
            )

    def to_json(self) -> dict:
        q = {
            f"{round(100 * p)}%": (v if math.isfinite(v) else None)
            for p, v in zip(QUANTILES, self.quantiles, strict=True)
        }
        return {
            "name": self.name,
            "unit": self.unit,
            "rows": self.rows,
            "failed": self.failed,
            "quantiles": q,
        }

    @classmethod
    def from_json(cls, d) -> Distribution:
        if not isinstance(d, dict) or not {"name", "unit", "rows", "quantiles"} <= set(d):
            raise ValueError(f"a distribution needs name, unit, rows and quantiles: {d!r:.80}")
        q = d["quantiles"]
        vals = tuple(
            math.nan if q.get(f"{round(100 * p)}%") is None else float(q[f"{round(100 * p)}%"])
            for p in QUANTILES
        )
        return cls(str(d["name"]), str(d["unit"]), int(d["rows"]), int(d.get("failed", 0)), vals)


def distributions(table: pd.DataFrame, columns: Sequence) -> list[Distribution]:
    """Per column (a :class:`~holofold.design.scenarios.Column` or a name), its quantiles over
    the rows of ``table`` whose simulation did not fail."""
    failed = failed_rows(table) if "status" in table else np.zeros(len(table), bool)
    out = []
    for c in columns:
        name, unit = (c, "") if isinstance(c, str) else (c.name, c.unit)
        if name not in table:
            continue
        v = table.loc[~failed, name].to_numpy(dtype=float)
        v = v[np.isfinite(v)]
        q = np.quantile(v, QUANTILES) if len(v) else np.full(len(QUANTILES), np.nan)
        out.append(Distribution(name, unit, int(len(v)), int(failed.sum()), tuple(map(float, q))))
    return out


def _g(v: float) -> str:
    from holofold.design.scenarios import format_value

    return "-" if not math.isfinite(v) else format_value(v, digits=4)


def distributions_text(dists: Sequence[Distribution], source: str = "") -> str:
    """A fixed-width table: column, unit, rows, then the quantiles."""
    head = ["column", "unit", "rows"] + [
        "min" if p == 0 else "max" if p == 1 else f"{round(100 * p)}%" for p in QUANTILES
    ]
    rows = [[d.name, d.unit or "-", str(d.rows), *(_g(v) for v in d.quantiles)] for d in dists]
    widths = [max(len(r[k]) for r in [head, *rows]) for k in range(len(head))]
    lines = [f"{source}" if source else None]
    for r in [head, *rows]:
        lines.append(
            "  ".join(
                x.rjust(w) if k > 1 else x.ljust(w)
                for k, (x, w) in enumerate(zip(r, widths, strict=True))
            )
        )
    return "\n".join(line for line in lines if line is not None)


def describe_source(
    source,
    *,
    n: int = PILOT,
    seed: int = 0,
    workers: int = 1,
    progress: bool | None = None,
    folder=None,
) -> tuple[list[Distribution], str]:
    """The performance columns' distributions of a database folder (``holofold generate``'s
    or a design folder's ``database/``), or of a pilot sample of ``n`` designs of a scenario
    (a name or a ``.toml`` file) simulated into ``folder`` (a temporary one if None).

    Returns the distributions and a line saying where they come from.
    """
    import json
    import tempfile
    from contextlib import nullcontext
    from pathlib import Path

    from holofold.design.database.sampling import sample_designs
    from holofold.design.database.store import build_database, load_database
    from holofold.design.scenarios import Column, load_scenario

    path = Path(str(source))
    if path.is_dir():
        tables = sorted(path.rglob("designs.parquet"))
        if not tables:
            raise ValueError(f"{source}: not a database folder (no designs.parquet inside)")
        parts, columns = [], {}
        for d in tables:
            try:
                info = json.loads((d.parent / "meta.json").read_text(encoding="utf-8"))
                parts.append(load_database(d.parent))
            except (OSError, ValueError, KeyError, TypeError) as exc:
                raise ValueError(f"{d.parent}: cannot read this database ({exc})") from None
            columns.update(info.get("performance") or {})
        table = pd.concat(parts, ignore_index=True)
        cols = [Column(k, str(u)) for k, u in columns.items()]
        return distributions(table, cols), f"{len(table)} simulated designs in {source}"
    sc = load_scenario(source)
    if int(n) != n or n < 1:
        raise ValueError(f"n = {n!r} pilot designs must be a whole number >= 1")
    designs = sample_designs(sc, int(n), seed=seed)
    with tempfile.TemporaryDirectory() if folder is None else nullcontext(folder) as where:
        table = build_database(
            sc, designs, Path(where), workers=workers, progress=progress, on_invalid="skip"
        )
    return (
        distributions(table, sc.performance),
        f"a pilot sample of {int(n)} designs of {sc.name} drawn in its feature ranges "
        f"(seed {seed})",
    )
