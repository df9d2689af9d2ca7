"""Dense-path models (at most DENSE_MAX_DOF free DOFs) factorise their tangent by a Cholesky
(banded where the band is narrow, else dense) and by LU only where it is not positive definite
(issue 37 item 2): the two-panel gripper's tangent, positive definite and indefinite, solved by
each path on both kernel paths, against the dense LU."""

import numpy as np
import pytest
from _kernel_paths import path  # noqa: F401  (the kernel-path fixture: numpy, compiled)
from scipy.linalg import lu_factor, lu_solve

from holofold.design.scenarios.gripper import gripper_model
from holofold.mechanics.assembly import Assembler
from holofold.mechanics.linear import (
    DENSE_MAX_DOF,
    SMALL_BAND_SHARE,
    SingularSystemError,
    dense_solver,
    small_cholesky,
    solver_path,
)

#: two-panel row 2 of the published sample (data2_TwoPanel_sample.txt), SI units
ROW = dict(
    Pattern=3.0, L1=0.00368126880596801, L2=0.00212764616566953, t1=2.26408095856513e-07,
    t2=8.40695611154828e-07, tpanel=2.52316182998975e-05, rate=0.294787950175021,
    W=0.000286383490247001,
)  # fmt: skip
RTOL = 1e-12


@pytest.fixture(scope="module")
def gripper():
    """The two-panel gripper held as in its heating stage: (assembler, U positive definite,
    U indefinite), U (ndof,) m. The definite state stretches the model by 1 % about its
    centroid (every bar in tension), the indefinite one shrinks it by 5 % (every bar in
    compression, a negative geometric stiffness across it)."""
    model = gripper_model(ROW)
    s = model.structure.fixed(model.nodes.hold_heating)
    asm = Assembler(s)
    X = np.asarray(s.nodes, float)
    U_pd = 0.01 * (X - X.mean(axis=0))
    U_ind = -0.05 * (X - X.mean(axis=0))
    return asm, U_pd.ravel(), U_ind.ravel()


def _tangent(asm, U):
    _, f, K = asm.evaluate_reduced(U.reshape(-1, 3), dense=True)
    return np.asarray(K), f


def _definite(K) -> bool:
    return bool(np.linalg.eigvalsh(K).min() > 0.0)


def _relative_residual(K, x, b) -> float:
    return float(np.linalg.norm(K @ x - b) / (np.linalg.norm(K, 2) * np.linalg.norm(x)))


def test_the_gripper_takes_the_banded_cholesky(gripper):
    asm, *_ = gripper
    red = asm.reduction
    assert solver_path(red) == "dense" and red.n_free <= DENSE_MAX_DOF
    assert red.n_free == 99 and red.band.bandwidth == 32  # benchmarks/speed_targets.md
    assert small_cholesky(red) == "banded"


def test_a_wide_band_takes_the_dense_cholesky(gripper):
    """The choice follows the band's width: with a share below the gripper's 33 / 99 its
    dense Cholesky is chosen."""
    asm, *_ = gripper
    red = asm.reduction
    share = (red.band.bandwidth + 1) / red.n_free
    assert share <= SMALL_BAND_SHARE
    import holofold.mechanics.linear as linear

    old = linear.SMALL_BAND_SHARE
    try:
        linear.SMALL_BAND_SHARE = 0.9 * share
        assert small_cholesky(red) == "dense"
    finally:
        linear.SMALL_BAND_SHARE = old


def test_the_two_states_are_what_they_say(gripper):
    asm, U_pd, U_ind = gripper
    assert _definite(_tangent(asm, U_pd)[0])
    assert not _definite(_tangent(asm, U_ind)[0])


@pytest.mark.parametrize("state", ["definite", "indefinite"])
def test_dense_solver_agrees_with_lu(gripper, state):
    asm, U_pd, U_ind = gripper
    K, _ = _tangent(asm, U_pd if state == "definite" else U_ind)
    b = np.random.default_rng(1).normal(size=K.shape[0])
    solve = dense_solver(np.asfortranarray(K), symmetric=True)
    x = solve(b)
    assert solve.factorisation() == ("cholesky" if state == "definite" else "lu")
    x_lu = lu_solve(lu_factor(K), b)
    assert _relative_residual(K, x, b) <= RTOL
    assert _relative_residual(K, x_lu, b) <= RTOL
    # several right-hand sides: the same factorisation
    B = np.column_stack([b, 2 * b])
    X2 = solve(B)
    np.testing.assert_allclose(X2[:, 0], x, rtol=0, atol=1e-12 * np.abs(x).max())


def test_dense_solver_raises_on_a_singular_matrix():
    K = np.zeros((3, 3))
    K[0, 0] = 1.0
    with pytest.raises(SingularSystemError):
        dense_solver(K, symmetric=True)(np.ones(3))


@pytest.mark.parametrize("cholesky", ["banded", "dense"])
@pytest.mark.parametrize("state", ["definite", "indefinite"])
def test_newton_step_agrees_with_lu(gripper, path, state, cholesky, monkeypatch):  # noqa: F811
    """One Newton step (the kernel path's ``small_newton_step``) on the gripper's tangent:
    the Cholesky where it is positive definite, else the LU (and ``lu`` set for the rest of
    the increment); the solution solves K dU = r to 1e-12 relative residual, as the step
    forced onto the LU does."""
    import holofold.mechanics.linear as linear

    asm, U_pd, U_ind = gripper
    if cholesky == "dense":
        monkeypatch.setattr(linear, "SMALL_BAND_SHARE", 0.0)
    asm.reduction._symbolic.pop(f"small_step:{path.module.__name__}", None)  # re-chosen
    try:
        U0 = U_pd if state == "definite" else U_ind
        K, f = _tangent(asm, U0)
        F = np.zeros(asm.structure.n_dof)
        r = np.empty(asm.free_dofs.size)
        U = U0.copy()
        step = asm.dense_stepper(U, F, r=r)
        dU = step().copy()
        assert step.lu[0] == (0 if state == "definite" else 1)
        b = (F - f)[asm.free_dofs]
        np.testing.assert_allclose(r, b, rtol=0, atol=1e-12 * np.abs(b).max())
        assert _relative_residual(K, dU, b) <= RTOL
        np.testing.assert_allclose(U[asm.free_dofs], U0[asm.free_dofs] + dU, rtol=0, atol=0)
        # the same step forced onto the LU (what the dense path did before)
        U_lu = U0.copy()
        forced = asm.dense_stepper(U_lu, F)
        forced.lu[0] = 1
        dU_lu = forced().copy()
        assert _relative_residual(K, dU_lu, b) <= RTOL
        # a well-conditioned direction: the two solutions agree far beyond the tolerances
        np.testing.assert_allclose(K @ dU, K @ dU_lu, rtol=0, atol=1e-10 * np.abs(b).max())
    finally:
        asm.reduction._symbolic.pop(f"small_step:{path.module.__name__}", None)


def test_the_lu_stays_for_the_increment(gripper, path):  # noqa: F811
    """Once the Cholesky failed, the stepper (one increment) factorises by LU directly."""
    asm, U_pd, U_ind = gripper
    U = U_ind.copy()
    step = asm.dense_stepper(U, np.zeros(asm.structure.n_dof))
    step()
    assert step.lu[0] == 1
    U[:] = U_pd
    step()  # now positive definite, still LU
    assert step.lu[0] == 1
    fresh = asm.dense_stepper(U_pd.copy(), np.zeros(asm.structure.n_dof))
    fresh()
    assert fresh.lu[0] == 0
