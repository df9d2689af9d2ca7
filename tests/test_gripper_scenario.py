"""The gripper scenario (data2): published formulas, full runs against published rows."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from holofold.design.scenarios import get_scenario, gripper
from holofold.design.scenarios.gripper import (
    SCENARIO,
    STATUS_NO_CLOSURE,
    GripperOptions,
    check,
    decode_closing_step,
    gripper_model,
    published_q,
    run_frequency,
    run_heating,
    run_prebias,
    run_prying,
    simulate,
)
from holofold.mechanics.compat import PAPER
from holofold.mechanics.status import Outcome, Status
from holofold.mechanics.structure import support_mask

STEMS = ["data2_MiuraBased_sample", "data2_SplittedMiura_sample", "data2_TwoPanel_sample"]
STEP_RANGE = {1: (67, 387), 2: (72, 398), 3: (41, 298)}  # of the published rows


@pytest.mark.parametrize("stem", STEMS)
def test_published_final_q_decodes_to_whole_heating_steps(reference_data, stem):
    df = reference_data.load(stem)
    P = int(df["Pattern"].iloc[0])
    step = decode_closing_step(P, df["L1"].to_numpy(), df["L2"].to_numpy(), df["finalQ"])
    np.testing.assert_allclose(step, np.round(step), atol=1e-9)
    lo, hi = STEP_RANGE[P]
    assert lo <= step.min() and step.max() <= hi
    back = published_q(P, df["L1"].iloc[0], df["L2"].iloc[0], np.round(step[0]))
    assert back == pytest.approx(df["finalQ"].iloc[0], rel=1e-13)


def _row(df, i):
    return {k: float(df[k].iloc[i]) for k in SCENARIO.feature_names}


# (file, row index, closing step): two-panel row 12, splitted row 1, Miura-based row 2. The
# two-panel row is one whose prying stiffness is insensitive to round-off (many are not: see
# test_two_panel_stiffness_is_robust_on_a_stable_row and the module docstring of the scenario).
FULL_RUNS = [
    ("data2_TwoPanel_sample", 11, 103),
    ("data2_SplittedMiura_sample", 0, 117),
    ("data2_MiuraBased_sample", 1, 145),
]


@pytest.mark.slow
@pytest.mark.parametrize("stem,i,step", FULL_RUNS)
def test_full_run_reproduces_published_row(reference_data, stem, i, step):
    df = reference_data.load(stem)
    res = simulate(_row(df, i))
    P = int(df["Pattern"].iloc[i])
    pub_step = decode_closing_step(P, df["L1"].iloc[i], df["L2"].iloc[i], df["finalQ"].iloc[i])
    assert pub_step == pytest.approx(step, abs=1e-9)
    assert res.closing_step == step
    # (the Miura-based prying run starts with a 29-iteration increment, as in the reference)
    assert "heating" not in str(res.status) and "failed" not in str(res.status)
    assert res.freqFinal == pytest.approx(df["freqFinal"].iloc[i], rel=1e-6)
    assert res.finalQ == pytest.approx(df["finalQ"].iloc[i], rel=1e-12)
    assert res.Tmax == pytest.approx(df["Tmax"].iloc[i], rel=1e-6)
    assert res.stiff == pytest.approx(df["stiff"].iloc[i], rel=1e-3)


def test_two_panel_stiffness_is_robust_on_a_stable_row(reference_data):
    """Row 12 of the two-panel sample: a 1e-15 relative change of L1 leaves the closing step,
    Tmax and the prying stiffness unchanged (to 1e-6), and all match the published row. (On
    about 60 % of the rows the same change moves the stiffness by 0.1-50 %: the Newton solves
    end with large soft-mode steps taken from ~1e-9 N residuals.)"""
    df = reference_data.load("data2_TwoPanel_sample")
    row = _row(df, 11)
    a = simulate(row)
    b = simulate(row | {"L1": row["L1"] * (1 + 1e-15)})
    assert a.closing_step == b.closing_step == 103
    assert b.stiff == pytest.approx(a.stiff, rel=1e-6)
    assert b.Tmax == pytest.approx(a.Tmax, rel=1e-9)
    assert a.stiff == pytest.approx(df["stiff"].iloc[11], rel=1e-6)
    assert a.Tmax == pytest.approx(df["Tmax"].iloc[11], rel=1e-9)


def test_converged_mode_is_repeatable(reference_data):
    """Two-panel row 4: with the scripts' loose tolerances its prying stiffness is one of the
    round-off-sensitive ones (module docstring); with ``converged=True`` a 1e-15 change of L1
    moves the stiffness by < 1e-9 and the tip path by < 1 nm, and the closing step, Tmax and
    frequency are still the published ones."""
    df = reference_data.load("data2_TwoPanel_sample")
    row = _row(df, 3)
    opt = GripperOptions(converged=True, keep_history=True)
    a = simulate(row, opt)
    b = simulate(row | {"L1": row["L1"] * (1 + 1e-15)}, opt)
    assert str(a.status) == str(b.status) == "converged"
    assert a.closing_step == b.closing_step == 80
    assert b.stiff == pytest.approx(a.stiff, rel=1e-9)
    np.testing.assert_allclose(b.tip_distance, a.tip_distance, rtol=0, atol=1e-9)  # 1 nm
    assert a.Tmax == pytest.approx(df["Tmax"].iloc[3], rel=1e-6)
    assert a.freqFinal == pytest.approx(df["freqFinal"].iloc[3], rel=1e-6)
    # every prying increment met the tight tolerance
    (run,) = a.stiffness_runs
    assert run.ok and run.converged.all()
    # the scenario object runs the converged mode
    conv = get_scenario("gripper-converged").evaluate(row)
    assert conv["stiff"] == pytest.approx(a.stiff, rel=1e-9) and str(conv["status"]) == "converged"
    assert GripperOptions(converged=True).tolerance(5e-6, "displacement") == {
        "tol": 1e-12,
        "max_iter": 200,
    }
    assert GripperOptions().tolerance(5e-6, "force") == {"tol": 5e-6}


@pytest.mark.slow
def test_converged_mode_splitted_row(reference_data):
    """Splitted row 1 in converged mode (pre-bias and both prying runs with the tight
    tolerance): repeatable, every solve converged, the published closing step and Tmax, and the
    published stiffness to 1e-4 (this row's loosely converged solves end near equilibrium)."""
    df = reference_data.load("data2_SplittedMiura_sample")
    row = _row(df, 0)
    opt = GripperOptions(converged=True, keep_history=True)
    a = simulate(row, opt)
    b = simulate(row | {"L1": row["L1"] * (1 + 1e-15)}, opt)
    assert str(a.status) == str(b.status) == "converged" and a.closing_step == b.closing_step == 117
    assert b.stiff == pytest.approx(a.stiff, rel=1e-9)
    r1, r2 = a.stiffness_runs
    assert r1.converged.all() and r2.converged.all()
    assert a.Tmax == pytest.approx(df["Tmax"].iloc[0], rel=1e-6)
    assert a.stiff == pytest.approx(df["stiff"].iloc[0], rel=1e-4)


@pytest.mark.slow
def test_physical_polarity_gives_the_same_folding(reference_data):
    """Normalised springs with the pattern's fold_sign fold exactly like the reference's raw
    springs with the scripts' signs (first 25 heating steps of a splitted gripper)."""
    df = reference_data.load("data2_SplittedMiura_sample")
    row = _row(df, 0)
    a = simulate(row, GripperOptions(step_cap=25, keep_history=True))
    physical = dataclasses.replace(PAPER, raw_crease_polarity=False)
    b = simulate(row, GripperOptions(step_cap=25, keep_history=True, profile=physical))
    assert a.status == b.status == STATUS_NO_CLOSURE
    np.testing.assert_allclose(a.tip_distance, b.tip_distance, rtol=1e-7)
    np.testing.assert_allclose(a.Tmax_history, b.Tmax_history, rtol=1e-12)
    assert a.tip_distance[-1] < a.tip_distance[0] - 1e-5  # the arms do move


def test_no_closure_within_cap(reference_data):
    df = reference_data.load("data2_TwoPanel_sample")
    res = simulate(_row(df, 1), GripperOptions(step_cap=5, keep_history=True))
    assert res.status == STATUS_NO_CLOSURE
    assert res.closing_step is None
    assert all(math.isnan(v) for v in (res.finalQ, res.Tmax, res.stiff))
    assert res.freqFinal == pytest.approx(df["freqFinal"].iloc[1], rel=1e-6)
    assert len(res.tip_distance) == 5
    assert np.all(np.diff(res.tip_distance) < 0)  # closing, slowly
    assert np.all(np.diff(res.Tmax_history) > 0)
    row = res.as_row()
    assert set(row) == {"freqFinal", "finalQ", "Tmax", "stiff", "status"}


def test_check_rejects_invalid_designs():
    good = dict(Pattern=3, L1=4e-3, L2=3e-3, t1=0.2e-6, t2=0.8e-6, tpanel=20e-6, rate=0.4,
                W=200e-6)  # fmt: skip
    assert check(good) == []
    assert any("Pattern" in e for e in check(good | {"Pattern": 4}))
    assert any("L2/2" in e for e in check(good | {"Pattern": 1, "rate": 0.9}))
    assert any("t1" in e for e in check(good | {"t1": -1.0}))
    assert any("W" in e for e in check(good | {"W": 2e-3}))
    with pytest.raises(ValueError, match="rate"):
        simulate(good | {"Pattern": 2, "rate": 0.95})


def test_scenario_columns():
    assert SCENARIO.name == "gripper"
    assert SCENARIO.feature_names == ["Pattern", "L1", "L2", "t1", "t2", "tpanel", "rate", "W"]
    assert SCENARIO.performance_names == ["freqFinal", "finalQ", "Tmax", "stiff"]
    assert [c.unit for c in SCENARIO.performance] == ["rad/s", "W", "degC", "N/m"]


# ---------------------------------------------------------------- named node sets
ALL = "xyz"
#: the scenario's former tables of 1-based meshed node ids, as the reference scripts list them
FREQ_SUPPORTS = {
    1: [(n, ALL) for n in (1, 3, 4, 5, 74, 75)],
    2: [(n, ALL) for n in (1, 2, 3, 4)],
    3: [(n, ALL) for n in (1, 2, 3, 4)],
}
PREBIAS_SUPPORTS = {
    1: [(1, "xy"), (3, "xy"), (4, "x"), (5, "x"), (74, "xz"), (75, "xz")],
    2: [(n, ALL) for n in (1, 2, 3, 4)],
}
PREBIAS_SUPPORTS_7CD7ABC = [(1, "xy"), (3, "xy"), (4, "x"), (5, "x"), (74, "z"), (75, "z")]
PREBIAS_LOADS = {  # (nodes, axis, sign)
    1: [((2, 6, 8, 24), 2, -1.0), ((14, 27), 2, 1.0)],
    2: [((15, 24, 38, 46), 2, -1.0), ((31, 32, 53, 54), 2, 1.0)],
}
THERMAL_SUPPORTS = {
    1: [(1, "xy"), (4, "xy"), (4, "x"), (5, "x"), (74, "xz"), (75, "xz")],
    2: [(n, ALL) for n in (1, 2, 3, 4)],
    3: [(n, ALL) for n in (1, 2, 3, 4)],
}
STIFF_SUPPORTS = {
    1: [(1, "xy"), (3, "xy"), (4, "x"), (5, "x"), (74, "xz"), (75, "xz")],
    2: [(n, ALL) for n in (1, 2, 3, 4)],
    3: [(n, ALL) for n in (1, 2, 3, 4)],
}
STIFF_LOADS = {
    1: [((29, 32), 0, -1.0), ((16, 19), 0, 1.0)],
    2: [((31, 32), 1, 1.0), ((53, 54), 1, -1.0)],
    3: [((17, 18), 1, -1.0), ((11, 12), 1, 1.0)],
}
CLOSURE_PAIR = {1: (59, 71), 2: (32, 53), 3: (12, 17)}
STIFF_PROBE = {1: (16, 0), 2: (31, 1), 3: (11, 1)}  # (node, axis) whose displacement is measured
DESIGN = dict(L1=5.2e-3, L2=2.9e-3, t1=0.2e-6, t2=0.8e-6, tpanel=20e-6, rate=0.37, W=180e-6)


def _entries(groups):
    """[(1-based node, dofs), ...] of ((nodes, dofs), ...) support groups, in order."""
    return [(int(i) + 1, dofs) for nodes, dofs in groups for i in nodes]


def _loads(groups):
    """{(node, axis): sign} of ((nodes, axis, sign), ...) load groups."""
    return {(int(i), axis): sign for nodes, axis, sign in groups for i in nodes}


@pytest.mark.parametrize("P", [1, 2, 3])
def test_named_node_sets_are_the_reference_scripts_ids(P):
    """Every support and load of the scenario, now chosen by name, is the node list the
    reference scripts use (including pattern 1's thermal list: node 4 twice, node 3 never)."""
    model = gripper_model(DESIGN | {"Pattern": P})
    n, nn = model.nodes, model.structure.n_nodes
    assert _entries(n.clamp) == FREQ_SUPPORTS[P]
    assert _entries(n.hold) == STIFF_SUPPORTS[P]
    assert _entries(n.hold_heating) == THERMAL_SUPPORTS[P]
    if P in PREBIAS_SUPPORTS:
        assert _entries(n.hold) == PREBIAS_SUPPORTS[P]
        seven = PREBIAS_SUPPORTS_7CD7ABC if P == 1 else PREBIAS_SUPPORTS[P]
        assert _entries(n.hold_7cd7abc) == seven
        got = [(n.prebias_down + 1, 2, -1.0), (n.prebias_up + 1, 2, 1.0)]
        assert _loads(got) == _loads(PREBIAS_LOADS[P])
        assert [tuple(g[0]) for g in got] == [g[0] for g in PREBIAS_LOADS[P]]  # same order
    else:
        assert len(n.prebias_down) == len(n.prebias_up) == 0
    got = [(n.pry_plus + 1, n.arm_axis, 1.0), (n.pry_minus + 1, n.arm_axis, -1.0)]
    assert _loads(got) == _loads(STIFF_LOADS[P])
    assert tuple(n.tips + 1) == CLOSURE_PAIR[P]
    assert (n.probe + 1, n.arm_axis) == STIFF_PROBE[P]
    # the support masks the solvers see
    for groups, table in ((n.clamp, FREQ_SUPPORTS[P]), (n.hold_heating, THERMAL_SUPPORTS[P])):
        mask = support_mask(nn, [(np.array([i - 1]), d) for i, d in table])
        np.testing.assert_array_equal(model.structure.fixed(groups).supports, mask)


@pytest.mark.parametrize("P", [1, 2, 3])
def test_named_node_sets_are_what_their_names_say(P):
    """The base holds the root, the tips and the pried nodes lie at the arms' ends."""
    model = gripper_model(DESIGN | {"Pattern": P})
    n, X = model.nodes, model.structure.nodes
    ax = n.arm_axis
    reach = np.abs(X[:, ax]).max()
    assert np.all(np.abs(X[n.base, ax]) < 0.5 * reach)  # near the middle
    assert np.all(X[n.pry_plus, ax] > 0.9 * reach) and np.all(X[n.pry_minus, ax] < -0.9 * reach)
    a, b = X[n.tips]
    assert a[ax] > 0.8 * reach and b[ax] < -0.8 * reach
    assert n.probe in n.pry_plus


# ---------------------------------------------------------------- the step functions
def test_step_functions_compose_to_simulate(reference_data):
    """Two-panel row 12 (closing step 103): the four steps, run one after the other, give
    exactly the outputs of simulate; each carries its own Status."""
    df = reference_data.load("data2_TwoPanel_sample")
    row = _row(df, 11)
    opt = GripperOptions()
    model = gripper_model(row)
    a = run_frequency(model)
    b = run_prebias(model, opt)
    c = run_heating(model, b.state, opt)
    d = run_prying(model, c.state, opt)
    for step in (a, b, c, d):
        assert isinstance(step.status, Status)
    assert a.status.converged and b.status.converged and b.run is None  # no pre-bias here
    assert c.closing_step == 103 and len(c.tip_distance) == 103 and c.status.converged
    assert c.tip_distance[-1] < gripper.CLOSURE <= c.tip_distance[-2]
    assert len(d.runs) == 1 and d.status == d.runs[0].status
    res = simulate(row)
    assert (a.freqFinal, c.Tmax, d.stiff) == (res.freqFinal, res.Tmax, res.stiff)
    assert res.finalQ == float(published_q(3, row["L1"], row["L2"], 103))
    # the pattern's own step cap: no closure is a failed heating status, Tmax undefined
    c5 = run_heating(model, b.state, GripperOptions(step_cap=5))
    assert c5.closing_step is None and c5.status == STATUS_NO_CLOSURE and math.isnan(c5.Tmax)
    np.testing.assert_array_equal(c5.tip_distance, c.tip_distance[:5])


def test_prebias_step_status(reference_data, monkeypatch):
    """Pattern 2's pre-bias: converged with the scripts' tolerance, not converged (and saying
    so) with one no solve can meet; its forces stay applied."""
    df = reference_data.load("data2_SplittedMiura_sample")
    model = gripper_model(_row(df, 0))
    b = run_prebias(model, GripperOptions())
    assert b.status.converged and b.run.n_increments == gripper.PREBIAS_INCREMENTS
    n = model.nodes
    np.testing.assert_allclose(b.state.force[n.prebias_down, 2], -10 * gripper.PREBIAS_FORCE)
    np.testing.assert_allclose(b.state.force[n.prebias_up, 2], 10 * gripper.PREBIAS_FORCE)
    monkeypatch.setattr(gripper, "PREBIAS_TOL", 1e-30)
    tight = run_prebias(model, GripperOptions())
    assert tight.status.outcome is Outcome.NOT_CONVERGED
    assert "increments above tol" in str(tight.status)


def test_unconverged_prebias_is_reported_in_the_row_status(reference_data, monkeypatch):
    """A pre-bias that misses its tolerance does not go unnoticed: the row (which still closes
    and has every output) is not converged and names the pre-bias."""
    df = reference_data.load("data2_SplittedMiura_sample")
    monkeypatch.setattr(gripper, "PREBIAS_TOL", 1e-30)
    res = simulate(_row(df, 0))
    assert res.closing_step is not None
    assert res.status.outcome is Outcome.NOT_CONVERGED
    assert str(res.status).startswith("not converged: pre-bias: 10 of 10 increments above tol")
    assert np.isfinite([res.freqFinal, res.finalQ, res.Tmax, res.stiff]).all()
