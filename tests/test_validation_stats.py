"""The exchangeability statistic of validation/reproduce_gripper.py on synthetic ensembles."""

import runpy
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
exchangeability = runpy.run_path(str(ROOT / "validation" / "reproduce_gripper.py"))[
    "exchangeability"
]


def _ensembles(n=2000, K=7, seed=1):
    """Rows whose outcome is one of a few discrete values (as the chaotic gripper rows are)."""
    rng = np.random.default_rng(seed)
    centre = rng.uniform(1e-5, 1e-3, n)
    stable = rng.random(n) < 0.4

    def draw():
        factor = rng.choice([0.9, 1.0, 1.0, 1.03, 1.2], n)
        return centre * np.where(stable, 1.0, factor)

    return np.column_stack([draw() for _ in range(K)]), draw(), stable


def test_an_extra_draw_of_the_same_process_is_exchangeable():
    v, pub, stable = _ensembles()
    x = exchangeability(v, pub, rtol=1e-3)
    assert x["n"] == len(pub) and x["members"] == 7
    assert x["rank_hist"].sum() == len(pub)
    assert abs(x["agree_published"] - x["agree_members"]) < 0.03
    assert x["p_rank"] > 1e-3
    assert x["stable"] >= stable.sum() and x["stable_agree"] > 0.97
    # the published value lies inside the ensemble at least as often as (K-1)/(K+1) = 0.75
    assert x["inside"] > 0.74


def test_a_biased_published_column_is_detected():
    v, pub, _ = _ensembles()
    x = exchangeability(v, pub * 1.05, rtol=1e-3)
    assert x["p_rank"] < 1e-6
    assert x["agree_published"] < x["agree_members"] - 0.2
    # a bias only within the tolerance is not visible
    y = exchangeability(v, pub * (1 + 1e-4), rtol=1e-3)
    assert abs(y["agree_published"] - y["agree_members"]) < 0.03


def test_rows_with_non_finite_values_are_left_out():
    v, pub, _ = _ensembles(n=50)
    v[3, 2] = np.nan
    pub[7] = np.inf
    assert exchangeability(v, pub, rtol=1e-3)["n"] == 48


@pytest.mark.parametrize("rtol", [0.0, 1e-2])
def test_integer_steps_with_ties(rtol):
    rng = np.random.default_rng(0)
    base = rng.integers(40, 300, 500).astype(float)
    v = base[:, None] + rng.choice([0, 0, 0, 1], (500, 5))
    pub = base + rng.choice([0, 0, 0, 1], 500)
    x = exchangeability(v, pub, rtol)
    assert x["p_rank"] > 1e-3
    assert x["inside"] > 0.9


def test_ensemble_picture(tmp_path):
    import pandas as pd

    plot = runpy.run_path(str(ROOT / "validation" / "reproduce_gripper.py"))["plot_ensemble"]
    v, pub, _ = _ensembles(n=40, K=4)
    table = pd.DataFrame(
        {"Pattern": np.repeat([2.0, 3.0], 20), "stiff": v[:, 0], "stiff_published": pub}
        | {f"stiff_m{k}": v[:, k] for k in range(1, 4)}
    )
    png = tmp_path / "ens.png"
    assert plot(table, png) == [2, 3]
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ValueError, match="ensemble columns"):
        plot(table[["Pattern", "stiff", "stiff_published"]], tmp_path / "no.png")
