"""Newton-Raphson load control, the reference simulator's semantics (docs/bar-and-hinge.md §6.2).

At increment ``i = 1..increments`` the applied force is ``F0 + i * load`` (``load`` is a
*per-increment* load; the total after the stage is ``increments * load``). Each increment
iterates, starting from the previous increment's displacement::

    R = inf, step = 1
    while step < max_iter and R > tol:
        assemble f_int(U), K(U)
        r = F0 + i * load - f_int                 (supported DOFs eliminated)
        dU = K_ff^-1 r_f ;  U_f += dU ;  R = ||dU||_2
        step += 1

so there are at most ``max_iter - 1`` iterations and the first one always runs (the reference
starts from ``R = 1``, which is the same for every ``tol < 1 m``). Convergence means
``R <= tol`` after the last update, and, for an increment that adds load, a displacement change
of at least ``RESOLUTION`` (1e-10) times the model's size: below that the displacement is at the
round-off of the coordinates (a force of 1e-14 N, a modulus of 1e25 Pa) and whatever stiffness
it gives is noise, so the increment is "not converged" with that reason. A non-converged
increment is *accepted* (the last iterate is kept and the next increment starts from it), as
the reference does; it is recorded in ``SolveResult.converged`` and ``status``. Supported DOFs
keep their current value (``U0``).
"""

from __future__ import annotations

import numpy as np

from holofold.geometry.errors import ParameterError
from holofold.mechanics.assembly import Assembler, BatchAssembler, SingularSystemError
from holofold.mechanics.linear import NON_FINITE, SINGULAR
from holofold.mechanics.newton_step import (
    NewtonRecords,
    batch_newton_increments,
    load_increments,
)
from holofold.mechanics.solvers._common import (
    RESOLUTION,
    History,
    check_controls,
    describe,
    get_assembler,
    logger,
    model_size,
    nodal_array,
)
from holofold.mechanics.solvers.result import SolveResult
from holofold.mechanics.status import CONVERGED
from holofold.mechanics.structure import Structure
from holofold.mechanics.threads import single_threaded

__all__ = ["solve_newton", "solve_newton_batch"]


@single_threaded
def solve_newton(
    structure: Structure,
    load,
    *,
    increments: int,
    tol: float = 1e-5,
    max_iter: int = 30,
    U0=None,
    F0=None,
    assembler: Assembler | None = None,
) -> SolveResult:
    """Newton-Raphson load control (reference semantics).

    Parameters
    ----------
    structure : Structure
        The model; ``structure.supports`` gives the fixed DOFs.
    load : (nn, 3) float
        Load added per increment, N (applied load at increment i is ``F0 + i * load``).
    increments : int
        Number of load increments (>= 1).
    tol : float
        Convergence tolerance on ``||dU||_2``, m.
    max_iter : int
        Iteration cap: at most ``max_iter - 1`` iterations per increment (reference).
    U0 : (nn, 3) float, optional
        Starting displacement (default 0), m.
    F0 : (nn, 3) float, optional
        External force already applied by earlier stages (default 0), N.
    assembler : Assembler, optional
        A prebuilt ``Assembler(structure)`` to reuse across solves.

    Returns
    -------
    SolveResult
        ``load_factor`` is the increment index; ``residual`` is the last ``||dU||_2``.
    """
    asm = get_assembler(structure, assembler)
    increments, tol, max_iter = check_controls(increments, tol, max_iter)
    nn = structure.n_nodes
    P = nodal_array("load", load, nn).ravel()
    F0v = nodal_array("F0", F0, nn).ravel()
    U = nodal_array("U0", U0, nn).ravel()
    free = asm.free_dofs
    hist = History(increments, nn)
    floor = RESOLUTION * model_size(structure) if np.any(P[free]) else 0.0
    # every increment in one kernel call where the dense step applies
    rec = load_increments(asm, U, F0v, P, increments, tol, max_iter)
    if rec is not None:
        one = NewtonRecords(rec.U, rec.conv, rec.iters, rec.res, rec.moved, rec.failed, None)
        return _from_records(one, 0, structure, tol, floor, F0v, P)
    i = 0
    for i in range(1, increments + 1):
        Fi = F0v + i * P
        step = 1
        R = np.inf
        start = U.copy() if floor else None
        # the compiled dense step where it applies, else the same operations here
        dense = asm.dense_stepper(U, Fi)
        try:
            while step < max_iter and R > tol:
                if dense is not None:
                    dU = dense()
                else:
                    _, f, solve = asm.evaluate_factorized(U)
                    dU = solve((Fi - f)[free])
                    U[free] += dU
                R = float(np.sqrt(dU @ dU))
                step += 1
        except SingularSystemError as exc:
            hist.failure = f"increment {i}, iteration {step}: {exc}"
            hist.record(U, i, False, step - 1, R)
            break
        resolved = not floor or hist.check_resolution(float(np.abs(U - start).max()), floor)
        hist.record(U, i, R <= tol and resolved, step - 1, R)
    return hist.result(tol, "||dU||", F0v + i * P, structure.spring_rest, "solve_newton")


