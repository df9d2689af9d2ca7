"""Nonlinear solvers: Newton-Raphson (reference semantics), MGDCM, displacement control,
self-folding, on problems with analytic answers."""

import numpy as np
import pytest

from holofold.geometry.errors import ParameterError
from holofold.mechanics.assembly import Assembler
from holofold.mechanics.solvers import (
    SolveResult,
    solve_displacement,
    solve_mgdcm,
    solve_newton,
    solve_selffold,
)
from holofold.mechanics.springs import dihedral_angle
from holofold.mechanics.structure import Structure

NO_SPRINGS = dict(springs=np.zeros((0, 4), int), spring_k=[], spring_rest=[])


def single_bar(L=2.0, EA=3.0e5):
    sup = np.ones((2, 3), bool)
    sup[1, 0] = False  # node 1 moves along the bar only
    return Structure(
        nodes=[[0.0, 0.0, 0.0], [L, 0.0, 0.0]],
        bars=[[0, 1]],
        bar_area=1.0,
        bar_E=EA,
        supports=sup,
        **NO_SPRINGS,
    )


def von_mises(a=1.0, h=0.1, EA=1e3):
    """Shallow two-bar truss: supports at (+-a, 0, 0), apex (0, 0, h) free in x and z."""
    sup = np.zeros((3, 3), bool)
    sup[:2] = True
    sup[2, 1] = True
    s = Structure(
        nodes=[[-a, 0.0, 0.0], [a, 0.0, 0.0], [0.0, 0.0, h]],
        bars=[[0, 2], [1, 2]],
        bar_area=1.0,
        bar_E=EA,
        supports=sup,
        **NO_SPRINGS,
    )
    L0 = np.hypot(a, h)
    # Green-Lagrange bars: P(z) = EA z (h^2 - z^2) / L0^3 (downward load at apex height z);
    # dP/dz = 0 at z = h / sqrt(3):  P_lim = 2 EA h^3 / (3 sqrt(3) L0^3)
    P_lim = 2.0 * EA * h**3 / (3.0 * np.sqrt(3.0) * L0**3)
    return s, (lambda z: EA * z * (h * h - z * z) / L0**3), P_lim


def hinge(k=0.7, fix_l=False):
    """Two triangles on the hinge 1-2 (x axis); triangle (0,1,2) fixed, wing node 3 free."""
    x = np.array([[0.4, -1.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.6, 1.0, 0.0]])
    springs = np.array([[0, 1, 2, 3]])
    sup = np.zeros((4, 3), bool)
    sup[:3] = True
    return Structure(
        nodes=x,
        bars=[[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]],
        bar_area=1e-2,
        bar_E=1e7,
        springs=springs,
        spring_k=[k],
        spring_rest=dihedral_angle(x, springs),
        supports=sup,
    )


# ------------------------------------------------------------------------------- Newton
def test_newton_single_bar_small_and_large_load():
    L, EA = 2.0, 3.0e5
    s = single_bar(L, EA)
    F = 1e-3  # small load: u = F L / EA
    load = np.zeros((2, 3))
    load[1, 0] = F / 4
    r = solve_newton(s, load, increments=4, tol=1e-16 * L)
    assert isinstance(r, SolveResult) and r.ok and str(r.status) == "converged"
    assert r.U[1, 0] == pytest.approx(F * L / EA, rel=1e-8)
    np.testing.assert_array_equal(r.load_factor, [1, 2, 3, 4])
    np.testing.assert_allclose(r.applied_force, 4 * load)
    # large load: Green-Lagrange equilibrium F = EA eps (L + u) / L, eps = ((L+u)^2 - L^2)/(2L^2)
    load[1, 0] = 0.2 * EA / 5
    r = solve_newton(s, load, increments=5, tol=1e-12)
    assert r.ok
    for i, Ui in enumerate(r.U_history, start=1):
        u = Ui[1, 0]
        eps = (2 * L * u + u * u) / (2 * L * L)
        assert EA * eps * (L + u) / L == pytest.approx(i * load[1, 0], rel=1e-10)


def test_newton_von_mises_below_limit_matches_cubic():
    s, P_of_z, P_lim = von_mises()
    load = np.zeros((3, 3))
    load[2, 2] = -0.15 * P_lim
    r = solve_newton(s, load, increments=5, tol=1e-12)
    assert r.ok
    for i, Ui in enumerate(r.U_history, start=1):
        z = 0.1 + Ui[2, 2]
        assert P_of_z(z) == pytest.approx(i * 0.15 * P_lim, rel=1e-9)
        assert z > 0.1 / np.sqrt(3)  # still on the first (stable) branch


