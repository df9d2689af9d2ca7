"""Linear solvers of the reduced (free-free) tangent, and the choice among them.

:func:`solver_path` picks, per reduction, the fastest path for a symmetric tangent: dense
LAPACK up to :data:`DENSE_MAX_DOF` free DOFs (a Cholesky, banded where the band is narrow,
:func:`small_cholesky`, and the LU only where the tangent is not positive definite), then a
banded Cholesky (LAPACK ``dpbtrf``) on the cached reverse Cuthill-McKee band while its work
``nf (bw + 1)^2`` stays under
:data:`CHOLESKY_MIN_WORK`, and a supernodal sparse Cholesky above it (:func:`cholesky_backend`:
CHOLMOD where ``holofold[cholmod]`` is installed, else holofold's own multifrontal one,
:mod:`~holofold.mechanics.supernodal`, on the compiled kernel path). Without either (no cvxopt
and the numpy kernel path) the band serves up to :data:`BANDED_MAX_WORK` and
SuperLU (LU with a cached minimum-degree ordering) beyond. A tangent on the sparse-Cholesky
path that is not positive definite gets holofold's sparse LDL^T where the compiled kernels run
(:func:`cholesky_solver`), else SuperLU, as does a banded tangent that is not positive
definite. Each ``*_solver`` returns ``solve(rhs)`` for ``rhs`` (nf,) (or (nf, k)) that
raises :class:`SingularSystemError` for a singular matrix or a non-finite solution.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.linalg.lapack import dgetrf, dgetrs, dpbtrf, dpbtrs, dpotrf, dpotrs

from holofold.mechanics.sparsity import ReducedPattern
from holofold.mechanics.status import SingularSystemError

__all__ = [
    "SingularSystemError",
    "DENSE_MAX_DOF",
    "BANDED_MAX_WORK",
    "CHOLESKY_MIN_WORK",
    "SMALL_BAND_SHARE",
    "small_cholesky",
    "SOLVER_PATHS",
    "cholesky_backend",
    "solver_path",
    "storage_of",
    "dense_solver",
    "band_solver",
    "lu_solver",
    "cholesky_solver",
    "zero_solver",
    "finite",
]

#: Reduced systems with at most this many free DOFs are assembled and solved densely (LAPACK);
#: larger ones sparsely (crossover measured at ~200 DOFs).
DENSE_MAX_DOF = 200
#: Sparse systems whose reverse Cuthill-McKee band costs at most this many flops
#: (n * (bandwidth + 1)^2) use the banded Cholesky; above it the supernodal sparse Cholesky
#: (:func:`cholesky_backend`; holofold's own multifrontal one is as fast as CHOLMOD from
#: 36 x 12 to 72 x 24 cells, benchmarks/large_solvers.md). Measured on Miura sheets (CPU
#: time): a whole solve_newton_batch per sample, band (its compiled whole-solve kernel) /
#: sparse Cholesky, 6.0 / 7.5 ms at 24 x 8 (work 1.2e7), 12.7 / 13.9 at 30 x 10 (3.0e7),
#: 37.5 / 34.1 at 36 x 12 (6.1e7), 57.8 / 50.0 at 48 x 16; the factorisation + solve alone
#: (benchmarks/bench_large_solvers.py) 3.3 / 2.4 ms at 36 x 12, 32 / 14 at 72 x 24, 505 / 56
#: at 120 x 40, 3334 / 167 at 100 x 100.
CHOLESKY_MIN_WORK = 4e7
#: A dense-path model (at most :data:`DENSE_MAX_DOF` free DOFs) whose reverse Cuthill-McKee
#: band (bandwidth + 1) is at most this share of its free DOFs is factorised by the banded
#: Cholesky, else by the dense one (:func:`small_cholesky`); the LU only where the Cholesky
#: fails. Factorisation + one solve of the two-panel gripper's tangent (99 DOFs, bandwidth 32:
#: 0.33 of nf), CPU us at load 12: band 19.4, dense Cholesky 37.5, dense LU 61.9.
SMALL_BAND_SHARE = 0.5
#: Without the sparse Cholesky: band work up to which the banded Cholesky beats SuperLU
#: (bench_large_solvers, band / SuperLU, two runs at load 13-20: 195-505 / 282-314 ms at
#: 120 x 40 (work 6.9e9), 291-453 / 359-382 at 100 x 50 (1.1e10), 506-921 / 573-794 at
#: 150 x 50 (1.7e10), 922-1780 / 747-936 at 100 x 75 (3.7e10); the band's streaming suffers
#: most from other jobs).
BANDED_MAX_WORK = 2e10
#: the solver paths, by the storage of the tangent each factorises
SOLVER_PATHS = {
    "none": None, "dense": "dense", "banded": "banded", "cholesky": "csr_upper", "superlu": "csr",
}  # fmt: skip

NON_FINITE = "non-finite solution of the linear system (singular stiffness)"
SINGULAR = "singular stiffness matrix (Singular matrix)"


def solver_path(red: ReducedPattern, dense_max: int = DENSE_MAX_DOF) -> str:
    """The solver path of a reduction: ``"none"`` (no free DOF), ``"dense"``, ``"banded"`` or
    ``"cholesky"`` (both SuperLU if the tangent is not positive definite) or ``"superlu"``."""
    nf = red.n_free
    if nf == 0:
        return "none"
    if nf <= dense_max:
        return "dense"
    work = nf * (red.band.bandwidth + 1) ** 2
    if work <= CHOLESKY_MIN_WORK:
        return "banded"
    if cholesky_backend() is not None:
        return "cholesky"
    return "banded" if work <= BANDED_MAX_WORK else "superlu"


def small_cholesky(red: ReducedPattern) -> str:
    """The Cholesky a dense-path reduction tries first (the LU of the whole matrix where the
    tangent is not positive definite): ``"banded"`` where its band is narrow
    (:data:`SMALL_BAND_SHARE`), else ``"dense"``."""
    nf = red.n_free
    return "banded" if red.band.bandwidth + 1 <= SMALL_BAND_SHARE * nf else "dense"


def cholesky_backend() -> str | None:
    """The supernodal sparse Cholesky of the ``"cholesky"`` path: ``"cholmod"`` where cvxopt
    imports (``holofold[cholmod]``), else ``"supernodal"`` (holofold's own, numba and scipy's
    BLAS) where the compiled kernels run (it is compiled with them, into their cache), else
    None: on the numpy kernel path (``HOLOFOLD_KERNELS=numpy``, or ``auto`` while the kernels
    compile) the band and SuperLU serve."""
    from holofold.mechanics import kernels, sparse_cholesky

    if sparse_cholesky.available():
        return "cholmod"
    return "supernodal" if kernels.active().compiled else None


def storage_of(path: str) -> str | None:
    """The tangent storage a solver path factorises (see :data:`~holofold.mechanics.sparsity.
    STORAGES`)."""
    return SOLVER_PATHS[path]


def finite(x: np.ndarray) -> np.ndarray:
    """``x``, or :class:`SingularSystemError` if any entry is not finite."""
    if not np.all(np.isfinite(x)):
        raise SingularSystemError(NON_FINITE)
    return x


def zero_solver(rhs):
    """The solver of a system without free DOFs."""
    return np.zeros_like(rhs, dtype=float)


def dense_solver(K: np.ndarray, symmetric: bool = False):
    """``solve(rhs)`` by LAPACK of the dense (nf, nf) ``K``: for a ``symmetric`` K (a tangent)
    its Cholesky (``dpotrf`` once, of the upper triangle; ``dpotrs`` per right-hand side, one
    (nf,) or several (nf, k)) where it is positive definite, else (and for any other K) its LU
    (``dgetrf``, ``dgetrs``). A singular K raises at the solve. ``solve.factorisation()``:
    ``"cholesky"``, ``"lu"`` or None before the first solve."""
    fac = None

    def solve(rhs):
        nonlocal fac
        if fac is None:
            info = 1
            if symmetric:
                c, info = dpotrf(K, lower=0, clean=0)
                fac = ("cholesky", c)
            if info != 0:
                lu, piv, info = dgetrf(K)
                fac = ("lu", lu, piv, info)
        if fac[0] == "cholesky":
            x, _ = dpotrs(fac[1], rhs, lower=0)
        else:
            if fac[3] > 0:
                raise SingularSystemError(SINGULAR)
            x, _ = dgetrs(fac[1], fac[2], rhs)
        return finite(x)

    solve.factorisation = lambda: None if fac is None else fac[0]
    return solve


def band_solver(ab: np.ndarray, red: ReducedPattern):
    """``solve(rhs)`` by banded Cholesky of the flat column-major upper band ``ab`` (factorised
    in place), or None if the matrix is not positive definite."""
    band = red.band
    nf = red.n_free
    c, info = dpbtrf(ab.reshape(nf, band.bandwidth + 1).T, lower=0, overwrite_ab=1)
    if info != 0:
        return None

    def solve(rhs):
        y, info = dpbtrs(c, rhs[band.perm], lower=0)
        if info != 0:  # pragma: no cover - only for invalid arguments
            raise SingularSystemError(f"banded solve failed (LAPACK info {info})")
        x = np.empty_like(y)
        x[band.perm] = y
        return finite(x)

    return solve


class FillOrdering(NamedTuple):
    """A fill-reducing symmetric ordering ``order`` (``K[order][:, order]``; multiple minimum
    degree on K + K') and the CSR pattern of the permuted matrix (``perm_keep`` the full CSR
    slots in its order, ``perm_indptr``, ``perm_indices``), so that SuperLU factorises with its
    natural ordering and no per-iteration ordering cost."""

    order: np.ndarray
    perm_keep: np.ndarray
    perm_indptr: np.ndarray
    perm_indices: np.ndarray


def _fill_ordering(red: ReducedPattern) -> FillOrdering:
    nf = red.n_free
    # symbolic ordering from the pattern alone (diagonally dominant stand-in values)
    vals = np.where(red.rows == red.cols, float(nf + 1), -1.0 / max(nf, 1))
    A = sp.csc_matrix((vals, red.indices, red.indptr), shape=(nf, nf))
    lu = spla.splu(
        A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True}
    )
    order = np.argsort(lu.perm_c)
    inv = np.empty(nf, np.intp)
    inv[order] = np.arange(nf)
    pr = inv[red.rows]
    pc = inv[red.cols]
    srt = np.argsort(pr.astype(np.int64) * nf + pc)
    perm_indptr = np.concatenate([[0], np.cumsum(np.bincount(pr, minlength=nf))])
    return FillOrdering(
        order, red.keep[srt], perm_indptr.astype(np.int32), pc[srt].astype(np.int32)
    )


def lu_solver(data: np.ndarray, red: ReducedPattern):
    """``solve(rhs)`` by SuperLU of the free-free block of the full CSR ``data`` (the
    reduction's cached :class:`FillOrdering`)."""
    nf = red.n_free
    o = red.symbolic("superlu", _fill_ordering)
    # csc from the permuted CSR arrays is Kp^T; factorise it and solve with trans='T'
    KpT = sp.csc_matrix((data[o.perm_keep], o.perm_indices, o.perm_indptr), shape=(nf, nf))
    try:
        lu = spla.splu(
            KpT,
            permc_spec="NATURAL",
            diag_pivot_thresh=0.01,
            relax=3,
            panel_size=10,
            options={"SymmetricMode": True},
        )
    except RuntimeError as exc:
        raise SingularSystemError(f"singular stiffness matrix ({exc})") from None

    def solve(rhs):
        y = lu.solve(np.ascontiguousarray(rhs[o.order]), trans="T")
        x = np.empty_like(y)
        x[o.order] = y
        return finite(x)

    return solve


def _cholesky_analysis(red: ReducedPattern, backend: str):
    """The reduction's :class:`~holofold.mechanics.sparse_cholesky.SparseCholesky` (CHOLMOD)
    or :class:`~holofold.mechanics.supernodal.SupernodalCholesky` (ordering and symbolic
    analysis of the free-free pattern), reading the ``"csr_upper"`` storage (each
    upper-triangle entry of the reduced CSR at its compact position)."""
    if backend == "cholmod":
        from holofold.mechanics.sparse_cholesky import SparseCholesky as Analysis
    else:
        from holofold.mechanics.supernodal import SupernodalCholesky as Analysis

    compact = np.cumsum(red.rows <= red.cols) - 1  # lower entries: never read
    return Analysis(red.indptr, red.indices, data_slots=np.maximum(compact, 0))


def cholesky_solver(data: np.ndarray, red: ReducedPattern, backend: str | None = None):
    """``solve(rhs)`` by the supernodal sparse Cholesky (``backend``, default
    :func:`cholesky_backend`) of the free-free block from its upper triangle ``data`` (the
    ``"csr_upper"`` storage; the reduction's cached analysis). A block that is not positive
    definite gets holofold's sparse LDL^T where the compiled kernels run
    (:meth:`~holofold.mechanics.supernodal.SupernodalCholesky.factor_ldl`: 1.6-10x faster
    than SuperLU on indefinite Miura tangents of 36 x 12 to 120 x 40 cells); None where that
    is refused or not available (then LU)."""
    backend = backend or cholesky_backend() or "supernodal"
    analysis = red.symbolic(f"cholesky:{backend}", lambda r: _cholesky_analysis(r, backend))
    solve = analysis.factor(data)
    if solve is not None:
        return solve
    from holofold.mechanics import kernels

    if backend != "supernodal" and not kernels.active().compiled:
        return None
    own = red.symbolic("cholesky:supernodal", lambda r: _cholesky_analysis(r, "supernodal"))
    return own.factor_ldl(data)
