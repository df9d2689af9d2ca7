"""Load control of one dense-path design in one kernel call (``load_increments``, issue 37
item 2: the gripper's prying): the same results as the per-increment ``DenseStepper`` loop and
the numpy path, to round-off."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from _kernel_paths import NO_COMPILED, path  # noqa: F401  (the kernel-path fixture: numpy, compiled)
from test_selffold_kernel import _gripper

from holofold.mechanics import kernels
from holofold.mechanics.assembly import Assembler
from holofold.mechanics.solvers import newton as newton_module
from holofold.mechanics.solvers import solve_newton


def _pull(s, increments, force=1e-7, tol=1e-11, max_iter=30, loop=False, monkeypatch=None):
    """solve_newton of the held gripper pulled up at its free corner nodes (``force`` N per
    increment, 1e-7 N down on every node already applied), by the kernel or (``loop``) by
    the per-increment loop it replaced."""
    if loop:
        monkeypatch.setattr(newton_module, "load_increments", lambda *a: None)
    P = np.zeros((s.n_nodes, 3))
    P[-4:, 2] = force
    F0 = np.zeros((s.n_nodes, 3))
    F0[:, 2] = -1e-7
    try:
        return solve_newton(
            s, P, increments=increments, tol=tol, max_iter=max_iter, F0=F0,
            assembler=Assembler(s),
        )  # fmt: skip
    finally:
        if loop:
            monkeypatch.undo()


def _same(a, b, exact_status=True):
    scale = np.abs(b.U_history).max()
    assert scale > 1e-7  # it did move
    np.testing.assert_allclose(a.U_history, b.U_history, rtol=0, atol=1e-12 * scale)
    np.testing.assert_array_equal(a.iterations, b.iterations)
    np.testing.assert_array_equal(a.converged, b.converged)
    np.testing.assert_allclose(a.residual, b.residual, rtol=1e-6)
    np.testing.assert_array_equal(a.load_factor, b.load_factor)
    np.testing.assert_allclose(a.applied_force, b.applied_force, rtol=1e-15)
    np.testing.assert_array_equal(a.spring_rest, b.spring_rest)
    assert a.status.converged == b.status.converged
    assert type(a.status) is type(b.status)
    if exact_status:
        assert str(a.status) == str(b.status)


@pytest.mark.parametrize("increments, max_iter", [(4, 30), (3, 2)])
def test_the_kernel_loads_as_the_increment_loop(path, increments, max_iter, monkeypatch):  # noqa: F811
    """Every increment in one call gives the loop's histories (1e-12 of the displacement),
    iteration counts, convergence flags and status; ``max_iter`` 2 (one iteration) leaves
    increments above the tolerance, named alike."""
    s = _gripper()
    a = _pull(s, increments, max_iter=max_iter)
    b = _pull(s, increments, max_iter=max_iter, loop=True, monkeypatch=monkeypatch)
    _same(a, b, exact_status=max_iter == 30)
    assert a.status.converged == (max_iter == 30)


def test_an_unresolved_increment_is_named_as_the_loop_names_it(path, monkeypatch):  # noqa: F811
    """A load of 1e-30 N moves the nodes below the round-off resolution: every increment is
    'not converged' with that reason, as in the loop."""
    s = _gripper()
    a = _pull(s, 2, force=1e-30, tol=1e-5)
    b = _pull(s, 2, force=1e-30, tol=1e-5, loop=True, monkeypatch=monkeypatch)
    assert not a.status.converged and not b.status.converged
    assert str(a.status) == str(b.status)
    np.testing.assert_array_equal(a.converged, b.converged)
    np.testing.assert_array_equal(a.iterations, b.iterations)


def test_a_singular_model_fails_as_the_loop_does(path, monkeypatch):  # noqa: F811
    """Bars without stiffness: the first factorisation fails (Cholesky, then the LU); the
    status and histories are the loop's."""
    s = _gripper()
    s = dataclasses.replace(s, bar_E=np.zeros_like(s.bar_E))
    a = _pull(s, 3)
    b = _pull(s, 3, loop=True, monkeypatch=monkeypatch)
    assert a.failed and b.failed
    assert str(a.status) == str(b.status)
    assert "increment 1, iteration 1" in str(a.status)
    np.testing.assert_array_equal(a.U_history, b.U_history)
    np.testing.assert_array_equal(a.iterations, b.iterations)
    np.testing.assert_array_equal(a.applied_force, b.applied_force)


@pytest.mark.skipif(bool(NO_COMPILED), reason=f"compiled path: {NO_COMPILED}")
def test_both_kernel_paths_load_alike(monkeypatch):
    """The compiled and the numpy ``load_increments`` agree to 1e-9 on the converged run."""
    s = _gripper()
    out = {}
    for name in ("numpy", "compiled"):
        monkeypatch.setenv(kernels.ENV, name)
        out[name] = _pull(s, 3)
    a, b = out["numpy"], out["compiled"]
    assert a.ok and b.ok
    np.testing.assert_allclose(b.U, a.U, rtol=0, atol=1e-9 * np.abs(a.U).max())
    np.testing.assert_array_equal(a.iterations, b.iterations)
