"""Cholesky factorisations of a sequence of symmetric positive definite matrices of one pattern.

The surface fit (:mod:`~holofold.fitting.surface_fit`) factorises its preconditioner block
``J_s^T J_s + rho J_c^T J_c + mu I`` (3 nv DOFs) about ten times per fit, each time with new
values on the same sparsity pattern. :class:`SPDFactor` does it with

* CHOLMOD's supernodal sparse Cholesky where the optional ``holofold[cholmod]`` extra (cvxopt)
  is installed: the fill-reducing ordering (approximate minimum degree) and the symbolic
  factorisation once per pattern, then only numeric factorisations. On the 64 x 64 fit's
  12,675 DOFs a numeric factorisation takes 0.03 CPU s against 0.07 for the banded one, and
  the gap grows with the size (the band's work grows as n min(m, n)^2);
* else LAPACK's banded Cholesky (``scipy.linalg.cholesky_banded``) in a band order of the
  DOFs given by the caller.

Both raise the diagonal damping tenfold while the factorisation breaks down (a matrix that is
positive definite only in exact arithmetic), at most eight times.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sl
import scipy.sparse as sp

__all__ = ["SPDFactor", "cholmod_available"]


def _cvxopt():
    """cvxopt's (matrix, spmatrix, cholmod, amd), or None where it is not installed."""
    try:
        from cvxopt import amd, cholmod, matrix, spmatrix
    except ImportError:
        return None
    return matrix, spmatrix, cholmod, amd


def cholmod_available() -> bool:
    """True where cvxopt's CHOLMOD imports (``pip install 'holofold[cholmod]'``)."""
    return _cvxopt() is not None


def _supernodal(cholmod, fn, *args):
    """``fn(*args)`` with CHOLMOD's supernodal factorisation chosen (cvxopt's module-wide
    options set for the call only)."""
    saved = dict(cholmod.options)
    cholmod.options["supernodal"] = 2
    try:
        return fn(*args)
    finally:
        cholmod.options.clear()
        cholmod.options.update(saved)


