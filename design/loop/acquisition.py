"""Where to simulate next: designs where the rule miner's forest says the target is likely.

For a rare target (met by 1 % of the design space or less) a random database holds a handful of
designs that meet it, too few for a rule. :func:`likely_designs` draws many random candidate
designs (free: nothing is simulated), asks the fitted rule miner
(:class:`~holofold.design.rules.ForestRuleMiner`) for its vote on each (``forest_probability``)
and picks the designs to simulate at random with probability proportional to the vote raised to
``power``: most where the target is likely, some elsewhere (forest-likelihood sampling, as in
forest-based generative inverse design). The design loop's refinement rounds draw half of their
designs with it and half inside the best rule (``strategy="mixed"``, the default) or all of them
(``strategy="likely"``); ``benchmarks/rare_targets.md`` measures both: by the vote alone the loop
verified every run on four targets met by about 1 % of random designs and none on two narrow
window targets, which the half inside the best rule reaches in 5 of 8 runs.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from holofold.design.database.sampling import sample_designs

__all__ = ["likely_designs", "CANDIDATES"]

#: random candidate designs scored per call
CANDIDATES = 20_000


def likely_designs(
    scenario,
    miner,
    n: int,
    *,
    seed: int,
    start: int = 0,
    candidates: int = CANDIDATES,
    power: float = 2.0,
) -> pd.DataFrame:
    """``n`` new designs of ``scenario`` drawn where ``miner``'s forest votes for the target.

    Parameters
    ----------
    scenario : Scenario
    miner : fitted ForestRuleMiner
        Fitted on the scenario's designs; its ``feature_names_`` are columns of the scenario.
    n : int
        Designs to return (at most ``candidates``).
    seed : int
        Seeds the candidates and the draw.
    start : int
        ``sample`` number of the first design returned.
    candidates : int
        Random candidate designs scored.
    power : float
        Sharpness: the chance of a candidate is proportional to ``vote ** power`` (0: uniform).

    Returns
    -------
    DataFrame
        ``sample`` and the scenario's feature columns, ``n`` rows.
    """
    n, candidates = int(n), int(candidates)
    if not 0 < n <= candidates:
        raise ValueError(f"n = {n} designs must be in [1, candidates = {candidates}]")
    pool = sample_designs(scenario, candidates, seed=seed, start=10**7)
    vote = miner.forest_probability(pool[list(miner.feature_names_)])
    weight = np.asarray(vote, dtype=float) ** float(power) + 1e-12
    rng = np.random.default_rng([int(seed), 0x1A7E])
    pick = np.sort(rng.choice(candidates, n, replace=False, p=weight / weight.sum()))
    out = pool.iloc[pick].reset_index(drop=True)
    out["sample"] = np.arange(start, start + n)
    return out
