"""Supernodal sparse Cholesky of the reduced tangent, for large models (issue 22, item 6).

CHOLMOD (SuiteSparse; supernodal, BLAS-3 on dense blocks), reached through cvxopt's wheels
(``cvxopt.cholmod``; x86_64 and aarch64, the BLAS they bundle), factorises the symmetric positive
definite free-free tangent of a Miura sheet of 100 x 100 panels (60,300 DOFs) in about 0.5-0.7 s,
where SuperLU (scipy's LU, the fallback) takes 1.3-5 s and the banded Cholesky of the reverse
Cuthill-McKee band 4-12 s (``benchmarks/bench_large_solvers.py``).

A :class:`SparseCholesky` is built once per sparsity pattern (one topology and support mask):
it keeps the slots of the upper triangle and computes the fill-reducing ordering (approximate
minimum degree) and the symbolic factorisation. Each :meth:`SparseCholesky.factor` then does
only the numeric factorisation of new values on that pattern and returns a
:class:`CholeskyFactor` (``solve(rhs)``), or None when the matrix is not positive definite,
so that the caller falls back to LU. Factors are independent: several may be alive at once
(a batch keeps one per sample); their symbolic storage is recycled when they are dropped.

cvxopt is an optional dependency (``pip install 'holofold[cholmod]'``: cvxopt and CHOLMOD's
supernodal module are GPL); :func:`available` says whether it imports, and constructing a
:class:`SparseCholesky` without it raises :class:`~holofold.geometry.errors.EnvironmentFault`.
CHOLMOD runs on one thread (cvxopt's CHOLMOD calls a serial ATLAS) and holds the GIL.

Typical use::

    chol = SparseCholesky(K.indptr, K.indices)      # once per pattern (csr, both triangles)
    factor = chol.factor(K.data)                     # per Newton iteration; None: not SPD
    x = factor.solve(rhs)                            # (n,) or (n, k)
"""

from __future__ import annotations

import weakref

import numpy as np

from holofold.geometry.errors import EnvironmentFault
from holofold.mechanics.assembly import SingularSystemError

__all__ = ["SparseCholesky", "CholeskyFactor", "available", "INSTALL_HINT"]

#: How to install the optional CHOLMOD path.
INSTALL_HINT = "pip install 'holofold[cholmod]' (cvxopt >= 1.3.2, which bundles CHOLMOD)"

_CVXOPT = None


def _cvxopt():
    """(matrix, spmatrix, cholmod, amd) from cvxopt, imported on first use."""
    global _CVXOPT
    if _CVXOPT is None:
        try:
            from cvxopt import amd, cholmod, matrix, spmatrix
        except ImportError as exc:
            raise EnvironmentFault(
                f"the sparse Cholesky path needs cvxopt ({exc}); install it with {INSTALL_HINT}"
            ) from None
        _CVXOPT = (matrix, spmatrix, cholmod, amd)
    return _CVXOPT


def available() -> bool:
    """True if cvxopt's CHOLMOD imports (the sparse Cholesky path can be used)."""
    try:
        _cvxopt()
    except EnvironmentFault:
        return False
    return True


def _with_options(cholmod, options: dict, fn, *args):
    """``fn(*args)`` with ``cholmod.options`` (cvxopt's module-wide CHOLMOD settings) set to
    ``options`` for the call only."""
    saved = dict(cholmod.options)
    cholmod.options.clear()
    cholmod.options.update(options)
    try:
        return fn(*args)
    finally:
        cholmod.options.clear()
        cholmod.options.update(saved)


