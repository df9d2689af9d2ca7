"""Limits before work (issue 15, section 2): sizes that drive memory or time are refused with
one line naming the value, the estimate or limit and, where sensible, the override."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from holofold.cli import main
from holofold.design import get_scenario, read_scenario, shipped_text
from holofold.design.rules.miner import FewRulesWarning
from holofold.design.rules.mining import (
    MAX_MINING_BYTES,
    MAX_MINING_SECONDS,
    MAX_TREE_DEPTH,
    check_mining_size,
    mine_rules,
    mining_estimate,
)
from holofold.design.scenarios import ScenarioFileError
from holofold.fitting import MAX_M
from holofold.geometry import MAX_PANELS


@pytest.fixture(scope="module")
def table():
    rng = np.random.default_rng(0)
    X = rng.uniform(0, 1, (80, 3))
    df = pd.DataFrame(X, columns=["a", "b", "c"])
    df["perf"] = X[:, 0] + 0.1 * rng.normal(size=80)
    return df


def test_the_estimate_matches_the_measured_constants():
    # 10,000 trees on 48 training rows (24 per tree) took 48-51 s, 100 trees on 1800 rows 1.3 s
    assert mining_estimate(48, 10_000)[1] == pytest.approx(53.6, rel=0.01)
    nbytes, seconds = mining_estimate(1800, 100)
    assert 0.5 < seconds < 3 and nbytes < 2**30


@pytest.mark.parametrize(
    "params, match",
    [
        ({"n_estimators": 1_000_000}, r"n_estimators \(--trees\) = 1000000 trees on 48 training "
         r"rows would take an estimated 11.2 GiB of memory \(limit 4 GiB\) and 1.49 h on one "
         r"thread \(limit 300 s\); use fewer trees, or force it \(force=True, holofold mine "
         r"--force\)"),
        ({"max_depth": 10**20}, rf"max_depth \(--depth\) = 10{{20}} is over the limit of "
         rf"{MAX_TREE_DEPTH}"),
        ({"n_jobs": 100_000}, r"n_jobs \(--jobs\) = 100000 threads is over the limit of"),
    ],
)  # fmt: skip
def test_mining_sizes_are_refused_before_training(table, params, match):
    with pytest.raises(ValueError, match=match):  # before training (it would take hours)
        mine_rules(table, "perf > 0.5", features=["a", "b", "c"], **params)


def test_force_lets_a_large_forest_through_and_progress_is_told():
    nbytes, seconds = check_mining_size(48, {"n_estimators": 10**6}, force=True)
    assert nbytes > MAX_MINING_BYTES and seconds > MAX_MINING_SECONDS


def test_progress_line_before_long_training(table, monkeypatch):
    import holofold.design.rules.mining as mining

    monkeypatch.setattr(mining, "SECONDS_PER_TREE", 1.0)  # pretend: 1 s per tree
    lines = []
    with pytest.warns(FewRulesWarning):  # 20 trees on 48 noisy rows: fewer distinct rules
        mine_rules(table, "perf > 0.5", features=["a", "b", "c"], n_estimators=20,
                   progress=lines.append)  # fmt: skip
    assert lines == [lines[0]] and lines[0].startswith("training 20 trees on 48 rows: about 20")


def test_cli_mine_refuses_a_million_trees_in_one_line(tmp_path, capsys, table):
    db = tmp_path / "db.csv"
    table.to_csv(db, index=False)
    base = ["mine", str(db), "--target", "perf > 0.5", "--features", "a,b,c"]
    for extra, match in [
        (["--trees", "1000000"], "--trees) = 1000000 trees on 48 training rows"),
        (["--depth", "99999999999999999999"], "--depth) = 99999999999999999999 is over"),
        (["--jobs", "100000"], "--jobs) = 100000 threads"),
    ]:
        assert main(base + extra) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert err[-1].startswith("holofold mine: error: ") and match in err[-1], err


def test_sheet_rows_over_the_panel_limit_are_invalid_not_simulated():
    canopy = get_scenario("canopy")
    row = {"pattern": 1, "m": 1_000_000, "n": 6, "tcrease": 8e-4, "tpanel": 3e-3, "W": 2e-3}
    msg = f"m = 1000000 x n = 6 = 6000000 panels is over the limit of {MAX_PANELS}"
    assert any(msg in p for p in canopy.check(row))
    with pytest.raises(ValueError, match=msg):
        canopy.evaluate(row)
    ok = {**row, "m": MAX_PANELS // 6 // 2 * 2, "pattern": 2}  # TMP: checked further, not size
    assert not any("panels is over" in p for p in canopy.check(ok))


def test_strip_rows_over_the_fit_limit_are_invalid():
    arch = get_scenario("arch")
    row = {"m": 100_000, "tcrease": 8e-4, "tpanel": 3e-3, "W": 2e-3, "offset": 0.2,
           "stripeWidth": 0.02, "extrude": 0.1}  # fmt: skip
    assert arch.check(row) == [f"m = 100000 is over the limit of {MAX_M} (4m panels; "
                               "docs/limits.md)"]  # fmt: skip
    assert arch.check({**row, "m": MAX_M}) == []


def test_cli_evaluate_canopy_with_a_huge_m_is_refused_at_once(tmp_path, capsys):
    rows = tmp_path / "rows.csv"
    rows.write_text("pattern,m,n,tcrease,tpanel,W\n1,1000000,6,8e-4,3e-3,2e-3\n")
    assert main(["evaluate", "canopy", str(rows), "-o", str(tmp_path / "r.csv")]) == 2
    assert "6000000 panels is over the limit of 10000" in capsys.readouterr().err
    assert not (tmp_path / "r.csv").exists()


def test_a_sheet_file_whose_largest_sheet_is_over_the_limit_is_refused(tmp_path):
    text = shipped_text("canopy").replace("m = { choices = [24, 30, 36] }",
                                          "m = { choices = [24, 30, 3600] }")  # fmt: skip
    path = tmp_path / "big.toml"
    path.write_text(text)
    with pytest.raises(ScenarioFileError, match="the largest sheet has 43200 panels; at most"):
        read_scenario(path)


def test_a_strip_file_whose_m_is_over_the_fit_limit_is_refused(tmp_path):
    text = shipped_text("arch").replace("m = { choices = [8, 12, 16, 24] }",
                                        "m = { choices = [8, 5000] }")  # fmt: skip
    path = tmp_path / "big.toml"
    path.write_text(text)
    with pytest.raises(ScenarioFileError, match=rf"\[features\] m = .*: at most {MAX_M}"):
        read_scenario(path)
