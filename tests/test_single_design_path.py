"""The path of one sheet design (issue 37 item 3): cached supports and load groups, the stacked
kernel inputs of structures sharing one bar array, the converged records of the batched
Newton solve, and the numpy and compiled kernels on it."""

from __future__ import annotations

import numpy as np
import pytest

from holofold.design.scenarios import sheet, single_miura
from holofold.mechanics import kernels
from holofold.mechanics.analyses import load_along
from holofold.mechanics.assembly import BatchAssembler, KernelInputs
from holofold.mechanics.solvers import solve_newton, solve_newton_batch
from holofold.mechanics.status import CONVERGED
from holofold.mechanics.structure import support_mask

ROW = dict(tcrease=0.75e-3, tpanel=3.5e-3, W=2.5e-3, gama=1.1)
OTHER = dict(tcrease=0.6e-3, tpanel=2.0e-3, W=1.5e-3, gama=1.3)


def _models(row):
    return sheet.sheet_models(single_miura.SETTING, row)


def test_supports_and_load_groups_are_those_of_the_end_nodes():
    """Each model's supports fix the nodes at x = min in xyz and its load group holds the nodes
    at x = max, as built from the nodes directly; designs with the same end nodes share the
    (read-only) arrays."""
    setting = single_miura.SETTING
    first, second = _models(ROW), _models(OTHER)
    for row, models in ((ROW, first), (OTHER, second)):
        for ext, (st, groups) in zip(setting.extensions, models, strict=True):
            x = sheet.sheet_nodes(setting, row, ext)
            low = np.flatnonzero(x[:, 0] == x[:, 0].min())
            high = np.flatnonzero(x[:, 0] == x[:, 0].max())
            np.testing.assert_array_equal(st.supports, support_mask(st.n_nodes, low, "xyz"))
            assert len(groups) == len(setting.loads) == 1
            ref = load_along(high, setting.loads[0].direction)
            np.testing.assert_array_equal(groups[0].nodes, ref.nodes)
            assert (groups[0].axis, groups[0].sign) == (ref.axis, ref.sign)
            assert not st.supports.flags.writeable
            assert not groups[0].nodes.flags.writeable
    assert first[0][0].supports is second[0][0].supports
    assert first[0][1] is second[0][1]


def test_stacked_inputs_of_a_shared_bar_array_match_the_general_stack():
    """Structures that share their bar array (one builder call) stack to the same kernel
    inputs as structures with bar arrays of their own (the general path), same dtypes and
    C order."""
    structures = [st for st, _ in _models(ROW)]
    assert all(st.bars is structures[0].bars for st in structures)
    own = [st.replace(bars=st.bars.copy()) for st in structures]
    fast, general = KernelInputs.stack_of(structures), KernelInputs.stack_of(own)
    for a, b in zip(fast, general, strict=True):
        assert a.dtype == b.dtype and a.shape == b.shape
        assert a.flags.c_contiguous and b.flags.c_contiguous
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=0.0)


@pytest.mark.parametrize("max_iter", [30, 2])
def test_batched_records_match_one_solve_each(max_iter):
    """Converged samples (their records built without describing each increment) and samples
    that miss the tolerance (max_iter 2: one iteration per increment) give the result of
    :func:`solve_newton` alone: displacements within 1e-9 of their size, the same status,
    iterations and applied force."""
    models = _models(ROW)
    structures = [st for st, _ in models]
    loads = np.stack([g[0].load(structures[0].n_nodes, 1.0) for _, g in models])
    runs = solve_newton_batch(
        structures, loads, increments=3, tol=1e-7, max_iter=max_iter,
        batch=BatchAssembler(structures),
    )  # fmt: skip
    for st, load, got in zip(structures, loads, runs, strict=True):
        ref = solve_newton(st, load, increments=3, tol=1e-7, max_iter=max_iter)
        scale = np.abs(ref.U_history).max()
        np.testing.assert_allclose(got.U_history, ref.U_history, rtol=0, atol=1e-9 * scale)
        assert str(got.status) == str(ref.status)
        assert (got.status is CONVERGED) == (max_iter == 30)
        np.testing.assert_array_equal(got.iterations, ref.iterations)
        np.testing.assert_array_equal(got.converged, ref.converged)
        np.testing.assert_allclose(got.applied_force, ref.applied_force, rtol=1e-12, atol=0)
        np.testing.assert_allclose(got.spring_rest, ref.spring_rest, rtol=1e-12, atol=0)
        np.testing.assert_allclose(got.load_factor, ref.load_factor, rtol=0, atol=0)


def test_one_design_on_the_numpy_and_compiled_kernels(monkeypatch):
    """The single Miura design evaluated on the numpy kernels (the reference path) and on the
    compiled ones: the converged stiffnesses agree to 1e-9 relative, the status is the same."""
    monkeypatch.setenv(kernels.ENV, "compiled")
    try:
        kernels.active()
    except kernels.EnvironmentFault:
        pytest.skip("no compiled kernels here (numba missing)")
    rows = [ROW, OTHER]
    compiled = [single_miura.SCENARIO.evaluate(r) for r in rows]
    monkeypatch.setenv(kernels.ENV, "numpy")
    numpy = [single_miura.SCENARIO.evaluate(r) for r in rows]
    batched = single_miura.SCENARIO.evaluate_batch(rows)  # numpy, all six sheets together
    for c, n, b in zip(compiled, numpy, batched, strict=True):
        assert str(c["status"]) == str(n["status"]) == str(b["status"]) == "converged"
        for col in ("axialstiff30", "axialstiff60", "axialstiff90"):
            assert c[col] > 0
            assert n[col] == pytest.approx(c[col], rel=1e-9)
            assert b[col] == pytest.approx(c[col], rel=1e-9)


def test_a_load_direction_given_as_a_list_still_builds():
    """A setting written in Python with a list direction (unhashable) builds the same load
    groups as with the tuple."""
    from dataclasses import replace

    listed = replace(
        single_miura.SETTING, loads=(sheet.SheetLoad("axial", [1.0, 0.0, 0.0], 3.0, 3),)
    )
    got = sheet.sheet_models(listed, ROW)
    ref = _models(ROW)
    for (_, g), (_, r) in zip(got, ref, strict=True):
        np.testing.assert_array_equal(g[0].nodes, r[0].nodes)
        assert (g[0].axis, g[0].sign) == (r[0].axis, r[0].sign)
