"""Sampling design features inside a scenario's ranges.

Every method is reproducible from ``seed`` and gives row ``i`` independently of how many rows
are drawn after it for ``random`` (each row has its own generator ``default_rng([seed, i])``),
so a database can be extended or resumed without changing the rows it already has. ``lhs`` and
``sobol`` spread the rows over the box (scipy.stats.qmc); they depend on ``n``.

Continuous features are drawn uniformly in ``[low, high]`` of their :class:`Column`;
categorical ones uniformly among ``choices``. ``ranges`` overrides either per feature.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from holofold.design.scenarios.base import Scenario

__all__ = ["sample_designs", "METHODS", "MAX_SAMPLES"]

METHODS = ("random", "lhs", "sobol")
#: most designs drawn in one call: a table of 5e6 rows is ~0.3 GB and days of simulation;
#: larger databases are built in batches (``start=``), each resumable
MAX_SAMPLES = 5_000_000


def _unit_samples(method: str, n: int, d: int, seed: int, start: int) -> np.ndarray:
    if method == "random":
        return np.array([np.random.default_rng([seed, start + i]).random(d) for i in range(n)])
    from scipy.stats import qmc

    if method == "lhs":
        u = qmc.LatinHypercube(d=d, seed=seed).random(start + n)
    else:
        sob = qmc.Sobol(d=d, scramble=True, seed=seed)
        m = int(np.ceil(np.log2(max(start + n, 2))))
        u = sob.random_base2(m)
    return u[start : start + n]


def _range_of(c, r, categorical: bool):
    """``r`` checked against the kind of feature ``c``: a (low, high) tuple of a categorical
    feature becomes its choices in [low, high]; a list of a continuous feature is refused."""
    if r is None:
        return None
    if categorical and isinstance(r, tuple):
        if len(r) != 2:
            raise ValueError(f"range of {c.name!r}: expected (low, high), got {r!r}")
        lo, hi = (float(v) for v in r)
        inside = [v for v in c.choices or () if lo <= v <= hi]
        if not inside:
            have = ", ".join(f"{v:g}" for v in c.choices or ()) or "none"
            raise ValueError(
                f"range of {c.name!r}: no choice of this categorical feature lies in "
                f"[{lo:g}, {hi:g}] (its choices: {have}); give the choices as a list"
            )
        return inside
    if not categorical and isinstance(r, list):
        raise ValueError(
            f"range of {c.name!r}: {c.name} is continuous; give (low, high), not a list of "
            f"values {r!r} (on the command line NAME=LOW:HIGH)"
        )
    return r


def sample_designs(
    scenario: Scenario,
    n: int,
    *,
    seed: int = 0,
    method: str = "random",
    ranges: Mapping[str, Sequence[float]] | None = None,
    fixed: Mapping[str, float] | None = None,
    start: int = 0,
) -> pd.DataFrame:
    """Draw ``n`` designs of ``scenario``.

    Parameters
    ----------
    scenario : Scenario
        Gives the feature columns, their ranges (``low``/``high``) and categorical ``choices``.
    n : int
        Number of rows (>= 1).
    seed : int
        Seed; the same seed gives the same rows.
    method : {"random", "lhs", "sobol"}
    ranges : mapping, optional
        ``name -> (low, high)`` (a tuple) for continuous features, ``name -> [choices...]``
        (a list) for categorical ones, replacing the paper's ranges. A tuple for a categorical
        feature keeps its choices in [low, high]; a list for a continuous one is refused.
    fixed : mapping, optional
        ``name -> value`` for features held constant.
    start : int
        Index of the first row (to extend a database: rows ``start .. start+n-1``).

    Returns
    -------
    DataFrame
        Columns: the scenario's required features (SI units), in its order, plus ``sample``
        (the row index used for seeding).
    """
    if method not in METHODS:
        raise ValueError(f"method = {method!r} is not one of {', '.join(METHODS)}")
    if not float(n).is_integer():
        raise ValueError(f"n = {n!r} designs must be a whole number")
    n = int(n)
    if n < 1:
        raise ValueError(f"n = {n} must be >= 1")
    if n > MAX_SAMPLES:
        gb = n * (len(scenario.features) + 1) * 8 / 1e9
        raise ValueError(
            f"n = {n:,} designs would need ~{gb:.3g} GB for the design table alone and, at ~30 "
            f"ms a design on one core, ~{n * 0.03 / 86400:.3g} core-days; at most "
            f"{MAX_SAMPLES:,} in one call: build a larger database in batches (start=...)"
        )
    ranges = dict(ranges or {})
    fixed = dict(fixed or {})
    names = [c.name for c in scenario.features]
    for k in list(ranges) + list(fixed):
        if k not in names:
            raise ValueError(f"unknown feature {k!r}; {scenario.name} has {', '.join(names)}")
    cols = [c for c in scenario.features if c.required or c.name in ranges or c.name in fixed]
    free = [c for c in cols if c.name not in fixed]
    u = _unit_samples(method, n, max(len(free), 1), int(seed), int(start))
    out: dict[str, np.ndarray] = {}
    for j, c in enumerate(free):
        r = _range_of(c, ranges.get(c.name), c.name in scenario.categorical or bool(c.choices))
        if c.name in scenario.categorical or c.choices:
            choices = np.asarray(r if r is not None else c.choices, float)
            if choices.size == 0:
                raise ValueError(f"categorical feature {c.name!r} has no choices to sample")
            out[c.name] = choices[
                np.minimum((u[:, j] * len(choices)).astype(int), len(choices) - 1)
            ]
        else:
            lo, hi = r if r is not None else (c.low, c.high)
            if lo is None or hi is None or not (np.isfinite(lo) and np.isfinite(hi)) or hi < lo:
                raise ValueError(
                    f"feature {c.name!r} needs a finite range low <= high, got {lo}, {hi}"
                )
            out[c.name] = lo + (hi - lo) * u[:, j]
    for k, v in fixed.items():
        out[k] = np.full(n, float(v))
    df = pd.DataFrame({c.name: out[c.name] for c in cols})
    df.insert(0, "sample", np.arange(start, start + n))
    return df