@single_threaded
def solve_newton_batch(
    structures,
    loads,
    *,
    increments: int,
    tol: float = 1e-5,
    max_iter: int = 30,
    U0=None,
    F0=None,
    batch: BatchAssembler | None = None,
) -> list[SolveResult]:
    """:func:`solve_newton` for S structures of one topology and support mask, in lockstep.

    Every iteration evaluates the samples still iterating together (one kernel call and one
    scatter for the batch, :class:`~holofold.mechanics.assembly.BatchAssembler`); each sample
    keeps its own increment loop, convergence, iteration count and failure, and its
    :class:`SolveResult` is the one :func:`solve_newton` gives it alone (to round-off).

    Parameters
    ----------
    structures : sequence of Structure
    loads : sequence of (nn, 3) float, or (S, nn, 3) float
        Per-sample load per increment, N.
    increments, tol, max_iter
        As for :func:`solve_newton` (shared).
    U0, F0 : sequence of (nn, 3) float, optional
        Per-sample start displacement (m) and applied force (N); default 0.
    batch : BatchAssembler, optional
        Prebuilt for ``structures``.

    Returns
    -------
    list of SolveResult
    """
    structures = list(structures)
    B = BatchAssembler(structures) if batch is None else batch
    if B.n != len(structures):
        raise ParameterError(f"batch holds {B.n} structures, got {len(structures)}")
    increments, tol, max_iter = check_controls(increments, tol, max_iter)
    S = len(structures)
    nn = structures[0].n_nodes
    if len(loads) != S:
        raise ParameterError(f"loads: {len(loads)} given for {S} structures")
    if isinstance(loads, np.ndarray) and loads.shape == (S, nn, 3):  # one check for all
        P = nodal_array("loads", loads.reshape(S * nn, 3), S * nn).reshape(S, 3 * nn)
    else:
        P = np.stack([nodal_array("load", ld, nn).ravel() for ld in loads])
    F0v = _stacked("F0", F0, S, nn)
    U = _stacked("U0", U0, S, nn)
    free = B.free_dofs
    X = B.inputs.X  # model_size of every structure at once
    lo, hi = X.min(axis=1), X.max(axis=1)  # per sample: max(ptp, max |x|) over the axes
    size = np.maximum(hi - lo, np.maximum(-lo, hi)).max(axis=1)
    floors = np.where(np.any(P[:, free] != 0.0, axis=1), RESOLUTION * np.maximum(size, 1e-300), 0.0)
    rec = batch_newton_increments(B, U, F0v, P, increments, tol, max_iter)
    if rec is not None:  # every increment of every sample in one kernel call per connectivity
        # samples with every increment converged and resolved and no failure: status
        # CONVERGED without describing each increment (what describe() returns for them)
        clean = (
            (rec.failed[:, 0] == 0)
            & rec.converged.all(axis=1)
            & ((floors == 0.0) | (rec.moved >= floors[:, None]).all(axis=1))
        ).tolist()
        # their shared arrays, made once: the applied force after every increment and the
        # convergence flags (a copy; each sample's row of it)
        applied = (F0v + increments * P).reshape(S, nn, 3)
        conv = rec.converged.copy()
        out = []
        for s in range(S):
            if clean[s]:
                out.append(_converged_record(rec, s, structures[s], applied[s], conv[s]))
            elif rec.failed[s, 0] == 1 and rec.banded[s]:  # not positive definite: LU alone
                out.append(solve_newton(
                    structures[s], loads[s], increments=increments, tol=tol,
                    max_iter=max_iter, U0=None if U0 is None else U0[s],
                    F0=None if F0 is None else F0[s],
                ))  # fmt: skip
            else:
                out.append(_from_records(rec, s, structures[s], tol, floors[s], F0v[s], P[s]))
        return out
    hists = [History(increments, nn) for _ in range(S)]
    alive = np.ones(S, bool)
    last = np.zeros(S, np.int64)
    for i in range(1, increments + 1):
        Fi = F0v + i * P
        step = np.ones(S, np.int64)
        R = np.full(S, np.inf)
        last[alive] = i
        start = U.copy()
        while True:
            it = alive & (step < max_iter) & (R > tol)
            if not it.any():
                break
            dU, errors = B.newton_step(U, Fi, it)  # U[s, free] += dU[s] where solved
            for s, exc in errors.items():
                hists[s].failure = f"increment {i}, iteration {step[s]}: {exc}"
                hists[s].record(U[s], i, False, step[s] - 1, R[s])
                alive[s] = False
                it[s] = False
            # ||dU|| of each solved sample
            ok = np.flatnonzero(it)
            R[ok] = np.sqrt(np.vecdot(dU[ok], dU[ok]))
            step[ok] += 1
        moved = np.abs(U - start).max(axis=1)
        for s in np.flatnonzero(alive):
            ok = not floors[s] or hists[s].check_resolution(float(moved[s]), floors[s])
            hists[s].record(U[s], i, R[s] <= tol and ok, step[s] - 1, R[s])
    return [
        hists[s].result(
            tol, "||dU||", F0v[s] + last[s] * P[s], structures[s].spring_rest, "solve_newton"
        )
        for s in range(S)
    ]