class SparseCholesky:
    """Ordering and symbolic factorisation of one symmetric sparsity pattern, for numeric
    Cholesky factorisations of any values on it.

    Parameters
    ----------
    indptr : (n + 1,) int
        CSR row pointers of the pattern.
    indices : (nnz,) int
        CSR column indices, sorted or not; the pattern must hold every diagonal entry and
        be structurally symmetric (both triangles, as the assembler's reduced pattern), or
        hold the upper triangle only.
    ordering : (n,) int, optional
        A fill-reducing elimination order (the matrix is factorised as ``K[o][:, o]``);
        default: CHOLMOD's approximate minimum degree (AMD) of the pattern.

    Attributes
    ----------
    n : int
    order : (n,) int
        The elimination order used.
    upper : (nnz_u,) int
        Slots of the CSR data that lie in the upper triangle (column >= row), the entries
        factorised (the lower triangle is taken as their mirror).
    """

    def __init__(self, indptr, indices, *, ordering=None):
        matrix, spmatrix, cholmod, amd = _cvxopt()
        indptr = np.asarray(indptr, dtype=np.int64)
        indices = np.asarray(indices, dtype=np.int64)
        n = indptr.size - 1
        if n < 1 or indptr[0] != 0 or indptr[-1] != indices.size or np.any(np.diff(indptr) < 0):
            raise ValueError("indptr is not a CSR row pointer array of a non-empty matrix")
        if indices.size and (indices.min() < 0 or indices.max() >= n):
            raise ValueError(f"column indices must lie in 0..{n - 1}")
        rows = np.repeat(np.arange(n, dtype=np.int64), np.diff(indptr))
        up = np.flatnonzero(indices >= rows)
        # row-major with columns sorted: read as column-compressed storage of the transpose,
        # this is the lower triangle column by column, rows increasing (cvxopt's own order)
        key = rows[up] * n + indices[up]
        srt = np.argsort(key, kind="stable")
        if np.any(np.diff(key[srt]) == 0):
            raise ValueError("the pattern has duplicate entries")
        self.upper = up[srt]
        r_low = indices[self.upper]  # row in the lower triangle of the transpose
        c_low = rows[self.upper]
        if np.count_nonzero(r_low == c_low) != n:
            raise ValueError("the pattern must hold every diagonal entry")
        self.n = int(n)
        self.nnz_upper = int(self.upper.size)
        self._A = spmatrix(
            matrix(np.ones(self.upper.size)),
            matrix(r_low),
            matrix(c_low),
            (self.n, self.n),
        )
        stored = np.asarray(self._A.I, dtype=np.int64).ravel()
        if not np.array_equal(stored, r_low):  # pragma: no cover - cvxopt's storage order
            raise RuntimeError("cvxopt stored the pattern in an unexpected order")
        if ordering is None:
            p = amd.order(self._A)  # AMD of the pattern (lower triangle + mirror)
        else:
            o = np.asarray(ordering, dtype=np.int64).ravel()
            if o.size != n or not np.array_equal(np.sort(o), np.arange(n)):
                raise ValueError(f"ordering must be a permutation of 0..{n - 1}")
            p = matrix(o)
        self.order = np.asarray(p, dtype=np.int64).ravel()
        self._p = p
        self._idle: list = []  # symbolic/numeric CHOLMOD factors no live CholeskyFactor holds
        self._idle.append(self._symbolic())

    def _symbolic(self):
        """A new CHOLMOD symbolic factorisation with :attr:`order` (no ordering search)."""
        _, _, cholmod, _ = _cvxopt()
        return _with_options(
            cholmod, {"supernodal": 2, "nmethods": 1, "postorder": True},
            cholmod.symbolic, self._A, self._p,
        )  # fmt: skip

    def factor(self, data) -> CholeskyFactor | None:
        """Numeric Cholesky factorisation of the matrix with CSR ``data`` (nnz,) on the pattern
        (only the upper-triangle slots are read).

        Returns
        -------
        CholeskyFactor, or None if the matrix is not (numerically) positive definite.
        """
        matrix, _, cholmod, _ = _cvxopt()
        values = np.asarray(data, dtype=float)
        F = self._idle.pop() if self._idle else self._symbolic()
        self._A.V = matrix(np.ascontiguousarray(values[self.upper]))
        try:
            _with_options(cholmod, {"supernodal": 2}, cholmod.numeric, self._A, F)
        except ArithmeticError:  # CHOLMOD_NOT_POSDEF: a pivot <= 0 (or NaN)
            self._idle.append(F)
            return None
        except ValueError as exc:  # pragma: no cover - CHOLMOD's other failures
            self._idle.append(F)
            raise SingularSystemError(f"sparse Cholesky failed ({exc})") from None
        return CholeskyFactor(F, self.n, self._idle)


class CholeskyFactor:
    """One numeric factorisation ``K = P' L L' P`` of :class:`SparseCholesky` (use
    :meth:`solve`; calling the factor is the same). Its CHOLMOD storage goes back to the
    pattern's pool when the factor is dropped."""

    def __init__(self, F, n: int, pool: list):
        self._F = F
        self.n = n
        weakref.finalize(self, pool.append, F)

    def solve(self, rhs) -> np.ndarray:
        """``K^-1 rhs`` for ``rhs`` (n,) or (n, k); raises
        :class:`~holofold.mechanics.assembly.SingularSystemError` if the result is not
        finite."""
        matrix, _, cholmod, _ = _cvxopt()
        b = np.asarray(rhs, dtype=float)
        if b.shape[:1] != (self.n,) or b.ndim > 2:
            raise ValueError(f"rhs must have shape ({self.n},) or ({self.n}, k), got {b.shape}")
        B = matrix(np.asfortranarray(b.reshape(self.n, -1)))
        cholmod.solve(self._F, B)
        x = np.array(B).reshape(b.shape)
        if not np.all(np.isfinite(x)):
            raise SingularSystemError(
                "non-finite solution of the linear system (singular stiffness)"
            )
        return x

    __call__ = solve
