"""The supernodal sparse Cholesky path (mechanics.sparse_cholesky, CHOLMOD through cvxopt)
against scipy's SuperLU / spsolve, on holofold's own tangents and on well-conditioned SPD
matrices, to stated tolerances (never bit equality: two libraries round differently)."""

from __future__ import annotations

import gc
import sys

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

pytest.importorskip("cvxopt", reason="cvxopt (the optional CHOLMOD path) is not installed")

from holofold.geometry.errors import EnvironmentFault  # noqa: E402
from holofold.geometry.miura import miura_sheet  # noqa: E402
from holofold.mechanics import sparse_cholesky  # noqa: E402
from holofold.mechanics.assembly import Assembler, SingularSystemError  # noqa: E402
from holofold.mechanics.hinges import build_concentrated  # noqa: E402
from holofold.mechanics.sparse_cholesky import SparseCholesky  # noqa: E402


def _sheet(m: int, n: int):
    """A concentrated-hinge Miura sheet clamped at x = min (the scaling benchmark's model)."""
    p = miura_sheet(m, n, 0.2 / m, 0.2 / n, np.deg2rad(70.0), 0.6)
    s = build_concentrated(p, crease_width=2.5e-3, crease_thickness=7.5e-4, panel_thickness=3.5e-3)
    x = s.nodes[:, 0]
    return s.fixed(np.flatnonzero(np.isclose(x, x.min())))


@pytest.fixture(scope="module")
def tangents():
    """Reduced csr tangents of a 12 x 4 sheet (324 free DOFs): at rest and displaced by 1 um
    (both positive definite, condition ~4e6) and displaced by 0.1 mm at random (indefinite:
    compressed bars, lowest eigenvalue about -9e3 N/m)."""
    s = _sheet(12, 4)
    asm = Assembler(s)
    rng = np.random.default_rng(7)
    out = []
    for scale in (0.0, 1e-6, 1e-4):
        U = scale * rng.standard_normal((s.n_nodes, 3))
        U[s.supports] = 0.0
        _, _, K = asm.evaluate_reduced(U, dense=False)
        out.append(K.tocsr())
    return out


def _laplacian_spd(n_side: int, seed: int = 0) -> sp.csr_matrix:
    """A well-conditioned SPD matrix: a random-weight 2-D grid Laplacian plus a diagonal shift,
    indices unsorted within rows (condition number below 1e3)."""
    rng = np.random.default_rng(seed)
    n = n_side * n_side
    idx = np.arange(n).reshape(n_side, n_side)
    a = np.concatenate([idx[:, :-1].ravel(), idx[:-1, :].ravel()])
    b = np.concatenate([idx[:, 1:].ravel(), idx[1:, :].ravel()])
    w = rng.uniform(0.5, 2.0, a.size)
    W = sp.coo_matrix((w, (a, b)), shape=(n, n))
    W = W + W.T
    L = sp.diags(np.asarray(W.sum(axis=1)).ravel() + 0.1) - W
    K = L.tocsr()
    for i in range(n):  # shuffle the column order inside each row
        lo, hi = K.indptr[i], K.indptr[i + 1]
        p = lo + rng.permutation(hi - lo)
        K.indices[lo:hi], K.data[lo:hi] = K.indices[p].copy(), K.data[p].copy()
    K.has_sorted_indices = False
    return K


def _rel(x, ref):
    return np.abs(x - ref).max() / np.abs(ref).max()


def test_real_tangents_match_superlu(tangents):
    """On holofold's tangents (condition ~1e8: stiff bars, soft hinges) the solutions agree
    with SuperLU's to 1e-6 relative (cond x machine epsilon, with margin) and their backward
    error is at round-off (1e-12 of ||K|| ||x||)."""
    for K in tangents[:2]:
        n = K.shape[0]
        chol = SparseCholesky(K.indptr, K.indices)
        f = chol.factor(K.data)
        assert f is not None
        b = np.random.default_rng(1).standard_normal(n)
        x = f.solve(b)
        ref = spla.splu(K.tocsc()).solve(b)
        assert _rel(x, ref) < 1e-6
        backward = np.linalg.norm(K @ x - b) / (spla.norm(K, 1) * np.linalg.norm(x, 1))
        assert backward < 1e-12


