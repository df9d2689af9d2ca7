"""The records the assembly and Newton kernels take (both paths: :mod:`~holofold.mechanics.
_compiled` and :mod:`~holofold.mechanics._numpy_kernels`).

Named tuples of arrays, so that numba takes them as they are (a named tuple is a tuple type to
it) and a kernel has a handful of arguments instead of thirty (tests/test_kernel_paths.py
checks both paths' signatures: the same names, at most :data:`MAX_KERNEL_ARGS`). S designs
of one size share the arrays' leading sample axis.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = [
    "MAX_KERNEL_ARGS",
    "ModelArrays",
    "Scatter",
    "Factor",
    "StepOut",
    "BandOut",
    "Increments",
    "IncrementRecords",
    "RestControl",
]

#: the most arguments a kernel takes (issue 35: "at most about 8 arguments per kernel")
MAX_KERNEL_ARGS = 10


class ModelArrays(NamedTuple):
    """What the element kernels read of S designs: reference coordinates ``X`` (S, nn, 3) m,
    displacements ``U`` (S, nn, 3) m, bar end nodes ``b0``, ``b1`` (S, nb), reference bar
    vectors ``D0`` (S, 3, nb) m, rest lengths ``L0`` (S, nb) m, axial rigidities ``EA``
    (S, nb) N, spring node quadruples ``sT`` (S, 4, ns), stiffnesses ``k`` (S, ns) N m/rad,
    rest angles ``theta0`` (S, ns) rad and ``k_nonneg`` (S,) bool (every stiffness >= 0)."""

    X: np.ndarray
    U: np.ndarray
    b0: np.ndarray
    b1: np.ndarray
    D0: np.ndarray
    L0: np.ndarray
    EA: np.ndarray
    sT: np.ndarray
    k: np.ndarray
    theta0: np.ndarray
    k_nonneg: np.ndarray


class Scatter(NamedTuple):
    """How one design's element arrays become its internal force: ``force`` the force's sum
    lists (six arrays, see :func:`~holofold.mechanics._compiled.scatter`), ``views`` the
    element arrays the kernels write (an ``ElementArrays``), ``flats`` the same memory flat
    (what the sum lists index). The tangent's sum lists go beside it (a kernel may take two:
    a Cholesky's and the whole matrix's)."""

    force: tuple
    views: tuple
    flats: tuple


class Factor(NamedTuple):
    """What a Newton kernel factorises and solves with: the free DOFs ``free`` (nf,), the
    band's order ``perm`` (nf,; empty for a dense matrix), its half bandwidth ``bw`` (-1: a
    dense matrix) and the LAPACK routines' addresses ``addrs`` (int64)."""

    free: np.ndarray
    perm: np.ndarray
    bw: int
    addrs: np.ndarray


class StepOut(NamedTuple):
    """Outputs of ``small_newton_step``, row j for sample ``idx[j]``: the update ``dU``
    (n, nf) m, ``info`` (n,) int8 (0 done, 1 singular, 2 not finite), the residual ``res``
    (n, nf) N, and ``lu`` (n,) int8 (1: the tangent was not positive definite, LU from now
    on; read and written)."""

    dU: np.ndarray
    info: np.ndarray
    res: np.ndarray
    lu: np.ndarray


class BandOut(NamedTuple):
    """Outputs of ``band_newton_step``, row j for sample ``idx[j]``: the update ``dU`` (n, nf)
    m, the internal force ``f`` (n, ndof) N and ``info`` (n,) int8 (0 done, 1 not positive
    definite, 2 not finite)."""

    dU: np.ndarray
    f: np.ndarray
    info: np.ndarray


class Increments(NamedTuple):
    """Load control: the force of increment ``i`` is ``F0[s] + i P[s]`` ((S, ndof) N) for
    ``i = 1..increments``; Newton iterates while ``step < max_iter`` and ``||dU|| > tol`` (m)."""

    F0: np.ndarray
    P: np.ndarray
    increments: int
    tol: float
    max_iter: int


class RestControl(NamedTuple):
    """Rest-angle control (``solve_selffold``): at increment ``i = 1..increments`` the rest
    angles are ``(1 - i/increments) start[s] + (i/increments) target[s]`` ((S, ns) rad) under
    the applied force ``F0`` ((S, ndof) N); Newton iterates while ``step < max_iter`` and the
    residual norm before the update ``||(F0 - f_int)[free]||`` exceeds ``tol`` (N)."""

    F0: np.ndarray
    start: np.ndarray
    target: np.ndarray
    increments: int
    tol: float
    max_iter: int


class IncrementRecords(NamedTuple):
    """Per-increment records of ``newton_increments``, row j for sample ``idx[j]``: ``U``
    (n, increments, ndof) m, ``conv`` (n, increments) bool, ``iters``, ``res`` (the last
    ||dU||, m), ``moved`` (max |U - U at the increment's start|, m) and ``failed`` (n, 3):
    (code, increment, step) of the step that stopped the sample."""

    U: np.ndarray
    conv: np.ndarray
    iters: np.ndarray
    res: np.ndarray
    moved: np.ndarray
    failed: np.ndarray

    @classmethod
    def empty(cls, n: int, increments: int, ndof: int) -> IncrementRecords:
        return cls(
            np.empty((n, increments, ndof)), np.zeros((n, increments), bool),
            np.zeros((n, increments), np.int64), np.full((n, increments), np.nan),
            np.zeros((n, increments)), np.zeros((n, 3), np.int64),
        )  # fmt: skip
