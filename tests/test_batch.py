"""Batched evaluation (issue 14): designs of one size solved in lockstep give each design the
numbers it gets alone (to round-off: 1e-9 of the displacements' scale for converged solves, the
same iterations and statuses), whatever the others do (converge, stall, fail)."""

import numpy as np
import pytest

from holofold.design.database.runner import BATCH_ROWS, evaluate_designs, plan_tasks
from holofold.design.scenarios import arch
from holofold.mechanics import BatchAssembler, solve_newton, solve_newton_batch
from holofold.mechanics.analyses import load_along, secant_stiffness, secant_stiffness_batch
from holofold.mechanics.structure import Structure

MID = dict(tcrease=0.75e-3, tpanel=3.5e-3, W=2.5e-3)


def _rows(m, n):
    rng = np.random.default_rng(m)
    return [
        dict(MID, m=m, offset=rng.uniform(0.1, 0.3), stripeWidth=rng.uniform(0.01, 0.04),
             extrude=rng.uniform(0.05, 0.25), tpanel=rng.uniform(1e-3, 6e-3))
        for _ in range(n)
    ]  # fmt: skip


def _same(a, b):
    """The same outcome, increments and iterations; converged solves to 1e-9 of the
    displacements' scale (a diverging one only its outcome: its numbers are round-off
    amplified, and the batch factorises by Cholesky where a design alone takes LU)."""
    assert a.status.outcome == b.status.outcome
    for name in ("load_factor", "converged", "iterations"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    np.testing.assert_allclose(b.applied_force, a.applied_force, rtol=1e-12)
    if a.status.converged:
        assert str(a.status) == str(b.status)
        scale = np.nanmax(np.abs(a.U_history), initial=0.0)
        np.testing.assert_allclose(b.U_history, a.U_history, rtol=0, atol=1e-9 * scale)
    elif a.failed:  # the same reason: where and why it stopped
        assert str(a.status) == str(b.status)


@pytest.mark.parametrize("m", [8, 12])
def test_secant_stiffness_batch_is_each_design_alone(m):
    models = [arch.arch_model(r) for r in _rows(m, 6)]
    ss = [s for s, _, _ in models]
    assert len({s.springs.tobytes() for s in ss}) > 1  # several spring orientations in a batch
    gs = [load_along([apex], (0, 0, -1)) for _, apex, _ in models]
    kw = dict(force_per_increment=1.0, increments=5, tol=1e-7)
    alone = [secant_stiffness(s, g, **kw) for s, g in zip(ss, gs, strict=True)]
    together = secant_stiffness_batch(ss, gs, **kw)
    for a, b in zip(alone, together, strict=True):
        assert b.stiffness == pytest.approx(a.stiffness, rel=1e-9)
        assert b.displacement == pytest.approx(a.displacement, rel=1e-9)
        _same(a.result, b.result)


def _truss(k_spring, n=5, supported=1):
    """A small chain of bars with springs; ``supported`` first nodes fixed."""
    x = np.arange(n, dtype=float)
    nodes = np.c_[x, 0.1 * np.sin(x), 0.05 * np.cos(x)]
    bars = np.array([[i, j] for i in range(n) for j in range(i + 1, min(n, i + 3))])
    springs = np.array([[i, i + 1, i + 2, i + 3] for i in range(n - 3)])
    sup = np.zeros((n, 3), bool)
    sup[:supported] = True
    from holofold.mechanics.springs import dihedral_angle

    return Structure(
        nodes=nodes, bars=bars, bar_area=1e-4, bar_E=1e9, springs=springs,
        spring_k=k_spring, spring_rest=dihedral_angle(nodes, springs), supports=sup,
    )  # fmt: skip


def test_newton_batch_keeps_failures_and_stalls_per_design():
    ok = _truss(1.0, supported=2)
    stiff = _truss(2.0, supported=2)
    dead = ok.replace(bar_E=0.0, spring_k=0.0)  # K = 0: singular at the first iteration
    ld = np.zeros((5, 3))
    ld[-1] = [0.0, 1e3, 1e3]
    kw = dict(increments=3, tol=1e-12, max_iter=6)  # a tolerance some iterations miss
    cases = [(ok, ld), (dead, ld), (stiff, ld), (ok, 2 * ld)]
    alone = [solve_newton(s, f, **kw) for s, f in cases]
    assert alone[1].failed and not alone[0].failed
    together = solve_newton_batch([s for s, _ in cases], [f for _, f in cases], **kw)
    for a, b in zip(alone, together, strict=True):
        _same(a, b)
    with pytest.raises(ValueError, match="supports"):
        BatchAssembler([ok, ok.with_supports(np.zeros((5, 3), bool))])


def test_runnerplan_tasks_rows_of_one_m_and_gives_each_row_its_own_outputs():
    rows = _rows(8, 3) + _rows(12, 2) + _rows(8, 2)
    import pandas as pd

    table = pd.DataFrame(rows)
    tasks = plan_tasks(arch.SCENARIO, table.to_dict("records"))
    assert sorted(len(t) for t in tasks) == [2, 5] and BATCH_ROWS >= 5
    res = evaluate_designs("arch", table)
    for i, r in enumerate(rows):
        alone = arch.evaluate(r)
        for c in arch.SCENARIO.performance_names:
            assert res[c].iloc[i] == pytest.approx(alone[c], rel=1e-9, nan_ok=True), (i, c)
        assert res["status"].iloc[i] == str(alone["status"])
