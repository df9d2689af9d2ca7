"""Whole Newton updates in one kernel call: kernels, sums, factorisation, solve, update.

``U[free] += K_ff(U)^-1 (F - f_int(U))[free]`` is what every load-controlled solver iterates.
On the dense and banded solver paths the active kernel path (:mod:`~holofold.mechanics.
kernels`) does it in one call per design (:class:`DenseStepper`) or per connectivity of a
batch (:func:`batch_newton_step`); the compiled path calls scipy's LAPACK by address, the
numpy path through scipy's wrappers. Where neither applies (SuperLU, the reference's arccos
angle, banded tangents that are not positive definite) the batch falls back to
:meth:`~holofold.mechanics.assembly.BatchAssembler.factorized`.
"""

from __future__ import annotations

import weakref
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from holofold.mechanics import kernels
from holofold.mechanics.kernel_args import (
    BandOut,
    Factor,
    IncrementRecords,
    Increments,
    RestControl,
    Scatter,
    StepOut,
)
from holofold.mechanics.linear import (
    NON_FINITE,
    SINGULAR,
    SingularSystemError,
    small_cholesky,
    solver_path,
)

if TYPE_CHECKING:
    from holofold.mechanics.assembly import Assembler, BatchAssembler

__all__ = [
    "DenseStepper",
    "NewtonRecords",
    "batch_newton_step",
    "batch_newton_increments",
    "selffold_increments",
    "load_increments",
]

_LAPACK = {"banded": ("dpbtrf", "dpbtrs"), "dense": ("dgetrf", "dgetrs")}
#: the LAPACK routines of the whole-solve call (dense: LU's for the fallback, Cholesky's)
_SOLVE = {"banded": _LAPACK["banded"], "dense": (*_LAPACK["dense"], "dpotrf", "dpotrs")}
#: the small-model step's: the LU's, then the Cholesky's it tries first (small_cholesky)
_SMALL = {"banded": (*_LAPACK["dense"], *_LAPACK["banded"]), "dense": _SOLVE["dense"]}


def _error(code: int) -> SingularSystemError:
    return SingularSystemError(SINGULAR if code == 1 else NON_FINITE)


class DenseStepper:
    """One design's Newton update on the dense path, its arguments bound once.

    ``step()`` evaluates the kernels at ``U``, factorises the free-free block (the Cholesky of
    :func:`~holofold.mechanics.linear.small_cholesky`, banded or dense; the LU of the whole
    block where the tangent is not positive definite, and from then on for this stepper's
    life, one increment: :attr:`lu`), solves for ``(F - f_int)[free]``, adds the solution to
    ``U[free]`` (in place) and returns it (a buffer the next call overwrites); ``r``, if
    given, receives the residual. Raises :class:`SingularSystemError` (U left alone). Build it
    with :meth:`~holofold.mechanics.assembly.Assembler.dense_stepper`.
    """

    def __init__(self, asm: Assembler, U, F, spring_rest=None, r=None):
        red = asm.reduction
        path = kernels.active()
        self._fn = path.module.small_newton_step
        rest = asm.theta0 if spring_rest is None else spring_rest
        theta0 = np.ascontiguousarray(rest, dtype=float).reshape(1, -1)
        self.dU = np.empty((1, red.n_free))
        self.info = np.zeros(1, np.int8)
        #: 1 once the tangent was not positive definite: LU from then on
        self.lu = np.zeros(1, np.int8)
        res = self.dU if r is None else r.reshape(1, -1)
        scratch = asm._buffers()
        one = asm.inputs.batch_of_one()
        chol, full, perm, bw, addrs = _small_args(red, path.module)
        self._args = (
            one.model(U.reshape(1, -1, 3), theta0, np.array([asm.k_nonneg])), _ONE,
            Scatter(asm.pattern.force_sums, scratch, scratch.flat()), (chol, full),
            F.reshape(1, -1), Factor(red.free, perm, bw, addrs), U.reshape(1, -1),
            StepOut(self.dU, self.info, res, self.lu),
        )  # fmt: skip

    def __call__(self) -> np.ndarray:
        self._fn(*self._args)
        if self.info[0]:
            raise _error(int(self.info[0]))
        return self.dU[0]


