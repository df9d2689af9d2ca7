"""Supernodal sparse Cholesky of the reduced tangent, for large models (issue 22, item 6).

CHOLMOD (SuiteSparse; supernodal, BLAS-3 on dense blocks), reached through cvxopt's wheels
(``cvxopt.cholmod``; x86_64 and aarch64, the BLAS they bundle), factorises the symmetric positive
definite free-free tangent of a Miura sheet of 100 x 100 panels (60,300 DOFs) in about 0.17 s of
CPU (0.23 s on AMD's ordering alone), where SuperLU (scipy's LU, the fallback) takes 1.3 s and
the banded Cholesky of the reverse Cuthill-McKee band 3.3 s (``benchmarks/large_solvers.md``).
The solver choice (:func:`holofold.mechanics.linear.solver_path`) takes it above a band work of
:data:`~holofold.mechanics.linear.CHOLESKY_MIN_WORK` (about 2,000 free DOFs on Miura sheets).

A :class:`SparseCholesky` is built once per sparsity pattern (one topology and support mask;
:func:`holofold.mechanics.linear.cholesky_solver` caches it on the reduction): it keeps the
slots of the upper triangle and computes the fill-reducing ordering (approximate minimum
degree; on large patterns also METIS's nested dissection where pymetis is installed, CHOLMOD
keeping the better) and the symbolic factorisation. Each :meth:`SparseCholesky.factor` then
does only the numeric factorisation of new values on that pattern and returns a
:class:`CholeskyFactor` (``solve(rhs)``), or None when the matrix is not positive definite,
so that the caller falls back to LU. Factors are independent: several may be alive at once
(a batch keeps one per sample); their CHOLMOD storage is recycled when they are dropped.

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
from holofold.mechanics.status import SingularSystemError

__all__ = ["SparseCholesky", "CholeskyFactor", "available", "INSTALL_HINT", "METIS_MIN_DOF"]

#: How to install the optional CHOLMOD path.
INSTALL_HINT = "pip install 'holofold[cholmod]' (cvxopt >= 1.3.2, which bundles CHOLMOD)"

_CVXOPT = None
_AVAILABLE: bool | None = None


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
    """True if cvxopt's CHOLMOD imports (the sparse Cholesky path can be used); the answer is
    kept for the process."""
    global _AVAILABLE
    if _AVAILABLE is None:
        try:
            _cvxopt()
            _AVAILABLE = True
        except EnvironmentFault:
            _AVAILABLE = False
    return _AVAILABLE


#: Patterns of at least this many rows get METIS's nested dissection as a candidate ordering
#: where pymetis is installed (x86_64 wheels; the `cholmod` extra brings it there): on Miura
#: sheets of 120 x 40 panels and more it saves 20-30 % of the factorisation against AMD
#: (bench_large_solvers), below about 10,000 DOFs the two are alike.
METIS_MIN_DOF = 10_000


def nested_dissection(rows: np.ndarray, cols: np.ndarray, n: int) -> np.ndarray | None:
    """METIS's nested-dissection order of the symmetric pattern with entries (rows, cols) of
    one triangle (either: the graph is made symmetric), or None where pymetis is not
    installed. Both sparse Cholesky paths order with it (CHOLMOD's, and
    :mod:`~holofold.mechanics.supernodal`)."""
    try:
        import pymetis
    except ImportError:
        return None
    import scipy.sparse as sp

    off = rows != cols
    r, c = rows[off], cols[off]
    G = sp.csr_matrix(
        (np.ones(2 * r.size, np.int8), (np.concatenate([r, c]), np.concatenate([c, r]))),
        shape=(n, n),
    )
    order, _ = pymetis.nested_dissection(pymetis.CSRAdjacency(G.indptr, G.indices))
    return np.array(order).astype(np.int64)  # a copy in numpy's own buffer format


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
    ordering : (n,) int or "amd", optional
        A fill-reducing elimination order (the matrix is factorised as ``K[o][:, o]``), used
        as given, or ``"amd"``: CHOLMOD's approximate minimum degree (AMD) alone. Default: AMD;
        from :data:`METIS_MIN_DOF` rows, where pymetis is installed, CHOLMOD compares METIS's
        nested dissection with its AMD and keeps the one with fewer flops.
    data_slots : (nnz,) int, optional
        Where each pattern entry lies in the ``data`` arrays given to :meth:`factor` (default:
        ``data`` is the CSR data itself), e.g. the slots of a larger matrix's CSR data.

    Attributes
    ----------
    n : int
    order : (n,) int
        The elimination order given to CHOLMOD (AMD's, the caller's, or METIS's candidate).
    upper : (nnz_u,) int
        Slots of ``data`` that hold the upper triangle (column >= row), the entries factorised
        (the lower triangle is taken as their mirror).
    """

    def __init__(self, indptr, indices, *, ordering=None, data_slots=None):
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
        upper = up[srt]
        r_low = indices[upper]  # row in the lower triangle of the transpose
        c_low = rows[upper]
        if np.count_nonzero(r_low == c_low) != n:
            raise ValueError("the pattern must hold every diagonal entry")
        if data_slots is not None:
            data_slots = np.asarray(data_slots, dtype=np.intp).ravel()
            if data_slots.size != indices.size:
                raise ValueError(f"data_slots must have {indices.size} entries")
            upper = data_slots[upper]
        self.upper = upper
        self.n = int(n)
        self.nnz_upper = int(upper.size)
        self._A = spmatrix(
            matrix(np.ones(self.upper.size)),
            matrix(r_low),
            matrix(c_low),
            (self.n, self.n),
        )
        stored = np.asarray(self._A.I, dtype=np.int64).ravel()
        if not np.array_equal(stored, r_low):  # pragma: no cover - cvxopt's storage order
            raise RuntimeError("cvxopt stored the pattern in an unexpected order")
        self._nmethods = 1  # CHOLMOD takes the ordering as given
        if isinstance(ordering, str) and ordering != "amd":
            raise ValueError(f"ordering must be 'amd' or a permutation, got {ordering!r}")
        if ordering is None or isinstance(ordering, str):
            auto = ordering is None and n >= METIS_MIN_DOF
            nd = nested_dissection(r_low, c_low, n) if auto else None
            if nd is None:
                p = amd.order(self._A)  # AMD of the pattern (lower triangle + mirror)
            else:  # CHOLMOD keeps the better of METIS's and its own AMD
                p, self._nmethods = matrix(nd), 0
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
            cholmod, {"supernodal": 2, "nmethods": self._nmethods, "postorder": True},
            cholmod.symbolic, self._A, self._p,
        )  # fmt: skip

    def factor(self, data) -> CholeskyFactor | None:
        """Numeric Cholesky factorisation of the matrix with CSR ``data`` (nnz,) on the pattern
        (or the larger array ``data_slots`` points into; only the upper-triangle slots are
        read).

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
