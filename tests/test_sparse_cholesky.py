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


@pytest.mark.parametrize(
    "case, message",
    [
        ("no diagonal", "every diagonal entry"),
        ("bad indptr", "CSR row pointer"),
        ("index out of range", "column indices"),
        ("bad ordering", "permutation"),
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
    else:
        ordering = np.zeros(K.shape[0], int)
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
    monkeypatch.setitem(sys.modules, "cvxopt", None)
    assert not sparse_cholesky.available()
    K = _laplacian_spd(3)
    with pytest.raises(EnvironmentFault, match=r"holofold\[cholmod\]"):
        SparseCholesky(K.indptr, K.indices)
