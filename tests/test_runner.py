"""Batch evaluation: validation before simulation, warnings, per-row failures, row order."""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd
import pytest
from _toy import toy_scenario

from holofold.design.database.runner import DesignTableError, evaluate_designs, validate_designs
from holofold.design.scenarios import Scenario, get_scenario
from holofold.mechanics.status import Status


def _toy_check(row):
    return [] if row["a"] > 0 else [f"a = {row['a']!r} must be > 0"]


def _toy_evaluate(row):
    if row["a"] == 13:
        raise RuntimeError("unlucky design\nsecond line")
    return {"double": 2 * row["a"], "status": "converged"}


TOY = toy_scenario(_toy_evaluate, _toy_check)


def test_missing_column_is_reported():
    with pytest.raises(DesignTableError, match="missing column.*gama"):
        validate_designs(get_scenario("single-miura"), pd.DataFrame({"tcrease": [1e-3]}))


def test_invalid_rows_are_reported_with_numbers_before_any_simulation(monkeypatch):
    calls = []
    sc = Scenario(**{**TOY.__dict__, "evaluate": lambda r: calls.append(r) or {}})
    df = pd.DataFrame({"a": [1.0, -2.0, 3.0, "x", np.nan]})
    with pytest.raises(DesignTableError) as exc:
        evaluate_designs(sc, df)
    msg = str(exc.value)
    assert "3 invalid row(s)" in msg
    assert "row 2: a = -2.0 must be > 0" in msg
    assert "row 4: a = 'x' is not a number" in msg
    assert "row 5: a is missing" in msg
    assert calls == []


def test_out_of_range_values_only_warn(caplog):
    df = pd.DataFrame({"a": [0.5, 2.0, 20.0, 30.0]})
    checked = validate_designs(TOY, df)
    assert len(checked.rows) == 4
    assert len(checked.warnings) == 1
    assert "a = 0.5 m is outside the paper's sampling range [1, 10]" in checked.warnings[0]
    assert "3 row(s) in all" in checked.warnings[0]
    with caplog.at_level(logging.WARNING):
        res = evaluate_designs(TOY, df)
    assert "sampling range" in caplog.text
    assert res["double"].tolist() == [1.0, 4.0, 40.0, 60.0]


@pytest.mark.parametrize("workers", [1, 2])
def test_failed_row_is_recorded_and_batch_goes_on(workers):
    df = pd.DataFrame({"id": ["p", "q", "r", "s"], "a": [1.0, 13.0, 3.0, 4.0]}, index=[7, 5, 3, 1])
    res = evaluate_designs(TOY, df, workers=workers)
    assert list(res.index) == [7, 5, 3, 1]
    assert res["id"].tolist() == ["p", "q", "r", "s"]
    assert res["double"].iloc[[0, 2, 3]].tolist() == [2.0, 6.0, 8.0]
    assert np.isnan(res["double"].iloc[1])
    assert res["status"].iloc[1] == "failed: RuntimeError: unlucky design"
    assert (res["status"].iloc[[0, 2, 3]] == "converged").all()


def test_performance_columns_in_input_are_replaced():
    df = pd.DataFrame({"a": [2.0], "double": [99.0], "status": ["old"]})
    res = evaluate_designs(TOY, df)
    assert res.columns.tolist() == ["a", "double", "status", "state", "reason"]
    assert res["double"].tolist() == [4.0] and res["status"].tolist() == ["converged"]


def test_bad_workers():
    with pytest.raises(ValueError, match="workers"):
        evaluate_designs(TOY, pd.DataFrame({"a": [1.0]}), workers=0)


def test_real_scenario_rows_keep_their_order(reference_data):
    d = reference_data.load("data0_SingleMiura").iloc[[5, 0, 3]]
    feats = ["tcrease", "tpanel", "W", "gama"]
    res = evaluate_designs("single-miura", d[feats].iloc[::-1], workers=1)
    ref = d.iloc[::-1]
    for c in ("axialstiff30", "axialstiff60", "axialstiff90"):
        assert np.allclose(res[c].to_numpy(), ref[c].to_numpy(), rtol=1e-4)
    assert (res["status"] == "converged").all()


def test_optional_columns_default():
    sc = get_scenario("canopy")
    df = pd.DataFrame([dict(pattern=2, m=24, n=6, tcrease=7e-4, tpanel=3e-3, W=2e-3)])
    row = validate_designs(sc, df).rows[0]
    assert row["creaseE"] == row["panelE"] == 2e9
    df["creaseE"] = [np.nan]
    assert validate_designs(sc, df).rows[0]["creaseE"] == 2e9


def _inf_or_missing(row):
    if row["a"] == 2:
        return {"double": float("inf"), "status": "converged"}
    if row["a"] == 3:
        return {"status": "converged"}  # an output left out
    if row["a"] == 4:
        return {"double": 8.0}  # no status at all
    return {"double": 2 * row["a"], "status": Status.not_converged("kept as is")}


def test_a_non_finite_or_missing_output_is_never_converged():
    sc = Scenario("toy2", "", TOY.features, TOY.performance, _toy_check, _inf_or_missing)
    res = evaluate_designs(sc, pd.DataFrame({"a": [2.0, 3.0, 4.0, 5.0]}))
    assert res["status"].tolist() == [
        "not converged: non-finite output: double",
        "not converged: non-finite output: double",
        "failed: the evaluator returned no status",
        "not converged: kept as is",
    ]
