"""The exchangeability statistic of validation/reproduce_gripper.py on synthetic ensembles."""

import runpy
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


def _run_script(name: str) -> dict:
    """The namespace of a validation script (its sibling imports need validation/ on the path)."""
    with pytest.MonkeyPatch.context() as mp:
        mp.syspath_prepend(str(ROOT / "validation"))
        return runpy.run_path(str(ROOT / "validation" / name))


NS = _run_script("reproduce_gripper.py")
exchangeability = NS["exchangeability"]


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


def test_rank_is_uniform_for_continuous_noise_of_the_tolerance_scale():
    """The rank uses exact ties: tolerance ties are intransitive and would bias it."""
    rng = np.random.default_rng(0)
    w = 1 + 1e-3 * rng.standard_normal((20000, 9))
    x = exchangeability(w[:, 1:], w[:, 0], rtol=1e-3)
    share = x["rank_hist"] / x["rank_hist"].sum()
    assert np.abs(share - 1 / 9).max() < 0.01
    assert x["p_rank"] > 1e-3
    # pairwise member differences of N(0, s) noise: |a - b| ~ s sqrt(2) |N(0, 1)|
    assert x["pair_median"] == pytest.approx(1e-3 * np.sqrt(2) * 0.6745, rel=0.05)


def test_a_less_noisy_ensemble_is_told_apart():
    """Members with half the published noise: agreement and rank both show it."""
    rng = np.random.default_rng(1)
    centre = rng.uniform(1, 2, 5000)
    v = centre[:, None] * (1 + 0.5e-3 * rng.standard_normal((5000, 6)))
    pub = centre * (1 + 1e-3 * rng.standard_normal(5000))
    x = exchangeability(v, pub, rtol=1e-3)
    assert x["agree_published"] < x["agree_members"] - 0.1
    assert x["p_rank"] < 1e-6
    assert x["rank_hist"][0] > x["rank_hist"][3] and x["rank_hist"][6] > x["rank_hist"][3]


def _saved_run(n=40, K=4, arccos=True):
    import pandas as pd

    v, pub, _ = _ensembles(n=n, K=K)
    steps = np.full((n, K), 100.0)
    table = pd.DataFrame(
        {
            "Pattern": np.repeat([2.0, 3.0], n // 2),
            "L1": 5e-3,
            "L2": 3e-3,
            "finalQ_published": 0.1,
            "stiff": v[:, 0],
            "step": steps[:, 0],
            "stiff_published": pub,
        }
    )
    for k in range(1, K):
        table[f"stiff_m{k}"] = v[:, k]
        table[f"step_m{k}"] = steps[:, k]
        table[f"angle_m{k}"] = "arccos" if (arccos and k % 2) else "atan2"
    return table


def test_ensemble_arrays_and_groups():
    ns = NS
    table = _saved_run()
    steps, stiff, groups = ns["ensemble_arrays"](table)
    assert steps.shape == stiff.shape == (40, 4)
    np.testing.assert_array_equal(stiff[:, 2], table["stiff_m2"])
    assert groups == {
        "all": [0, 1, 2, 3],
        "with the arccos angle": [1, 3],
        "with the atan2 angle": [0, 2],
    }
    assert list(ns["ensemble_arrays"](_saved_run(arccos=False))[2]) == ["all"]


def test_ensemble_picture(tmp_path):
    plot = NS["plot_ensemble"]
    table = _saved_run()
    png = tmp_path / "ens.png"
    assert plot(table, png) == [2, 3]
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ValueError, match="ensemble columns"):
        plot(table[["Pattern", "stiff", "stiff_published"]], tmp_path / "no.png")
    with pytest.raises(ValueError, match="not a --save CSV"):
        plot(table.drop(columns="stiff_published"), tmp_path / "no.png")
    assert not (tmp_path / "no.png").exists()


def test_command_line_rejects_meaningless_combinations(capsys):
    main = NS["main"]
    for argv in (
        ["--ensemble", "1"],
        ["--random", "3", "--ensemble", "4"],
        ["--plot", "x.png"],
        ["--ensemble-arccos"],
        ["--from-csv", "/nonexistent.csv"],
    ):
        with pytest.raises(SystemExit) as exc:
            main(argv)
        assert exc.value.code == 2, argv
    assert "--from-csv /nonexistent.csv" in capsys.readouterr().err


def test_report_of_a_saved_run(tmp_path, capsys):
    main = NS["main"]
    csv = tmp_path / "ens.csv"
    _saved_run().to_csv(csv, index=False)
    assert main(["--from-csv", str(csv), "--plot", str(tmp_path / "ens.png")]) == 0
    out = capsys.readouterr().out
    assert out.count("members all (4 runs per row)") == 2  # one per pattern
    assert "members with the arccos angle (2 runs per row)" in out
    assert "member vs member median" in out
    assert (tmp_path / "ens.png").exists()
