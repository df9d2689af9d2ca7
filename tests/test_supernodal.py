"""holofold's own supernodal Cholesky (mechanics.supernodal, the "cholesky" path on a plain
install) against dense LAPACK solves, and the solver choice between it, CHOLMOD and the
numpy/scipy fallback (band, SuperLU). Tolerances, never bit equality."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from holofold.geometry.miura import miura_sheet
from holofold.mechanics import linear, sparse_cholesky
from holofold.mechanics.assembly import Assembler, BatchAssembler
from holofold.mechanics.hinges import build_concentrated
from holofold.mechanics.supernodal import SupernodalCholesky, SupernodalFactor, metis_order


def _sheet(m: int, n: int):
    """A concentrated-hinge Miura sheet clamped at x = min (the scaling benchmark's model)."""
    p = miura_sheet(m, n, 0.2 / m, 0.2 / n, np.deg2rad(70.0), 0.6)
    s = build_concentrated(p, crease_width=2.5e-3, crease_thickness=7.5e-4, panel_thickness=3.5e-3)
    x = s.nodes[:, 0]
    return s.fixed(np.flatnonzero(np.isclose(x, x.min())))


def _backward_error(K, x, b) -> float:
    """||K x - b|| / (||K||_1 ||x||_1 + ||b||_1), per column: the relative residual."""
    K = sp.csr_matrix(K)
    r = K @ x - b
    norm_k = abs(K).sum(axis=0).max()
    return float(
        np.max(np.abs(r).sum(axis=0) / (norm_k * np.abs(x).sum(axis=0) + np.abs(b).sum(axis=0)))
    )


@pytest.fixture(scope="module")
def sheet_tangents():
    """Reduced csr tangents of a 24 x 8 sheet (1224 free DOFs): at rest (positive definite,
    condition ~1e7) and displaced by 0.1 mm at random (indefinite: compressed bars)."""
    s = _sheet(24, 8)
    asm = Assembler(s)
    rng = np.random.default_rng(3)
    out = []
    for scale in (0.0, 1e-4):
        U = scale * rng.standard_normal((s.n_nodes, 3))
        U[s.supports] = 0.0
        K = asm.evaluate_reduced(U, dense=False)[2].tocsr()
        K.sort_indices()
        out.append(K)
    return out


def test_spd_sheet_tangent_matches_the_dense_solve(sheet_tangents):
    """At rest: relative residual below 1e-12 (one and three right-hand sides) and the
    solution of dense LAPACK to 1e-7 (condition ~1e7 x eps, with margin)."""
    K = sheet_tangents[0]
    rng = np.random.default_rng(0)
    B = rng.standard_normal((K.shape[0], 3))
    ref = np.linalg.solve(K.toarray(), B)
    for ordering in (None, "mmd"):
        f = SupernodalCholesky(K.indptr, K.indices, ordering=ordering).factor(K.data)
        assert isinstance(f, SupernodalFactor)
        x = f.solve(B[:, 0])
        assert x.shape == (K.shape[0],)
        assert _backward_error(K, x[:, None], B[:, :1]) < 1e-12
        X = f.solve(B)
        assert X.shape == B.shape
        assert _backward_error(K, X, B) < 1e-12
        assert np.abs(X - ref).max() / np.abs(ref).max() < 1e-7
    # the dense reference meets the same relative residual
    assert _backward_error(K, ref, B) < 1e-12


def test_indefinite_tangent_gets_the_ldl_factor(sheet_tangents, monkeypatch):
    """An indefinite tangent has no Cholesky factor (factor() gives None) but an LDL^T one:
    relative residual below 1e-12 and dense LAPACK's solution to 1e-7; the assembler on the
    supernodal path takes it (and the Cholesky factor where the tangent is definite)."""
    K = sheet_tangents[1]
    assert np.linalg.eigvalsh(K.toarray())[0] < 0.0
    chol = SupernodalCholesky(K.indptr, K.indices)
    assert chol.factor(K.data) is None
    f = chol.factor_ldl(K.data)
    assert f.ldl
    B = np.random.default_rng(2).standard_normal((K.shape[0], 2))
    X = f.solve(B)
    assert _backward_error(K, X, B) < 1e-12
    ref = np.linalg.solve(K.toarray(), B)
    assert np.abs(X - ref).max() / np.abs(ref).max() < 1e-7
    monkeypatch.setattr(sparse_cholesky, "_AVAILABLE", False)
    monkeypatch.setenv("HOLOFOLD_KERNELS", "compiled")
    s = _sheet(36, 12)
    asm = Assembler(s)
    assert asm.solver == "cholesky" and linear.cholesky_backend() == "supernodal"
    rng = np.random.default_rng(5)
    for scale in (0.0, 1e-4):  # positive definite (Cholesky), indefinite (LDL^T)
        U = scale * rng.standard_normal((s.n_nodes, 3))
        U[s.supports] = 0.0
        _, _, solve = asm.evaluate_factorized(U)
        assert isinstance(solve, SupernodalFactor) and solve.ldl == (scale != 0.0)
        K = asm.evaluate_reduced(U, dense=False)[2]
        b = rng.standard_normal((K.shape[0], 2))
        assert _backward_error(K, solve(b), b) < 1e-12


def test_upper_triangle_pattern_with_data_slots_and_a_given_ordering():
    """A pattern holding the upper triangle only, values read through data_slots from a
    larger array, a caller's ordering, several components (a forest of elimination trees)
    and a 1 x 1 block: solutions of dense LAPACK to 1e-12."""
    rng = np.random.default_rng(1)
    n = 60
    A = sp.random(n, n, density=0.08, random_state=2)
    A = A + A.T
    A = A + sp.diags(np.asarray(abs(A).sum(axis=1)).ravel() + 1.0)  # diagonally dominant
    K = sp.block_diag([A, sp.csr_matrix([[4.0]]), A]).tocsr()  # three components
    K.sort_indices()
    U = sp.triu(K).tocsr()
    U.sort_indices()
    big = np.full(2 * U.nnz, np.nan)
    slots = 2 * np.arange(U.nnz)[::-1]
    big[slots] = U.data
    order = rng.permutation(K.shape[0])
    b = rng.standard_normal(K.shape[0])
    ref = np.linalg.solve(K.toarray(), b)
    chol = SupernodalCholesky(U.indptr, U.indices, ordering=order, data_slots=slots)
    x = chol.factor(big).solve(b)
    assert np.abs(x - ref).max() / np.abs(ref).max() < 1e-12
    assert _backward_error(K, x[:, None], b[:, None]) < 1e-14
    # one analysis serves new values on the pattern
    x2 = chol.factor(2.0 * big).solve(b)
    np.testing.assert_allclose(x2, 0.5 * x, rtol=1e-12, atol=0.0)


def test_metis_ordering_where_pymetis_is_installed():
    """From METIS_MIN_DOF rows the nested dissection competes with MMD; either way the
    factor solves to round-off (a 2-D grid Laplacian of 10,000 rows)."""
    n_side = 100
    idx = np.arange(n_side * n_side).reshape(n_side, n_side)
    a = np.concatenate([idx[:, :-1].ravel(), idx[:-1, :].ravel()])
    c = np.concatenate([idx[:, 1:].ravel(), idx[1:, :].ravel()])
    W = sp.coo_matrix((np.ones(a.size), (a, c)), shape=(idx.size, idx.size))
    W = W + W.T
    K = (sp.diags(np.asarray(W.sum(axis=1)).ravel() + 0.1) - W).tocsr()
    K.sort_indices()
    b = np.random.default_rng(4).standard_normal(K.shape[0])
    chol = SupernodalCholesky(K.indptr, K.indices)
    x = chol.factor(K.data).solve(b)
    assert _backward_error(K, x[:, None], b[:, None]) < 1e-14
    rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
    if metis_order(K.shape[0], rows, K.indices) is None:
        pytest.skip("pymetis (x86_64 wheels, the cholmod extra) is not installed: MMD only")


def test_solver_path_choice(monkeypatch):
    """Above CHOLESKY_MIN_WORK: CHOLMOD where cvxopt is installed, else holofold's own
    supernodal Cholesky on the compiled kernel path; on the numpy one without cvxopt the band up to
    BANDED_MAX_WORK and SuperLU beyond; small models stay dense or banded whatever is
    installed."""
    red = Assembler(_sheet(36, 12)).reduction
    work = red.n_free * (red.band.bandwidth + 1) ** 2
    assert linear.CHOLESKY_MIN_WORK < work <= linear.BANDED_MAX_WORK
    small = Assembler(_sheet(12, 4)).reduction
    monkeypatch.setattr(sparse_cholesky, "_AVAILABLE", False)
    monkeypatch.setenv("HOLOFOLD_KERNELS", "compiled")
    assert linear.cholesky_backend() == "supernodal"
    assert linear.solver_path(red) == "cholesky"
    assert linear.solver_path(small) == "banded"
    monkeypatch.setenv("HOLOFOLD_KERNELS", "numpy")
    assert linear.cholesky_backend() is None
    assert linear.solver_path(red) == "banded"
    monkeypatch.setattr(linear, "BANDED_MAX_WORK", work / 2)
    assert linear.solver_path(red) == "superlu"
    monkeypatch.setattr(sparse_cholesky, "_AVAILABLE", True)
    assert linear.cholesky_backend() == "cholmod"
    assert linear.solver_path(red) == "cholesky"
    assert linear.solver_path(small) == "banded"


def test_batch_newton_step_on_the_supernodal_path(monkeypatch):
    """BatchAssembler.newton_step of two samples on the supernodal path (one indefinite: LDL^T)
    gives each sample's own Assembler increment to 1e-9 relative."""
    monkeypatch.setattr(sparse_cholesky, "_AVAILABLE", False)
    monkeypatch.setenv("HOLOFOLD_KERNELS", "compiled")
    s = _sheet(36, 12)
    batch = BatchAssembler([s, s])
    rng = np.random.default_rng(6)
    U = np.zeros((2, s.n_dof))
    U[1] = 1e-4 * rng.standard_normal(s.n_dof) * ~s.supports.ravel()
    F = 1e-3 * rng.standard_normal((2, s.n_dof))
    want = []
    for k in range(2):
        _, f, solve = Assembler(s).evaluate_factorized(U[k].copy())
        want.append(solve((F[k] - f)[batch.free_dofs]))
    dU, errors = batch.newton_step(U, F, np.ones(2, bool))
    assert not errors
    for k in range(2):
        assert np.abs(dU[k] - want[k]).max() <= 1e-9 * np.abs(want[k]).max()


@pytest.mark.parametrize("relax", [0.0, 0.1, 1.0])
def test_random_patterns_and_amalgamation(relax, monkeypatch):
    """Random symmetric patterns (1 to 300 rows, sparse to dense-ish), MMD or a random order,
    no, the default or heavy amalgamation of supernodes: dense LAPACK's solution to 1e-12."""
    from holofold.mechanics import supernodal

    monkeypatch.setattr(supernodal, "RELAX_ZEROS", relax)
    rng = np.random.default_rng(11)
    for _ in range(8):
        n = int(rng.integers(1, 300))
        A = sp.random(n, n, density=float(rng.uniform(0.003, 0.1)), random_state=rng)
        A = A + A.T
        K = (A + sp.diags(np.asarray(abs(A).sum(axis=1)).ravel() + 0.5)).tocsr()
        K.sort_indices()
        b = rng.standard_normal((n, 2))
        ref = np.linalg.solve(K.toarray(), b)
        for ordering in ("mmd", rng.permutation(n)):
            x = SupernodalCholesky(K.indptr, K.indices, ordering=ordering).factor(K.data)
            assert np.abs(x.solve(b) - ref).max() <= 1e-12 * np.abs(ref).max()


def test_ldl_on_random_indefinite_patterns_and_a_singular_pivot():
    """Random symmetric indefinite (diagonally dominant, mixed signs) patterns: LDL^T solves
    as dense LAPACK to 1e-12; a matrix with a zero row and column is refused (None: LU)."""
    rng = np.random.default_rng(12)
    for _ in range(8):
        n = int(rng.integers(1, 300))
        A = sp.random(n, n, density=float(rng.uniform(0.003, 0.1)), random_state=rng)
        A = A + A.T
        d = (np.asarray(abs(A).sum(axis=1)).ravel() + 0.5) * np.where(rng.random(n) < 0.4, -1, 1)
        K = (A + sp.diags(d)).tocsr()
        K.sort_indices()
        b = rng.standard_normal((n, 2))
        ref = np.linalg.solve(K.toarray(), b)
        f = SupernodalCholesky(K.indptr, K.indices).factor_ldl(K.data)
        assert np.abs(f.solve(b) - ref).max() <= 1e-12 * np.abs(ref).max()
    pattern = sp.csr_matrix(np.ones((3, 3)))
    values = np.array([[2.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, -3.0]])
    chol = SupernodalCholesky(pattern.indptr, pattern.indices)
    assert chol.factor_ldl(values.ravel()) is None
    assert chol.factor(values.ravel()) is None


def test_canopy_design_on_the_plain_install_matches_the_band_and_superlu(monkeypatch):
    """One canopy design of 36 x 12 panels (the "cholesky" path) on holofold's own sparse
    Cholesky, as a plain install runs it, gives the outputs of the numpy/scipy fallback (band,
    SuperLU) to 1e-9 (converged outputs)."""
    from holofold.design import get_scenario

    monkeypatch.setattr(sparse_cholesky, "_AVAILABLE", False)
    monkeypatch.setenv("HOLOFOLD_KERNELS", "compiled")
    sc = get_scenario("canopy")
    row = sc.complete(dict(pattern=2, m=36, n=12, tcrease=7e-4, tpanel=3e-3, W=2e-3))
    assert linear.cholesky_backend() == "supernodal"
    own = sc.evaluate(row)
    monkeypatch.setattr(linear, "cholesky_backend", lambda: None)
    ref = sc.evaluate(row)
    assert str(own["status"]) == str(ref["status"]) == "converged"
    for name in sc.performance_names:
        assert own[name] == pytest.approx(ref[name], rel=1e-9), name