def selffold_increments(asm: Assembler, U, F0, start, target, increments, tol, max_iter):
    """Every increment and iteration of :func:`~holofold.mechanics.solvers.solve_selffold`
    (rest angles from ``start`` to ``target`` (ns,) rad, force ``F0`` (ndof,) N kept applied)
    in one kernel call, each step that of :class:`DenseStepper`: ``U`` (ndof,) C-contiguous,
    updated in place; returns an :class:`~holofold.mechanics.kernel_args.IncrementRecords` of
    one sample (``U`` (1, increments, ndof), ``conv``, ``iters``, ``res`` (the last
    ``||r||``, N), ``moved`` and ``failed`` (1, 3): (code, increment, step), code 0 none, 1
    singular, 2 a non-finite solution; rows after a failing increment are undefined), or
    None where the assembler is off the dense path or uses the reference's arccos angle."""
    if asm.arccos or asm.solver != "dense":
        return None
    module = kernels.active().module
    fixed = _STATIC.get(asm)
    if fixed is None or fixed[0] is not module:
        fixed = _STATIC[asm] = (module, *_selffold_args(asm, module))
    _, one, k_nonneg, scatter, lists, factor = fixed
    theta0 = np.empty((1, len(start)))
    model = one.model(U.reshape(1, -1, 3), theta0, k_nonneg)
    drive = RestControl(
        np.ascontiguousarray(F0, dtype=float).reshape(1, -1),
        np.ascontiguousarray(start, dtype=float).reshape(1, -1),
        np.ascontiguousarray(target, dtype=float).reshape(1, -1),
        int(increments), float(tol), int(max_iter),
    )  # fmt: skip
    rec = IncrementRecords.empty(1, int(increments), U.size)
    module.selffold_increments(
        model, _ONE, scatter, lists, drive, factor, U.reshape(1, -1), rec
    )  # fmt: skip
    return rec


def load_increments(asm: Assembler, U, F0, P, increments, tol, max_iter):
    """Every increment and iteration of :func:`~holofold.mechanics.solvers.solve_newton`
    (force ``F0 + i P`` (ndof,) N at increment ``i``, the rest angles ``asm.theta0``) in one
    kernel call, each step that of :class:`DenseStepper`: ``U`` (ndof,) C-contiguous, updated
    in place; returns an :class:`~holofold.mechanics.kernel_args.IncrementRecords` of one
    sample (``res`` the last ``||dU||``, m; ``failed`` (1, 3): (code, increment, step)), or
    None where the assembler is off the dense path or uses the reference's arccos angle."""
    if asm.arccos or asm.solver != "dense":
        return None
    module = kernels.active().module
    fixed = _STATIC.get(asm)
    if fixed is None or fixed[0] is not module:
        fixed = _STATIC[asm] = (module, *_selffold_args(asm, module))
    _, one, k_nonneg, scatter, lists, factor = fixed
    theta0 = np.ascontiguousarray(asm.theta0, dtype=float).reshape(1, -1)
    model = one.model(U.reshape(1, -1, 3), theta0, k_nonneg)
    load = Increments(
        np.ascontiguousarray(F0, dtype=float).reshape(1, -1),
        np.ascontiguousarray(P, dtype=float).reshape(1, -1),
        int(increments), float(tol), int(max_iter),
    )  # fmt: skip
    rec = IncrementRecords.empty(1, int(increments), U.size)
    module.load_increments(model, _ONE, scatter, lists, load, factor, U.reshape(1, -1), rec)
    return rec


