"""Self-folding by rest-angle control (docs/bar-and-hinge.md §6.5).

The spring rest angles move linearly from ``start_rest`` to ``target_rest`` over the increments,
``theta0_i = (1 - i/n) start + (i/n) target``, and each increment runs Newton iterations on
``r = F0 - f_int(U)`` (no new load) with the supports eliminated, as the reference does::

    R = inf, step = 1
    while step < max_iter and R > tol:
        r = F0 - f_int(U; theta0_i);  dU = K_ff^-1 r_f;  U_f += dU;  R = ||r_f||_2;  step += 1

Note the reference's order: the residual norm is that of the residual *before* the update, and the
update is applied even on the iteration that meets the tolerance. Snap-through cannot be followed.

``line_search=True`` (:func:`~holofold.mechanics.folding.fold_pattern`'s optional retry of a
failed step) keeps that order but backtracks a Newton update that does not lower the potential
energy ``Pi = E(U) - F0 . U`` by the Armijo amount ``1e-4 a r . dU`` and does not lower ``||r||``
either (:func:`_backtrack`): the full step's linearised rotations stretch the stiff panel bars
(a residual 100-1000x the step's start), and from a state far from equilibrium the full step
can leave the basin altogether. A full step that passes either test is taken as it is, so the
last, quadratically converging iterations are the plain ones. Measured (docs/patterns.md,
"Stalls: step control"): it lands on Newton's equilibrium but takes 2-4x the iterations on a
waterbomb step and doubles the factorisations of the surface fold check: the energy that the
full step's stretch adds is removed by the next full step, so cutting the step only slows the
fold. Off by default.
"""

from __future__ import annotations

import math

import numpy as np

from holofold.mechanics.assembly import Assembler, SingularSystemError
from holofold.mechanics.linear import NON_FINITE, SINGULAR
from holofold.mechanics.newton_step import selffold_increments
from holofold.mechanics.solvers._common import (
    History,
    check_controls,
    describe,
    get_assembler,
    logger,
    nodal_array,
    spring_array,
)
from holofold.mechanics.solvers.result import SolveResult
from holofold.mechanics.status import CONVERGED
from holofold.mechanics.structure import Structure
from holofold.mechanics.threads import single_threaded

__all__ = ["solve_selffold"]


@single_threaded
def solve_selffold(
    structure: Structure,
    target_rest,
    *,
    increments: int = 50,
    tol: float = 1e-5,
    max_iter: int = 30,
    U0=None,
    F0=None,
    start_rest=None,
    assembler: Assembler | None = None,
    line_search: bool = False,
) -> SolveResult:
    """Fold by driving the spring rest angles to ``target_rest``.

    Parameters
    ----------
    structure : Structure
        The model; supports from ``structure.supports``.
    target_rest : (ns,) float
        Spring rest angles at the end of the stage, rad (pi = flat).
    increments : int
        Number of rest-angle increments (>= 1).
    tol : float
        Convergence tolerance on the support-modified residual ``||r||_2``, N.
    max_iter : int
        At most ``max_iter - 1`` iterations per increment.
    U0, F0 : (nn, 3) float, optional
        Starting displacement (m) and the external force kept applied (N); default 0.
    start_rest : (ns,) float, optional
        Rest angles at the start (default ``structure.spring_rest``), rad.
    assembler : Assembler, optional
        A prebuilt ``Assembler(structure)``.
    line_search : bool
        Backtrack Newton updates that raise both the potential energy and the residual
        (see the module docstring); default False (the reference's full steps).

    Returns
    -------
    SolveResult
        ``load_factor`` is ``i / increments``; ``spring_rest`` is ``target_rest``.
    """
    asm = get_assembler(structure, assembler)
    increments, tol, max_iter = check_controls(increments, tol, max_iter)
    nn = structure.n_nodes
    ns = len(structure.springs)
    target = spring_array("target_rest", target_rest, ns)
    if start_rest is None:
        start = structure.spring_rest
    else:
        start = spring_array("start_rest", start_rest, ns)
    F0v = nodal_array("F0", F0, nn).ravel()
    U = nodal_array("U0", U0, nn).ravel()
    if not line_search:  # every increment in one kernel call where the dense step applies
        rec = selffold_increments(asm, U, F0v, start, target, increments, tol, max_iter)
        if rec is not None:
            return _result(rec, increments, tol, F0v, target)
    free = asm.free_dofs
    hist = History(increments, nn)
    r = np.empty(free.size)
    for i in range(1, increments + 1):
        s = i / increments
        rest = (1.0 - s) * start + s * target
        step = 1
        R = np.inf
        # the compiled dense step where it applies, else the same operations here
        dense = asm.dense_stepper(U, F0v, rest, r)
        try:
            E = None
            while step < max_iter and R > tol:
                if line_search:
                    before = U[free].copy()
                if dense is not None:
                    if line_search and E is None:
                        E = asm.internal_force(U, rest)[0] - F0v @ U
                    dU = dense()
                else:
                    e, f, solve = asm.evaluate_factorized(U, rest)
                    if line_search and E is None:
                        E = e - F0v @ U
                    r = (F0v - f)[free]
                    dU = solve(r)
                    U[free] += dU
                R = math.sqrt(r @ r)  # = float(np.sqrt(r @ r)): both correctly rounded
                step += 1
                if line_search and R > tol:
                    E = _backtrack(asm, U, before, dU, r, R, E, rest, F0v)
        except SingularSystemError as exc:
            hist.failure = f"increment {i}, iteration {step}: {exc}"
            hist.record(U, s, False, step - 1, R)
            break
        hist.record(U, s, R <= tol, step - 1, R)
    return hist.result(tol, "||r||", F0v, target, "solve_selffold")