def test_newton_reference_iteration_semantics():
    # near-linear response: iteration 1 lands on the solution, iteration 2 gives dU = 0 and the
    # test ||dU|| <= tol is made after that update -> 2 iterations per increment
    s = single_bar()
    load = np.zeros((2, 3))
    load[1, 0] = 1e-12
    r = solve_newton(s, load, increments=3, tol=1e-20)
    np.testing.assert_array_equal(r.iterations, [2, 2, 2])
    # nonlinear response: quadratic convergence, the last recorded ||dU|| is below tol
    load[1, 0] = 1e2
    r = solve_newton(s, load, increments=3, tol=1e-12)
    np.testing.assert_array_equal(r.iterations, [3, 3, 3])
    assert np.all(r.residual <= 1e-12) and np.all(r.residual > 0)
    # the first iteration always runs, even at the exact solution (no load)
    r0 = solve_newton(s, np.zeros((2, 3)), increments=2, tol=1e-8)
    np.testing.assert_array_equal(r0.iterations, [1, 1])
    assert r0.ok and np.all(r0.residual == 0.0)


def test_newton_non_convergence_is_recorded_not_raised():
    s, _, P_lim = von_mises()
    load = np.zeros((3, 3))
    load[2, 2] = -0.6 * P_lim  # increment 2 asks for 1.2 P_lim: no equilibrium nearby
    r = solve_newton(s, load, increments=3, tol=1e-12, max_iter=30)
    assert not r.ok and not r.failed
    assert r.converged[0] and not r.converged.all()
    bad = np.flatnonzero(~r.converged)
    assert r.iterations[bad].max() == 29  # at most max_iter - 1 iterations
    assert "not converged" in str(r.status) and f"increment {bad[0] + 1}" in str(r.status)
    assert len(r.U_history) == 3  # increments were accepted and the stage went on
    np.testing.assert_allclose(r.applied_force, 3 * load)


def test_newton_keeps_supported_dofs_and_starts_from_state():
    s, P_of_z, P_lim = von_mises()
    U0 = np.zeros((3, 3))
    U0[0, 0] = 0.01  # a prescribed support displacement stays put
    F0 = np.zeros((3, 3))
    F0[2, 2] = -0.1 * P_lim
    load = np.zeros((3, 3))
    load[2, 2] = -0.05 * P_lim
    r = solve_newton(s, load, increments=2, tol=1e-12, U0=U0, F0=F0)
    assert r.ok
    assert r.U[0, 0] == 0.01 and r.U[1, 0] == 0.0 and r.U[2, 1] == 0.0
    np.testing.assert_allclose(r.applied_force, F0 + 2 * load)


def test_singular_stiffness_is_a_recorded_failure():
    # a bar whose far node is free transversally: zero transverse stiffness at rest
    s = single_bar()
    sup = s.supports.copy()
    sup[1, 1] = False
    s = s.with_supports(sup)
    load = np.zeros((2, 3))
    load[1, 0] = 1.0
    for dense_max in (1000, 0):  # dense LAPACK and sparse SuperLU paths
        asm = Assembler(s, dense_max=dense_max)
        r = solve_newton(s, load, increments=3, assembler=asm)
        assert r.failed and not r.ok
        assert r.status.is_failed and "increment 1" in str(r.status) and "singular" in str(r.status)
        assert len(r.U_history) == 1 and np.all(np.isfinite(r.U_history))


def test_invalid_inputs_raise_value_errors():
    s = single_bar()
    with pytest.raises(ParameterError, match="increments"):
        solve_newton(s, np.zeros((2, 3)), increments=0)
    with pytest.raises(ParameterError, match="tol"):
        solve_newton(s, np.zeros((2, 3)), increments=1, tol=0.0)
    with pytest.raises(ParameterError, match="load"):
        solve_newton(s, np.zeros((3, 3)), increments=1)
    with pytest.raises(ParameterError, match="another Structure"):
        solve_newton(s, np.zeros((2, 3)), increments=1, assembler=Assembler(single_bar()))
    with pytest.raises(ParameterError, match="supported"):
        solve_displacement(s, np.zeros((2, 3)), (1, 1), step=0.1)


