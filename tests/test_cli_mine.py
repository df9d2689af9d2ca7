"""``holofold mine``: output, agreement with the library, validation before any output."""

import json

import numpy as np
import pandas as pd
import pytest

from holofold.cli import main
from holofold.design import read_rules


def test_mine_prints_the_summary_and_writes_strict_json(reference_data, tmp_path, capsys):
    db = reference_data.path("data0_SingleMiura")
    out = tmp_path / "rules.json"
    rc = main(
        ["mine", str(db), "--target", "axialstiff60 < 6000", "--seed", "2", "--json", str(out)]
    )
    assert rc == 0
    text = capsys.readouterr().out
    assert "met by 70 rows, 7.0 %" in text
    assert "600 train / 400 test rows (seed 2)" in text
    assert text.count("    train:    precision") == 3 and text.count("    held-out: precision") == 3
    assert text.count("    estimate: precision") == 3 and "95 % interval" in text
    assert "the target does not depend on: " in text
    assert " mm" in text and " deg" in text  # thresholds in display units
    assert [r.rank for r in read_rules(out)] == [1, 2, 3]
    recs = json.loads(out.read_text())
    assert all(r["display"]["tcrease"]["unit"] == "mm" for r in recs if "tcrease" in r["bounds"])
    for r in recs:
        lo, hi = r["estimate"]["interval"]
        assert 0 <= lo <= r["estimate"]["precision"] <= hi <= 1 and r["estimate"]["rows"] > 0
    assert "axialstiff60" not in json.dumps([r["bounds"] for r in recs])
    assert "NaN" not in out.read_text() and "Infinity" not in out.read_text()


def _synthetic_csv(tmp_path):
    rng = np.random.default_rng(0)
    n = 600
    df = pd.DataFrame(
        {
            "m": rng.choice([8, 12, 16, 24], size=n),
            "t": rng.uniform(1e-3, 5e-3, size=n),
            "w": rng.uniform(0, 1, size=n),
        }
    )
    df["k"] = (df["m"] >= 16) * 1000 + 1e5 * df["t"] + rng.normal(0, 10, size=n)
    path = tmp_path / "db.csv"
    df.to_csv(path, index=False)
    return path


@pytest.mark.slow
def test_mine_csv_with_features_categorical_and_plot(tmp_path, capsys):
    db = _synthetic_csv(tmp_path)
    png = tmp_path / "r.png"
    rc = main(
        [
            "mine",
            str(db),
            "--target",
            "k > 1300",
            "--features",
            "m,t,w",
            "--categorical",
            "m",
            "--rules",
            "2",
            "--trees",
            "30",
            "--plot",
            str(png),
        ]
    )
    assert rc == 0
    out = capsys.readouterr().out
    assert "categorical: m" in out
    assert "m in {16, 24}" in out and "m >" not in out
    assert png.stat().st_size > 1000


@pytest.mark.parametrize(
    "extra, match",
    [
        (["--target", "Zstif > 800"], "unknown column 'Zstif' at position 0"),
        (["--target", "k > 1300 &"], "position 10"),
        (["--target", "k > 1300", "--features", "m,k"], "'k' is a performance column"),
        (["--target", "k > 1300", "--features", "m,q"], "feature 'q' is not a column"),
        (["--target", "k > 1300", "--features", "m,t", "--categorical", "w"], "'w' is not among"),
        (["--target", "k > 1e9", "--features", "m,t"], "met by 0 of 600 rows"),
        (["--target", "k > 1300"], "list them with --features"),
        (
            ["--target", "k > 1300", "--features", "t", "--rules", "0"],
            "--rules must be an int in the range [1, inf)",
        ),
        (["--target", "k > 1300", "--features", "t", "--plot", "X.gif"], "expected one of"),
    ],
)
def test_bad_input_writes_nothing(tmp_path, capsys, extra, match):
    db = _synthetic_csv(tmp_path)
    out_json = tmp_path / "o.json"
    args = ["mine", str(db), *extra, "--json", str(out_json)]
    if "--plot" not in extra:
        args += ["--plot", str(tmp_path / "o.png")]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.startswith("holofold mine: error:") and match in err
    assert not out_json.exists() and not (tmp_path / "o.png").exists()


def test_headerless_txt_needs_columns(tmp_path, capsys):
    rng = np.random.default_rng(1)
    a = rng.uniform(size=(300, 2))
    np.savetxt(tmp_path / "mydb.txt", np.column_stack([a, a[:, 0] + a[:, 1]]), delimiter=",")
    assert main(["mine", str(tmp_path / "mydb.txt"), "--target", "s > 1.5"]) == 2
    assert "no header" in capsys.readouterr().err
    rc = main(
        [
            "mine",
            str(tmp_path / "mydb.txt"),
            "--columns",
            "x y s",
            "--features",
            "x,y",
            "--target",
            "s > 1.5",
            "--trees",
            "20",
        ]
    )
    assert rc == 0
    assert "rule 1:" in capsys.readouterr().out


def test_the_papers_method_stays_selectable(reference_data, tmp_path, capsys):
    """--scoring train --ranking fbeta is the paper's method: its ranking (the default) on
    leaf bounds that are not tightened."""
    from holofold.design import ForestRuleMiner, holdout, parse_target

    db = reference_data.path("data0_SingleMiura")
    out = tmp_path / "paper.json"
    argv = ["mine", str(db), "--target", "axialstiff60 < 6000", "--seed", "1", "--json", str(out)]
    assert main([*argv, "--scoring", "train", "--ranking", "fbeta"]) == 0
    df = reference_data.load("data0_SingleMiura")
    ref = holdout(
        ForestRuleMiner(tighten=False),
        df[["tcrease", "tpanel", "W", "gama"]],
        parse_target("axialstiff60 < 6000").evaluate(df),
        random_state=1,
    )
    assert ref.miner.get_params()["beta"] == 0.2
    assert [r.text() for r in read_rules(out)] == ref.rules["rule"].tolist()
    assert main(argv) == 0  # the default: the same ranking, bounds tightened
    assert [r.text() for r in read_rules(out)] != ref.rules["rule"].tolist()
    capsys.readouterr()


def test_the_papers_grid_knobs_reach_the_miner(tmp_path, capsys, monkeypatch):
    """--ccp-alpha, --criterion and --max-samples set the miner's parameters (Figs. S6-S8);
    a bad value is one line naming the option."""
    import holofold.design.rules.mining as mining

    db = _synthetic_csv(tmp_path)
    seen = {}
    real = mining.holdout

    def spy(miner, *a, **kw):
        seen.update(miner.get_params())
        return real(miner, *a, **kw)

    monkeypatch.setattr(mining, "holdout", spy)
    argv = ["mine", str(db), "--target", "k > 1300", "--features", "m,t,w", "--trees", "10"]
    assert main([*argv, "--ccp-alpha", "0.001", "--criterion", "gini", "--max-samples", "0.7"]) == 0
    assert (seen["ccp_alpha"], seen["criterion"], seen["max_samples"]) == (0.001, "gini", 0.7)
    assert main([*argv, "--max-samples", "200"]) == 0 and seen["max_samples"] == 200
    capsys.readouterr()
    for flag, value, match in (
        ("--ccp-alpha", "-1", "--ccp-alpha must be a float in the range [0, inf)"),
        ("--max-samples", "0", "--max-samples must be an int in the range [1, inf)"),
        ("--max-samples", "1.5", "or a float in the range (0, 1], got 1.5"),
    ):
        assert main([*argv, flag, value]) == 2
        err = capsys.readouterr().err.strip()
        assert match in err and "\n" not in err