def test_indefinite_tangent_gives_none(tangents):
    """The displaced sheet's indefinite tangent is refused (None), as its eigenvalues say."""
    K = tangents[2]
    assert np.linalg.eigvalsh(K.toarray()).min() < 0
    assert SparseCholesky(K.indptr, K.indices).factor(K.data) is None


def test_well_conditioned_matches_spsolve_and_several_rhs():
    """A well-conditioned SPD matrix with unsorted indices: one and several right-hand sides
    agree with spsolve to 1e-12 relative; calling the factor is solve."""
    K = _laplacian_spd(30)
    chol = SparseCholesky(K.indptr, K.indices)
    f = chol.factor(K.data)
    B = np.random.default_rng(2).standard_normal((K.shape[0], 3))
    X = f.solve(B)
    ref = spla.spsolve(K.tocsc(), B)
    assert X.shape == B.shape
    assert _rel(X, ref) < 1e-12
    assert _rel(f(B[:, 1]), ref[:, 1]) < 1e-12


def test_not_positive_definite_gives_none_then_recovers():
    """An indefinite matrix on the pattern gives None (the caller's cue to use LU); the next
    positive definite values still factorise correctly."""
    K = _laplacian_spd(12)
    chol = SparseCholesky(K.indptr, K.indices)
    bad = K.copy()
    bad.data = np.where(bad.indices == np.repeat(np.arange(K.shape[0]), np.diff(K.indptr)),
                        -bad.data, bad.data)  # fmt: skip
    assert chol.factor(bad.data) is None
    assert chol.factor(-K.data) is None
    b = np.ones(K.shape[0])
    assert _rel(chol.factor(K.data).solve(b), spla.spsolve(K.tocsc(), b)) < 1e-12


def test_nan_values_never_give_a_finite_looking_answer():
    K = _laplacian_spd(8)
    chol = SparseCholesky(K.indptr, K.indices)
    data = K.data.copy()
    data[K.indptr[5] : K.indptr[6]] = np.nan  # a whole row, the diagonal and upper part too
    f = chol.factor(data)
    if f is not None:
        with pytest.raises(SingularSystemError, match="non-finite"):
            f.solve(np.ones(K.shape[0]))


def test_live_factors_are_independent_and_storage_is_recycled():
    """Two factors of one pattern alive at once each solve their own matrix; a dropped
    factor's CHOLMOD storage is reused by the next factorisation."""
    K = _laplacian_spd(15)
    chol = SparseCholesky(K.indptr, K.indices)
    b = np.random.default_rng(3).standard_normal(K.shape[0])
    K2 = K.copy()
    K2.data = K2.data * 3.0
    f1 = chol.factor(K.data)
    f2 = chol.factor(K2.data)
    assert _rel(f1.solve(b), spla.spsolve(K.tocsc(), b)) < 1e-12
    assert _rel(f2.solve(b), spla.spsolve(K2.tocsc(), b)) < 1e-12
    assert len(chol._idle) == 0
    del f1
    gc.collect()
    assert len(chol._idle) == 1
    chol.factor(K.data)
    assert len(chol._idle) <= 1


def test_given_ordering_and_upper_pattern(tangents):
    """A caller's ordering is used as given (reverse Cuthill-McKee here), and a pattern that
    holds only the upper triangle gives the same solution as the full one (to 1e-9)."""
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    K = tangents[0]
    b = np.random.default_rng(4).standard_normal(K.shape[0])
    ref = SparseCholesky(K.indptr, K.indices).factor(K.data).solve(b)
    rcm = reverse_cuthill_mckee(K, symmetric_mode=True).astype(np.int64)
    chol = SparseCholesky(K.indptr, K.indices, ordering=rcm)
    np.testing.assert_array_equal(chol.order, rcm)
    assert _rel(chol.factor(K.data).solve(b), ref) < 1e-9
    U = sp.triu(K, format="csr")
    assert _rel(SparseCholesky(U.indptr, U.indices).factor(U.data).solve(b), ref) < 1e-9


