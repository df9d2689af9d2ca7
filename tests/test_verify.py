"""Verifying mined rules by fresh simulations, and the end-to-end demo."""

import json

import numpy as np
import pandas as pd
import pytest

from holofold.cli import main
from holofold.design import verify_rules, write_verification
from holofold.design.rules.verify import rule_ranges, verify_rule
from holofold.design.scenarios import get_scenario


def test_rule_ranges_intersect_the_scenario_box():
    arch = get_scenario("arch")
    r = rule_ranges(
        arch, {"m": {"in": [8]}, "offset": {"gt": None, "le": 0.2}, "W": {"gt": 0.0035, "le": 0.01}}
    )
    assert r["m"] == [8.0]
    assert r["offset"] == (0.1, 0.2)
    assert r["W"] == (0.0035, 0.004)
    with pytest.raises(ValueError, match="not a feature"):
        rule_ranges(arch, {"Zstiff": {"gt": 1, "le": None}})
    with pytest.raises(ValueError, match="outside the scenario's range"):
        rule_ranges(arch, {"W": {"gt": 0.01, "le": None}})


def test_verify_counts_designs_meeting_the_target():
    # thin, soft creases and thin panels make a soft cell: the paper's axialstiff60 < 6000 rule
    box = {"tcrease": {"gt": None, "le": 0.6e-3}, "tpanel": {"gt": None, "le": 1.2e-3},
           "W": {"gt": 3.5e-3, "le": None}}  # fmt: skip
    v = verify_rule("single-miura", box, "axialstiff60 < 6000", n=8, seed=1)
    assert v.n_ok == 8 and v.n_failed == 0
    d = v.designs
    assert d["tcrease"].le(0.6e-3).all() and d["W"].ge(3.5e-3).all()
    assert v.n_meeting == int((d["axialstiff60"] < 6000).sum())
    assert v.precision == v.n_meeting / 8
    lo, hi = v.interval
    assert 0 <= lo <= v.precision <= hi <= 1
    stiff = {"tcrease": {"gt": 0.95e-3, "le": None}, "tpanel": {"gt": 5.5e-3, "le": None}}
    assert verify_rule("single-miura", stiff, "axialstiff60 < 6000", n=4).n_meeting == 0


@pytest.mark.parametrize(
    "argv, match",
    [(["-n", "5"], "samples = 5 must be an integer >= 20"),
     (["--verify", "0"], "verify = 0 must be an integer >= 1"),
     (["--target", "Zstif > 1"], "unknown column"), (["--workers", "0"], "workers")],
)  # fmt: skip
def test_demo_refuses_bad_arguments_before_writing(tmp_path, capsys, argv, match):
    out = tmp_path / "demo"
    assert main(["demo", "-o", str(out), *argv]) == 2
    assert match in capsys.readouterr().err and not out.exists()


def test_verify_rejects_bad_rules_file(tmp_path):
    bad = tmp_path / "rules.json"
    bad.write_text("{not json")
    assert main(["verify", "arch", "--rules", str(bad), "--target", "Zstiff > 1"]) == 2
    bad.write_text(json.dumps([{"rule": "x"}]))
    assert main(["verify", "arch", "--rules", str(bad), "--target", "Zstiff > 1"]) == 2
    bad.write_text(json.dumps([{"bounds": {"m": {"in": [8]}}}]))
    assert main(["verify", "arch", "--rules", str(bad), "--target", "Zsniff > 1"]) == 2


def test_verify_rules_checks_every_rule_first_and_writes_strict_json(tmp_path):
    soft = {"tcrease": {"gt": None, "le": 0.6e-3}, "tpanel": {"gt": None, "le": 1.2e-3}}
    rules = [{"rule": "soft", "bounds": soft}, {"rule": "bad", "bounds": {"W": {"gt": 1.0}}}]
    with pytest.raises(ValueError, match="outside the scenario's range"):
        verify_rules("single-miura", rules, "axialstiff60 < 6000", 3)
    res = verify_rules("single-miura", rules[:1], "axialstiff60 < 6000", 3, seed=4)
    assert len(res) == 1 and res[0].n_ok == 3
    # rule i is sampled with seed + i, as verify_rule would be
    alone = verify_rule("single-miura", soft, "axialstiff60 < 6000", 3, seed=5)
    assert alone.designs["tcrease"].tolist() == res[0].designs["tcrease"].tolist()
    report = write_verification(tmp_path / "v", rules[:1], res)
    assert json.loads((tmp_path / "v" / "verify.json").read_text()) == report
    assert (tmp_path / "v" / "verify_rule1.csv").is_file()


@pytest.mark.parametrize(
    "bounds, match",
    [([1, 2], "must be a mapping"), ({"offset": [0.1, 0.2]}, "bounds of 'offset'"),
     ({"offset": None}, "bounds of 'offset'"), ({"offset": "wide"}, "bounds of 'offset'"),
     ({"m": {"in": 8}}, "'m': levels must be a list"), ({"m": {"in": ["8"]}}, "finite numbers"),
     ({"offset": {"gt": "0.1"}}, "'gt' = '0.1' must be a number"),
     ({"offset": {"le": True}}, "must be a number"), ({"offset": {"gt": 0.1, "lt": 1}}, "must be")],
)  # fmt: skip
def test_malformed_rule_bounds_are_refused_in_one_line(bounds, match):

    with pytest.raises(ValueError, match=match) as err:
        rule_ranges(get_scenario("arch"), bounds)
    assert "\n" not in str(err.value)


