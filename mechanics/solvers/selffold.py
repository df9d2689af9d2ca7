"""Self-folding by rest-angle control (docs/bar-and-hinge.md §6.5).

The spring rest angles move linearly from ``start_rest`` to ``target_rest`` over the increments,
``theta0_i = (1 - i/n) start + (i/n) target``, and each increment runs Newton iterations on
``r = F0 - f_int(U)`` (no new load) with the supports eliminated, as the reference does::

    R = inf, step = 1
    while step < max_iter and R > tol:
        r = F0 - f_int(U; theta0_i);  dU = K_ff^-1 r_f;  U_f += dU;  R = ||r_f||_2;  step += 1

Note the reference's order: the residual norm is that of the residual *before* the update, and the
update is applied even on the iteration that meets the tolerance. Snap-through cannot be followed.
"""

from __future__ import annotations

import math

import numpy as np

from holofold.mechanics.assembly import Assembler, SingularSystemError
from holofold.mechanics.solvers._common import (
    History,
    check_controls,
    get_assembler,
    nodal_array,
    spring_array,
)
from holofold.mechanics.solvers.result import SolveResult
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
    free = asm.free_dofs
    r = np.empty(free.size)
    hist = History(increments, nn)
    for i in range(1, increments + 1):
        s = i / increments
        rest = (1.0 - s) * start + s * target
        step = 1
        R = np.inf
        # the compiled dense step where it applies, else the same operations here
        dense = asm.dense_stepper(U, F0v, rest, r)
        try:
            while step < max_iter and R > tol:
                if dense is not None:
                    dense()
                else:
                    _, f, solve = asm.evaluate_factorized(U, rest)
                    r = (F0v - f)[free]
                    U[free] += solve(r)
                R = math.sqrt(r @ r)  # = float(np.sqrt(r @ r)): both correctly rounded
                step += 1
        except SingularSystemError as exc:
            hist.failure = f"increment {i}, iteration {step}: {exc}"
            hist.record(U, s, False, step - 1, R)
            break
        hist.record(U, s, R <= tol, step - 1, R)
    return hist.result(tol, "||r||", F0v, target, "solve_selffold")
