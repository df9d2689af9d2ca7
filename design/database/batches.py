"""A database grown in batches: asking for more rows later adds a batch, never rebuilds one.

A batched database is a folder of resumable databases
(:func:`~holofold.design.database.store.build_database`)
named ``{prefix}{a:06d}-{b:06d}``, each holding rows ``a .. b-1`` of one reproducible sample
(the sampler draws row i from the seed and i alone, so rows do not depend on how many are
drawn). :func:`grow` simulates what is missing and returns the first ``n`` rows.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import pandas as pd

__all__ = ["batch_spans", "grow"]


def batch_spans(folder: Path, n: int, prefix: str = "", covered: int = 0) -> list[tuple[int, int]]:
    """Row spans [a, b) from ``covered`` on: the batches on disk that continue one another,
    then what is missing up to ``n``."""
    pattern = re.compile(rf"{re.escape(prefix)}(\d{{6}})-(\d{{6}})$")
    spans = sorted(
        (int(m[1]), int(m[2]))
        for p in (folder.iterdir() if folder.is_dir() else ())
        if (m := pattern.match(p.name))
    )
    out = []
    for a, b in spans:
        if a == covered and covered < n:
            out.append((a, b))
            covered = b
    if covered < n:
        out.append((covered, n))
    return out


def grow(
    folder: Path,
    n: int,
    sample: Callable[[int, int], pd.DataFrame],
    simulate: Callable[[pd.DataFrame, Path], pd.DataFrame],
    *,
    prefix: str = "",
    covered: int = 0,
) -> tuple[pd.DataFrame, list[Path]]:
    """Rows ``covered .. n-1`` (at least; a batch on disk may reach past ``n``) simulated in
    batches under ``folder``: ``sample(start, count)`` draws the designs, ``simulate(designs,
    path)`` simulates them into a database folder. Returns the rows and the batch folders."""
    parts, used = [], []
    for a, b in batch_spans(folder, n, prefix, covered):
        path = folder / f"{prefix}{a:06d}-{b:06d}"
        parts.append(simulate(sample(a, b - a), path))
        used.append(path)
    table = pd.concat(parts, ignore_index=True) if parts else pd.DataFrame()
    return table, used