#: per assembler: (kernel module, the fixed arguments of selffold_increments), made once
_STATIC: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _selffold_args(asm: Assembler, module):
    """The arguments of ``selffold_increments`` that do not change between calls: the batch
    of one's inputs, ``k_nonneg``, the scatter, the sum lists and the factor record."""
    red = asm.reduction
    scratch = asm._buffers()
    chol, full, perm, bw, addrs = _small_args(red, module)
    return (
        asm.inputs.batch_of_one(), np.array([asm.k_nonneg]),
        Scatter(asm.pattern.force_sums, scratch, scratch.flat()), (chol, full),
        Factor(red.free, perm, bw, addrs),
    )  # fmt: skip


def _small_args(red, module):
    """(Cholesky sums, whole-matrix sums, perm, bw, addrs) of :func:`small_newton_step` for
    ``red`` on the kernel path ``module`` (cached on the reduction): the band's order and half
    bandwidth, or an empty order and -1 for the dense Cholesky (:func:`~holofold.mechanics.
    linear.small_cholesky`); the LAPACK addresses, LU's first."""

    def build(red):
        full = red.tangent_sums("dense_cm")
        if small_cholesky(red) == "banded":
            band = red.band
            addrs = module.lapack_addresses(*_SMALL["banded"])
            return red.tangent_sums("banded"), full, band.perm, int(band.bandwidth), addrs
        return full, full, _NO_PERM, -1, module.lapack_addresses(*_SMALL["dense"])

    return red.symbolic(f"small_step:{module.__name__}", build)


_NO_PERM = np.zeros(0, np.intp)
_ONE = np.zeros(1, np.intp)  # the sample index of a batch of one


def batch_newton_step(batch: BatchAssembler, U, rhs_force, active):
    """One Newton update of the ``active`` samples of ``batch`` (see
    :meth:`~holofold.mechanics.assembly.BatchAssembler.newton_step`): ``(dU (S, nf), errors)``.
    """
    path = kernels.active()
    ck = path.module
    if U.dtype != float or not U.flags.c_contiguous or U.shape != (batch.n, batch.n_dof):
        raise ValueError(f"U must be a C-contiguous float ({batch.n}, {batch.n_dof}) array")
    active = np.ascontiguousarray(active, dtype=bool)
    U3 = U.reshape(batch.n, -1, 3)
    Fi = np.ascontiguousarray(rhs_force, dtype=float)
    dU_all = np.empty((batch.n, batch.free_dofs.size))
    errors: dict = {}
    rest = active.copy()
    if not any(batch.arccos):
        for pat, red, members in batch.groups:
            idx = np.ascontiguousarray(members[active[members]], dtype=np.intp)
            kind = solver_path(red, batch.dense_max)
            if idx.size == 0 or kind not in _LAPACK:
                continue
            model = batch.inputs.model(U3, batch.theta0, batch.k_nonneg)
            dU = np.empty((idx.size, red.n_free))
            info = np.zeros(idx.size, np.int8)
            if kind == "banded":
                band = red.band
                fac = Factor(
                    red.free, band.perm, int(band.bandwidth), ck.lapack_addresses(*_LAPACK[kind])
                )
                out = BandOut(dU, np.empty((idx.size, batch.n_dof)), info)
                ck.band_newton_step(
                    model, idx, batch.scatter(pat), red.tangent_sums("banded"), Fi, fac, U, out
                )
            else:  # the Cholesky first, the LU where it fails (as DenseStepper)
                chol, full, perm, bw, small = _small_args(red, ck)
                ck.small_newton_step(
                    model, idx, batch.scatter(pat), (chol, full), Fi,
                    Factor(red.free, perm, bw, small), U,
                    StepOut(dU, info, dU, np.zeros(idx.size, np.int8)),
                )  # fmt: skip
            dU_all[idx] = dU
            rest[idx] = False
            for j in np.flatnonzero(info):  # the failed samples only
                if info[j] == 1 and kind == "banded":
                    rest[idx[j]] = True  # not positive definite: LU by factorized below
                else:
                    errors[int(idx[j])] = _error(int(info[j]))
    if rest.any():
        f, solves = batch.factorized(U3, rest)
        free = batch.free_dofs
        for s in np.flatnonzero(rest):
            try:
                if isinstance(solves[s], SingularSystemError):
                    raise solves[s]
                dU_s = solves[s]((Fi[s] - f[s])[free])
            except SingularSystemError as exc:
                errors[int(s)] = exc
                continue
            U[s, free] += dU_s
            dU_all[s] = dU_s
    return dU_all, errors