class SPDFactor:
    """Factorise ``A + mu I`` for SPD matrices ``A`` (scipy sparse, both triangles) of one
    pattern and solve with the last factorisation.

    Parameters
    ----------
    band_order : (n,) int
        A DOF order in which every ``A`` is banded (the banded path factorises
        ``A[o][:, o]``).
    bandwidth : int
        Upper bandwidth of ``A`` in that order.
    sparse : bool, optional
        Use CHOLMOD (default: where installed).
    """

    def __init__(self, band_order: np.ndarray, bandwidth: int, *, sparse: bool | None = None):
        self.order = np.asarray(band_order)
        self.inv = np.argsort(self.order)
        self.bw = int(bandwidth)
        cv = _cvxopt()
        self.sparse = cv is not None if sparse is None else bool(sparse)
        if self.sparse and cv is None:
            raise ImportError("the sparse path needs cvxopt (pip install 'holofold[cholmod]')")
        self._pattern = None  # (indptr, indices) of the last pattern, CHOLMOD's symbolic
        self._symbolic = None
        self._A = None
        self._diag = np.zeros(0, np.int64)
        self._gather = None  # (indptr, indices, gather, scatter or None) of the last A
        self._factor = None

    # --------------------------------------------------------------------- factorise
    def factor(self, A: sp.spmatrix, mu: float, structure: sp.spmatrix | None = None) -> float:
        """Factorise ``A + mu' I`` with ``mu' >= mu`` (raised while the factorisation breaks
        down, from at least 1e-11 of A's largest diagonal entry); returns ``mu'``. Raises
        :class:`numpy.linalg.LinAlgError` when eight tenfold raises do not make it positive
        definite.

        ``structure`` (optional, CHOLMOD path): a matrix whose pattern holds every later A's
        (a sparse product drops the entries that cancel to exactly 0, as on a symmetric
        starting state): the symbolic factorisation is made for it once, and an A with fewer
        entries is scattered into it instead of a new ordering and symbolic factorisation."""
        A = A.tocsr()
        if self.sparse:
            if structure is not None and self._pattern is None:
                S = sp.triu(structure, format="csr")
                S.sum_duplicates()
                S.sort_indices()
                self._ensure_pattern(S.indptr, S.indices, np.zeros(S.nnz))
            return self._factor_sparse(A, mu)
        return self._factor_banded(A, max(float(mu), 1e-11 * float(A.diagonal().max(initial=0.0))))

    def _factor_banded(self, A: sp.csr_matrix, mu: float) -> float:
        B = A[self.order][:, self.order].tocoo()
        n, bw = B.shape[0], self.bw
        up = B.col >= B.row
        if (B.col[up] - B.row[up]).max(initial=0) > bw:
            raise AssertionError("band pattern wider than planned")
        ab = np.zeros((bw + 1, n))
        ab[bw + B.row[up] - B.col[up], B.col[up]] = B.data[up]
        ab[bw] += mu
        for _ in range(8):
            try:  # ab itself is left untouched (overwrite_ab False)
                cf = sl.cholesky_banded(ab, lower=False, check_finite=False)
            except np.linalg.LinAlgError:
                ab[bw] += 9 * mu
                mu *= 10
                continue
            self._factor = cf
            return mu
        raise np.linalg.LinAlgError("not positive definite")

    def _upper(self, A: sp.csr_matrix) -> np.ndarray:
        """The values of A's upper triangle in the order of CHOLMOD's stored pattern (the
        upper triangle row by row, columns ascending). The gather is planned once per pattern
        of ``A`` (a product of the same sparse patterns has the same, possibly unsorted, CSR
        pattern every time): then it is one indexing, not ``triu`` and a sort per call."""
        if self._gather is not None and (
            np.array_equal(self._gather[0], A.indptr) and np.array_equal(self._gather[1], A.indices)
        ):
            if self._gather[3] is None:
                return A.data[self._gather[2]]
            out = np.zeros(len(self._pattern[1]))
            out[self._gather[3]] = A.data[self._gather[2]]
            return out
        n = A.shape[0]
        rows = np.repeat(np.arange(n), np.diff(A.indptr))
        cols = A.indices
        # the positions in (row, column) order: the rows are in order already, the columns are
        # sorted within each row by scipy's C routine carrying the positions as values (a
        # third of a lexsort's time; exact: positions < 2^53)
        P = sp.csr_matrix((np.arange(A.nnz, dtype=float), cols.copy(), A.indptr.copy()),
                          shape=A.shape)  # fmt: skip
        P.sort_indices()
        up = P.data[P.indices >= rows].astype(np.int64)
        if len(up) and np.any(
            (rows[up][1:] == rows[up][:-1]) & (cols[up][1:] == cols[up][:-1])
        ):  # duplicate entries: sum them the slow way (not planned)
            self._gather = None
            U = sp.triu(A, format="csr")
            U.sum_duplicates()
            U.sort_indices()
            return self._ensure_pattern(U.indptr, U.indices, U.data)
        indptr = np.searchsorted(rows[up], np.arange(n + 1)).astype(A.indptr.dtype)
        if self._pattern is not None and not (
            np.array_equal(self._pattern[0], indptr) and np.array_equal(self._pattern[1], cols[up])
        ):  # a sub-pattern of the planned one (entries that cancelled): scattered into it
            pr = np.repeat(np.arange(n), np.diff(self._pattern[0]))
            key = pr * n + self._pattern[1]  # sorted: rows, then columns ascending
            want = rows[up] * n + cols[up]
            pos = np.searchsorted(key, want)
            if (pos < len(key)).all() and np.array_equal(key[np.minimum(pos, len(key) - 1)], want):
                self._gather = (A.indptr.copy(), A.indices.copy(), up, pos)
                out = np.zeros(len(key))
                out[pos] = A.data[up]
                return out
        self._gather = (A.indptr.copy(), A.indices.copy(), up, None)
        return self._ensure_pattern(indptr, cols[up], A.data[up])

    def _ensure_pattern(self, indptr: np.ndarray, indices: np.ndarray, data: np.ndarray):
        """Set up CHOLMOD's matrix and symbolic factorisation for the upper-triangle pattern
        (indptr, indices) unless it is the last one; returns ``data``."""
        matrix, spmatrix, cholmod, amd = _cvxopt()
        if self._pattern is not None and (
            np.array_equal(self._pattern[0], indptr) and np.array_equal(self._pattern[1], indices)
        ):
            return data
        n = len(indptr) - 1
        rows = np.repeat(np.arange(n), np.diff(indptr))
        self._pattern = (np.array(indptr), np.array(indices))
        # the upper triangle row by row is the lower triangle column by column (cvxopt's CCS)
        self._A = spmatrix(matrix(np.asarray(data, float)), matrix(indices.astype(np.int64)),
                           matrix(rows.astype(np.int64)), (n, n))  # fmt: skip
        if not np.array_equal(np.asarray(self._A.I).ravel(), indices):  # pragma: no cover
            raise RuntimeError("cvxopt stored the pattern in an unexpected order")
        self._diag = np.flatnonzero(indices == rows)
        self._symbolic = _supernodal(cholmod, cholmod.symbolic, self._A, amd.order(self._A))
        return data

    def _factor_sparse(self, A: sp.csr_matrix, mu: float) -> float:
        matrix, _, cholmod, _ = _cvxopt()
        values = np.array(self._upper(A), dtype=float)
        if len(self._diag) != A.shape[0]:
            raise np.linalg.LinAlgError("not positive definite (an empty row)")
        mu = max(float(mu), 1e-11 * float(values[self._diag].max(initial=0.0)))
        values[self._diag] += mu
        for _ in range(8):
            self._A.V = matrix(values)
            try:
                _supernodal(cholmod, cholmod.numeric, self._A, self._symbolic)
            except ArithmeticError:  # not positive definite
                values[self._diag] += 9 * mu
                mu *= 10
                continue
            self._factor = self._symbolic
            return mu
        raise np.linalg.LinAlgError("not positive definite")

    # ------------------------------------------------------------------------- solve
    def solve(self, r: np.ndarray) -> np.ndarray:
        """``(A + mu' I)^-1 r`` with the last factorisation, r (n,)."""
        if not self.sparse:
            return sl.cho_solve_banded((self._factor, False), r[self.order],
                                       check_finite=False)[self.inv]  # fmt: skip
        matrix, _, cholmod, _ = _cvxopt()
        B = matrix(np.ascontiguousarray(r, dtype=float))
        cholmod.solve(self._factor, B)
        return np.asarray(B).ravel()
