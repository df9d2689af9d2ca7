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

from typing import TYPE_CHECKING

import numpy as np

from holofold.mechanics import kernels
from holofold.mechanics.linear import NON_FINITE, SINGULAR, SingularSystemError, solver_path

if TYPE_CHECKING:
    from holofold.mechanics.assembly import Assembler, BatchAssembler

__all__ = ["DenseStepper", "batch_newton_step"]

_LAPACK = {"banded": ("dpbtrf", "dpbtrs"), "dense": ("dgetrf", "dgetrs")}


def _error(code: int) -> SingularSystemError:
    return SingularSystemError(SINGULAR if code == 1 else NON_FINITE)


class DenseStepper:
    """One design's Newton update on the dense path, its arguments bound once.

    ``step()`` evaluates the kernels at ``U``, factorises the free-free block (LU), solves for
    ``(F - f_int)[free]``, adds the solution to ``U[free]`` (in place) and returns it (a buffer
    the next call overwrites); ``r``, if given, receives the residual. Raises
    :class:`SingularSystemError` (U left alone). Build it with
    :meth:`~holofold.mechanics.assembly.Assembler.dense_stepper`.
    """

    def __init__(self, asm: Assembler, U, F, spring_rest=None, r=None):
        red = asm.reduction
        path = kernels.active()
        self._fn = path.module.dense_newton_step
        rest = asm.theta0 if spring_rest is None else spring_rest
        theta0 = np.ascontiguousarray(rest, dtype=float).reshape(1, -1)
        self.dU = np.empty((1, red.n_free))
        self.info = np.zeros(1, np.int8)
        res = self.dU if r is None else r.reshape(1, -1)
        scratch = asm._buffers()
        one = asm.inputs.batch_of_one()
        self._args = (
            *one.with_displacements(U.reshape(1, -1, 3)), theta0, np.array([asm.k_nonneg]),
            np.zeros(1, np.intp),
            asm.pattern.force_sums, red.tangent_sums("dense_cm"), scratch, scratch.flat(),
            F.reshape(1, -1), red.free, path.module.lapack_addresses(*_LAPACK["dense"]),
            U.reshape(1, -1), self.dU, self.info, res,
        )  # fmt: skip

    def __call__(self) -> np.ndarray:
        self._fn(*self._args)
        if self.info[0]:
            raise _error(int(self.info[0]))
        return self.dU[0]


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
        flats = batch.scratch.flat()
        for pat, red, members in batch.groups:
            idx = np.ascontiguousarray(members[active[members]], dtype=np.intp)
            kind = solver_path(red, batch.dense_max)
            if idx.size == 0 or kind not in _LAPACK:
                continue
            addrs = ck.lapack_addresses(*_LAPACK[kind])
            common = (
                *batch.inputs.with_displacements(U3), batch.theta0, batch.k_nonneg, idx,
                pat.force_sums,
            )  # fmt: skip
            dU = np.empty((idx.size, red.n_free))
            info = np.zeros(idx.size, np.int8)
            if kind == "banded":
                band = red.band
                fj = np.empty((idx.size, batch.n_dof))
                ck.band_newton_step(
                    *common, red.tangent_sums("banded"), batch.scratch, flats, Fi, red.free,
                    band.perm, band.bandwidth, addrs, U, dU, fj, info,
                )  # fmt: skip
            else:
                ck.dense_newton_step(
                    *common, red.tangent_sums("dense_cm"), batch.scratch, flats, Fi, red.free,
                    addrs, U, dU, info, dU,
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