def test_nested_dissection_candidate(monkeypatch):
    """On large patterns METIS's nested dissection (pymetis, where installed) is offered to
    CHOLMOD beside its AMD; without pymetis AMD alone. Both solve to 1e-12 of spsolve."""
    K = _laplacian_spd(20)
    b = np.random.default_rng(8).standard_normal(K.shape[0])
    ref = spla.spsolve(K.tocsc(), b)
    monkeypatch.setattr(sparse_cholesky, "METIS_MIN_DOF", 100)
    metis = SparseCholesky(K.indptr, K.indices)
    if sparse_cholesky.nested_dissection(np.array([1]), np.array([0]), 2) is None:
        assert metis._nmethods == 1  # no pymetis: AMD as given
    else:
        assert metis._nmethods == 0  # METIS's order and CHOLMOD's AMD compared
        assert sorted(metis.order.tolist()) == list(range(K.shape[0]))
    assert _rel(metis.factor(K.data).solve(b), ref) < 1e-12
    amd = SparseCholesky(K.indptr, K.indices, ordering="amd")
    assert amd._nmethods == 1
    assert _rel(amd.factor(K.data).solve(b), ref) < 1e-12
    monkeypatch.setitem(sys.modules, "pymetis", None)
    assert SparseCholesky(K.indptr, K.indices)._nmethods == 1


@pytest.mark.parametrize(
    "case, message",
    [
        ("no diagonal", "every diagonal entry"),
        ("bad indptr", "CSR row pointer"),
        ("index out of range", "column indices"),
        ("bad ordering", "permutation"),
        ("unknown ordering", "'amd' or a permutation"),
    ],
)
def test_bad_input_is_one_clear_error(case, message):
    K = _laplacian_spd(4)
    indptr, indices, ordering = K.indptr, K.indices, None
    if case == "no diagonal":
        M = K.copy()
        M.setdiag(0)
        M.eliminate_zeros()
        indptr, indices = M.indptr, M.indices
    elif case == "bad indptr":
        indptr = indptr[::-1]
    elif case == "index out of range":
        indices = indices + 1
    elif case == "bad ordering":
        ordering = np.zeros(K.shape[0], int)
    else:
        ordering = "metis"
    with pytest.raises(ValueError, match=message):
        SparseCholesky(indptr, indices, ordering=ordering)
    if case == "no diagonal":
        f = SparseCholesky(K.indptr, K.indices).factor(K.data)
        with pytest.raises(ValueError, match="rhs must have shape"):
            f.solve(np.ones(K.shape[0] + 1))


def test_missing_cvxopt_is_an_environment_fault(monkeypatch):
    """Without cvxopt, available() is False and building the solver stops in one line that
    names the fix."""
    monkeypatch.setattr(sparse_cholesky, "_CVXOPT", None)
    monkeypatch.setattr(sparse_cholesky, "_AVAILABLE", None)
    monkeypatch.setitem(sys.modules, "cvxopt", None)
    assert not sparse_cholesky.available()
    K = _laplacian_spd(3)
    with pytest.raises(EnvironmentFault, match=r"holofold\[cholmod\]"):
        SparseCholesky(K.indptr, K.indices)


# ---------------------------------------------------------------- the solver choice (linear)
@pytest.fixture(scope="module")
def canopy_sheet():
    """A 36 x 12 sheet: 2700 free DOFs, band work 6.1e7 > CHOLESKY_MIN_WORK."""
    return _sheet(36, 12)