class NewtonRecords(NamedTuple):
    """Per-increment records of S samples' Newton-Raphson load control
    (:func:`batch_newton_increments`): ``U`` (S, increments, ndof) m, ``converged`` (R <= tol),
    ``iterations``, ``residual`` (the last ||dU||, m) and ``moved`` (max |U - U at the
    increment's start|, m), each (S, increments); ``failed`` (S, 3): (code, increment, step)
    of the step that stopped a sample (code 0 none, 1 singular or, ``banded[s]``, not positive
    definite, 2 a non-finite solution); rows after a failing increment are undefined."""

    U: np.ndarray
    converged: np.ndarray
    iterations: np.ndarray
    residual: np.ndarray
    moved: np.ndarray
    failed: np.ndarray
    banded: np.ndarray


def batch_newton_increments(batch: BatchAssembler, U, F0, P, increments, tol, max_iter):
    """Every increment and iteration of :func:`~holofold.mechanics.solvers.solve_newton` for
    each sample of ``batch`` in one kernel call per connectivity (``U`` (S, ndof) C-contiguous,
    updated in place; ``F0``, ``P`` (S, ndof): applied force and load per increment, N), or
    None where some sample is on neither the dense nor the banded path or uses the reference's
    arccos angle (then iterate with :func:`batch_newton_step`)."""
    kinds = [solver_path(red, batch.dense_max) for _, red, _ in batch.groups]
    if any(batch.arccos) or any(k not in _LAPACK for k in kinds):
        return None
    ck = kernels.active().module
    S, nd = U.shape
    U3 = U.reshape(S, -1, 3)
    rec = NewtonRecords(
        np.empty((S, increments, nd)), np.zeros((S, increments), bool),
        np.zeros((S, increments), np.int64), np.full((S, increments), np.nan),
        np.zeros((S, increments)), np.zeros((S, 3), np.int64), np.zeros(S, bool),
    )  # fmt: skip
    load = Increments(
        np.ascontiguousarray(F0, dtype=float), np.ascontiguousarray(P, dtype=float),
        int(increments), float(tol), int(max_iter),
    )  # fmt: skip
    model = batch.inputs.model(U3, batch.theta0, batch.k_nonneg)
    for (pat, red, members), kind in zip(batch.groups, kinds, strict=True):
        banded = kind == "banded"
        band = red.band if banded else None
        perm = band.perm if banded else np.zeros(0, np.intp)
        bw = int(band.bandwidth) if banded else -1
        idx = np.ascontiguousarray(members, dtype=np.intp)
        whole = idx.size == S and (idx == np.arange(S)).all()  # rows of rec in place
        if whole:
            out = IncrementRecords(*rec[:6])
        else:
            out = IncrementRecords.empty(idx.size, increments, nd)
        lists = (
            red.tangent_sums("banded" if banded else "dense_upper"),
            red.tangent_sums("banded" if banded else "dense_cm"),
        )
        fac = Factor(red.free, perm, bw, ck.lapack_addresses(*_SOLVE[kind]))
        ck.newton_increments(model, idx, batch.scatter(pat), lists, load, fac, U, out)
        if not whole:
            for field, values in zip(rec[:6], out, strict=True):
                field[idx] = values
        rec.banded[idx] = banded
    return rec
