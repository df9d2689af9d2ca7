"""Newton step control of the rest-angle fold (issue 32 item 3, stalls): the backtracking line
search of solve_selffold and fold_pattern's retry of a failed step (mechanics/folding.py,
mechanics/solvers/selffold.py)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from holofold.mechanics import Assembler, fold_pattern
from holofold.mechanics.hinges import crease_rest_targets
from holofold.mechanics.solvers import solve_selffold
from holofold.mechanics.solvers.selffold import _ARMIJO, _backtrack

_OS = Path(__file__).parent / "data" / "origami-simulator"
_PP = dict(panel_thickness=1e-3, crease_thickness=0.2e-3, crease_width=1e-3, E=1.5e9, nu=0.42)
SIZE = 0.2  # m


def _os(name):
    from holofold.geometry import read_pattern
    from holofold.mechanics import scaled_pattern

    p = read_pattern(_OS / name)
    return scaled_pattern(p, SIZE / float(np.ptp(p.flat, axis=0).max()))


def _waterbomb_at(fraction):
    p = _os("waterbombBase.svg")
    r = fold_pattern(p, fraction, check_intersections=False, **_PP)
    st = r.structure

    def rest(f):
        return crease_rest_targets(st, np.full(p.n_edges, math.pi) + np.radians(f * r.target))

    return r, Assembler(st), rest


def test_line_search_lands_on_newtons_equilibrium():
    """The same step (waterbomb base, 10 -> 13 %) by full Newton steps and with the line
    search: both meet a tolerance of 1e-10 of the full actuation force and end on the same
    state (within 1e-9 of the sheet size)."""
    r, asm, rest = _waterbomb_at(0.1)
    assert r.complete
    f1 = asm.internal_force(np.zeros_like(r.U[0]), rest(1.0))[1][asm.free_dofs]
    tol = 1e-10 * float(np.linalg.norm(f1))
    out = [
        solve_selffold(r.structure, rest(0.13), start_rest=rest(0.1), increments=1, tol=tol,
                       max_iter=60, U0=r.U[-1], assembler=asm, line_search=ls)
        for ls in (False, True)
    ]  # fmt: skip
    assert all(o.ok for o in out)
    assert np.abs(out[0].U - out[1].U).max() <= 1e-9 * SIZE


def test_backtracking_keeps_a_state_that_lowers_the_energy_or_the_residual():
    """From the converged 10 % state, the first full Newton step at 50 % raises both the
    potential energy and the residual; the line search keeps a shorter step whose energy passes
    the Armijo test or whose residual is lower than the start's."""
    r, asm, rest = _waterbomb_at(0.1)
    free = asm.free_dofs
    target = rest(0.5)
    U = r.U[-1].ravel().copy()
    E0, f0, solve = asm.evaluate_factorized(U, target)
    res0 = -f0[free]
    R0 = float(np.linalg.norm(res0))
    dU = solve(res0)
    before = U[free].copy()
    U[free] += dU
    E1, f1 = asm.internal_force(U, target)
    assert E1 > E0 and np.linalg.norm(f1[free]) > R0  # the full step is worse on both counts
    E = _backtrack(asm, U, before, dU, res0, R0, E0, target, np.zeros_like(U))
    a = float(np.dot(U[free] - before, dU) / np.dot(dU, dU))
    assert 1.0 / 64 * (1 - 1e-9) <= a < 1.0  # a ratio of dot products: round-off at 1/64
    np.testing.assert_allclose(U[free], before + a * dU, rtol=0, atol=1e-12 * SIZE)
    Ek, fk = asm.internal_force(U, target)
    assert E == pytest.approx(Ek, rel=1e-12)
    slope = float(res0 @ dU)
    armijo = slope > 0 and Ek <= E0 - _ARMIJO * a * slope
    assert armijo or np.linalg.norm(fk[free]) <= (1 - _ARMIJO * a) * R0


def test_a_retried_step_carries_the_many_angle_square_twist_past_its_stall():
    """Origami Simulator's many-angle square twist stalls at 96.7 % with 29 Newton iterations
    per step (the residual still falling, slowly, at the cap); retrying a failed step with
    120 iterations before halving it carries the fold past that point."""
    p = _os("squaretwistManyAngles.svg")
    plain = fold_pattern(p, 1.0, **_PP)
    assert plain.verdict == "stalls" and plain.reached < 0.968
    retried = fold_pattern(p, 1.0, retry_iter=120, **_PP)
    assert retried.reached > plain.reached + 0.01
    assert retried.verdict != "stalls"
    assert "converged only when retried" in retried.note


@pytest.mark.parametrize("bad", [-1, 2.5, True])
def test_retry_iter_must_be_a_whole_number(bad):
    from holofold.geometry.errors import ParameterError

    with pytest.raises(ParameterError, match="retry_iter"):
        fold_pattern(_os("simpleVertex.svg"), 0.1, retry_iter=bad, **_PP)