def _stacked(name, values, S, nn) -> np.ndarray:
    """(S, 3 nn) C-contiguous: the per-sample nodal arrays ``values`` (checked), or zeros."""
    if values is None:
        return np.zeros((S, 3 * nn))
    return np.stack([nodal_array(name, values[s], nn).ravel() for s in range(S)])


def _converged_record(rec, s, structure, applied, converged) -> SolveResult:
    """:func:`_from_records` of a sample whose every increment converged above the round-off
    resolution and none failed (its status is :data:`CONVERGED`): ``applied`` (nn, 3) its
    force after the last increment, N, ``converged`` its flags (a copy of the records')."""
    count = rec.U.shape[1]
    return SolveResult(
        U_history=rec.U[s].reshape(count, -1, 3),
        load_factor=np.arange(1.0, count + 1.0),
        converged=converged,
        iterations=rec.iterations[s],
        residual=rec.residual[s],
        status=CONVERGED,
        applied_force=applied,
        spring_rest=np.array(structure.spring_rest, float),
    )


def _from_records(rec, s, structure, tol, floor, F0, P) -> SolveResult:
    """Sample ``s``'s :class:`SolveResult` from :func:`batch_newton_increments`' records, as
    :func:`solve_newton` builds it."""
    code, at, step = (int(v) for v in rec.failed[s])
    count = at if code else rec.U.shape[1]
    conv = rec.converged[s, :count].copy()
    unresolved = {}
    if floor:
        for c in range(count - (1 if code else 0)):
            if rec.moved[s, c] < floor:
                unresolved[c] = (float(rec.moved[s, c]), floor)
                conv[c] = False
    failure = None
    if code:
        failure = f"increment {at}, iteration {step}: {SINGULAR if code == 1 else NON_FINITE}"
    # views of this call's own records (no other reference to them is kept)
    iters, res = rec.iterations[s, :count], rec.residual[s, :count]
    status = describe(conv, iters, res, tol, "||dU||", failure, unresolved)
    if not status.converged:
        logger.info("solve_newton: %s", status)
    return SolveResult(
        U_history=rec.U[s, :count].reshape(count, -1, 3),
        load_factor=np.arange(1, count + 1, dtype=float),
        converged=conv,
        iterations=iters,
        residual=res,
        status=status,
        applied_force=(F0 + count * P).reshape(-1, 3),
        spring_rest=np.array(structure.spring_rest, float),
    )
