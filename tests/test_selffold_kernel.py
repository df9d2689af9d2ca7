"""The self-fold stage in one kernel call (``selffold_increments``) and the steady temperature's
compiled call (``thermal_steady``), issue 37 item 2: the same results as the per-increment
loop and the numpy path, to round-off."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from _kernel_paths import NO_COMPILED, path  # noqa: F401  (the kernel-path fixture: numpy, compiled)

from holofold.geometry.gripper import two_panel_gripper
from holofold.mechanics import kernels
from holofold.mechanics.assembly import Assembler
from holofold.mechanics.hinges import build_compliant, crease_rest_targets
from holofold.mechanics.solvers import selffold as selffold_module
from holofold.mechanics.solvers import solve_selffold
from holofold.mechanics.thermal import steady_temperature, thermal_model


def _gripper(held: bool = True):
    pat = two_panel_gripper(4.1e-3, 3.1e-3, 0.49).pattern
    s = build_compliant(
        pat, crease_width=150e-6, crease_thickness=1.2e-6, panel_thickness=27e-6,
        E_panel=2e9, E_crease=2e9, nu_panel=0.3, nu_crease=0.3, diagonal_rate=100.0,
    )  # fmt: skip
    if held:
        sup = np.zeros((s.n_nodes, 3), bool)
        sup[:4] = True
        s = s.with_supports(sup)
    return s


def _fold(s, increments, max_iter=30, tol=1e-9, loop=False, monkeypatch=None):
    """solve_selffold of the compliant creases to 40 degrees from flat (1e-7 N down on every
    node), by the kernel or (``loop``) by the per-increment loop it replaced."""
    if loop:
        monkeypatch.setattr(selffold_module, "selffold_increments", lambda *a: None)
    cid = s.creases.ids
    full = np.full(int(cid.max()) + 1, np.pi)
    full[cid] = np.pi + np.deg2rad(40.0)
    target = crease_rest_targets(s, full)
    F0 = np.zeros((s.n_nodes, 3))
    F0[:, 2] = -1e-7
    asm = Assembler(s)
    try:
        return solve_selffold(
            s, target, increments=increments, tol=tol, max_iter=max_iter, F0=F0, assembler=asm
        )
    finally:
        if loop:
            monkeypatch.undo()


@pytest.mark.parametrize("increments, max_iter", [(4, 30), (3, 3)])
def test_the_kernel_folds_as_the_increment_loop(path, increments, max_iter, monkeypatch):  # noqa: F811
    """Every increment in one call gives the loop's histories (1e-12 of the displacement),
    iteration counts, convergence flags and status; ``max_iter`` 3 leaves increments above
    the tolerance, named alike."""
    s = _gripper()
    a = _fold(s, increments, max_iter)
    b = _fold(s, increments, max_iter, loop=True, monkeypatch=monkeypatch)
    scale = np.abs(b.U_history).max()
    assert scale > 1e-5  # it did fold
    np.testing.assert_allclose(a.U_history, b.U_history, rtol=0, atol=1e-12 * scale)
    np.testing.assert_array_equal(a.iterations, b.iterations)
    np.testing.assert_array_equal(a.converged, b.converged)
    np.testing.assert_allclose(a.residual, b.residual, rtol=1e-6)
    np.testing.assert_array_equal(a.load_factor, b.load_factor)
    np.testing.assert_array_equal(a.applied_force, b.applied_force)
    np.testing.assert_array_equal(a.spring_rest, b.spring_rest)
    assert a.status.converged == b.status.converged == (max_iter == 30)
    assert str(a.status) == str(b.status) or max_iter == 3
    assert type(a.status) is type(b.status)


@pytest.mark.skipif(bool(NO_COMPILED), reason=f"compiled path: {NO_COMPILED}")
def test_both_kernel_paths_fold_alike(monkeypatch):
    """The compiled and the numpy ``selffold_increments`` agree to 1e-9 on the converged fold."""
    s = _gripper()
    out = {}
    for name in ("numpy", "compiled"):
        monkeypatch.setenv(kernels.ENV, name)
        out[name] = _fold(s, 5)
    a, b = out["numpy"], out["compiled"]
    assert a.ok and b.ok
    np.testing.assert_allclose(b.U, a.U, rtol=0, atol=1e-9 * np.abs(a.U).max())
    np.testing.assert_array_equal(a.iterations, b.iterations)


def test_a_singular_model_fails_as_the_loop_does(path, monkeypatch):  # noqa: F811
    """Bars without stiffness: the first factorisation fails (Cholesky, then the LU); the
    status and histories are the loop's."""
    s = _gripper()
    s = dataclasses.replace(s, bar_E=np.zeros_like(s.bar_E))
    a = _fold(s, 3)
    b = _fold(s, 3, loop=True, monkeypatch=monkeypatch)
    assert a.failed and b.failed
    assert str(a.status) == str(b.status)
    assert "increment 1, iteration 1" in str(a.status)
    np.testing.assert_array_equal(a.U_history, b.U_history)
    np.testing.assert_array_equal(a.iterations, b.iterations)


@pytest.mark.skipif(bool(NO_COMPILED), reason=f"compiled path: {NO_COMPILED}")
def test_thermal_steady_is_the_numpy_path(monkeypatch):
    """steady_temperature's compiled call (``thermal_steady``) gives the numpy path's
    temperatures to 1e-12 of the rise, flat and deformed; a collapsed triangle is named."""
    s = _gripper(held=False)
    model = thermal_model(s, panel_conductivity=0.3, crease_conductivity=0.2, air_thickness=4e-3)
    rng = np.random.default_rng(7)
    q = rng.uniform(0, 1e-3, s.n_nodes)
    for scale in (0.0, 1e-6, 1e-4):
        x = s.nodes + rng.normal(0, scale, s.nodes.shape)
        monkeypatch.setenv(kernels.ENV, "numpy")
        T_np = steady_temperature(model, x, q)
        monkeypatch.setenv(kernels.ENV, "compiled")
        T_c = steady_temperature(model, x, q)
        rise = np.abs(T_np - model.room_temperature).max()
        assert rise > 0.1
        np.testing.assert_allclose(T_c, T_np, rtol=0, atol=1e-12 * rise)
    x = s.nodes.copy()
    a, _, c = model.triangles[5]
    x[c] = x[a]
    with pytest.raises(ValueError, match="triangle 5 .* zero area"):
        steady_temperature(model, x, q)