def test_solver_path_takes_the_sparse_cholesky_by_band_work(canopy_sheet, monkeypatch):
    """Above CHOLESKY_MIN_WORK the assembler takes the sparse Cholesky; without cvxopt (and
    on the numpy kernel path) the band up to BANDED_MAX_WORK; small models stay on the band."""
    from holofold.mechanics import linear

    red = Assembler(canopy_sheet).reduction
    work = red.n_free * (red.band.bandwidth + 1) ** 2
    assert linear.CHOLESKY_MIN_WORK < work <= linear.BANDED_MAX_WORK
    assert linear.solver_path(red) == "cholesky"
    assert Assembler(_sheet(12, 4)).solver == "banded"
    monkeypatch.setattr(sparse_cholesky, "_AVAILABLE", False)
    monkeypatch.setenv("HOLOFOLD_KERNELS", "numpy")  # else holofold's own sparse Cholesky
    assert linear.solver_path(red) == "banded"
    monkeypatch.setattr(linear, "BANDED_MAX_WORK", work / 2)
    assert linear.solver_path(red) == "superlu"


def test_assembler_on_the_cholesky_path_matches_superlu(canopy_sheet):
    """evaluate_factorized on the sparse Cholesky path solves as SuperLU does (1e-6 relative,
    the tangent's condition ~1e7 x eps with margin), one and several right-hand sides; at an
    indefinite state it falls back to LU and still solves."""
    from holofold.mechanics import linear

    asm = Assembler(canopy_sheet)
    assert asm.solver == "cholesky"
    rng = np.random.default_rng(5)
    for scale in (0.0, 1e-4):  # at rest (SPD) and displaced at random (indefinite)
        U = scale * rng.standard_normal((canopy_sheet.n_nodes, 3))
        U[canopy_sheet.supports] = 0.0
        _, _, solve = asm.evaluate_factorized(U)
        _, _, K = asm.evaluate_reduced(U, dense=False)
        B = rng.standard_normal((K.shape[0], 2))
        ref = spla.splu(K.tocsc()).solve(B)
        assert _rel(solve(B[:, 0]), ref[:, 0]) < 1e-6
        assert _rel(solve(B), ref) < 1e-6
        on_cholesky = isinstance(solve, sparse_cholesky.CholeskyFactor)
        assert on_cholesky == (scale == 0.0)
    a = asm._elements(np.zeros((canopy_sheet.n_nodes, 3)), None)[2]
    upper = asm._tangent(a, "csr_upper")  # the upper triangle, all the factorisation reads
    assert upper.size == asm.reduction.upper_keep.size
    np.testing.assert_allclose(upper, asm._tangent(a, "csr")[asm.reduction.upper_keep], rtol=1e-13)
    assert linear.cholesky_solver(upper, asm.reduction) is not None


def test_batch_newton_step_on_the_cholesky_path(canopy_sheet):
    """BatchAssembler.newton_step of three samples on the sparse Cholesky path (one at an
    indefinite state: LU) gives each sample's own Assembler increment to 1e-9 relative."""
    from holofold.mechanics.assembly import BatchAssembler

    s = canopy_sheet
    batch = BatchAssembler([s, s, s])
    rng = np.random.default_rng(6)
    U = np.zeros((3, s.n_dof))
    U[2] = 1e-4 * rng.standard_normal(s.n_dof) * ~s.supports.ravel()
    F = np.zeros((3, s.n_dof))
    F[:, 2::3] = -1e-3 * np.arange(1, 4)[:, None]  # a small load along -z, one per sample
    F[:, s.supports.ravel()] = 0.0
    expected = []
    asm = Assembler(s)
    free = asm.free_dofs
    for i in range(3):
        _, f, solve = asm.evaluate_factorized(U[i].reshape(-1, 3))
        expected.append(solve((F[i] - f)[free]))
    dU, errors = batch.newton_step(U, F, np.ones(3, bool))
    assert not errors
    for i in range(3):
        assert _rel(dU[i], expected[i]) < 1e-9