def solve_selffold_checked(
    asm: Assembler, U, F0v, start, target, increments: int, tol: float, max_iter: int
) -> SolveResult:
    """:func:`solve_selffold` (full steps) without its argument checks, for a caller that made
    them once for many solves (:func:`~holofold.mechanics.thermal.electrothermal_stage`):
    ``asm`` the structure's assembler; ``U`` (ndof,) float C-contiguous, m, updated in place
    to the last iterate; ``F0v`` (ndof,) N, ``start`` and ``target`` (ns,) rad: finite float
    arrays (not copied; ``target`` becomes the result's ``spring_rest``); the controls as
    :func:`~holofold.mechanics.solvers._common.check_controls` returns them."""
    rec = selffold_increments(asm, U, F0v, start, target, increments, tol, max_iter)
    if rec is not None:
        return _result(rec, increments, tol, F0v, target)
    res = solve_selffold(
        asm.structure, target, increments=increments, tol=tol, max_iter=max_iter, U0=U,
        F0=F0v, start_rest=start, assembler=asm,
    )  # fmt: skip
    U[:] = res.U.ravel()
    return res


def _result(rec, increments: int, tol: float, F0v, target) -> SolveResult:
    """The :class:`SolveResult` of :func:`~holofold.mechanics.newton_step.selffold_increments`'
    records of one sample: what the increment loop's :class:`History` gives (the records'
    rows as the histories, not copies)."""
    code, i, step = rec.failed[0].tolist()
    n = i if code else increments
    conv, iters, res = rec.conv[0, :n], rec.iters[0, :n], rec.res[0, :n]
    if code:
        failure = f"increment {i}, iteration {step}: {SINGULAR if code == 1 else NON_FINITE}"
    else:
        failure = None
    if failure is None and conv.all():
        status = CONVERGED  # what describe() gives
    else:
        status = describe(conv, iters, res, tol, "||r||", failure)
        logger.info("%s: %s", "solve_selffold", status)
    return SolveResult(
        U_history=rec.U[0, :n].reshape(n, -1, 3), load_factor=np.arange(1, n + 1) / increments,
        converged=conv, iterations=iters, residual=res, status=status,
        applied_force=F0v.reshape(-1, 3).copy(), spring_rest=target,
    )  # fmt: skip


#: Armijo constant of the line search, and its smallest step fraction
_ARMIJO = 1e-4
_MIN_STEP = 1.0 / 64


def _backtrack(asm, U, before, dU, r, R, E, rest, F0v) -> float:
    """Backtrack the Newton update ``U[free] = before + dU`` (``U`` (ndof,), updated in place)
    from the state with residual ``r`` (its norm ``R``) and potential ``E``: keep the first
    step fraction ``a`` (1, then a safeguarded quadratic fit of the energy, at least a tenth
    and at most half the last ``a``) whose potential passes the Armijo test
    ``Pi(a) <= E - 1e-4 a r.dU`` (only when ``dU`` is a descent direction, ``r.dU > 0``) or
    whose residual is below ``(1 - 1e-4 a) R``; below ``a`` = 1/64 keep the smallest.
    Returns the potential at the kept state."""
    free = asm.free_dofs
    slope = float(r @ dU)  # -dPi/da at a = 0
    a = 1.0
    while True:
        Et, f = asm.internal_force(U, rest)
        Et -= F0v @ U
        rt = (F0v - f)[free]
        if not np.isfinite(Et):
            ok = False
        else:
            ok = (slope > 0 and Et <= E - _ARMIJO * a * slope) or math.sqrt(rt @ rt) <= (
                1.0 - _ARMIJO * a
            ) * R
        if ok or a <= _MIN_STEP:
            return Et
        if slope > 0 and np.isfinite(Et):  # minimiser of the quadratic through E, -slope, Et
            q = slope * a * a / (2.0 * (Et - E + slope * a))
            a_new = min(max(q, 0.1 * a), 0.5 * a)
        else:
            a_new = 0.5 * a
        a = max(a_new, _MIN_STEP)
        U[free] = before + a * dU