# ------------------------------------------------------------------------------- path following
@pytest.mark.parametrize("dense_max", [200, 0])  # dense LAPACK / banded Cholesky + SuperLU
def test_mgdcm_passes_the_von_mises_limit_point(dense_max):
    s, P_of_z, P_lim = von_mises()
    load = np.zeros((3, 3))
    load[2, 2] = -P_lim
    asm = Assembler(s, dense_max=dense_max)
    r = solve_mgdcm(
        s, load, increments=100, lambda_bar=0.05, tol=1e-12, adapt_step=False, assembler=asm
    )
    assert r.ok
    z = 0.1 + r.U_history[:, 2, 2]
    lam = r.load_factor
    # every converged point lies on the analytic equilibrium path
    np.testing.assert_allclose(lam * P_lim, P_of_z(z), rtol=1e-8, atol=1e-12 * P_lim)
    # the apex keeps going down, the load passes its maximum and decreases (sign rule)
    assert np.all(np.diff(z) < 0)
    peak = int(np.argmax(lam))
    assert 0 < peak < len(lam) - 5
    assert np.all(np.diff(lam[peak:]) < 0)
    assert lam.max() == pytest.approx(1.0, rel=1e-2)  # limit load within 1 %
    assert z[-1] < 0.1 / np.sqrt(3) - 0.03  # well past the limit point


def test_mgdcm_default_step_adaptation_runs():
    s, P_of_z, P_lim = von_mises()
    load = np.zeros((3, 3))
    load[2, 2] = -P_lim
    r = solve_mgdcm(s, load, increments=8, lambda_bar=0.1, tol=1e-12)
    assert r.ok
    z = 0.1 + r.U_history[:, 2, 2]
    np.testing.assert_allclose(r.load_factor * P_lim, P_of_z(z), rtol=1e-8, atol=1e-12 * P_lim)
    np.testing.assert_allclose(r.applied_force, r.load_factor[-1] * load)


def test_displacement_control_reaches_prescribed_displacement():
    s, P_of_z, P_lim = von_mises()
    load = np.zeros((3, 3))
    load[2, 2] = -P_lim
    r = solve_displacement(s, load, (2, 2), increments=18, step=-0.01, tol=1e-12)
    assert r.ok
    np.testing.assert_allclose(r.U_history[:, 2, 2], -0.01 * np.arange(1, 19), atol=1e-12)
    z = 0.1 + r.U_history[:, 2, 2]
    np.testing.assert_allclose(r.load_factor * P_lim, P_of_z(z), rtol=1e-8, atol=1e-10 * P_lim)
    # through the limit point (lambda = 1 at z = h / sqrt(3)), through the flat position (z = 0,
    # no load) and on to negative loads (the truss pulls back before it snaps to z = -h)
    assert 0.99 < r.load_factor.max() < 1.0 and r.load_factor[-1] < 0
    # the reference predictor (sized by lambda_bar) follows the same path
    r2 = solve_displacement(s, load, (2, 2), increments=5, lambda_bar=0.1, tol=1e-12)
    z2 = 0.1 + r2.U_history[:, 2, 2]
    np.testing.assert_allclose(r2.load_factor * P_lim, P_of_z(z2), rtol=1e-8)


# ------------------------------------------------------------------------------- self-folding
def test_selffold_single_hinge_reaches_target_angle():
    s = hinge()
    target = np.array([np.pi + 1.2])
    r = solve_selffold(s, target, increments=6, tol=1e-10)
    assert r.ok
    x = s.nodes + r.U
    assert dihedral_angle(x, s.springs)[0] == pytest.approx(np.pi + 1.2, abs=1e-9)
    np.testing.assert_allclose(r.load_factor, np.arange(1, 7) / 6)
    np.testing.assert_array_equal(r.spring_rest, target)
    # intermediate increments sit at the interpolated rest angles
    th = dihedral_angle(s.nodes + r.U_history, s.springs)[:, 0]
    np.testing.assert_allclose(th, np.pi + 1.2 * np.arange(1, 7) / 6, atol=1e-9)
    # bars stay (nearly) inextensible: the wing tip keeps its distance to the hinge
    assert np.hypot(*x[3, 1:]) == pytest.approx(1.0, rel=1e-6)


def test_newton_hinge_moment_balances_load():
    # a small vertical tip load F on the hinge wing: k dtheta = F * lever arm (1 m)
    k = 0.7
    s = hinge(k)
    F = 1e-6
    load = np.zeros((4, 3))
    load[3, 2] = F
    r = solve_newton(s, load, increments=1, tol=1e-14)
    assert r.ok
    dtheta = dihedral_angle(s.nodes + r.U, s.springs)[0] - np.pi
    assert k * dtheta == pytest.approx(F * 1.0, rel=1e-5)