def test_an_interval_over_a_categorical_feature_gives_its_levels():

    arch = get_scenario("arch")
    got = rule_ranges(arch, {"m": {"gt": 10, "le": None}, "offset": {"gt": None, "le": 0.2}})
    assert got == {"m": [12.0, 16.0, 24.0], "offset": (0.10, 0.2)}


def test_verify_shows_what_mining_said_beside_the_verified_precision(tmp_path, capsys):
    soft = {"tcrease": {"gt": None, "le": 0.6e-3}, "tpanel": {"gt": None, "le": 1.2e-3}}
    rules = tmp_path / "rules.json"
    mined = {"rule": "soft", "bounds": soft, "test": {"precision": 0.9, "support": 30},
             "estimate": {"precision": 0.875, "interval": [0.78, 0.94], "rows": 55}}  # fmt: skip
    bare = {"rule": "bare", "bounds": soft, "estimate": {"precision": None}}
    rules.write_text(json.dumps([mined, bare]))
    argv = ["verify", "single-miura", "--rules", str(rules), "--target", "axialstiff60 < 6000",
            "-n", "3"]  # fmt: skip
    assert main(argv) == 0
    out = capsys.readouterr().out.splitlines()
    shown = [line.strip() for line in out if line.strip().startswith("mined with")]
    assert shown == [
        "mined with: estimate 0.875 (95 % interval 0.780-0.940), held-out precision 0.900"
    ]  # the second rule carries no usable estimate: nothing is made up


def test_holofold_verify_is_the_loops_resumable_verification(tmp_path, capsys):
    """With -o the fresh designs go to resumable databases, as the design loop's do: a second
    run simulates nothing, a larger -n adds a batch with the first designs unchanged."""
    soft = {"tcrease": {"gt": None, "le": 0.6e-3}, "tpanel": {"gt": None, "le": 1.2e-3}}
    rules = tmp_path / "rules.json"
    rules.write_text(json.dumps([{"rule": "soft", "bounds": soft}]))
    out = tmp_path / "v"
    argv = ["verify", "single-miura", "--rules", str(rules), "--target", "axialstiff60 < 6000",
            "-o", str(out)]  # fmt: skip
    assert main([*argv, "-n", "4"]) == 0
    (folder,) = [p for p in out.iterdir() if p.is_dir()]
    assert folder.name.startswith("rule1-") and [p.name for p in folder.iterdir()] == [
        "000000-000004"]  # fmt: skip
    chunks = sorted(folder.rglob("part-*.parquet"))
    stamps = [p.stat().st_mtime_ns for p in chunks]
    first = json.loads(capsys.readouterr().out.splitlines()[-1])
    assert main([*argv, "-n", "4"]) == 0
    assert [p.stat().st_mtime_ns for p in chunks] == stamps  # nothing simulated again
    assert json.loads(capsys.readouterr().out.splitlines()[-1]) == first
    assert main([*argv, "-n", "6"]) == 0
    assert sorted(p.name for p in folder.iterdir()) == ["000000-000004", "000004-000006"]
    got = json.loads(capsys.readouterr().out.splitlines()[-1])
    assert got[0]["simulated"] == 6
    # the loop's verification of the same rule with the same seed gives the same designs
    from holofold.design import parse_target, verify_rules

    direct = verify_rules("single-miura", [{"bounds": soft}], parse_target("axialstiff60 < 6000"),
                          6, folder=tmp_path / "w")[0]  # fmt: skip
    csv = pd.read_csv(out / "verify_rule1.csv")
    assert np.allclose(csv["tcrease"], direct.designs["tcrease"])


def test_a_failed_fresh_design_counts_as_one_that_misses_the_target():
    # the parabolic arch of validation/last_mile: 26 of 28 simulated designs met the target and
    # 22 were self-overlapping strips; the rule's precision is 26 / 50, not 26 / 28
    from holofold.design.loop.rounds import Counts
    from holofold.design.rules.targets import parse_target
    from holofold.design.rules.verify import Verification

    c = Counts(simulated=28, failed=22, meeting=26)
    assert c.tried == 50 and c.precision == pytest.approx(0.52)
    lo, hi = c.interval
    assert lo < 0.52 < hi < 0.7
    res = pd.DataFrame({
        "k": [1.0, 2.0, 3.0, np.nan],
        "status": ["converged", "converged", "converged", "failed: the strip overlaps itself"],
    })  # fmt: skip
    v = Verification.of(res, parse_target("k > 1.5", ["k"]))
    assert (v.n_ok, v.n_failed, v.n_meeting) == (3, 1, 2)
    assert v.precision == 0.5 and v.summary()["precision"] == 0.5
    assert "2/4 = 0.500" in v.describe() and "1 failed, counted as not meeting it" in v.describe()
